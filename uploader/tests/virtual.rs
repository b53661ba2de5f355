//! Uploads into the virtual Scorpion (the reference ROM on the emulated
//! board, at real baud timing): through the ROM's commands and through
//! the RAM loader, hooks last, pipelining bounded by the ROM's real
//! receive buffer, chaining, and the images and lines it must refuse.

mod common;

use std::time::Duration;

use common::{assert_done, extension, options, robot, run};
use isa::objfmt::{HookKind, HookRecord};
use romlib::VirtualScorpion;
use romlib::protocol::Answer;
use romlib::symbols::{BAD_COMMAND, HOOK_UNKNOWN};
use uploader::transport::{FaultConfig, FaultyTransport, Transport, VirtualTransport, char_time};
use uploader::{
    Area, Client, ClientConfig, Error, Expectations, InstalledHook, LoaderChoice,
    REFERENCE_RX_BUFFER, Required, RomProfile, UploadImage, UploadOptions,
};

/// Records what the host sends, to check the order of the writes.
struct Recorder<T> {
    inner: T,
    sent: Vec<u8>,
}

impl<T: Transport> Transport for Recorder<T> {
    fn send(&mut self, bytes: &[u8]) -> uploader::Result<()> {
        self.sent.extend_from_slice(bytes);
        self.inner.send(bytes)
    }
    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> uploader::Result<usize> {
        self.inner.receive(into, timeout)
    }
    fn baud(&self) -> u32 {
        self.inner.baud()
    }
    fn set_baud(&mut self, baud: u32) -> uploader::Result<()> {
        self.inner.set_baud(baud)
    }
    fn now(&self) -> Duration {
        self.inner.now()
    }
    fn clear_input(&mut self) -> uploader::Result<()> {
        self.inner.clear_input()
    }
    fn name(&self) -> String {
        self.inner.name()
    }
}

/// Where in the host's stream the hook's operand is written.
fn hook_writes(sent: &[u8]) -> Vec<usize> {
    let needle = format!("/9W{:04X}", HOOK_UNKNOWN + 1);
    sent.windows(needle.len())
        .enumerate()
        .filter(|(_, window)| *window == needle.as_bytes())
        .map(|(at, _)| at)
        .collect()
}

#[test]
fn rom_only_upload_verifies_and_hooks_last() {
    let image = extension(2048, 1);
    let recorder = Recorder {
        inner: robot(),
        sent: Vec::new(),
    };
    let (result, recorder) = run(recorder, &image, &options(LoaderChoice::Never));
    let report = result.expect("a clean upload succeeds");
    assert_eq!(report.bytes, 2048);
    assert_eq!((report.final_passes, report.rewrites), (0, 0));
    assert_eq!(report.loader, None);
    assert_eq!(
        report.hooks,
        vec![InstalledHook {
            kind: HookKind::Unknown,
            handler: 0x0403,
            previous: BAD_COMMAND,
            chain: Some(0x0401),
        }]
    );
    // The hook is written once, after every write to the body.
    let sent = &recorder.sent;
    let hooks = hook_writes(sent);
    assert_eq!(hooks.len(), 1);
    let last_body = sent
        .windows(5)
        .rposition(|w| w == b"/9W04" || w == b"/9W05" || w == b"/9W0B")
        .expect("body writes");
    assert!(hooks[0] > last_body);
    // Within 1.1x of the ROM-only bound: 11 characters per 2 bytes.
    let bound = char_time(2048 / 2 * 11, 9600);
    let ratio = report.device_time.as_secs_f64() / bound.as_secs_f64();
    assert!(
        ratio < 1.1,
        "{:?} is {ratio:.3}x {bound:?}",
        report.device_time
    );
    assert_done(recorder.inner, &image, "ROM only");
}

#[test]
fn the_loader_carries_the_body_at_19200_and_leaves() {
    let image = extension(2048, 2);
    let recorder = Recorder {
        inner: robot(),
        sent: Vec::new(),
    };
    let (result, recorder) = run(recorder, &image, &options(LoaderChoice::Always));
    let report = result.expect("the upload succeeds");
    let loader = report.loader.expect("the loader ran");
    assert_eq!(loader.baud, 19200);
    assert_eq!(loader.recoveries, 0);
    assert_eq!((report.final_passes, report.rewrites), (0, 0));
    assert_eq!(report.hooks[0].previous, BAD_COMMAND);
    // Frames, not /9W, carried the body: far fewer characters than 5.5 a
    // byte, and the image's hook was switched once, last.
    assert!(report.chars_sent < 2048 * 2, "{report:?}");
    let hooks = hook_writes(&recorder.sent);
    let last_frame = recorder
        .sent
        .windows(3)
        .rposition(|w| w == b"/1L")
        .expect("frames");
    let handler = format!("/9W{:04X}0304", HOOK_UNKNOWN + 1);
    let switch = recorder
        .sent
        .windows(handler.len())
        .position(|w| w == handler.as_bytes())
        .expect("the image's hook");
    assert!(switch > last_frame && hooks.last() == Some(&switch));
    // Faster than the ROM's commands could be at any rate.
    let rom_bound = char_time(2048 / 2 * 11, 9600);
    assert!(report.device_time < rom_bound / 3, "{report:?}");
    assert_done(recorder.inner, &image, "loader");
}

