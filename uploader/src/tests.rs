//! The upload algorithm against the model robot: clean uploads, flow
//! control against a robot that stops reading while it answers, and every
//! fault of issue 6 through the fault-injecting transport, each checked
//! for the one invariant that matters: a hook points at the handler only
//! if every byte of the image is in the robot's memory.

use std::time::Duration;

use isa::objfmt::{HookKind, HookRecord};

use crate::model::{ModelRobot, RESET_LOOP, RESET_UNKNOWN};
use crate::transport::{FaultConfig, FaultyTransport, Transport, char_time};
use crate::*;

const BAUD: u32 = 9600;

/// A 2 KiB extension at $0400 whose handler is at $0400 and whose chain
/// slot is at $0401 (a `JMP` operand), with pseudo-random bytes after.
fn extension(len: usize, seed: u32) -> UploadImage {
    let mut bytes: Vec<u8> = (0..len as u32)
        .map(|i| (i ^ seed).wrapping_mul(2_246_822_519).to_le_bytes()[2])
        .collect();
    bytes[0] = 0x4C;
    UploadImage::new(
        vec![Area {
            address: 0x0400,
            bytes,
        }],
        vec![HookRecord {
            kind: HookKind::Unknown,
            handler: 0x0403,
            chain: Some(0x0401),
        }],
    )
    .expect("a valid image")
}

/// The image as it must be in the robot: chain slot filled with `previous`.
fn expected_memory(image: &UploadImage, previous: u16) -> Vec<u8> {
    let mut bytes = image.areas()[0].bytes.clone();
    bytes[1..3].copy_from_slice(&previous.to_le_bytes());
    bytes
}

fn body(robot: &ModelRobot, image: &UploadImage) -> Vec<u8> {
    let area = &image.areas()[0];
    let start = usize::from(area.address);
    robot.memory[start..start + area.bytes.len()].to_vec()
}

/// The invariant: whatever happened, a hook at the handler means the
/// whole image is there.
fn assert_safe(robot: &ModelRobot, image: &UploadImage, outcome: &str) {
    let hook = robot.hook(0x0200);
    if hook == 0x0403 {
        let previous = u16::from_le_bytes([robot.memory[0x0401], robot.memory[0x0402]]);
        assert_eq!(
            body(robot, image),
            expected_memory(image, previous),
            "the hook points at code that did not verify ({outcome})"
        );
        assert!(
            !image.contains(previous),
            "the chain slot points into the image ({outcome})"
        );
    } else {
        assert_eq!(
            hook, RESET_UNKNOWN,
            "the hook points somewhere else ({outcome})"
        );
    }
}

fn run_upload<T: Transport>(
    transport: T,
    image: &UploadImage,
    config: ClientConfig,
) -> (Result<UploadReport>, T) {
    let mut client = Client::new(transport, config);
    let result = upload(
        client_ref(&mut client),
        image,
        &UploadOptions::default(),
        &mut NoProgress,
    );
    (result, client.into_transport())
}

fn client_ref<T: Transport>(client: &mut Client<T>) -> &mut Client<T> {
    client
}

