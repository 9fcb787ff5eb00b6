//! Bad input gets a clear error naming the cause, a non-zero exit and no panic.

mod common;

use std::path::Path;

use common::{stderr, temp_dir, voxcone, TEST_VOXELS};

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
    let cases: [(&str, &str, &[&str]); 4] = [
        (
            "scene.toml",
            "voxels = 48",
            &["voxels", "power of two", "48"],
        ),
        (
            "typo.toml",
            "voxel = 64",
            &["typo.toml", "unknown field", "voxel"],
        ),
        (
            "cones.toml",
            "diffuse_cones = 40",
            &["diffuse_cones", "between 1 and 16", "40"],
        ),
        (
            "emitters.toml",
            "sampled_emitters = 2000",
            &["sampled_emitters", "at most 1024", "2000"],
        ),
    ];
    for (name, setting, needles) in cases {
        let scene = write(
            &dir,
            name,
            &format!("[[mesh]]\npath = \"t.obj\"\n[gi]\n{setting}\n"),
        );
        assert_fails_naming(&["render", &scene], needles);
    }
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
    assert_fails_naming(
        &["render", "--gi", "off", "--sampled-emitters", "4"],
        &["--sampled-emitters", "--gi dense"],
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

#[test]
fn bad_bake_settings_and_scenes() {
    for (option, value) in [
        ("--probes", "0"),
        ("--overlaps", "65"),
        ("--lightmap-size", "8"),
    ] {
        assert_fails_naming(&["bake", option, value], &[option, value]);
    }
    let dir = temp_dir("bake");
    // One triangle: the placement grid spans its flat bounds, and it lies in every cell.
    write(&dir, "tri.obj", TRIANGLE);
    let scene = scene_for(&dir, "tri.obj");
    assert_fails_naming(&["bake", &scene], &["no free space", "probes"]);
    let moving = write(
        &dir,
        "moving.toml",
        "[[mesh]]\npath = \"tri.obj\"\nanimate = { kind = \"spin\", axis = [0, 1, 0], deg_per_s = 45.0 }\n",
    );
    assert_fails_naming(&["bake", &moving], &["no static triangles"]);
    assert_fails_naming(
        &["bake", "--probe-bounces", "2"],
        &["--probe-bounces", "not its bake"],
    );
    assert_fails_naming(
        &["bake", "--probe-lod", "off"],
        &["--probe-lod", "not its bake"],
    );
}

/// `--cone` names a cone of the gather, with a technique that has one.
#[test]
fn bad_cone_component() {
    assert_fails_naming(
        &["render", "--cone", "6", "-o", "x.png"],
        &["--cone 6", "cones 0 to 5"],
    );
    assert_fails_naming(
        &["render", "--gi", "path", "--cone", "6", "-o", "x.png"],
        &["--cone 6", "cones 0 to 5"],
    );
    assert_fails_naming(
        &["render", "--gi", "off", "--cone", "0", "-o", "x.png"],
        &["--cone", "needs --gi dense, --gi octree or --gi path"],
    );
}

#[test]
fn bad_probe_settings() {
    assert_fails_naming(
        &["render", "--sh-order", "5", "-o", "x.png"],
        &["--sh-order", "needs --gi probes"],
    );
    assert_fails_naming(
        &[
            "render",
            "--gi",
            "probes",
            "--probe-bounces",
            "0",
            "-o",
            "x.png",
        ],
        &["--probe-bounces 0", "1 to 64"],
    );
    assert_fails_naming(
        &["render", "--gi", "probes", "--sh-order", "8", "-o", "x.png"],
        &["--sh-order 8", "0 to 7"],
    );
    assert_fails_naming(
        &[
            "render",
            "--gi",
            "probes",
            "--relight-side",
            "30",
            "-o",
            "x.png",
        ],
        &["--relight-side 30", "16 to 128", "a multiple of 4"],
    );
    assert_fails_naming(
        &[
            "render",
            "--gi",
            "probes",
            "--spatial-receivers",
            "300000",
            "-o",
            "x.png",
        ],
        &["--spatial-receivers 300000", "0 to 262144"],
    );
    assert_fails_naming(
        &[
            "render",
            "--gi",
            "probes",
            "--lod-distances",
            "4,2,8",
            "-o",
            "x.png",
        ],
        &["--lod-distances 4,2,8", "increasing"],
    );
    assert_fails_naming(
        &[
            "render",
            "--gi",
            "probes",
            "--debug-view",
            "voxel-albedo",
            "-o",
            "x.png",
        ],
        &["--debug-view", "--gi probes"],
    );
}

/// How a corpus case must end.
enum Outcome {
    /// A non-zero exit whose error names each of these.
    Error(&'static [&'static str]),
    /// A clean render whose every value is finite and non-negative.
    Image,
}

