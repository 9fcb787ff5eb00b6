//! `--gi octree` against `--gi dense` and the path-traced ground truth; every render runs with
//! validation and fails on any message.

mod common;

use std::path::Path;

use common::{render_256 as render, shared, stderr, temp_dir, voxcone, TEST_OCTREE_DEPTH};
use voxcone::compare::{compare, CompareOptions};
use voxcone::imageio::load_rgb;

fn flip(reference: &Path, test: &Path) -> f32 {
    compare(reference, test, &CompareOptions::default())
        .unwrap()
        .flip_ldr
}

/// The octree at depth 6 and the dense grid at 64³ give the same picture of the Cornell
/// box, and the octree's is at least as close to the path-traced one: with the default
/// lookups, and with `--snapped-cones`, whose reads the octree's bricks make too, with
/// the cells' planes (kept by the bricks as by the dense grid) and without.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn octree_agrees_with_dense_grid() {
    for extra in [
        &[][..],
        &["--snapped-cones", "--no-plane-occlusion"][..],
        &["--snapped-cones"][..],
    ] {
        octree_agrees_with_dense_grid_with(extra);
    }
}

fn octree_agrees_with_dense_grid_with(extra: &[&str]) {
    let shared = shared();
    let reference = shared.join("reference/cornell_point.exr");
    let scene = shared.join("reference/cornell_point.scene.json");
    let dir = temp_dir("octree_gi");
    let (octree, dense) = (dir.join("octree.exr"), dir.join("dense.exr"));
    render(
        &scene,
        &[&["--gi", "octree", "--octree-depth", "6"], extra].concat(),
        &octree,
    );
    render(
        &scene,
        &[&["--gi", "dense", "--voxels", "64"], extra].concat(),
        &dense,
    );
    let between = flip(&dense, &octree);
    let (flip_octree, flip_dense) = (flip(&reference, &octree), flip(&reference, &dense));
    eprintln!(
        "{extra:?}: LDR-FLIP octree vs dense {between:.6}; against cornell_point: octree \
         {flip_octree:.7}, dense {flip_dense:.7}"
    );
    // Measured 1.7e-5 to 2.1e-5, and 0.1325243-0.1325253 against 0.1325251: both average the same
    // exact fragment sums, and the frame after the octree's build stores its radiance
    // exactly, as the dense grid does. (0.0019 while the dense grid kept a running RGBA8
    // average and the octree stored only changes beyond 1/512; the issue asks for 0.03.)
    // What is left is the sampler's rounding where the bricks land (see below).
    assert!(
        between <= 0.0005,
        "octree and dense differ: LDR-FLIP {between}"
    );
    assert!(
        flip_octree <= flip_dense + 1e-5,
        "octree {flip_octree} worse than dense {flip_dense}"
    );
}

/// With the lattice of 72 cones the octree at depth 8 and the dense grid at 256³ give
/// the same picture of the built-in box. Each lattice cone's lookups descend the octree
/// and may search neighbouring nodes, in loops, and lavapipe ends every loop of an
/// invocation after 65535 iterations of all of them together: traced in one dispatch the
/// octree's picture lost light in blocks (LDR-FLIP 0.045 against the dense grid's; 0.29
/// on `cornell_area`), shared out over dispatches of 24 cones it loses none (measured 0
/// and 4.6e-5: where the bricks land varies). The image is small and the bounce single: the loss is per traced pixel.
#[test]
fn octree_agrees_with_dense_grid_at_depth_8_with_the_lattice() {
    let dir = temp_dir("octree_lattice");
    let (octree, dense) = (dir.join("octree.exr"), dir.join("dense.exr"));
    let scene = voxcone::cli::default_scene();
    let common = ["--size", "64x64", "--bounces", "1", "--lattice-cones", "72"];
    common::render(
        &scene,
        &[&common[..], &["--gi", "octree", "--octree-depth", "8"]].concat(),
        &octree,
    );
    common::render(
        &scene,
        &[&common[..], &["--gi", "dense", "--voxels", "256"]].concat(),
        &dense,
    );
    let between = flip(&dense, &octree);
    eprintln!("LDR-FLIP octree at depth 8 vs dense at 256³, lattice of 72: {between:.6}");
    assert!(
        between <= 0.0005,
        "octree and dense differ: LDR-FLIP {between}"
    );
}

