//! Lightmap UVs (Sedláček 2019, 3.2.1.1): every static triangle gets its own place in one
//! square-ish atlas, so that each texel is one receiver.
//!
//! The atlas comes from `uvunwrap` (xatlas's method in pure Rust: charts grown from planar
//! regions, LSCM with ARAP, packing of the rasterised chart shapes), which replaces the
//! thesis's packing of whole meshes' texture squares: it never overlaps, keeps the texel
//! density uniform across meshes (the positions are in world units) and leaves `padding`
//! empty texels round each chart, so that the bilinear lookup of one chart never reads
//! another's (the thesis's 3.2.1.1 gap of three texels, for the same reason).

use anyhow::{bail, Context, Result};
use glam::Vec3;

use crate::progress::Progress;
use crate::scene::Scene;

/// Empty texels round each chart. The unwrapper dilates each chart's conservative
/// raster by this much and keeps the dilated charts apart, so one texel is enough for the
/// receivers' border (the texels within one texel of a chart, [`super::receivers`]) never
/// to reach another chart's. Each chart costs at least (1 + 2 · padding)² texels: with
/// Sponza's 9,657 charts, two texels left a 512² page 0.6 % surface, one 31 %.
pub const PADDING: u32 = 1;

/// The atlas of the scene's static meshes.
#[derive(Clone, Debug)]
pub struct Lightmap {
    pub width: u32,
    pub height: u32,
    /// Texels per world unit along a surface.
    pub texels_per_unit: f32,
    pub charts: u32,
    /// The share of the atlas's texels that chart surface covers.
    pub utilization: f32,
    /// Per scene mesh, the lightmap UV of each triangle corner (as the mesh's `indices`),
    /// in [0, 1] with (0, 0) the corner of texel row 0, column 0; empty for moving meshes,
    /// which the probes do not hold (Sedláček 2019, 4.1: they are lit from the grid).
    pub corners: Vec<Vec<[f32; 2]>>,
    /// The UVs are the scene's own second set, not an atlas made here.
    pub authored: bool,
}

impl Lightmap {
    /// The scene's own lightmap UVs on a `size` × `size` page where every static mesh has
    /// them, inside the page (3.2.1.1: "use the mesh's second UV set where the scene has
    /// one"); else the atlas at the highest density that fits one page.
    pub fn generate(scene: &Scene, size: u32) -> Result<Self> {
        let meshes = static_meshes(scene)?;
        match Self::authored(scene, &meshes, size) {
            Some(lightmap) => Ok(lightmap),
            None => Self::unwrap(scene, &meshes, size),
        }
    }

    /// The scene's second UV set as the lightmap, if every static mesh has one within
    /// [0, 1]². The texel density is the mean over the surfaces (the square root of the
    /// page's texels the triangles cover over their world area).
    fn authored(scene: &Scene, meshes: &[usize], size: u32) -> Option<Self> {
        let usable = meshes.iter().all(|&m| {
            let mesh = &scene.meshes[m];
            mesh.lightmap_uvs.len() == mesh.vertices.len()
                && mesh
                    .lightmap_uvs
                    .iter()
                    .all(|uv| uv.iter().all(|c| (0.0..=1.0).contains(c)))
        });
        if !usable {
            return None;
        }
        let mut corners = vec![Vec::new(); scene.meshes.len()];
        let (mut uv_area, mut world_area) = (0.0f64, 0.0f64);
        for &m in meshes {
            let mesh = &scene.meshes[m];
            corners[m] = mesh
                .indices
                .iter()
                .map(|&i| mesh.lightmap_uvs[i as usize])
                .collect();
            for t in mesh.indices.chunks_exact(3) {
                let [a, b, c] =
                    [0, 1, 2].map(|k| glam::Vec2::from(mesh.lightmap_uvs[t[k] as usize]));
                uv_area += f64::from((b - a).perp_dot(c - a).abs() / 2.0);
                let [p, q, r] = [0, 1, 2].map(|k| {
                    mesh.transform
                        .transform_point3(Vec3::from(mesh.vertices[t[k] as usize].position))
                });
                world_area += f64::from((q - p).cross(r - p).length() / 2.0);
            }
        }
        let texels = uv_area * f64::from(size) * f64::from(size);
        Some(Self {
            width: size,
            height: size,
            texels_per_unit: (texels / world_area.max(f64::MIN_POSITIVE)).sqrt() as f32,
            charts: meshes.len() as u32,
            utilization: uv_area.min(1.0) as f32,
            corners,
            authored: true,
        })
    }

