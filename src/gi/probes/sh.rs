//! Real spherical harmonics up to any band (Sedláček 2019, 3.1.2.1; the probes store their
//! radiance in bands 0 to 7, 64 coefficients).
//!
//! Evaluated with the recurrences of Sloan, "Efficient Spherical Harmonic Evaluation"
//! (JCGT 2013): the associated Legendre functions by the three-term recurrence in l, and
//! sin^m θ cos(mφ), sin^m θ sin(mφ) as the real and imaginary parts of (x + iy)^m, so no
//! trigonometric function is called. Coefficient j = l² + l + m, as in the thesis; no
//! Condon–Shortley phase, so band 1 is √(3/4π) (y, z, x), the thesis's table (its z is up:
//! z = cos θ).

use glam::Vec3;

/// Coefficients of bands 0 to `order`.
pub const fn coefficient_count(order: u32) -> usize {
    ((order + 1) * (order + 1)) as usize
}

/// The highest band the probes may use: 64 coefficients (the thesis's order 7) leave the
/// relight's per-probe sums in single precision well conditioned and fit one cluster
/// matrix row in 64 floats.
pub const MAX_ORDER: u32 = 7;

/// The normalisation constants K_l^m for 0 ≤ m ≤ l ≤ `order`, at index l(l+1)/2 + m,
/// times √2 where m > 0 (the real harmonics' factor).
fn normalisation(order: u32) -> Vec<f64> {
    let mut k = Vec::with_capacity(((order + 1) * (order + 2) / 2) as usize);
    for l in 0..=order {
        for m in 0..=l {
            // (l - m)! / (l + m)! as a product, exact enough in f64 for these bands.
            let ratio: f64 = (l - m + 1..=l + m).map(|i| 1.0 / i as f64).product();
            let base = ((2 * l + 1) as f64 / (4.0 * std::f64::consts::PI) * ratio).sqrt();
            k.push(if m == 0 {
                base
            } else {
                std::f64::consts::SQRT_2 * base
            });
        }
    }
    k
}

/// Evaluates the real spherical harmonics of bands 0 to `order` in the unit direction
/// `d`, once the normalisation constants are computed ([`Basis::new`]).
#[derive(Clone, Debug)]
pub struct Basis {
    order: u32,
    k: Vec<f64>,
}

impl Basis {
    pub fn new(order: u32) -> Self {
        Self {
            order,
            k: normalisation(order),
        }
    }

    pub fn order(&self) -> u32 {
        self.order
    }

    /// The number of coefficients, (order + 1)².
    pub fn count(&self) -> usize {
        coefficient_count(self.order)
    }

    /// Y_j(d) for every j into `out` (at least [`Basis::count`] long).
    pub fn eval_into(&self, d: Vec3, out: &mut [f64]) {
        let n = self.order as usize;
        let (x, y, z) = (d.x as f64, d.y as f64, d.z as f64);
        // (x + iy)^m, m = 0..=n.
        let mut c = vec![1.0; n + 1];
        let mut s = vec![0.0; n + 1];
        for m in 1..=n {
            c[m] = x * c[m - 1] - y * s[m - 1];
            s[m] = x * s[m - 1] + y * c[m - 1];
        }
        // P_m^m without its (1 - z²)^(m/2), which (x + iy)^m carries: (2m - 1)!! (no
        // Condon–Shortley sign); then P_{m+1}^m = (2m + 1) z P_m^m and
        // (l - m) P_l^m = (2l - 1) z P_{l-1}^m - (l + m - 1) P_{l-2}^m.
        let mut pmm = 1.0;
        for m in 0..=n {
            if m > 0 {
                pmm *= (2 * m - 1) as f64;
            }
            let mut p_prev = 0.0;
            let mut p = pmm;
            for l in m..=n {
                if l == m + 1 {
                    p_prev = p;
                    p = (2 * m + 1) as f64 * z * pmm;
                } else if l > m + 1 {
                    let next =
                        ((2 * l - 1) as f64 * z * p - (l + m - 1) as f64 * p_prev) / (l - m) as f64;
                    p_prev = p;
                    p = next;
                }
                let k = self.k[l * (l + 1) / 2 + m] * p;
                let centre = l * l + l;
                if m == 0 {
                    out[centre] = k;
                } else {
                    out[centre + m] = k * c[m];
                    out[centre - m] = k * s[m];
                }
            }
        }
    }

