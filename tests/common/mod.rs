//! Helpers shared by the integration tests.

#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use voxcone::imageio::{load_rgb, RgbImage};

/// The shared scenes and references that build.rs found (`$VOXCONE_SHARED`, else
/// `../shared`). Tests that call it carry
/// `#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]`, so that without it the
/// summary counts them as ignored, not passed.
pub fn shared() -> PathBuf {
    // Reached without it only under `--include-ignored`.
    let dir = option_env!("VOXCONE_SHARED_DIR");
    PathBuf::from(dir.unwrap_or_else(|| panic!("built without ../shared (see build.rs)")))
}

/// The cone tracer's resolution for the tests that do not test its rule: `render`'s
/// default follows the host's memory (256³ where the host has 7 GiB, 128³ where it has
/// less), and a test's figures must not; a render at 256³ also takes four to five times
/// as long on lavapipe. 128³ is the default such tests were measured at.
pub const TEST_VOXELS: &str = "128";
/// The octree's depth of the same effective resolution, `TEST_VOXELS`.
pub const TEST_OCTREE_DEPTH: &str = "7";

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

/// Runs `voxcone render scene -o out` with the options `options`, validation on.
pub fn run_render(scene: &Path, options: &[&str], out: &Path) -> Output {
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(options);
    voxcone(&args)
}

/// Renders `scene` to `out` with the options `options`, validation clean.
pub fn render(scene: &Path, options: &[&str], out: &Path) {
    assert_clean(&run_render(scene, options, out));
}

/// Renders `scene` at 256x256 to `out` with the options `extra`, validation clean.
pub fn render_256(scene: &Path, extra: &[&str], out: &Path) {
    render(scene, &[&["--size", "256x256"], extra].concat(), out);
}

/// Writes `text` to `dir/name` and returns its path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A flat square [-1, 1]² at y = 0 facing up, of the MTL statements `material`, seen from
/// a camera 1 above its centre with the vertical field of view `fov_y_deg`, as a scene
/// file in `dir` with `extra` appended (a `[sky]` table, say).
pub fn flat_plane(dir: &Path, material: &str, fov_y_deg: f32, extra: &str) -> PathBuf {
    write(dir, "plane.mtl", &format!("newmtl plane\n{material}"));
    write(
        dir,
        "plane.obj",
        "mtllib plane.mtl\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nusemtl plane\nf 1 2 3 4\n",
    );
    write(
        dir,
        "plane.toml",
        &format!(
            "[camera]\nposition = [0, 1, 0.01]\ntarget = [0, 0, 0]\nfov_y_deg = {fov_y_deg}\n\
             [[mesh]]\npath = \"plane.obj\"\n{extra}"
        ),
    )
}

/// A furnace with a probe, as a scene file in `dir`: a cube [-1, 1]^3 whose walls emit
/// radiance 0.5 inwards (albedo 0, no lights), a small white quad facing +Z in the
/// middle, and a narrow camera on it, so that the centre pixels show what the quad
/// gathers (0.5, exactly).
pub fn probe_furnace(dir: &Path) -> PathBuf {
    write(
        dir,
        "box.mtl",
        "newmtl wall\nKd 0 0 0\nKe 0.5 0.5 0.5\nnewmtl probe\nKd 1 1 1\n",
    );
    // Every face wound so that its normal points inwards.
    let obj = "mtllib box.mtl\n\
        v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
        v -0.2 -0.2 0\nv 0.2 -0.2 0\nv 0.2 0.2 0\nv -0.2 0.2 0\n\
        usemtl wall\nf 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n\
        usemtl probe\nf 9 10 11 12\n";
    write(dir, "box.obj", obj);
    write(
        dir,
        "furnace.toml",
        "[camera]\nposition = [0, 0, 0.9]\ntarget = [0, 0, 0]\nfov_y_deg = 10\n\
         [[mesh]]\npath = \"box.obj\"\n",
    )
}

/// Renders `scene` with `--gi path` and `extra` to `out` (EXR), validation clean.
pub fn render_path(scene: &Path, extra: &[&str], out: &Path) -> RgbImage {
    render(scene, &[&["--gi", "path"], extra].concat(), out);
    load_rgb(out).unwrap().0
}

/// The camera at the furnace's centre, looking at its -Z wall with a 90 degree view.
pub const FURNACE_CAMERA: &str =
    "[camera]\nposition = [0.5, 0.5, 0.5]\ntarget = [0.5, 0.5, 0.0]\nfov_y_deg = 90\n";

/// A closed unit box whose every wall has the MTL statements `walls` (each emitting
/// inwards where they give Ke), as a scene file in `dir` with `extra` appended (its
/// `[camera]`, such as `FURNACE_CAMERA`, and a `[gi]` table where it has one).
pub fn furnace(dir: &Path, walls: &str, extra: &str) -> PathBuf {
    std::fs::write(dir.join("box.mtl"), format!("newmtl wall\n{walls}")).unwrap();
    // A unit cube whose faces wind towards its inside (their normals point in).
    let obj = "mtllib box.mtl\nusemtl wall\n\
        v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
        f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n";
    std::fs::write(dir.join("box.obj"), obj).unwrap();
    let scene = dir.join("furnace.toml");
    std::fs::write(&scene, format!("[[mesh]]\npath = \"box.obj\"\n{extra}")).unwrap();
    scene
}

/// A unit sphere (a UV sphere of 24 × 48 quads, smooth normals) as `name.obj` in `dir`,
/// its one material `ball` with the MTL statements `material`, for a scene to place.
pub fn sphere(dir: &Path, name: &str, material: &str) {
    use std::f32::consts::PI;
    use std::fmt::Write;
    let (rings, segments) = (24usize, 48usize);
    let mut obj = format!("mtllib {name}.mtl\nusemtl ball\n");
    for i in 0..=rings {
        let theta = PI * i as f32 / rings as f32;
        for j in 0..=segments {
            let phi = 2.0 * PI * j as f32 / segments as f32;
            let p = [
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ];
            writeln!(
                obj,
                "v {} {} {}\nvn {} {} {}",
                p[0], p[1], p[2], p[0], p[1], p[2]
            )
            .unwrap();
        }
    }
    let at = |i: usize, j: usize| i * (segments + 1) + j + 1;
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            // Wound outwards; the poles' degenerate halves left out.
            if i > 0 {
                writeln!(obj, "f {a}//{a} {d}//{d} {b}//{b}").unwrap();
            }
            if i + 1 < rings {
                writeln!(obj, "f {b}//{b} {d}//{d} {c}//{c}").unwrap();
            }
        }
    }
    std::fs::write(dir.join(format!("{name}.obj")), obj).unwrap();
    std::fs::write(
        dir.join(format!("{name}.mtl")),
        format!("newmtl ball\n{material}"),
    )
    .unwrap();
}
