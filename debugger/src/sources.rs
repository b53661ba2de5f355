//! The source files the images name, read when a front end shows a line
//! (the monitor's listings and stops, the DAP server's `source` and
//! `disassemble`): relative to the project's root; `scorpion.inc` built in.

use std::path::PathBuf;

/// The source files the images name, read when shown: relative to the
/// project's root (or the current directory); `scorpion.inc` built in.
#[derive(Debug)]
pub struct Sources {
    /// Where the images' source paths start.
    pub root: PathBuf,
    files: std::collections::HashMap<String, Option<Vec<String>>>,
}

impl Sources {
    /// Sources relative to `root`.
    #[must_use]
    pub fn new(root: PathBuf) -> Sources {
        Sources {
            root,
            files: std::collections::HashMap::new(),
        }
    }

    /// Line `line` (from 1) of `file`, if it can be read.
    pub fn line(&mut self, file: &str, line: u32) -> Option<String> {
        let root = &self.root;
        let lines = self.files.entry(file.to_owned()).or_insert_with(|| {
            let text = if file == "scorpion.inc" && !root.join(file).is_file() {
                Some(romlib::SCORPION_INC.to_owned())
            } else {
                hostfs::read_text(root.join(file), hostfs::TEXT).ok()
            };
            text.map(|t| t.lines().map(str::to_owned).collect())
        });
        lines
            .as_ref()?
            .get(usize::try_from(line).ok()?.checked_sub(1)?)
            .cloned()
    }
}
