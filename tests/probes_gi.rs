//! The irradiance probes, `--gi probes`: an analytic furnace through every bounce, the
//! bake's file read back and rebuilt, and the path-traced reference of the Cornell box.
//! Every render runs with validation and fails on any message.

mod common;

use common::{assert_clean, furnace, render, run_render, shared, stderr, temp_dir, FURNACE_CAMERA};
use voxcone::compare::{compare, CompareOptions};
use voxcone::imageio::load_rgb;

/// Bake settings small enough for a test: the furnace's walls hold a few thousand
/// receivers, seen by 27 probes.
const SMALL_BAKE: &[&str] = &[
    "--lightmap-size",
    "64",
    "--probes",
    "27",
    "--probe-side",
    "32",
    "--receiver-rays",
    "64",
];

/// The white furnace: a closed box of albedo a emitting L everywhere shows L / (1 - a) at
/// every pixel once the bounces have converged (64 bounces leave 0.8^64 of the series),
/// within 4 % (measured 1.9 % and 2.5 % at the default PCA bound, 0.05, whose truncation
/// error is local, of zero mean; 0.24 % and 0.46 % with the thesis's 0.005). Albedo 0.8 puts four
/// fifths of the image in the bounces: the relight's albedo, the lightmap's reads and
/// writes and the gather all count.
#[test]
fn furnace_gives_the_geometric_series_at_every_pixel() {
    let dir = temp_dir("probes_furnace");
    for albedo in [0.5f32, 0.8] {
        let emitted = 0.5f32;
        let walls = format!("Kd {albedo} {albedo} {albedo}\nKe {emitted} {emitted} {emitted}\n");
        let scene = furnace(&dir, &walls, FURNACE_CAMERA);
        let out = dir.join(format!("furnace_{albedo}.exr"));
        let bake = dir.join(format!("furnace_{albedo}.bake"));
        let options = [
            &["--gi", "probes", "--size", "16x16", "--supersample", "1"],
            SMALL_BAKE,
            &[
                "--probe-bounces",
                "64",
                "--bake-file",
                bake.to_str().unwrap(),
            ],
        ]
        .concat();
        render(&scene, &options, &out);
        let image = load_rgb(&out).unwrap().0;
        let expected = emitted / (1.0 - albedo);
        let worst = image
            .data
            .iter()
            .map(|&v| (v / expected - 1.0).abs())
            .fold(0.0f32, f32::max);
        eprintln!(
            "albedo {albedo}: expected {expected}, worst pixel {:.2} % off",
            100.0 * worst
        );
        assert!(
            worst <= 0.04,
            "a pixel {:.2} % off L / (1 - a)",
            100.0 * worst
        );
    }
}

/// A bake read from its file renders the same image, bit for bit, as the bake that wrote
/// it; a truncated file is reported, baked again, and renders the same image again.
#[test]
fn a_cached_bake_renders_bit_identical_and_a_damaged_one_is_rebuilt() {
    let dir = temp_dir("probes_cache");
    let walls = "Kd 0.6 0.6 0.6\nKe 0.5 0.5 0.5\n";
    let scene = furnace(&dir, walls, FURNACE_CAMERA);
    let bake = dir.join("box.bake");
    let options = [
        &["--gi", "probes", "--size", "16x16"],
        SMALL_BAKE,
        &["--bake-file", bake.to_str().unwrap()],
    ]
    .concat();
    let image = |name: &str| {
        let out = dir.join(name);
        let output = run_render(&scene, &options, &out);
        assert_clean(&output);
        (std::fs::read(&out).unwrap(), stderr(&output))
    };
    let (fresh, log) = image("fresh.exr");
    assert!(
        log.contains("wrote bake"),
        "the first render did not bake: {log}"
    );
    let (cached, log) = image("cached.exr");
    assert!(
        log.contains("is up to date"),
        "the second render baked again: {log}"
    );
    assert!(fresh == cached, "the cached bake rendered another image");
    let bytes = std::fs::read(&bake).unwrap();
    std::fs::write(&bake, &bytes[..bytes.len() / 2]).unwrap();
    let (rebuilt, log) = image("rebuilt.exr");
    assert!(
        log.contains("baking again") && log.contains("truncated"),
        "the truncated bake was not reported: {log}"
    );
    assert!(fresh == rebuilt, "the rebuilt bake rendered another image");
}

/// The Cornell box with its point light against the path-traced reference, at the
/// probes' default settings: LDR-FLIP within 0.08 (measured 0.070; the target
/// is 0.10).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn cornell_matches_the_path_traced_reference() {
    let dir = temp_dir("probes_cornell");
    let reference = shared().join("reference");
    let out = dir.join("cornell.exr");
    let bake = dir.join("cornell.bake");
    render(
        &reference.join("cornell_point.scene.json"),
        &["--gi", "probes", "--bake-file", bake.to_str().unwrap()],
        &out,
    );
    let score = compare(
        &reference.join("cornell_point.exr"),
        &out,
        &CompareOptions::default(),
    )
    .unwrap();
    eprintln!("cornell_point: LDR-FLIP {:.4}", score.flip_ldr);
    assert!(score.flip_ldr <= 0.08, "LDR-FLIP {:.4}", score.flip_ldr);
}
