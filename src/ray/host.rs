//! Scene ray casting on the host: closest hits against the meshes through an obvhs BVH2,
//! for the bake's geometric tests (is a point in free space?) and the diffuse walks that
//! measure how much light a bounce keeps, where a GPU round trip per handful of rays would
//! cost more than the rays.
//!
//! obvhs speaks a newer glam than voxcone; its vectors are built here from arrays
//! (`.into()`), so the two never meet in a signature.

use glam::{DVec3, Quat, Vec3};
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::bvh2::Bvh2;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;
use rayon::prelude::*;

use super::Triangles;
use crate::scene::{Mesh, Scene};

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostHit {
    pub t: f32,
    /// Whether the ray met the triangle's front (the side its winding faces).
    pub front: bool,
    /// The triangle's unit geometric normal (its winding's; zero for a degenerate one).
    pub normal: Vec3,
    /// The triangle's material, an index into the scene's.
    pub material: u32,
}

/// Triangles of the scene's meshes in a BVH2 on the host.
pub struct HostRays {
    bvh: Bvh2,
    triangles: Vec<Triangle>,
    corners: Vec<[Vec3; 3]>,
    materials: Vec<u32>,
}

impl HostRays {
    /// The static meshes of `scene`.
    pub fn of_static(scene: &Scene) -> Self {
        Self::of(scene, |m| m.animation.is_none())
    }

    /// The meshes of `scene` that `keep` accepts, at time 0.
    pub fn of(scene: &Scene, keep: impl Fn(&Mesh) -> bool) -> Self {
        let Triangles {
            corners,
            triangles: gpu,
            ..
        } = Triangles::of(scene, 0.0, keep);
        let triangles: Vec<Triangle> = corners
            .iter()
            .map(|[a, b, c]| Triangle {
                v0: a.to_array().into(),
                v1: b.to_array().into(),
                v2: c.to_array().into(),
            })
            .collect();
        // The GPU's layout keeps the material in the first corner's fourth component.
        let materials = gpu.iter().map(|t| t.v0[3].to_bits()).collect();
        let mut core = std::time::Duration::ZERO;
        let bvh = build_bvh2_from_tris(&triangles, BvhBuildParams::fast_build(), &mut core);
        Self {
            bvh,
            triangles,
            corners,
            materials,
        }
    }

    /// The closest hit along the unit `dir` from `origin`, beyond `t_min`.
    pub fn closest(&self, origin: Vec3, dir: Vec3, t_min: f32) -> Option<HostHit> {
        let ray = Ray::new(
            origin.to_array().into(),
            dir.to_array().into(),
            t_min,
            f32::INFINITY,
        );
        let mut hit = RayHit::none();
        let found = self.bvh.ray_traverse(ray, &mut hit, |ray, i| {
            self.triangles[self.bvh.primitive_indices[i] as usize].intersect(ray)
        });
        if !found {
            return None;
        }
        let triangle = self.bvh.primitive_indices[hit.primitive_id as usize] as usize;
        let normal = self.normal(triangle);
        Some(HostHit {
            t: hit.t,
            front: normal.dot(dir) < 0.0,
            normal,
            material: self.materials[triangle],
        })
    }

    fn normal(&self, triangle: usize) -> Vec3 {
        let [a, b, c] = self.corners[triangle];
        (b - a).cross(c - a).normalize_or_zero()
    }
}

/// Walks that [`bounce_rate`] follows: its estimate's relative noise is about 1 / √(the
/// walks still carrying light), under 1 % in a closed room, which moves the bounces it
/// decides by at most one.
const WALKS: usize = 16384;
/// Walks per task: each task's generator is seeded by its index, so that the estimate is
/// the same on any count of threads.
const WALKS_PER_TASK: usize = 1024;
/// Diffuse steps of each walk past the surface the camera sees; the rate is the geometric
/// mean of the steps' after the first.
const STEPS: usize = 4;

