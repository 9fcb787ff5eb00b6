//! The path-traced reference, `--gi path`: an analytic furnace, determinism, its settings,
//! and the path-traced references it must agree with. Every render runs with validation
//! and fails on any message.

mod common;

use common::{furnace, render_path as render, shared, stderr, temp_dir, voxcone, FURNACE_CAMERA};
use voxcone::compare::{compare, CompareOptions};
use voxcone::imageio::{load_rgb, RgbImage};

/// The furnace's walls: Lambertian of albedo `albedo`, emitting `emitted`.
fn diffuse_walls(albedo: f32, emitted: f32) -> String {
    format!("Kd {albedo} {albedo} {albedo}\nKe {emitted} {emitted} {emitted}\n")
}

fn mean(image: &RgbImage) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for p in image.data.chunks_exact(3) {
        for c in 0..3 {
            sum[c] += f64::from(p[c]);
        }
    }
    sum.map(|s| s / (image.data.len() / 3) as f64)
}

/// The white furnace: a closed box of albedo a emitting L everywhere shows L / (1 - a) at
/// every pixel, within 0.5 %, for a = 0.5 and 0.8 (emission, bounces, next-event
/// estimation of the emitters and their MIS weights, and Russian roulette together).
#[test]
fn furnace_gives_the_geometric_series_at_every_pixel() {
    let dir = temp_dir("path_furnace");
    // Russian roulette makes the longer series noisy: at 16,384 samples a pixel's error
    // has a standard deviation of 0.46 % for a = 0.8, so 131,072 keep every pixel of four
    // well within the bound (0.16 %).
    for (albedo, spp) in [(0.5f32, "32768"), (0.8, "131072")] {
        let emitted = 0.5f32;
        let scene = furnace(&dir, &diffuse_walls(albedo, emitted), FURNACE_CAMERA);
        let out = dir.join(format!("furnace_{albedo}.exr"));
        let image = render(&scene, &["--size", "2x2", "--spp", spp], &out);
        let expected = emitted / (1.0 - albedo);
        let worst = image
            .data
            .iter()
            .map(|&v| (v / expected - 1.0).abs())
            .fold(0.0f32, f32::max);
        eprintln!("albedo {albedo}: expected {expected}, worst pixel off by {worst:.4}");
        assert!(worst <= 0.005, "albedo {albedo}: a pixel is off by {worst}");
    }
}

