//! Settings that cannot be used are refused where they were written, by
//! the resolution itself (found by a hostile tester: `SCORPION_BAUD=0` and
//! an empty `port` in the per-user file passed `scorpion config`).

use scorpion_project::{Environment, Error, Flags, Resolved};

fn resolve(baud: Option<&str>, user: &str) -> Result<Resolved, Error> {
    let dir = tempfile::tempdir().expect("a directory");
    let user_file = dir.path().join("config.toml");
    std::fs::write(&user_file, user).expect("write");
    let env = Environment {
        port: None,
        baud: baud.map(str::to_owned),
        user_file: Some(user_file),
    };
    Resolved::resolve(&Flags::default(), &env, dir.path())
}

#[test]
fn a_rate_of_zero_is_refused_where_it_was_written() {
    let error = resolve(Some("0"), "").expect_err("a rate of 0");
    let said = error.to_string();
    assert!(
        said.contains("baud") && said.contains("SCORPION_BAUD"),
        "{said}"
    );
    let error = resolve(None, "[robot]\nbaud = 0\n").expect_err("a rate of 0");
    let said = error.to_string();
    assert!(
        said.contains("baud") && said.contains("config.toml"),
        "{said}"
    );
    assert!(resolve(Some("9600"), "").is_ok());
}

#[test]
fn an_empty_port_is_refused_where_it_was_written() {
    let error = resolve(None, "[robot]\nport = \"\"\n").expect_err("an empty port");
    let said = error.to_string();
    assert!(
        said.contains("port") && said.contains("config.toml"),
        "{said}"
    );
    assert!(resolve(None, "[robot]\nport = \"emu\"\n").is_ok());
}

/// hostile10 F15: `--baud 1` and `4000000000` were taken, and went on to
/// a silent line; the robot's 6551 runs at its standard rates only.
#[test]
fn a_rate_the_robots_acia_cannot_run_at_is_refused_where_it_was_written() {
    for rate in ["1", "4000000000", "38400", "9000"] {
        let error = resolve(Some(rate), "").expect_err("refused");
        let said = error.to_string();
        assert!(
            said.contains("SCORPION_BAUD") && said.contains("6551"),
            "{rate}: {said}"
        );
    }
    let error = resolve(None, "[robot]\nbaud = 115200\n").expect_err("refused");
    assert!(error.to_string().contains("config.toml"), "{error}");
    for rate in ["300", "2400", "19200"] {
        assert!(resolve(Some(rate), "").is_ok(), "{rate}");
    }
}
