//! An image uploaded again while an earlier copy of it sits behind another
//! extension in a chain (hostile14 F6b). The upload took it out of the
//! chain and hooked it at the head: a project of two images swapped their
//! order at every `test --port`, so no second run was ever "unchanged",
//! and its undo went back one run only. The copy now goes back where it
//! was, once verified, and such an upload that changed nothing says so.

mod common;

use common::{Kept, extension_at, robot};
use isa::objfmt::HookKind;
use romlib::symbols::{BAD_COMMAND, HOOK_UNKNOWN};
use uploader::transport::{FaultConfig, FaultyTransport, Transport, VirtualTransport};
use uploader::{Client, LoaderChoice, NoProgress, UploadOptions, upload, upload_keeping};

fn word(memory: &[u8], at: u16) -> u16 {
    u16::from_le_bytes([memory[usize::from(at)], memory[usize::from(at) + 1]])
}

/// The handlers HOOK_UNKNOWN reaches, in order, each extension's bytes
/// checked as it is reached (its handler `JMP base`, then `JMP slot`):
/// no handler is reached whose code is not as uploaded.
fn chain(memory: &[u8]) -> Vec<u16> {
    let mut at = word(memory, HOOK_UNKNOWN + 1);
    let mut reached = Vec::new();
    while at != BAD_COMMAND {
        let base = at - 3;
        assert!(
            [0x0403, 0x0703, 0x0A03].contains(&at)
                && memory[usize::from(at)..][..3] == [0x4C, base as u8, (base >> 8) as u8],
            "HOOK_UNKNOWN's chain reaches ${at:04X}, which is no verified handler: {reached:04X?}"
        );
        assert!(reached.len() < 4, "a loop: {reached:04X?}");
        reached.push(at);
        at = word(memory, base + 1);
    }
    reached
}

fn options(loader: LoaderChoice) -> UploadOptions {
    UploadOptions {
        loader,
        ..UploadOptions::default()
    }
}

/// A robot with the extension at $0400 installed, then the one at $0700
/// in front of it.
fn two_installed<T: Transport>(client: &mut Client<T>, options: &UploadOptions) {
    for base in [0x0400, 0x0700] {
        upload(client, &extension_at(base), options, &mut NoProgress).expect("installed");
    }
}

#[test]
fn a_copy_behind_another_goes_back_where_it_was_and_nothing_changed() {
    for path in [LoaderChoice::Never, LoaderChoice::Always] {
        let options = options(path);
        let mut client = uploader::client(robot(), &options.profile);
        two_installed(&mut client, &options);
        let memory = client.transport().robot().robot().board().memory();
        assert_eq!(chain(memory), [0x0703, 0x0403], "{path:?}");
        let mut kept = Kept::default();
        let report = upload_keeping(
            &mut client,
            &extension_at(0x0400),
            &options,
            &mut NoProgress,
            &mut kept,
        )
        .expect("uploaded again");
        let memory = client.transport().robot().robot().board().memory();
        assert_eq!(chain(memory), [0x0703, 0x0403], "{path:?}: the order kept");
        assert_eq!(report.relinked, [(HookKind::Unknown, 0x0701)], "{path:?}");
        assert!(report.unchanged, "{path:?}: {report:?}");
        assert!(kept.1, "{path:?}: the older undo file is kept");
        // The one at the head, again: unchanged too.
        let report = upload(
            &mut client,
            &extension_at(0x0700),
            &options,
            &mut NoProgress,
        )
        .expect("uploaded again");
        assert_eq!(report.relinked, [], "{path:?}");
        let memory = client.transport().robot().robot().board().memory();
        assert_eq!(chain(memory), [0x0703, 0x0403], "{path:?}");
    }
}

