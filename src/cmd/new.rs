//! `scorpion new NAME`: a project that builds, runs and passes its tests
//! at once (the library's [`scorpion_project::template`] makes it).

use std::path::PathBuf;
use std::process::ExitCode;

use scorpion_project::template::{self, Kind};

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

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    let name = &args.name;
    let kind = if args.os {
        Kind::OperatingSystem
    } else {
        Kind::Extension
    };
    let root = PathBuf::from(name);
    template::create(&root, name, kind)?;
    crate::cmd::say_out(&format!(
        "created {} `{name}` in {}/: cd {name} && scorpion test\n",
        kind.word(),
        root.display()
    ));
    Ok(ExitCode::SUCCESS)
}
