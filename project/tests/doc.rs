//! docs/PROJECT.md against the schema: its full Scorpion.toml, workspace
//! and per-user file deserialize with the real structs (every documented
//! key exists), set exactly the keys the structs have (every key is
//! documented), and every environment variable the resolution reads is in
//! its table.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use scorpion_project::file::{WorkspaceFile, WorkspaceSpec};
use scorpion_project::{
    ImageSpec, Meta, ProjectFile, RobotSpec, TestsSpec, UserRobot, UserSettings,
};

fn doc() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/PROJECT.md"))
        .expect("docs/PROJECT.md")
}

/// The first ```toml block after `heading`.
fn block(doc: &str, heading: &str) -> String {
    let section = &doc[doc.find(heading).expect(heading)..];
    let start = section.find("```toml\n").expect("a toml block") + "```toml\n".len();
    let end = start + section[start..].find("```").expect("the block's end");
    section[start..end].to_owned()
}

/// Keys whose tables are the user's names (defines), not the schema's.
const MAPS: [&str; 2] = ["defines", "budgets"];

/// Every key path of `value` (`image.name`), into the first element of
/// arrays of tables.
fn keys(value: &serde_json::Value, prefix: &str, out: &mut BTreeSet<String>) {
    match value {
        serde_json::Value::Object(map) => {
            for (key, inner) in map {
                let path = if prefix.is_empty() {
                    key.clone()
                } else {
                    format!("{prefix}.{key}")
                };
                out.insert(path.clone());
                if !MAPS.contains(&key.as_str()) {
                    keys(inner, &path, out);
                }
            }
        }
        serde_json::Value::Array(items) => {
            if let Some(first) = items.first() {
                keys(first, prefix, out);
            }
        }
        _ => {}
    }
}

fn key_set<T: serde::Serialize>(value: &T) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    keys(
        &serde_json::to_value(value).expect("serializes"),
        "",
        &mut out,
    );
    out
}

fn toml_keys(text: &str) -> BTreeSet<String> {
    let value: toml::Value = toml::from_str(text).expect("the doc's block is TOML");
    key_set(&value)
}

/// Every field of every struct set: a struct literal without `..`, so a
/// new field fails to compile here until it is added (and documented).
fn everything() -> ProjectFile {
    ProjectFile {
        project: Meta { name: "p".into() },
        images: vec![ImageSpec {
            name: "i".into(),
            sources: vec!["i.s".into()],
            target: "scorpion-ext".into(),
            include: vec!["inc".into()],
            defines: BTreeMap::from([("X".into(), 1)]),
        }],
        robot: RobotSpec {
            port: Some("emu".into()),
            baud: Some(9600),
            cards: vec!["c.rhai".into()],
            world: Some("w.rhai".into()),
            rom: Some("r.elf".into()),
        },
        tests: TestsSpec {
            transcripts: vec!["t.expect".into()],
            builtin_listing: true,
        },
        budgets: BTreeMap::from([("/2A".into(), 3000)]),
    }
}

#[test]
fn the_documented_project_file_sets_every_key_the_schema_has() {
    let text = block(&doc(), "## Scorpion.toml");
    let parsed: ProjectFile = toml::from_str(&text).expect("the doc's file is a valid project");
    assert!(!parsed.images.is_empty());
    assert_eq!(toml_keys(&text), key_set(&everything()));
}

#[test]
fn the_documented_workspace_and_user_file_set_every_key() {
    let doc = doc();
    let workspace = block(&doc, "### A workspace");
    let _: WorkspaceFile = toml::from_str(&workspace).expect("a valid workspace");
    let all = WorkspaceFile {
        workspace: WorkspaceSpec {
            members: vec!["m".into()],
        },
    };
    assert_eq!(toml_keys(&workspace), key_set(&all));

    let user = block(&doc, "## The per-user file");
    let _: UserSettings = toml::from_str(&user).expect("a valid per-user file");
    let all = UserSettings {
        robot: UserRobot {
            port: Some("emu".into()),
            baud: Some(9600),
        },
    };
    assert_eq!(toml_keys(&user), key_set(&all));
}

#[test]
fn every_variable_the_resolution_reads_is_documented() {
    let doc = doc();
    let section = &doc[doc.find("## The environment").expect("the section")..];
    for name in scorpion_project::resolve::VARIABLES {
        assert!(section.contains(&format!("| `{name}` |")), "{name}");
    }
}