/// A reset (`/1R`) or lost bytes anywhere in that upload: no hook or chain
/// slot leads to code that did not verify, and the upload ends verified
/// with the image reachable, or fails clearly; one more upload puts it in
/// a chain.
#[test]
fn a_reset_or_noise_while_a_copy_goes_back_leaves_no_way_to_unverified_code() {
    for path in [LoaderChoice::Never, LoaderChoice::Always] {
        let options = options(path);
        let offsets: &[usize] = match path {
            LoaderChoice::Never => &[20, 200, 600, 1000, 1400],
            _ => &[20, 150, 400, 700, 1000],
        };
        let faults = offsets
            .iter()
            .map(|&at| {
                (
                    format!("/1R after {at}"),
                    FaultConfig {
                        reset_after: Some(at),
                        ..FaultConfig::none(5)
                    },
                )
            })
            .chain((0..3).map(|seed| {
                (
                    format!("1% lost, seed {seed}"),
                    FaultConfig::noise(seed, 0.01, 0.0, 0.0),
                )
            }));
        for (name, config) in faults {
            let mut client = uploader::client(robot(), &options.profile);
            two_installed(&mut client, &options);
            let transport = client.into_transport();
            let mut client =
                uploader::client(FaultyTransport::new(transport, config), &options.profile);
            let result = upload(
                &mut client,
                &extension_at(0x0400),
                &options,
                &mut NoProgress,
            );
            let outcome = format!("{path:?}, {name}: {result:?}");
            let transport: VirtualTransport = client.into_transport().into_inner();
            let reached = chain(transport.robot().robot().board().memory());
            if result.is_ok() {
                assert!(reached.contains(&0x0403), "{outcome}: {reached:04X?}");
            }
            // A `/1R` cleared the table: the extension in front is code no
            // entry names now, which the RAM loader must not go near.
            let mut client = uploader::client(transport, &options.profile);
            let again = UploadOptions::default();
            upload(&mut client, &extension_at(0x0400), &again, &mut NoProgress)
                .unwrap_or_else(|error| panic!("{outcome}, then: {error}"));
            let reached = chain(client.transport().robot().robot().board().memory());
            assert!(reached.contains(&0x0403), "{outcome}: {reached:04X?}");
        }
    }
}

/// recheck17 F1: an edit of an extension behind another, uploaded with
/// `--replace`, went to the head of the chain, and then answered a command
/// both handle in place of the one in front. It takes the place of the
/// one it replaces; the one at the head, edited, stays at the head.
#[test]
fn a_replacement_takes_the_place_of_the_extension_it_replaces() {
    for path in [LoaderChoice::Never, LoaderChoice::Always] {
        let options = UploadOptions {
            replace: true,
            ..options(path)
        };
        let mut client = uploader::client(robot(), &options.profile);
        two_installed(&mut client, &options);
        let behind = common::one_byte_changed(&extension_at(0x0400), 40);
        let report = upload(&mut client, &behind, &options, &mut NoProgress).expect("replaced");
        assert_eq!(report.replaced.len(), 1, "{path:?}");
        assert_eq!(report.relinked, [(HookKind::Unknown, 0x0701)], "{path:?}");
        let memory = client.transport().robot().robot().board().memory();
        assert_eq!(chain(memory), [0x0703, 0x0403], "{path:?}: its place kept");
        assert_eq!(memory[0x0400 + 40], behind.areas()[0].bytes[40], "{path:?}");
        let front = common::one_byte_changed(&extension_at(0x0700), 40);
        let report = upload(&mut client, &front, &options, &mut NoProgress).expect("replaced");
        assert_eq!(report.relinked, [], "{path:?}");
        let memory = client.transport().robot().robot().board().memory();
        assert_eq!(
            chain(memory),
            [0x0703, 0x0403],
            "{path:?}: the head stays the head"
        );
    }
}