#[test]
fn the_loader_alone_at_9600() {
    let image = extension(1500, 3);
    let options = UploadOptions {
        fast_baud: None,
        ..options(LoaderChoice::Always)
    };
    let (result, transport) = run(robot(), &image, &options);
    let report = result.expect("the upload succeeds");
    assert_eq!(report.loader.expect("the loader ran").baud, 9600);
    assert_done(transport, &image, "loader at 9600");
}

#[test]
fn auto_takes_the_loader_only_where_it_pays() {
    let small = extension(64, 4);
    let (result, transport) = run(robot(), &small, &options(LoaderChoice::Auto));
    assert_eq!(result.expect("uploads").loader, None);
    assert_done(transport, &small, "small");
    let large = extension(1024, 5);
    let (result, transport) = run(robot(), &large, &options(LoaderChoice::Auto));
    assert!(result.expect("uploads").loader.is_some());
    assert_done(transport, &large, "large");
}

/// The ROM's receive ring holds 255 characters: two 99-byte questions keep
/// it answering for 400 character times, while the host sends `/9W`s
/// behind them. Up to the ring's size, every write lands.
#[test]
fn the_reference_rom_buffers_255_characters() {
    for (writes, all_land) in [(REFERENCE_RX_BUFFER / 11, true), (30, false)] {
        let mut robot = VirtualScorpion::new();
        let mut stream = b"/7R000099/7R000099".to_vec();
        for i in 0..writes {
            stream.extend_from_slice(format!("/9W{:04X}A55A", 0x2000 + 2 * i).as_bytes());
        }
        robot.send(&stream);
        robot.run_for(1_000_000).expect("the CPU runs");
        let memory = robot.robot().board().memory();
        let landed = (0..writes)
            .filter(|i| memory[0x2000 + 2 * i..0x2002 + 2 * i] == [0xA5, 0x5A])
            .count();
        if all_land {
            assert_eq!(landed, writes, "{} characters fit", writes * 11);
        } else {
            assert!(landed < writes, "{} characters cannot all fit", writes * 11);
        }
    }
    assert_eq!(RomProfile::reference().window(), REFERENCE_RX_BUFFER - 16);
}

/// A window past the receive ring (4000 characters ahead of an answer)
/// still ends verified. With frames checked by sums (issue 27) it loses
/// nothing: the loader takes a frame's bytes as they arrive and a sum's
/// answer is ten characters, where `/7R` answers of two characters a byte
/// used to hold the ROM while frames piled up in the ring (rewrites > 0).
#[test]
fn a_window_past_the_ring_still_ends_verified() {
    let options = options(LoaderChoice::Always);
    let greedy = ClientConfig {
        window: 4000,
        ..ClientConfig::default()
    };
    let image = extension(2048, 6);
    let mut client = Client::new(robot(), greedy);
    let report = uploader::upload(&mut client, &image, &options, &mut uploader::NoProgress)
        .expect("uploads");
    assert_eq!(report.rewrites, 0, "frames checked by sums: {report:?}");
    assert_done(client.into_transport(), &image, "greedy window, sums");

    let mut client = uploader::client(robot(), &options.profile);
    let report = uploader::upload(&mut client, &image, &options, &mut uploader::NoProgress)
        .expect("uploads");
    assert_eq!(report.rewrites, 0, "the ROM's window loses nothing");
}

#[test]
fn chains_behind_an_installed_extension() {
    let first = extension(300, 7);
    let (result, transport) = run(robot(), &first, &options(LoaderChoice::Auto));
    result.expect("the first upload");
    // A second extension elsewhere chains to the first; the robot's table
    // names the first one's extent, so the loader may go in beside it.
    let mut bytes = extension(300, 8).areas()[0].bytes.clone();
    bytes[3..6].copy_from_slice(&[0x4C, 0x00, 0x20]);
    let second = UploadImage::new(
        vec![Area {
            address: 0x2000,
            bytes,
        }],
        vec![HookRecord {
            kind: HookKind::Unknown,
            handler: 0x2003,
            chain: Some(0x2001),
        }],
    )
    .expect("an image");
    let (result, transport) = run(transport, &second, &options(LoaderChoice::Auto));
    let report = result.expect("the second upload");
    assert_eq!(report.hooks[0].previous, 0x0403);
    let (result, transport) = run(transport, &second, &options(LoaderChoice::Always));
    let report = result.expect("again, through the loader beside the first");
    assert!(report.loader.is_some(), "{report:?}");
    assert_eq!(report.hooks[0].previous, 0x0403);
    // The first is whole: the loader met none of its memory.
    let memory = transport.robot().robot().board().memory().to_vec();
    for area in first.areas() {
        let at = usize::from(area.address);
        let mut wanted = area.bytes.clone();
        // Its chain slot holds where it falls through.
        wanted[1..3].copy_from_slice(&memory[at + 1..at + 3]);
        assert_eq!(&memory[at..at + area.bytes.len()], &wanted[..]);
    }
}