    /// Y_j(d) for every j.
    pub fn eval(&self, d: Vec3) -> Vec<f64> {
        let mut out = vec![0.0; self.count()];
        self.eval_into(d, &mut out);
        out
    }
}

/// The zonal coefficients of the clamped cosine max(cos θ, 0) convolved as irradiance
/// (Ramamoorthi & Hanrahan 2001): E(n) = Σ_lm Â_l L_lm Y_lm(n), where L_lm are the
/// radiance's coefficients. Â_0 = π, Â_1 = 2π/3, zero for the other odd bands, and for even
/// l ≥ 2, 2π (-1)^(l/2 - 1) / ((l + 2)(l - 1)) · l! / (2^l ((l/2)!)²).
pub fn clamped_cosine_band(l: u32) -> f64 {
    let pi = std::f64::consts::PI;
    match l {
        0 => pi,
        1 => 2.0 * pi / 3.0,
        _ if l % 2 == 1 => 0.0,
        _ => {
            let half = l / 2;
            let sign = if half % 2 == 1 { 1.0 } else { -1.0 };
            // l! / (2^l ((l/2)!)²) = C(l, l/2) / 2^l.
            let binomial: f64 = (1..=half).map(|i| (half + i) as f64 / i as f64).product();
            2.0 * pi * sign / (((l + 2) * (l - 1)) as f64) * binomial / 2f64.powi(l as i32)
        }
    }
}

