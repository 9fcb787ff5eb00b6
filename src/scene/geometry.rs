//! What the mesh loaders (OBJ in `obj.rs`, glTF in `gltf_file.rs`) share: the scene's
//! meshes and materials as they accumulate, the triangles of one model, and the textures
//! requested while the files are read, decoded together at the end.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{bail, Context as _, Result};
use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::texture::Adjust;
use super::{Aabb, Animation, Camera, Light, LoadOptions, Material, Mesh, Texture};
use super::{TextureKind, Vertex};
use crate::progress::Progress;

/// What a scene file says about one mesh file (`.obj`, `.gltf` or `.glb`).
pub struct MeshEntry<'a> {
    pub path: &'a Path,
    pub transform: Mat4,
    pub emission_scale: f32,
    pub animation: Option<Animation>,
}

impl<'a> MeshEntry<'a> {
    /// The file on its own: no transform, animation or emission scale.
    pub fn bare(path: &'a Path) -> Self {
        Self {
            path,
            transform: Mat4::IDENTITY,
            emission_scale: 1.0,
            animation: None,
        }
    }
}

/// The camera and lights a mesh file brings (glTF's cameras and `KHR_lights_punctual`),
/// in world space.
#[derive(Default)]
pub struct FileSetup {
    pub camera: Option<Camera>,
    pub lights: Vec<Light>,
}

/// The meshes and materials of a scene's files. Textures are only collected while the
/// files are read, so that [`Geometry::finish`] can decode all of them in parallel.
#[derive(Default)]
pub struct Geometry {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    pub(super) textures: TextureRequests,
    /// Shared by every group without a material, in every file of the scene.
    default_material: Option<u32>,
}

impl Geometry {
    /// Reads one mesh file, by its extension. Its materials are appended after those
    /// already loaded, so that equal names in different files stay different materials.
    pub fn add(&mut self, entry: &MeshEntry, options: &LoadOptions) -> Result<FileSetup> {
        let name = entry.path.to_string_lossy().to_ascii_lowercase();
        if name.ends_with(".gltf") || name.ends_with(".glb") {
            super::gltf_file::add(self, entry, options)
        } else if name.ends_with(".obj") {
            super::obj::add(self, entry, options)?;
            Ok(FileSetup::default())
        } else {
            bail!(
                "{}: unknown mesh file type (expected .obj, .gltf or .glb)",
                entry.path.display()
            )
        }
    }

    pub(super) fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.materials.push(Material::default_grey());
            self.materials.len() as u32 - 1
        })
    }

    /// Adds the meshes of one file entry, each with the bounds of all of them as its
    /// object bounds (the pivot of the entry's animation).
    pub(super) fn push_entry_meshes(&mut self, mut meshes: Vec<Mesh>) {
        let object_bounds = meshes
            .iter()
            .fold(Aabb::EMPTY, |b, m| b.union(&m.local_bounds));
        for mesh in &mut meshes {
            mesh.object_bounds = object_bounds;
        }
        self.meshes.extend(meshes);
    }

    /// Decodes every requested texture (in parallel) and builds its mips.
    pub fn finish(self) -> Result<(Vec<Mesh>, Vec<Material>, Vec<Texture>)> {
        let textures = self.textures.decode()?;
        Ok((self.meshes, self.materials, textures))
    }
}

/// The triangles of one model, ready for a [`Mesh`].
pub struct ModelGeometry {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
    pub bounds: Aabb,
    /// The second UV set per vertex, where the model gave one for every position.
    pub lightmap_uvs: Vec<[f32; 2]>,
}

/// One model's vertex attributes as a file gives them, each list indexed by `indices`.
pub struct ModelAttributes<'a> {
    pub name: &'a str,
    pub positions: &'a [Vec3],
    /// Used only when there is one for every position, none of them zero.
    pub normals: &'a [Vec3],
    /// `[u, v]` with (0, 0) the top-left of the image; used only when there is one for
    /// every position.
    pub uvs: &'a [[f32; 2]],
    /// A second UV set (glTF's TEXCOORD_1), the irradiance probes' lightmap UVs; used only
    /// when there is one for every position.
    pub lightmap_uvs: &'a [[f32; 2]],
    pub indices: &'a [u32],
}