#[test]
fn clean_upload_verifies_and_hooks_last() {
    let image = extension(2048, 1);
    let config = ClientConfig {
        window: 1024,
        ..ClientConfig::default()
    };
    let (result, robot) = run_upload(ModelRobot::new(BAUD), &image, config);
    let report = result.expect("a clean upload succeeds");
    assert_eq!(report.bytes, 2048);
    assert_eq!(report.final_passes, 0);
    assert_eq!(report.rewrites, 0);
    assert_eq!(
        report.hooks,
        vec![InstalledHook {
            kind: HookKind::Unknown,
            handler: 0x0403,
            previous: RESET_UNKNOWN
        }]
    );
    assert_eq!(body(&robot, &image), expected_memory(&image, RESET_UNKNOWN));
    assert_eq!(robot.hook(0x0200), 0x0403);
    assert_eq!(robot.hook(0x0203), RESET_LOOP);
    // Every write to the hook comes after the last write to the body.
    let last_body = robot
        .writes
        .iter()
        .filter(|(_, a)| *a >= 0x0400)
        .map(|(t, _)| *t)
        .max()
        .expect("body writes");
    let first_hook = robot
        .writes
        .iter()
        .filter(|(_, a)| *a < 0x0400)
        .map(|(t, _)| *t)
        .min()
        .expect("hook writes");
    assert!(first_hook > last_body);
    // The ROM-only bound: 11 characters per 2 bytes written.
    let bound = char_time(2048 / 2 * 11, BAUD);
    let ratio = report.device_time.as_secs_f64() / bound.as_secs_f64();
    eprintln!(
        "model robot, 2048 bytes at {BAUD} baud: {:.3} s device time, ROM-only bound {:.3} s, {ratio:.3}x",
        report.device_time.as_secs_f64(),
        bound.as_secs_f64()
    );
    assert!(
        ratio < 1.1,
        "{:?} is {ratio:.3}x the ROM-only bound {bound:?}",
        report.device_time
    );
}

#[test]
fn flow_control_keeps_a_polled_robot_from_overrunning() {
    let image = extension(700, 2);
    let mut robot = ModelRobot::new(BAUD);
    robot.sync_tx = true;
    robot.rx_capacity = 64;
    let (result, robot) = run_upload(robot, &image, ClientConfig::default());
    let report = result.expect("the upload succeeds");
    assert_eq!(robot.overruns, 0, "{report:?}");
    assert_eq!(report.final_passes, 0);
    assert_eq!(robot.hook(0x0200), 0x0403);

    // Without the window the same robot loses bytes, and the upload
    // recovers through rewrites and a final pass.
    let mut robot = ModelRobot::new(BAUD);
    robot.sync_tx = true;
    robot.rx_capacity = 64;
    let greedy = ClientConfig {
        window: 100_000,
        ..ClientConfig::default()
    };
    let (result, robot) = run_upload(robot, &image, greedy);
    assert!(robot.overruns > 0);
    assert_safe(&robot, &image, &format!("{result:?}"));
}

#[test]
fn chains_behind_an_installed_extension() {
    let mut robot = ModelRobot::new(BAUD);
    robot.memory[0x0201..0x0203].copy_from_slice(&0x2000u16.to_le_bytes());
    let image = extension(300, 3);
    let (result, robot) = run_upload(robot, &image, ClientConfig::default());
    let report = result.expect("the upload succeeds");
    assert_eq!(report.hooks[0].previous, 0x2000);
    assert_eq!(&robot.memory[0x0401..0x0403], &[0x00, 0x20]);
    assert_eq!(robot.hook(0x0200), 0x0403);
}

#[test]
fn a_hook_into_the_upload_is_refused_or_disarmed() {
    let image = extension(300, 4);
    let mut robot = ModelRobot::new(BAUD);
    robot.memory[0x0201..0x0203].copy_from_slice(&0x0410u16.to_le_bytes());
    let (result, robot) = run_upload(robot, &image, ClientConfig::default());
    assert!(
        matches!(result, Err(Error::HookInUse { target: 0x0410, .. })),
        "{result:?}"
    );
    assert_eq!(robot.hook(0x0200), 0x0410, "nothing was touched");

    let mut robot = ModelRobot::new(BAUD);
    robot.memory[0x0201..0x0203].copy_from_slice(&0x0410u16.to_le_bytes());
    let mut client = Client::new(robot, ClientConfig::default());
    let options = UploadOptions {
        profile: RomProfile {
            reset_targets: Some((RESET_UNKNOWN, RESET_LOOP)),
            ..RomProfile::default()
        },
        ..UploadOptions::default()
    };
    let report = upload(&mut client, &image, &options, &mut NoProgress).expect("disarmed");
    assert_eq!(report.hooks[0].previous, RESET_UNKNOWN);
    assert_eq!(client.into_transport().hook(0x0200), 0x0403);
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
    let (result, _) = run_upload(ModelRobot::new(BAUD), &image, ClientConfig::default());
    assert!(matches!(result, Err(Error::BadImage { .. })), "{result:?}");
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
}