/// A case: its files (name, contents; the scene is the first), the options after
/// `render SCENE -o out.exr`, and how it must end.
struct Case {
    name: &'static str,
    files: Vec<(&'static str, Vec<u8>)>,
    options: &'static [&'static str],
    outcome: Outcome,
}

fn case(
    name: &'static str,
    files: &[(&'static str, &[u8])],
    options: &'static [&'static str],
    outcome: Outcome,
) -> Case {
    Case {
        name,
        files: files.iter().map(|(n, b)| (*n, b.to_vec())).collect(),
        options,
        outcome,
    }
}

const QUAD_SCENE: &[u8] = b"[camera]\nposition = [0, 1, 2]\ntarget = [0, 0, 0]\n\
    [[mesh]]\npath = \"m.obj\"\n[[light]]\nkind = \"point\"\nposition = [0, 1, 0.5]\n\
    intensity = [1, 1, 1]\n";

/// `QUAD_SCENE` around `m.obj` holding `obj_body` (material `a`, whose MTL statements
/// are `mtl`).
fn quad_case(
    name: &'static str,
    obj_body: &str,
    mtl: &str,
    options: &'static [&'static str],
    outcome: Outcome,
) -> Case {
    Case {
        name,
        files: vec![
            ("scene.toml", QUAD_SCENE.to_vec()),
            (
                "m.obj",
                format!("mtllib m.mtl\nusemtl a\n{obj_body}").into_bytes(),
            ),
            ("m.mtl", format!("newmtl a\n{mtl}").into_bytes()),
        ],
        options,
        outcome,
    }
}

const QUAD: &str = "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
    f 1/1 4/4 3/3 2/2\n";

fn png(width: u32, height: u32) -> Vec<u8> {
    let image = image::RgbaImage::from_pixel(width, height, image::Rgba([200, 100, 50, 255]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

/// A TOML scene `text` around the quad `m.obj` (no MTL).
fn toml_case(
    name: &'static str,
    text: &str,
    options: &'static [&'static str],
    outcome: Outcome,
) -> Case {
    Case {
        name,
        files: vec![
            ("scene.toml", text.as_bytes().to_vec()),
            ("m.obj", QUAD.as_bytes().to_vec()),
        ],
        options,
        outcome,
    }
}

/// A TOML scene of the quad and one point light at `position` of `intensity`.
fn point_light(position: &str, intensity: &str) -> String {
    format!(
        "[[mesh]]\npath = \"m.obj\"\n[[light]]\nkind = \"point\"\n\
         position = {position}\nintensity = {intensity}\n"
    )
}

/// The quad with the texture `t.png` of `bytes` as its `map_Kd`.
fn texture_case(name: &'static str, bytes: Vec<u8>, outcome: Outcome) -> Case {
    let mut case = quad_case(name, QUAD, "Kd 1 1 1\nmap_Kd t.png\n", &[], outcome);
    case.files.push(("t.png", bytes));
    case
}

/// The quad's geometry as a glTF buffer: four positions (y = 0, facing up), six indices.
fn gltf_quad_bin() -> Vec<u8> {
    let positions: [f32; 12] = [-1., 0., -1., -1., 0., 1., 1., 0., 1., 1., 0., -1.];
    let indices: [u32; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend(indices.iter().flat_map(|v| v.to_le_bytes()));
    bin
}

/// A glTF of the quad whose buffer is at `uri`, with `count` positions and the required
/// extensions `required`.
fn gltf_quad(uri: &str, count: u32, required: &str) -> Vec<u8> {
    format!(
        r#"{{"asset": {{"version": "2.0"}}, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
        "meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0}}, "indices": 1}}]}}],
        "buffers": [{{"uri": "{uri}", "byteLength": 72}}],
        "bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
                        {{"buffer": 0, "byteOffset": 48, "byteLength": 24}}],
        "accessors": [{{"bufferView": 0, "componentType": 5126, "count": {count}, "type": "VEC3",
                        "min": [-1, 0, -1], "max": [1, 0, 1]}},
                      {{"bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR"}}],
        "extensionsUsed": [{required}], "extensionsRequired": [{required}]}}"#
    )
    .into_bytes()
}

