//! Irradiance receivers (Sedláček 2019, 3.2.1.2): one per lightmap texel that a static
//! triangle covers, with the surface's position, normal and material there.
//!
//! The thesis rasterises positions, normals and material ids in UV space with OpenGL;
//! here the triangles are scanned on the CPU, which is exact and needs no render target
//! as large as the lightmap. A texel is a receiver wherever a triangle comes within one
//! texel of its centre (in the lightmap's max-norm): the bilinear lookup of any point of
//! a chart reads exactly those texels, so the chart's border needs no separate dilation
//! pass (the thesis's one-texel "extend", 3.2.1). Where the centre lies outside every
//! triangle, the receiver sits at the closest point of the closest triangle: the border
//! texels carry the light at the chart's edge.

use glam::{Mat3, Vec2, Vec3};

use super::lightmap::Lightmap;
use crate::ray::host::HostRays;
use crate::scene::Scene;

/// One receiver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Receiver {
    pub position: Vec3,
    /// Unit normal (the interpolated vertex normals, the winding's where they vanish).
    pub normal: Vec3,
    pub material: u32,
    /// Its texel, column and row.
    pub texel: [u32; 2],
    /// Whether the texel's centre lies on the surface (else it is a border texel, placed
    /// at the closest point of the chart).
    pub inside: bool,
}

/// The receivers of a lightmap, and what the scan found.
#[derive(Clone, Debug)]
pub struct Receivers {
    pub list: Vec<Receiver>,
    /// Receiver index per texel (row-major), or `NO_RECEIVER`.
    pub index: Vec<u32>,
    /// Texels whose centre lies inside two triangles more than a texel apart on the
    /// surfaces: overlapping charts (zero for a valid atlas).
    pub overlaps: usize,
}

pub const NO_RECEIVER: u32 = u32::MAX;

/// The best triangle found so far for one texel.
#[derive(Clone, Copy)]
struct Candidate {
    /// Distance in texels from the texel's centre to the triangle (0 inside).
    distance: f32,
    mesh: u32,
    triangle: u32,
    /// Barycentric coordinates of the closest point, for corners 1 and 2.
    bary: Vec2,
}

/// Barycentrics (of corners 1 and 2) of `p` in the triangle a, b, c.
fn barycentric(p: Vec2, a: Vec2, b: Vec2, c: Vec2) -> Option<Vec2> {
    let (e1, e2, d) = (b - a, c - a, p - a);
    let det = e1.perp_dot(e2);
    if det.abs() < 1e-12 {
        return None;
    }
    Some(Vec2::new(d.perp_dot(e2), e1.perp_dot(d)) / det)
}

/// The closest point of segment a-b to p, as the parameter along it.
fn segment_parameter(p: Vec2, a: Vec2, b: Vec2) -> f32 {
    let e = b - a;
    ((p - a).dot(e) / e.length_squared().max(1e-20)).clamp(0.0, 1.0)
}

/// Distance from p to the triangle and the barycentrics of its closest point.
fn closest(p: Vec2, a: Vec2, b: Vec2, c: Vec2) -> Option<(f32, Vec2)> {
    let bary = barycentric(p, a, b, c)?;
    if bary.x >= 0.0 && bary.y >= 0.0 && bary.x + bary.y <= 1.0 {
        return Some((0.0, bary));
    }
    // The closest point lies on an edge: each as (barycentrics of its ends, parameter).
    let edges = [
        (a, b, Vec2::ZERO, Vec2::X),
        (b, c, Vec2::X, Vec2::Y),
        (c, a, Vec2::Y, Vec2::ZERO),
    ];
    edges
        .iter()
        .map(|&(from, to, b0, b1)| {
            let t = segment_parameter(p, from, to);
            (p.distance(from.lerp(to, t)), b0.lerp(b1, t))
        })
        .min_by(|x, y| x.0.total_cmp(&y.0))
}

/// The world position of the point with barycentrics `bary` (of corners 1 and 2) on
/// triangle `t` of mesh `m`.
fn surface_point(scene: &Scene, m: usize, t: usize, bary: Vec2) -> Vec3 {
    let mesh = &scene.meshes[m];
    let p = |k: usize| {
        mesh.transform.transform_point3(Vec3::from(
            mesh.vertices[mesh.indices[3 * t + k] as usize].position,
        ))
    };
    p(0) * (1.0 - bary.x - bary.y) + p(1) * bary.x + p(2) * bary.y
}

/// The barycentrics `bary` of a point on an edge of triangle `t` of mesh `m`, moved
/// `shift` (world units) towards the triangle's centroid, at most halfway there. A border
/// receiver at the closest point of its chart would lie on the edge, where the chart
/// meets its neighbour (a room's floor its wall), and half its hemisphere's rays would
/// leave through the neighbour's plane at distance zero.
fn inward(scene: &Scene, m: usize, t: usize, bary: Vec2, shift: f32) -> Vec2 {
    let centroid = Vec2::splat(1.0 / 3.0);
    let span = surface_point(scene, m, t, bary).distance(surface_point(scene, m, t, centroid));
    if span <= 0.0 {
        return bary;
    }
    bary.lerp(centroid, (shift / span).min(0.5))
}

