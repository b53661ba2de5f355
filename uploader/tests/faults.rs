//! Issue 6's faults, through the fault-injecting transport over the
//! virtual Scorpion, on both paths (the ROM's commands and the RAM loader
//! at 19200 baud): 1% of bytes dropped, corrupted or duplicated; a reset
//! in the middle (a `/1R`, and the reset button, with and without RAM
//! lost); a stalled line, short and for good; a write gone astray onto a
//! hook (what a `/9W` whose address digits noise changed does). Every case
//! either ends verified or fails with a clear error, and in every case the
//! emulated RAM shows no hook pointing at code that did not verify.

mod common;

use std::time::Duration;

use common::{
    assert_at_9600, assert_done, assert_safe, extension, one_byte_changed, options, robot, run,
    target,
};
use romlib::symbols::{BAD_COMMAND, HOOK_UNKNOWN};
use uploader::transport::{FaultConfig, FaultyTransport, VirtualTransport};
use uploader::{Error, LoaderChoice, NoProgress, UploadOptions};

const PATHS: [LoaderChoice; 2] = [LoaderChoice::Never, LoaderChoice::Always];

fn faulty(
    transport: VirtualTransport,
    config: FaultConfig,
    image: &uploader::UploadImage,
    path: LoaderChoice,
) -> (
    uploader::Result<uploader::UploadReport>,
    FaultyTransport<VirtualTransport>,
) {
    run(
        FaultyTransport::new(transport, config),
        image,
        &options(path),
    )
}

#[test]
fn one_percent_noise_ends_verified() {
    let image = extension(1024, 11);
    type MakeFaults = fn(u64) -> FaultConfig;
    let kinds: [(&str, MakeFaults); 4] = [
        ("drop", |seed| FaultConfig::noise(seed, 0.01, 0.0, 0.0)),
        ("corrupt", |seed| FaultConfig::noise(seed, 0.0, 0.01, 0.0)),
        ("duplicate", |seed| FaultConfig::noise(seed, 0.0, 0.0, 0.01)),
        ("all three", |seed| {
            FaultConfig::noise(seed, 0.01 / 3.0, 0.01 / 3.0, 0.01 / 3.0)
        }),
    ];
    for path in PATHS {
        for (name, make) in kinds {
            for seed in 0..5 {
                let (result, faulty) = faulty(robot(), make(seed), &image, path);
                let stats = faulty.stats();
                let outcome = format!("{path:?}, {name}, seed {seed}: {stats:?} {result:?}");
                assert!(
                    stats.dropped + stats.corrupted + stats.duplicated > 0,
                    "{outcome}"
                );
                let report = result.unwrap_or_else(|error| panic!("{outcome}: {error}"));
                assert!(report.final_passes >= 1, "{outcome}");
                assert_done(faulty.into_inner(), &image, &outcome);
            }
        }
    }
}

#[test]
fn a_reset_command_in_the_middle_ends_verified() {
    let image = extension(1024, 12);
    for path in PATHS {
        // Host characters: about 5900 through the ROM, 1900 with the loader.
        let offsets: &[usize] = match path {
            LoaderChoice::Never => &[100, 2000, 4000, 5500],
            _ => &[30, 120, 500, 1200, 1800],
        };
        for &at in offsets {
            let config = FaultConfig {
                reset_after: Some(at),
                ..FaultConfig::none(7)
            };
            let (result, faulty) = faulty(robot(), config, &image, path);
            let outcome = format!("{path:?}, /1R after {at}: {result:?}");
            assert_eq!(faulty.stats().resets, 1, "{outcome}");
            result.unwrap_or_else(|error| panic!("{outcome}: {error}"));
            assert_done(faulty.into_inner(), &image, &outcome);
        }
    }
}

