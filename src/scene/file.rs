//! Scene files: voxcone's TOML format, a bare `.obj` and a bare glTF (the path-traced
//! references' `*.scene.json`: `super::reference`), and what loading them shares.
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
//! [[mesh]]                       # at least one; each file keeps its own materials
//! path = "cornell.obj"           # .obj, .gltf or .glb, relative to the scene file or absolute
//! translate = [0, 0, 0]          # optional
//! rotate_deg = [0, 0, 0]         # optional, about X first, then Y, then Z
//! scale = 1.0                    # optional, uniform, or per axis as [x, y, z]
//! emission_scale = 1.0           # optional, multiplies Ke or glTF emission (0: emitters off)
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
//! quality = "accurate"           # --quality: "fast" or "accurate" (default: by the command)
//! voxels = 64                    # --voxels (default: by the device, see voxel_size)
//! voxel_size = 0.05              # --voxel-size: instead of voxels, the largest voxel
//! diffuse_cones = 6              # --diffuse-cones
//! diffuse_aperture_deg = 60.0    # --diffuse-aperture
//! step_factor = 0.25             # --step-factor
//! bounce_step_factor = 0.5       # --bounce-step-factor
//! shadow_step_factor = 0.5       # --shadow-step-factor
//! wide_steps_by_level = false    # --wide-steps-by-level
//! cosine_cones = false           # --cosine-cones
//! snapped_cones = false          # --snapped-cones
//! lattice_cones = 72             # --lattice-cones (default: 72 where quality is accurate, else
//!                                #   0, the ring of diffuse_cones)
//! bounces = 8                    # --bounces
//! indirect_scale = 2             # --indirect-scale (default: by image height)
//! shadow_cones = false           # --shadow-cones
//! shadow_aperture_deg = 4.0      # --shadow-aperture
//! ao_distance_voxels = 4.0       # --ao-distance
//! sampled_emitters = 64          # --sampled-emitters
//! emitter_pieces = 8             # --emitter-pieces (default: 8 where quality is accurate, else 1)
//! spp = 256                      # --spp (--gi path)
//! max_depth = 2                  # --max-depth (--gi path): 2 is direct light only
//! lightmap_size = 512            # --lightmap-size (--gi probes and bake)
//! probes = 256                   # --probes
//! overlaps = 10                  # --overlaps
//! probe_side = 64                # --probe-side
//! relight_side = 64              # --relight-side
//! receiver_rays = 64             # --receiver-rays
//! sh_order = 7                   # --sh-order
//! pca_error = 0.005              # --pca-error
//! max_basis = 32                 # --max-basis
//! spatial_receivers = 2048       # --spatial-receivers
//! probe_bounces = 8              # --probe-bounces (--gi probes)
//! probe_lod = true               # --probe-lod on|off (--gi probes)
//! lod_distances = [4.0, 8.0, 16.0]   # --lod-distances (--gi probes)
//! ```
//!
//! `spin` turns about the centre of the entry's object-space bounds at `deg_per_s`;
//! `oscillate` translates by `amplitude * sin(2 pi t / period_s)` along `axis`; `orbit`
//! turns a light's position about `center` around `axis` once per `period_s`. Axes and
//! directions need not be unit length but must be non-zero; intensities must be finite and
//! non-negative.
//!
//! A glTF mesh entry brings its geometry and materials only: a TOML scene's camera and
//! lights are those of the TOML.
//!
//! # Bare `.obj` and glTF
//!
//! The camera looks at the centre of the bounds from the +Z side, a little above, far
//! enough for the bounding sphere to fit a 45 degree field of view. One point light sits
//! at 90 % of the height above the centre, with 0.5 * diagonal^2 W/sr per channel so that
//! its irradiance at the scene's scale stays about the same whatever the units. A bare
//! glTF keeps its first camera and its lights, and gets the framing camera and the point
//! light only where it has none (the light only when nothing emits either).

use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context as _, Result};
use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;

use super::geometry::{FileSetup, Geometry, MeshEntry};
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

pub(super) fn finite(v: [f32; 3], key: &str) -> Result<Vec3> {
    let v = Vec3::from(v);
    ensure!(v.is_finite(), "{key} must be finite, got {v}");
    Ok(v)
}

/// A direction or axis, normalised.
pub(super) fn direction(v: [f32; 3], key: &str) -> Result<Vec3> {
    let v = finite(v, key)?;
    ensure!(v.length_squared() > 1e-12, "{key} must be non-zero");
    Ok(v.normalize())
}

