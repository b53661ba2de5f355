//! `scorpion installed`: what a robot has installed, from its table of
//! installed extensions, and where each hook's chain runs.

use std::fmt::Write as _;
use std::io::Write as _;
use std::process::ExitCode;

use isa::objfmt::HookKind;
use miette::IntoDiagnostic;
use romlib::installed::{Installed, extent_text};

use crate::cmd::ports;

/// List the extensions a robot has installed (the ROM's table, read with
/// `/7R`): each one's id, memory and hooks, then each hook's chain in the
/// order a command travels it.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    #[command(flatten)]
    line: ports::Line,
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let (mut client, profile) = ports::probed(&args.line)?;
    let names = project_images(&args.line);
    let everyone = uploader::read_installed(&mut client, &profile)?;
    let mut chains = Vec::new();
    for kind in HookKind::ALL {
        chains.push((
            kind,
            uploader::chain_of(&mut client, &profile, &everyone, kind)?,
        ));
    }
    // A chain that ends at no extension's handler may end at a debug stub
    // a killed session left: the user must hear of it here, before an
    // upload refuses it.
    let mut text = String::new();
    for (kind, targets) in &mut chains {
        let Some(&last) = targets.last() else {
            continue;
        };
        let owned = everyone
            .iter()
            .flat_map(|image| image.hooks.iter())
            .any(|hook| hook.kind == *kind && hook.handler == last);
        if owned || profile.reset_target(*kind) == Some(last) {
            continue;
        }
        if let Some(place) = uploader::loader_left_at(&mut client, &profile, last)? {
            let _ = writeln!(
                text,
                "{}: ${last:04X} is the RAM loader (${:04X}-${:04X}) an upload, a restore or a debug session's attach left hooked: it did not finish (killed, or its line failed); unknown commands other than the loader's own go to the ROM\n  `scorpion upload --undo --port {}` puts back what an upload overwrote (after a restore: that restore again; after an attach, `scorpion upload` of the image takes the loader out and keeps the image); then upload again",
                kind.rom_symbol(),
                place.start(),
                place.end(),
                client.transport().name(),
            );
            continue;
        }
        if let Some(stub) = uploader::stub::left::at_target(&mut client, &profile, last)? {
            let what = if last == stub.handler {
                "is"
            } else {
                "lies inside the code of"
            };
            let _ = writeln!(
                text,
                "{}: ${last:04X} {what} a debug stub left hooked at ${:04X}-${:04X} (chaining to ${:04X}): a debug session did not detach, and its breakpoints may still be in the code\n  to take it out: `scorpion debug --port {}` in the project that built the image it debugged (elsewhere, with `--image ELF`), then `quit`; or reset the robot",
                kind.rom_symbol(),
                stub.address,
                stub.end,
                stub.previous,
                client.transport().name(),
            );
            // fresh19 F5: what it chains to is reached through it.
            let onward = (*kind, stub.previous);
            targets.extend(uploader::chain_from(
                &mut client,
                &profile,
                &everyone,
                onward,
            )?);
        }
    }
    // recheck26 N4: a chain that ends in code no entry lists may go on
    // through it to an extension the table's chain slots do not reach.
    let open_ends: Vec<HookKind> = chains
        .iter()
        .filter(|(kind, targets)| {
            targets.last().is_some_and(|&last| {
                profile.reset_target(*kind) != Some(last)
                    && !everyone
                        .iter()
                        .flat_map(|image| image.hooks.iter())
                        .any(|hook| hook.kind == *kind && hook.handler == last)
            })
        })
        .map(|(kind, _)| *kind)
        .collect();
    let mut text = listing(&everyone, (&chains, &open_ends), &names) + text.as_str();
    // fresh25 F7: how much room is left, for a project refused as the
    // table is full.
    if let Some((_, capacity)) = profile.table.filter(|_| !everyone.is_empty()) {
        let used: usize = everyone.iter().map(Installed::entries).sum();
        let _ = writeln!(
            text,
            "{} of the table's {capacity} entries in use, {} free",
            used,
            capacity.saturating_sub(used)
        );
    }
    std::io::stdout()
        .lock()
        .write_all(text.as_bytes())
        .into_diagnostic()?;
    Ok(ExitCode::SUCCESS)
}

/// A project image, built as its sources are now: its name, id and memory.
struct Known {
    name: String,
    id: u32,
    extents: Vec<std::ops::RangeInclusive<u16>>,
}

