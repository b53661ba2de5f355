//! The reader against what a name can point at: a file, a missing one, a
//! directory, a FIFO with no writer, `/dev/zero`, a file over its limit.

use std::path::Path;
use std::sync::mpsc;
use std::time::Duration;

use super::*;

/// Runs `read` on another thread and fails the test if it has not
/// returned within two seconds (a FIFO opened for reading blocks for
/// ever), instead of hanging the test run.
fn read_within_two_seconds(path: &Path, limit: Limit) -> Result<Vec<u8>, Error> {
    let (sender, receiver) = mpsc::channel();
    let owned = path.to_path_buf();
    std::thread::spawn(move || {
        let _ = sender.send(read(&owned, limit));
    });
    receiver
        .recv_timeout(Duration::from_secs(2))
        .unwrap_or_else(|_| panic!("reading {} blocked", path.display()))
}

#[test]
fn a_regular_file_is_read_whole() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("a.s");
    std::fs::write(&path, "nop\n").expect("written");
    assert_eq!(read(&path, TEXT).expect("read"), b"nop\n");
    assert_eq!(read_text(&path, TEXT).expect("read"), "nop\n");
    assert_eq!(check(&path, TEXT).expect("checked"), 4);
}

#[test]
fn a_missing_file_is_not_found_and_stays_so_as_an_io_error() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("missing.s");
    let error = read(&path, TEXT).expect_err("nothing there");
    assert!(error.is_not_found(), "{error}");
    assert_eq!(error.path(), path);
    let io: io::Error = error.into();
    assert_eq!(io.kind(), io::ErrorKind::NotFound);
}

#[test]
fn a_directory_is_refused() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let error = read(dir.path(), TEXT).expect_err("a directory");
    assert!(
        matches!(
            error,
            Error::NotAFile {
                what: "a directory",
                ..
            }
        ),
        "{error}"
    );
}

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_without_blocking() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("pipe");
    let made = std::process::Command::new("mkfifo")
        .arg(&path)
        .status()
        .expect("mkfifo runs");
    assert!(made.success(), "mkfifo {}", path.display());
    let error = read_within_two_seconds(&path, BINARY).expect_err("a FIFO");
    assert!(
        matches!(
            error,
            Error::NotAFile {
                what: "a FIFO (named pipe)",
                ..
            }
        ),
        "{error}"
    );
    let text = error.to_string();
    assert!(text.contains("pipe") && text.contains("FIFO"), "{text}");
    // The message survives the trip through io::Error, not as "not found".
    let io: io::Error = error.into();
    assert_ne!(io.kind(), io::ErrorKind::NotFound);
    assert!(io.to_string().contains("FIFO"), "{io}");
}

#[cfg(unix)]
#[test]
fn dev_zero_is_refused_as_a_device() {
    let error = read_within_two_seconds(Path::new("/dev/zero"), TEXT).expect_err("a device");
    assert!(
        matches!(
            error,
            Error::NotAFile {
                what: "a character device",
                ..
            }
        ),
        "{error}"
    );
    assert_eq!(
        error.to_string(),
        "/dev/zero: a character device, not a regular file"
    );
}

#[test]
fn a_file_over_its_limit_is_refused_naming_both() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("big.bin");
    std::fs::write(&path, vec![0u8; 70_000]).expect("written");
    let error = read(&path, RAW_IMAGE).expect_err("over 64 KiB");
    assert!(
        matches!(
            error,
            Error::TooLarge {
                size: 70_000,
                limit: 65_536,
                ..
            }
        ),
        "{error}"
    );
    assert!(
        error
            .to_string()
            .ends_with("big.bin: 70000 bytes, over the 64 KiB limit for a raw 6502 image"),
        "{error}"
    );
    // Exactly at the limit is fine.
    std::fs::write(&path, vec![0u8; 65_536]).expect("written");
    assert_eq!(read(&path, RAW_IMAGE).expect("at the limit").len(), 65_536);
}

#[cfg(target_os = "linux")]
#[test]
fn a_file_whose_metadata_says_zero_is_still_bounded() {
    // /proc files report a length of 0 and can be longer than that.
    let tiny = Limit::new(8, "a test file");
    let error = read(Path::new("/proc/self/status"), tiny).expect_err("longer than 8 bytes");
    assert!(
        error
            .to_string()
            .contains("more than 8 bytes, the limit for a test file"),
        "{error}"
    );
}

#[test]
fn text_that_is_not_utf8_names_the_byte() {
    let dir = tempfile::tempdir().expect("a temporary directory");
    let path = dir.path().join("latin1.s");
    std::fs::write(&path, b"lda #1 ; caf\xe9\n").expect("written");
    let error = read_text(&path, TEXT).expect_err("not UTF-8");
    assert!(
        matches!(error, Error::NotText { offset: 12, .. }),
        "{error}"
    );
}

#[test]
fn sizes_read_as_people_write_them() {
    assert_eq!(limit::bytes_text(16 << 20), "16 MiB");
    assert_eq!(limit::bytes_text(1 << 16), "64 KiB");
    assert_eq!(limit::bytes_text(70_000), "70000 bytes");
    assert_eq!(limit::bytes_text(1), "1 byte");
}

/// A file written over keeps its mode; a new one is not owner-only (the
/// temporary file's mode), unless the umask says so.
#[cfg(unix)]
#[test]
fn a_file_written_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt as _;
    let dir = tempfile::tempdir().expect("a directory");
    let old = dir.path().join("old.svg");
    std::fs::write(&old, b"before").expect("written");
    std::fs::set_permissions(&old, std::fs::Permissions::from_mode(0o640)).expect("chmod");
    write(&old, b"after").expect("written over");
    let mode = std::fs::metadata(&old).expect("there").permissions().mode() & 0o777;
    assert_eq!(mode, 0o640);
    let new = dir.path().join("new.svg");
    write(&new, b"new").expect("written");
    let plain = dir.path().join("plain.svg");
    std::fs::write(&plain, b"plain").expect("written");
    let mode = |path: &Path| std::fs::metadata(path).expect("there").permissions().mode() & 0o777;
    assert_eq!(
        mode(&new),
        mode(&plain),
        "as a plain create under this umask"
    );
}
