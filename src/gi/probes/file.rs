//! The bake's file: what the frame needs from a bake, behind a versioned header keyed by
//! a hash of everything the bake read (the static meshes, their cut-outs, the settings).
//!
//! Layout, little-endian: the magic `VXCBAKE\0`, the format version (u32), a reserved
//! u32, the content key (u128), the payload's length (u64) and its hash (u128, xxh3),
//! then the payload: sections of a u64 byte count and the bytes. A file whose magic,
//! version, key, length or hash does not match is not used; the caller rebakes, saying
//! why.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use bytemuck::Pod;
use xxhash_rust::xxh3::Xxh3;

use super::BakeSettings;
use crate::gpu_layout::RayHit;
use crate::scene::Scene;

const MAGIC: &[u8; 8] = b"VXCBAKE\0";
/// Raised whenever the payload's sections or their meaning change.
pub const VERSION: u32 = 3;
const HEADER: usize = 8 + 4 + 4 + 16 + 8 + 16;

/// What a frame of `--gi probes` reads from a bake.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeData {
    pub lightmap: [u32; 2],
    pub sh_order: u32,
    /// Per static mesh, where its corners' lightmap UVs start in `corner_uvs` (and the
    /// end, last).
    pub mesh_corners: Vec<u32>,
    pub corner_uvs: Vec<[f32; 2]>,
    /// Per receiver: its texel, its cluster, where its row of U_k starts, its sky factor.
    /// The lightmap's receivers come first, one per texel of `receiver_texels`; then the
    /// grid's spatial receivers, direction after direction (`grid::DIRECTIONS`), each
    /// direction's points in the grid's order.
    pub receiver_texels: Vec<[u32; 2]>,
    pub receiver_clusters: Vec<u32>,
    pub receiver_offsets: Vec<u32>,
    pub receiver_sky: Vec<f32>,
    pub coordinates: Vec<f32>,
    /// The grid of spatial receivers: its points per axis (zero: no grid) and its box.
    pub grid_size: [u32; 3],
    pub grid_bounds: [[f32; 3]; 2],
    pub probes: Vec<[f32; 3]>,
    /// The relight maps' first side and every probe's relight rays' hits
    /// ([`super::casting::RelightRays`]).
    pub relight_side: u32,
    pub relight_hits: Vec<RayHit>,
    /// Per cluster: where its probes start in `cluster_probes`, its basis count, where
    /// its (Σ V^T)_k starts in `projections` (each with an end, last).
    pub cluster_probe_starts: Vec<u32>,
    pub cluster_probes: Vec<u32>,
    pub cluster_basis: Vec<u32>,
    pub cluster_projection_starts: Vec<u32>,
    pub projections: Vec<f32>,
    /// Per cluster, the box of its receivers (least and greatest corner).
    pub cluster_bounds: Vec<[[f32; 3]; 2]>,
    /// The bake's report, as JSON.
    pub report: String,
}

/// Why a bake file was not used.
#[derive(Clone, Debug, PartialEq)]
pub enum Unusable {
    Missing,
    /// Another format version, or another scene or settings (stale).
    Stale(String),
    /// Truncated or damaged.
    Corrupt(String),
}

/// The key of a bake of `scene` (its static meshes) with `settings`.
pub fn content_key(scene: &Scene, settings: &BakeSettings) -> u128 {
    let mut h = Xxh3::new();
    h.update(&VERSION.to_le_bytes());
    for v in [
        settings.lightmap_size,
        settings.probes,
        settings.overlaps,
        settings.probe_side,
        settings.relight_side,
        settings.receiver_rays,
        settings.sh_order,
        settings.pca_error.to_bits(),
        settings.max_basis,
        settings.spatial_receivers,
    ] {
        h.update(&v.to_le_bytes());
    }
    for mesh in scene.meshes.iter().filter(|m| m.animation.is_none()) {
        h.update(bytemuck::cast_slice(&mesh.vertices));
        h.update(bytemuck::cast_slice(&mesh.indices));
        h.update(bytemuck::cast_slice(&mesh.lightmap_uvs));
        h.update(bytemuck::cast_slice(&mesh.transform.to_cols_array()));
        // What the rays see of its material: cut-outs and straight transmission.
        let material = &scene.materials[mesh.material as usize];
        h.update(&material.dissolve.to_le_bytes());
        h.update(&[u8::from(material.refracts())]);
        if let Some(t) = material.coverage_texture {
            h.update(&scene.textures[t as usize].mips[0]);
        }
    }
    h.digest128()
}

