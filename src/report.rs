//! How the CLI renders a diagnostic: miette's graphical report, unless a
//! place in it lies too far along its line for miette to pad to (its
//! renderer panics past column 65535: a minified or generated line), when
//! it is said in lines of its own: the message, each place as
//! `file:line:col`, the help and the code, without the snippet (a line
//! that long is no use on a terminal).

use std::fmt;

use miette::{Diagnostic, ReportHandler, SourceCode};

/// Columns and label lengths past this are narrated: miette pads with
/// Rust's formatting width, which stops at 65535.
const FAR: usize = 60_000;

/// The CLI's report handler.
pub(crate) struct Reports {
    graphical: miette::MietteHandler,
}

impl Reports {
    /// The graphical handler as the CLI configures it, and its fallback.
    pub(crate) fn new() -> Reports {
        Reports {
            graphical: miette::MietteHandlerOpts::new().wrap_lines(false).build(),
        }
    }
}

impl fmt::Debug for Reports {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Reports")
    }
}

impl ReportHandler for Reports {
    fn debug(&self, diagnostic: &dyn Diagnostic, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if far(diagnostic, None) {
            plain(diagnostic, None, "Error", f)
        } else {
            self.graphical.debug(diagnostic, f)
        }
    }
}

/// Whether a label of `diagnostic` (or of a diagnostic related to it or
/// causing it) starts or runs past [`FAR`] columns.
fn far(diagnostic: &dyn Diagnostic, inherited: Option<&dyn SourceCode>) -> bool {
    let source = diagnostic.source_code().or(inherited);
    let labelled = diagnostic.labels().into_iter().flatten().any(|label| {
        label.len() > FAR
            || source
                .and_then(|source| source.read_span(label.inner(), 0, 0).ok())
                .is_some_and(|contents| contents.column() > FAR)
    });
    labelled
        || diagnostic
            .related()
            .into_iter()
            .flatten()
            .any(|related| far(related, source))
        || diagnostic
            .diagnostic_source()
            .is_some_and(|cause| far(cause, source))
}

/// `diagnostic` in lines of its own, places as `file:line:col`.
fn plain(
    diagnostic: &dyn Diagnostic,
    inherited: Option<&dyn SourceCode>,
    head: &str,
    f: &mut fmt::Formatter<'_>,
) -> fmt::Result {
    let source = diagnostic.source_code().or(inherited);
    writeln!(f, "{head}: {diagnostic}")?;
    for label in diagnostic.labels().into_iter().flatten() {
        let Some(contents) = source.and_then(|source| source.read_span(label.inner(), 0, 0).ok())
        else {
            continue;
        };
        writeln!(
            f,
            "  at {}:{}:{}{}",
            contents.name().unwrap_or("<input>"),
            contents.line() + 1,
            contents.column() + 1,
            label
                .label()
                .map(|text| format!(": {text}"))
                .unwrap_or_default()
        )?;
    }
    if let Some(help) = diagnostic.help() {
        writeln!(f, "  help: {help}")?;
    }
    if let Some(code) = diagnostic.code() {
        writeln!(f, "  code: {code}")?;
    }
    let mut cause = std::error::Error::source(diagnostic);
    while let Some(error) = cause {
        writeln!(f, "  caused by: {error}")?;
        cause = error.source();
    }
    for related in diagnostic.related().into_iter().flatten() {
        plain(related, source, "  Error", f)?;
    }
    Ok(())
}
