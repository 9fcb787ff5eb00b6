//! Scene files: voxcone's TOML format, the path-traced references' `*.scene.json`, and a
//! bare `.obj`.
//!
//! # TOML scene format
//!
//! Right-handed coordinates, +Y up, scene units as in the OBJs. Relative paths are relative
//! to the scene file. Unknown keys are errors, so a typo never passes silently.
//!
//! ```toml
//! [camera]                       # optional: without it the camera frames the scene
//! position = [0.0, 1.0, 3.9]
//! target = [0.0, 1.0, 0.0]
//! up = [0.0, 1.0, 0.0]           # optional, default +Y; must not be parallel to the view
//! fov_y_deg = 39.3               # full vertical field of view in (0, 180), default 45
//!
//! [[mesh]]                       # at least one; each OBJ keeps its own materials
//! path = "cornell.obj"           # relative to the scene file, or absolute
//! translate = [0, 0, 0]          # optional
//! rotate_deg = [0, 0, 0]         # optional, about X first, then Y, then Z
//! scale = 1.0                    # optional, uniform, or per axis as [x, y, z]
//! emission_scale = 1.0           # optional, multiplies MTL Ke (0 turns the emitters off)
//! # optional animation, in object space before the transform above:
//! animate = { kind = "spin", axis = [0, 1, 0], deg_per_s = 45.0 }
//! # animate = { kind = "oscillate", axis = [1, 0, 0], amplitude = 0.5, period_s = 4.0 }
//!
//! [[light]]                      # any number, including none
//! kind = "point"
//! position = [0.0, 1.5, 0.0]
//! intensity = [3.0, 3.0, 3.0]    # radiant intensity in W/sr per channel
//! orbit = { center = [0, 1, 0], axis = [0, 1, 0], period_s = 8.0 }   # optional
//!
//! [[light]]
//! kind = "spot"
//! position = [0.0, 1.9, 0.0]
//! direction = [0.0, -1.0, 0.0]   # the cone's axis
//! intensity = [10.0, 10.0, 10.0] # W/sr on the axis
//! inner_deg = 20.0               # half-angle from the axis where the fall-off starts
//! outer_deg = 30.0               # half-angle where it reaches zero: inner <= outer < 90
//! # orbit as for point lights: it moves the position, the axis keeps its direction
//!
//! [[light]]
//! kind = "directional"
//! direction = [0.25, -1.0, 0.1]  # direction of travel (from the light into the scene)
//! irradiance = [8.0, 7.6, 7.0]   # W/m^2 on a surface facing the light; no orbit
//!
//! [sky]                          # optional
//! radiance = [0.3, 0.35, 0.45]   # constant environment radiance, default zero
//!
//! [gi]                           # optional; each key as its command-line option, which wins
//! voxels = 64                    # --voxels
//! diffuse_cones = 6              # --diffuse-cones
//! diffuse_aperture_deg = 60.0    # --diffuse-aperture
//! step_factor = 0.25             # --step-factor
//! bounce_step_factor = 0.5       # --bounce-step-factor
//! shadow_step_factor = 0.5       # --shadow-step-factor
//! wide_steps_by_level = false    # --wide-steps-by-level
//! bounces = 8                    # --bounces
//! indirect_scale = 2             # --indirect-scale (default: by image height)
//! shadow_cones = false           # --shadow-cones
//! shadow_aperture_deg = 4.0      # --shadow-aperture
//! ao_distance_voxels = 4.0       # --ao-distance
//! ```
//!
//! `spin` turns about the centre of the entry's object-space bounds at `deg_per_s`;
//! `oscillate` translates by `amplitude * sin(2 pi t / period_s)` along `axis`; `orbit`
//! turns a light's position about `center` around `axis` once per `period_s`. Axes and
//! directions need not be unit length but must be non-zero; intensities must be finite and
//! non-negative.
//!
//! # Reference `*.scene.json`
//!
//! Read keys: `scenes_root` (relative to the JSON's folder), `obj` (relative to
//! `scenes_root`), `camera.{pos, target, up, fov_y_deg}`, `lights.point[].{position,
//! intensity_W_sr}`, `lights.directional[].{direction_of_travel, irradiance_W_m2}`,
//! `lights.env_radiance` (null or RGB), `lights.mtl_emission` (false sets the emission scale
//! to 0) and `lights.emission_scale`. Other keys are ignored.
//!
//! # Bare `.obj`
//!
//! The camera looks at the centre of the bounds from the +Z side, a little above, far
//! enough for the bounding sphere to fit a 45 degree field of view. One point light sits
//! at 90 % of the height above the centre, with 0.5 * diagonal^2 W/sr per channel so that
//! its irradiance at the scene's scale stays about the same whatever the units.

