//! Scene files.
//!
//! A `.toml` scene (paths relative to the file):
//!
//! ```toml
//! [camera]                       # right-handed, +Y up
//! position = [0.0, 1.0, 3.9]
//! target = [0.0, 1.0, 0.0]
//! up = [0.0, 1.0, 0.0]           # optional, default +Y
//! fov_y_deg = 39.3               # full vertical field of view, optional, default 45
//!
//! [[mesh]]
//! path = "cornell.obj"           # relative to the scene file, or absolute
//! translate = [0, 0, 0]          # optional
//! rotate_deg = [0, 0, 0]         # optional, about X, then Y, then Z
//! scale = 1.0                    # optional, uniform or [x, y, z]
//! emission_scale = 1.0           # optional multiplier for MTL Ke (0 turns emitters off)
//! animate = { kind = "spin", axis = [0, 1, 0], deg_per_s = 45 }   # optional
//! # animate = { kind = "oscillate", axis = [1, 0, 0], amplitude = 0.5, period_s = 4 }
//!
//! [[light]]
//! kind = "point"                 # point | spot | directional
//! position = [0.0, 1.5, 0.0]     # point, spot
//! intensity = [3.0, 3.0, 3.0]    # radiant intensity in W/sr (point, spot)
//! # spot: direction = [..] (axis), inner_deg, outer_deg (half-angles from the axis)
//! # directional: direction = [..] (of travel), irradiance = [..] (W/m^2 facing the light)
//! orbit = { center = [0, 1, 0], axis = [0, 1, 0], period_s = 8 }  # optional
//!
//! [sky]
//! radiance = [0.3, 0.35, 0.45]   # constant environment radiance, optional
//! ```
//!
//! Also accepted: the `*.scene.json` of the path-traced references, and a bare `.obj`
//! (camera framed on its bounds, one point light under its top).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::Deserialize;

use super::obj::{self, ObjEntry, TextureRequests};
use super::{Animation, Camera, Light, LightKind, LoadOptions, Orbit, Scene};

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: Option<CameraSpec>,
    #[serde(default)]
    mesh: Vec<MeshSpec>,
    #[serde(default)]
    light: Vec<LightSpec>,
    sky: Option<SkySpec>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct CameraSpec {
    position: [f32; 3],
    target: [f32; 3],
    up: Option<[f32; 3]>,
    fov_y_deg: Option<f32>,
}

