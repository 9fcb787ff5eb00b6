//! OBJ + MTL loading through `tobj`.

use std::cell::RefCell;
use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail, Context as _, Result};
use glam::Vec3;

use super::geometry::{
    model_geometry, Geometry, MeshEntry, ModelAttributes, ModelGeometry, TextureRequests,
};
use super::{LoadOptions, Material, Mesh, TextureKind};
use crate::progress::{Progress, ProgressReader};

/// Reads one OBJ with its MTLs into `geometry`.
pub fn add(geometry: &mut Geometry, entry: &MeshEntry, options: &LoadOptions) -> Result<()> {
    let path = entry.path;
    let start = Instant::now();
    let (models, obj_materials, material_dirs) = parse(path)?;

    let first_material = geometry.materials.len() as u32;
    for (m, dir) in obj_materials.iter().zip(&material_dirs) {
        let material = convert_material(
            m,
            dir,
            entry.emission_scale,
            options,
            &mut geometry.textures,
        )
        .with_context(|| format!("in the materials of {}", path.display()))?;
        geometry.materials.push(material);
    }

    let mut meshes = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        let positions: Vec<Vec3> = mesh
            .positions
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect();
        let normals: Vec<Vec3> = mesh.normals.chunks_exact(3).map(Vec3::from_slice).collect();
        // OBJ puts v = 0 at the bottom of the image (see `Vertex`).
        let uvs: Vec<[f32; 2]> = mesh
            .texcoords
            .chunks_exact(2)
            .map(|t| [t[0], 1.0 - t[1]])
            .collect();
        let attributes = ModelAttributes {
            name: &model.name,
            positions: &positions,
            normals: &normals,
            uvs: &uvs,
            lightmap_uvs: &[],
            indices: &mesh.indices,
        };
        let Some(ModelGeometry {
            vertices,
            indices,
            bounds,
            ..
        }) = model_geometry(&attributes).with_context(|| format!("in OBJ {}", path.display()))?
        else {
            continue;
        };
        let material = match mesh.material_id {
            Some(id) if id < obj_materials.len() => first_material + id as u32,
            _ => geometry.default_material(),
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
            lightmap_uvs: Vec::new(),
        });
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
    geometry.push_entry_meshes(meshes);
    Ok(())
}

/// Parses an OBJ and its MTLs: models, materials, and the folder of the MTL each material
/// came from (its texture paths are relative to that).
fn parse(path: &Path) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>, Vec<PathBuf>)> {
    let file = File::open(path).with_context(|| format!("cannot open OBJ {}", path.display()))?;
    let size = file.metadata().map_or(0, |m| m.len());
    let name = path
        .file_name()
        .unwrap_or(path.as_os_str())
        .to_string_lossy();
    let progress = Progress::bytes(&format!("parsing {name}"), size);
    let dir = path.parent().unwrap_or(Path::new(""));
    // tobj keeps going after a failed mtllib and only reports an error when no MTL loaded at
    // all, so every failure is recorded here to name the file.
    let failures: RefCell<Vec<(PathBuf, String)>> = RefCell::new(Vec::new());
    let material_dirs = RefCell::new(Vec::new());
    // GPU_LOAD_OPTIONS: triangulated, one index for position, normal and uv, and points and
    // lines dropped (they are not surfaces).
    let mut reader = ProgressReader::new(BufReader::new(file), &progress);
    let (models, materials) = tobj::load_obj_buf(&mut reader, &tobj::GPU_LOAD_OPTIONS, |mtl| {
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
    progress.finish();
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
        |statement: &str, kind| textures.request_file(texture_path(dir, statement), kind, name);
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
    let emission_texture = m
        .unknown_param
        .get("map_Ke")
        .map(|t| texture(t, TextureKind::Albedo))
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
        emission_texture,
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

#[cfg(test)]
mod tests;