fn faulty_upload(config: FaultConfig, image: &UploadImage) -> (Result<UploadReport>, ModelRobot) {
    let robot = ModelRobot::new(BAUD);
    let (result, faulty) = run_upload(
        FaultyTransport::new(robot, config),
        image,
        ClientConfig::default(),
    );
    (result, faulty.into_inner())
}

#[test]
fn one_percent_noise_ends_verified() {
    let image = extension(1024, 5);
    type MakeFaults = fn(u64) -> FaultConfig;
    let kinds: [(&str, MakeFaults); 4] = [
        ("drop", |seed| FaultConfig::noise(seed, 0.01, 0.0, 0.0)),
        ("corrupt", |seed| FaultConfig::noise(seed, 0.0, 0.01, 0.0)),
        ("duplicate", |seed| FaultConfig::noise(seed, 0.0, 0.0, 0.01)),
        ("all three", |seed| {
            FaultConfig::noise(seed, 0.01 / 3.0, 0.01 / 3.0, 0.01 / 3.0)
        }),
    ];
    for (name, make) in kinds {
        for seed in 0..4 {
            let (result, robot) = faulty_upload(make(seed), &image);
            let outcome = format!("{name}, seed {seed}: {result:?}");
            assert_safe(&robot, &image, &outcome);
            let report = result.unwrap_or_else(|error| panic!("{outcome}: {error}"));
            assert_eq!(robot.hook(0x0200), 0x0403, "{outcome}");
            assert!(report.final_passes >= 1, "{outcome}");
        }
    }
}

#[test]
fn a_reset_in_the_middle_ends_verified_or_fails_safely() {
    let image = extension(1024, 6);
    for clears in [false, true] {
        for at in [100, 2000, 4000, 5500] {
            let mut robot = ModelRobot::new(BAUD);
            robot.reset_clears = clears;
            let config = FaultConfig {
                reset_after: Some(at),
                ..FaultConfig::none(7)
            };
            let (result, faulty) = run_upload(
                FaultyTransport::new(robot, config),
                &image,
                ClientConfig::default(),
            );
            assert_eq!(faulty.stats().resets, 1, "{result:?}");
            let robot = faulty.into_inner();
            assert_eq!(robot.resets, 1);
            let outcome = format!("reset at {at}, clears {clears}: {result:?}");
            assert_safe(&robot, &image, &outcome);
            result.unwrap_or_else(|error| panic!("{outcome}: {error}"));
        }
    }
}

#[test]
fn a_short_stall_recovers_and_a_dead_line_fails_clearly() {
    let image = extension(1024, 8);
    let config = FaultConfig {
        stall_after: Some(4000),
        stall_for: Some(Duration::from_millis(1500)),
        ..FaultConfig::none(9)
    };
    let (result, robot) = faulty_upload(config, &image);
    assert_safe(&robot, &image, &format!("{result:?}"));
    let report = result.expect("the upload survives a 1.5 s stall");
    assert!(report.final_passes >= 1);

    let config = FaultConfig {
        stall_after: Some(4000),
        stall_for: None,
        ..FaultConfig::none(9)
    };
    let (result, robot) = faulty_upload(config, &image);
    assert_safe(&robot, &image, &format!("{result:?}"));
    assert_eq!(robot.hook(0x0200), RESET_UNKNOWN);
    assert!(matches!(result, Err(Error::Stalled { .. })), "{result:?}");
    let message = result.expect_err("stalled").to_string();
    assert!(message.contains("stalled"), "{message}");
}

