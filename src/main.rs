//! `scorpion`: the command-line front end of the Scorpion toolchain.
//!
//! Each subcommand lives in its own module under `cmd/`; this file only
//! parses arguments and reports errors. The CLI is the one place that prints
//! or exits: the libraries return typed errors and report progress through
//! callbacks.

mod args;
mod cmd;
mod report;

use std::io::Write as _;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// The Scorpion robot cross-toolchain: assemble, link, emulate and upload
/// 6502 extensions for the Scorpion's ROM.
#[derive(Debug, Parser)]
#[command(name = "scorpion", version, about, long_about = None, max_term_width = 100)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Assemble a ca65-syntax source file into an ELF object.
    Asm(cmd::asm::Args),
    /// Disassemble a linked image, an ELF object or a raw binary.
    Disasm(cmd::disasm::Args),
    /// Run 6502 code on the emulator.
    Emu(cmd::emu::Args),
    /// Link 6502 ELF objects into a Scorpion image.
    Link(cmd::link::Args),
    /// Assemble ca65-syntax sources and link them into a Scorpion image.
    Build(cmd::build::Args),
    /// Upload a linked image into a robot, verified, hooks last.
    Upload(cmd::upload::Args),
    /// List the serial ports a robot could be on.
    Ports(cmd::ports::Args),
    /// Dump robot memory with `/7R` questions.
    Read(cmd::read::Args),
    /// List the extensions a robot has installed, and its hooks' chains.
    Installed(cmd::installed::Args),
    /// A robot's ROM: `rom read -o ROM.elf` reads it into a ROM profile.
    Rom(cmd::rom::Args),
    /// Save what a robot holds (user RAM and zero page, the extension
    /// table, the hooks) to a file, verified.
    Backup(cmd::backup::BackupArgs),
    /// Put a backup (or an upload's undo file) back into a robot,
    /// verified, hooks last.
    Restore(cmd::backup::RestoreArgs),
    /// Run the virtual Scorpion on a pseudo-terminal or stdin/stdout.
    Sim(cmd::sim::Args),
    /// Send commands to a robot and print the answers.
    Ask(cmd::ask::Args),
    /// Start a project: a project file, a source, a transcript test.
    New(cmd::new::Args),
    /// Run a project's tests: snapshots and transcripts.
    Test(cmd::test::Args),
    /// Profile a project's tests on the virtual Scorpion: cycles per
    /// routine, robot command and source line, and a flame graph.
    Profile(cmd::profile::Args),
    /// Debug a program on the virtual Scorpion: breakpoints, stepping,
    /// back in time.
    Debug(cmd::debug::Args),
    /// Serve the Debug Adapter Protocol on stdin/stdout, for editors.
    Dap(cmd::dap::Args),
    /// Show the configuration a command here resolves, and where each
    /// setting came from.
    Config(cmd::config::Args),
}

fn main() -> ExitCode {
    // A diagnostic's message, help and causes each on one line (the
    // terminal folds them): an editor's problem matcher (editors/vscode's
    // `$scorpion`) reads the message on the line above its place, which a
    // message wrapped at 80 columns split from it.
    let _ = miette::set_hook(Box::new(|_| Box::new(report::Reports::new())));
    let cli = Cli::try_parse().unwrap_or_else(|error| {
        let _ = error.print();
        // recheck22 F2: `read --port $0200 6` took `$0200` for the port,
        // and clap then missed an argument: said, with the way to write it.
        if error.kind() == clap::error::ErrorKind::MissingRequiredArgument
            && let Some(taken) = cmd::ports::swallowed(std::env::args().skip(1))
        {
            cmd::say_err(&format!(
                "note: --port took `{taken}` as its value; {}\n",
                scorpion_project::BARE_PORT
            ));
        }
        std::process::exit(error.exit_code());
    });
    let result = match cli.command {
        Command::Asm(args) => cmd::asm::run(&args),
        Command::Disasm(args) => cmd::disasm::run(&args),
        Command::Emu(args) => cmd::emu::run(&args),
        Command::Link(args) => cmd::link::run(&args),
        Command::Build(args) => cmd::build::run(&args),
        Command::Upload(args) => cmd::upload::run(&args),
        Command::Ports(args) => cmd::ports::run(&args),
        Command::Read(args) => cmd::read::run(&args),
        Command::Installed(args) => cmd::installed::run(&args),
        Command::Rom(args) => cmd::rom::run(&args),
        Command::Backup(args) => cmd::backup::run_backup(&args),
        Command::Restore(args) => cmd::backup::run_restore(&args),
        Command::Sim(args) => cmd::sim::run(&args),
        Command::Ask(args) => cmd::ask::run(&args),
        Command::New(args) => cmd::new::run(&args),
        Command::Test(args) => cmd::test::run(&args),
        Command::Profile(args) => cmd::profile::run(&args),
        Command::Debug(args) => cmd::debug::run(&args),
        Command::Dap(args) => cmd::dap::run(&args),
        Command::Config(args) => cmd::config::run(&args),
    };
    match result {
        Ok(code) => code,
        Err(report) => {
            // The only place errors reach the user: render them with miette.
            // A closed stderr (`2>&1 | head`) must not turn an error into
            // a panic: what cannot be written is dropped.
            let _ = writeln!(std::io::stderr(), "{report:?}");
            ExitCode::FAILURE
        }
    }
}