pub(super) fn non_negative(v: [f32; 3], key: &str) -> Result<Vec3> {
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

pub(super) fn camera_from(
    position: Vec3,
    target: Vec3,
    up: Vec3,
    fov_y_deg: f32,
) -> Result<Camera> {
    ensure!(
        fov_y_deg > 0.0 && fov_y_deg < 180.0,
        "camera.fov_y_deg must be in (0, 180), got {fov_y_deg}"
    );
    let forward = target - position;
    ensure!(
        forward.length_squared() > 0.0,
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
    // In the scene's units, however small; a scene of one point gets a unit sphere.
    let half = bounds.diagonal() * 0.5;
    let radius = if half > 0.0 { half } else { 1.0 };
    let distance = radius / (FOV_Y_DEG * 0.5).to_radians().sin();
    let direction = Vec3::new(0.0, 0.25, 1.0).normalize();
    Camera::look_at(center + direction * distance, center, Vec3::Y, FOV_Y_DEG)
}

/// Loads the mesh files and textures, with the cameras and lights the files bring (the
/// first camera, every light); the scene's camera, lights and sky are left for the caller.
pub(super) fn load_geometry(
    entries: &[MeshEntry],
    options: &LoadOptions,
    source: &Path,
) -> Result<(Scene, FileSetup)> {
    let mut geometry = Geometry::default();
    let mut setup = FileSetup::default();
    for entry in entries {
        let file = geometry.add(entry, options)?;
        setup.camera = setup.camera.or(file.camera);
        setup.lights.extend(file.lights);
    }
    let triangle_count = geometry.meshes.iter().map(|m| m.indices.len() / 3).sum();
    if triangle_count == 0 {
        bail!("scene has no triangles: {}", source.display());
    }
    let (meshes, materials, textures) = geometry.finish()?;
    let scene = Scene {
        meshes,
        materials,
        textures,
        camera: Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0),
        lights: Vec::new(),
        sky: Vec3::ZERO,
        source: source.to_path_buf(),
        triangle_count,
        gi: GiOverrides::default(),
        image_size: None,
    };
    Ok((scene, setup))
}

pub(super) fn resolve(base: &Path, path: &Path) -> PathBuf {
    if path.is_absolute() {
        path.to_path_buf()
    } else {
        base.join(path)
    }
}

pub(super) fn folder(path: &Path) -> &Path {
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
            Ok(MeshEntry {
                path,
                transform: mesh_transform(i, spec)?,
                emission_scale,
                animation: animation_from_spec(i, &spec.animate)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;

    let (mut scene, setup) = load_geometry(&entries, options, source)?;
    if setup.camera.is_some() || !setup.lights.is_empty() {
        log::info!(
            "the cameras and {} lights of the glTF meshes are not used: a TOML scene takes \
             them from [camera] and [[light]]",
            setup.lights.len()
        );
    }
    scene.camera = camera.unwrap_or_else(|| framing_camera(&scene.bounds(0.0)));
    scene.lights = lights;
    scene.sky = sky;
    scene.gi = file.gi.unwrap_or_default();
    Ok(scene)
}

/// Loads a bare OBJ with a framing camera and one point light (see the module docs).
pub fn load_bare_obj(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let (mut scene, _) = load_geometry(&[MeshEntry::bare(path)], options, path)?;
    let bounds = scene.bounds(0.0);
    scene.lights.push(default_light(&bounds));
    scene.camera = framing_camera(&bounds);
    Ok(scene)
}

/// Loads a glTF scene with its first camera and its lights; without a camera it is framed,
/// and without lights or emissive materials it gets a bare OBJ's point light.
pub fn load_bare_gltf(path: &Path, options: &LoadOptions) -> Result<Scene> {
    let (mut scene, setup) = load_geometry(&[MeshEntry::bare(path)], options, path)?;
    let bounds = scene.bounds(0.0);
    scene.camera = setup.camera.unwrap_or_else(|| framing_camera(&bounds));
    scene.lights = setup.lights;
    let emissive = scene
        .materials
        .iter()
        .any(|m| m.emission.max_element() > 0.0);
    if scene.lights.is_empty() && !emissive {
        log::info!("{} has no lights: adding a point light", path.display());
        scene.lights.push(default_light(&bounds));
    }
    Ok(scene)
}

/// At 90 % of the height above the centre, with 0.5 * diagonal^2 W/sr (module docs).
fn default_light(bounds: &Aabb) -> Light {
    let diagonal = bounds.diagonal();
    let mut position = bounds.center();
    position.y = bounds.min.y + 0.9 * bounds.size().y;
    Light {
        kind: LightKind::Point,
        position,
        intensity: Vec3::splat(0.5 * diagonal * diagonal),
        orbit: None,
    }
}

#[cfg(test)]
mod tests;
