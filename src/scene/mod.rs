//! Scenes: OBJ/MTL and glTF geometry and materials, textures with mips, camera, lights,
//! animation.
//!
//! Pure CPU code: everything the renderer uploads is decoded and laid out here, so the
//! loaders can be tested without a GPU. The scene file formats are described in `file.rs`.

mod animation;
mod camera;
mod file;
mod geometry;
mod gltf_file;
mod light;
mod obj;
mod reference;
mod texture;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, Result};
use glam::{Mat4, Vec3};

pub use animation::{Animation, Orbit};
pub use camera::Camera;
pub use light::{Light, LightKind};
pub use texture::{Adjust, AlphaCutout, Texture, TextureKind};

/// One vertex, as uploaded to the GPU.
///
/// `uv` is stored as `[u, 1 - v]` of the OBJ's texture coordinate: OBJ puts v = 0 at the
/// bottom of the image, whereas texture memory starts with the top row, so after this single
/// flip at load time (0, 0) is the top-left texel of row 0 and shaders sample `uv` as is.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

/// An axis-aligned box. [`Aabb::EMPTY`] (inverted, infinite) is the identity of `union`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Self = Self {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    pub fn extend(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    pub fn size(&self) -> Vec3 {
        self.max - self.min
    }

    pub fn diagonal(&self) -> f32 {
        self.size().length()
    }

    /// The bounds of this box's eight corners after `m` (conservative under rotation).
    pub fn transformed(&self, m: Mat4) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        let mut out = Aabb::EMPTY;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            out.extend(m.transform_point3(corner));
        }
        out
    }
}

/// Triangles of one material from one OBJ model or glTF primitive.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub name: String,
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
    pub material: u32,
    /// Object to world, from the scene file.
    pub transform: Mat4,
    pub animation: Option<Animation>,
    /// Object-space bounds of this mesh's vertices.
    pub local_bounds: Aabb,
    /// Object-space bounds of everything its scene-file entry loaded. Animations pivot about
    /// its centre, so that the many meshes of one OBJ move as one rigid object.
    pub object_bounds: Aabb,
    /// The lightmap UVs of its vertices where the file has a second UV set (glTF's
    /// TEXCOORD_1), (0, 0) the top-left; else empty (the probes' bake makes an atlas).
    pub lightmap_uvs: Vec<[f32; 2]>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Kd (0.8 when the MTL has none, as the references assume).
    pub albedo: Vec3,
    /// Multiplies `albedo`.
    pub albedo_texture: Option<u32>,
    /// Ks (zero with [`LoadOptions::diffuse_only`]).
    pub specular: Vec3,
    /// From Ns: sqrt(2 / (Ns + 2)), the Beckmann-to-Phong correspondence, clamped to
    /// [0.02, 1].
    pub roughness: f32,
    /// Ke times the scene entry's emission_scale: radiance of a one-sided emitter along the
    /// winding normal.
    pub emission: Vec3,
    /// Multiplies `emission` (map_Ke, glTF's emissive texture).
    pub emission_texture: Option<u32>,
    /// d, or 1 - Tr (1 = opaque).
    pub dissolve: f32,
    /// map_d cut-out coverage.
    pub coverage_texture: Option<u32>,
    /// Tangent-space normal map (`norm`, or a `map_Bump`/`bump` whose file name says it is a
    /// normal map; height maps are ignored).
    pub normal_texture: Option<u32>,
    /// Ni.
    pub ior: f32,
}

impl Material {
    /// Grey 0.8, for groups without a material (the references' convention).
    pub fn default_grey() -> Self {
        Self {
            name: "default".into(),
            albedo: Vec3::splat(0.8),
            albedo_texture: None,
            specular: Vec3::ZERO,
            roughness: 1.0,
            emission: Vec3::ZERO,
            emission_texture: None,
            dissolve: 1.0,
            coverage_texture: None,
            normal_texture: None,
            ior: 1.0,
        }
    }