    /// The atlas of `uvunwrap` at the highest density that fits one `size` × `size` page.
    pub fn unwrap(scene: &Scene, meshes: &[usize], size: u32) -> Result<Self> {
        let positions: Vec<Vec<[f32; 3]>> = meshes
            .iter()
            .map(|&m| {
                let mesh = &scene.meshes[m];
                mesh.vertices
                    .iter()
                    .map(|v| {
                        mesh.transform
                            .transform_point3(Vec3::from(v.position))
                            .to_array()
                    })
                    .collect()
            })
            .collect();
        // The triangles over vertices welded by position: the loaders split vertices
        // wherever the normal or the texture's UV changes, and the unwrapper would cut
        // charts along every such split; the lightmap follows the surface, not the
        // texture's seams (its own charts still break at creases, by their angle).
        let welded: Vec<Vec<u32>> = meshes
            .iter()
            .zip(&positions)
            .map(|(&m, p)| weld(p, &scene.meshes[m].indices))
            .collect();
        let inputs: Vec<uvunwrap::MeshInput> = positions
            .iter()
            .zip(&welded)
            .map(|(p, i)| uvunwrap::MeshInput::new(p, i))
            .collect();
        let options = uvunwrap::Options {
            density: uvunwrap::Density::Auto { page_size: size },
            padding: PADDING,
            ..Default::default()
        };
        let faces: usize = meshes
            .iter()
            .map(|&m| scene.meshes[m].indices.len() / 3)
            .sum();
        let progress = Progress::new("unwrapping lightmap UVs (faces)", faces as u64);
        let atlas = uvunwrap::generate_with_progress(&inputs, &options, |p| {
            if p.stage == uvunwrap::Stage::Parameterizing {
                progress.set(p.done as u64);
            }
            true
        })
        .context("generating the lightmap UVs")?;
        progress.finish();
        if atlas.page_count != 1 {
            bail!(
                "the lightmap's charts need {} pages of {size}² texels: give a larger lightmap",
                atlas.page_count
            );
        }
        let mut corners = vec![Vec::new(); scene.meshes.len()];
        for (&m, out) in meshes.iter().zip(&atlas.meshes) {
            corners[m] = out
                .indices
                .iter()
                .map(|&i| out.vertices[i as usize].uv)
                .collect();
        }
        Ok(Self {
            width: atlas.width,
            height: atlas.height,
            texels_per_unit: atlas.texels_per_unit,
            charts: atlas.chart_count,
            utilization: atlas.utilization,
            corners,
            authored: false,
        })
    }
}

/// The static meshes with triangles, which the lightmap holds.
pub fn static_meshes(scene: &Scene) -> Result<Vec<usize>> {
    let meshes: Vec<usize> = (0..scene.meshes.len())
        .filter(|&m| scene.meshes[m].animation.is_none() && !scene.meshes[m].indices.is_empty())
        .collect();
    if meshes.is_empty() {
        bail!(
            "{} has no static triangles to place receivers on",
            scene.source.display()
        );
    }
    Ok(meshes)
}

/// `indices` with every vertex replaced by the first vertex at the same position.
fn weld(positions: &[[f32; 3]], indices: &[u32]) -> Vec<u32> {
    let mut first = std::collections::HashMap::new();
    let canonical: Vec<u32> = positions
        .iter()
        .enumerate()
        .map(|(i, p)| *first.entry(p.map(f32::to_bits)).or_insert(i as u32))
        .collect();
    indices.iter().map(|&i| canonical[i as usize]).collect()
}