use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context as _, Result};
use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;

use super::obj::{Geometry, ObjEntry};
use super::{Aabb, Animation, Camera, GiOverrides, Light, LightKind, LoadOptions, Orbit, Scene};

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: Option<CameraSpec>,
    #[serde(default)]
    mesh: Vec<MeshSpec>,
    #[serde(default)]
    light: Vec<LightSpec>,
    sky: Option<SkySpec>,
    gi: Option<GiOverrides>,
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
#[serde(untagged, expecting = "a number or an [x, y, z] array")]
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

/// One variant per kind, so that a key of another kind (a point light's `irradiance`) is
/// rejected like any unknown key.
#[derive(Deserialize, Debug)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
enum LightSpec {
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
        orbit: Option<OrbitSpec>,
    },
    Spot {
        position: [f32; 3],
        direction: [f32; 3],
        intensity: [f32; 3],
        inner_deg: f32,
        outer_deg: f32,
        orbit: Option<OrbitSpec>,
    },
    Directional {
        direction: [f32; 3],
        irradiance: [f32; 3],
    },
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

fn finite(v: [f32; 3], key: &str) -> Result<Vec3> {
    let v = Vec3::from(v);
    ensure!(v.is_finite(), "{key} must be finite, got {v}");
    Ok(v)
}

/// A direction or axis, normalised.
fn direction(v: [f32; 3], key: &str) -> Result<Vec3> {
    let v = finite(v, key)?;
    ensure!(v.length_squared() > 1e-12, "{key} must be non-zero");
    Ok(v.normalize())
}

fn non_negative(v: [f32; 3], key: &str) -> Result<Vec3> {
    let v = finite(v, key)?;
    ensure!(
        v.min_element() >= 0.0,
        "{key} must be non-negative, got {v}"
    );
    Ok(v)
}

fn positive(x: f32, key: &str) -> Result<f32> {
    ensure!(
        x.is_finite() && x > 0.0,
        "{key} must be positive and finite, got {x}"
    );
    Ok(x)
}

fn orbit(spec: &Option<OrbitSpec>, key: &str) -> Result<Option<Orbit>> {
    spec.as_ref()
        .map(|o| {
            Ok(Orbit {
                center: finite(o.center, &format!("{key}.center"))?,
                axis: direction(o.axis, &format!("{key}.axis"))?,
                period_s: positive(o.period_s, &format!("{key}.period_s"))?,
            })
        })
        .transpose()
}

fn light_from_spec(i: usize, spec: &LightSpec) -> Result<Light> {
    let key = |k: &str| format!("light[{i}].{k}");
    Ok(match spec {
        LightSpec::Point {
            position,
            intensity,
            orbit: o,
        } => Light {
            kind: LightKind::Point,
            position: finite(*position, &key("position"))?,
            intensity: non_negative(*intensity, &key("intensity"))?,
            orbit: orbit(o, &key("orbit"))?,
        },
        LightSpec::Spot {
            position,
            direction: axis,
            intensity,
            inner_deg,
            outer_deg,
            orbit: o,
        } => {
            let (inner, outer) = (*inner_deg, *outer_deg);
            ensure!(
                (0.0..90.0).contains(&outer),
                "{} must be in [0, 90) (a half-angle from the axis), got {outer}",
                key("outer_deg")
            );
            ensure!(
                (0.0..=outer).contains(&inner),
                "{} must be in [0, outer_deg = {outer}] (a half-angle from the axis), got {inner}",
                key("inner_deg")
            );
            Light {
                kind: LightKind::Spot {
                    direction: direction(*axis, &key("direction"))?,
                    inner_deg: inner,
                    outer_deg: outer,
                },
                position: finite(*position, &key("position"))?,
                intensity: non_negative(*intensity, &key("intensity"))?,
                orbit: orbit(o, &key("orbit"))?,
            }
        }
        LightSpec::Directional {
            direction: travel,
            irradiance,
        } => Light {
            kind: LightKind::Directional {
                direction: direction(*travel, &key("direction"))?,
            },
            position: Vec3::ZERO,
            intensity: non_negative(*irradiance, &key("irradiance"))?,
            orbit: None,
        },
    })
}

