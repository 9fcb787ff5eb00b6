//! `--gi dense` against path-traced ground truth and the colour-bleeding invariant; every
//! render runs with validation and fails on any message.

mod common;

use std::path::Path;

use common::{assert_clean, shared, temp_dir, voxcone};
use voxcone::compare::{compare, CompareOptions};
use voxcone::imageio::load_rgb;

fn render(scene: &Path, gi: &str, out: &Path) {
    let output = voxcone(&[
        "render",
        scene.to_str().unwrap(),
        "--gi",
        gi,
        "--size",
        "256x256",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_clean(&output);
}

/// Mean red minus green of the floor strip next to the left (red) and right (green) walls.
fn floor_tint(path: &Path) -> (f32, f32) {
    let (image, _) = load_rgb(path).unwrap();
    let w = image.width as usize;
    let strip = |x0: usize, x1: usize| {
        let mut sum = 0.0;
        let mut count = 0.0;
        for y in 215..240 {
            for x in x0..x1 {
                let p = &image.data[(y * w + x) * 3..(y * w + x) * 3 + 3];
                sum += p[0] - p[1];
                count += 1.0;
            }
        }
        sum / count
    };
    (strip(40, 60), strip(196, 216))
}

#[test]
fn cornell_point_dense_gi() {
    let Some(shared) = shared() else { return };
    let reference = shared.join("reference/cornell_point.exr");
    let scene = shared.join("reference/cornell_point.scene.json");
    let dir = temp_dir("dense_gi");
    let (off, dense) = (dir.join("off.exr"), dir.join("dense.exr"));
    render(&scene, "off", &off);
    render(&scene, "dense", &dense);

    let flip_off = compare(&reference, &off, &CompareOptions::default())
        .unwrap()
        .flip_ldr;
    let flip_dense = compare(&reference, &dense, &CompareOptions::default())
        .unwrap()
        .flip_ldr;
    eprintln!("LDR-FLIP against cornell_point: --gi off {flip_off:.3}, --gi dense {flip_dense:.3}");
    // Measured 0.591 and 0.206; the target for dense is 0.10 (not reached yet).
    assert!(
        flip_dense < flip_off - 0.25,
        "indirect light does not bring the image closer"
    );

    // Colour bleeding: the floor by the red wall is redder than by the green wall, and more
    // so with indirect light than without.
    let (red_off, green_off) = floor_tint(&off);
    let (red_dense, green_dense) = floor_tint(&dense);
    eprintln!("floor red-green: off {red_off:.4} / {green_off:.4}, dense {red_dense:.4} / {green_dense:.4}");
    assert!(
        red_dense - green_dense > 0.0,
        "no red bleeding onto the floor"
    );
    assert!(
        red_dense - green_dense > red_off - green_off + 0.005,
        "indirect light adds no colour bleeding"
    );
}