#[test]
fn read_memory_pipelines_and_survives_noise() {
    let mut robot = ModelRobot::new(BAUD);
    for (i, byte) in robot.memory[0x1000..0x1400].iter_mut().enumerate() {
        *byte = (i * 7) as u8;
    }
    let expected = robot.memory[0x1000..0x1400].to_vec();
    let mut client = Client::new(robot, ClientConfig::default());
    assert_eq!(client.read_memory(0x1000, 0x400).expect("reads"), expected);
    assert_eq!(client.read_memory(0xFFFF, 1).expect("reads").len(), 1);
    assert!(client.read_memory(0xFFFF, 2).is_err());
    let robot = client.into_transport();
    let faulty = FaultyTransport::new(robot, FaultConfig::noise(3, 0.01, 0.0, 0.01));
    let mut client = Client::new(faulty, ClientConfig::default());
    assert_eq!(client.read_memory(0x1000, 0x400).expect("reads"), expected);
}

/// A line where nothing ever answers, or only garbage does.
#[derive(Debug)]
struct DeadLine {
    now: Duration,
    garbage: bool,
}

impl Transport for DeadLine {
    fn send(&mut self, _: &[u8]) -> Result<()> {
        Ok(())
    }
    fn receive(&mut self, into: &mut Vec<u8>, timeout: Duration) -> Result<usize> {
        self.now += timeout;
        if self.garbage {
            // What 9600-baud answers look like read at 2400 baud.
            into.extend_from_slice(&[0x80, 0xF8, 0x00, 0x78, 0xE0]);
            return Ok(5);
        }
        Ok(0)
    }
    fn baud(&self) -> u32 {
        2400
    }
    fn now(&self) -> Duration {
        self.now
    }
    fn clear_input(&mut self) -> Result<()> {
        Ok(())
    }
    fn name(&self) -> String {
        "/dev/ttyTEST".into()
    }
}

#[test]
fn probe_tells_no_answer_from_wrong_baud() {
    let mut client = Client::new(
        DeadLine {
            now: Duration::ZERO,
            garbage: false,
        },
        ClientConfig::default(),
    );
    let error = client.probe().expect_err("nothing there");
    assert!(
        matches!(error, Error::NoAnswer { baud: 2400, .. }),
        "{error:?}"
    );
    assert!(error.to_string().contains("no answer"), "{error}");
    let mut client = Client::new(
        DeadLine {
            now: Duration::ZERO,
            garbage: true,
        },
        ClientConfig::default(),
    );
    let error = client.probe().expect_err("garbage");
    assert!(matches!(error, Error::WrongBaud { .. }), "{error:?}");
    let mut client = Client::new(ModelRobot::new(BAUD), ClientConfig::default());
    assert_eq!(
        client.probe().expect("answers"),
        romlib::protocol::BusyByte(0)
    );
}

#[test]
fn expectations_parse_and_check() {
    let text =
        "# rehearsal\n/1X => X00\n/7R040003 => R4C23F1  # the chain slot\n/2E3\n/1X\n/1X => *\n";
    let expectations = Expectations::parse(text).expect("parses");
    assert_eq!(expectations.lines.len(), 5);
    assert_eq!(expectations.lines[2].required, Required::Nothing);
    assert_eq!(expectations.lines[3].required, Required::Any);
    let mut robot = ModelRobot::new(BAUD);
    robot.memory[0x0400..0x0403].copy_from_slice(&[0x4C, 0x23, 0xF1]);
    let mut client = Client::new(robot, ClientConfig::default());
    let transcript = expectations.check(&mut client).expect("all answered");
    assert_eq!(transcript.len(), 5);
    assert_eq!(
        transcript[1].1,
        Some(romlib::protocol::Answer::Memory(vec![0x4C, 0x23, 0xF1]))
    );

    let wrong = Expectations::parse("/7R040001 => R00").expect("parses");
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
