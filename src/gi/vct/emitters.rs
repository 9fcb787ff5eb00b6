//! The emitters whose light the cone tracer samples instead of gathering it through the
//! voxels.
//!
//! A cone gather sees an emitter only through the cones that happen to cover it: a small
//! one falls in the gaps between the ring's cones from some directions and under two of
//! them from others, and a surface beside it gathers the emitter's voxels blended into its
//! own (BENCHMARKS.md, session 28: `cornell_area`'s emitter light 0.43 to 11.3 of the path
//! tracer's per block). So the emitters a scene has few triangles of are lights here: the
//! screen and voxel shading add their exact unoccluded irradiance (Lambert's polygon
//! formula), times a soft-shadow cone's visibility, and their emission is left out of the
//! voxels, so that no cone gathers it a second time.
//!
//! Sampled: the triangles of static meshes whose material emits a constant radiance (no
//! emission texture, no cut-out, opaque), grouped into planar connected pieces, each one
//! emitter with one visibility cone; only where the scene has at most
//! `VctSettings::sampled_emitters` such triangles (each costs every shaded point an
//! irradiance evaluation). Others stay in the voxels and reach the surfaces through the
//! gather, as all emitters do with `--sampled-emitters 0`.

use std::collections::HashMap;
use std::sync::Arc;

use anyhow::Result;
use ash::vk;
use glam::Vec3;

use crate::gpu_layout::{VctEmitter, VctEmitterTriangle};
use crate::scene::{Material, Scene};
use crate::vk::{Buffer, Context};

/// The sampled emitters, their triangles, and the material bits (`BINDING_VCT_SAMPLED_MATERIALS`).
#[derive(Debug, Default)]
pub struct SampledEmitters {
    pub emitters: Vec<VctEmitter>,
    pub triangles: Vec<VctEmitterTriangle>,
    pub material_bits: Vec<u32>,
}

impl SampledEmitters {
    /// Whether material `m`'s emission is sampled (and so left out of the voxels).
    pub fn samples_material(&self, m: usize) -> bool {
        self.material_bits
            .get(m / 32)
            .is_some_and(|w| w & (1 << (m % 32)) != 0)
    }

    /// The storage buffers of `BINDING_VCT_EMITTERS`, `BINDING_VCT_EMITTER_TRIANGLES` and
    /// `BINDING_VCT_SAMPLED_MATERIALS`, each of one unused entry where it would be empty.
    pub fn upload(&self, ctx: &Arc<Context>) -> Result<[Buffer; 3]> {
        fn storage<T: bytemuck::Pod + Default>(
            ctx: &Arc<Context>,
            name: &str,
            entries: &[T],
        ) -> Result<Buffer> {
            let unused = [T::default()];
            let entries = if entries.is_empty() { &unused } else { entries };
            Buffer::with_data(
                ctx,
                name,
                bytemuck::cast_slice(entries),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )
        }
        Ok([
            storage(ctx, "vct emitters", &self.emitters)?,
            storage(ctx, "vct emitter triangles", &self.triangles)?,
            storage(ctx, "vct sampled materials", &self.material_bits)?,
        ])
    }
}

/// Whether `m`'s light can be sampled: a constant radiance from an opaque surface.
fn constant_emitter(m: &Material) -> bool {
    m.emission.max_element() > 0.0
        && m.emission_texture.is_none()
        && m.coverage_texture.is_none()
        && m.dissolve >= 1.0
}

