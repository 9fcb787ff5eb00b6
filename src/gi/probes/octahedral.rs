//! Clarberg's equal-area octahedral map of the sphere onto a square ("Fast Equal-Area
//! Mapping of the (Hemi)Sphere using SIMD", JGT 2008): every texel of an N × N map covers
//! 4π / N² steradians, so the probes' rays through its texel centres are equally
//! weighted samples of the sphere (Sedláček's relight rays, 3.2.3.1), and the same map
//! holds how far each probe sees, for the receivers' visibility match (3.2.3.2).

use glam::{Vec2, Vec3};
use std::f32::consts::FRAC_PI_4;

/// The unit direction of the point `p` of [-1, 1]².
pub fn decode(p: Vec2) -> Vec3 {
    let (u, v) = (p.x.abs(), p.y.abs());
    let d = 1.0 - (u + v);
    let r = 1.0 - d.abs();
    let phi = if r == 0.0 {
        FRAC_PI_4
    } else {
        ((v - u) / r + 1.0) * FRAC_PI_4
    };
    let z = (1.0 - r * r).copysign(d);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(
        (phi.cos() * s).copysign(p.x),
        (phi.sin() * s).copysign(p.y),
        z,
    )
    .normalize()
}

/// The point of [-1, 1]² of the unit direction `d`.
pub fn encode(d: Vec3) -> Vec2 {
    let r = (1.0 - d.z.abs()).max(0.0).sqrt();
    let phi = d.y.abs().atan2(d.x.abs());
    let mut v = phi / (2.0 * FRAC_PI_4) * r;
    let mut u = r - v;
    if d.z < 0.0 {
        (u, v) = (1.0 - v, 1.0 - u);
    }
    Vec2::new(u.copysign(d.x), v.copysign(d.y))
}

/// The direction through the centre of texel `i` (row-major) of a `side` × `side` map.
pub fn texel_direction(i: usize, side: usize) -> Vec3 {
    let (x, y) = (i % side, i / side);
    decode(Vec2::new(
        (x as f32 + 0.5) / side as f32 * 2.0 - 1.0,
        (y as f32 + 0.5) / side as f32 * 2.0 - 1.0,
    ))
}

/// The texel (row-major) of a `side` × `side` map that holds the unit direction `d`.
pub fn texel_of(d: Vec3, side: usize) -> usize {
    let p = (encode(d) * 0.5 + 0.5) * side as f32;
    let x = (p.x as usize).min(side - 1);
    let y = (p.y as usize).min(side - 1);
    y * side + x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decode_inverts_encode() {
        for d in super::super::sh::sphere_directions(5000) {
            let back = decode(encode(d));
            assert!(back.distance(d) < 1e-5, "{d} comes back as {back}");
        }
        for i in 0..64 * 64 {
            let d = texel_direction(i, 64);
            assert!((d.length() - 1.0).abs() < 1e-5);
            assert_eq!(texel_of(d, 64), i);
        }
    }

    /// Directions spread evenly over the sphere fall evenly into the texels: with 256
    /// per texel on average, every texel of a 16 × 16 map holds 256 within ±12 %, about
    /// four standard deviations of a lattice's counting error (a map that is not
    /// equal-area, the plain octahedral one, spreads its texels' areas by a factor of
    /// about three).
    #[test]
    fn every_texel_covers_the_same_solid_angle() {
        let side = 16;
        let mut counts = vec![0u32; side * side];
        for d in super::super::sh::sphere_directions(256 * side * side) {
            counts[texel_of(d, side)] += 1;
        }
        let (low, high) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
        assert!(
            *low >= 225 && *high <= 287,
            "texels hold {low} to {high} of 256"
        );
    }
}
