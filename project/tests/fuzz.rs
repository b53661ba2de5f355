//! Issue 23's fuzz target for `Scorpion.toml`, the per-user file and the
//! environment: any text, and any mix of well-formed keys with hostile
//! values, is read and resolved to a project or to an error, never a
//! panic; and what is accepted keeps its promises (image names stay
//! inside the project, defines fit the assembler, nothing repeats).
//! Short in CI (`PROPTEST_CASES` runs more).

use std::collections::BTreeSet;
use std::path::Path;

use proptest::prelude::*;
use scorpion_project::{Environment, Flags, Found, Project, Resolved};

/// A value a careless or hostile user might write for any key.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("\"\"".to_owned()),
        Just("\"..\"".to_owned()),
        Just("\"../../outside\"".to_owned()),
        Just("\"/etc/passwd\"".to_owned()),
        Just("\"a/b\"".to_owned()),
        Just("\"ok\"".to_owned()),
        Just("\"src/x.s\"".to_owned()),
        Just("\"/dev/zero\"".to_owned()),
        Just("\"emu\"".to_owned()),
        Just("[]".to_owned()),
        Just("[\"src/x.s\", \"src/x.s\"]".to_owned()),
        Just("{ X = 9223372036854775807 }".to_owned()),
        Just("{ X = -9223372036854775808 }".to_owned()),
        Just("{ X = 4294967295, Y = -1 }".to_owned()),
        Just("18446744073709551615".to_owned()),
        Just("-1".to_owned()),
        Just("0".to_owned()),
        Just("9600".to_owned()),
        Just("true".to_owned()),
        Just("[\"c.rhai@ZZZZ\", \"c.rhai@10000\", \"c.rhai@9000\"]".to_owned()),
        "\"[^\"\\\\]{0,12}\"".prop_map(|s| s),
        any::<i64>().prop_map(|n| n.to_string()),
    ]
}

/// A line of a project file: a table header, a key with a value, or noise.
fn line() -> impl Strategy<Value = String> {
    let keys = prop::sample::select(vec![
        "name",
        "sources",
        "target",
        "include",
        "defines",
        "port",
        "baud",
        "cards",
        "world",
        "rom",
        "transcripts",
        "builtin_listing",
        "members",
        "bogus",
    ]);
    prop_oneof![
        3 => (keys, value()).prop_map(|(k, v)| format!("{k} = {v}")),
        1 => prop::sample::select(vec![
            "[project]", "[[image]]", "[robot]", "[tests]", "[workspace]", "[[image]", "[robot.x]",
        ])
        .prop_map(str::to_owned),
        1 => "[ -~]{0,30}",
    ]
}

fn file() -> impl Strategy<Value = String> {
    prop::collection::vec(line(), 0..14).prop_map(|lines| lines.join("\n"))
}

/// Reads `text` as a project (and `user` as the per-user file, `baud` as
/// `SCORPION_BAUD`) and checks what an accepted project promises.
fn check(text: &str, user: &str, baud: Option<String>) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().expect("a directory");
    std::fs::write(dir.path().join("Scorpion.toml"), text).expect("write");
    let user_file = dir.path().join("user.toml");
    std::fs::write(&user_file, user).expect("write");
    if let Ok(Found::Project(project)) = Found::load(dir.path()) {
        accepted(&project)?;
    }
    let env = Environment {
        port: None,
        baud,
        user_file: Some(user_file),
    };
    let _ = Resolved::resolve(&Flags::default(), &env, dir.path());
    Ok(())
}

fn accepted(project: &Project) -> Result<(), TestCaseError> {
    let mut names = BTreeSet::new();
    for image in &project.file.images {
        let name = &image.name;
        prop_assert!(!name.is_empty(), "an empty name was accepted");
        prop_assert!(
            !Path::new(name).is_absolute() && !name.contains("..") && !name.contains('/'),
            "`{name}` leaves the project"
        );
        prop_assert!(names.insert(name.clone()), "`{name}` repeats");
        prop_assert!(!image.sources.is_empty(), "`{name}` has no sources");
        for (define, value) in &image.defines {
            prop_assert!(
                assembler::DEFINE_VALUES.contains(value),
                "{define} = {value} would be truncated"
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    /// Lines of plausible keys with hostile values, in any order.
    #[test]
    fn any_project_file_is_a_project_or_an_error(text in file(), user in file()) {
        check(&text, &user, None)?;
    }

    /// Arbitrary text, and arbitrary `SCORPION_BAUD`.
    #[test]
    fn any_text_is_a_project_or_an_error(text in "\\PC{0,200}", baud in proptest::option::of("\\PC{0,12}")) {
        check(&text, "", baud)?;
    }

    /// The project below is valid: one hostile key at a time changes it.
    #[test]
    fn a_valid_project_with_one_hostile_key(key in line()) {
        let text = format!(
            "[project]\nname = \"p\"\n\n[[image]]\nname = \"p\"\nsources = [\"p.s\"]\n{key}\n\n[robot]\n{key}\n"
        );
        check(&text, &format!("[robot]\n{key}\n"), None)?;
    }
}
