//! Probe placement and radius (Sedláček 2019, 3.2.2): probes in free space near the
//! surfaces, thinned to an even density, and one support radius for all of them.

use anyhow::{bail, Result};
use glam::{IVec3, UVec3, Vec3};

use super::receivers::Receiver;
use crate::ray::host::HostRays;
use crate::scene::{Aabb, Scene};

/// The most cells per axis of the placement grid.
const MAX_CELLS: u32 = 256;

/// The spatial weight kernel w(t) = 2t³ − 3t² + 1 on [0, 1], 0 beyond (3.1.2.3, 3.2.2.1).
pub fn kernel(t: f32) -> f32 {
    if t >= 1.0 {
        0.0
    } else {
        let t = t.max(0.0);
        2.0 * t * t * t - 3.0 * t * t + 1.0
    }
}

/// The placed probes.
#[derive(Clone, Debug)]
pub struct Probes {
    pub positions: Vec<Vec3>,
    /// The spacing of the desired density, ρ_p: the placement grid's cells are a quarter
    /// of it.
    pub spacing: f32,
    /// Free cells next to a surface's front that could hold a probe, before thinning.
    pub candidates: usize,
    /// Every probe's support radius: the mean distance from a sample of receivers to
    /// their `overlaps`-th closest probe (3.2.2.2).
    pub radius: f32,
}

/// What the placement grid holds per cell.
#[derive(Clone, Copy, Default)]
struct Cell {
    /// The sum of the unit normals of the surface samples in the cell.
    normal_sum: Vec3,
    samples: u32,
}

impl Cell {
    /// The cell's normal, where the surfaces in it agree: the mean of their unit normals
    /// is at least 0.7 long (about 45° of spread; the thesis's "roughly the same
    /// direction", 3.2.2.1). A cell with none cannot place probes.
    fn normal(&self) -> Option<Vec3> {
        if self.samples == 0 {
            return None;
        }
        let mean = self.normal_sum / self.samples as f32;
        (mean.length() >= 0.7).then(|| mean.normalize())
    }
}

/// The bounds of the static meshes.
pub fn static_bounds(scene: &Scene) -> Aabb {
    let mut bounds = Aabb::EMPTY;
    for mesh in scene.meshes.iter().filter(|m| m.animation.is_none()) {
        bounds = bounds.union(&mesh.local_bounds.transformed(mesh.transform));
    }
    bounds
}

impl Probes {
    /// About `desired` probes for `scene` (whose static meshes `rays` casts against),
    /// each supporting the receivers within a radius
    /// that reaches `overlaps` probes from a typical receiver.
    pub fn place(
        scene: &Scene,
        rays: &HostRays,
        receivers: &[Receiver],
        desired: u32,
        overlaps: u32,
    ) -> Result<Self> {
        if desired == 0 || overlaps == 0 {
            bail!("probe placement needs at least one probe and one overlap");
        }
        let bounds = static_bounds(scene);
        let size = bounds
            .size()
            .max(Vec3::splat(1e-3 * bounds.diagonal().max(1e-6)));
        // The desired density: `desired` cells of side ρ_p fill the scene's box.
        let spacing = (size.x * size.y * size.z / desired as f32).cbrt();
        // Candidates on a grid four times finer than the spacing, so that thinning has
        // free cells close to every surface to choose from (at half the spacing Sponza's
        // detail left fewer free cells than probes desired, and 8 % of its receivers out
        // of every probe's reach).
        let cell = (spacing * 0.25).max(size.max_element() / MAX_CELLS as f32);
        let dims = (size / cell)
            .ceil()
            .as_uvec3()
            .clamp(UVec3::ONE, UVec3::splat(MAX_CELLS));
        let index = |c: UVec3| (c.x + dims.x * (c.y + dims.y * c.z)) as usize;
        let cell_of = |p: Vec3| {
            ((p - bounds.min) / cell)
                .floor()
                .as_ivec3()
                .clamp(IVec3::ZERO, dims.as_ivec3() - 1)
                .as_uvec3()
        };
        let mut cells = vec![Cell::default(); (dims.x * dims.y * dims.z) as usize];
        // Every static triangle, sampled at most half a cell apart.
        for mesh in scene.meshes.iter().filter(|m| m.animation.is_none()) {
            for t in mesh.indices.chunks_exact(3) {
                let [a, b, c] = [0, 1, 2].map(|k| {
                    mesh.transform
                        .transform_point3(Vec3::from(mesh.vertices[t[k] as usize].position))
                });
                let normal = (b - a).cross(c - a).normalize_or_zero();
                if normal == Vec3::ZERO {
                    continue;
                }
                let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
                let steps = ((longest / (0.5 * cell)).ceil() as u32).clamp(1, 4096);
                for i in 0..=steps {
                    for j in 0..=steps - i {
                        let (u, v) = (i as f32 / steps as f32, j as f32 / steps as f32);
                        let p = a + (b - a) * u + (c - a) * v;
                        let c = &mut cells[index(cell_of(p))];
                        c.normal_sum += normal;
                        c.samples += 1;
                    }
                }
            }
        }
        // Free cells that more of their neighbours' surfaces face than turn their back on
        // (3.2.2.1's rules: no object in the cell, near a surface, not inside an object;
        // cells whose surfaces disagree do not vote, as the thesis's voxels without a
        // normal place no probes, but neither do they veto the cells round them, which in
        // detailed scenes, Sponza's columns and plants, would leave no free cell at all).
        let mut candidates = Vec::new();
        for z in 0..dims.z {
            for y in 0..dims.y {
                for x in 0..dims.x {
                    let here = UVec3::new(x, y, z);
                    if cells[index(here)].samples > 0 {
                        continue;
                    }
                    let (mut front, mut behind) = (0, 0);
                    for offset in (0..27).map(|i| IVec3::new(i % 3, (i / 3) % 3, i / 9) - 1) {
                        let n = here.as_ivec3() + offset;
                        if offset == IVec3::ZERO
                            || n.cmplt(IVec3::ZERO).any()
                            || n.cmpge(dims.as_ivec3()).any()
                        {
                            continue;
                        }
                        if let Some(normal) = cells[index(n.as_uvec3())].normal() {
                            if normal.dot(-offset.as_vec3()) > 0.0 {
                                front += 1;
                            } else {
                                behind += 1;
                            }
                        }
                    }
                    if front > behind {
                        candidates.push(bounds.min + (here.as_vec3() + 0.5) * cell);
                    }
                }
            }
        }
        // Not inside an object (rule 3), by rays: from free space in a closed scene every
        // ray meets a surface's front. The votes above pass cells inside an object that
        // stands on a floor (the floor faces them, from under the object); their rays
        // meet the object's walls from behind: 60-70 % of the Cornell box's blocks',
        // where 97 % of all candidates see no back at all. A tenth is allowed for open,
        // one-sided surfaces seen from behind (Sponza's curtains and plants: 3.5 % of
        // its candidates see 20-50 % backs).
        let directions = super::sh::sphere_directions(32);
        candidates.retain(|c| {
            let (mut hits, mut back) = (0, 0);
            for d in &directions {
                if let Some(h) = rays.closest(*c, *d, 0.0) {
                    hits += 1;
                    back += usize::from(!h.front);
                }
            }
            back * 10 <= hits
        });
        if candidates.is_empty() {
            bail!(
                "{} has no free space next to the front of a surface for probes \
                 (placement cells {cell:.3} wide)",
                scene.source.display()
            );
        }
        let positions = thin(&candidates, desired as usize, spacing);
        let radius = support_radius(&positions, receivers, overlaps as usize);
        Ok(Self {
            positions,
            spacing,
            candidates: candidates.len(),
            radius,
        })
    }