    /// Whether light passing the surface bends (d < 1 and Ni > 1): ray casting then counts
    /// only map_d as a cut-out and leaves the 1 - d that passes to the shading, which
    /// refracts it. With Ni = 1 the light passes straight, as through a cut-out of
    /// coverage d.
    pub fn refracts(&self) -> bool {
        self.dissolve < 1.0 && self.ior > 1.0
    }

    /// Whether rays pass the surface where its coverage (d x map_d, map_d alone where it
    /// refracts) falls short: ray casting's `RAY_CUT_OUT`.
    pub fn cut_out(&self) -> bool {
        self.coverage_texture.is_some() || (self.dissolve < 1.0 && !self.refracts())
    }
}

/// How to load a scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// Ignore Ks (Lambertian only).
    pub diffuse_only: bool,
    /// Ignore normal maps (they are not even loaded).
    pub no_normal_maps: bool,
    /// Ignore Ni: transmissive surfaces (d < 1) pass light straight through.
    pub no_refraction: bool,
}

impl LoadOptions {
    /// The conventions of the path-traced references: Lambertian, no normal maps, `d` a
    /// straight mask.
    pub const REFERENCE: Self = Self {
        diffuse_only: true,
        no_normal_maps: true,
        no_refraction: true,
    };
}

/// GI settings a scene file may give (`[gi]`); the command line overrides them.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GiOverrides {
    /// The cone tracer's defaults (`--quality`).
    pub quality: Option<crate::gi::vct::Quality>,
    pub voxels: Option<u32>,
    /// The largest voxel wanted, in scene units (`--voxel-size`).
    pub voxel_size: Option<f32>,
    pub diffuse_cones: Option<u32>,
    pub diffuse_aperture_deg: Option<f32>,
    pub step_factor: Option<f32>,
    pub bounce_step_factor: Option<f32>,
    pub shadow_step_factor: Option<f32>,
    pub wide_steps_by_level: Option<bool>,
    pub cosine_cones: Option<bool>,
    pub snapped_cones: Option<bool>,
    pub lattice_cones: Option<u32>,
    pub bounces: Option<u32>,
    pub indirect_scale: Option<u32>,
    pub shadow_cones: Option<bool>,
    pub shadow_aperture_deg: Option<f32>,
    pub ao_distance_voxels: Option<f32>,
    pub sampled_emitters: Option<u32>,
    pub emitter_pieces: Option<u32>,
    /// The path tracer's samples per pixel.
    pub spp: Option<u32>,
    /// The path tracer's longest path (a reference's `flags.max_depth`, where it has one).
    pub max_depth: Option<u32>,
    /// The irradiance probes' bake: lightmap page size, desired probe count, N_OVERLAPS,
    /// each probe's map side, its relight map's side, rays per receiver, highest harmonic
    /// band.
    pub lightmap_size: Option<u32>,
    pub probes: Option<u32>,
    pub overlaps: Option<u32>,
    pub probe_side: Option<u32>,
    pub relight_side: Option<u32>,
    pub receiver_rays: Option<u32>,
    pub sh_order: Option<u32>,
    /// The irradiance probes' clustered PCA: error bound and most basis vectors.
    pub pca_error: Option<f32>,
    pub max_basis: Option<u32>,
    /// The irradiance probes' grid for moving meshes: the desired spatial receivers.
    pub spatial_receivers: Option<u32>,
    /// The irradiance probes' bounces in a first frame.
    pub probe_bounces: Option<u32>,
    /// The irradiance probes' level of detail, and the distances where its levels 1 to 3
    /// begin.
    pub probe_lod: Option<bool>,
    pub lod_distances: Option<[f32; 3]>,
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub camera: Camera,
    pub lights: Vec<Light>,
    /// Constant sky radiance (zero when the scene has none).
    pub sky: Vec3,
    pub source: PathBuf,
    pub triangle_count: usize,
    /// GI settings from the scene file.
    pub gi: GiOverrides,
    /// The image size the scene file asks for (a reference's `resolution`): `render`'s and
    /// `bench`'s size without `--size`.
    pub image_size: Option<(u32, u32)>,
}