/// The share of its light that one diffuse bounce passes on in the image of the scene's
/// camera, in the colour channel that keeps the most: the rate at which the image's later
/// bounces fall. Measured by reciprocity along walks from the camera (each through a
/// random point of its view, a square of its vertical field), on from each surface met in
/// a cosine-distributed direction, each walk's weight in each channel the product of the
/// albedos it met (each material's [`Scene::material_albedo`]); a walk that leaves the
/// scene carries nothing after. A walk's k-th step's weight is what the image's k-th
/// bounce keeps where light reaches every surface alike. Each channel falls at its own
/// rate (a red wall keeps red light): the largest channel of each albedo would overstate
/// them all where walls of different colours face each other. In a closed room of one
/// albedo a the rate is a; it falls with the share of light that escapes (an open plane
/// passes nothing on: it sees only the sky) and with the albedo of what the light meets
/// (a white object in a black room passes almost nothing on). Walks start where the
/// camera looks, so the insides of closed objects, which no light reaches, count for
/// nothing. Every mesh counts at time 0, cut-outs as opaque.
pub fn bounce_rate(scene: &Scene) -> f32 {
    let rays = HostRays::of(scene, |_| true);
    let albedos: Vec<Vec3> = (0..scene.materials.len())
        .map(|m| scene.material_albedo(m as u32))
        .collect();
    // Off the surface by a little of the scene's size, so that a walk does not hit the
    // triangle it leaves.
    let lift = 1e-5 * scene.bounds(0.0).diagonal();
    let camera = &scene.camera;
    let (forward, right) = (camera.forward(), camera.right());
    let up = right.cross(forward);
    let half = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let walk = |random: &mut Random, carried: &mut [DVec3; STEPS + 1]| {
        let (x, y) = (2.0 * random.unit() - 1.0, 2.0 * random.unit() - 1.0);
        let mut dir = (forward + (right * x + up * y) * half).normalize();
        let mut origin = camera.position;
        let mut weight = DVec3::ONE;
        for carried in carried.iter_mut() {
            let Some(hit) = rays.closest(origin, dir, 0.0) else {
                return;
            };
            weight *= albedos[hit.material as usize].as_dvec3();
            if weight.max_element() <= 0.0 || hit.normal == Vec3::ZERO {
                return;
            }
            *carried += weight;
            let side = if hit.front { hit.normal } else { -hit.normal };
            origin = origin + dir * hit.t + side * lift;
            dir = cosine_direction(random, side);
        }
    };
    let carried = (0..WALKS / WALKS_PER_TASK)
        .into_par_iter()
        .map(|task| {
            let mut random = Random(0x9e37_79b9_7f4a_7c15 ^ ((task as u64 + 1) << 20));
            let mut carried = [DVec3::ZERO; STEPS + 1];
            for _ in 0..WALKS_PER_TASK {
                walk(&mut random, &mut carried);
            }
            carried
        })
        // Summed in task order, not by rayon's reduce, whose grouping follows the work
        // stealing: the same walks then give the same rate to the last bit.
        .collect::<Vec<_>>()
        .iter()
        .fold([DVec3::ZERO; STEPS + 1], |mut sum, c| {
            for (s, c) in sum.iter_mut().zip(c) {
                *s += *c;
            }
            sum
        });
    (0..3)
        .filter(|&c| carried[1][c] > 0.0)
        .map(|c| (carried[STEPS][c] / carried[1][c]).powf(1.0 / (STEPS - 1) as f64))
        .fold(0.0, f64::max) as f32
}

/// A direction about the unit `n` distributed as cos θ / π (Malley's method).
fn cosine_direction(random: &mut Random, n: Vec3) -> Vec3 {
    let (r, phi) = (random.unit().sqrt(), std::f32::consts::TAU * random.unit());
    let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r * r).max(0.0).sqrt());
    (Quat::from_rotation_arc(Vec3::Z, n) * local).normalize()
}

/// A small deterministic generator (xorshift), so that random cases and estimates are the
/// same every run.
pub struct Random(pub u64);

impl Random {
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform on the unit sphere.
    pub fn direction(&mut self) -> Vec3 {
        let z = 2.0 * self.unit() - 1.0;
        let phi = std::f32::consts::TAU * self.unit();
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}
