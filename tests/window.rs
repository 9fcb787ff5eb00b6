//! The viewer in a real window under Xvfb: open, render, resize, render, close, with
//! validation clean.

mod common;

use std::ffi::OsStr;
use std::process::{Command, Output};

use common::{assert_clean, stderr, temp_dir};

/// Runs `voxcone view` with `args` in a virtual screen, validation on; `None` (saying why)
/// without xvfb-run.
fn view_under_xvfb(args: &[&OsStr]) -> Option<Output> {
    if Command::new("xvfb-run").arg("--help").output().is_err() {
        eprintln!("skipped: xvfb-run is not installed (Debian: apt-get install xvfb xauth)");
        return None;
    }
    let output = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1024x768x24"])
        .arg(env!("CARGO_BIN_EXE_voxcone"))
        .arg("view")
        .args(args)
        .env("VOXCONE_VALIDATION", "1")
        .env("RUST_LOG", "info")
        .output()
        .expect("running xvfb-run");
    eprintln!("{}", stderr(&output));
    assert_clean(&output);
    Some(output)
}

#[test]
fn viewer_opens_resizes_and_closes_under_xvfb() {
    let shot = temp_dir("window").join("view.png");
    let args = [
        "--frames",
        "30",
        "--size",
        "320x240",
        "--resize-to",
        "400x300",
        "--screenshot",
    ];
    let mut args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
    args.push(shot.as_os_str());
    let Some(output) = view_under_xvfb(&args) else {
        return;
    };
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

/// `view --gi path` accumulates while nothing moves and starts again when a light moves:
/// after 8 frames of 64 samples per pixel (a 64x64 window), 512 samples in a still scene,
/// 64 with an orbiting light.
#[test]
fn path_tracer_accumulates_until_a_light_moves() {
    let dir = temp_dir("window_path");
    let obj = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell.obj");
    for (orbit, expected) in [
        ("", 512),
        (
            "orbit = { center = [0, 1, 0], axis = [0, 1, 0], period_s = 8 }\n",
            64,
        ),
    ] {
        let scene = dir.join("scene.toml");
        std::fs::write(
            &scene,
            format!(
                "[camera]\nposition = [0.0, 1.0, 3.9]\ntarget = [0.0, 1.0, 0.0]\nfov_y_deg = 39.3\n\
                 [[mesh]]\npath = {obj:?}\n\
                 [[light]]\nkind = \"point\"\nposition = [0.3, 1.5, 0.0]\nintensity = [3.0, 3.0, 3.0]\n{orbit}"
            ),
        )
        .unwrap();
        let args = [
            "--gi", "path", "--spp", "100000", "--frames", "8", "--size", "64x64",
        ];
        let mut args: Vec<&OsStr> = args.iter().map(OsStr::new).collect();
        args.insert(0, scene.as_os_str());
        let Some(output) = view_under_xvfb(&args) else {
            return;
        };
        let err = stderr(&output);
        let shown = format!("the last frame showed {expected} of 100000 samples per pixel");
        assert!(
            err.contains(&shown),
            "{orbit:?}: expected {shown:?} in {err}"
        );
    }
}
