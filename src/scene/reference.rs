//! The path-traced references' `*.scene.json` (see shared/reference/README.md).
//!
//! Read keys: `scenes_root` (relative to the JSON's folder), `obj` (relative to
//! `scenes_root`), `camera.{pos, target, up, fov_y_deg}`, `lights.point[].{position,
//! intensity_W_sr}`, `lights.directional[].{direction_of_travel, irradiance_W_m2}`,
//! `lights.env_radiance` (null or RGB), `lights.mtl_emission` (false sets the emission scale
//! to 0), `lights.emission_scale` and `flags.max_depth` (the path tracer's longest path:
//! -1 for no limit) and `resolution` (`render`'s and `bench`'s default size). Other keys
//! are ignored.

use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context as _, Result};
use glam::{Mat4, Vec3};
use serde::Deserialize;

use super::file::{camera_from, direction, finite, folder, load_geometry, non_negative, resolve};
use super::geometry::MeshEntry;
use super::{Light, LightKind, LoadOptions, Scene};

#[derive(Deserialize)]
struct ReferenceScene {
    scenes_root: Option<PathBuf>,
    obj: PathBuf,
    camera: ReferenceCamera,
    lights: ReferenceLights,
    #[serde(default)]
    flags: ReferenceFlags,
    /// The reference image's `[width, height]`.
    resolution: Option<[i64; 2]>,
}

/// How the reference was integrated: the longest path (-1: no limit, 2: direct light).
#[derive(Deserialize, Default)]
struct ReferenceFlags {
    max_depth: Option<i64>,
}

#[derive(Deserialize)]
struct ReferenceCamera {
    pos: [f32; 3],
    target: [f32; 3],
    up: Option<[f32; 3]>,
    fov_y_deg: f32,
}

#[derive(Deserialize)]
struct ReferenceLights {
    #[serde(default)]
    point: Vec<ReferencePoint>,
    #[serde(default)]
    directional: Vec<ReferenceDirectional>,
    env_radiance: Option<[f32; 3]>,
    #[serde(default = "yes")]
    mtl_emission: bool,
    emission_scale: Option<f32>,
}

fn yes() -> bool {
    true
}

#[derive(Deserialize)]
struct ReferencePoint {
    position: [f32; 3],
    #[serde(rename = "intensity_W_sr")]
    intensity: [f32; 3],
}

#[derive(Deserialize)]
struct ReferenceDirectional {
    direction_of_travel: [f32; 3],
    #[serde(rename = "irradiance_W_m2")]
    irradiance: [f32; 3],
}

/// Loads a path-traced reference's `*.scene.json` (see shared/reference/README.md).
pub fn load_reference_json(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let spec: ReferenceScene = serde_json::from_str(&text)
        .with_context(|| format!("invalid reference scene {}", path.display()))?;
    scene_from_reference(&spec, folder(path), path, options)
        .with_context(|| format!("in reference scene {}", path.display()))
}

