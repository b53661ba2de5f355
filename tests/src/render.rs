//! Diagnostics as the CLI shows them, without colour, for snapshots.

/// Renders `diagnostic` with miette's graphical handler, unicode without
/// colour, 100 columns wide: what `scorpion` prints, stable in a snapshot.
#[must_use]
pub fn render(diagnostic: &dyn miette::Diagnostic) -> String {
    let mut out = String::new();
    miette::GraphicalReportHandler::new_themed(miette::GraphicalTheme::unicode_nocolor())
        .with_width(100)
        .render_report(&mut out, diagnostic)
        .expect("rendering to a String cannot fail");
    out
}