/// The emitters of `scene` to sample, when it has at most `max_triangles` triangles of
/// them; none otherwise (and with `max_triangles` 0).
pub fn sampled_emitters(scene: &Scene, max_triangles: u32) -> SampledEmitters {
    let words = scene.materials.len().div_ceil(32).max(1);
    let mut out = SampledEmitters {
        material_bits: vec![0; words],
        ..Default::default()
    };
    // A material on a moving mesh stays in the voxels everywhere: the bits are per material.
    let mut candidate: Vec<bool> = scene.materials.iter().map(constant_emitter).collect();
    for mesh in &scene.meshes {
        if mesh.animation.is_some() {
            candidate[mesh.material as usize] = false;
        }
    }
    let meshes: Vec<_> = scene
        .meshes
        .iter()
        .filter(|m| candidate[m.material as usize])
        .collect();
    let count: usize = meshes.iter().map(|m| m.indices.len() / 3).sum();
    if count == 0 || max_triangles == 0 {
        return out;
    }
    if count > max_triangles as usize {
        log::info!(
            "the scene has {count} emissive triangles, over the {max_triangles} the cone tracer \
             samples (--sampled-emitters): their light is gathered through the voxels"
        );
        return out;
    }
    let extent = match scene.swept_bounds().diagonal() {
        d if d > 0.0 => d,
        _ => 1.0,
    };
    for mesh in meshes {
        let m = mesh.material as usize;
        out.material_bits[m / 32] |= 1 << (m % 32);
        let world: Vec<Vec3> = mesh
            .vertices
            .iter()
            .map(|v| mesh.transform.transform_point3(Vec3::from(v.position)))
            .collect();
        let triangles: Vec<[Vec3; 3]> = mesh
            .indices
            .chunks_exact(3)
            .map(|t| [0, 1, 2].map(|k| world[t[k] as usize]))
            .filter(|t| (t[1] - t[0]).cross(t[2] - t[0]).length_squared() > 0.0)
            .collect();
        for group in planar_pieces(&triangles, extent) {
            let normal = group.normal;
            out.emitters.push(VctEmitter {
                plane: normal
                    .extend(normal.dot(triangles[group.members[0]][0]))
                    .to_array(),
                radiance: scene.materials[m].emission.extend(0.0).to_array(),
                first_triangle: out.triangles.len() as u32,
                triangle_count: group.members.len() as u32,
                ..Default::default()
            });
            out.triangles
                .extend(group.members.iter().map(|&i| VctEmitterTriangle {
                    v0: triangles[i][0].extend(0.0).to_array(),
                    v1: triangles[i][1].extend(0.0).to_array(),
                    v2: triangles[i][2].extend(0.0).to_array(),
                }));
        }
    }
    log::info!(
        "the cone tracer samples the emitters' light instead of gathering it: {} planar \
         pieces, {count} triangles",
        out.emitters.len()
    );
    out
}

/// A connected set of coplanar triangles.
struct Piece {
    normal: Vec3,
    members: Vec<usize>,
}

/// The triangles grouped into pieces: connected through shared corners (within 1e-5 of
/// the scene's `extent`), and in one plane (normals within about 0.5 degrees, offsets
/// within 1e-4 of the extent). Each piece is one emitter, whose visibility one cone
/// stands for: two panels apart on one mesh are two emitters.
fn planar_pieces(triangles: &[[Vec3; 3]], extent: f32) -> Vec<Piece> {
    let normals: Vec<Vec3> = triangles
        .iter()
        .map(|t| (t[1] - t[0]).cross(t[2] - t[0]).normalize())
        .collect();
    let key = |p: Vec3| (p / (extent * 1e-5)).round().as_ivec3();
    let mut parent: Vec<usize> = (0..triangles.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut corners: HashMap<_, Vec<usize>> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        for p in t {
            corners.entry(key(*p)).or_default().push(i);
        }
    }
    let coplanar = |a: usize, b: usize| {
        normals[a].dot(normals[b]) > 0.99996
            && (normals[a].dot(triangles[b][0]) - normals[a].dot(triangles[a][0])).abs()
                < extent * 1e-4
    };
    for sharing in corners.values() {
        for (k, &a) in sharing.iter().enumerate() {
            for &b in &sharing[k + 1..] {
                if coplanar(a, b) {
                    let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                    parent[rb] = ra;
                }
            }
        }
    }
    let mut pieces: Vec<Piece> = Vec::new();
    let mut index: HashMap<usize, usize> = HashMap::new();
    for i in 0..triangles.len() {
        let r = root(&mut parent, i);
        let p = *index.entry(r).or_insert_with(|| {
            pieces.push(Piece {
                normal: normals[r],
                members: Vec::new(),
            });
            pieces.len() - 1
        });
        pieces[p].members.push(i);
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quad_is_one_piece_and_two_panels_are_two() {
        let quad = |x: f32| {
            let [a, b, c, d] = [
                Vec3::new(x, 2.0, 0.0),
                Vec3::new(x + 1.0, 2.0, 0.0),
                Vec3::new(x + 1.0, 2.0, 1.0),
                Vec3::new(x, 2.0, 1.0),
            ];
            [[a, c, b], [a, d, c]]
        };
        let mut triangles = quad(0.0).to_vec();
        assert_eq!(planar_pieces(&triangles, 10.0).len(), 1);
        triangles.extend(quad(3.0));
        let pieces = planar_pieces(&triangles, 10.0);
        assert_eq!(pieces.len(), 2);
        assert!(pieces.iter().all(|p| p.members.len() == 2));
        assert!(pieces.iter().all(|p| (p.normal - Vec3::Y).length() < 1e-6));
        // Folded along a shared edge: two planes, two pieces.
        let folded = vec![
            [Vec3::ZERO, Vec3::X, Vec3::Z],
            [Vec3::ZERO, Vec3::Y, Vec3::X],
        ];
        assert_eq!(planar_pieces(&folded, 10.0).len(), 2);
    }
}
