//! OBJ + MTL loading through `tobj`.

use std::cell::RefCell;
use std::collections::HashMap;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Context as _, Result};
use glam::{Mat4, Vec3};
use rayon::prelude::*;

use super::{Aabb, Animation, LoadOptions, Material, Mesh, Texture, TextureKind, Vertex};

/// What a scene file says about one OBJ.
pub struct ObjEntry<'a> {
    pub path: &'a Path,
    pub transform: Mat4,
    pub emission_scale: f32,
    pub animation: Option<Animation>,
}

/// The meshes and materials of a scene's OBJs. Textures are only collected while the OBJs
/// are read, so that [`Geometry::finish`] can decode all of them in parallel.
#[derive(Default)]
pub struct Geometry {
    pub meshes: Vec<Mesh>,
    pub materials: Vec<Material>,
    textures: TextureRequests,
    /// Shared by every group without a material, in every OBJ of the scene.
    default_material: Option<u32>,
}

impl Geometry {
    /// Reads one OBJ with its MTLs; its materials are appended after those already loaded,
    /// so that equal names in different OBJs stay different materials.
    pub fn add_obj(&mut self, entry: &ObjEntry, options: &LoadOptions) -> Result<()> {
        let path = entry.path;
        let start = Instant::now();
        let (models, obj_materials, material_dirs) = parse(path)?;

        let first_material = self.materials.len() as u32;
        for (m, dir) in obj_materials.iter().zip(&material_dirs) {
            let material =
                convert_material(m, dir, entry.emission_scale, options, &mut self.textures)
                    .with_context(|| format!("in the materials of {}", path.display()))?;
            self.materials.push(material);
        }

        let mut meshes = Vec::new();
        for model in &models {
            let Some(ModelGeometry {
                vertices,
                indices,
                bounds,
            }) = model_geometry(model).with_context(|| format!("in OBJ {}", path.display()))?
            else {
                continue;
            };
            let material = match model.mesh.material_id {
                Some(id) if id < obj_materials.len() => first_material + id as u32,
                _ => self.default_material(),
            };
            meshes.push(Mesh {
                name: model.name.clone(),
                vertices,
                indices,
                material,
                transform: entry.transform,
                animation: entry.animation,
                local_bounds: bounds,
                object_bounds: bounds,
            });
        }
        let object_bounds = meshes
            .iter()
            .fold(Aabb::EMPTY, |b, m| b.union(&m.local_bounds));
        for mesh in &mut meshes {
            mesh.object_bounds = object_bounds;
        }
        let triangles: usize = meshes.iter().map(|m| m.indices.len() / 3).sum();
        log::info!(
            "loading {}: {triangles} triangles, {} materials ({:.2} s)",
            path.file_name()
                .unwrap_or(path.as_os_str())
                .to_string_lossy(),
            obj_materials.len(),
            start.elapsed().as_secs_f64()
        );
        self.meshes.extend(meshes);
        Ok(())
    }

    fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.materials.push(Material::default_grey());
            self.materials.len() as u32 - 1
        })
    }

    /// Decodes every requested texture (in parallel) and builds its mips.
    pub fn finish(self) -> Result<(Vec<Mesh>, Vec<Material>, Vec<Texture>)> {
        let textures = self.textures.decode()?;
        Ok((self.meshes, self.materials, textures))
    }
}

