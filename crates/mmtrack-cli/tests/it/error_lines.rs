//! Errors are one clean line: the file once, the record, the problem once,
//! and no raw bytes of the input (a corrupt log cannot garble the terminal).

use std::process::Output;

use super::common::{mmtrack, text};

/// Asserts a failure with exit 1 and a single `error: ` line on stderr that
/// names `path` exactly once, says the OS error at most once, repeats no
/// `: `-separated piece, and holds no control characters. Returns the line.
fn one_clean_line(out: &Output, path: &str) -> String {
    let (stdout, stderr) = text(out);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stdout.is_empty(), "{stdout}");
    let line = stderr.strip_suffix('\n').unwrap_or(&stderr);
    assert!(!line.contains('\n'), "more than one line: {stderr:?}");
    assert!(line.starts_with("error: "), "{line:?}");
    assert!(line.chars().all(|c| !c.is_control()), "control characters: {line:?}");
    assert_eq!(line.matches(path).count(), 1, "{path} not named exactly once: {line:?}");
    assert!(line.matches("(os error").count() <= 1, "OS error repeated: {line:?}");
    let pieces: Vec<&str> = line.split(": ").collect();
    for (i, piece) in pieces.iter().enumerate() {
        assert!(!pieces[i + 1..].contains(piece), "`{piece}` repeated: {line:?}");
    }
    line.to_string()
}

#[test]
fn a_missing_file_is_named_once_with_the_os_error_once() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [&[&str]; 5] = [
        &["inspect", "missing.mcap"],
        &["process", "odometry", "missing.mcap", "-o", "tables"],
        &["process", "mpc", "missing.mcap", "-o", "tables"],
        &["ingest", "poses", "missing.mcap", "--format", "tum", "-o", "out.mcap"],
        &["ingest", "nmea", "missing.mcap", "-o", "out.mcap"],
    ];
    for args in cases {
        let line = one_clean_line(&mmtrack(dir.path(), args), "missing.mcap");
        assert!(line.contains("No such file or directory"), "{args:?}: {line}");
    }
}

#[test]
fn a_directory_given_as_a_file_says_so_once() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("folder.nmea")).unwrap();
    let cases: [&[&str]; 3] = [
        &["ingest", "nmea", "folder.nmea", "-o", "out.mcap"],
        &["ingest", "poses", "folder.nmea", "--format", "tum", "-o", "out.mcap"],
        &["ingest", "cir", "folder.nmea", "--format", "decawave", "-o", "out.mcap"],
    ];
    for args in cases {
        let line = one_clean_line(&mmtrack(dir.path(), args), "folder.nmea");
        assert!(line.contains("directory"), "{args:?}: {line}");
    }
}

#[test]
fn binary_garbage_in_a_log_is_escaped_not_printed() {
    let dir = tempfile::tempdir().unwrap();
    // Control bytes (a terminal escape that would turn the screen red, NUL,
    // a carriage return) inside a field the reader quotes in its error.
    std::fs::write(dir.path().join("garbage.txt"), b"1.0 \x01\x00\x1b[31mred\r 0 0 0 0 0 1\n").unwrap();
    let out = mmtrack(dir.path(), &["ingest", "poses", "garbage.txt", "--format", "tum", "-o", "out.mcap"]);
    let line = one_clean_line(&out, "garbage.txt");
    assert!(line.contains("line 1") && line.contains(r"\x1b[31mred"), "the record and the escaped bytes: {line}");

    // Bytes that are not UTF-8 at all.
    std::fs::write(dir.path().join("binary.nmea"), b"$GPGGA,\xff\xfe\x00\x9b*00\r\n\x89PNG\x1a\n").unwrap();
    let out = mmtrack(dir.path(), &["ingest", "nmea", "binary.nmea", "-o", "out.mcap"]);
    one_clean_line(&out, "binary.nmea");
    assert!(!dir.path().join("out.mcap").exists());
}

#[test]
fn a_log_that_is_not_text_is_refused_at_its_first_line() {
    let dir = tempfile::tempdir().unwrap();
    // Like /dev/zero: no line end in the first 4 KiB. Read one line's cap,
    // not the file.
    std::fs::write(dir.path().join("zeros.nmea"), vec![0u8; 1 << 20]).unwrap();
    let out = mmtrack(dir.path(), &["ingest", "nmea", "zeros.nmea", "-o", "out.mcap"]);
    let line = one_clean_line(&out, "zeros.nmea");
    assert!(line.contains("zeros.nmea: line 1: line: longer than 4096 bytes"), "{line}");
    assert!(!dir.path().join("out.mcap").exists());
}
