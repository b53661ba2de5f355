//! A project's own layout (`target = "FILE.toml"` or `"FILE.cfg"`) checked
//! against the memory an upload may write, at build time: an area that
//! reaches into the ROM's own RAM (its INJECT queue and extension table
//! above user RAM) links fine and would only be refused at the upload, or,
//! as BSS, silently overwrite the ROM's variables. The map is the ROM
//! profile's (`uploader::RomProfile::writable`, from the ROM's exported
//! bounds and the board's KIM bus).

use std::ops::RangeInclusive;

/// An area of a layout that leaves the writable memory.
#[derive(Debug, thiserror::Error, miette::Diagnostic)]
#[error("image {image}: the layout {layout} puts area `{area}` at ${start:04X}-${last:04X}, {why}")]
#[diagnostic(code(scorpion::project::layout_outside_ram), help("{help}"))]
pub struct OutsideMemory {
    image: String,
    layout: String,
    area: String,
    start: u64,
    last: u64,
    why: String,
    help: String,
}

fn ranges_text(writable: &[RangeInclusive<u16>]) -> String {
    writable
        .iter()
        .map(|r| format!("${:04X}-${:04X}", r.start(), r.end()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Checks every area of `layout` (the file `layout_file`) against
/// `writable`.
pub fn check(
    image: &str,
    layout_file: &str,
    layout: &linker::Layout,
    writable: &[RangeInclusive<u16>],
) -> Result<(), Box<OutsideMemory>> {
    let cfg = layout_file.ends_with(".cfg");
    for area in &layout.areas {
        if area.size == 0 {
            continue;
        }
        let start = area.start;
        let last = area.start + area.size - 1;
        let inside =
            |r: &RangeInclusive<u16>| u64::from(*r.start()) <= start && last <= u64::from(*r.end());
        if writable.iter().any(inside) {
            continue;
        }
        let holding = writable
            .iter()
            .find(|r| (u64::from(*r.start())..=u64::from(*r.end())).contains(&start));
        let (why, help) = match holding {
            Some(range) => {
                let end = *range.end();
                let fix = if cfg {
                    format!("size = ${:X}", u64::from(end) + 1 - start)
                } else {
                    format!("end = \"${end:04X}\"")
                };
                (
                    format!(
                        "past the end of the memory an upload may write (${:04X}-${end:04X}); above it is the ROM's own",
                        range.start()
                    ),
                    format!(
                        "end the area at ${end:04X}: `{fix}` in {layout_file}'s area `{}` (an upload may write {})",
                        area.name,
                        ranges_text(writable)
                    ),
                )
            }
            None => (
                "outside the memory an upload may write".to_owned(),
                format!(
                    "move the area `{}` of {layout_file} into the user zero page, user RAM or the KIM bus: {}",
                    area.name,
                    ranges_text(writable)
                ),
            ),
        };
        return Err(Box::new(OutsideMemory {
            image: image.to_owned(),
            layout: layout_file.to_owned(),
            area: area.name.clone(),
            start,
            last,
            why,
            help,
        }));
    }
    Ok(())
}