fn scene_from_reference(
    spec: &ReferenceScene,
    base: &Path,
    source: &Path,
    options: &LoadOptions,
) -> Result<Scene> {
    let c = &spec.camera;
    let camera = camera_from(
        finite(c.pos, "camera.pos")?,
        finite(c.target, "camera.target")?,
        finite(c.up.unwrap_or([0.0, 1.0, 0.0]), "camera.up")?,
        c.fov_y_deg,
    )?;
    let mut lights = Vec::new();
    for (i, p) in spec.lights.point.iter().enumerate() {
        lights.push(Light {
            kind: LightKind::Point,
            position: finite(p.position, &format!("lights.point[{i}].position"))?,
            intensity: non_negative(p.intensity, &format!("lights.point[{i}].intensity_W_sr"))?,
            orbit: None,
        });
    }
    for (i, d) in spec.lights.directional.iter().enumerate() {
        let key = |k: &str| format!("lights.directional[{i}].{k}");
        lights.push(Light {
            kind: LightKind::Directional {
                direction: direction(d.direction_of_travel, &key("direction_of_travel"))?,
            },
            position: Vec3::ZERO,
            intensity: non_negative(d.irradiance, &key("irradiance_W_m2"))?,
            orbit: None,
        });
    }
    let sky = spec
        .lights
        .env_radiance
        .map_or(Ok(Vec3::ZERO), |r| non_negative(r, "lights.env_radiance"))?;
    let emission_scale = if spec.lights.mtl_emission {
        spec.lights.emission_scale.unwrap_or(1.0)
    } else {
        0.0
    };
    ensure!(
        emission_scale.is_finite() && emission_scale >= 0.0,
        "lights.emission_scale must be finite and non-negative, got {emission_scale}"
    );

    let root = resolve(base, spec.scenes_root.as_deref().unwrap_or(Path::new("")));
    let obj_path = resolve(&root, &spec.obj);
    let entry = MeshEntry {
        path: &obj_path,
        transform: Mat4::IDENTITY,
        emission_scale,
        animation: None,
    };
    let max_depth = match spec.flags.max_depth {
        None | Some(-1) => None,
        Some(depth @ 1..=1024) => Some(depth as u32),
        Some(other) => bail!("flags.max_depth must be -1 (no limit) or 1 to 1024, got {other}"),
    };
    let image_size = match spec.resolution {
        None => None,
        Some([w, h]) => {
            let side = 1..=i64::from(crate::cli::MAX_IMAGE_SIDE);
            ensure!(
                side.contains(&w) && side.contains(&h),
                "resolution must be [width, height] of 1 to {} pixels each, got [{w}, {h}]",
                crate::cli::MAX_IMAGE_SIDE
            );
            Some((w as u32, h as u32))
        }
    };
    let (mut scene, _) = load_geometry(&[entry], options, source)?;
    scene.image_size = image_size;
    scene.camera = camera;
    scene.lights = lights;
    scene.sky = sky;
    scene.gi.max_depth = max_depth;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::super::testing::{error_text, shared_dir, write_quad, TempDir};
    use super::*;

    #[test]
    fn reference_json_is_read_relative_to_its_folder() {
        let dir = TempDir::new("json");
        std::fs::create_dir(dir.0.join("scenes")).unwrap();
        std::fs::create_dir(dir.0.join("ref")).unwrap();
        write_quad(&dir.0.join("scenes"));
        let json = r#"{"scenes_root": "../scenes", "obj": "quad.obj", "resolution": [4, 4],
            "camera": {"pos": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 30},
            "lights": {"point": [], "directional": [{"direction_of_travel": [0, -2, 0],
            "irradiance_W_m2": [1, 2, 3]}], "env_radiance": [0.1, 0.2, 0.3],
            "mtl_emission": true, "emission_scale": 2.0}}"#;
        std::fs::write(dir.0.join("ref/q.scene.json"), json).unwrap();
        let scene = Scene::load(&dir.0.join("ref/q.scene.json"), &LoadOptions::default()).unwrap();
        assert_eq!(scene.materials[0].emission, Vec3::new(4.0, 6.0, 8.0));
        assert_eq!(scene.sky, Vec3::new(0.1, 0.2, 0.3));
        assert_eq!(scene.gi.max_depth, None, "no flags: no limit");
        assert_eq!(
            scene.image_size,
            Some((4, 4)),
            "resolution: the default size"
        );
        assert_eq!(
            scene.lights[0].kind,
            LightKind::Directional {
                direction: Vec3::NEG_Y
            }
        );
        assert_eq!(scene.lights[0].intensity, Vec3::new(1.0, 2.0, 3.0));

        let deep = json.replace("}}", "}, \"flags\": {\"max_depth\": 5000}}");
        std::fs::write(dir.0.join("ref/deep.scene.json"), deep).unwrap();
        let message = error_text(Scene::load(
            &dir.0.join("ref/deep.scene.json"),
            &LoadOptions::default(),
        ));
        assert!(message.contains("flags.max_depth must be -1"), "{message}");

        for (resolution, expected) in [
            ("[0, 0]", "got [0, 0]"),
            ("[-5, 10]", "got [-5, 10]"),
            ("[20000, 10]", "got [20000, 10]"),
            ("\"256x256\"", "invalid type"),
        ] {
            let bad = json.replace("[4, 4]", resolution);
            std::fs::write(dir.0.join("ref/bad.scene.json"), bad).unwrap();
            let message = error_text(Scene::load(
                &dir.0.join("ref/bad.scene.json"),
                &LoadOptions::default(),
            ));
            assert!(
                message.contains("bad.scene.json") && message.contains(expected),
                "{resolution}: {message}"
            );
        }

        let broken = dir.write("broken.scene.json", "{\"obj\": 3}");
        let message = error_text(Scene::load(&broken, &LoadOptions::default()));
        assert!(message.contains("broken.scene.json"), "{message}");
    }

    #[test]
    #[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
    fn reference_cornell_point_direct() {
        let shared = shared_dir();
        let path = shared.join("reference/cornell_point_direct.scene.json");
        let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
        assert_eq!(scene.triangle_count, 36);
        assert_eq!(scene.materials.len(), 8);
        let camera = &scene.camera;
        assert_eq!(camera.position, Vec3::new(0.0, 1.0, 3.9));
        assert_eq!(camera.target, Vec3::new(0.0, 1.0, 0.0));
        assert_eq!(camera.up, Vec3::Y);
        assert_eq!(camera.fov_y_deg, 39.3);
        assert_eq!(
            scene.lights,
            vec![Light {
                kind: LightKind::Point,
                position: Vec3::new(0.0, 1.5, 0.0),
                intensity: Vec3::splat(3.0),
                orbit: None,
            }]
        );
        assert!(
            scene.materials.iter().all(|m| m.emission == Vec3::ZERO),
            "mtl_emission false"
        );
        assert_eq!(scene.sky, Vec3::ZERO);
        assert_eq!(
            scene.gi.max_depth,
            Some(2),
            "flags.max_depth: direct light only"
        );
        let b = scene.bounds(0.0);
        assert!(b.min.abs_diff_eq(Vec3::new(-1.0, 0.0, -1.0), 0.05), "{b:?}");
        assert!(b.max.abs_diff_eq(Vec3::new(1.0, 2.0, 1.0), 0.05), "{b:?}");
    }

    #[test]
    #[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
    fn reference_sponza_main() {
        let shared = shared_dir();
        let path = shared.join("reference/sponza_main.scene.json");
        let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
        assert!(scene.triangle_count > 260_000);
        assert_eq!(scene.sky, Vec3::new(0.3, 0.35, 0.45));
        assert!(matches!(
            scene.lights[..],
            [Light {
                kind: LightKind::Directional { .. },
                ..
            }]
        ));
        assert!(scene.materials.iter().any(|m| m.coverage_texture.is_some()));
    }
}
