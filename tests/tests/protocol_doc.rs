//! `docs/PROTOCOL.md` is the contract with the robot: these tests keep it
//! true against the reference ROM it describes. Its command tables list
//! exactly the (count, letter) pairs of the ROM's dispatch table, its name
//! tables exactly the names and addresses the ROM exports, and nothing in
//! the repository sends a reader to a contract outside it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("the workspace")
        .to_path_buf()
}

fn doc() -> String {
    std::fs::read_to_string(root().join("docs/PROTOCOL.md")).expect("docs/PROTOCOL.md")
}

/// The text of section `heading` (a `##`/`###` line) up to the next heading.
fn section<'a>(text: &'a str, heading: &str) -> &'a str {
    let start = text
        .find(heading)
        .unwrap_or_else(|| panic!("docs/PROTOCOL.md has no `{heading}`"));
    let rest = &text[start + heading.len()..];
    let end = rest.find("\n#").unwrap_or(rest.len());
    &rest[..end]
}

/// The table rows of `text`, split into trimmed cells (header and rule
/// rows left out).
fn rows(text: &str) -> Vec<Vec<String>> {
    let lines: Vec<&str> = text.lines().filter(|l| l.starts_with('|')).collect();
    lines
        .iter()
        .skip(2)
        .map(|line| {
            line.trim_matches('|')
                .split('|')
                .map(|cell| cell.trim().to_string())
                .collect()
        })
        .collect()
}

/// The ROM's dispatch table, read from the linked ROM: 4-byte entries
/// (count, letter, handler) from `commands` up to a zero count.
fn rom_commands() -> BTreeSet<(u8, char)> {
    let rom = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("the ROM parses");
    let table = rom.symbol("commands").expect("the ROM's dispatch table");
    let mut pairs = BTreeSet::new();
    for entry in 0.. {
        let at = table + entry * 4;
        let count = rom.byte_at(at).expect("in the ROM");
        if count == 0 {
            break;
        }
        let letter = rom.byte_at(at + 1).expect("in the ROM");
        assert!(pairs.insert((count, char::from(letter))), "a pair twice");
    }
    pairs
}

/// Every `/N<letter>...` command written in backticks in the first column.
fn commands_in(table: &str) -> BTreeSet<(u8, char)> {
    let mut pairs = BTreeSet::new();
    for row in rows(table) {
        for form in row[0].split('`').skip(1).step_by(2) {
            let mut chars = form.chars();
            assert_eq!(chars.next(), Some('/'), "a command starts with `/`: {form}");
            let count = chars.next().and_then(|c| c.to_digit(10)).expect("a count");
            let letter = chars.next().expect("a letter");
            // The count says how many bytes follow: the form shows them.
            assert_eq!(
                form.len() - 2,
                count as usize,
                "`{form}` does not have {count} bytes after its count"
            );
            pairs.insert((count as u8, letter));
        }
    }
    pairs
}

#[test]
fn the_command_tables_are_the_roms_dispatch_table() {
    let rom = rom_commands();
    let text = doc();
    let commands = section(&text, "## 2. The ROM's commands");
    let (instructions, questions) = commands
        .split_once("Questions answer:")
        .expect("the questions table");
    let instructions = commands_in(instructions);
    let questions = commands_in(questions.split("\n###").next().unwrap_or(""));
    let listed: BTreeSet<(u8, char)> = instructions.union(&questions).copied().collect();
    assert_eq!(
        listed, rom,
        "the command tables against the ROM's dispatch table"
    );
    // And each question is one the host library expects an answer to.
    for &(count, letter) in &questions {
        let sample = match (count, letter) {
            (7, 'R') => "/7R000001".to_string(),
            _ => format!("/{count}{letter}"),
        };
        let command = romlib::protocol::Command::parse(sample.as_bytes()).expect(&sample);
        assert!(command.is_question(), "{sample} is listed as a question");
    }

    let owned = section(&text, "### The pairs free for extensions");
    let mut pairs = BTreeSet::new();
    for row in rows(owned) {
        let count: u8 = row[0].parse().expect("a count");
        for letter in row[1].split_whitespace() {
            pairs.insert((count, letter.chars().next().expect("a letter")));
        }
    }
    assert_eq!(pairs, rom, "the table of owned pairs against the ROM");
}