/// Camera rays go where the projection puts the pixels: an emitting quad seen with
/// `--max-depth 1` (emission only) whose edge crosses the middle of pixel column (or row)
/// `EDGE` of 512 shows exactly half its radiance there. The edge sits 244 pixels from the
/// centre, where a relative error of 1e-4 in the rays' slopes moves it by 0.024 pixels;
/// 8 rows (or columns) of 1024 samples measure the coverage to 0.006 (one sigma).
#[test]
fn camera_rays_put_edges_where_the_projection_does() {
    const LONG: u32 = 512;
    const EDGE: u32 = 500;
    let dir = temp_dir("path_camera_rays");
    std::fs::write(dir.join("quad.mtl"), "newmtl glow\nKd 0 0 0\nKe 1 1 1\n").unwrap();
    let distance = 5.0f64;
    for vertical in [false, true] {
        // The image is LONG pixels along the edge's normal and 8 along it; the view's
        // vertical field is 2 degrees (wide images) or what gives the same slopes (tall).
        let (width, height) = if vertical { (8, LONG) } else { (LONG, 8) };
        let half_short = 1f64.to_radians().tan();
        let half_long = half_short * f64::from(LONG) / 8.0;
        let fov_y = 2.0
            * if vertical { half_long } else { half_short }
                .atan()
                .to_degrees();
        // The middle of pixel EDGE, in NDC, then on the quad's plane.
        let ndc = (f64::from(EDGE) + 0.5) / f64::from(LONG) * 2.0 - 1.0;
        let edge = ndc * half_long * distance;
        let far = -1.2 * half_long * distance;
        let side = 1.2 * half_short * distance;
        // Wide: the quad covers x < edge (pixel columns grow with x). Tall: rows grow
        // downwards, so row EDGE sees y = -edge, and the quad covers y > -edge (the rows
        // above it).
        let corners = if vertical {
            [(-side, -edge), (side, -edge), (side, -far), (-side, -far)]
        } else {
            [(far, -side), (edge, -side), (edge, side), (far, side)]
        };
        let mut obj = String::from("mtllib quad.mtl\nusemtl glow\n");
        for (x, y) in corners {
            obj += &format!("v {x} {y} 0\n");
        }
        obj += "f 1 2 3 4\n";
        std::fs::write(dir.join("quad.obj"), obj).unwrap();
        let scene = dir.join("quad.toml");
        std::fs::write(
            &scene,
            format!(
                "[camera]\nposition = [0, 0, {distance}]\ntarget = [0, 0, 0]\nfov_y_deg = {fov_y}\n\
                 [[mesh]]\npath = \"quad.obj\"\n"
            ),
        )
        .unwrap();
        let size = format!("{width}x{height}");
        let out = dir.join(format!("edge_{vertical}.exr"));
        let image = render(
            &scene,
            &["--size", &size, "--spp", "1024", "--max-depth", "1"],
            &out,
        );
        let at = |x: u32, y: u32| image.data[((y * width + x) * 3) as usize];
        let line: Vec<f32> = (0..8)
            .map(|i| if vertical { at(i, EDGE) } else { at(EDGE, i) })
            .collect();
        let coverage = line.iter().sum::<f32>() / 8.0;
        let (inside, outside) = if vertical {
            (at(0, EDGE - 1), at(0, EDGE + 1))
        } else {
            (at(EDGE - 1, 0), at(EDGE + 1, 0))
        };
        eprintln!("vertical {vertical}: coverage of the edge's pixels {coverage:.4}");
        assert!(
            (inside, outside) == (1.0, 0.0),
            "neighbours {inside}, {outside}"
        );
        assert!(
            (coverage - 0.5).abs() < 0.02,
            "vertical {vertical}: the edge's pixels are {coverage} covered, not 0.5: {line:?}"
        );
    }
}

/// The scene file's `[gi]` table sets the samples and the path length, and the command
/// line wins: in the furnace (a = 0.5, L = 0.5) paths of one vertex see only the walls'
/// emission, L exactly, and paths of three L (1 + a + a^2).
#[test]
fn scene_file_sets_the_path_length() {
    let dir = temp_dir("path_scene_file");
    let (albedo, emitted) = (0.5f32, 0.5f32);
    let scene = furnace(
        &dir,
        &diffuse_walls(albedo, emitted),
        &format!("{FURNACE_CAMERA}[gi]\nspp = 4096\nmax_depth = 1\n"),
    );
    let cases = [
        ("depth1.exr", &[][..], emitted),
        (
            "depth3.exr",
            &["--max-depth", "3"][..],
            emitted * (1.0 + albedo + albedo * albedo),
        ),
    ];
    for (name, extra, expected) in cases {
        let mut args = vec!["--size", "2x2"];
        args.extend_from_slice(extra);
        let image = render(&scene, &args, &dir.join(name));
        for &v in &image.data {
            assert!(
                (v / expected - 1.0).abs() < 0.01,
                "{name}: {v}, expected {expected}"
            );
        }
    }
    let zero = furnace(
        &dir,
        &diffuse_walls(albedo, emitted),
        &format!("{FURNACE_CAMERA}[gi]\nspp = 0\n"),
    );
    let output = common::run_render(&zero, &["--gi", "path"], &dir.join("zero.exr"));
    assert!(!output.status.success(), "spp = 0 was accepted");
    assert!(
        stderr(&output).contains("--spp must be at least 1"),
        "{}",
        stderr(&output)
    );
}

