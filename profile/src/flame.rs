//! The folded stacks as an SVG flame graph, drawn by `inferno`.

use crate::Error;
use crate::profile::Profile;

/// The SVG flame graph of `profile`'s stacks, titled `title`, widths in
/// cycles.
///
/// # Errors
/// [`Error::FlameGraph`] if there is nothing to draw or the renderer
/// fails.
pub fn svg(profile: &Profile, title: &str) -> Result<Vec<u8>, Error> {
    let folded = profile.folded();
    if folded.is_empty() {
        return Err(Error::FlameGraph {
            reason: "no cycles were counted".into(),
        });
    }
    let mut options = inferno::flamegraph::Options::default();
    title.clone_into(&mut options.title);
    "cycles".clone_into(&mut options.count_name);
    let mut out = Vec::new();
    inferno::flamegraph::from_lines(&mut options, folded.lines(), &mut out).map_err(|error| {
        Error::FlameGraph {
            reason: error.to_string(),
        }
    })?;
    Ok(out)
}