#[test]
fn the_reset_button_in_the_middle_ends_verified_or_fails_safely() {
    let image = extension(1024, 13);
    for path in PATHS {
        let times: &[u64] = match path {
            LoaderChoice::Never => &[20, 1500, 4000, 6200],
            _ => &[20, 100, 300, 800, 1300],
        };
        for &ms in times {
            for lose_ram in [false, true] {
                let mut transport = robot();
                transport.at(Duration::from_millis(ms), move |robot| {
                    if lose_ram {
                        let garbage: Vec<u8> =
                            (0..0x0C00u32).map(|i| (i * 97 + 13) as u8).collect();
                        robot
                            .robot_mut()
                            .board_mut()
                            .load(0x0400, &garbage)
                            .expect("user RAM");
                    }
                    robot.robot_mut().power_on();
                });
                let (result, transport) = run(transport, &image, &options(path));
                let outcome =
                    format!("{path:?}, reset at {ms} ms, RAM lost {lose_ram}: {result:?}");
                assert_safe(transport.robot(), &image, &outcome);
                result.unwrap_or_else(|error| panic!("{outcome}: {error}"));
                assert_done(transport, &image, &outcome);
            }
        }
    }
}

#[test]
fn a_short_stall_recovers() {
    let image = extension(1024, 14);
    for path in PATHS {
        // In the middle of the image's frames (through the loader, after
        // the ROM's sums: a stall there loses answers, asked again, and
        // needs no round of sums after the writes).
        let config = FaultConfig {
            stall_after: Some(if path == LoaderChoice::Never {
                3000
            } else {
                1100
            }),
            stall_for: Some(Duration::from_millis(1500)),
            ..FaultConfig::none(9)
        };
        let (result, faulty) = faulty(robot(), config, &image, path);
        let outcome = format!("{path:?}: {result:?}");
        assert!(faulty.stats().stalled > 0, "{outcome}");
        let report = result.unwrap_or_else(|error| panic!("{outcome}: {error}"));
        assert!(report.final_passes >= 1, "{outcome}");
        assert_done(faulty.into_inner(), &image, &outcome);
    }
}

#[test]
fn a_dead_line_fails_clearly_and_the_next_upload_succeeds() {
    let image = extension(1024, 15);
    for path in PATHS {
        // Host characters: about 5900 through the ROM, 2000 with the loader.
        let offsets: &[usize] = match path {
            LoaderChoice::Never => &[60, 900, 3000],
            _ => &[60, 400, 1200],
        };
        for &at in offsets {
            let config = FaultConfig {
                stall_after: Some(at),
                stall_for: None,
                ..FaultConfig::none(9)
            };
            let (result, faulty) = faulty(robot(), config, &image, path);
            let outcome = format!("{path:?}, dead after {at}: {result:?}");
            let error = result.expect_err("a dead line");
            assert!(
                matches!(error, Error::Stalled { .. } | Error::NoAnswer { .. }),
                "{outcome}"
            );
            let message = error.to_string();
            assert!(
                message.contains("stalled") || message.contains("no answer"),
                "{message}"
            );
            let transport = faulty.into_inner();
            assert_safe(transport.robot(), &image, &outcome);
            // The line comes back: the robot may still be at 19200 with the
            // loader in; the next upload finds it and finishes the job.
            let (result, transport) = run(transport, &image, &options(path));
            result.unwrap_or_else(|error| panic!("{outcome}, then: {error}"));
            assert_done(transport, &image, &outcome);
        }
    }
}