#[test]
fn a_hook_into_the_upload_is_disarmed_first() {
    let image = extension(300, 9);
    let (result, transport) = run(robot(), &image, &options(LoaderChoice::Never));
    result.expect("the first upload");
    // The same image again: the hook points into it, so it goes back to
    // BAD_COMMAND before a byte is written, and the new copy chains there.
    let (result, transport) = run(transport, &image, &options(LoaderChoice::Auto));
    let report = result.expect("the second upload");
    assert_eq!(report.hooks[0].previous, BAD_COMMAND);
    assert_done(transport, &image, "re-upload");
}

#[test]
fn images_outside_user_memory_are_refused() {
    let image = UploadImage::new(
        vec![Area {
            address: 0x01F0,
            bytes: vec![0; 32],
        }],
        vec![],
    )
    .expect("a valid image");
    let (result, transport) = run(robot(), &image, &options(LoaderChoice::Auto));
    assert!(matches!(result, Err(Error::BadImage { .. })), "{result:?}");
    assert_eq!(transport.now(), Duration::ZERO, "nothing was sent");
    assert!(UploadImage::new(vec![], vec![]).is_err());
    let overlapping = UploadImage::new(
        vec![
            Area {
                address: 0x0400,
                bytes: vec![0; 4],
            },
            Area {
                address: 0x0402,
                bytes: vec![0; 4],
            },
        ],
        vec![],
    );
    assert!(overlapping.is_err());
    let outside_hook = UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes: vec![0; 4],
        }],
        vec![HookRecord {
            kind: HookKind::Loop,
            handler: 0x0500,
            chain: None,
        }],
    );
    assert!(matches!(outside_hook, Err(Error::BadHookRecord { .. })));
    // No room for the loader in user RAM.
    let full = UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes: vec![0xEA; usize::from(romlib::symbols::USER_RAM_END) + 1 - 0x0400],
        }],
        vec![],
    )
    .expect("an image");
    let error = run(robot(), &full, &options(LoaderChoice::Always))
        .0
        .expect_err("no room");
    assert!(
        matches!(error, Error::LoaderUnavailable { .. }),
        "{error:?}"
    );
}

#[test]
fn read_memory_pipelines_and_survives_noise() {
    let mut scorpion = VirtualScorpion::new();
    let pattern: Vec<u8> = (0..0x400).map(|i| (i * 7) as u8).collect();
    scorpion
        .robot_mut()
        .board_mut()
        .load(0x1000, &pattern)
        .expect("RAM");
    let mut client = Client::new(VirtualTransport::new(scorpion), ClientConfig::default());
    assert_eq!(client.read_memory(0x1000, 0x400).expect("reads"), pattern);
    assert_eq!(
        client.read_memory(0xFFFF, 1).expect("reads"),
        vec![romlib::ROM[0xFFF]]
    );
    assert!(client.read_memory(0xFFFF, 2).is_err());
    let faulty = FaultyTransport::new(
        client.into_transport(),
        FaultConfig::noise(3, 0.01, 0.0, 0.01),
    );
    let mut client = Client::new(faulty, ClientConfig::default());
    assert_eq!(client.read_memory(0x1000, 0x400).expect("reads"), pattern);
}

#[test]
fn probe_tells_no_answer_from_wrong_baud() {
    let dead = FaultyTransport::new(
        robot(),
        FaultConfig {
            stall_after: Some(0),
            ..FaultConfig::none(1)
        },
    );
    let mut client = Client::new(dead, ClientConfig::default());
    let error = client.probe().expect_err("nothing there");
    assert!(
        matches!(error, Error::NoAnswer { baud: 9600, .. }),
        "{error:?}"
    );
    assert!(error.to_string().contains("no answer"), "{error}");

    // The ROM hears no command in what a 2400-baud host sends it.
    let mut slow = robot();
    slow.set_baud(2400).expect("a 6551 rate");
    let mut client = Client::new(slow, ClientConfig::default());
    let error = client.probe().expect_err("nothing understood");
    assert!(
        matches!(error, Error::NoAnswer { baud: 2400, .. }),
        "{error:?}"
    );
    assert!(error.to_string().contains("2400 baud"), "{error}");

    // Answers that arrive as garbage are the other sign of a wrong rate.
    let garbled = FaultyTransport::new(
        robot(),
        FaultConfig {
            corrupt_rate: 1.0,
            to_robot: false,
            ..FaultConfig::none(2)
        },
    );
    let mut client = Client::new(garbled, ClientConfig::default());
    let error = client.probe().expect_err("garbage");
    assert!(
        matches!(error, Error::WrongBaud { baud: 9600, .. }),
        "{error:?}"
    );

    let mut client = Client::new(robot(), ClientConfig::default());
    assert_eq!(
        client.probe().expect("answers"),
        romlib::protocol::BusyByte(0)
    );
}

