//! The irradiance probes, `--gi probes`: an analytic furnace through every bounce, the
//! bake's file read back and rebuilt, and the path-traced reference of the Cornell box.
//! Every render runs with validation and fails on any message.

mod common;

use common::{
    assert_clean, furnace, render, run_render, shared, sphere, stderr, temp_dir, FURNACE_CAMERA,
};
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
/// writes and the gather all count. A moving sphere of the walls' material fills a third
/// of the view: its pixels read the grid of spatial receivers, which must give the same.
#[test]
fn furnace_gives_the_geometric_series_at_every_pixel() {
    let dir = temp_dir("probes_furnace");
    for albedo in [0.5f32, 0.8] {
        let emitted = 0.5f32;
        let walls = format!("Kd {albedo} {albedo} {albedo}\nKe {emitted} {emitted} {emitted}\n");
        sphere(&dir, "ball", &walls);
        let ball = "[[mesh]]\npath = \"ball.obj\"\ntranslate = [0.5, 0.5, 0.2]\nscale = 0.12\n\
                    animate = { kind = \"oscillate\", axis = [1, 0, 0], amplitude = 0.1, period_s = 4 }\n";
        let scene = furnace(&dir, &walls, &format!("{FURNACE_CAMERA}{ball}"));
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
        let output = run_render(&scene, &options, &out);
        assert_clean(&output);
        assert!(
            stderr(&output).contains("probe_grid"),
            "the sphere did not read the grid"
        );
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
/// probes' default settings: LDR-FLIP within 0.08 (measured 0.074 with the seven bounces
/// one image takes there, 0.070 with eight, 0.065 with sixteen: the probes' image is 2 %
/// darker than the reference's, and the 1 % of the indirect light that seven leave
/// untraced widens that; the target is 0.10).
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

/// A sphere of albedo 0.8 (radius 0.25) moving through the built-in Cornell box, caught
/// at t = 1 s, at (0.4, 0.6, 0.3), lit by the point light alone (the ceiling's emitter
/// off, so that the path tracer's two-vertex paths are the direct light and nothing
/// else): `--gi probes` shades it from the grid of spatial receivers. Against
/// `--gi path` at the same time, the sphere's indirect light (the frame less
/// `--gi off`'s, which is the same direct light; the path tracer's less its
/// `--max-depth 2`), over the disc of pixels inside 80 % of its outline, within 10 % in
/// each channel (measured 0.984, 0.936, 0.965: the green wall's light on the near side
/// comes 9 % short, as the static receivers' first bounce does), and the whole image's
/// LDR-FLIP within 0.14 (measured 0.118; the sphere neither shadows nor lights the room
/// in the probes' transport).
#[test]
fn a_moving_sphere_lit_from_the_grid_matches_the_path_tracer() {
    let dir = temp_dir("probes_moving_sphere");
    sphere(&dir, "ball", "Kd 0.8 0.8 0.8\n");
    let cornell = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell.obj");
    let scene = dir.join("scene.toml");
    std::fs::write(
        &scene,
        format!(
            "[camera]\nposition = [0.0, 1.0, 3.9]\ntarget = [0.0, 1.0, 0.0]\nfov_y_deg = 39.3\n\
             [[mesh]]\npath = {cornell:?}\nemission_scale = 0.0\n\
             [[mesh]]\npath = \"ball.obj\"\ntranslate = [0.0, 0.6, 0.3]\nscale = 0.25\n\
             animate = {{ kind = \"oscillate\", axis = [1, 0, 0], amplitude = 0.4, period_s = 4 }}\n\
             [[light]]\nkind = \"point\"\nposition = [0.0, 1.5, 0.0]\nintensity = [3.0, 3.0, 3.0]\n"
        ),
    )
    .unwrap();
    let bake = dir.join("scene.bake");
    let common = ["--time", "1", "--size", "128x128"];
    let image = |name: &str, options: &[&str]| {
        let out = dir.join(name);
        render(&scene, &[&common[..], options].concat(), &out);
        load_rgb(&out).unwrap().0
    };
    let probes = image(
        "probes.exr",
        &[
            "--gi",
            "probes",
            "--lightmap-size",
            "256",
            "--bake-file",
            bake.to_str().unwrap(),
        ],
    );
    let direct = image("off.exr", &["--gi", "off"]);
    let path = image("path.exr", &["--gi", "path", "--spp", "256"]);
    let path_direct = image(
        "path_direct.exr",
        &["--gi", "path", "--spp", "256", "--max-depth", "2"],
    );
    // The sphere's outline: its centre and radius seen through the camera, in pixels.
    let tan = (39.3f32.to_radians() / 2.0).tan();
    let (centre, camera) = (
        glam::Vec3::new(0.4, 0.6, 0.3),
        glam::Vec3::new(0.0, 1.0, 3.9),
    );
    let d = centre - camera;
    let to_pixel = |ndc: f32| (ndc + 1.0) * 64.0;
    let (cx, cy) = (to_pixel(d.x / -d.z / tan), to_pixel(-d.y / -d.z / tan));
    let radius = 0.8 * 0.25 / d.length() / tan * 64.0;
    let mean = |a: &voxcone::imageio::RgbImage, b: &voxcone::imageio::RgbImage| {
        let (mut sum, mut count) = (glam::Vec3::ZERO, 0);
        for y in 0..128 {
            for x in 0..128 {
                let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
                if dx * dx + dy * dy < radius * radius {
                    let i = 3 * (y * 128 + x);
                    sum += glam::Vec3::from_slice(&a.data[i..i + 3])
                        - glam::Vec3::from_slice(&b.data[i..i + 3]);
                    count += 1;
                }
            }
        }
        sum / count as f32
    };
    let ratio = mean(&probes, &direct) / mean(&path, &path_direct);
    let score = compare(
        &dir.join("path.exr"),
        &dir.join("probes.exr"),
        &CompareOptions::default(),
    )
    .unwrap();
    eprintln!(
        "the sphere's indirect light over the path tracer's: {ratio:.3}; LDR-FLIP {:.4}",
        score.flip_ldr
    );
    assert!(
        (ratio - 1.0).abs().max_element() <= 0.10,
        "the sphere's indirect light is {ratio} of the path tracer's"
    );
    assert!(score.flip_ldr <= 0.14, "LDR-FLIP {:.4}", score.flip_ldr);
}