/// `count` directions spread evenly over the sphere (a spherical Fibonacci lattice: equal
/// areas in z, the golden angle in φ), each standing for 4π / count steradians.
pub fn sphere_directions(count: usize) -> Vec<Vec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / count as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Gauss–Legendre nodes and weights on [-1, 1] (Newton's method on P_n).
    fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
        (0..n)
            .map(|i| {
                let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
                loop {
                    let (mut p0, mut p1) = (1.0, x);
                    for k in 2..=n {
                        let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                        p0 = p1;
                        p1 = p2;
                    }
                    let derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                    let step = p1 / derivative;
                    x -= step;
                    if step.abs() < 1e-15 {
                        return (x, 2.0 / ((1.0 - x * x) * derivative * derivative));
                    }
                }
            })
            .collect()
    }

    /// Product quadrature over the sphere: Gauss–Legendre in z, `2 · rows` even steps in
    /// φ; exact for every product of two harmonics of bands below `rows`.
    fn integrate(rows: usize, mut f: impl FnMut(Vec3, f64)) {
        let cols = 2 * rows;
        for (z, wz) in gauss_legendre(rows) {
            let r = (1.0 - z * z).sqrt();
            for j in 0..cols {
                let phi = 2.0 * PI * (j as f64 + 0.5) / cols as f64;
                let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
                f(d, wz * 2.0 * PI / cols as f64);
            }
        }
    }

    fn project(basis: &Basis, rows: usize, f: impl Fn(Vec3) -> f64) -> Vec<f64> {
        let mut coefficients = vec![0.0; basis.count()];
        let mut y = vec![0.0; basis.count()];
        integrate(rows, |d, w| {
            basis.eval_into(d, &mut y);
            let v = f(d) * w;
            for (c, y) in coefficients.iter_mut().zip(&y) {
                *c += v * y;
            }
        });
        coefficients
    }

    #[test]
    fn low_bands_match_the_closed_forms() {
        let basis = Basis::new(2);
        let d = Vec3::new(0.48, -0.6, 0.64);
        let (x, y, z) = (d.x as f64, d.y as f64, d.z as f64);
        let expected = [
            0.5 * (1.0 / PI).sqrt(),
            (3.0 / (4.0 * PI)).sqrt() * y,
            (3.0 / (4.0 * PI)).sqrt() * z,
            (3.0 / (4.0 * PI)).sqrt() * x,
            0.5 * (15.0 / PI).sqrt() * x * y,
            0.5 * (15.0 / PI).sqrt() * y * z,
            0.25 * (5.0 / PI).sqrt() * (2.0 * z * z - x * x - y * y),
            0.5 * (15.0 / PI).sqrt() * z * x,
            0.25 * (15.0 / PI).sqrt() * (x * x - y * y),
        ];
        for (j, (got, want)) in basis.eval(d).iter().zip(expected).enumerate() {
            assert!((got - want).abs() < 1e-6, "Y_{j}: {got} against {want}");
        }
    }

    #[test]
    fn the_basis_is_orthonormal_up_to_band_7() {
        let basis = Basis::new(MAX_ORDER);
        let n = basis.count();
        let mut gram = vec![0.0; n * n];
        let mut y = vec![0.0; n];
        integrate(16, |d, w| {
            basis.eval_into(d, &mut y);
            for a in 0..n {
                for b in 0..n {
                    gram[a * n + b] += w * y[a] * y[b];
                }
            }
        });
        let worst = (0..n * n)
            .map(|i| (gram[i] - if i / n == i % n { 1.0 } else { 0.0 }).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-6, "largest deviation from the identity {worst}");
    }

    #[test]
    fn a_constant_projects_onto_band_0_only() {
        let basis = Basis::new(MAX_ORDER);
        let c = project(&basis, 16, |_| 3.0);
        assert!((c[0] - 3.0 * (4.0 * PI).sqrt()).abs() < 1e-6, "{}", c[0]);
        assert!(c[1..].iter().all(|c| c.abs() < 1e-6), "{c:?}");
    }

    /// A zonal function about axis a projects to c_lm = √(4π / (2l + 1)) g_l Y_lm(a),
    /// with g_l its coefficients about z: for the clamped cosine Â_l Y_lm(a).
    #[test]
    fn the_clamped_cosine_projects_to_its_closed_form() {
        let basis = Basis::new(MAX_ORDER);
        let axis = Vec3::new(0.3, 0.8, -0.52).normalize();
        let c = project(&basis, 1500, |d| d.dot(axis).max(0.0) as f64);
        let y = basis.eval(axis);
        for l in 0..=MAX_ORDER {
            for m in -(l as i32)..=l as i32 {
                let j = (l * l + l) as usize;
                let j = (j as i32 + m) as usize;
                let want = clamped_cosine_band(l) * y[j];
                assert!(
                    (c[j] - want).abs() < 2e-4,
                    "l {l} m {m}: {} against {want}",
                    c[j]
                );
            }
        }
    }

    /// P_l(x) by Bonnet's recurrence.
    fn legendre(l: i32, x: f64) -> f64 {
        let (mut a, mut b) = (1.0, x);
        for n in 2..=l {
            let next = ((2 * n - 1) as f64 * x * b - (n - 1) as f64 * a) / n as f64;
            a = b;
            b = next;
        }
        if l == 0 {
            a
        } else {
            b
        }
    }

    /// The zonal coefficient g_l about z of the cap cos θ ≥ c (1 inside, 0 outside):
    /// 2π K_l^0 ∫ from c to 1 of P_l = 2π K_l^0 (P_{l-1}(c) - P_{l+1}(c)) / (2l + 1).
    fn cap_band(l: i32, c: f64) -> f64 {
        let k = ((2 * l + 1) as f64 / (4.0 * PI)).sqrt();
        let integral = if l == 0 {
            1.0 - c
        } else {
            (legendre(l - 1, c) - legendre(l + 1, c)) / (2 * l + 1) as f64
        };
        2.0 * PI * k * integral
    }

    /// A narrow lobe, the cap of half-angle 20° about a, [`cap_band`]; its band-limited
    /// reconstruction along a is Σ_l √((2l + 1) / 4π) g_l.
    #[test]
    fn a_narrow_cap_projects_and_reconstructs_to_its_closed_form() {
        let basis = Basis::new(MAX_ORDER);
        let axis = Vec3::new(-0.6, 0.0, 0.8);
        let cos_cap = 20f64.to_radians().cos();
        let c = project(&basis, 1500, |d| {
            if d.dot(axis) as f64 >= cos_cap {
                1.0
            } else {
                0.0
            }
        });
        let y = basis.eval(axis);
        let mut reconstruction = 0.0;
        for l in 0..=MAX_ORDER as i32 {
            let k = ((2 * l + 1) as f64 / (4.0 * PI)).sqrt();
            let g = cap_band(l, cos_cap);
            reconstruction += k * g;
            for m in -l..=l {
                let j = (l * l + l + m) as usize;
                let want = (4.0 * PI / (2 * l + 1) as f64).sqrt() * g * y[j];
                assert!(
                    (c[j] - want).abs() < 5e-4,
                    "l {l} m {m}: {} against {want}",
                    c[j]
                );
            }
        }
        let reconstructed: f64 = c.iter().zip(&y).map(|(c, y)| c * y).sum();
        assert!(
            (reconstructed - reconstruction).abs() < 1e-3,
            "reconstructed {reconstructed} along the axis, closed form {reconstruction}"
        );
    }

    #[test]
    fn fibonacci_directions_integrate_the_basis() {
        let basis = Basis::new(MAX_ORDER);
        let directions = sphere_directions(4096);
        let mut sums = vec![0.0; basis.count()];
        let mut y = vec![0.0; basis.count()];
        for d in &directions {
            assert!((d.length() - 1.0).abs() < 1e-5);
            basis.eval_into(*d, &mut y);
            for (s, y) in sums.iter_mut().zip(&y) {
                *s += y * 4.0 * PI / directions.len() as f64;
            }
        }
        assert!((sums[0] - (4.0 * PI).sqrt()).abs() < 1e-6);
        let worst = sums[1..].iter().map(|s| s.abs()).fold(0.0, f64::max);
        assert!(worst < 5e-3, "a higher band integrates to {worst}");
    }

    /// The relight's quadrature (`casting::RelightRays`): each map's rays project a
    /// clamped cosine and a half-space step (a shadow's edge) about a dozen axes onto
    /// bands 0 to 7, and the irradiance those coefficients give every normal, Σ Â_l
    /// c_lm Y_lm, is compared with the closed form's (the zonal coefficients turned to the
    /// axis). Mean error over axes and normals, as a share of the mean irradiance:
    /// 64² 0.02 % and 0.15 %, 32² 0.10 % and 0.41 %, 16² 0.40 % and 1.3 %; one texel of
    /// each of 64²'s 2 × 2 blocks, as level 1's relight read before, 1.4 % and 1.5 % (over
    /// 24 axes).
    #[test]
    fn relight_maps_integrate_analytic_radiance() {
        use crate::gi::probes::casting::RelightRays;
        let basis = Basis::new(MAX_ORDER);
        let axes = sphere_directions(12);
        let normals = sphere_directions(400);
        let side = 64;
        let rays = RelightRays::rays(side);
        let maps = [
            (0, [0.0005, 0.0025]),
            (1, [0.0015, 0.0065]),
            (2, [0.006, 0.021]),
        ];
        for (m, bounds) in maps {
            let (first, s) = RelightRays::map(side, m);
            let map = &rays[first..first + s * s];
            let solid: f64 = map.iter().map(|r| r.1).sum();
            assert!((solid - 4.0 * PI).abs() < 1e-9, "map {m}: {solid} sr");
            for (f, cap, bound) in [("cosine", None, bounds[0]), ("step", Some(0.0), bounds[1])] {
                let (mut error, mut total) = (0.0, 0.0);
                for &axis in &axes {
                    let radiance = |d: Vec3| {
                        let c = f64::from(d.dot(axis));
                        match cap {
                            None => c.max(0.0),
                            Some(c0) => f64::from(u8::from(c >= c0)),
                        }
                    };
                    let mut sampled = vec![0.0; basis.count()];
                    let mut y = vec![0.0; basis.count()];
                    for &(d, w) in map {
                        basis.eval_into(d, &mut y);
                        let v = radiance(d) * w;
                        for (c, y) in sampled.iter_mut().zip(&y) {
                            *c += v * y;
                        }
                    }
                    let ya = basis.eval(axis);
                    for &n in &normals {
                        basis.eval_into(n, &mut y);
                        let (mut got, mut want) = (0.0, 0.0);
                        for l in 0..=MAX_ORDER as i32 {
                            let zonal = match cap {
                                None => clamped_cosine_band(l as u32),
                                Some(c0) => {
                                    (4.0 * PI / (2 * l + 1) as f64).sqrt() * cap_band(l, c0)
                                }
                            };
                            let a = clamped_cosine_band(l as u32);
                            for j in (l * l) as usize..((l + 1) * (l + 1)) as usize {
                                got += a * sampled[j] * y[j];
                                want += a * zonal * ya[j] * y[j];
                            }
                        }
                        error += (got - want).abs();
                        total += want.abs();
                    }
                }
                let share = error / total;
                eprintln!("map {m} ({s}²), {f}: mean irradiance error {share:.5}");
                assert!(share <= bound, "map {m} ({s}²), {f}: {share} > {bound}");
            }
        }
    }
}