fn corpus() -> Vec<Case> {
    use Outcome::{Error, Image};
    let kd = "Kd 0.5 0.5 0.5\n";
    let mut garbage = vec![0u8; 4096];
    let mut state = 0x9e37_79b9_u32;
    for byte in &mut garbage {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        *byte = state as u8;
    }
    let truncated_png = png(64, 64)[..100].to_vec();
    let scene_json = |camera: &str, lights: &str| {
        format!(
            "{{\"obj\": \"m.obj\", \"resolution\": [16, 16], \"camera\": {camera}, \
             \"lights\": {lights}}}"
        )
        .into_bytes()
    };
    let camera =
        "{\"pos\": [0, 1, 2], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y_deg\": 40}";
    let point = "{\"point\": [{\"position\": [0, 1, 0], \"intensity_W_sr\": [1, 1, 1]}]}";
    let json_case = |name, camera: &str, lights: &str, outcome| Case {
        name,
        files: vec![
            ("scene.scene.json", scene_json(camera, lights)),
            (
                "m.obj",
                format!("mtllib m.mtl\nusemtl a\n{QUAD}").into_bytes(),
            ),
            ("m.mtl", format!("newmtl a\n{kd}").into_bytes()),
        ],
        options: &[],
        outcome,
    };
    let bin = gltf_quad_bin();
    let data_uri = {
        use base64::Engine as _;
        format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bin)
        )
    };
    let gltf_case = |name, gltf: Vec<u8>, outcome| Case {
        name,
        files: vec![("g.gltf", gltf), ("g.bin", bin.clone())],
        options: &[],
        outcome,
    };
    let draco = "\"KHR_draco_mesh_compression\"";
    let gltf_cases = vec![
        gltf_case("gltf fine", gltf_quad("g.bin", 4, ""), Image),
        gltf_case("gltf data uri", gltf_quad(&data_uri, 4, ""), Image),
        gltf_case(
            "gltf truncated",
            gltf_quad("g.bin", 4, "")[..120].to_vec(),
            Error(&["g.gltf", "cannot parse"]),
        ),
        gltf_case(
            "gltf missing bin",
            gltf_quad("absent.bin", 4, ""),
            Error(&["g.gltf", "absent.bin) not found"]),
        ),
        gltf_case(
            "gltf accessor past its view",
            gltf_quad("g.bin", 40, ""),
            Error(&["g.gltf", "accessor 0"]),
        ),
        gltf_case(
            "gltf unsupported extension",
            gltf_quad("g.bin", 4, draco),
            Error(&["g.gltf", "KHR_draco_mesh_compression"]),
        ),
        case(
            "glb garbage",
            &[("g.glb", &garbage)],
            &[],
            Error(&["g.glb", "cannot parse"]),
        ),
        Case {
            name: "gltf in a toml scene",
            files: vec![
                (
                    "scene.toml",
                    format!(
                        "{}[[mesh]]\npath = \"g.gltf\"\n",
                        point_light("[0, 1, 0]", "[1, 1, 1]")
                    )
                    .into_bytes(),
                ),
                ("m.obj", QUAD.as_bytes().to_vec()),
                ("g.gltf", gltf_quad("g.bin", 4, "")),
                ("g.bin", bin.clone()),
            ],
            options: &[],
            outcome: Image,
        },
    ];
    let mut cases = vec![
        // OBJ
        quad_case("obj fine", QUAD, kd, &[], Image),
        quad_case(
            "obj truncated face",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2",
            kd,
            &[],
            Error(&["m.obj"]),
        ),
        quad_case(
            "obj index out of range",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n",
            kd,
            &[],
            Error(&["m.obj"]),
        ),
        quad_case(
            "obj index zero",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
            kd,
            &[],
            Error(&["m.obj"]),
        ),
        quad_case(
            "obj negative indices",
            "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nf -3 -1 -2\n",
            kd,
            &[],
            Image,
        ),
        quad_case(
            "obj negative index out of range",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -7\n",
            kd,
            &[],
            Error(&["m.obj"]),
        ),
        quad_case(
            "obj nan coordinate",
            "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            kd,
            &[],
            Error(&["m.obj"]),
        ),
        quad_case(
            "obj infinite coordinate",
            "v inf 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            kd,
            &[],
            Error(&["m.obj"]),
        ),
        // A normal that is not finite and non-zero is replaced by the face's.
        quad_case(
            "obj nan normal",
            &format!("{QUAD}vn nan 0 0\nf 1//1 2//1 3//1\n"),
            kd,
            &[],
            Image,
        ),
        quad_case(
            "obj degenerate faces only",
            "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 1 1\n",
            kd,
            &[],
            Error(&["no triangles"]),
        ),
        quad_case(
            "obj degenerate face among good",
            &format!("{QUAD}f 1 1 2\n"),
            kd,
            &[],
            Image,
        ),
        case(
            "obj binary garbage",
            &[("scene.toml", QUAD_SCENE), ("m.obj", &garbage)],
            &[],
            Error(&["m.obj"]),
        ),
        case(
            "obj empty",
            &[("scene.toml", QUAD_SCENE), ("m.obj", b"")],
            &[],
            Error(&["no triangles"]),
        ),
        // MTL
        quad_case(
            "mtl single-value colour",
            QUAD,
            "Kd 0.5\nKa 1\nKs 0.1\n",
            &[],
            Image,
        ),
        quad_case(
            "mtl nan colour",
            QUAD,
            "Kd nan 0.5 0.5\n",
            &[],
            Error(&["m.mtl", "Kd"]),
        ),
        quad_case(
            "mtl infinite emission",
            QUAD,
            "Kd 0.5\nKe inf inf inf\n",
            &[],
            Error(&["m.mtl", "Ke"]),
        ),
        quad_case(
            "mtl negative colour",
            QUAD,
            "Kd -5 -5 -5\n",
            &[],
            Error(&["m.mtl", "Kd"]),
        ),
        Case {
            name: "mtl missing",
            files: vec![
                ("scene.toml", QUAD_SCENE.to_vec()),
                (
                    "m.obj",
                    format!("mtllib gone.mtl\nusemtl a\n{QUAD}").into_bytes(),
                ),
            ],
            options: &[],
            outcome: Error(&["gone.mtl"]),
        },
        quad_case(
            "mtl missing texture",
            QUAD,
            "Kd 1 1 1\nmap_Kd gone.png\n",
            &[],
            Error(&["gone.png"]),
        ),
        texture_case("mtl corrupt texture", truncated_png, Error(&["t.png"])),
        texture_case("mtl texture", png(64, 32), Image),
        // Beyond the device's largest image (lavapipe: 16384): a smaller mip level.
        texture_case("mtl huge texture", png(20000, 1), Image),
        // The same for the path tracer's texture atlas.
        Case {
            options: &["--gi", "path", "--spp", "4"],
            ..texture_case("mtl huge texture, path traced", png(20000, 1), Image)
        },
        quad_case(
            "mtl texture is a directory",
            QUAD,
            "Kd 1 1 1\nmap_Kd .\n",
            &[],
            Error(&["is a directory"]),
        ),
        // TOML
        case(
            "toml syntax error",
            &[("scene.toml", b"[[mesh]\npath = \"m.obj\"\n")],
            &[],
            Error(&["scene.toml", "line 1"]),
        ),
        case(
            "toml type error",
            &[("scene.toml", b"[[mesh]]\npath = 5\n")],
            &[],
            Error(&["scene.toml", "path"]),
        ),
        toml_case(
            "toml nan light",
            &point_light("[nan, 1, 0]", "[1, 1, 1]"),
            &[],
            Error(&["light[0].position", "finite"]),
        ),
        toml_case(
            "toml negative intensity",
            &point_light("[0, 1, 0]", "[-1, 1, 1]"),
            &[],
            Error(&["light[0].intensity"]),
        ),
        toml_case(
            "toml camera on its target",
            "[camera]\n\
             position = [0, 1, 0]\n\
             target = [0, 1, 0]\n\
             [[mesh]]\n\
             path = \"m.obj\"\n",
            &[],
            Error(&["camera.position and camera.target must differ"]),
        ),
        toml_case(
            "toml camera up along the view",
            "[camera]\n\
             position = [0, 2, 0]\n\
             target = [0, 0, 0]\n\
             [[mesh]]\n\
             path = \"m.obj\"\n",
            &[],
            Error(&["camera.up"]),
        ),
        toml_case(
            "toml zero light direction",
            "[[mesh]]\n\
             path = \"m.obj\"\n\
             [[light]]\n\
             kind = \"directional\"\n\
             direction = [0, 0, 0]\n\
             irradiance = [1, 1, 1]\n",
            &[],
            Error(&["direction", "non-zero"]),
        ),
        toml_case(
            "toml zero mesh scale",
            "[[mesh]]\npath = \"m.obj\"\nscale = 0\n",
            &[],
            Error(&["scale"]),
        ),
        toml_case(
            "toml no light",
            "[camera]\n\
             position = [0, 1, 2]\n\
             target = [0, 0, 0]\n\
             [[mesh]]\n\
             path = \"m.obj\"\n\
             [sky]\n\
             radiance = [0.2, 0.2, 0.2]\n",
            &["--gi", "dense", "--voxels", "16"],
            Image,
        ),
        // Scene JSON
        json_case("json fine", camera, point, Image),
        json_case(
            "json syntax error",
            "{\"pos\": [0, 1, 2]",
            point,
            Error(&["scene.scene.json"]),
        ),
        json_case(
            "json type error",
            "{\"pos\": \"up\", \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y_deg\": 40}",
            point,
            Error(&["scene.scene.json", "expected an array", "column"]),
        ),
        json_case(
            "json out-of-range number",
            "{\"pos\": [1e999, 1, 2], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y_deg\": 40}",
            point,
            Error(&["scene.scene.json"]),
        ),
        json_case(
            "json fov 180",
            "{\"pos\": [0, 1, 2], \"target\": [0, 0, 0], \"up\": [0, 1, 0], \"fov_y_deg\": 180}",
            point,
            Error(&["fov_y_deg"]),
        ),
        json_case(
            "json negative intensity",
            camera,
            "{\"point\": [{\"position\": [0, 1, 0], \"intensity_W_sr\": [1, -1, 1]}]}",
            Error(&["intensity_W_sr"]),
        ),
        // CLI extremes
        quad_case(
            "cli smallest frame",
            QUAD,
            kd,
            &["--size", "1x1", "--supersample", "1"],
            Image,
        ),
        quad_case(
            "cli zero size",
            QUAD,
            kd,
            &["--size", "0x16"],
            Error(&["--size"]),
        ),
        quad_case(
            "cli nan exposure",
            QUAD,
            kd,
            &["--exposure", "nan"],
            Error(&["--exposure"]),
        ),
        quad_case(
            "cli huge voxels",
            QUAD,
            kd,
            &["--gi", "dense", "--voxels", "4096"],
            Error(&["voxels"]),
        ),
        quad_case(
            "cli tiny shadow budget",
            QUAD,
            kd,
            &["--shadow-budget", "0"],
            Error(&["--shadow-budget"]),
        ),
        quad_case(
            "cli shadow resolution not a power of two",
            QUAD,
            kd,
            &["--shadow-res", "1000"],
            Error(&["--shadow-res", "power of two"]),
        ),
        quad_case(
            "cli every technique",
            QUAD,
            kd,
            &["--gi", "svo", "--octree-depth", "6", "--shadow-cones"],
            Image,
        ),
        quad_case("cli path", QUAD, kd, &["--gi", "path", "--spp", "4"], Image),
    ];
    cases.extend(gltf_cases);
    cases
}