    /// The probes supporting a receiver at `p` with their weights w(|p − p_i| / r):
    /// those within the radius, at most `overlaps` of them, closest first (3.2.3.2).
    pub fn support(&self, p: Vec3, overlaps: usize) -> Vec<(u32, f32)> {
        let mut near: Vec<(u32, f32)> = self
            .positions
            .iter()
            .enumerate()
            .map(|(i, q)| (i as u32, p.distance(*q)))
            .filter(|&(_, d)| d < self.radius)
            .collect();
        near.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        near.truncate(overlaps);
        near.into_iter()
            .map(|(i, d)| (i, kernel(d / self.radius)))
            .collect()
    }
}

/// Removes the candidate of highest kernel density K_i = Σ_j w(|p_i − p_j| / ρ_p) until
/// `desired` remain (3.2.2.1); ties go to the later candidate, so the result depends on
/// the positions only.
pub(super) fn thin(candidates: &[Vec3], desired: usize, spacing: f32) -> Vec<Vec3> {
    let n = candidates.len();
    let mut density = vec![0.0f64; n];
    for i in 0..n {
        for j in i + 1..n {
            let w = kernel(candidates[i].distance(candidates[j]) / spacing) as f64;
            density[i] += w;
            density[j] += w;
        }
    }
    let mut alive = vec![true; n];
    for _ in desired..n {
        let worst = (0..n)
            .filter(|&i| alive[i])
            .max_by(|&a, &b| density[a].total_cmp(&density[b]).then(a.cmp(&b)))
            .expect("more candidates than desired");
        alive[worst] = false;
        for j in (0..n).filter(|&j| alive[j]) {
            density[j] -= kernel(candidates[worst].distance(candidates[j]) / spacing) as f64;
        }
    }
    (0..n)
        .filter(|&i| alive[i])
        .map(|i| candidates[i])
        .collect()
}

/// The mean, over up to 4096 receivers spread through the list, of the distance to the
/// `overlaps`-th closest probe (to the farthest where there are fewer probes).
fn support_radius(probes: &[Vec3], receivers: &[Receiver], overlaps: usize) -> f32 {
    let stride = receivers.len().div_ceil(4096).max(1);
    let k = overlaps.min(probes.len()) - 1;
    let mut sum = 0.0f64;
    let mut count = 0;
    let mut distances = vec![0.0f32; probes.len()];
    for r in receivers.iter().step_by(stride) {
        for (d, p) in distances.iter_mut().zip(probes) {
            *d = r.position.distance(*p);
        }
        distances.select_nth_unstable_by(k, f32::total_cmp);
        sum += distances[k] as f64;
        count += 1;
    }
    (sum / count.max(1) as f64) as f32
}