/// recheck20 F2: a `/1R` while an edit of the extension behind another
/// went in with `--replace`. The reset freed every entry, and the upload
/// then chained the edit to the one in front as it had found the hook: it
/// ended "verified" with the one in front hooked, which no entry listed.
/// Wherever the reset falls, an upload that finishes leaves every handler
/// its hook reaches listed in the robot's table. hostile21 F10: the same
/// with an edit of the one in front, the reset between the upload's read
/// of the hooks and its read of the table (in its first bytes): the hook
/// was pointed past the old one at the one behind, then no longer listed,
/// and the edit chained to it.
#[test]
fn a_reset_anywhere_in_a_replacement_behind_another_leaves_nothing_hooked_unlisted() {
    // The extension behind, the one in front, and (recheck21 F1) the middle
    // one of three.
    let cases = [LoaderChoice::Never, LoaderChoice::Always]
        .into_iter()
        .flat_map(|path| [(path, 0x0400, 2), (path, 0x0700, 2), (path, 0x0700, 3)]);
    for (path, base, installed) in cases {
        let set_up = |client: &mut uploader::Client<VirtualTransport>, options: &UploadOptions| {
            for base in [0x0400, 0x0700, 0x0A00].into_iter().take(installed) {
                upload(client, &extension_at(base), options, &mut NoProgress).expect("installed");
            }
        };
        let options = UploadOptions {
            replace: true,
            ..options(path)
        };
        let behind = common::one_byte_changed(&extension_at(base), 40);
        let sent = {
            let mut client = uploader::client(robot(), &options.profile);
            set_up(&mut client, &options);
            let before = client.stats().sent;
            upload(&mut client, &behind, &options, &mut NoProgress).expect("replaced");
            client.stats().sent - before
        };
        let mut finished = 0;
        // Every byte of the first 80 (where the hooks and the table are
        // read), then every 41st.
        let points = (0..80).chain((80..sent).step_by(common::fault_step(41)));
        for at in points {
            let mut client = uploader::client(robot(), &options.profile);
            set_up(&mut client, &options);
            let transport = client.into_transport();
            let config = FaultConfig {
                reset_after: Some(at),
                ..FaultConfig::none(5)
            };
            let mut client =
                uploader::client(FaultyTransport::new(transport, config), &options.profile);
            let result = upload(&mut client, &behind, &options, &mut NoProgress);
            let outcome = format!(
                "{path:?}, ${base:04X} of {installed}, /1R after {at} of {sent}: {result:?}"
            );
            let transport: VirtualTransport = client.into_transport().into_inner();
            let reached = chain(transport.robot().robot().board().memory());
            let mut client = uploader::client(transport, &options.profile);
            let listed = uploader::read_installed(&mut client, &options.profile)
                .unwrap_or_else(|error| panic!("{outcome}: the table: {error}"));
            // recheck21 F1: a reset as the upload began is said as one,
            // not as a loop the chain slots left in RAM seemed to make.
            assert!(
                !matches!(result, Err(uploader::Error::ChainComesBack { .. })),
                "{outcome}"
            );
            if let Ok(report) = &result {
                finished += 1;
                for handler in &reached {
                    assert!(
                        listed
                            .iter()
                            .any(|entry| entry.hooks.iter().any(|hook| hook.handler == *handler)),
                        "{outcome}: ${handler:04X} is hooked, the table lists {listed:?}"
                    );
                }
                assert!(reached.contains(&(base + 3)), "{outcome}: {reached:04X?}");
                // What the reset took out is said, if the table was read
                // before it (else the upload found a robot just reset).
                let others = [0x0403, 0x0703, 0x0A03]
                    .into_iter()
                    .take(installed)
                    .filter(|&handler| handler != base + 3);
                let read_before = !report.replaced.is_empty();
                let lost = others.filter(|handler| !reached.contains(handler)).count();
                assert_eq!(
                    report.reset_freed.len(),
                    if read_before { lost } else { 0 },
                    "{outcome}: {reached:04X?}"
                );
            }
        }
        assert!(finished > 0, "{path:?}: no upload finished");
    }
}