/// Every case of the bad-input corpus ends in a clear error naming its cause or in a
/// clean image finite and non-negative everywhere; none panics or hangs (each runs
/// under a timeout through the harness's own).
#[test]
fn corpus_ends_in_an_error_or_a_finite_image() {
    let root = temp_dir("corpus");
    let (mut errors, mut images) = (0, 0);
    for (i, case) in corpus().into_iter().enumerate() {
        let dir = root.join(format!("{i:02}"));
        std::fs::create_dir_all(&dir).unwrap();
        for (name, bytes) in &case.files {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
        let scene = dir.join(case.files[0].0);
        let out = dir.join("out.exr");
        let mut args = vec![
            "render",
            scene.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ];
        if !case.options.contains(&"--size") {
            args.extend(["--size", "16x16"]);
        }
        if case.options.is_empty() {
            args.extend(["--voxels", TEST_VOXELS]);
        }
        args.extend_from_slice(case.options);
        let output = voxcone(&args);
        let err = stderr(&output);
        assert!(!err.contains("panicked"), "{}: panicked: {err}", case.name);
        match case.outcome {
            Outcome::Error(needles) => {
                assert!(!output.status.success(), "{}: expected an error", case.name);
                for needle in needles {
                    assert!(
                        err.contains(needle),
                        "{}: error does not name {needle:?}: {err}",
                        case.name
                    );
                }
                errors += 1;
            }
            Outcome::Image => {
                common::assert_clean(&output);
                let (image, _) = voxcone::imageio::load_rgb(&out).unwrap();
                let bad = image
                    .data
                    .iter()
                    .filter(|v| !v.is_finite() || **v < 0.0)
                    .count();
                assert_eq!(bad, 0, "{}: {bad} non-finite or negative values", case.name);
                images += 1;
            }
        }
    }
    eprintln!(
        "corpus: {} cases, {errors} clear errors, {images} correct images",
        errors + images
    );
}
