//! Fixtures in `data/` are regenerable: a fresh generation equals the committed bytes.

use super::common::{files, mmtrack, root};

#[test]
fn demo_fixture_folder_regenerates_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = root().join("data/demo/fixture-scenario.toml");
    let out = mmtrack(
        dir.path(),
        &[
            "simulate",
            "radar",
            "--scenario",
            scenario.to_str().unwrap(),
            "--format",
            "oxford",
            "-o",
            "fresh",
            "--quiet",
        ],
    );
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let committed = root().join("data/demo/oxford-demo");
    let fresh = dir.path().join("fresh");
    assert_eq!(files(&committed), files(&fresh));
    for relative in files(&committed) {
        assert!(
            std::fs::read(committed.join(&relative)).unwrap() == std::fs::read(fresh.join(&relative)).unwrap(),
            "{} differs from a fresh generation; regenerate with the command in data/demo/fixture-scenario.toml",
            relative.display()
        );
    }
}