/// translate * rotate (X, then Y, then Z) * scale.
fn mesh_transform(i: usize, spec: &MeshSpec) -> Result<Mat4> {
    let key = |k: &str| format!("mesh[{i}].{k}");
    let scale = match spec.scale {
        None => Vec3::ONE,
        Some(Scale::Uniform(s)) => Vec3::splat(s),
        Some(Scale::Axes(s)) => Vec3::from(s),
    };
    ensure!(
        scale.is_finite() && scale.abs().min_element() > 1e-12,
        "{} must be finite and non-zero, got {scale}",
        key("scale")
    );
    let r = finite(spec.rotate_deg.unwrap_or([0.0; 3]), &key("rotate_deg"))?;
    let rotation = Quat::from_rotation_z(r.z.to_radians())
        * Quat::from_rotation_y(r.y.to_radians())
        * Quat::from_rotation_x(r.x.to_radians());
    let translation = finite(spec.translate.unwrap_or([0.0; 3]), &key("translate"))?;
    Ok(Mat4::from_scale_rotation_translation(
        scale,
        rotation,
        translation,
    ))
}

fn animation_from_spec(i: usize, spec: &Option<AnimationSpec>) -> Result<Option<Animation>> {
    let key = |k: &str| format!("mesh[{i}].animate.{k}");
    Ok(match spec {
        None => None,
        Some(AnimationSpec::Spin { axis, deg_per_s }) => {
            ensure!(deg_per_s.is_finite(), "{} must be finite", key("deg_per_s"));
            Some(Animation::Spin {
                axis: direction(*axis, &key("axis"))?,
                deg_per_s: *deg_per_s,
            })
        }
        Some(AnimationSpec::Oscillate {
            axis,
            amplitude,
            period_s,
        }) => {
            ensure!(amplitude.is_finite(), "{} must be finite", key("amplitude"));
            Some(Animation::Oscillate {
                axis: direction(*axis, &key("axis"))?,
                amplitude: *amplitude,
                period_s: positive(*period_s, &key("period_s"))?,
            })
        }
    })
}

fn camera_from(position: Vec3, target: Vec3, up: Vec3, fov_y_deg: f32) -> Result<Camera> {
    ensure!(
        fov_y_deg > 0.0 && fov_y_deg < 180.0,
        "camera.fov_y_deg must be in (0, 180), got {fov_y_deg}"
    );
    let forward = target - position;
    ensure!(
        forward.length_squared() > 1e-12,
        "camera.position and camera.target must differ"
    );
    ensure!(
        forward.normalize().cross(up).length_squared() > 1e-8,
        "camera.up must be non-zero and not parallel to target - position"
    );
    Ok(Camera::look_at(position, target, up.normalize(), fov_y_deg))
}

/// Looks at the centre of `bounds` from the +Z side, slightly above, with the bounding
/// sphere filling a 45 degree view.
fn framing_camera(bounds: &Aabb) -> Camera {
    const FOV_Y_DEG: f32 = 45.0;
    let center = bounds.center();
    let radius = (bounds.diagonal() * 0.5).max(1e-3);
    let distance = radius / (FOV_Y_DEG * 0.5).to_radians().sin();
    let direction = Vec3::new(0.0, 0.25, 1.0).normalize();
    Camera::look_at(center + direction * distance, center, Vec3::Y, FOV_Y_DEG)
}

/// Loads the OBJs and textures; camera, lights and sky are left for the caller.
fn load_geometry(entries: &[ObjEntry], options: &LoadOptions, source: &Path) -> Result<Scene> {
    let mut geometry = Geometry::default();
    for entry in entries {
        geometry.add_obj(entry, options)?;
    }
    let triangle_count = geometry.meshes.iter().map(|m| m.indices.len() / 3).sum();
    if triangle_count == 0 {
        bail!("scene has no triangles: {}", source.display());
    }
    let (meshes, materials, textures) = geometry.finish()?;
    Ok(Scene {
        meshes,
        materials,
        textures,
        camera: Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0),
        lights: Vec::new(),
        sky: Vec3::ZERO,
        source: source.to_path_buf(),
        triangle_count,
        gi: GiOverrides::default(),
    })
}

fn resolve(base: &Path, path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        base.join(path)
    }
}

fn folder(path: &Path) -> &Path {
    path.parent().unwrap_or(Path::new(""))
}

/// Loads a TOML scene (format in the module documentation).
pub fn load_toml(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let file: SceneFile =
        toml::from_str(&text).with_context(|| format!("invalid scene file {}", path.display()))?;
    scene_from_toml(&file, folder(path), path, options)
        .with_context(|| format!("in scene file {}", path.display()))
}