impl Scene {
    /// Loads a `.toml` scene file, a reference `.scene.json`, a bare `.obj`, or a glTF
    /// scene (`.gltf`, `.glb`).
    pub fn load(path: &Path, options: &LoadOptions) -> Result<Scene> {
        if !path.is_file() {
            bail!("scene file not found: {}", path.display());
        }
        let start = Instant::now();
        let name = path.to_string_lossy().to_ascii_lowercase();
        let mut scene = if name.ends_with(".toml") {
            file::load_toml(path, options)?
        } else if name.ends_with(".json") {
            reference::load_reference_json(path, options)?
        } else if name.ends_with(".obj") {
            file::load_bare_obj(path, options)?
        } else if name.ends_with(".gltf") || name.ends_with(".glb") {
            file::load_bare_gltf(path, options)?
        } else {
            bail!(
                "{}: unknown scene type (expected .toml, .scene.json, .obj, .gltf or .glb)",
                path.display()
            );
        };
        scene.camera.fit_clip_planes(&scene.bounds(0.0));
        log::info!(
            "loaded {} in {:.2} s: {} triangles, {} meshes, {} materials, {} textures, {} lights",
            path.display(),
            start.elapsed().as_secs_f64(),
            scene.triangle_count,
            scene.meshes.len(),
            scene.materials.len(),
            scene.textures.len(),
            scene.lights.len()
        );
        Ok(scene)
    }

    /// World bounds at time `time_s`, animated meshes included.
    pub fn bounds(&self, time_s: f32) -> Aabb {
        (0..self.meshes.len()).fold(Aabb::EMPTY, |b, i| {
            b.union(
                &self.meshes[i]
                    .local_bounds
                    .transformed(self.mesh_transform(i, time_s)),
            )
        })
    }

    /// World bounds that hold the scene at every time (moving meshes over their whole
    /// motion): what the shadow maps and the voxel grid cover, so that they stay put as
    /// meshes move.
    pub fn swept_bounds(&self) -> Aabb {
        self.meshes.iter().fold(Aabb::EMPTY, |b, m| {
            let object = match &m.animation {
                Some(a) => a.swept(&m.local_bounds, &m.object_bounds),
                None => m.local_bounds,
            };
            b.union(&object.transformed(m.transform))
        })
    }

    /// Object to world of mesh `mesh` at time `time_s`: the animation acts in object space.
    pub fn mesh_transform(&self, mesh: usize, time_s: f32) -> Mat4 {
        let m = &self.meshes[mesh];
        match &m.animation {
            Some(a) => m.transform * a.matrix(&m.object_bounds, time_s),
            None => m.transform,
        }
    }

    /// Light `light` at time `time_s` (orbit applied).
    pub fn light_at(&self, light: usize, time_s: f32) -> Light {
        let mut l = self.lights[light].clone();
        if let Some(orbit) = &l.orbit {
            l.position = orbit.apply(l.position, time_s);
        }
        l
    }

    /// Whether some mesh moves (lights may orbit without it).
    pub fn has_moving_meshes(&self) -> bool {
        self.meshes.iter().any(|m| m.animation.is_some())
    }

    /// World bounds of the moving meshes at time `time_s` (empty without any).
    pub fn moving_bounds(&self, time_s: f32) -> Aabb {
        (0..self.meshes.len())
            .filter(|&i| self.meshes[i].animation.is_some())
            .fold(Aabb::EMPTY, |b, i| {
                b.union(
                    &self.meshes[i]
                        .local_bounds
                        .transformed(self.mesh_transform(i, time_s)),
                )
            })
    }

