//! The path's picture as PNG (`--path FILE.png`): the SVG of [`picture`]
//! rasterized with resvg, so both formats show the same room and trail.
//! The labels (time marks, bumps, commands) are left out of the PNG: text
//! needs fonts, which differ between machines, and the picture would no
//! longer be the same everywhere.
//!
//! [`picture`]: super::picture

use std::path::Path;

use super::RoomView;

/// The longest side of a PNG, pixels: the SVG asks for 3 pixels a
/// centimetre, which a trail across an open floor would turn into
/// gigabytes; past this the picture is scaled down to fit.
pub const MAX_SIDE: u32 = 4096;

/// Why a picture could not be made.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
pub enum RasterError {
    /// The SVG did not parse (a bug of [`super::picture`]).
    #[error("the path's SVG does not parse: {0}")]
    #[diagnostic(code(room::picture_svg))]
    Svg(String),
    /// The picture has no area or could not be encoded.
    #[error("the path's picture cannot be made into a PNG: {0}")]
    #[diagnostic(code(room::picture_png))]
    Png(String),
}

/// Whether `path` asks for a PNG (its extension is `png`, any case).
#[must_use]
pub fn wants_png(path: &Path) -> bool {
    path.extension()
        .is_some_and(|extension| extension.eq_ignore_ascii_case("png"))
}

/// `svg` rasterized at its own size (at most [`MAX_SIDE`] pixels a side),
/// on white, PNG-encoded.
///
/// # Errors
/// [`RasterError`] if the SVG does not parse or the PNG cannot be made.
pub fn png(svg: &str) -> Result<Vec<u8>, RasterError> {
    use resvg::{tiny_skia, usvg};
    let tree = usvg::Tree::from_str(svg, &usvg::Options::default())
        .map_err(|error| RasterError::Svg(error.to_string()))?;
    let size = tree.size();
    let longest = size.width().max(size.height());
    #[allow(clippy::cast_precision_loss, reason = "MAX_SIDE is small")]
    let scale = if longest > MAX_SIDE as f32 {
        MAX_SIDE as f32 / longest
    } else {
        1.0
    };
    #[allow(
        clippy::cast_possible_truncation,
        clippy::cast_sign_loss,
        reason = "at most MAX_SIDE, positive"
    )]
    let (width, height) = (
        ((size.width() * scale).ceil() as u32).clamp(1, MAX_SIDE),
        ((size.height() * scale).ceil() as u32).clamp(1, MAX_SIDE),
    );
    let mut pixmap = tiny_skia::Pixmap::new(width, height)
        .ok_or_else(|| RasterError::Png(format!("a picture of {width}x{height} pixels")))?;
    pixmap.fill(tiny_skia::Color::WHITE);
    resvg::render(
        &tree,
        tiny_skia::Transform::from_scale(scale, scale),
        &mut pixmap.as_mut(),
    );
    pixmap
        .encode_png()
        .map_err(|error| RasterError::Png(error.to_string()))
}

impl RoomView {
    /// The picture of the path for `path`: PNG bytes if it ends in
    /// `.png`, else the SVG text ([`RoomView::svg`]).
    ///
    /// # Errors
    /// [`RasterError`] if a PNG cannot be made.
    pub fn picture_for(
        &self,
        path: &Path,
        commands: &[(u64, String)],
    ) -> Result<Vec<u8>, RasterError> {
        self.picture_of(path, &self.trail(), commands)
    }

    /// [`RoomView::picture_for`] with `trail` in place of the room's own
    /// (a session's whole run, [`super::Trail::follow`]).
    ///
    /// # Errors
    /// [`RasterError`] if a PNG cannot be made.
    pub fn picture_of(
        &self,
        path: &Path,
        trail: &super::Trail,
        commands: &[(u64, String)],
    ) -> Result<Vec<u8>, RasterError> {
        let svg = super::picture::svg(self.layout(), trail, commands);
        if wants_png(path) {
            png(&svg)
        } else {
            Ok(svg.into_bytes())
        }
    }
}