fn scene_from_toml(
    file: &SceneFile,
    base: &Path,
    source: &Path,
    options: &LoadOptions,
) -> Result<Scene> {
    ensure!(!file.mesh.is_empty(), "the scene has no [[mesh]] entries");
    // Everything that does not need the geometry is checked first, to fail before the
    // (possibly long) OBJ and texture loading.
    let camera = file
        .camera
        .as_ref()
        .map(|c| {
            camera_from(
                finite(c.position, "camera.position")?,
                finite(c.target, "camera.target")?,
                finite(c.up.unwrap_or([0.0, 1.0, 0.0]), "camera.up")?,
                c.fov_y_deg.unwrap_or(45.0),
            )
        })
        .transpose()?;
    let lights = file
        .light
        .iter()
        .enumerate()
        .map(|(i, l)| light_from_spec(i, l))
        .collect::<Result<Vec<_>>>()?;
    let sky = file
        .sky
        .as_ref()
        .map_or(Ok(Vec3::ZERO), |s| non_negative(s.radiance, "sky.radiance"))?;
    let paths: Vec<PathBuf> = file.mesh.iter().map(|m| resolve(base, &m.path)).collect();
    let entries = file
        .mesh
        .iter()
        .zip(&paths)
        .enumerate()
        .map(|(i, (spec, path))| {
            let emission_scale = spec.emission_scale.unwrap_or(1.0);
            ensure!(
                emission_scale.is_finite() && emission_scale >= 0.0,
                "mesh[{i}].emission_scale must be finite and non-negative, got {emission_scale}"
            );
            Ok(ObjEntry {
                path,
                transform: mesh_transform(i, spec)?,
                emission_scale,
                animation: animation_from_spec(i, &spec.animate)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;

    let mut scene = load_geometry(&entries, options, source)?;
    scene.camera = camera.unwrap_or_else(|| framing_camera(&scene.bounds(0.0)));
    scene.lights = lights;
    scene.sky = sky;
    scene.gi = file.gi.unwrap_or_default();
    Ok(scene)
}

#[derive(Deserialize)]
struct ReferenceScene {
    scenes_root: Option<PathBuf>,
    obj: PathBuf,
    camera: ReferenceCamera,
    lights: ReferenceLights,
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
    let entry = ObjEntry {
        path: &obj_path,
        transform: Mat4::IDENTITY,
        emission_scale,
        animation: None,
    };
    let mut scene = load_geometry(&[entry], options, source)?;
    scene.camera = camera;
    scene.lights = lights;
    scene.sky = sky;
    Ok(scene)
}

/// Loads a bare OBJ with a framing camera and one point light (see the module docs).
pub fn load_bare_obj(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let entry = ObjEntry {
        path,
        transform: Mat4::IDENTITY,
        emission_scale: 1.0,
        animation: None,
    };
    let mut scene = load_geometry(&[entry], options, path)?;
    let bounds = scene.bounds(0.0);
    let diagonal = bounds.diagonal();
    let mut position = bounds.center();
    position.y = bounds.min.y + 0.9 * bounds.size().y;
    scene.lights.push(Light {
        kind: LightKind::Point,
        position,
        intensity: Vec3::splat(0.5 * diagonal * diagonal),
        orbit: None,
    });
    scene.camera = framing_camera(&bounds);
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::super::testing::{error_text, shared_dir, write_quad, TempDir};
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
        // The swept bounds hold the scene at every time, and the shadow views built from
        // them stay put while the meshes move (the lights held still).
        let swept = scene.swept_bounds();
        for i in 0..40 {
            let now = scene.bounds(i as f32 * 0.1);
            assert!(now.min.cmpge(swept.min - 1e-5).all() && now.max.cmple(swept.max + 1e-5).all());
        }
        let mut still = scene.clone();
        for light in &mut still.lights {
            light.orbit = None;
        }
        let views = |t| crate::shadow::scene_views(&still, t, Default::default());
        assert_eq!(
            bytemuck::cast_slice::<_, u8>(&views(0.0)),
            bytemuck::cast_slice::<_, u8>(&views(1.0))
        );

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
        assert!(scene.camera.near > 0.0 && scene.camera.far > 3.9);
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
        assert_eq!(
            scene.lights[0].kind,
            LightKind::Directional {
                direction: Vec3::NEG_Y
            }
        );
        assert_eq!(scene.lights[0].intensity, Vec3::new(1.0, 2.0, 3.0));

        let broken = dir.write("broken.scene.json", "{\"obj\": 3}");
        let message = error_text(Scene::load(&broken, &LoadOptions::default()));
        assert!(message.contains("broken.scene.json"), "{message}");
    }

    #[test]
    fn reference_cornell_point_direct() {
        let Some(shared) = shared_dir() else { return };
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
        let b = scene.bounds(0.0);
        assert!(b.min.abs_diff_eq(Vec3::new(-1.0, 0.0, -1.0), 0.05), "{b:?}");
        assert!(b.max.abs_diff_eq(Vec3::new(1.0, 2.0, 1.0), 0.05), "{b:?}");
    }

    #[test]
    fn reference_sponza_main() {
        let Some(shared) = shared_dir() else { return };
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
