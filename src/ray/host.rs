//! Scene ray casting on the host: closest hits against the static meshes through an
//! obvhs BVH2, for the bake's geometric tests (is a point in free space?), where a GPU
//! round trip per handful of rays would cost more than the rays.
//!
//! obvhs speaks a newer glam than voxcone; its vectors are built here from arrays
//! (`.into()`), so the two never meet in a signature.

use glam::Vec3;
use obvhs::bvh2::builder::build_bvh2_from_tris;
use obvhs::bvh2::Bvh2;
use obvhs::ray::{Ray, RayHit};
use obvhs::triangle::Triangle;
use obvhs::BvhBuildParams;

use super::Triangles;
use crate::scene::Scene;

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostHit {
    pub t: f32,
    /// Whether the ray met the triangle's front (the side its winding faces).
    pub front: bool,
}

/// The static meshes' triangles in a BVH2 on the host.
pub struct HostRays {
    bvh: Bvh2,
    triangles: Vec<Triangle>,
}

impl HostRays {
    /// The static meshes of `scene`.
    pub fn of_static(scene: &Scene) -> Self {
        let corners = Triangles::of(scene, 0.0, |m| m.animation.is_none()).corners;
        let triangles: Vec<Triangle> = corners
            .iter()
            .map(|[a, b, c]| Triangle {
                v0: a.to_array().into(),
                v1: b.to_array().into(),
                v2: c.to_array().into(),
            })
            .collect();
        let mut core = std::time::Duration::ZERO;
        let bvh = build_bvh2_from_tris(&triangles, BvhBuildParams::fast_build(), &mut core);
        Self { bvh, triangles }
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
        let triangle =
            &self.triangles[self.bvh.primitive_indices[hit.primitive_id as usize] as usize];
        let normal: [f32; 3] = triangle.compute_normal().into();
        Some(HostHit {
            t: hit.t,
            front: Vec3::from(normal).dot(dir) < 0.0,
        })
    }
}
