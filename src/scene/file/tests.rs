use super::super::testing::{error_text, write_quad, TempDir};
use super::*;

const FULL: &str = r#"
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
direction = [0, -2, 0]
intensity = [10, 10, 10]
inner_deg = 20
outer_deg = 30

[[light]]
kind = "directional"
direction = [0.25, -1, 0.1]
irradiance = [8, 7.6, 7]

[sky]
radiance = [0.3, 0.35, 0.45]
"#;

#[test]
fn full_toml_scene() {
    let dir = TempDir::new("full");
    write_quad(&dir.0);
    let path = dir.write("scene.toml", FULL);
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    assert_eq!(scene.source, path);
    assert_eq!(scene.meshes.len(), 2);
    assert_eq!(scene.triangle_count, 4);
    assert_eq!(
        scene.materials.len(),
        2,
        "each OBJ entry keeps its materials"
    );
    assert_eq!(
        scene.textures.len(),
        2,
        "one albedo and one coverage texture"
    );
    let material = |m: usize| &scene.materials[scene.meshes[m].material as usize];
    assert_eq!(
        material(0).emission,
        Vec3::new(1.0, 1.5, 2.0),
        "Ke x emission_scale"
    );
    assert_eq!(material(1).emission, Vec3::ZERO);
    // translate(1, 2, 3) * rotate_y(90) * scale(2): local +X goes to world -Z, doubled.
    let p = scene.meshes[0].transform.transform_point3(Vec3::X);
    assert!(p.abs_diff_eq(Vec3::new(1.0, 2.0, 1.0), 1e-5), "{p}");
    let p = scene.meshes[1].transform.transform_point3(Vec3::ONE);
    assert_eq!(p, Vec3::new(1.0, 2.0, 3.0));
    assert!(
        matches!(scene.meshes[0].animation, Some(Animation::Spin { deg_per_s, .. }) if deg_per_s == 45.0)
    );
    assert!(matches!(
        scene.meshes[1].animation,
        Some(Animation::Oscillate { period_s, .. }) if period_s == 4.0
    ));
    assert!(scene.is_animated());
    // Oscillating by 0.5 along X at its peak (t = 1 s of 4).
    let moved = scene.mesh_transform(1, 1.0).transform_point3(Vec3::ZERO);
    assert!(moved.abs_diff_eq(Vec3::new(0.5, 0.0, 0.0), 1e-5), "{moved}");
    assert!(scene.bounds(1.0).max.x > scene.bounds(0.0).max.x);
    // The swept bounds hold the scene at every time (the shadow views are built from
    // them: `passes::shadow`'s tests).
    let swept = scene.swept_bounds();
    for i in 0..40 {
        let now = scene.bounds(i as f32 * 0.1);
        assert!(now.min.cmpge(swept.min - 1e-5).all() && now.max.cmple(swept.max + 1e-5).all());
    }

    assert_eq!(scene.lights.len(), 3);
    assert_eq!(scene.lights[0].intensity, Vec3::splat(3.0));
    assert_eq!(
        scene.lights[1].kind,
        LightKind::Spot {
            direction: Vec3::NEG_Y,
            inner_deg: 20.0,
            outer_deg: 30.0
        }
    );
    let LightKind::Directional { direction } = scene.lights[2].kind else {
        panic!("{:?}", scene.lights[2].kind)
    };
    assert!(direction.abs_diff_eq(Vec3::new(0.25, -1.0, 0.1).normalize(), 1e-6));
    assert_eq!(scene.lights[2].intensity, Vec3::new(8.0, 7.6, 7.0));
    // A quarter turn in 2 s about (1, 1.5, 0) takes the light from -X of the centre to +Z.
    let moved = scene.light_at(0, 2.0).position;
    assert!(moved.abs_diff_eq(Vec3::new(1.0, 1.5, 1.0), 1e-5), "{moved}");
    assert_eq!(scene.sky, Vec3::new(0.3, 0.35, 0.45));
    assert_eq!(scene.camera.position, Vec3::new(0.0, 1.0, 3.9));
    assert_eq!(scene.camera.fov_y_deg, 39.3);
    assert!(scene.camera.near > 0.0 && scene.camera.near < 1e-3);
}

#[test]
fn defaults_and_rotation_order() {
    let dir = TempDir::new("defaults");
    write_quad(&dir.0);
    let path = dir.write(
        "s.toml",
        "[[mesh]]\npath = \"quad.obj\"\nrotate_deg = [90, 90, 0]\n",
    );
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    assert!(scene.lights.is_empty() && scene.sky == Vec3::ZERO && !scene.is_animated());
    assert_eq!(scene.camera.fov_y_deg, 45.0, "a framing camera");
    // X first: +Y turns to +Z, then Y turns +Z to +X.
    let p = scene.meshes[0].transform.transform_point3(Vec3::Y);
    assert!(p.abs_diff_eq(Vec3::X, 1e-6), "{p}");
}

