//! `scorpion new NAME`: a project that builds, runs and passes its tests
//! at once (a project file, a source using `scorpion.inc`, a transcript
//! test, its snapshots, a `.gitignore`, a README of the loop).

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};

use crate::project::build::build;
use crate::project::snapshot;
use crate::project::{FILE, Project};

/// Start a project: an extension (a new command) or, with --os, an
/// operating system that takes the control loop.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The project's name, and its directory.
    #[arg(value_name = "NAME")]
    name: String,
    /// An operating system in KIM-bus RAM (the `scorpion-os` target)
    /// instead of an extension in user RAM.
    #[arg(long)]
    os: bool,
}

const EXTENSION: &str = r#"; {NAME}: a new command for the Scorpion.
;
; /1V answers V01, the version of this extension; every other command
; the ROM does not know goes on to whatever HOOK_UNKNOWN pointed at before.

        .include "scorpion.inc"

VERSION = $01

        .code

; HOOK_UNKNOWN lands here with A = the command letter, X = its count.
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'V'
        bne not_mine
        jsr PUTCH               ; A is still 'V'
        lda #VERSION
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE

not_mine:
        SCORPION_CHAIN_UNKNOWN
"#;

const OPERATING_SYSTEM: &str = r#"; {NAME}: an operating system for the Scorpion, in KIM-bus RAM.
;
; It takes the control loop (HOOK_LOOP): each pass it counts, then runs
; one pass of the ROM's own loop, so the robot still answers everything.
; /1V answers V01 once the loop has come round.

        .include "scorpion.inc"

        .data
passes:         .byte 0

        .code

        SCORPION_LOOP_HANDLER
tick:
        inc passes
        bne @counted
        inc passes              ; never back to 0: 0 means "not yet"
@counted:
        SCORPION_CHAIN_LOOP

        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'V'
        bne not_mine
        jsr PUTCH
        lda passes
        beq @none
        lda #$01
@none:  jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE

not_mine:
        SCORPION_CHAIN_UNKNOWN
"#;

const PROJECT: &str = r#"# {NAME}: `scorpion build`, `scorpion test`, `scorpion sim` and
# `scorpion upload` act on this project from this directory or below.

[project]
name = "{NAME}"

[[image]]
name = "{NAME}"
sources = ["src/{NAME}.s"]
target = "{TARGET}"

[robot]
# The robot's serial port; better in your environment (SCORPION_PORT), so
# that the project does not carry one person's device.
# port = "/dev/ttyUSB0"
baud = 9600
# Cards on the virtual robot's KIM bus (docs/CARDS.md): "cards/x.rhai@9000".
cards = []
"#;

const TRANSCRIPT: &str = "# What {NAME} must answer once it is in the robot: a command a line, and\n\
# after `=>` its answer (`*` any, `nothing` none). `scorpion test` runs it on\n\
# the virtual Scorpion; `scorpion test --port` on the robot.\n\
/1V => V01                # the new command\n\
/1X => X00                # the ROM still answers its own\n";

const README: &str = "# {NAME}\n\n\
A Scorpion {KIND}, made by `scorpion new`.\n\n\
```sh\n\
scorpion build                      # target/scorpion/{NAME}.elf, .lst, .map\n\
scorpion test                       # snapshots and transcripts, on the virtual Scorpion\n\
scorpion test --review              # a new or changed snapshot at a time: accept, reject, skip\n\
scorpion test {NAME}/listing --accept # take that one as it is now\n\
echo /1V | scorpion sim             # try it by hand\n\
scorpion upload --port /dev/ttyUSB0 # rehearse, upload, verify\n\
scorpion test --port /dev/ttyUSB0   # the transcripts on the robot\n\
```\n\n\
`src/` holds the source, `tests/*.expect` the transcripts, `tests/snapshots/`\n\
the listing, map, symbols and bytes `scorpion test` compares with (a failing\n\
one leaves its new text beside it as `NAME.snap.new`, which `cargo insta\n\
review` shows as well).\n";

fn write(path: &Path, text: &str) -> miette::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot create {}", dir.display()))?;
    }
    std::fs::write(path, text)
        .into_diagnostic()
        .wrap_err_with(|| format!("cannot write {}", path.display()))
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let name = &args.name;
    if name.is_empty()
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        miette::bail!(
            help = "letters, digits, `_` and `-`: it names the directory, the image and the source",
            "`{name}` cannot name a project"
        );
    }
    let root = PathBuf::from(name);
    if root.exists() {
        miette::bail!("{} already exists", root.display());
    }
    let fill = |text: &str| {
        text.replace("{NAME}", name)
            .replace(
                "{TARGET}",
                if args.os {
                    "scorpion-os"
                } else {
                    "scorpion-ext"
                },
            )
            .replace(
                "{KIND}",
                if args.os {
                    "operating system"
                } else {
                    "extension"
                },
            )
    };
    write(&root.join(FILE), &fill(PROJECT))?;
    let source = if args.os { OPERATING_SYSTEM } else { EXTENSION };
    write(&root.join("src").join(format!("{name}.s")), &fill(source))?;
    write(
        &root.join("tests").join(format!("{name}.expect")),
        &fill(TRANSCRIPT),
    )?;
    // Pending snapshots (`*.snap.new`) are not ignored: `cargo insta
    // review` and `pending-snapshots` skip what git ignores.
    write(&root.join(".gitignore"), "/target/\n")?;
    write(&root.join("README.md"), &fill(README))?;
    // The snapshots of what it builds now, so that its tests pass at once.
    let project = Project::load(&root)?;
    for spec in &project.file.images {
        let built = build(&project, spec)?;
        for (kind, content) in built.snapshots() {
            let label = format!("{}/{kind}", built.name);
            write(
                &project.snapshot_path(&built.name, kind),
                &snapshot::render(FILE, &label, &content),
            )?;
        }
    }
    #[allow(clippy::print_stdout, reason = "the CLI reports what it made")]
    {
        println!(
            "created {} `{name}` in {}/: cd {name} && scorpion test",
            if args.os {
                "operating system"
            } else {
                "extension"
            },
            root.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
