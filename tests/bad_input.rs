//! Bad input gets a clear error naming the cause, a non-zero exit and no panic.

mod common;

use std::path::Path;

use common::{stderr, temp_dir, voxcone};

fn assert_fails_naming(args: &[&str], needles: &[&str]) {
    let output = voxcone(args);
    let err = stderr(&output);
    assert!(!output.status.success(), "expected failure for {args:?}");
    assert!(!err.contains("panicked"), "panicked: {err}");
    for needle in needles {
        assert!(
            err.contains(needle),
            "error for {args:?} does not mention {needle:?}: {err}"
        );
    }
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_string_lossy().into_owned()
}

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

fn scene_for(dir: &Path, obj: &str) -> String {
    write(dir, "scene.toml", &format!("[[mesh]]\npath = \"{obj}\"\n"))
}

#[test]
fn missing_scene_file() {
    assert_fails_naming(
        &["render", "/nonexistent/scene.toml"],
        &["/nonexistent/scene.toml", "not found"],
    );
}

#[test]
fn malformed_obj() {
    let dir = temp_dir("malformed_obj");
    write(&dir, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 zz\n");
    let scene = scene_for(&dir, "bad.obj");
    assert_fails_naming(&["render", &scene, "-o", "x.png"], &["bad.obj", "parse"]);
}

#[test]
fn missing_mtl() {
    let dir = temp_dir("missing_mtl");
    write(
        &dir,
        "m.obj",
        &format!("mtllib nowhere.mtl\nusemtl a\n{TRIANGLE}"),
    );
    let scene = scene_for(&dir, "m.obj");
    assert_fails_naming(&["render", &scene], &["nowhere.mtl", "not found"]);
}

#[test]
fn malformed_mtl() {
    let dir = temp_dir("malformed_mtl");
    write(&dir, "m.mtl", "newmtl a\nKd 0.5 zz 0.5\n");
    write(
        &dir,
        "m.obj",
        &format!("mtllib m.mtl\nusemtl a\n{TRIANGLE}"),
    );
    let scene = scene_for(&dir, "m.obj");
    assert_fails_naming(&["render", &scene], &["m.mtl", "parse"]);
}

#[test]
fn missing_texture() {
    let dir = temp_dir("missing_texture");
    write(&dir, "m.mtl", "newmtl brick\nKd 1 1 1\nmap_Kd gone.png\n");
    write(
        &dir,
        "m.obj",
        &format!("mtllib m.mtl\nusemtl brick\n{TRIANGLE}"),
    );
    let scene = scene_for(&dir, "m.obj");
    assert_fails_naming(&["render", &scene], &["gone.png", "brick", "not found"]);
}

#[test]
fn zero_triangles() {
    let dir = temp_dir("zero_triangles");
    write(&dir, "empty.obj", "v 0 0 0\nv 1 0 0\n");
    let scene = scene_for(&dir, "empty.obj");
    assert_fails_naming(&["render", &scene], &["no triangles"]);
}

#[test]
fn broken_scene_file() {
    let dir = temp_dir("broken_scene");
    let scene = write(&dir, "scene.toml", "[[mesh]\npath = 3\n");
    assert_fails_naming(&["render", &scene], &["scene.toml", "line 1"]);
    let scene = write(
        &dir,
        "typo.toml",
        "[[mesh]]\npath = \"a.obj\"\nemision_scale = 1\n",
    );
    assert_fails_naming(&["render", &scene], &["typo.toml", "emision_scale"]);
}

#[test]
fn unknown_gi_mode() {
    assert_fails_naming(&["render", "--gi", "magic"], &["magic", "off"]);
}

#[test]
fn supersampled_frame_too_large() {
    assert_fails_naming(
        &["render", "--size", "10000x100", "--supersample", "2"],
        &["10000x100", "--supersample 2", "20000x200", "16384"],
    );
    assert_fails_naming(
        &["render", "--supersample", "5"],
        &["--supersample", "1..=4"],
    );
}

#[test]
fn bad_output_extension() {
    assert_fails_naming(
        &["render", "-o", "picture.bmp"],
        &["picture.bmp", ".png", ".exr"],
    );
}

#[test]
fn no_such_device() {
    assert_fails_naming(&["render", "--device", "no-such-gpu"], &["no-such-gpu"]);
}

#[test]
fn no_vulkan_driver() {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_voxcone"))
        .args(["render", "-o", "never.png"])
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .output()
        .unwrap();
    let err = stderr(&output);
    assert!(!output.status.success());
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("mesa-vulkan-drivers"),
        "no install hint: {err}"
    );
}

#[test]
fn bad_gi_settings_in_scene_file() {
    let dir = temp_dir("bad_gi_settings");
    write(&dir, "t.obj", TRIANGLE);
    let scene = write(
        &dir,
        "scene.toml",
        "[[mesh]]\npath = \"t.obj\"\n[gi]\nvoxels = 48\n",
    );
    assert_fails_naming(&["render", &scene], &["voxels", "power of two", "48"]);
    let scene = write(
        &dir,
        "typo.toml",
        "[[mesh]]\npath = \"t.obj\"\n[gi]\nvoxel = 64\n",
    );
    assert_fails_naming(
        &["render", &scene],
        &["typo.toml", "unknown field", "voxel"],
    );
    let scene = write(
        &dir,
        "cones.toml",
        "[[mesh]]\npath = \"t.obj\"\n[gi]\ndiffuse_cones = 40\n",
    );
    assert_fails_naming(
        &["render", &scene],
        &["diffuse_cones", "between 1 and 16", "40"],
    );
}

#[test]
fn voxel_options_without_voxels() {
    for option in ["--shadow-cones", "--full-update"] {
        assert_fails_naming(&["render", "--gi", "off", option], &[option, "--gi dense"]);
    }
    assert_fails_naming(
        &["render", "--gi", "off", "--debug-view", "ao"],
        &["--debug-view", "--gi dense"],
    );
}

#[test]
fn move_light_without_a_light() {
    let dir = temp_dir("move_light");
    write(&dir, "tri.obj", TRIANGLE);
    let scene = scene_for(&dir, "tri.obj");
    assert_fails_naming(
        &["bench", &scene, "--move-light", "--frames", "1"],
        &["--move-light", "no light"],
    );
}