impl Receivers {
    /// Scans every static triangle of `scene` in `lightmap`.
    pub fn place(scene: &Scene, lightmap: &Lightmap) -> Self {
        let (w, h) = (lightmap.width as usize, lightmap.height as usize);
        let size = Vec2::new(w as f32, h as f32);
        let mut best: Vec<Option<Candidate>> = vec![None; w * h];
        // A texel one world texel on the surface: two claims of a texel's centre farther
        // apart than this are two charts over each other.
        let texel_world = 1.0 / lightmap.texels_per_unit;
        let mut overlaps = 0;
        for (m, mesh) in scene.meshes.iter().enumerate() {
            let corners = &lightmap.corners[m];
            if corners.is_empty() {
                continue;
            }
            for t in 0..mesh.indices.len() / 3 {
                let [a, b, c] = [0, 1, 2].map(|k| Vec2::from(corners[3 * t + k]) * size);
                let low = (a.min(b).min(c) - 1.0).floor().max(Vec2::ZERO);
                let high = (a.max(b).max(c) + 1.0).ceil().min(size);
                for y in low.y as usize..high.y as usize {
                    for x in low.x as usize..high.x as usize {
                        let centre = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                        let Some((distance, bary)) = closest(centre, a, b, c) else {
                            continue;
                        };
                        // Within one texel in the max-norm: the bilinear footprint.
                        let offset = centre - (a + (b - a) * bary.x + (c - a) * bary.y);
                        if offset.abs().max_element() >= 1.0 {
                            continue;
                        }
                        let slot = &mut best[y * w + x];
                        if let Some(old) = slot {
                            if distance == 0.0 && old.distance == 0.0 {
                                let here = surface_point(scene, m, t, bary);
                                let there = surface_point(
                                    scene,
                                    old.mesh as usize,
                                    old.triangle as usize,
                                    old.bary,
                                );
                                if here.distance(there) > 2.0 * texel_world {
                                    overlaps += 1;
                                }
                            }
                            if old.distance <= distance {
                                continue;
                            }
                        }
                        *slot = Some(Candidate {
                            distance,
                            mesh: m as u32,
                            triangle: t as u32,
                            bary,
                        });
                    }
                }
            }
        }
        let mut list = Vec::new();
        let mut index = vec![NO_RECEIVER; w * h];
        for (i, candidate) in best.iter().enumerate() {
            let Some(c) = candidate else {
                continue;
            };
            let mesh = &scene.meshes[c.mesh as usize];
            let t = c.triangle as usize;
            let v = |k: usize| &mesh.vertices[mesh.indices[3 * t + k] as usize];
            let bary = if c.distance > 0.0 {
                inward(scene, c.mesh as usize, t, c.bary, 0.5 * texel_world)
            } else {
                c.bary
            };
            let weights = [1.0 - bary.x - bary.y, bary.x, bary.y];
            let normal_matrix = Mat3::from_mat4(mesh.transform).inverse().transpose();
            let corner = |k: usize| mesh.transform.transform_point3(Vec3::from(v(k).position));
            let winding = (corner(1) - corner(0)).cross(corner(2) - corner(0));
            let smooth: Vec3 = (0..3).map(|k| Vec3::from(v(k).normal) * weights[k]).sum();
            let smooth = normal_matrix * smooth;
            let normal = if smooth.length_squared() > 1e-12 && smooth.is_finite() {
                smooth.normalize()
            } else {
                winding.normalize_or_zero()
            };
            index[i] = list.len() as u32;
            list.push(Receiver {
                position: surface_point(scene, c.mesh as usize, t, bary),
                normal,
                material: mesh.material,
                texel: [(i % w) as u32, (i / w) as u32],
                inside: c.distance == 0.0,
            });
        }
        Self {
            list,
            index,
            overlaps,
        }
    }

    /// Moves the receivers that lie inside geometry out of it (Sedláček 2019, 5.1.4): a
    /// texel of a floor under a box, or at a contact, would gather the light of the
    /// box's inside. From each receiver, `rays` rays over its hemisphere: where at least
    /// 60 % meet a back face and none leaves the scene, the receiver moves along the
    /// shortest of those rays to `offset` beyond the back face it met. Its texel stays.
    /// Returns the receivers moved.
    pub fn shift_out_of_geometry(&mut self, host: &HostRays, rays: usize, offset: f32) -> usize {
        use rayon::prelude::*;
        let pattern = super::casting::cosine_directions(rays);
        let moved: Vec<Option<Vec3>> = self
            .list
            .par_iter()
            .map(|r| {
                let origin = r.position + r.normal * offset;
                let mut back = 0;
                let mut shortest: Option<(f32, Vec3)> = None;
                for d in super::casting::oriented(&pattern, r.normal, 0.0) {
                    let hit = host.closest(origin, d, 0.0)?;
                    if !hit.front {
                        back += 1;
                        if shortest.is_none_or(|(t, _)| hit.t < t) {
                            shortest = Some((hit.t, d));
                        }
                    }
                }
                let (t, d) = shortest?;
                (back * 10 >= rays * 6).then(|| origin + d * (t + offset))
            })
            .collect();
        let mut count = 0;
        for (r, m) in self.list.iter_mut().zip(moved) {
            if let Some(p) = m {
                r.position = p;
                count += 1;
            }
        }
        count
    }

    /// Receivers whose texel's centre lies on the surface.
    pub fn inside(&self) -> usize {
        self.list.iter().filter(|r| r.inside).count()
    }
}