#[test]
fn a_write_gone_astray_onto_a_hook_is_put_right() {
    // Noise on a `/9W`'s address digits (`/9W0201...` with a `0` doubled
    // writes `$0200`) can land a write on a hook. The upload reads both
    // hooks back whole, opcodes included, and repairs them: here `$1C` on
    // HOOK_UNKNOWN's opcode (an NMOS NOP that falls into HOOK_LOOP, so the
    // loader's frames stop landing) and, through the ROM's commands (no
    // unknown command goes through the hook before the end), a changed
    // operand.
    let image = extension(1024, 16);
    for path in PATHS {
        let (times, hits): (&[u64], &[(u16, u8)]) = match path {
            LoaderChoice::Never => (&[500, 3000, 6000], &[(0x0200, 0x1C), (0x0202, 0x12)]),
            _ => (&[150, 400, 900], &[(0x0200, 0x1C)]),
        };
        for &ms in times {
            for &(at, value) in hits {
                let mut transport = robot();
                transport.at(Duration::from_millis(ms), move |robot| {
                    robot
                        .robot_mut()
                        .board_mut()
                        .load(at, &[value])
                        .expect("the hooks are RAM");
                });
                let (result, transport) = run(transport, &image, &options(path));
                let outcome =
                    format!("{path:?}, ${value:02X} at ${at:04X} after {ms} ms: {result:?}");
                result.unwrap_or_else(|error| panic!("{outcome}: {error}"));
                assert_done(transport, &image, &outcome);
            }
        }
        // HOOK_LOOP's `JMP` gone: the ROM's own loop runs into it at once
        // and stops. Nothing can put that right over the line; the upload
        // fails and says so.
        let mut transport = robot();
        transport.at(Duration::from_millis(times[1]), |robot| {
            robot
                .robot_mut()
                .board_mut()
                .load(0x0203, &[0x02])
                .expect("the hooks are RAM");
        });
        let (result, _) = run(transport, &image, &options(path));
        let error = result.expect_err("a robot that stopped");
        assert!(
            matches!(
                error,
                Error::RobotJammed { .. } | Error::Stalled { .. } | Error::NoAnswer { .. }
            ),
            "{path:?}: {error:?}"
        );
    }
}

/// A KIM-bus RAM card with one cell that holds `stuck` whatever is written
/// to it (a failed chip): it counts the writes that cell takes.
#[derive(Debug)]
struct CardWithABadCell {
    bytes: Vec<u8>,
    bad: u16,
    stuck: u8,
    writes_to_bad: u32,
}

