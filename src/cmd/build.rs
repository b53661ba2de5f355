//! `scorpion build`: assemble sources and link them in one step, with the
//! objects kept in memory.

use std::path::PathBuf;
use std::process::ExitCode;

use miette::IntoDiagnostic;

use crate::cmd::asm::{AsmOptions, report};
use crate::cmd::link::{DiskSources, LinkArgs, link_and_write};

/// Assemble ca65-syntax sources and link them into a Scorpion image.
#[derive(Debug, clap::Args)]
pub(crate) struct Args {
    /// The sources, in link order; none: the images of the project
    /// (`Scorpion.toml` here or above) into `target/scorpion/`.
    #[arg(value_name = "SRC")]
    sources: Vec<PathBuf>,
    #[command(flatten)]
    assembler: AsmOptions,
    /// Write the sources' listings, one after the other, to this file.
    #[arg(short = 'l', long = "listing", value_name = "LISTING")]
    listing: Option<PathBuf>,
    #[command(flatten)]
    link: LinkArgs,
}

/// Builds every image of the project found from here (of every member,
/// in a workspace): `NAME.elf`, `NAME.lst` and `NAME.map` in each
/// project's `target/scorpion/`. The assembler's flags (`-D`, `-I`,
/// `--feature`...) apply to every image, on top of its own; the output's
/// flags are refused, saying why: a project's outputs are its own.
fn project(args: &Args) -> miette::Result<ExitCode> {
    let mut refused = args.link.given();
    if args.listing.is_some() {
        refused.insert(0, "-l");
    }
    if !refused.is_empty() {
        miette::bail!(
            help = "a project writes target/scorpion/NAME.elf, .lst and .map for each [[image]], where `upload`, `test` and `debug` find them, and each image's `target` in Scorpion.toml says where it goes; copy or convert the ELF (`scorpion link`), or build the sources outside a project (`scorpion build SRC... -o OUT`)",
            "{} cannot apply to a project's build",
            refused.join(", ")
        );
    }
    // Relative directories are the user's, from here: made absolute, as
    // the project's own are read from its root.
    let here = std::env::current_dir().into_diagnostic()?;
    let mut given = args.assembler.options(true);
    for dir in given
        .include_dirs
        .iter_mut()
        .chain(given.bin_include_dirs.iter_mut())
    {
        *dir = here.join(&*dir);
    }
    match scorpion_project::Found::here()? {
        scorpion_project::Found::Project(project) => build_project(&project, "", &given),
        scorpion_project::Found::Workspace(workspace) => {
            for (name, project) in workspace.projects()? {
                build_project(&project, &format!("{name}/"), &given)?;
            }
            Ok(())
        }
    }?;
    Ok(ExitCode::SUCCESS)
}

/// Builds `project`'s images; `at` is its directory as printed.
fn build_project(
    project: &scorpion_project::Project,
    at: &str,
    given: &assembler::Options,
) -> miette::Result<()> {
    for spec in &project.file.images {
        let (built, _) =
            scorpion_project::runner::build::build_to_target_with(project, spec, given)?;
        for warning in &built.warnings {
            // "Warning: " as miette heads a related warning: the problem
            // matcher reads a warning's severity there.
            crate::cmd::say_err(&format!("Warning: {warning:?}\n"));
        }
        let bytes: usize = built.linked.image.areas.iter().map(|a| a.bytes.len()).sum();
        // fresh21 F8: each line names its image (it named the project).
        crate::cmd::say_out(&format!(
            "{}: {at}target/scorpion/{}.elf ({bytes} bytes, target {}), .lst, .map\n",
            built.name, built.name, spec.target
        ));
    }
    Ok(())
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    if args.sources.is_empty() {
        return project(args);
    }
    // Every output is checked before anything is written.
    if let Some(path) = &args.listing {
        hostfs::check_writable(path)?;
    }
    crate::cmd::link::check_outputs(&args.link)?;
    let options = args.assembler.options(args.listing.is_some());
    let mut objects = Vec::with_capacity(args.sources.len());
    let mut listings = String::new();
    let mut failures = Vec::new();
    for source in &args.sources {
        match assembler::assemble(&assembler::FsSource, source, &options) {
            Ok(assembly) => {
                report(&assembly);
                if let Some(listing) = &assembly.listing {
                    listings.push_str(listing);
                    listings.push('\n');
                }
                objects.push((source.display().to_string(), assembly.object));
            }
            // Every source is assembled, so all their errors show at once.
            Err(error) => failures.push(error),
        }
    }
    if let Some(last) = failures.pop() {
        for error in failures {
            crate::cmd::say_err(&format!("{:?}\n", miette::Report::new(error)));
        }
        return Err(last.into());
    }
    if let Some(path) = &args.listing {
        hostfs::write(path, listings.as_bytes())?;
    }
    link_and_write(&objects, &args.link, &DiskSources)
}