/// Parses an OBJ and its MTLs: models, materials, and the folder of the MTL each material
/// came from (its texture paths are relative to that).
fn parse(path: &Path) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>, Vec<PathBuf>)> {
    let file = File::open(path).with_context(|| format!("cannot open OBJ {}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    // tobj keeps going after a failed mtllib and only reports an error when no MTL loaded at
    // all, so every failure is recorded here to name the file.
    let failures: RefCell<Vec<(PathBuf, String)>> = RefCell::new(Vec::new());
    let material_dirs = RefCell::new(Vec::new());
    // GPU_LOAD_OPTIONS: triangulated, one index for position, normal and uv, and points and
    // lines dropped (they are not surfaces).
    let (models, materials) =
        tobj::load_obj_buf(&mut BufReader::new(file), &tobj::GPU_LOAD_OPTIONS, |mtl| {
            let mtl_path = dir.join(mtl);
            let text = match read_mtl(&mtl_path) {
                Ok(text) => text,
                Err(e) => {
                    failures.borrow_mut().push((mtl_path, format!("{e:#}")));
                    return Err(tobj::LoadError::MaterialParseError);
                }
            };
            let result = tobj::load_mtl_buf(&mut text.as_bytes());
            match &result {
                Ok((materials, _)) => {
                    let mtl_dir = mtl_path.parent().unwrap_or(Path::new("")).to_path_buf();
                    material_dirs
                        .borrow_mut()
                        .extend(std::iter::repeat_n(mtl_dir, materials.len()));
                }
                Err(e) => failures
                    .borrow_mut()
                    .push((mtl_path, format!("cannot parse: {e}"))),
            }
            result
        })
        .map_err(|e| anyhow!("cannot parse OBJ {}: {e}", path.display()))?;
    if let Some((mtl, e)) = failures.into_inner().first() {
        bail!("MTL {} (mtllib of {}): {e}", mtl.display(), path.display());
    }
    let materials =
        materials.map_err(|e| anyhow!("cannot load the MTLs of {}: {e}", path.display()))?;
    Ok((models, materials, material_dirs.into_inner()))
}

/// The colours an MTL gives as `r [g b]`, which tobj reads as three numbers.
const MTL_COLOURS: [&str; 4] = ["Ka", "Kd", "Ks", "Ke"];

/// The scalars an MTL gives that must be finite and not negative.
const MTL_SCALARS: [&str; 4] = ["Ns", "Ni", "d", "Tr"];

/// The text of MTL `path`, checked and made readable by tobj: a colour given by one value
/// (the format's `Kd r`, g and b equal to r) repeated three times, which tobj would
/// panic on; a colour of two values, or a colour or scalar not finite or negative, refused
/// with its line.
fn read_mtl(path: &Path) -> Result<String> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        if path.is_file() {
            anyhow!("cannot read it: {e}")
        } else {
            anyhow!("not found")
        }
    })?;
    let mut out = String::with_capacity(text.len());
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next().unwrap_or("");
        let values: Vec<&str> = words.collect();
        let colour = MTL_COLOURS.contains(&key);
        if colour || MTL_SCALARS.contains(&key) {
            // `Kd spectral file.rfl` and `Kd xyz x y z` are left to tobj, which refuses them.
            let numbers: Option<Vec<f32>> = values.iter().map(|v| v.parse().ok()).collect();
            if let Some(numbers) = numbers {
                if let Some(bad) = numbers.iter().find(|v| !v.is_finite() || **v < 0.0) {
                    bail!(
                        "line {}: {key} {bad} is not a finite number of at least 0",
                        n + 1
                    );
                }
                if colour && numbers.len() == 2 {
                    bail!(
                        "line {}: {key} takes one value (grey) or three (r g b), not two",
                        n + 1
                    );
                }
                if colour && numbers.len() == 1 {
                    let v = values[0];
                    out.push_str(&format!("{key} {v} {v} {v}\n"));
                    continue;
                }
            }
        }
        out.push_str(line);
        out.push('\n');
    }
    Ok(out)
}

fn convert_material(
    m: &tobj::Material,
    dir: &Path,
    emission_scale: f32,
    options: &LoadOptions,
    textures: &mut TextureRequests,
) -> Result<Material> {
    let name = &m.name;
    let mut texture =
        |statement: &str, kind| textures.request(texture_path(dir, statement), kind, name);
    let albedo_texture = m
        .diffuse_texture
        .as_deref()
        .map(|t| texture(t, TextureKind::Albedo))
        .transpose()?;
    let coverage_texture = m
        .dissolve_texture
        .as_deref()
        .map(|t| texture(t, TextureKind::Coverage))
        .transpose()?;
    let normal_map = m.unknown_param.get("norm").map(String::as_str).or_else(|| {
        m.normal_texture
            .as_deref()
            .filter(|t| looks_like_normal_map(t))
    });
    let normal_texture = match normal_map {
        Some(t) if !options.no_normal_maps => Some(texture(t, TextureKind::Normal)?),
        _ => None,
    };
    let dissolve = match (m.dissolve, m.unknown_param.get("Tr")) {
        (Some(d), _) => d,
        (None, Some(tr)) => {
            let tr: f32 = first_word(tr)
                .parse()
                .with_context(|| format!("material {name:?}: Tr {tr:?} is not a number"))?;
            1.0 - tr
        }
        (None, None) => 1.0,
    };
    // MTL's default Ns is 0, which is the roughest surface.
    let shininess = m.shininess.unwrap_or(0.0).max(0.0);
    let vec3 = |v: Option<[f32; 3]>| v.map_or(Vec3::ZERO, Vec3::from);
    Ok(Material {
        name: name.clone(),
        albedo: m.diffuse.map_or(Vec3::splat(0.8), Vec3::from),
        albedo_texture,
        specular: if options.diffuse_only {
            Vec3::ZERO
        } else {
            vec3(m.specular)
        },
        roughness: (2.0 / (shininess + 2.0)).sqrt().clamp(0.02, 1.0),
        emission: vec3(m.emissive) * emission_scale,
        dissolve: dissolve.clamp(0.0, 1.0),
        coverage_texture,
        normal_texture,
        ior: if options.no_refraction {
            1.0
        } else {
            m.optical_density.unwrap_or(1.0).max(1.0)
        },
    })
}

