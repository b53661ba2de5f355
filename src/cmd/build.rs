//! `scorpion build`: assemble sources and link them in one step, with the
//! objects kept in memory.

use std::path::PathBuf;
use std::process::ExitCode;

use miette::{Context, IntoDiagnostic};

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

/// Builds every image of the project found from here: `NAME.elf`,
/// `NAME.lst` and `NAME.map` in `target/scorpion/`.
fn project() -> miette::Result<ExitCode> {
    let project = crate::project::Project::here()?;
    for spec in &project.file.images {
        let (built, _) = crate::project::build::build_to_target(&project, spec)?;
        for warning in &built.warnings {
            #[allow(clippy::print_stderr, reason = "the CLI reports warnings")]
            {
                eprintln!("{warning:?}");
            }
        }
        let bytes: usize = built.linked.image.areas.iter().map(|a| a.bytes.len()).sum();
        #[allow(clippy::print_stdout, reason = "the CLI reports what it wrote")]
        {
            println!(
                "{}: target/scorpion/{}.elf ({bytes} bytes, target {}), .lst, .map",
                project.file.project.name, built.name, spec.target
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

pub(crate) fn run(args: &Args) -> miette::Result<ExitCode> {
    if args.sources.is_empty() {
        return project();
    }
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
            #[allow(clippy::print_stderr, reason = "the CLI reports errors")]
            {
                eprintln!("{:?}", miette::Report::new(error));
            }
        }
        return Err(last.into());
    }
    if let Some(path) = &args.listing {
        std::fs::write(path, &listings)
            .into_diagnostic()
            .wrap_err_with(|| format!("cannot write {}", path.display()))?;
    }
    link_and_write(&objects, &args.link, &DiskSources)
}