/// In a project, its images built in memory (nothing written), to name
/// what the table lists by id alone (fresh19 F12). An image that does not
/// build names nothing, said on stderr.
fn project_images(line: &ports::Line) -> Vec<Known> {
    let Some(project) = line.resolve().ok().and_then(|resolved| resolved.project) else {
        return Vec::new();
    };
    let mut known = Vec::new();
    for spec in &project.file.images {
        let built = scorpion_project::runner::build::build(&project, spec)
            .map_err(|error| error.to_string())
            .and_then(|built| {
                uploader::UploadImage::try_from(&built.linked.image)
                    .map_err(|error| error.to_string())
            });
        match built {
            Ok(image) => known.push(Known {
                name: spec.name.clone(),
                id: image.id(),
                extents: image.extents().to_vec(),
            }),
            Err(why) => {
                let _ = writeln!(
                    std::io::stderr(),
                    "note: the project's image {} does not build ({why}): what the robot lists is not matched with it",
                    spec.name
                );
            }
        }
    }
    known
}

/// How `image` is named beside its id: the project image it is (the same
/// bytes at the same place: an image whose bytes do not depend on where it
/// loads has one id wherever it goes, hostile21 F1), or those whose memory
/// it lies in (another build of one of them, or someone else's).
fn named(image: &Installed, names: &[Known]) -> String {
    if let Some(known) = is(image, names) {
        return format!(" ({})", known.name);
    }
    let overlaps = |known: &&Known| {
        known.extents.iter().any(|ours| {
            image
                .extents
                .iter()
                .any(|theirs| ours.start() <= theirs.end() && theirs.start() <= ours.end())
        })
    };
    let under: Vec<&str> = names
        .iter()
        .filter(overlaps)
        .map(|known| known.name.as_str())
        .collect();
    match under.as_slice() {
        [] => String::new(),
        [one] => format!(" (where the project's {one} goes, but not it as its sources build now)"),
        many => format!(
            " (where the project's {} go, but none of them as its sources build now)",
            many.join(", ")
        ),
    }
}

/// The project image `image` is: its id and its memory.
fn is<'a>(image: &Installed, names: &'a [Known]) -> Option<&'a Known> {
    names
        .iter()
        .find(|known| known.id == image.id && known.extents == image.extents)
}