/// The triangles of `model`, or `None` for a model without any of non-zero area.
pub fn model_geometry(model: &ModelAttributes) -> Result<Option<ModelGeometry>> {
    let count = model.positions.len();
    if model.positions.iter().any(|p| !p.is_finite()) {
        bail!(
            "model {:?} has a vertex position that is not a finite number",
            model.name
        );
    }
    if model.indices.iter().any(|&i| i as usize >= count) {
        bail!(
            "model {:?} indexes a vertex that does not exist",
            model.name
        );
    }
    let position = |i: u32| model.positions[i as usize];
    let has_uvs = model.uvs.len() == count;
    let uv = |i: u32| {
        if has_uvs {
            model.uvs[i as usize]
        } else {
            [0.0, 0.0]
        }
    };
    let has_normals = model.normals.len() == count
        && model
            .normals
            .iter()
            .all(|n| n.is_finite() && n.length_squared() > 1e-24);
    // Zero-area triangles are dropped, as the references do: they cover no pixel and
    // have no normal.
    let triangles: Vec<([u32; 3], Vec3)> = model
        .indices
        .chunks_exact(3)
        .filter_map(|t| {
            let t = [t[0], t[1], t[2]];
            let [p0, p1, p2] = t.map(position);
            let n = (p1 - p0).cross(p2 - p0);
            (n != Vec3::ZERO).then(|| (t, n.normalize_or(Vec3::Z)))
        })
        .collect();
    if triangles.is_empty() {
        return Ok(None);
    }

    let second = model.lightmap_uvs.len() == count;
    let (vertices, indices, lightmap_uvs): (Vec<Vertex>, Vec<u32>, Vec<[f32; 2]>) = if has_normals {
        let vertices = (0..count as u32)
            .map(|i| Vertex {
                position: position(i).to_array(),
                normal: model.normals[i as usize].normalize().to_array(),
                uv: uv(i),
            })
            .collect();
        let lightmap_uvs = if second {
            model.lightmap_uvs.to_vec()
        } else {
            Vec::new()
        };
        (
            vertices,
            triangles.iter().flat_map(|(t, _)| *t).collect(),
            lightmap_uvs,
        )
    } else {
        // Flat normals from the winding (counter-clockwise = front), as the references use
        // for OBJs without normals (and glTF prescribes); each corner gets its own vertex.
        let vertices: Vec<Vertex> = triangles
            .iter()
            .flat_map(|&(t, n)| {
                t.map(|i| Vertex {
                    position: position(i).to_array(),
                    normal: n.to_array(),
                    uv: uv(i),
                })
            })
            .collect();
        let indices = (0..vertices.len() as u32).collect();
        let lightmap_uvs = if second {
            triangles
                .iter()
                .flat_map(|(t, _)| t.map(|i| model.lightmap_uvs[i as usize]))
                .collect()
        } else {
            Vec::new()
        };
        (vertices, indices, lightmap_uvs)
    };
    let bounds = indices.iter().fold(Aabb::EMPTY, |mut b, &i| {
        b.extend(Vec3::from(vertices[i as usize].position));
        b
    });
    Ok(Some(ModelGeometry {
        vertices,
        indices,
        bounds,
        lightmap_uvs,
    }))
}

/// Where a texture's encoded image is.
#[derive(Clone)]
pub enum TextureSource {
    File(PathBuf),
    /// Bytes inside a file (a `.glb`'s buffer, a data URI), with a name for messages.
    Memory {
        name: PathBuf,
        bytes: Arc<[u8]>,
    },
}

impl TextureSource {
    fn name(&self) -> &Path {
        match self {
            TextureSource::File(path) => path,
            TextureSource::Memory { name, .. } => name,
        }
    }
}

/// One texture to decode: where, as what, and the first material that asked (to name it
/// in errors).
struct TextureRequest {
    source: TextureSource,
    kind: TextureKind,
    adjust: Option<Adjust>,
    material: String,
}

/// Textures requested by materials, each (image, kind, adjustment) once.
#[derive(Default)]
pub(super) struct TextureRequests {
    index: HashMap<(PathBuf, TextureKind, Option<[u32; 3]>), u32>,
    list: Vec<TextureRequest>,
}

impl TextureRequests {
    /// A texture file, which must exist.
    pub fn request_file(
        &mut self,
        path: PathBuf,
        kind: TextureKind,
        material: &str,
    ) -> Result<u32> {
        if path.is_dir() {
            bail!(
                "texture {} of material {material:?} is a directory, not an image",
                path.display()
            );
        }
        if !path.is_file() {
            bail!(
                "texture {} of material {material:?} not found",
                path.display()
            );
        }
        let path = path.canonicalize().unwrap_or(path);
        Ok(self.request(TextureSource::File(path), kind, None, material))
    }

    /// A texture from `source` (a file's existence checked by the caller). Requests with
    /// the same source name, kind and adjustment share one texture.
    pub fn request(
        &mut self,
        source: TextureSource,
        kind: TextureKind,
        adjust: Option<Adjust>,
        material: &str,
    ) -> u32 {
        let key = (source.name().to_path_buf(), kind, adjust.map(|a| a.key()));
        if let Some(&index) = self.index.get(&key) {
            return index;
        }
        let index = self.list.len() as u32;
        self.list.push(TextureRequest {
            source,
            kind,
            adjust,
            material: material.to_string(),
        });
        self.index.insert(key, index);
        index
    }

    fn decode(self) -> Result<Vec<Texture>> {
        if self.list.is_empty() {
            return Ok(Vec::new());
        }
        let start = Instant::now();
        let progress = Progress::new("decoding textures", self.list.len() as u64);
        let textures = self
            .list
            .par_iter()
            .map(|r| {
                let texture = match &r.source {
                    TextureSource::File(path) => Texture::load(path, r.kind, r.adjust),
                    TextureSource::Memory { name, bytes } => {
                        Texture::decode(name, bytes, r.kind, r.adjust)
                    }
                }
                .with_context(|| format!("texture of material {:?}", r.material));
                progress.advance();
                texture
            })
            .collect::<Result<Vec<_>>>()?;
        progress.finish();
        let bytes: usize = textures.iter().map(Texture::bytes).sum();
        log::info!(
            "decoded {} textures ({:.0} MiB with mips) in {:.2} s",
            textures.len(),
            bytes as f64 / (1024.0 * 1024.0),
            start.elapsed().as_secs_f64()
        );
        Ok(textures)
    }
}
