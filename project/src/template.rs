//! New projects, as `scorpion new` makes them: a project that builds,
//! runs and passes its tests at once (a project file, a source using
//! `scorpion.inc`, a transcript test, its snapshots, a `.gitignore`, a
//! README of the loop). Here so that an editor can make one too.

use std::path::Path;

use miette::{Context, IntoDiagnostic};

use crate::runner::build::build;
use crate::runner::snapshot;
use crate::{FILE, Project};

/// What a new project makes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An extension (a new command) in user RAM (`scorpion-ext`).
    Extension,
    /// An operating system in KIM-bus RAM that takes the control loop
    /// (`scorpion-os`).
    OperatingSystem,
}

impl Kind {
    /// What it is called: `extension`, `operating system`.
    pub fn word(self) -> &'static str {
        match self {
            Kind::Extension => "extension",
            Kind::OperatingSystem => "operating system",
        }
    }

    fn target(self) -> &'static str {
        match self {
            Kind::Extension => "scorpion-ext",
            Kind::OperatingSystem => "scorpion-os",
        }
    }
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

/// Makes the project `name` of `kind` in the new directory `root`, with
/// the snapshots of what it builds now, so that its tests pass at once.
///
/// # Errors
/// A name that cannot name a project, a `root` that exists, a file that
/// cannot be written, a template that does not build.
pub fn create(root: &Path, name: &str, kind: Kind) -> miette::Result<Project> {
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
    if root.exists() {
        miette::bail!("{} already exists", root.display());
    }
    let fill = |text: &str| {
        text.replace("{NAME}", name)
            .replace("{TARGET}", kind.target())
            .replace("{KIND}", kind.word())
    };
    write(&root.join(FILE), &fill(PROJECT))?;
    let source = match kind {
        Kind::Extension => EXTENSION,
        Kind::OperatingSystem => OPERATING_SYSTEM,
    };
    write(&root.join("src").join(format!("{name}.s")), &fill(source))?;
    write(
        &root.join("tests").join(format!("{name}.expect")),
        &fill(TRANSCRIPT),
    )?;
    // Pending snapshots (`*.snap.new`) are not ignored: `cargo insta
    // review` and `pending-snapshots` skip what git ignores.
    write(&root.join(".gitignore"), "/target/\n")?;
    write(&root.join("README.md"), &fill(README))?;
    let project = Project::load(root)?;
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
    Ok(project)
}