/// The listing, for people.
fn listing(
    everyone: &[Installed],
    (chains, open_ends): (&[(HookKind, Vec<u16>)], &[HookKind]),
    names: &[Known],
) -> String {
    let mut out = String::new();
    if everyone.is_empty() {
        out.push_str("nothing installed\n");
    }
    for image in everyone {
        let extents: Vec<String> = image.extents.iter().map(extent_text).collect();
        let _ = write!(
            out,
            "extension {:06X}{}: {}",
            image.id,
            named(image, names),
            extents.join(", ")
        );
        for hook in &image.hooks {
            let _ = write!(out, "; {} -> ${:04X}", hook.kind.rom_symbol(), hook.handler);
            if let Some(slot) = hook.chain {
                let _ = write!(out, " (chain slot ${slot:04X})");
            }
            // recheck16 F5: an extension a restore left unhooked looked
            // hooked in the table's own words.
            let reached = chains
                .iter()
                .find(|(kind, _)| *kind == hook.kind)
                .is_none_or(|(_, targets)| targets.contains(&hook.handler));
            if !reached && open_ends.contains(&hook.kind) {
                let _ = write!(
                    out,
                    " (not on {}'s chain as the table follows it: that goes on through code no entry lists, which may lead here)",
                    hook.kind.rom_symbol()
                );
            } else if !reached {
                let _ = write!(
                    out,
                    " (not hooked: {} does not lead to it)",
                    hook.kind.rom_symbol()
                );
            }
        }
        out.push('\n');
    }
    for (kind, targets) in chains {
        // recheck17 F4: a chain that comes back is cut where it does.
        let again = (1..targets.len()).find(|&i| targets[..i].contains(&targets[i]));
        let targets = &targets[..again.map_or(targets.len(), |i| i + 1)];
        let steps: Vec<String> = targets
            .iter()
            .map(|target| {
                let owner = everyone.iter().find(|image| {
                    image
                        .hooks
                        .iter()
                        .any(|hook| hook.kind == *kind && hook.handler == *target)
                });
                let name = |image: &Installed| {
                    is(image, names).map_or(String::new(), |known| format!(" {}", known.name))
                };
                match owner {
                    Some(image) => format!("${target:04X} ({:06X}{})", image.id, name(image)),
                    None => format!("${target:04X}"),
                }
            })
            .collect();
        let _ = write!(out, "{}: {}", kind.rom_symbol(), steps.join(" -> "));
        if again.is_some() {
            out.push_str(
                " (comes back to where it has been: a loop the robot would run for ever at its next command)",
            );
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{Known, listing, named};
    use isa::objfmt::HookKind;
    use romlib::installed::{Installed, TakenHook};

    fn known(name: &str, id: u32, extents: std::ops::RangeInclusive<u16>) -> Known {
        Known {
            name: name.to_owned(),
            id,
            extents: vec![extents],
        }
    }

    /// hostile21 F1, F2: two images of the same bytes at two places have
    /// one id: each is named where it is, not the first found; an older
    /// build where two images go names both.
    #[test]
    fn an_extension_is_named_by_its_id_and_its_place() {
        let names = [
            known("i3", 0x79_4B2A, 0x0600..=0x0611),
            known("i4", 0x79_4B2A, 0x0700..=0x0711),
            known("za", 0x11_1111, 0x0400..=0x0411),
            known("zb", 0x22_2222, 0x0400..=0x0411),
        ];
        let at = |id: u32, extents: std::ops::RangeInclusive<u16>| Installed {
            id,
            extents: vec![extents],
            hooks: Vec::new(),
            slot: 0,
        };
        assert_eq!(named(&at(0x79_4B2A, 0x0700..=0x0711), &names), " (i4)");
        assert_eq!(named(&at(0x79_4B2A, 0x0600..=0x0611), &names), " (i3)");
        assert_eq!(
            named(&at(0x86_9D46, 0x0400..=0x0411), &names),
            " (where the project's za, zb go, but none of them as its sources build now)"
        );
        assert_eq!(
            named(&at(0x79_4B2A, 0x0608..=0x0620), &names),
            " (where the project's i3 goes, but not it as its sources build now)"
        );
        assert_eq!(named(&at(0x12_3456, 0x0900..=0x0910), &names), "");
    }

    /// recheck16 F5: after a restore that left an extension unhooked, the
    /// listing named its hook as if it were taken.
    #[test]
    fn an_extension_no_chain_reaches_is_said_not_hooked() {
        let everyone = [Installed {
            id: 0x8C_8390,
            extents: vec![0x0400..=0x044F],
            hooks: vec![TakenHook {
                kind: HookKind::Unknown,
                handler: 0x0400,
                chain: Some(0x0416),
            }],
            slot: 0,
        }];
        let unhooked = listing(&everyone, (&[(HookKind::Unknown, vec![0xFF21])], &[]), &[]);
        assert!(
            unhooked.contains(
                "HOOK_UNKNOWN -> $0400 (chain slot $0416) (not hooked: HOOK_UNKNOWN does not lead to it)"
            ),
            "{unhooked}"
        );
        let hooked = listing(
            &everyone,
            (&[(HookKind::Unknown, vec![0x0400, 0xFF21])], &[]),
            &[],
        );
        assert!(!hooked.contains("not hooked"), "{hooked}");
        // recheck26 N4: a chain that ends in code no entry lists may lead
        // on to it.
        let open = listing(
            &everyone,
            (&[(HookKind::Unknown, vec![0x0600])], &[HookKind::Unknown]),
            &[],
        );
        assert!(
            open.contains("(not on HOOK_UNKNOWN's chain as the table follows it: that goes on through code no entry lists, which may lead here)"),
            "{open}"
        );
    }

    /// recheck17 F4: a chain slot sent to its own handler by hand was
    /// listed as `$040B -> $040B -> $040B` with no word of the loop.
    #[test]
    fn a_chain_that_comes_back_is_cut_and_said() {
        let looped = listing(
            &[],
            (&[(HookKind::Unknown, vec![0x040B, 0x040B, 0x040B])], &[]),
            &[],
        );
        assert_eq!(
            looped,
            "nothing installed\nHOOK_UNKNOWN: $040B -> $040B (comes back to where it has been: a loop the robot would run for ever at its next command)\n"
        );
    }
}
