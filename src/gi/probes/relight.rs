//! The probes' relight and the receivers' reconstruction on the host (Sedláček 2019,
//! 3.3.1.1 and 3.3.1.3, before the clusters): the radiance each probe ray meets,
//! projected onto the harmonics, λ_ij = 4π / N Σ_rays L Y_j over the N rays of the finest
//! relight map (its texels are equal in solid angle), and each receiver's irradiance
//! Σ_ij λ_ij α_ij plus its sky.
//!
//! Of the radiance at the hits this holds what the bake knows without the frame: the
//! materials' emission (one-sided, along the winding's normal; emission textures are
//! not read here) and the sky where a ray leaves the scene. The direct light and the
//! bounces come with the per-frame passes.

use glam::Vec3;

use super::casting::{triangle_normal, RelightRays};
use super::sh::Basis;
use super::transport::Transport;
use crate::gpu_layout::RAY_NONE;
use crate::ray::Triangles;
use crate::scene::Scene;

/// λ of every probe from the emission and sky its rays of the finest relight map meet
/// (level 0 of the level of detail): `probes` × (order + 1)² RGB coefficients.
pub fn emitted_lambda(
    scene: &Scene,
    triangles: &Triangles,
    relight: &RelightRays,
    probes: usize,
    basis: &Basis,
) -> Vec<Vec3> {
    let per_probe = RelightRays::per_probe(relight.side);
    let (first, side) = RelightRays::map(relight.side, 0);
    let rays = &RelightRays::rays(relight.side)[first..first + side * side];
    let n = basis.count();
    let mut lambda = vec![Vec3::ZERO; probes * n];
    let mut y = vec![0.0f64; n];
    for p in 0..probes {
        let mut sums = vec![[0.0f64; 3]; n];
        for (t, &(dir, weight)) in rays.iter().enumerate() {
            let hit = &relight.hits[p * per_probe + first + t];
            let radiance = if hit.triangle == RAY_NONE {
                scene.sky
            } else {
                let triangle = &triangles.triangles[hit.triangle as usize];
                let material = triangle.v0[3].to_bits() as usize;
                if triangle_normal(triangles, hit.triangle).dot(dir) < 0.0 {
                    scene.materials[material].emission
                } else {
                    Vec3::ZERO
                }
            };
            if radiance == Vec3::ZERO {
                continue;
            }
            basis.eval_into(dir, &mut y);
            for (s, y) in sums.iter_mut().zip(&y) {
                for c in 0..3 {
                    s[c] += weight * y * radiance[c] as f64;
                }
            }
        }
        for (l, s) in lambda[p * n..(p + 1) * n].iter_mut().zip(&sums) {
            *l = Vec3::new(s[0] as f32, s[1] as f32, s[2] as f32);
        }
    }
    lambda
}

/// Receiver `r`'s irradiance from the probes' `lambda` and a sky of radiance `sky`.
pub fn irradiance(transport: &Transport, lambda: &[Vec3], sky: Vec3, r: usize) -> Vec3 {
    let n = super::sh::coefficient_count(transport.order);
    let range = transport.offsets[r] as usize..transport.offsets[r + 1] as usize;
    let mut e = sky * transport.sky[r];
    for k in range {
        let probe = transport.probes[k] as usize;
        let alpha = &transport.alpha[k * n..(k + 1) * n];
        for (a, l) in alpha.iter().zip(&lambda[probe * n..(probe + 1) * n]) {
            e += *l * *a;
        }
    }
    e
}