/// Where the bake of `scene` with `settings` is kept: the user's cache folder
/// (`$XDG_CACHE_HOME/voxcone/bakes`, else `~/.cache/voxcone/bakes`), one file per scene
/// file and settings.
pub fn default_path(scene: &Scene, settings: &BakeSettings) -> Result<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .context("no cache folder for the bake: set XDG_CACHE_HOME or HOME, or give --bake-file")?;
    let source = std::fs::canonicalize(&scene.source).unwrap_or_else(|_| scene.source.clone());
    let mut h = Xxh3::new();
    h.update(source.to_string_lossy().as_bytes());
    h.update(format!("{settings:?}").as_bytes());
    let stem = scene
        .source
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    Ok(base
        .join("voxcone/bakes")
        .join(format!("{stem}-{:016x}.bake", h.digest())))
}

fn section<T: Pod>(out: &mut Vec<u8>, data: &[T]) {
    let bytes: &[u8] = bytemuck::cast_slice(data);
    out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
    out.extend_from_slice(bytes);
}

impl BakeData {
    /// Writes the bake to `path` with `key`, through a temporary file renamed over it (a
    /// bake interrupted while writing leaves no half file under the name).
    pub fn write(&self, path: &Path, key: u128) -> Result<()> {
        let mut payload = Vec::new();
        section(&mut payload, &self.lightmap);
        section(&mut payload, &[self.sh_order, self.relight_side]);
        section(&mut payload, &self.mesh_corners);
        section(&mut payload, &self.corner_uvs);
        section(&mut payload, &self.receiver_texels);
        section(&mut payload, &self.receiver_clusters);
        section(&mut payload, &self.receiver_offsets);
        section(&mut payload, &self.receiver_sky);
        section(&mut payload, &self.coordinates);
        section(&mut payload, &self.grid_size);
        section(&mut payload, &self.grid_bounds);
        section(&mut payload, &self.probes);
        section(&mut payload, &self.relight_hits);
        section(&mut payload, &self.cluster_probe_starts);
        section(&mut payload, &self.cluster_probes);
        section(&mut payload, &self.cluster_basis);
        section(&mut payload, &self.cluster_projection_starts);
        section(&mut payload, &self.projections);
        section(&mut payload, &self.cluster_bounds);
        section(&mut payload, self.report.as_bytes());
        let mut file = Vec::with_capacity(HEADER + payload.len());
        file.extend_from_slice(MAGIC);
        file.extend_from_slice(&VERSION.to_le_bytes());
        file.extend_from_slice(&0u32.to_le_bytes());
        file.extend_from_slice(&key.to_le_bytes());
        file.extend_from_slice(&(payload.len() as u64).to_le_bytes());
        file.extend_from_slice(&xxhash_rust::xxh3::xxh3_128(&payload).to_le_bytes());
        file.extend_from_slice(&payload);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("creating the bake's folder {}", dir.display()))?;
        }
        let temporary = path.with_extension("bake.partial");
        std::fs::write(&temporary, &file)
            .with_context(|| format!("writing the bake {}", temporary.display()))?;
        std::fs::rename(&temporary, path)
            .with_context(|| format!("moving the bake to {}", path.display()))?;
        Ok(())
    }

    /// Reads the bake at `path` if it is whole and was made with `key`.
    pub fn read(path: &Path, key: u128) -> std::result::Result<Self, Unusable> {
        let bytes = match std::fs::read(path) {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Err(Unusable::Missing),
            Err(e) => return Err(Unusable::Corrupt(format!("unreadable: {e}"))),
        };
        if bytes.len() < HEADER || &bytes[..8] != MAGIC {
            return Err(Unusable::Corrupt("not a voxcone bake (no header)".into()));
        }
        let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().expect("4 bytes"));
        let u64_at = |i: usize| u64::from_le_bytes(bytes[i..i + 8].try_into().expect("8 bytes"));
        let u128_at =
            |i: usize| u128::from_le_bytes(bytes[i..i + 16].try_into().expect("16 bytes"));
        let version = u32_at(8);
        if version != VERSION {
            return Err(Unusable::Stale(format!(
                "made by bake format {version}, this build reads {VERSION}"
            )));
        }
        if u128_at(16) != key {
            return Err(Unusable::Stale(
                "made from another version of the scene or other settings".into(),
            ));
        }
        let length = u64_at(32) as usize;
        let payload = &bytes[HEADER..];
        if payload.len() != length {
            return Err(Unusable::Corrupt(format!(
                "truncated: {} of {length} payload bytes",
                payload.len()
            )));
        }
        if xxhash_rust::xxh3::xxh3_128(payload) != u128_at(40) {
            return Err(Unusable::Corrupt(
                "damaged: its contents do not match their hash".into(),
            ));
        }
        Self::parse(payload).map_err(|e| Unusable::Corrupt(format!("{e:#}")))
    }

    fn parse(payload: &[u8]) -> Result<Self> {
        let mut at = 0;
        let mut next = || -> Result<&[u8]> {
            if payload.len() < at + 8 {
                bail!("a section runs past the end");
            }
            let n = u64::from_le_bytes(payload[at..at + 8].try_into().expect("8 bytes")) as usize;
            at += 8;
            if payload.len() - at < n {
                bail!("a section runs past the end");
            }
            at += n;
            Ok(&payload[at - n..at])
        };
        fn array<T: Pod>(bytes: &[u8]) -> Result<Vec<T>> {
            if bytes.len() % std::mem::size_of::<T>() != 0 {
                bail!("a section's length is not a whole number of its elements");
            }
            Ok(bytes
                .chunks_exact(std::mem::size_of::<T>())
                .map(bytemuck::pod_read_unaligned)
                .collect())
        }
        let lightmap: Vec<u32> = array(next()?)?;
        let orders: Vec<u32> = array(next()?)?;
        if lightmap.len() != 2 || orders.len() != 2 {
            bail!("the lightmap's size or the orders are malformed");
        }
        let data = Self {
            lightmap: [lightmap[0], lightmap[1]],
            sh_order: orders[0],
            relight_side: orders[1],
            mesh_corners: array(next()?)?,
            corner_uvs: array(next()?)?,
            receiver_texels: array(next()?)?,
            receiver_clusters: array(next()?)?,
            receiver_offsets: array(next()?)?,
            receiver_sky: array(next()?)?,
            coordinates: array(next()?)?,
            grid_size: exactly(array(next()?)?, "the grid's size")?,
            grid_bounds: exactly(array(next()?)?, "the grid's box")?,
            probes: array(next()?)?,
            relight_hits: array(next()?)?,
            cluster_probe_starts: array(next()?)?,
            cluster_probes: array(next()?)?,
            cluster_basis: array(next()?)?,
            cluster_projection_starts: array(next()?)?,
            projections: array(next()?)?,
            cluster_bounds: array(next()?)?,
            report: String::from_utf8(next()?.to_vec()).context("the report is not UTF-8")?,
        };
        let receivers = data.receiver_texels.len() + 6 * data.grid_points();
        let counts = [
            data.receiver_clusters.len(),
            data.receiver_offsets.len(),
            data.receiver_sky.len(),
        ];
        if counts.iter().any(|&n| n != receivers) {
            bail!("the receivers' tables do not match their count ({receivers})");
        }
        let side = data.relight_side as usize;
        if !super::casting::RelightRays::allows(side) {
            bail!("the relight maps' side ({side}) is not a multiple of 4 from 16 to 128");
        }
        let rays = super::casting::RelightRays::per_probe(side);
        if data.relight_hits.len() != data.probes.len() * rays {
            bail!(
                "the relight rays' hits do not match {} probes of {rays} rays",
                data.probes.len()
            );
        }
        let clusters = data.cluster_basis.len();
        if data.cluster_bounds.len() != clusters
            || data.cluster_probe_starts.len() != clusters + 1
            || data.cluster_projection_starts.len() != clusters + 1
        {
            bail!("the clusters' tables do not match their count ({clusters})");
        }
        Ok(data)
    }

    /// The points of the grid of spatial receivers.
    pub fn grid_points(&self) -> usize {
        self.grid_size.iter().map(|&n| n as usize).product()
    }
}

/// The one element of a section that holds exactly one.
fn exactly<T: Copy>(v: Vec<T>, what: &str) -> Result<T> {
    match v.as_slice() {
        [x] => Ok(*x),
        _ => bail!("{what} is malformed"),
    }
}