#[test]
fn errors_name_their_cause_and_file() {
    let dir = TempDir::new("errors");
    write_quad(&dir.0);
    let mesh = "[[mesh]]\npath = \"quad.obj\"\n";
    let spot = "[[light]]\nkind = \"spot\"\nposition = [0, 0, 0]\ndirection = [0, -1, 0]\n\
                intensity = [1, 1, 1]\n";
    dir.write("garbage.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 zz\n");
    dir.write("lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n");
    dir.write(
        "no_mtl.obj",
        "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    dir.write("gone.mtl", "newmtl brick\nmap_Kd gone.png\n");
    dir.write(
        "no_tex.obj",
        "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl brick\nf 1 2 3\n",
    );
    let cases = [
        ("[[mesh]]\npath = \"absent.obj\"\n".to_string(), vec!["absent.obj"]),
        ("[[mesh]]\npath = \"garbage.obj\"\n".into(), vec!["garbage.obj", "parse"]),
        ("[[mesh]]\npath = \"no_mtl.obj\"\n".into(), vec!["nowhere.mtl", "not found"]),
        ("[[mesh]]\npath = \"no_tex.obj\"\n".into(), vec!["gone.png", "brick", "not found"]),
        ("[[mesh]]\npath = \"lines.obj\"\n".into(), vec!["scene has no triangles"]),
        (format!("{mesh}emision_scale = 1\n"), vec!["emision_scale", "line 3"]),
        (format!("{mesh}[[light]]\nkind = \"point\"\nposition = [0, 0, 0]\nirradiance = [1, 1, 1]\n"), vec!["irradiance"]),
        ("[[mesh]\npath = 3\n".into(), vec!["line 1", "column"]),
        (format!("{mesh}scale = \"big\"\n"), vec!["line 3", "a number or an [x, y, z] array"]),
        (format!("{mesh}{spot}inner_deg = 40\nouter_deg = 30\n"), vec!["light[0].inner_deg"]),
        (format!("{mesh}{spot}inner_deg = 10\nouter_deg = 90\n"), vec!["light[0].outer_deg"]),
        (format!("{mesh}[[light]]\nkind = \"directional\"\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]\n"), vec!["light[0].direction must be non-zero"]),
        (format!("{mesh}[[light]]\nkind = \"point\"\nposition = [0, 0, 0]\nintensity = [-1, 1, 1]\n"), vec!["light[0].intensity"]),
        (format!("{mesh}[[light]]\nkind = \"point\"\nposition = [0, 0, 0]\nintensity = [nan, 1, 1]\n"), vec!["light[0].intensity", "finite"]),
        (format!("{mesh}[[light]]\nkind = \"laser\"\n"), vec!["laser"]),
        (format!("[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 0]\nfov_y_deg = 200\n{mesh}"), vec!["camera.fov_y_deg"]),
        (format!("[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 0]\nup = [0, 0, 1]\n{mesh}"), vec!["camera.up"]),
        (format!("{mesh}animate = {{ kind = \"oscillate\", axis = [1, 0, 0], amplitude = 1, period_s = 0 }}\n"), vec!["mesh[0].animate.period_s"]),
        (format!("{mesh}scale = 0\n"), vec!["mesh[0].scale"]),
        (format!("{mesh}emission_scale = -1\n"), vec!["mesh[0].emission_scale"]),
        ("[sky]\nradiance = [1, 1, 1]\n".into(), vec!["no [[mesh]]"]),
    ];
    for (i, (text, needles)) in cases.iter().enumerate() {
        let name = format!("case{i}.toml");
        let message = error_text(Scene::load(
            &dir.write(&name, text),
            &LoadOptions::default(),
        ));
        for needle in needles.iter().chain([&name.as_str()]) {
            assert!(
                message.contains(needle),
                "case {i}: {message:?} lacks {needle:?}"
            );
        }
    }
    let message = error_text(Scene::load(
        &dir.0.join("none.toml"),
        &LoadOptions::default(),
    ));
    assert!(
        message.contains("none.toml") && message.contains("not found"),
        "{message}"
    );
    let message = error_text(Scene::load(
        &dir.write("x.gltf", ""),
        &LoadOptions::default(),
    ));
    assert!(message.contains("x.gltf"), "{message}");
}

#[test]
fn bare_obj_is_framed_and_lit() {
    let dir = TempDir::new("bare");
    let scene = Scene::load(&write_quad(&dir.0), &LoadOptions::default()).unwrap();
    let bounds = scene.bounds(0.0);
    let camera = &scene.camera;
    assert!((camera.target - bounds.center()).length() < 1e-6);
    assert!(camera.position.z > bounds.max.z && camera.position.y > bounds.center().y);
    let to_center = (bounds.center() - camera.position).length();
    let half_fov = (camera.fov_y_deg * 0.5).to_radians();
    assert!(
        bounds.diagonal() * 0.5 <= to_center * half_fov.sin() + 1e-5,
        "sphere fits"
    );
    assert_eq!(scene.lights.len(), 1);
    let light = &scene.lights[0];
    assert!(
        light.position.abs_diff_eq(Vec3::new(0.5, 0.9, 0.0), 1e-6),
        "{light:?}"
    );
    assert!(
        (light.intensity.x - 0.5 * 2.0).abs() < 1e-5,
        "0.5 x diagonal^2 = 1"
    );
    assert_eq!(scene.materials[0].emission, Vec3::new(2.0, 3.0, 4.0));
}