#[derive(Deserialize, Debug)]
#[serde(untagged)]
enum Scale {
    Uniform(f32),
    Axes([f32; 3]),
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct MeshSpec {
    path: PathBuf,
    translate: Option<[f32; 3]>,
    rotate_deg: Option<[f32; 3]>,
    scale: Option<Scale>,
    emission_scale: Option<f32>,
    animate: Option<AnimationSpec>,
}

#[derive(Deserialize, Debug)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
enum AnimationSpec {
    Spin {
        axis: [f32; 3],
        deg_per_s: f32,
    },
    Oscillate {
        axis: [f32; 3],
        amplitude: f32,
        period_s: f32,
    },
}

#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum LightKindSpec {
    Point,
    Spot,
    Directional,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct LightSpec {
    kind: LightKindSpec,
    position: Option<[f32; 3]>,
    intensity: Option<[f32; 3]>,
    direction: Option<[f32; 3]>,
    irradiance: Option<[f32; 3]>,
    inner_deg: Option<f32>,
    outer_deg: Option<f32>,
    orbit: Option<OrbitSpec>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct OrbitSpec {
    center: [f32; 3],
    axis: [f32; 3],
    period_s: f32,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SkySpec {
    radiance: [f32; 3],
}

fn nonzero(v: [f32; 3], what: &str) -> Result<Vec3> {
    let v = Vec3::from(v);
    if !v.is_finite() || v.length_squared() < 1e-12 {
        bail!("{what} must be a non-zero, finite vector");
    }
    Ok(v.normalize())
}

fn non_negative(v: [f32; 3], what: &str) -> Result<Vec3> {
    let v = Vec3::from(v);
    if !v.is_finite() || v.min_element() < 0.0 {
        bail!("{what} must be finite and non-negative, got {v}");
    }
    Ok(v)
}

fn light_from_spec(i: usize, spec: &LightSpec) -> Result<Light> {
    let key = |k: &str| format!("light[{i}].{k}");
    let need = |v: Option<[f32; 3]>, k: &str| {
        v.with_context(|| format!("{} is required for this kind", key(k)))
    };
    let (kind, position, intensity) = match spec.kind {
        LightKindSpec::Point => (
            LightKind::Point,
            Vec3::from(need(spec.position, "position")?),
            non_negative(need(spec.intensity, "intensity")?, &key("intensity"))?,
        ),
        LightKindSpec::Spot => {
            let inner = spec
                .inner_deg
                .with_context(|| format!("{} is required", key("inner_deg")))?;
            let outer = spec
                .outer_deg
                .with_context(|| format!("{} is required", key("outer_deg")))?;
            if !(0.0..90.0).contains(&outer) || !(0.0..=outer).contains(&inner) {
                bail!(
                    "{} and {} must satisfy 0 <= inner <= outer < 90 (half-angles), got {inner} and {outer}",
                    key("inner_deg"),
                    key("outer_deg")
                );
            }
            (
                LightKind::Spot {
                    direction: nonzero(need(spec.direction, "direction")?, &key("direction"))?,
                    inner_deg: inner,
                    outer_deg: outer,
                },
                Vec3::from(need(spec.position, "position")?),
                non_negative(need(spec.intensity, "intensity")?, &key("intensity"))?,
            )
        }
        LightKindSpec::Directional => (
            LightKind::Directional {
                direction: nonzero(need(spec.direction, "direction")?, &key("direction"))?,
            },
            Vec3::ZERO,
            non_negative(need(spec.irradiance, "irradiance")?, &key("irradiance"))?,
        ),
    };
    let orbit = match &spec.orbit {
        Some(o) => {
            if !(o.period_s.is_finite() && o.period_s > 0.0) {
                bail!("{} must be positive", key("orbit.period_s"));
            }
            Some(Orbit {
                center: Vec3::from(o.center),
                axis: nonzero(o.axis, &key("orbit.axis"))?,
                period_s: o.period_s,
            })
        }
        None => None,
    };
    Ok(Light {
        kind,
        position,
        intensity,
        orbit,
    })
}

fn mesh_transform(i: usize, spec: &MeshSpec) -> Result<Mat4> {
    let scale = match spec.scale {
        None => Vec3::ONE,
        Some(Scale::Uniform(s)) => Vec3::splat(s),
        Some(Scale::Axes(s)) => Vec3::from(s),
    };
    if !scale.is_finite() || scale.abs().min_element() < 1e-12 {
        bail!("mesh[{i}].scale must be finite and non-zero");
    }
    let r = spec.rotate_deg.map_or(Vec3::ZERO, Vec3::from);
    // X first, then Y, then Z: R = Rz * Ry * Rx.
    let rotation = Quat::from_euler(
        EulerRot::ZYX,
        r.z.to_radians(),
        r.y.to_radians(),
        r.x.to_radians(),
    );
    let translation = spec.translate.map_or(Vec3::ZERO, Vec3::from);
    Ok(Mat4::from_scale_rotation_translation(
        scale,
        rotation,
        translation,
    ))
}

fn animation_from_spec(i: usize, spec: &Option<AnimationSpec>) -> Result<Option<Animation>> {
    Ok(match spec {
        None => None,
        Some(AnimationSpec::Spin { axis, deg_per_s }) => Some(Animation::Spin {
            axis: nonzero(*axis, &format!("mesh[{i}].animate.axis"))?,
            deg_per_s: *deg_per_s,
        }),
        Some(AnimationSpec::Oscillate {
            axis,
            amplitude,
            period_s,
        }) => {
            if period_s.is_nan() || *period_s <= 0.0 {
                bail!("mesh[{i}].animate.period_s must be positive");
            }
            Some(Animation::Oscillate {
                axis: nonzero(*axis, &format!("mesh[{i}].animate.axis"))?,
                amplitude: *amplitude,
                period_s: *period_s,
            })
        }
    })
}

/// Loads the OBJs and textures of a scene; camera and lights come from the caller.
fn load_geometry(entries: &[ObjEntry], options: &LoadOptions, source: &Path) -> Result<Scene> {
    let mut requests = TextureRequests::default();
    let mut meshes = Vec::new();
    let mut materials = Vec::new();
    for entry in entries {
        let (m, mats) = obj::load(entry, options, materials.len() as u32, &mut requests)?;
        meshes.extend(m);
        materials.extend(mats);
    }
    Ok(Scene {
        meshes,
        materials,
        textures: requests.decode()?,
        camera: Camera {
            position: Vec3::new(0.0, 0.0, 1.0),
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_deg: 45.0,
            near: 0.01,
            far: 100.0,
        },
        lights: Vec::new(),
        sky: Vec3::ZERO,
        source: source.to_path_buf(),
        triangle_count: 0,
    })
}

fn camera_from(position: Vec3, target: Vec3, up: Vec3, fov_y_deg: f32) -> Result<Camera> {
    if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) {
        bail!("camera.fov_y_deg must be in (0, 180), got {fov_y_deg}");
    }
    if (target - position).length_squared() < 1e-12 {
        bail!("camera.position and camera.target must differ");
    }
    Ok(Camera {
        position,
        target,
        up: up.normalize_or(Vec3::Y),
        fov_y_deg,
        near: 0.01,
        far: 100.0,
    })
}

/// Frames the bounds from the +Z side, slightly above, filling a 45 degree view.
fn framing_camera(scene: &Scene) -> Camera {
    let bounds = scene.bounds(0.0);
    let center = bounds.center();
    let radius = (bounds.size().length() * 0.5).max(1e-3);
    let distance = radius / (22.5f32.to_radians().sin());
    let direction = Vec3::new(0.0, 0.25, 1.0).normalize();
    Camera {
        position: center + direction * distance,
        target: center,
        up: Vec3::Y,
        fov_y_deg: 45.0,
        near: 0.01,
        far: 100.0,
    }
}

fn resolve(base: &Path, path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        base.join(path)
    }
}

pub fn load_toml(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let file: SceneFile =
        toml::from_str(&text).with_context(|| format!("invalid scene file {}", path.display()))?;
    let base = path.parent().unwrap_or(Path::new("."));
    (|| {
        if file.mesh.is_empty() {
            bail!("the scene has no [[mesh]] entries");
        }
        let mut entries = Vec::new();
        let mut paths = Vec::new();
        for (i, spec) in file.mesh.iter().enumerate() {
            paths.push(resolve(base, &spec.path));
            let scale = spec.emission_scale.unwrap_or(1.0);
            if !(scale.is_finite() && scale >= 0.0) {
                bail!("mesh[{i}].emission_scale must be finite and non-negative");
            }
            entries.push((
                mesh_transform(i, spec)?,
                scale,
                animation_from_spec(i, &spec.animate)?,
            ));
        }
        let entries: Vec<ObjEntry> = entries
            .into_iter()
            .zip(&paths)
            .map(|((transform, emission_scale, animation), path)| ObjEntry {
                path,
                transform,
                emission_scale,
                animation,
            })
            .collect();
        let mut scene = load_geometry(&entries, options, path)?;
        scene.lights = file
            .light
            .iter()
            .enumerate()
            .map(|(i, l)| light_from_spec(i, l))
            .collect::<Result<_>>()?;
        if let Some(sky) = &file.sky {
            scene.sky = non_negative(sky.radiance, "sky.radiance")?;
        }
        scene.camera = match &file.camera {
            Some(c) => camera_from(
                Vec3::from(c.position),
                Vec3::from(c.target),
                c.up.map_or(Vec3::Y, Vec3::from),
                c.fov_y_deg.unwrap_or(45.0),
            )?,
            None => framing_camera(&scene),
        };
        Ok(scene)
    })()
    .with_context(|| format!("in scene file {}", path.display()))
}

#[derive(Deserialize)]
struct ReferenceJson {
    scenes_root: Option<PathBuf>,
    obj: PathBuf,
    camera: ReferenceCamera,
    lights: ReferenceLights,
}

#[derive(Deserialize)]
struct ReferenceCamera {
    pos: [f32; 3],
    target: [f32; 3],
    up: [f32; 3],
    fov_y_deg: f32,
}

#[derive(Deserialize)]
struct ReferenceLights {
    #[serde(default)]
    point: Vec<ReferencePoint>,
    #[serde(default)]
    directional: Vec<ReferenceDirectional>,
    env_radiance: Option<[f32; 3]>,
    mtl_emission: bool,
    emission_scale: Option<f32>,
}

#[derive(Deserialize)]
struct ReferencePoint {
    position: [f32; 3],
    intensity_w_sr: [f32; 3],
}

#[derive(Deserialize)]
struct ReferenceDirectional {
    direction_of_travel: [f32; 3],
    irradiance_w_m2: [f32; 3],
}

/// Loads a path-traced reference's `*.scene.json` (see shared/reference/README.md).
pub fn load_reference_json(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    // The files spell units as "intensity_W_sr"; accept them case-insensitively.
    let text = text
        .replace("\"intensity_W_sr\"", "\"intensity_w_sr\"")
        .replace("\"irradiance_W_m2\"", "\"irradiance_w_m2\"");
    let spec: ReferenceJson = serde_json::from_str(&text)
        .with_context(|| format!("invalid reference scene {}", path.display()))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let root = resolve(base, spec.scenes_root.as_deref().unwrap_or(Path::new(".")));
    let obj_path = resolve(&root, &spec.obj);
    let emission_scale = if spec.lights.mtl_emission {
        spec.lights.emission_scale.unwrap_or(1.0)
    } else {
        0.0
    };
    let entry = ObjEntry {
        path: &obj_path,
        transform: Mat4::IDENTITY,
        emission_scale,
        animation: None,
    };
    let mut scene = load_geometry(&[entry], options, path)?;
    let c = &spec.camera;
    scene.camera = camera_from(
        Vec3::from(c.pos),
        Vec3::from(c.target),
        Vec3::from(c.up),
        c.fov_y_deg,
    )?;
    for p in &spec.lights.point {
        scene.lights.push(Light {
            kind: LightKind::Point,
            position: Vec3::from(p.position),
            intensity: non_negative(p.intensity_w_sr, "point intensity")?,
            orbit: None,
        });
    }
    for d in &spec.lights.directional {
        scene.lights.push(Light {
            kind: LightKind::Directional {
                direction: nonzero(d.direction_of_travel, "direction_of_travel")?,
            },
            position: Vec3::ZERO,
            intensity: non_negative(d.irradiance_w_m2, "irradiance")?,
            orbit: None,
        });
    }
    scene.sky = spec.lights.env_radiance.map_or(Vec3::ZERO, Vec3::from);
    Ok(scene)
}

/// Loads a bare OBJ: camera framed on it, one point light under its top.
pub fn load_bare_obj(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let entry = ObjEntry {
        path,
        transform: Mat4::IDENTITY,
        emission_scale: 1.0,
        animation: None,
    };
    let mut scene = load_geometry(&[entry], options, path)?;
    if scene.meshes.is_empty() {
        bail!("scene has no triangles: {}", path.display());
    }
    let bounds = scene.bounds(0.0);
    let diagonal = bounds.size().length();
    let mut position = bounds.center();
    position.y = bounds.min.y + 0.9 * bounds.size().y;
    scene.lights.push(Light {
        kind: LightKind::Point,
        position,
        intensity: Vec3::splat(0.5 * diagonal * diagonal),
        orbit: None,
    });
    scene.camera = framing_camera(&scene);
    Ok(scene)
}
