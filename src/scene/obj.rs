//! OBJ + MTL loading through `tobj`.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Context as _, Result};
use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::{Aabb, Animation, LoadOptions, Material, Mesh, Texture, TextureKind, Vertex};

/// Textures requested by materials, decoded together (in parallel) at the end.
#[derive(Default)]
pub struct TextureRequests {
    index: HashMap<(PathBuf, TextureKind), u32>,
    list: Vec<(PathBuf, TextureKind, String)>,
}

impl TextureRequests {
    fn request(&mut self, path: PathBuf, kind: TextureKind, material: &str) -> Result<u32> {
        if !path.is_file() {
            bail!(
                "texture {} of material {material:?} not found",
                path.display()
            );
        }
        let key = (path.canonicalize().unwrap_or(path), kind);
        let next = self.list.len() as u32;
        Ok(*self.index.entry(key.clone()).or_insert_with(|| {
            self.list.push((key.0, kind, material.to_string()));
            next
        }))
    }

    /// Decodes every requested texture and builds its mips.
    pub fn decode(self) -> Result<Vec<Texture>> {
        if self.list.is_empty() {
            return Ok(Vec::new());
        }
        let start = Instant::now();
        let textures = self
            .list
            .par_iter()
            .map(|(path, kind, material)| {
                Texture::load(path, *kind)
                    .with_context(|| format!("texture of material {material:?}"))
            })
            .collect::<Result<Vec<_>>>()?;
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

/// What a scene file says about one OBJ.
pub struct ObjEntry<'a> {
    pub path: &'a Path,
    pub transform: Mat4,
    pub emission_scale: f32,
    pub animation: Option<Animation>,
}

fn mtllib_names(obj: &Path) -> Vec<String> {
    std::fs::read_to_string(obj)
        .map(|text| {
            text.lines()
                .filter_map(|l| l.trim().strip_prefix("mtllib "))
                .map(|s| s.trim().to_string())
                .collect()
        })
        .unwrap_or_default()
}

/// A texture path in an MTL statement, relative to the MTL's folder; options such as
/// `-bm 1` before the file name are skipped.
fn texture_path(dir: &Path, statement: &str) -> PathBuf {
    let name = statement.split_whitespace().last().unwrap_or(statement);
    dir.join(name.replace('\\', "/"))
}

/// Is this map_Bump/bump a tangent-space normal map (rather than a height map)?
fn looks_like_normal_map(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower.contains("normal") || lower.contains("_nrm") || lower.contains("_norm")
}

/// Loads one OBJ; materials are appended after `material_offset` existing ones.
pub fn load(
    entry: &ObjEntry,
    options: &LoadOptions,
    material_offset: u32,
    textures: &mut TextureRequests,
) -> Result<(Vec<Mesh>, Vec<Material>)> {
    let path = entry.path;
    if !path.is_file() {
        bail!("OBJ file not found: {}", path.display());
    }
    let start = Instant::now();
    let load_options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, materials) = tobj::load_obj(path, &load_options)
        .map_err(|e| anyhow!("cannot parse OBJ {}: {e}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let obj_materials = match materials {
        Ok(m) => m,
        Err(e) => {
            let libs = mtllib_names(path);
            if let Some(missing) = libs.iter().find(|l| !dir.join(l).is_file()) {
                bail!(
                    "MTL file {} (mtllib of {}) not found",
                    dir.join(missing).display(),
                    path.display()
                );
            }
            if libs.is_empty() {
                Vec::new()
            } else {
                bail!(
                    "cannot parse MTL {} of {}: {e}",
                    libs.join(", "),
                    path.display()
                );
            }
        }
    };

    let mut materials = Vec::new();
    for m in &obj_materials {
        let name = &m.name;
        let vec3 = |v: Option<[f32; 3]>| v.map_or(Vec3::ZERO, Vec3::from);
        let ke = m
            .emissive
            .map(Vec3::from)
            .or_else(|| {
                m.unknown_param.get("Ke").and_then(|s| {
                    let v: Vec<f32> = s
                        .split_whitespace()
                        .filter_map(|x| x.parse().ok())
                        .collect();
                    (v.len() == 3).then(|| Vec3::new(v[0], v[1], v[2]))
                })
            })
            .unwrap_or(Vec3::ZERO);
        let albedo_texture = m
            .diffuse_texture
            .as_ref()
            .map(|t| textures.request(texture_path(dir, t), TextureKind::Albedo, name))
            .transpose()?;
        let coverage_texture = m
            .dissolve_texture
            .as_ref()
            .map(|t| textures.request(texture_path(dir, t), TextureKind::Coverage, name))
            .transpose()?;
        let normal_name = m.unknown_param.get("norm").cloned().or_else(|| {
            m.normal_texture
                .clone()
                .filter(|t| looks_like_normal_map(t))
        });
        let normal_texture = match normal_name {
            Some(t) if !options.no_normal_maps => {
                Some(textures.request(texture_path(dir, &t), TextureKind::Normal, name)?)
            }
            _ => None,
        };
        let shininess = m.shininess.unwrap_or(10.0).max(0.0);
        materials.push(Material {
            name: name.clone(),
            albedo: m.diffuse.map_or(Vec3::splat(0.8), Vec3::from),
            albedo_texture,
            specular: if options.diffuse_only {
                Vec3::ZERO
            } else {
                vec3(m.specular)
            },
            roughness: (2.0 / (shininess + 2.0)).sqrt().clamp(0.02, 1.0),
            emission: ke * entry.emission_scale,
            dissolve: m.dissolve.unwrap_or(1.0).clamp(0.0, 1.0),
            coverage_texture,
            normal_texture,
            ior: m.optical_density.unwrap_or(1.0),
        });
    }
    let mut default_material = None;

    let mut meshes = Vec::new();
    for model in models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let material = match mesh.material_id {
            Some(id) if id < materials.len() => material_offset + id as u32,
            _ => *default_material.get_or_insert_with(|| {
                materials.push(Material::default_grey());
                material_offset + materials.len() as u32 - 1
            }),
        };
        let vertex_count = mesh.positions.len() / 3;
        let has_normals = mesh.normals.len() == mesh.positions.len();
        let has_uvs = mesh.texcoords.len() == vertex_count * 2;
        let position = |i: usize| Vec3::from_slice(&mesh.positions[3 * i..3 * i + 3]);
        let mut local_bounds = Aabb::EMPTY;
        let (vertices, indices) = if has_normals {
            let vertices: Vec<Vertex> = (0..vertex_count)
                .map(|i| {
                    local_bounds.extend(position(i));
                    Vertex {
                        position: position(i).to_array(),
                        normal: Vec3::from_slice(&mesh.normals[3 * i..3 * i + 3])
                            .normalize_or_zero()
                            .to_array(),
                        uv: if has_uvs {
                            [mesh.texcoords[2 * i], 1.0 - mesh.texcoords[2 * i + 1]]
                        } else {
                            [0.0, 0.0]
                        },
                    }
                })
                .collect();
            (vertices, mesh.indices.clone())
        } else {
            // No normals in the file: flat normals from the winding, one vertex per corner.
            let mut vertices = Vec::with_capacity(mesh.indices.len());
            for tri in mesh.indices.chunks_exact(3) {
                let p = [tri[0], tri[1], tri[2]].map(|i| position(i as usize));
                let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
                for (k, &i) in tri.iter().enumerate() {
                    local_bounds.extend(p[k]);
                    let i = i as usize;
                    vertices.push(Vertex {
                        position: p[k].to_array(),
                        normal: n.to_array(),
                        uv: if has_uvs {
                            [mesh.texcoords[2 * i], 1.0 - mesh.texcoords[2 * i + 1]]
                        } else {
                            [0.0, 0.0]
                        },
                    });
                }
            }
            let indices = (0..vertices.len() as u32).collect();
            (vertices, indices)
        };
        meshes.push(Mesh {
            name: model.name.clone(),
            vertices,
            indices,
            material,
            transform: entry.transform,
            animation: entry.animation,
            local_bounds,
        });
    }
    let triangles: usize = meshes.iter().map(|m| m.indices.len() / 3).sum();
    log::info!(
        "parsed {}: {} triangles, {} materials in {:.2} s",
        path.display(),
        triangles,
        materials.len(),
        start.elapsed().as_secs_f64()
    );
    Ok((meshes, materials))
}