/// Every line that differs is reported, with its line and when it was
/// sent, and the lines after a difference are still checked.
#[test]
fn check_all_reports_every_mismatch_with_its_line_and_time() {
    let text = "/1X => X00\n/7R020001 => R00   # wrong\n/1X => X00\n/1X => X01   # wrong too\n";
    let expectations = Expectations::parse(text).expect("parses");
    let mut client = Client::new(robot(), ClientConfig::default());
    let checked = expectations.check_all(&mut client).expect("checked");
    assert_eq!(checked.transcript.len(), 4, "every line was sent");
    let found: Vec<(usize, &str, &str, &str)> = checked
        .mismatches
        .iter()
        .map(|m| {
            (
                m.line,
                m.command.as_str(),
                m.expected.as_str(),
                m.found.as_str(),
            )
        })
        .collect();
    assert_eq!(
        found,
        [(2, "/7R020001", "R00", "R4C"), (4, "/1X", "X01", "X00")]
    );
    let [first, second] = &checked.mismatches[..] else {
        panic!("two mismatches");
    };
    assert!(first.at > Duration::ZERO, "after line 1's exchange");
    assert!(
        second.at > first.at,
        "robot time goes on: {first:?} {second:?}"
    );
}

#[test]
fn expectations_parse_and_check() {
    let text =
        "# rehearsal\n/1X => X00\n/7R020003 => R4C21FF  # HOOK_UNKNOWN\n/2E3\n/1E\n/1E => E3\n";
    let expectations = Expectations::parse(text).expect("parses");
    assert_eq!(expectations.lines.len(), 5);
    assert_eq!(expectations.lines[2].required, Required::Sent);
    assert_eq!(expectations.lines[3].required, Required::Any);
    let mut client = Client::new(robot(), ClientConfig::default());
    let transcript = expectations.check(&mut client).expect("all answered");
    assert_eq!(transcript.len(), 5);
    assert_eq!(
        transcript[1].1,
        Some(Answer::Memory(vec![0x4C, 0x21, 0xFF]))
    );
    let wrong = Expectations::parse("/7R020001 => R00").expect("parses");
    let error = wrong.check(&mut client).expect_err("differs");
    assert!(
        matches!(&error, Error::RehearsalFailed { expected, found, .. } if expected == "R00" && found == "R4C"),
        "{error:?}"
    );
    for (bad, why) in [
        ("/1X => B00", "cannot answer"),
        ("/7R0400 => R", "command"),
        ("/1X =>", "nothing after"),
    ] {
        let error = Expectations::parse(bad).expect_err(bad);
        assert!(
            matches!(&error, Error::BadExpectations { line: 1, reason } if reason.contains(why)),
            "{bad}: {error:?}"
        );
    }
}

#[test]
fn the_rom_profile_comes_from_the_roms_symbols() {
    let profile = RomProfile::reference();
    let rom = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("parses");
    assert_eq!(
        RomProfile::from_rom_image("scorpion-rom.elf", &rom).expect("a profile"),
        profile,
        "the ring's size included: the ROM exports RXBUF_SIZE"
    );
    assert_eq!(profile.rx_buffer, REFERENCE_RX_BUFFER);
    assert_eq!(
        usize::from(romlib::symbols::RXBUF_SIZE),
        REFERENCE_RX_BUFFER + 1
    );
    // A ROM that does not say how much it buffers gets the cautious window.
    let mut quiet = rom.clone();
    quiet.symbols.retain(|symbol| symbol.name != "RXBUF_SIZE");
    assert_eq!(
        RomProfile::from_rom_image("quiet", &quiet)
            .expect("a profile")
            .rx_buffer,
        uploader::CONSERVATIVE_RX_BUFFER
    );
    assert_eq!(
        profile.reset_targets,
        Some((BAD_COMMAND, romlib::symbols::ROM_LOOP))
    );
    let error =
        RomProfile::from_rom_image("empty", &linker::Image::default()).expect_err("no symbols");
    assert!(
        error.to_string().contains("HOOK_UNKNOWN") || error.to_string().contains("USER_"),
        "{error}"
    );
}
