//! An image of the project built in memory: assembled with paths relative
//! to the project (so listings and maps name no directory of the machine),
//! linked against the reference ROM, with the texts its snapshots are made
//! of.

use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

use linker::{Image, Linked, SourceProvider, Target};

use crate::{ImageSpec, Project};

/// Files read relative to the project's root.
struct Rooted<'a>(&'a Path);

impl Rooted<'_> {
    fn full(&self, path: &Path) -> PathBuf {
        if path.is_absolute() {
            path.to_path_buf()
        } else {
            self.0.join(path)
        }
    }
}

impl assembler::FileSource for Rooted<'_> {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        Ok(hostfs::read(self.full(path), hostfs::SOURCE)?)
    }
}

impl SourceProvider for Rooted<'_> {
    fn source(&self, path: &str) -> Option<String> {
        hostfs::read_text(self.full(Path::new(path)), hostfs::TEXT).ok()
    }
}

/// What `scorpion test` snapshots of every image.
pub const SNAPSHOT_KINDS: [&str; 4] = ["listing", "map", "symbols", "bytes"];

/// A built image and what it is made of.
#[derive(Debug)]
pub struct Built {
    /// The image's name in the project.
    pub name: String,
    /// The link's result.
    pub linked: Linked,
    /// The listings of its sources, one after the other.
    pub listing: String,
    /// Warnings of the assembler and the linker, rendered.
    pub warnings: Vec<miette::Report>,
}

/// Assembles and links `spec`.
pub fn build(project: &Project, spec: &ImageSpec) -> miette::Result<Built> {
    build_with(project, spec, &assembler::Options::default())
}

/// Assembles and links `spec` with the command line's assembler options
/// `given` (`scorpion build -D`, `-I`...) on top of the image's own: its
/// include directories first, then the given ones; its defines, each
/// replaced by a given one of the same name.
pub fn build_with(
    project: &Project,
    spec: &ImageSpec,
    given: &assembler::Options,
) -> miette::Result<Built> {
    let source = Rooted(&project.root);
    let mut defines: Vec<(String, i64)> = spec
        .defines
        .iter()
        .filter(|(name, _)| !given.defines.iter().any(|(own, _)| own == *name))
        .map(|(name, value)| (name.clone(), *value))
        .collect();
    defines.extend(given.defines.iter().cloned());
    let options = assembler::Options {
        include_dirs: spec
            .include
            .iter()
            .map(PathBuf::from)
            .chain(given.include_dirs.iter().cloned())
            .collect(),
        defines,
        listing: true,
        list_builtin_includes: project.file.tests.builtin_listing,
        builtin_includes: super::toolchain::builtin_includes(),
        ..given.clone()
    };
    let mut objects = Vec::new();
    let mut listing = String::new();
    let mut warnings = Vec::new();
    for path in &spec.sources {
        let assembly = assembler::assemble(&source, Path::new(path), &options)?;
        for warning in assembly.warnings {
            warnings.push(miette::Report::new(warning));
        }
        if let Some(text) = assembly.listing {
            listing.push_str(&text);
        }
        objects.push((path.clone(), assembly.object));
    }
    let target = if spec.target.ends_with(".toml") {
        let text = hostfs::read_text(project.path(&spec.target), hostfs::TEXT).map_err(|e| {
            miette::miette!(
                "image {}: cannot read the layout {}: {e}",
                spec.name,
                spec.target
            )
        })?;
        Target::Custom(linker::Layout::from_toml(&spec.target, &text)?)
    } else if spec.target.ends_with(".cfg") {
        let text = hostfs::read_text(project.path(&spec.target), hostfs::TEXT).map_err(|e| {
            miette::miette!(
                "image {}: cannot read the ld65 configuration {}: {e}",
                spec.name,
                spec.target
            )
        })?;
        Target::Custom(linker::Layout::from_ld65(&spec.target, &text, None)?)
    } else {
        Target::builtin(&spec.target, None)?
    };
    if let Target::Custom(layout) = &target {
        let profile = match project.rom()? {
            Some((name, image)) => uploader::RomProfile::from_rom_image(&name, &image)?,
            None => uploader::RomProfile::reference(),
        };
        super::memory::check(&spec.name, &spec.target, layout, &profile.writable)
            .map_err(|outside| miette::Report::new(*outside))?;
    }
    let rom = match project.rom()? {
        Some(profile) => profile,
        None => (
            "scorpion-rom.elf".to_owned(),
            Image::parse("scorpion-rom.elf", romlib::ROM_ELF)?,
        ),
    };
    let mut linked = super::toolchain::link_objects(&objects, &target, &[rom], &source)?;
    for warning in std::mem::take(&mut linked.warnings) {
        warnings.push(miette::Report::new(warning));
    }
    Ok(Built {
        name: spec.name.clone(),
        linked,
        listing,
        warnings,
    })
}

