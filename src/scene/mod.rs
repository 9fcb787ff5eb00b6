//! Scenes: OBJ/MTL geometry and materials, textures with mips, camera, lights, animation.

mod animation;
mod camera;
mod file;
mod light;
mod obj;
mod texture;

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use glam::{Mat4, Vec3};

pub use animation::{Animation, Orbit};
pub use camera::Camera;
pub use light::{Light, LightKind};
pub use texture::{Texture, TextureKind};

/// One vertex. `uv` has v running down the image (row 0 at v = 0): OBJ's v is flipped once
/// at load time, so textures are sampled as stored in memory.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
}

/// An axis-aligned box.
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

    /// The bounds of this box's eight corners after `m`.
    pub fn transformed(&self, m: Mat4) -> Aabb {
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

/// Triangles of one material.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub name: String,
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
    pub material: u32,
    /// Object to world, from the scene file.
    pub transform: Mat4,
    pub animation: Option<Animation>,
    pub local_bounds: Aabb,
}

#[derive(Clone, Debug)]
pub struct Material {
    pub name: String,
    /// Kd.
    pub albedo: Vec3,
    pub albedo_texture: Option<u32>,
    /// Ks.
    pub specular: Vec3,
    /// From Ns: sqrt(2 / (Ns + 2)).
    pub roughness: f32,
    /// Ke times the mesh entry's emission_scale: radiance along the winding normal.
    pub emission: Vec3,
    /// d (1 = opaque).
    pub dissolve: f32,
    /// map_d cut-out coverage.
    pub coverage_texture: Option<u32>,
    /// Tangent-space normal map.
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
            dissolve: 1.0,
            coverage_texture: None,
            normal_texture: None,
            ior: 1.0,
        }
    }
}

/// How to load a scene.
#[derive(Clone, Copy, Debug, Default)]
pub struct LoadOptions {
    /// Ignore Ks (Lambertian only).
    pub diffuse_only: bool,
    /// Ignore normal maps (they are not even loaded).
    pub no_normal_maps: bool,
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub camera: Camera,
    pub lights: Vec<Light>,
    /// Constant sky radiance.
    pub sky: Vec3,
    pub source: PathBuf,
    pub triangle_count: usize,
}

impl Scene {
    /// Loads a `.toml` scene file, a reference `.scene.json`, or a bare `.obj`.
    pub fn load(path: &Path, options: &LoadOptions) -> Result<Scene> {
        if !path.exists() {
            bail!("scene file not found: {}", path.display());
        }
        let name = path.to_string_lossy().to_ascii_lowercase();
        let mut scene = if name.ends_with(".toml") {
            file::load_toml(path, options)?
        } else if name.ends_with(".json") {
            file::load_reference_json(path, options)?
        } else if name.ends_with(".obj") {
            file::load_bare_obj(path, options)?
        } else {
            bail!(
                "{}: unknown scene type (expected .toml, .scene.json or .obj)",
                path.display()
            );
        };
        scene.triangle_count = scene.meshes.iter().map(|m| m.indices.len() / 3).sum();
        if scene.triangle_count == 0 {
            bail!("scene has no triangles: {}", path.display());
        }
        scene.camera.fit_clip_planes(&scene.bounds(0.0));
        Ok(scene)
    }

    /// World bounds at time `time_s`.
    pub fn bounds(&self, time_s: f32) -> Aabb {
        (0..self.meshes.len()).fold(Aabb::EMPTY, |b, i| {
            b.union(
                &self.meshes[i]
                    .local_bounds
                    .transformed(self.mesh_transform(i, time_s)),
            )
        })
    }

    /// Object to world of mesh `mesh` at time `time_s`.
    pub fn mesh_transform(&self, mesh: usize, time_s: f32) -> Mat4 {
        let m = &self.meshes[mesh];
        match &m.animation {
            Some(a) => m.transform * a.matrix(&m.local_bounds, time_s),
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

    pub fn is_animated(&self) -> bool {
        self.meshes.iter().any(|m| m.animation.is_some())
            || self.lights.iter().any(|l| l.orbit.is_some())
    }
}
