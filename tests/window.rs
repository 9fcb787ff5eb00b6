//! The viewer in a real window under Xvfb: open, render, resize, render, close, with
//! validation clean.

mod common;

use std::process::Command;

use common::{assert_clean, stderr, temp_dir};

#[test]
fn viewer_opens_resizes_and_closes_under_xvfb() {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        eprintln!("skipped: xvfb-run is not installed (Debian: apt-get install xvfb xauth)");
        return;
    }
    let shot = temp_dir("window").join("view.png");
    let output = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_voxcone"))
        .args([
            "view",
            "--frames",
            "30",
            "--size",
            "320x240",
            "--resize-to",
            "400x300",
        ])
        .arg("--screenshot")
        .arg(&shot)
        .env("VOXCONE_VALIDATION", "1")
        .env("RUST_LOG", "info")
        .output()
        .expect("running xvfb-run");
    eprintln!("{}", stderr(&output));
    assert_clean(&output);
    let err = stderr(&output);
    assert!(err.contains("resizing the window to 400x300"), "{err}");
    let (image, _) = voxcone::imageio::load_rgb(&shot).unwrap();
    assert_eq!(
        (image.width, image.height),
        (400, 300),
        "the swapchain did not follow the resize"
    );
    assert!(
        image.data.iter().any(|&v| v > 0.1),
        "the window shows nothing"
    );
}
