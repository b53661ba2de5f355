//! The examples in `examples/`, built with our assembler and linker
//! against the reference ROM, then put into the virtual Scorpion by the
//! uploader itself (`uploader::upload` over the emulated serial line, the
//! RAM loader at 19200 baud where it pays), and used through the
//! expectation files of `scorpion upload --expect`: the whole main job,
//! across the crates.

mod rom_support;

use rom_support::{build, examples_dir};
use romlib::symbols::{BAD_COMMAND, HOOK_LOOP, HOOK_UNKNOWN, ROM_LOOP};
use uploader::transport::VirtualTransport;
use uploader::{
    Expectations, LoaderChoice, NoProgress, RomProfile, UploadImage, UploadOptions, UploadReport,
};

fn image(source: &str, target: &str) -> UploadImage {
    let linked = build(&[examples_dir().join(source)], target);
    UploadImage::try_from(&linked).expect("an example is an uploadable image")
}

fn upload(
    transport: VirtualTransport,
    image: &UploadImage,
    loader: LoaderChoice,
) -> (UploadReport, VirtualTransport) {
    let options = UploadOptions {
        loader,
        ..UploadOptions::default()
    };
    let mut client = uploader::client(transport, &options.profile);
    let report = uploader::upload(&mut client, image, &options, &mut NoProgress)
        .unwrap_or_else(|error| panic!("the upload fails: {error:?}"));
    (report, client.into_transport())
}

fn check(transport: VirtualTransport, expectations: &str) -> VirtualTransport {
    let expectations = Expectations::parse(expectations).expect("the expectations parse");
    let mut client = uploader::client(transport, &RomProfile::reference());
    expectations
        .check(&mut client)
        .unwrap_or_else(|error| panic!("{error}"));
    client.into_transport()
}

/// The checksum example, linked with its own layout (beside another
/// extension at `$0400`).
fn checksum_image() -> UploadImage {
    image(
        "checksum/checksum.s",
        &examples_dir()
            .join("checksum/checksum.toml")
            .display()
            .to_string(),
    )
}

fn hook(transport: &VirtualTransport, at: u16) -> u16 {
    let memory = transport.robot().robot().board().memory();
    u16::from_le_bytes([memory[usize::from(at) + 1], memory[usize::from(at) + 2]])
}

#[test]
fn the_patrol_os_goes_in_through_the_loader_and_the_checksum_chains_behind() {
    // An operating system in KIM-bus RAM: big enough for the loader.
    let patrol = image("patrol/patrol.s", "scorpion-os");
    let (report, transport) = upload(VirtualTransport::default(), &patrol, LoaderChoice::Auto);
    let loader = report.loader.expect("the loader carried it");
    assert_eq!(loader.baud, uploader::FAST_BAUD);
    assert_eq!(report.final_passes, 0);
    let handler = |kind| {
        patrol
            .hooks()
            .iter()
            .find(|record| record.kind == kind)
            .expect("patrol takes both hooks")
            .handler
    };
    assert_eq!(
        hook(&transport, HOOK_LOOP),
        handler(isa::objfmt::HookKind::Loop)
    );
    assert_eq!(
        hook(&transport, HOOK_UNKNOWN),
        handler(isa::objfmt::HookKind::Unknown)
    );
    let transport = check(transport, "/1X\n/2A0   # patrol stands still\n/1X => X00\n");

    // A second extension: the loader goes in beside patrol (the table
    // names where patrol lives, so the loader keeps out of it), and the
    // extension chains to patrol's handler.
    let checksum = checksum_image();
    let (report, transport) = upload(transport, &checksum, LoaderChoice::Auto);
    assert!(report.loader.is_some(), "{report:?}");
    assert_eq!(report.without_loader, None);
    assert_eq!(
        report.hooks[0].previous,
        handler(isa::objfmt::HookKind::Unknown)
    );
    let transport = check(
        transport,
        "/9W20000102\n/9K20000002 => K0003\n/2A0\n/1X => X00\n",
    );
    assert_eq!(
        hook(&transport, HOOK_LOOP),
        handler(isa::objfmt::HookKind::Loop)
    );
}

#[test]
fn every_example_uploads_on_both_paths() {
    for (source, target) in [
        ("rangefinder/rangefinder.s", "scorpion-ext".to_owned()),
        (
            "checksum/checksum.s",
            examples_dir()
                .join("checksum/checksum.toml")
                .display()
                .to_string(),
        ),
        ("patrol/patrol.s", "scorpion-os".to_owned()),
    ] {
        let image = image(source, &target);
        for loader in [LoaderChoice::Never, LoaderChoice::Always] {
            let (report, transport) = upload(VirtualTransport::default(), &image, loader);
            assert_eq!(
                report.loader.is_some(),
                loader == LoaderChoice::Always,
                "{source}"
            );
            // Every loaded byte is in the robot, and the chain ends in the ROM.
            let memory = transport.robot().robot().board().memory();
            for area in image.areas() {
                let start = usize::from(area.address);
                let chains: Vec<u16> = image.hooks().iter().filter_map(|r| r.chain).collect();
                for (i, &byte) in area.bytes.iter().enumerate() {
                    let at = area.address + i as u16;
                    if !chains.iter().any(|&slot| at == slot || at == slot + 1) {
                        assert_eq!(memory[start + i], byte, "{source} at ${at:04X}");
                    }
                }
            }
            for record in image.hooks() {
                if let Some(slot) = record.chain {
                    let to = u16::from_le_bytes([
                        memory[usize::from(slot)],
                        memory[usize::from(slot) + 1],
                    ]);
                    assert!(to == BAD_COMMAND || to == ROM_LOOP, "{source}: ${to:04X}");
                }
            }
            assert_eq!(transport.robot().robot().board().acia().control(), 0x1E);
        }
    }
}

/// An expectation file's three kinds of line against an extension's
/// command: an exact answer, no `=>` (whatever comes back is accepted and
/// kept for the transcript), and `=> nothing` (silence required).
#[test]
fn expectations_keep_every_answer_and_can_require_silence() {
    let checksum = checksum_image();
    let (_, transport) = upload(VirtualTransport::default(), &checksum, LoaderChoice::Never);
    let expectations =
        Expectations::parse("/9W10000102\n/9K10000002\n/1Q => nothing\n/9K10000000 => K0000\n")
            .expect("the expectations parse");
    let mut client = uploader::client(transport, &RomProfile::reference());
    let transcript = expectations
        .check(&mut client)
        .unwrap_or_else(|error| panic!("{error}"));
    let answers: Vec<Option<String>> = transcript
        .iter()
        .map(|(_, answer)| answer.as_ref().map(uploader::answer_text))
        .collect();
    assert_eq!(
        answers,
        [None, Some("K0003".into()), None, Some("K0000".into())],
        "the extension's answer to a line without `=>` is kept"
    );
    // The extension answers: `=> nothing` fails and says what came.
    let silent = Expectations::parse("/9K10000002 => nothing").expect("parses");
    let error = silent.check(&mut client).expect_err("an answer came");
    let text = error.to_string();
    assert!(
        text.contains("no answer") && text.contains("K0003"),
        "{text}"
    );
    // A file with nothing to check is an error, not "0 expectations met".
    for empty in ["", "# only a comment\n\n"] {
        let error = Expectations::parse(empty).expect_err("nothing to check");
        assert!(error.to_string().contains("no command"), "{error}");
    }
}
