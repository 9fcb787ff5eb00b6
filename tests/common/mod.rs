//! Helpers shared by the integration tests.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `../shared` beside the repository, or `None` (with the reason printed) when absent.
pub fn shared() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared");
    if dir.join("reference").is_dir() && dir.join("scenes").is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "skipped: {} is absent (reference images and scenes live there)",
            dir.display()
        );
        None
    }
}

/// A fresh directory for a test's files.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs the voxcone binary with validation (incl. synchronization validation) on.
pub fn voxcone(args: &[&str]) -> Output {
    let output = Command::new(env!("CARGO_BIN_EXE_voxcone"))
        .args(args)
        .env("VOXCONE_VALIDATION", "1")
        .env("RUST_LOG", "info")
        .output()
        .expect("running voxcone");
    eprintln!(
        "voxcone {}\n--- stdout\n{}\n--- stderr\n{}",
        args.join(" "),
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Asserts a command succeeded and the validation layer said nothing.
pub fn assert_clean(output: &Output) {
    let err = stderr(output);
    assert!(output.status.success(), "voxcone failed: {err}");
    assert!(
        err.contains("validation: no messages"),
        "validation was not on or not clean: {err}"
    );
}

/// Renders `scene` at 256x256 to `out` with the options `extra`, validation clean.
pub fn render_256(scene: &Path, extra: &[&str], out: &Path) {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "--size",
        "256x256",
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    assert_clean(&voxcone(&args));
}