/// Builds `spec` and writes `NAME.elf`, `NAME.lst` and `NAME.map` into
/// the project's `target/scorpion/`; returns the build and the image's
/// path.
pub fn build_to_target(project: &Project, spec: &ImageSpec) -> miette::Result<(Built, PathBuf)> {
    build_to_target_with(project, spec, &assembler::Options::default())
}

/// [`build_to_target`] with the command line's assembler options (see
/// [`build_with`]).
pub fn build_to_target_with(
    project: &Project,
    spec: &ImageSpec,
    given: &assembler::Options,
) -> miette::Result<(Built, PathBuf)> {
    let built = build_with(project, spec, given)?;
    let dir = project.target_dir();
    std::fs::create_dir_all(&dir)
        .map_err(|e| miette::miette!("cannot create {}: {e}", dir.display()))?;
    let elf = linker::Format::Elf.write(&built.linked.image)?;
    for (ext, bytes) in [
        ("elf", elf),
        ("lst", built.listing.clone().into_bytes()),
        ("map", built.linked.map().into_bytes()),
    ] {
        let path = dir.join(format!("{}.{ext}", built.name));
        std::fs::write(&path, bytes)
            .map_err(|e| miette::miette!("cannot write {}: {e}", path.display()))?;
    }
    let path = dir.join(format!("{}.elf", built.name));
    Ok((built, path))
}

impl Built {
    /// The texts its snapshots hold, by kind ([`SNAPSHOT_KINDS`]).
    pub fn snapshots(&self) -> [(&'static str, String); 4] {
        [
            (SNAPSHOT_KINDS[0], self.listing.clone()),
            (SNAPSHOT_KINDS[1], self.linked.map()),
            (SNAPSHOT_KINDS[2], self.symbols()),
            (SNAPSHOT_KINDS[3], self.bytes()),
        ]
    }

    /// The image's own symbols (not the ROM's it linked against), a line
    /// each, by address then name.
    pub fn symbols(&self) -> String {
        let rom = |name: &str, value: u32| {
            romlib::symbols::find(name).is_some_and(|s| u32::from(s.value) == value)
        };
        let mut symbols: Vec<_> = self
            .linked
            .image
            .symbols
            .iter()
            .filter(|s| !rom(&s.name, s.value))
            .collect();
        symbols.sort_by(|a, b| (a.value, &a.name).cmp(&(b.value, &b.name)));
        let mut text = String::new();
        for symbol in symbols {
            let _ = writeln!(
                text,
                "${:04X}  {}{}",
                symbol.value,
                symbol.name,
                if symbol.global { "  (global)" } else { "" }
            );
        }
        text
    }

    /// The loaded bytes as a hex dump, 16 a line, each line at its address.
    pub fn bytes(&self) -> String {
        let mut text = String::new();
        for area in &self.linked.image.areas {
            for (index, chunk) in area.bytes.chunks(16).enumerate() {
                let hex: Vec<String> = chunk.iter().map(|b| format!("{b:02X}")).collect();
                let _ = writeln!(
                    text,
                    "${:04X}  {}",
                    area.load as usize + index * 16,
                    hex.join(" ")
                );
            }
        }
        let _ = writeln!(text, "entry ${:04X}", self.linked.image.entry);
        text
    }
}
