//! Scene-file parsing: the TOML format, reference `*.scene.json`, bare OBJ, and their errors.

mod common;

use std::path::Path;

use common::{shared, temp_dir};
use glam::Vec3;
use voxcone::scene::{Animation, LightKind, LoadOptions, Scene};

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

fn quad_with_material(dir: &Path) {
    image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 128, 0, 255]))
        .save(dir.join("tex.png"))
        .unwrap();
    write(
        dir,
        "quad.mtl",
        "newmtl lamp\nKd 0.5 0.5 0.5\nKe 2 3 4\nmap_Kd tex.png\nmap_d tex.png\nKs 0.5 0.5 0.5\nNs 98\n",
    );
    write(
        dir,
        "quad.obj",
        "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl lamp\nf 1/1 2/2 3/3 4/4\n",
    );
}

#[test]
fn full_toml_scene_parses() {
    let dir = temp_dir("full_toml");
    quad_with_material(&dir);
    let path = write(
        &dir,
        "scene.toml",
        r#"
[camera]
position = [0.0, 1.0, 3.9]
target = [0.0, 1.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_y_deg = 39.3

[[mesh]]
path = "quad.obj"
translate = [1, 2, 3]
rotate_deg = [0, 90, 0]
scale = 2.0
emission_scale = 0.5
animate = { kind = "spin", axis = [0, 1, 0], deg_per_s = 45 }

[[mesh]]
path = "quad.obj"
scale = [1, 2, 3]
emission_scale = 0
animate = { kind = "oscillate", axis = [1, 0, 0], amplitude = 0.5, period_s = 4 }

[[light]]
kind = "point"
position = [0.0, 1.5, 0.0]
intensity = [3.0, 3.0, 3.0]
orbit = { center = [1, 1.5, 0], axis = [0, 1, 0], period_s = 8 }

[[light]]
kind = "spot"
position = [0, 2, 0]
direction = [0, -1, 0]
intensity = [10, 10, 10]
inner_deg = 20
outer_deg = 30

[[light]]
kind = "directional"
direction = [0.25, -1, 0.1]
irradiance = [8, 7.6, 7]

[sky]
radiance = [0.3, 0.35, 0.45]
"#,
    );
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    assert_eq!(scene.meshes.len(), 2);
    assert_eq!(scene.triangle_count, 4);
    assert_eq!(
        scene.materials.len(),
        2,
        "materials of each OBJ entry are kept apart"
    );
    assert_eq!(
        scene.textures.len(),
        2,
        "one albedo and one coverage texture"
    );
    let lamp = &scene.materials[scene.meshes[0].material as usize];
    assert_eq!(
        lamp.emission,
        Vec3::new(1.0, 1.5, 2.0),
        "Ke x emission_scale"
    );
    assert!(
        (lamp.roughness - 0.02f32.sqrt()).abs() < 1e-6,
        "sqrt(2 / (98 + 2))"
    );
    assert_eq!(
        scene.materials[scene.meshes[1].material as usize].emission,
        Vec3::ZERO
    );
    // translate(1,2,3) * rotate_y(90) * scale(2): local +X goes to world -Z, doubled.
    let p = scene.meshes[0].transform.transform_point3(Vec3::X);
    assert!(p.abs_diff_eq(Vec3::new(1.0, 2.0, 1.0), 1e-5), "{p}");
    assert!(matches!(
        scene.meshes[0].animation,
        Some(Animation::Spin { .. })
    ));
    assert!(matches!(
        scene.meshes[1].animation,
        Some(Animation::Oscillate { .. })
    ));
    assert!(scene.is_animated());
    assert_eq!(scene.lights.len(), 3);
    assert!(matches!(scene.lights[1].kind, LightKind::Spot { outer_deg, .. } if outer_deg == 30.0));
    assert!(matches!(
        scene.lights[2].kind,
        LightKind::Directional { .. }
    ));
    // A quarter turn in 2 s about (1, 1.5, 0) takes the light from -X of the centre to +Z.
    let moved = scene.light_at(0, 2.0).position;
    assert!(moved.abs_diff_eq(Vec3::new(1.0, 1.5, 1.0), 1e-4), "{moved}");
    assert_eq!(scene.sky, Vec3::new(0.3, 0.35, 0.45));
    assert!((scene.camera.fov_y_deg - 39.3).abs() < 1e-6);
    // UVs: OBJ v = 0 is the image bottom, stored as row 1.0.
    assert_eq!(scene.meshes[0].vertices[0].uv, [0.0, 1.0]);
}

#[test]
fn diffuse_only_drops_specular() {
    let dir = temp_dir("diffuse_only");
    quad_with_material(&dir);
    let path = write(&dir, "s.toml", "[[mesh]]\npath = \"quad.obj\"\n");
    let options = LoadOptions {
        diffuse_only: true,
        no_normal_maps: true,
    };
    let scene = Scene::load(&path, &options).unwrap();
    assert_eq!(scene.materials[0].specular, Vec3::ZERO);
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    assert_eq!(scene.materials[0].specular, Vec3::splat(0.5));
}

#[test]
fn invalid_values_name_their_key() {
    let dir = temp_dir("invalid_values");
    quad_with_material(&dir);
    let cases = [
        (
            "[[mesh]]\npath = \"quad.obj\"\n[[light]]\nkind = \"spot\"\nposition = [0,0,0]\ndirection = [0,-1,0]\nintensity = [1,1,1]\ninner_deg = 40\nouter_deg = 30\n",
            "light[0].inner_deg",
        ),
        (
            "[[mesh]]\npath = \"quad.obj\"\n[[light]]\nkind = \"directional\"\ndirection = [0,0,0]\nirradiance = [1,1,1]\n",
            "light[0].direction",
        ),
        (
            "[[mesh]]\npath = \"quad.obj\"\n[[light]]\nkind = \"point\"\nposition = [0,0,0]\nintensity = [-1,1,1]\n",
            "light[0].intensity",
        ),
        ("[camera]\nposition = [0,0,1]\ntarget = [0,0,0]\nfov_y_deg = 200\n[[mesh]]\npath = \"quad.obj\"\n", "fov_y_deg"),
        ("[[light]]\nkind = \"laser\"\n", "laser"),
        ("", "no [[mesh]]"),
    ];
    for (i, (text, needle)) in cases.iter().enumerate() {
        let path = write(&dir, &format!("case{i}.toml"), text);
        let err = Scene::load(&path, &LoadOptions::default()).unwrap_err();
        let message = format!("{err:#}");
        assert!(
            message.contains(needle),
            "case {i}: {message:?} does not name {needle:?}"
        );
        assert!(
            message.contains(&format!("case{i}.toml")),
            "case {i}: {message:?} does not name the file"
        );
    }
}

#[test]
fn bare_obj_gets_camera_and_light() {
    let dir = temp_dir("bare_obj");
    quad_with_material(&dir);
    let scene = Scene::load(&dir.join("quad.obj"), &LoadOptions::default()).unwrap();
    assert_eq!(scene.lights.len(), 1);
    let bounds = scene.bounds(0.0);
    assert!((scene.camera.target - bounds.center()).length() < 1e-5);
    assert!(
        scene.camera.position.z > bounds.max.z,
        "framed from the +Z side"
    );
}

#[test]
fn reference_scene_json_and_cornell_box() {
    let Some(shared) = shared() else { return };
    let scene = Scene::load(
        &shared.join("reference/cornell_point_direct.scene.json"),
        &LoadOptions::default(),
    )
    .unwrap();
    assert_eq!(
        scene.triangle_count, 36,
        "the reference's stats say 36 triangles"
    );
    assert_eq!(scene.materials.len(), 8);
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.lights[0].position, Vec3::new(0.0, 1.5, 0.0));
    assert_eq!(scene.lights[0].intensity, Vec3::splat(3.0));
    assert!(
        scene.materials.iter().all(|m| m.emission == Vec3::ZERO),
        "mtl_emission false"
    );
    assert_eq!(scene.camera.position, Vec3::new(0.0, 1.0, 3.9));
    let b = scene.bounds(0.0);
    assert!(
        b.min.abs_diff_eq(Vec3::new(-1.02, 0.0, -1.04), 0.05),
        "{:?}",
        b.min
    );
    assert!(
        b.max.abs_diff_eq(Vec3::new(1.0, 1.99, 0.99), 0.05),
        "{:?}",
        b.max
    );

    let sponza = Scene::load(
        &shared.join("reference/sponza_main.scene.json"),
        &LoadOptions::default(),
    )
    .unwrap();
    assert!(sponza.triangle_count > 260_000);
    assert!(matches!(
        sponza.lights[0].kind,
        LightKind::Directional { .. }
    ));
    assert!(
        sponza
            .materials
            .iter()
            .any(|m| m.coverage_texture.is_some()),
        "cut-outs"
    );
    for t in &sponza.textures {
        assert_eq!(
            t.mips.last().unwrap().len(),
            4,
            "{} has no full mip chain",
            t.path.display()
        );
    }
}