/// The host library's one table of commands is the ROM's dispatch table,
/// entry by entry, and its forms are the forms docs/PROTOCOL.md shows.
#[test]
fn the_host_librarys_command_table_is_the_roms() {
    let rom = linker::Image::parse("scorpion-rom.elf", romlib::ROM_ELF).expect("the ROM parses");
    let table = rom.symbol("commands").expect("the ROM's dispatch table");
    let mut dispatched = Vec::new();
    for entry in 0.. {
        let at = table + entry * 4;
        let count = rom.byte_at(at).expect("in the ROM");
        if count == 0 {
            break;
        }
        dispatched.push((count, rom.byte_at(at + 1).expect("in the ROM")));
    }
    let listed: Vec<(u8, u8)> = romlib::protocol::COMMANDS
        .iter()
        .map(|spec| (spec.count, spec.letter))
        .collect();
    assert_eq!(listed, dispatched, "COMMANDS against the ROM's `commands`");

    let text = doc();
    let commands = section(&text, "## 2. The ROM's commands");
    let forms: BTreeSet<String> = rows(commands)
        .iter()
        .flat_map(|row| {
            row[0]
                .split('`')
                .skip(1)
                .step_by(2)
                .map(str::to_owned)
                .collect::<Vec<_>>()
        })
        .collect();
    let ours: BTreeSet<String> = romlib::protocol::COMMANDS
        .iter()
        .map(|spec| spec.form.to_owned())
        .collect();
    assert_eq!(
        forms, ours,
        "the forms in docs/PROTOCOL.md against COMMANDS"
    );
}

#[test]
fn the_name_tables_are_the_roms_exported_symbols() {
    let text = doc();
    let mut documented: BTreeMap<String, u16> = BTreeMap::new();
    for heading in ["### Services", "### Names in RAM"] {
        for row in rows(section(&text, heading)) {
            let name = row[0].trim_matches('`').to_string();
            let address = row[1].trim_matches('`').trim_start_matches('$');
            let value = u16::from_str_radix(address, 16)
                .unwrap_or_else(|_| panic!("{name}: `{}` is not an address", row[1]));
            assert!(
                documented.insert(name.clone(), value).is_none(),
                "{name} twice"
            );
        }
    }
    let exported: BTreeMap<String, u16> = romlib::symbols::ALL
        .iter()
        .map(|symbol| (symbol.name.to_string(), symbol.value))
        .collect();
    assert_eq!(
        documented, exported,
        "the documented names against the ROM's exports"
    );
}

/// Every file of the repository that a reader follows (sources, docs,
/// examples, scripts), skipping build output and snapshots.
fn repository_files(dir: &Path, into: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("a directory") {
        let path = entry.expect("an entry").path();
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        if name.starts_with('.') && name != ".ci"
            || ["target", "snapshots"].contains(&name.as_ref())
        {
            continue;
        }
        if path.is_dir() {
            repository_files(&path, into);
        } else if ["rs", "s", "inc", "md", "toml", "sh", "expect"]
            .iter()
            .any(|ext| path.extension().is_some_and(|e| e == *ext))
        {
            into.push(path);
        }
    }
}

#[test]
fn every_reference_to_the_contract_points_into_the_repository() {
    let mut files = Vec::new();
    repository_files(&root(), &mut files);
    assert!(files.len() > 100, "only {} files found", files.len());
    // Spelled in two halves so that this file does not match itself: the
    // team's old notes and the directory beside the clone they lived in.
    let outside = [["PLATFORM", ".md"].concat(), ["../", "shared/"].concat()];
    let offenders: Vec<String> = files
        .iter()
        .filter(|path| {
            std::fs::read_to_string(path)
                .is_ok_and(|text| outside.iter().any(|o| text.contains(o.as_str())))
        })
        .map(|path| {
            path.strip_prefix(root())
                .unwrap_or(path)
                .display()
                .to_string()
        })
        .collect();
    assert!(
        offenders.is_empty(),
        "these files send readers outside the repository (to {outside:?}); point them at docs/PROTOCOL.md or CONTRIBUTING.md: {offenders:?}"
    );
}
