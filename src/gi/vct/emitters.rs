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
//!
//! One cone stands for the visibility of the whole piece, along its vector irradiance: a
//! hard shadow, as from the piece's centre, where an area emitter casts penumbrae (a
//! floor under a block lit by a square emitter took 0.24 of the path tracer's light in
//! view, the whole penumbra dark). So the pieces are cut, the longest first, into up to
//! `VctSettings::emitter_pieces` parts of at least a voxel, each an emitter with its own
//! cone: the shadow becomes the mean of the parts' (0.79 with 8; 0.90 since the narrow
//! cones read the voxels' coverage, `sample_base_snapped`), and the parts'
//! irradiances still sum to the piece's exactly. The specular and refraction cones take
//! each whole emitter's share of their solid angle (the parts' vector irradiances summed):
//! a share taken part by part, each as a disc, misses a narrow cone aimed where parts
//! meet.

use std::collections::HashMap;
use std::sync::Arc;

use anyhow::Result;
use ash::vk;
use glam::Vec3;

use crate::gpu_layout::{VctEmitter, VctEmitterTriangle};
use crate::scene::{Aabb, Material, Scene};
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
/// them (none otherwise, and with `max_triangles` 0), cut into up to `parts` emitters no
/// shorter than `smallest` (a voxel).
pub fn sampled_emitters(
    scene: &Scene,
    max_triangles: u32,
    parts: usize,
    smallest: f32,
) -> SampledEmitters {
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
    let mut pieces = Vec::new();
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
            pieces.push(Part {
                whole: pieces.len(),
                material: m,
                normal: group.normal,
                triangles: group.members.iter().map(|&i| triangles[i]).collect(),
            });
        }
    }
    let whole = pieces.len();
    cut(&mut pieces, parts, smallest);
    // Each emitter's pieces side by side, the first counting them (`group_pieces`).
    pieces.sort_by_key(|p| p.whole);
    for (i, part) in pieces.iter().enumerate() {
        let normal = part.normal;
        let first = i == 0 || pieces[i - 1].whole != part.whole;
        let group_pieces = if first {
            pieces[i..]
                .iter()
                .take_while(|p| p.whole == part.whole)
                .count() as u32
        } else {
            0
        };
        out.emitters.push(VctEmitter {
            plane: normal.extend(normal.dot(part.triangles[0][0])).to_array(),
            radiance: scene.materials[part.material]
                .emission
                .extend(0.0)
                .to_array(),
            first_triangle: out.triangles.len() as u32,
            triangle_count: part.triangles.len() as u32,
            group_pieces,
            ..Default::default()
        });
        out.triangles
            .extend(part.triangles.iter().map(|t| VctEmitterTriangle {
                v0: t[0].extend(0.0).to_array(),
                v1: t[1].extend(0.0).to_array(),
                v2: t[2].extend(0.0).to_array(),
            }));
    }
    log::info!(
        "the cone tracer samples the emitters' light instead of gathering it: {whole} planar \
         pieces of {count} triangles, cut into {} emitters",
        out.emitters.len()
    );
    out
}

/// A sampled emitter: triangles of one material in one plane, of the `whole` emitter.
struct Part {
    whole: usize,
    material: usize,
    normal: Vec3,
    triangles: Vec<[Vec3; 3]>,
}