/// The same seed gives the same image, bit for bit; another seed other noise with the same
/// mean.
#[test]
fn seeds_decide_the_noise_and_not_the_mean() {
    let dir = temp_dir("path_seeds");
    let scene = voxcone::cli::default_scene();
    let options = ["--size", "32x32", "--spp", "64"];
    let with_seed = |seed: &str, name: &str| {
        let out = dir.join(name);
        let mut args = options.to_vec();
        args.extend(["--seed", seed]);
        render(&scene, &args, &out);
        (std::fs::read(&out).unwrap(), load_rgb(&out).unwrap().0)
    };
    let (a, image_a) = with_seed("1", "a.exr");
    let (b, _) = with_seed("1", "b.exr");
    let (c, image_c) = with_seed("2", "c.exr");
    assert!(a == b, "two renders with seed 1 differ");
    assert!(a != c, "seeds 1 and 2 give the same image");
    let (ma, mc) = (mean(&image_a), mean(&image_c));
    for k in 0..3 {
        let ratio = mc[k] / ma[k];
        assert!(
            (ratio - 1.0).abs() < 0.02,
            "channel {k}: means {} and {}",
            ma[k],
            mc[k]
        );
    }
}

/// A render of several frames prints its estimate after the first, before the rest, and
/// its progress as it goes: 1024 samples per pixel at 32x32 take 4 frames of 256 samples
/// (2^18 paths a frame).
#[test]
fn render_prints_its_estimate_first() {
    let dir = temp_dir("path_estimate");
    let out = dir.join("x.exr");
    let scene = voxcone::cli::default_scene();
    let output = common::run_render(
        &scene,
        &["--gi", "path", "--size", "32x32", "--spp", "1024"],
        &out,
    );
    common::assert_clean(&output);
    let err = stderr(&output);
    let estimate = err
        .find("4 frames to render, about ")
        .unwrap_or_else(|| panic!("no estimate: {err}"));
    // Without a terminal the progress bar logs each quarter instead.
    let progress = err.find("256 of 1024 samples per pixel").unwrap();
    let rendered = err.find("rendered 32x32 (1024 samples per pixel)").unwrap();
    assert!(estimate < progress && progress < rendered, "{err}");
}

/// Settings the path tracer cannot take, and its options without it, are refused with the
/// reason, before any GPU work.
#[test]
fn path_settings_are_checked() {
    let dir = temp_dir("path_settings");
    let out = dir.join("x.exr");
    let out = out.to_str().unwrap();
    let cases: [(&[&str], &str); 4] = [
        (&["--gi", "path", "--spp", "0"], "--spp must be at least 1"),
        (
            &["--gi", "path", "--max-depth", "0"],
            "--max-depth must be at least 1",
        ),
        (&["--gi", "dense", "--spp", "16"], "needs --gi path"),
        (
            &["--gi", "path", "--voxels", "32"],
            "--voxels works on the voxels",
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

/// Against the path-traced references at 64 samples per pixel: direct light only
/// (`--max-depth 2`) on the Cornell box, and its area light with every bounce; LDR-FLIP
/// near an independent Mitsuba render's at the same samples, and the mean brightness
/// within 1 %.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn agrees_with_the_references() {
    let shared = shared();
    let dir = temp_dir("path_references");
    // (reference, options, bound): Mitsuba at 64 spp scores 0.069 on cornell_point.
    let cases: [(&str, &[&str], f32); 2] = [
        ("cornell_point_direct", &["--max-depth", "2"], 0.02),
        ("cornell_area", &[], 0.06),
    ];
    for (name, extra, bound) in cases {
        let scene = shared.join(format!("reference/{name}.scene.json"));
        let reference = shared.join(format!("reference/{name}.exr"));
        let out = dir.join(format!("{name}.exr"));
        let mut args = vec!["--size", "256x256", "--spp", "64"];
        args.extend_from_slice(extra);
        let image = render(&scene, &args, &out);
        let flip = compare(&reference, &out, &CompareOptions::default())
            .unwrap()
            .flip_ldr;
        let (ours, theirs) = (mean(&image), mean(&load_rgb(&reference).unwrap().0));
        eprintln!("{name}: LDR-FLIP {flip}, means {ours:?} against {theirs:?}");
        assert!(flip <= bound, "{name}: LDR-FLIP {flip} over {bound}");
        for k in 0..3 {
            let ratio = ours[k] / theirs[k];
            assert!(
                (ratio - 1.0).abs() <= 0.01,
                "{name}, channel {k}: brightness ratio {ratio}"
            );
        }
    }
}