/// Two renders of the same static frame agree. The voxels' values do not depend on the
/// order of the GPU's atomic operations (integer sums), but where a brick lands in its
/// pool does, and the sampler's fixed-point texel coordinates then round differently: a
/// few pixels differ by a few parts in ten thousand (measured: 140 of 65,536 pixels, at
/// most 4.2e-4 of the pixel's value).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn octree_renders_are_deterministic() {
    let shared = shared();
    let scene = shared.join("reference/cornell_point.scene.json");
    let dir = temp_dir("octree_determinism");
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    let octree = ["--gi", "octree", "--octree-depth", TEST_OCTREE_DEPTH];
    render(&scene, &octree, &a);
    render(&scene, &octree, &b);
    let (a, b) = (load_rgb(&a).unwrap().0.data, load_rgb(&b).unwrap().0.data);
    let worst = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs() / x.abs().max(1e-3))
        .fold(0.0f32, f32::max);
    let differing = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    eprintln!(
        "{differing} of {} values differ, by at most {worst:.2e} relative",
        a.len()
    );
    assert!(worst <= 2e-3, "renders differ by {worst} relative");
}

/// Settings the octree cannot take are refused with the reason, before any GPU work
/// (`svo`, the technique's old name, still selects it).
#[test]
fn octree_settings_are_checked() {
    let dir = temp_dir("octree_settings");
    let out = dir.join("x.png");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &str); 3] = [
        (&["--gi", "svo", "--octree-depth", "5"], "between 6 and 10"),
        (
            &["--gi", "dense", "--octree-depth", "7"],
            "needs --gi octree",
        ),
        (
            &["--gi", "dense", "--debug-view", "octree-nodes"],
            "needs --gi octree",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["render", "-o", out];
        args.extend_from_slice(extra);
        let output = voxcone(&args);
        assert!(!output.status.success(), "{extra:?} was accepted");
        let err = stderr(&output);
        assert!(err.contains(expected), "{extra:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

/// The octree debug view draws occupied nodes: on the Cornell box at level 2 (nodes of
/// 8^3 voxels) most of the image is covered, in more than a few colours.
#[test]
fn octree_node_view_draws_nodes() {
    let dir = temp_dir("octree_nodes");
    let out = dir.join("nodes.png");
    render(
        &voxcone::cli::default_scene(),
        &[
            "--gi",
            "octree",
            "--octree-depth",
            TEST_OCTREE_DEPTH,
            "--debug-view",
            "octree-nodes",
            "--debug-level",
            "2",
        ],
        &out,
    );
    let (image, _) = load_rgb(&out).unwrap();
    let pixels: Vec<[u8; 3]> = image
        .data
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]].map(|c| (c * 255.0).round() as u8))
        .collect();
    let covered = pixels.iter().filter(|p| **p != [0, 0, 0]).count();
    let colours: std::collections::HashSet<_> = pixels.iter().collect();
    eprintln!(
        "{} of {} pixels covered, {} colours",
        covered,
        pixels.len(),
        colours.len()
    );
    assert!(covered > pixels.len() * 3 / 4);
    assert!(colours.len() > 50);
}

/// Frames of the octree do not grow the process's memory. On lavapipe (Mesa 22.3) a
/// pipeline whose loops were bounded by a uniform was compiled anew at each bind, its old
/// code never freed: the octree's voxel bounce grew resident memory by 1.2 MiB per frame
/// (47.7 MiB over these 40 frames at 32x32, with validation; 0.1 MiB since the octree's
/// depth is a specialization constant). Not a timing: resident memory after frame 1 and
/// after the last, from `bench --json`.
#[test]
fn octree_frames_keep_memory_flat() {
    let dir = temp_dir("octree_memory");
    let json = dir.join("bench.json");
    let output = voxcone(&[
        "bench",
        "--gi",
        "octree",
        "--frames",
        "40",
        "--warmup",
        "0",
        "--size",
        "32x32",
        "--json",
        json.to_str().unwrap(),
    ]);
    common::assert_clean(&output);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let samples = report["rss_mib"].as_array().unwrap();
    let at = |i: usize| samples[i][1].as_f64().unwrap();
    let (first, last) = (at(0), at(samples.len() - 1));
    eprintln!("resident memory: {first:.2} MiB after frame 1, {last:.2} MiB after frame 40");
    assert!(last - first < 8.0, "grew {:.1} MiB", last - first);
}