/// The parts cut in halves, the longest first, across the longest side of their bounds
/// (so that a rectangle becomes a grid of near-square cells), until there are `parts` or
/// none is longer than `smallest`.
fn cut(pieces: &mut Vec<Part>, parts: usize, smallest: f32) {
    let longest = |t: &[[Vec3; 3]]| {
        let bounds = bounds(t);
        let size = bounds.size();
        let axis = (0..3).fold(0, |best, k| if size[k] > size[best] { k } else { best });
        (size[axis], axis, bounds.center()[axis])
    };
    while pieces.len() < parts {
        let Some((i, (size, axis, middle))) = pieces
            .iter()
            .map(|p| longest(&p.triangles))
            .enumerate()
            .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
        else {
            return;
        };
        if size <= smallest {
            return;
        }
        let (mut below, mut above) = (Vec::new(), Vec::new());
        for t in &pieces[i].triangles {
            clip_triangle(*t, axis, middle, &mut below, &mut above);
        }
        below.retain(|t| area(t) > 0.0);
        above.retain(|t| area(t) > 0.0);
        if below.is_empty() || above.is_empty() {
            return;
        }
        let (whole, material, normal) = (pieces[i].whole, pieces[i].material, pieces[i].normal);
        pieces[i].triangles = below;
        pieces.push(Part {
            whole,
            material,
            normal,
            triangles: above,
        });
    }
}

fn bounds(triangles: &[[Vec3; 3]]) -> Aabb {
    let mut bounds = Aabb::EMPTY;
    triangles.iter().flatten().for_each(|&p| bounds.extend(p));
    bounds
}

/// A cut through a corner leaves a triangle of no area, which no emitter needs.
fn area(t: &[Vec3; 3]) -> f32 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

/// Triangle `t` cut by the plane where coordinate `axis` is `at`: its parts below go to
/// `below`, those above to `above` (a triangle and a quad's two triangles where it
/// crosses), each keeping `t`'s winding.
fn clip_triangle(
    t: [Vec3; 3],
    axis: usize,
    at: f32,
    below: &mut Vec<[Vec3; 3]>,
    above: &mut Vec<[Vec3; 3]>,
) {
    let side = t.map(|p| p[axis] - at);
    if side.iter().all(|&s| s <= 0.0) {
        below.push(t);
        return;
    }
    if side.iter().all(|&s| s >= 0.0) {
        above.push(t);
        return;
    }
    // The corner alone on its side, and the other two in the triangle's order after it.
    let alone = (0..3)
        .find(|&k| {
            (side[k] > 0.0) != (side[(k + 1) % 3] > 0.0)
                && (side[k] > 0.0) != (side[(k + 2) % 3] > 0.0)
        })
        .unwrap_or(0);
    let (a, b, c) = (alone, (alone + 1) % 3, (alone + 2) % 3);
    let crossing = |p: usize, q: usize| t[p] + (t[q] - t[p]) * (side[p] / (side[p] - side[q]));
    let (ab, ca) = (crossing(a, b), crossing(c, a));
    let (one, two) = if side[a] > 0.0 {
        (above, below)
    } else {
        (below, above)
    };
    one.push([t[a], ab, ca]);
    two.push([ab, t[b], t[c]]);
    two.push([ab, t[c], ca]);
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

    /// A 2 x 1 rectangle cut into eight is a grid of 0.5 x 0.5 cells, their areas summing
    /// to its own and their triangles keeping its winding; no cell is cut below
    /// `smallest`.
    #[test]
    fn a_rectangle_is_cut_into_square_cells() {
        let [a, b, c, d] = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let rectangle = || {
            vec![Part {
                whole: 0,
                material: 0,
                normal: Vec3::Z,
                triangles: vec![[a, b, c], [a, c, d]],
            }]
        };
        for (parts, smallest, count, side) in [(8, 0.01, 8, 0.5), (64, 0.3, 32, 0.25)] {
            let mut pieces = rectangle();
            cut(&mut pieces, parts, smallest);
            assert_eq!(pieces.len(), count);
            let mut total = 0.0;
            for part in &pieces {
                let area: f32 = part.triangles.iter().map(area).sum();
                assert!((area - side * side).abs() < 1e-5, "{area}");
                total += area;
                let size = bounds(&part.triangles).size();
                assert!((size - Vec3::new(side, side, 0.0)).abs().max_element() < 1e-5);
                for t in &part.triangles {
                    assert!((t[1] - t[0]).cross(t[2] - t[0]).z > 0.0, "{t:?}");
                }
            }
            assert!((total - 2.0).abs() < 1e-5);
        }
    }
}