impl emulator::board::Device for CardWithABadCell {
    fn read(&mut self, offset: u16, _cycle: u64) -> u8 {
        self.peek(offset)
    }
    fn write(&mut self, offset: u16, value: u8, _cycle: u64) {
        if offset == self.bad {
            self.writes_to_bad += 1;
        } else {
            self.bytes[usize::from(offset)] = value;
        }
    }
    fn peek(&self, offset: u16) -> u8 {
        if offset == self.bad {
            self.stuck
        } else {
            self.bytes[usize::from(offset)]
        }
    }
    fn as_any(&self) -> &dyn std::any::Any {
        self
    }
    fn as_any_mut(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

#[test]
fn a_byte_that_will_not_hold_fails_naming_it_and_hooks_nothing() {
    // The extension at $0400 hooks HOOK_UNKNOWN; its table at $2000 lies on
    // a card whose cell $2037 reads $5A whatever is written. The upload
    // rewrites that byte a bounded number of times, then fails naming the
    // address, the byte it wanted and the byte it found; the hook stays on
    // the ROM and the RAM loader, when it carried the body, is taken out.
    let extension = extension(512, 21);
    let table: Vec<u8> = (0..64u8).map(|i| i.wrapping_mul(3)).collect();
    let image = uploader::UploadImage::new(
        vec![
            extension.areas()[0].clone(),
            uploader::Area {
                address: 0x2000,
                bytes: table.clone(),
            },
        ],
        extension.hooks().to_vec(),
    )
    .expect("a valid image");
    for path in PATHS {
        let mut transport = robot();
        let slot = transport
            .robot_mut()
            .robot_mut()
            .board_mut()
            .map_kim(
                0x2000,
                0x20FF,
                Box::new(CardWithABadCell {
                    bytes: vec![0; 256],
                    bad: 0x37,
                    stuck: 0x5A,
                    writes_to_bad: 0,
                }),
            )
            .expect("free KIM-bus space");
        let options = options(path);
        let (result, transport) = run(transport, &image, &options);
        let outcome = format!("{path:?}: {result:?}");
        let error = result.expect_err("a byte that never verifies");
        let Error::VerifyFailed {
            address,
            expected,
            found,
            attempts,
        } = error
        else {
            panic!("not a verification failure ({outcome})");
        };
        assert_eq!(
            (address, expected, found),
            (0x2037, table[0x37], 0x5A),
            "{outcome}"
        );
        assert!(
            (1..=options.max_writes).contains(&attempts),
            "{attempts} writes ({outcome})"
        );
        let message = error.to_string();
        for part in ["$2037", &format!("${:02X}", table[0x37]), "$5A"] {
            assert!(message.contains(part), "`{part}` missing from: {message}");
        }
        let card: &CardWithABadCell = transport
            .robot()
            .robot()
            .board()
            .kim_device(slot)
            .expect("the card");
        assert!(
            (1..=options.max_writes).contains(&card.writes_to_bad),
            "the bad cell took {} writes ({outcome})",
            card.writes_to_bad
        );
        assert_eq!(
            card.bytes[..0x37],
            table[..0x37],
            "the rest of the table verified ({outcome})"
        );
        let memory = transport.robot().robot().board().memory();
        assert_eq!(
            target(memory, HOOK_UNKNOWN),
            (0x4C, BAD_COMMAND),
            "HOOK_UNKNOWN left on the ROM ({outcome})"
        );
        assert_safe(transport.robot(), &image, &outcome);
        // The loader, if it ran, is gone: the robot answers at 9600 again.
        assert_at_9600(transport, &outcome);
    }
}

/// Issue 27: a reset (`/1R`) or lost bytes in the middle of a patch (a
/// one-byte change to an installed extension, a delta upload) leave no
/// hook pointing at code that did not verify, and the next try finishes.
#[test]
fn a_reset_or_noise_in_the_middle_of_a_patch_leaves_no_hook_on_unverified_code() {
    let image = extension(1024, 17);
    let patched = one_byte_changed(&image, 700);
    let options = UploadOptions {
        loader: LoaderChoice::Always,
        replace: true,
        ..UploadOptions::default()
    };
    let faults: Vec<(String, FaultConfig)> = [40usize, 150, 300, 450, 600, 750]
        .into_iter()
        .map(|at| {
            (
                format!("/1R after {at}"),
                FaultConfig {
                    reset_after: Some(at),
                    ..FaultConfig::none(21)
                },
            )
        })
        .chain((0..3).map(|seed| {
            (
                format!("1% lost, seed {seed}"),
                FaultConfig::noise(seed, 0.01, 0.0, 0.0),
            )
        }))
        .collect();
    for (name, config) in faults {
        let (installed, transport) = run(robot(), &image, &options);
        installed.unwrap_or_else(|error| panic!("{name}: the first upload: {error}"));
        let (result, faulty) = run(FaultyTransport::new(transport, config), &patched, &options);
        let outcome = format!("{name}: {result:?}");
        let transport = faulty.into_inner();
        assert_safe(transport.robot(), &patched, &outcome);
        let (again, transport) = run(transport, &patched, &options);
        again.unwrap_or_else(|error| panic!("{outcome}, then: {error}"));
        assert_done(transport, &patched, &outcome);
    }
}

/// Issue 27: a reset or lost bytes in the middle of a restore leave every
/// hook at the ROM, at the verified loader, or at the backup's handler
/// with the backup's memory in place; a restore after it puts everything
/// back.
#[test]
fn a_reset_or_noise_in_the_middle_of_a_restore_leaves_no_hook_on_unverified_code() {
    let image = extension(1024, 18);
    let options = UploadOptions::default();
    let faults: Vec<(String, FaultConfig)> = [40usize, 300, 800, 1500, 2500]
        .into_iter()
        .map(|at| {
            (
                format!("/1R after {at}"),
                FaultConfig {
                    reset_after: Some(at),
                    ..FaultConfig::none(22)
                },
            )
        })
        .chain((0..2).map(|seed| {
            (
                format!("1% lost, seed {seed}"),
                FaultConfig::noise(seed, 0.01, 0.0, 0.0),
            )
        }))
        .collect();
    for (name, config) in faults {
        let (installed, transport) = run(robot(), &image, &options);
        installed.expect("installed");
        let mut client = uploader::client(transport, &options.profile);
        let saved = uploader::backup(&mut client, &options.profile).expect("a backup");
        let mut transport = client.into_transport();
        // Hostile: the extension's code overwritten.
        transport
            .robot_mut()
            .robot_mut()
            .board_mut()
            .load(0x0400, &[0xA5; 0x200])
            .expect("RAM");
        let mut client =
            uploader::client(FaultyTransport::new(transport, config), &options.profile);
        let result = uploader::restore(&mut client, &saved, &options, &mut NoProgress);
        let outcome = format!("{name}: {result:?}");
        let transport = client.into_transport().into_inner();
        assert_safe(transport.robot(), &image, &outcome);
        let mut client = uploader::client(transport, &options.profile);
        if result.is_ok() {
            listed_if_hooked(&mut client, &image, &outcome);
        }
        uploader::restore(&mut client, &saved, &options, &mut NoProgress)
            .unwrap_or_else(|error| panic!("{outcome}, then: {error}"));
        assert_done(client.into_transport(), &image, &outcome);
    }
}

/// hostile19 F5: a reset while a restore's memory went in cleared the
/// table it had written, and the restore hooked the extension all the
/// same, "verified": the table listed nothing. Wherever the reset falls,
/// a restore that says it finished leaves the hooked extension listed.
#[test]
fn a_reset_anywhere_in_a_restore_that_finishes_leaves_the_table_listing_what_is_hooked() {
    let image = extension(256, 31);
    let options = UploadOptions {
        loader: LoaderChoice::Never,
        ..UploadOptions::default()
    };
    let (installed, transport) = run(robot(), &image, &options);
    installed.expect("installed");
    let mut client = uploader::client(transport, &options.profile);
    let saved = uploader::backup(&mut client, &options.profile).expect("a backup");
    let sent = {
        let mut client = uploader::client(robot(), &options.profile);
        uploader::restore(&mut client, &saved, &options, &mut NoProgress).expect("restored");
        client.stats().sent
    };
    let mut finished = 0;
    // Every 97th byte, and every 7th of the end, where the hooks go in.
    let end = sent.saturating_sub(700);
    let points = (0..end)
        .step_by(common::fault_step(97))
        .chain((end..sent).step_by(common::fault_step(7)));
    for at in points {
        let mut client = uploader::client(
            FaultyTransport::new(
                robot(),
                FaultConfig {
                    reset_after: Some(at),
                    ..FaultConfig::none(5)
                },
            ),
            &options.profile,
        );
        let result = uploader::restore(&mut client, &saved, &options, &mut NoProgress);
        let outcome = format!("/1R after {at} of {sent}: {result:?}");
        let transport = client.into_transport().into_inner();
        assert_safe(transport.robot(), &image, &outcome);
        if result.is_ok() {
            finished += 1;
            let mut client = uploader::client(transport, &options.profile);
            listed_if_hooked(&mut client, &image, &outcome);
            // hostile20 F5: and hooked as the file says, not left at the
            // ROM by a reset as the hooks went in.
            let memory = client.transport().robot().robot().board().memory();
            let (_, hook) = common::target(memory, HOOK_UNKNOWN);
            assert!(
                image.hooks().iter().any(|record| record.handler == hook),
                "finished, but HOOK_UNKNOWN -> ${hook:04X} ({outcome})"
            );
        }
    }
    assert!(finished > 0, "no restore finished");
}

/// Whether HOOK_UNKNOWN leads to `image`'s handler, and if so, that the
/// robot's table lists it.
fn listed_if_hooked(
    client: &mut uploader::Client<uploader::transport::VirtualTransport>,
    image: &uploader::UploadImage,
    outcome: &str,
) {
    let memory = client.transport().robot().robot().board().memory();
    let (_, hook) = common::target(memory, HOOK_UNKNOWN);
    if image.hooks().iter().any(|record| record.handler == hook) {
        let listed = uploader::read_installed(client, &uploader::RomProfile::reference())
            .expect("the table");
        assert!(
            listed.iter().any(|entry| entry.id == image.id()),
            "hooked but not listed ({outcome}): {listed:?}"
        );
    }
}