    pub fn is_animated(&self) -> bool {
        self.meshes.iter().any(|m| m.animation.is_some())
            || self.lights.iter().any(|l| l.orbit.is_some())
    }

    /// The area of mesh `mesh`'s triangles in the world at time 0.
    pub fn mesh_area(&self, mesh: usize) -> f64 {
        let model = self.mesh_transform(mesh, 0.0);
        let mesh = &self.meshes[mesh];
        mesh.indices
            .chunks_exact(3)
            .map(|t| {
                let p = [t[0], t[1], t[2]].map(|i| {
                    model.transform_point3(Vec3::from(mesh.vertices[i as usize].position))
                });
                f64::from((p[1] - p[0]).cross(p[2] - p[0]).length() * 0.5)
            })
            .sum()
    }

    /// The mean albedo of material `material`: its Kd times its texture's mean (the 1x1
    /// level, averaged in linear light).
    pub fn material_albedo(&self, material: u32) -> Vec3 {
        let material = &self.materials[material as usize];
        let mean = material.albedo_texture.map_or(Vec3::ONE, |t| {
            let texel = &self.textures[t as usize].mips.last().expect("a 1x1 level")[..4];
            let [r, g, b, _] =
                crate::imageio::srgba8_decode([texel[0], texel[1], texel[2], texel[3]]);
            Vec3::new(r, g, b)
        });
        material.albedo * mean
    }
}

/// Fixtures shared by the tests of this module's files.
#[cfg(test)]
pub(crate) mod testing {
    use std::path::{Path, PathBuf};
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// The shared scenes and references that build.rs found. Only tests marked
    /// `#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]` call it.
    pub fn shared_dir() -> PathBuf {
        // Reached without it only under `--include-ignored`.
        let dir = option_env!("VOXCONE_SHARED_DIR");
        PathBuf::from(dir.unwrap_or_else(|| panic!("built without ../shared (see build.rs)")))
    }

    /// `path` under the shared folder.
    pub fn shared_file(path: &str) -> PathBuf {
        shared_dir().join(path)
    }

    /// A fresh folder under the system temp dir, removed again when dropped.
    pub struct TempDir(pub PathBuf);

    impl TempDir {
        pub fn new(name: &str) -> Self {
            static NEXT: AtomicUsize = AtomicUsize::new(0);
            let dir = std::env::temp_dir().join(format!(
                "voxcone-scene-{}-{}-{name}",
                std::process::id(),
                NEXT.fetch_add(1, Ordering::Relaxed)
            ));
            std::fs::create_dir_all(&dir).unwrap();
            Self(dir)
        }

        pub fn write(&self, name: &str, text: &str) -> PathBuf {
            let path = self.0.join(name);
            std::fs::write(&path, text).unwrap();
            path
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// A unit quad in z = 0 (two triangles, counter-clockwise seen from +Z) with material
    /// `lamp`: Kd, Ke, Ks, Ns and a 2x2 PNG as map_Kd and map_d.
    pub fn write_quad(dir: &Path) -> PathBuf {
        image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 128, 0, 255]))
            .save(dir.join("tex.png"))
            .unwrap();
        let write = |name: &str, text: &str| {
            std::fs::write(dir.join(name), text).unwrap();
            dir.join(name)
        };
        write(
            "quad.mtl",
            "newmtl lamp\nKd 0.5 0.5 0.5\nKe 2 3 4\nKs 0.5 0.5 0.5\nNs 98\nNi 1.5\nTr 0.25\n\
             map_Kd tex.png\nmap_d -imfchan m tex.png\n",
        );
        write(
            "quad.obj",
            "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
             vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl lamp\nf 1/1 2/2 3/3 4/4\n",
        )
    }

    /// `format!("{e:#}")` of the error of `result`, which must have failed.
    pub fn error_text<T>(result: anyhow::Result<T>) -> String {
        match result {
            Ok(_) => panic!("expected an error"),
            Err(e) => format!("{e:#}"),
        }
    }
}