fn first_word(s: &str) -> &str {
    s.split_whitespace().next().unwrap_or("")
}

/// The file of an MTL texture statement, relative to the MTL's folder. Options such as
/// `-bm 1` come before the file name, so the last word is the file unless the whole
/// statement names an existing file (a name with spaces).
fn texture_path(dir: &Path, statement: &str) -> PathBuf {
    let statement = statement.replace('\\', "/");
    let whole = dir.join(&statement);
    if whole.is_file() {
        return whole;
    }
    dir.join(statement.split_whitespace().last().unwrap_or(&statement))
}

/// Is this map_Bump/bump a tangent-space normal map? Height maps are ignored, and only the
/// file name tells them apart.
fn looks_like_normal_map(statement: &str) -> bool {
    let name = statement
        .rsplit(['/', '\\'])
        .next()
        .unwrap_or(statement)
        .to_ascii_lowercase();
    name.contains("normal") || name.contains("_nrm") || name.contains("_norm")
}

struct ModelGeometry {
    vertices: Vec<Vertex>,
    indices: Vec<u32>,
    bounds: Aabb,
}

/// The triangles of one OBJ model, or `None` for a model without any of non-zero area.
fn model_geometry(model: &tobj::Model) -> Result<Option<ModelGeometry>> {
    let mesh = &model.mesh;
    let count = mesh.positions.len() / 3;
    if mesh.positions.iter().any(|p| !p.is_finite()) {
        bail!(
            "model {:?} has a vertex position that is not a finite number",
            model.name
        );
    }
    if mesh.indices.iter().any(|&i| i as usize >= count) {
        bail!(
            "model {:?} indexes a vertex that does not exist",
            model.name
        );
    }
    let position = |i: u32| Vec3::from_slice(&mesh.positions[3 * i as usize..][..3]);
    let has_uvs = mesh.texcoords.len() == 2 * count;
    let uv = |i: u32| {
        if has_uvs {
            [
                mesh.texcoords[2 * i as usize],
                1.0 - mesh.texcoords[2 * i as usize + 1],
            ]
        } else {
            [0.0, 0.0]
        }
    };
    let file_normal = |i: u32| Vec3::from_slice(&mesh.normals[3 * i as usize..][..3]);
    let has_normals = mesh.normals.len() == 3 * count
        && (0..count as u32).all(|i| file_normal(i).length_squared() > 1e-24);
    // Zero-area triangles are dropped, as the references do: they cover no pixel and
    // have no normal.
    let triangles: Vec<([u32; 3], Vec3)> = mesh
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

    let (vertices, indices): (Vec<Vertex>, Vec<u32>) = if has_normals {
        let vertices = (0..count as u32)
            .map(|i| Vertex {
                position: position(i).to_array(),
                normal: file_normal(i).normalize().to_array(),
                uv: uv(i),
            })
            .collect();
        (vertices, triangles.iter().flat_map(|(t, _)| *t).collect())
    } else {
        // Flat normals from the winding (counter-clockwise = front), as the references use
        // for OBJs without normals; each corner gets its own vertex.
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
        (vertices, indices)
    };
    let bounds = indices.iter().fold(Aabb::EMPTY, |mut b, &i| {
        b.extend(Vec3::from(vertices[i as usize].position));
        b
    });
    Ok(Some(ModelGeometry {
        vertices,
        indices,
        bounds,
    }))
}

/// Textures requested by materials, each (file, kind) once.
#[derive(Default)]
struct TextureRequests {
    index: HashMap<(PathBuf, TextureKind), u32>,
    /// File, kind, and the first material that asked (to name it in errors).
    list: Vec<(PathBuf, TextureKind, String)>,
}

impl TextureRequests {
    fn request(&mut self, path: PathBuf, kind: TextureKind, material: &str) -> Result<u32> {
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
        let key = (path.canonicalize().unwrap_or(path), kind);
        if let Some(&index) = self.index.get(&key) {
            return Ok(index);
        }
        let index = self.list.len() as u32;
        self.list.push((key.0.clone(), kind, material.to_string()));
        self.index.insert(key, index);
        Ok(index)
    }

    fn decode(self) -> Result<Vec<Texture>> {
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

#[cfg(test)]
mod tests;
