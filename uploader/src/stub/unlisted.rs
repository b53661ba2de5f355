//! Memory the stub keeps clear of besides what the table names: code a
//! hook leads to that no entry lists (an owner's, put there by hand; an
//! extension whose entry was freed), which runs on every pass of the
//! control loop or at every unknown command. Written over while it ran,
//! it jammed the robot (hostile26 F4). Its extent no look can tell, so the
//! stub keeps a margin around every byte its way was seen to touch.

use std::collections::BTreeSet;
use std::ops::RangeInclusive;

use romlib::installed::Installed;

use super::error::StubResult;
use crate::client::Client;
use crate::hooks::read_hooks;
use crate::image::{RomProfile, UploadImage};
use crate::transport::Transport;

/// Bytes kept clear on each side of what the way touched outside the
/// zero page: the code around an entry (a branch not taken this time, a
/// counter kept beside it) is seldom further than a page away.
pub const MARGIN: u16 = 0x100;

/// The memory both hooks' ways touch in code neither `installed` nor
/// `image` holds, each byte widened by [`MARGIN`] (zero-page bytes as
/// they are: the stub takes two of them and code keeps its pointers
/// there one by one).
///
/// # Errors
/// The line's errors.
pub(super) fn clear_of<T: Transport>(
    client: &mut Client<T>,
    profile: &RomProfile,
    installed: &[Installed],
    image: &UploadImage,
) -> StubResult<Vec<RangeInclusive<u16>>> {
    // Only reads: tried again whole where the line went quiet (fresh15
    // F5's quiet line, which every other look of an attach survives).
    let mut touched = crate::session::tried_quiet(crate::hooks::QUIET_LOOKS, || {
        let mut touched = BTreeSet::new();
        for (kind, target) in read_hooks(client, profile)? {
            if profile.reset_target(kind) == Some(target) {
                continue;
            }
            touched.extend(crate::chain::unlisted_touched(
                client,
                profile,
                installed,
                (kind, target),
            )?);
        }
        Ok(touched)
    })?;
    touched.retain(|&at| !image.contains(at));
    Ok(around(&touched))
}

/// `touched` as ranges: zero-page bytes one by one, the rest widened by
/// [`MARGIN`] each side and merged.
fn around(touched: &BTreeSet<u16>) -> Vec<RangeInclusive<u16>> {
    let mut ranges: Vec<RangeInclusive<u16>> = Vec::new();
    for &at in touched {
        if at <= 0xFF {
            ranges.push(at..=at);
            continue;
        }
        let (low, high) = (at.saturating_sub(MARGIN), at.saturating_add(MARGIN));
        match ranges.last_mut() {
            Some(last) if *last.start() > 0xFF && *last.end() >= low.saturating_sub(1) => {
                *last = *last.start()..=high.max(*last.end());
            }
            _ => ranges.push(low..=high),
        }
    }
    ranges
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_are_widened_by_the_margin_and_merged() {
        let touched: BTreeSet<u16> = [0x30, 0x31, 0x0D16, 0x0D17, 0x0D1C, 0x0F00, 0x2000].into();
        assert_eq!(
            around(&touched),
            vec![0x30..=0x30, 0x31..=0x31, 0x0C16..=0x1000, 0x1F00..=0x2100]
        );
    }

    #[test]
    fn the_ends_of_memory_do_not_wrap() {
        let touched: BTreeSet<u16> = [0x0150, 0xFFF0].into();
        assert_eq!(around(&touched), vec![0x0050..=0x0250, 0xFEF0..=0xFFFF]);
    }
}
