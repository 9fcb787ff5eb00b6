//! The GPU ray caster against a brute-force CPU twin that tests every ray against every
//! triangle with the same intersection, and honours the same cut-outs.

use std::sync::Arc;

use glam::Vec3;
use rayon::prelude::*;

use super::host::bounce_rate;
use super::query::RayQueries;
use super::surfaces::check_buffer_size;
use super::{RayFeatures, SceneRays, Triangles};
use crate::gi::bounces::converged_bounces;
use crate::gpu_layout::{RayHit, RayQuery, RAY_ANY, RAY_CLOSEST, RAY_NONE};
use crate::scene::testing::{shared_file, TempDir};
use crate::scene::{LoadOptions, Scene};
use crate::testing::{validating_context, Random};
use crate::vk::Context;

/// The scene's triangles as the CPU twin tests them, with their cut-out coverage.
struct Twin<'a> {
    scene: &'a Scene,
    triangles: Triangles,
    soa: Soa,
}

impl Twin<'_> {
    /// The GPU's Moeller-Trumbore, expression for expression.
    fn intersect(
        &self,
        i: usize,
        o: Vec3,
        d: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<(f32, f32, f32)> {
        let tri = &self.triangles.triangles[i];
        let v0 = Vec3::from_slice(&tri.v0[..3]);
        let e1 = Vec3::from_slice(&tri.e1[..3]);
        let e2 = Vec3::from_slice(&tri.e2[..3]);
        let p = d.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let s = o - v0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(e1);
        let v = d.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = e2.dot(q) * inv;
        (t > tmin && t < tmax).then_some((t, u, v))
    }

    /// Whether triangle `i` lets the ray through at (u, v): coverage (d x map_d, bilinear
    /// with wrap-around, as `texture_bilinear`; map_d alone where the material refracts)
    /// below one half.
    fn cut_out(&self, i: usize, u: f32, v: f32) -> bool {
        let tri = &self.triangles.triangles[i];
        if tri.e2[3].to_bits() & crate::gpu_layout::RAY_CUT_OUT == 0 {
            return false;
        }
        let material = &self.scene.materials[tri.v0[3].to_bits() as usize];
        let mut coverage = if material.refracts() {
            1.0
        } else {
            material.dissolve
        };
        if let Some(t) = material.coverage_texture {
            let s = &self.triangles.shading[i];
            let uv0 = [s.n0[3], s.n1[3]];
            let uv1 = [s.n2[3], s.uv[0]];
            let uv2 = [s.uv[1], s.uv[2]];
            let w = 1.0 - u - v;
            let uv = [0, 1].map(|k| uv0[k] * w + uv1[k] * u + uv2[k] * v);
            let texture = &self.scene.textures[t as usize];
            let (tw, th) = (texture.width as i32, texture.height as i32);
            let at = [uv[0] * tw as f32 - 0.5, uv[1] * th as f32 - 0.5];
            let base = at.map(|a| a.floor());
            let f = [at[0] - base[0], at[1] - base[1]];
            let mut sum = 0.0;
            for k in 0..4 {
                let (cx, cy) = (k & 1, k >> 1);
                let x = (base[0] as i32 + cx).rem_euclid(tw);
                let y = (base[1] as i32 + cy).rem_euclid(th);
                let texel = f32::from(texture.mips[0][((y * tw + x) * 4) as usize]) / 255.0;
                let wx = if cx == 0 { 1.0 - f[0] } else { f[0] };
                let wy = if cy == 0 { 1.0 - f[1] } else { f[1] };
                sum += wx * wy * texel;
            }
            coverage *= sum;
        }
        coverage < 0.5
    }

    /// The closest hit of every triangle, brute force: the intersection of every
    /// triangle computed in chunks without branches (so that it vectorizes), then the
    /// candidates nearer than the best so far, in order, checked with `intersect` itself
    /// and for their cut-outs.
    fn closest(&self, q: &RayQuery) -> RayHit {
        const CHUNK: usize = 1024;
        let o = Vec3::from_slice(&q.origin_tmin[..3]);
        let d = Vec3::from_slice(&q.direction_tmax[..3]);
        let tmin = q.origin_tmin[3];
        let mut best = RayHit {
            triangle: RAY_NONE,
            t: q.direction_tmax[3],
            u: 0.0,
            v: 0.0,
        };
        let s = &self.soa;
        let mut ts = [0.0f32; CHUNK];
        for start in (0..s.len()).step_by(CHUNK) {
            let end = (start + CHUNK).min(s.len());
            let range = start..end;
            for (k, t) in ts[..end - start].iter_mut().enumerate() {
                *t = s.distance(start + k, o, d, tmin);
            }
            for (k, &t) in ts[..end - start].iter().enumerate() {
                if t >= best.t {
                    continue;
                }
                let i = range.start + k;
                if let Some((t, u, v)) = self.intersect(i, o, d, tmin, best.t) {
                    if !self.cut_out(i, u, v) {
                        best = RayHit {
                            triangle: self.triangles.triangles[i].e1[3].to_bits(),
                            t,
                            u,
                            v,
                        };
                    }
                }
            }
        }
        best
    }
}

/// The triangles' vertex and edges, component by component.
#[derive(Default)]
struct Soa {
    v0: [Vec<f32>; 3],
    e1: [Vec<f32>; 3],
    e2: [Vec<f32>; 3],
}

impl Soa {
    fn of(triangles: &Triangles) -> Self {
        let mut soa = Self::default();
        for t in &triangles.triangles {
            for c in 0..3 {
                soa.v0[c].push(t.v0[c]);
                soa.e1[c].push(t.e1[c]);
                soa.e2[c].push(t.e2[c]);
            }
        }
        soa
    }

    fn len(&self) -> usize {
        self.v0[0].len()
    }

    /// The distance to triangle `i` along the ray (as `Twin::intersect`), infinity where
    /// the ray misses it; no branches.
    fn distance(&self, i: usize, o: Vec3, d: Vec3, tmin: f32) -> f32 {
        let v0 = Vec3::new(self.v0[0][i], self.v0[1][i], self.v0[2][i]);
        let e1 = Vec3::new(self.e1[0][i], self.e1[1][i], self.e1[2][i]);
        let e2 = Vec3::new(self.e2[0][i], self.e2[1][i], self.e2[2][i]);
        let p = d.cross(e2);
        let det = e1.dot(p);
        let inv = 1.0 / det;
        let s = o - v0;
        let u = s.dot(p) * inv;
        let q = s.cross(e1);
        let v = d.dot(q) * inv;
        let t = e2.dot(q) * inv;
        // `&`, not `&&`: no branch, so that the loop over triangles vectorizes.
        let inside =
            (det != 0.0) & (0.0..=1.0).contains(&u) & (v >= 0.0) & (u + v <= 1.0) & (t > tmin);
        if inside {
            t
        } else {
            f32::INFINITY
        }
    }
}

/// Casts `queries` on the GPU against `scene` at time 0.
fn gpu_hits(ctx: &Arc<Context>, scene: &Scene, queries: &[RayQuery]) -> Vec<RayHit> {
    let rays = SceneRays::new(ctx, scene, 1).unwrap();
    let mut pass = RayQueries::new(ctx, &rays, 65536).unwrap();
    pass.run(queries).unwrap()
}

fn query(o: Vec3, d: Vec3, kind: u32) -> RayQuery {
    RayQuery {
        origin_tmin: o.extend(0.0).to_array(),
        direction_tmax: d.normalize().extend(f32::MAX).to_array(),
        kind,
        ..Default::default()
    }
}

/// Compares the GPU's closest hits with the twin's: whether they hit, the distance within
/// 1e-4 relative, and the same triangle, or else a tie: the GPU's triangle is hit (and not
/// cut out) at the closest distance too, within that tolerance. Returns the rays that hit
/// something and the ties.
fn compare(
    what: &str,
    twin: &Twin,
    queries: &[RayQuery],
    gpu: &[RayHit],
    cpu: &[RayHit],
) -> (usize, usize) {
    let mut ties = 0;
    let mut hits = 0;
    for (i, ((q, g), c)) in queries.iter().zip(gpu).zip(cpu).enumerate() {
        assert_eq!(
            g.triangle == RAY_NONE,
            c.triangle == RAY_NONE,
            "{what} ray {i}: GPU {g:?}, CPU {c:?}"
        );
        if c.triangle == RAY_NONE {
            continue;
        }
        hits += 1;
        let close = |t: f32| (t - c.t).abs() <= 1e-4 * c.t.max(1e-6);
        assert!(close(g.t), "{what} ray {i}: GPU {g:?}, CPU {c:?}");
        if g.triangle != c.triangle {
            let o = Vec3::from_slice(&q.origin_tmin[..3]);
            let d = Vec3::from_slice(&q.direction_tmax[..3]);
            let j = g.triangle as usize;
            let tied = twin
                .intersect(j, o, d, q.origin_tmin[3], q.direction_tmax[3])
                .is_some_and(|(t, u, v)| close(t) && !twin.cut_out(j, u, v));
            assert!(tied, "{what} ray {i}: GPU {g:?} is no tie of CPU {c:?}");
            ties += 1;
        }
    }
    eprintln!("{what}: {hits} of {} rays hit, {ties} ties", gpu.len());
    (hits, ties)
}

/// Sponza, with 100,000 random rays through its bounds and 100,000 from the reference
/// camera: the GPU finds the closest triangle the brute-force twin does (or one tied with
/// it), at the same distance; and a hit exactly when any-hit queries see one.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn ray_caster_matches_brute_force_on_sponza() {
    let path = shared_file("reference/sponza_main.scene.json");
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    let bounds = scene.bounds(0.0);
    let mut random = Random(0x9e37_79b9_7f4a_7c15);
    let mut queries: Vec<RayQuery> = (0..100_000)
        .map(|_| {
            let o = bounds.min
                + (bounds.max - bounds.min)
                    * Vec3::new(random.unit(), random.unit(), random.unit());
            query(o, random.direction(), RAY_CLOSEST)
        })
        .collect();
    let camera = &scene.camera;
    let forward = (camera.target - camera.position).normalize();
    let right = forward.cross(camera.up).normalize();
    let up = right.cross(forward);
    let half = (camera.fov_y_deg.to_radians() * 0.5).tan();
    for _ in 0..100_000 {
        let (x, y) = (2.0 * random.unit() - 1.0, 2.0 * random.unit() - 1.0);
        let d = forward + right * (x * half) + up * (y * half);
        queries.push(query(camera.position, d, RAY_CLOSEST));
    }
    let ctx = validating_context();
    let gpu = gpu_hits(&ctx, &scene, &queries);
    let triangles = Triangles::of(&scene, 0.0, |_| true);
    let twin = Twin {
        scene: &scene,
        soa: Soa::of(&triangles),
        triangles,
    };
    let start = std::time::Instant::now();
    let cpu: Vec<RayHit> = queries.par_iter().map(|q| twin.closest(q)).collect();
    eprintln!(
        "brute force: {} rays x {} triangles in {:.1} s",
        queries.len(),
        twin.triangles.len(),
        start.elapsed().as_secs_f64()
    );
    let (random, camera) = queries.split_at(100_000);
    compare(
        "random rays",
        &twin,
        random,
        &gpu[..100_000],
        &cpu[..100_000],
    );
    let (hits, _) = compare(
        "camera rays",
        &twin,
        camera,
        &gpu[100_000..],
        &cpu[100_000..],
    );
    assert!(hits > 90_000, "the camera sees the scene");
    // Any hit: the same answer, blocked or clear, up to just short of the closest hit
    // and beyond it.
    let any: Vec<RayQuery> = queries[..20_000]
        .iter()
        .zip(&cpu)
        .flat_map(|(q, hit)| {
            let t = if hit.triangle == RAY_NONE { 1e3 } else { hit.t };
            [0.99 * t, 1.01 * t].map(|tmax| RayQuery {
                direction_tmax: [
                    q.direction_tmax[0],
                    q.direction_tmax[1],
                    q.direction_tmax[2],
                    tmax,
                ],
                kind: RAY_ANY,
                ..*q
            })
        })
        .collect();
    let blocked = gpu_hits(&ctx, &scene, &any);
    for (k, (answer, hit)) in blocked.chunks(2).zip(&cpu).enumerate() {
        let hits = hit.triangle != RAY_NONE;
        assert_eq!(
            answer[0].triangle, RAY_NONE,
            "any-hit ray {k} is blocked before its closest hit"
        );
        assert_eq!(answer[1].triangle != RAY_NONE, hits, "any-hit ray {k}");
    }
    assert_eq!(ctx.validation_messages(), 0);
}

/// A quad whose cut-out texture is transparent on its left half passes rays there and
/// stops them on its right half, for closest and any hits.
#[test]
fn cut_outs_pass_rays_where_coverage_is_below_one_half() {
    let dir = TempDir::new("ray_cutout");
    // Left columns alpha 0, right ones 255; rows alike.
    let image = image::RgbaImage::from_fn(8, 8, |x, _| {
        image::Rgba([255, 255, 255, if x < 4 { 0 } else { 255 }])
    });
    image.save(dir.0.join("leaf.png")).unwrap();
    dir.write("leaf.mtl", "newmtl leaf\nKd 0.5 0.5 0.5\nmap_d leaf.png\n");
    let path = dir.write(
        "leaf.obj",
        "mtllib leaf.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
         usemtl leaf\nf 1/1 2/2 3/3 4/4\n",
    );
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    let mut queries = Vec::new();
    for kind in [RAY_CLOSEST, RAY_ANY] {
        for x in [0.1, 0.3, 0.45, 0.55, 0.7, 0.9] {
            queries.push(query(Vec3::new(x, 0.5, 1.0), Vec3::NEG_Z, kind));
        }
    }
    let ctx = validating_context();
    let hits = gpu_hits(&ctx, &scene, &queries);
    for (q, hit) in queries.iter().zip(&hits) {
        let x = q.origin_tmin[0];
        assert_eq!(
            hit.triangle != RAY_NONE,
            x > 0.5,
            "ray at x = {x}, kind {}: {hit:?}",
            q.kind
        );
        if hit.triangle != RAY_NONE && q.kind == RAY_CLOSEST {
            assert!((hit.t - 1.0).abs() < 1e-6, "{hit:?}");
        }
    }
    assert_eq!(ctx.validation_messages(), 0);
}

/// The path tracer's and the ray caster's specialization follows the materials the meshes
/// use, under the switches that change them: none for a plain material beside others the
/// MTL defines and no mesh uses; each feature for the material that has it.
#[test]
fn features_follow_the_materials_the_meshes_use() {
    let dir = TempDir::new("ray_features");
    image::RgbaImage::from_pixel(2, 2, image::Rgba([128, 128, 255, 255]))
        .save(dir.0.join("t.png"))
        .unwrap();
    dir.write(
        "m.mtl",
        "newmtl plain\nKd 0.5 0.5 0.5\nnewmtl glossy\nKd 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 50\n\
         newmtl leaf\nKd 0.5 0.5 0.5\nmap_d t.png\nnewmtl veil\nKd 1 1 1\nd 0.3\n\
         newmtl glass\nKd 1 1 1\nd 0.3\nNi 1.5\nnewmtl painted\nKd 1 1 1\nmap_Kd t.png\n\
         newmtl bumpy\nKd 1 1 1\nnorm t.png\n",
    );
    let features = |materials: &[&str], options: &LoadOptions| {
        let mut obj = String::from("mtllib m.mtl\nvt 0 0\nvt 1 0\nvt 1 1\n");
        for (k, m) in materials.iter().enumerate() {
            let z = k as f32;
            obj += &format!("v 0 0 {z}\nv 1 0 {z}\nv 1 1 {z}\nusemtl {m}\n");
            obj += &format!("f {0}/1 {1}/2 {2}/3\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
        }
        let path = dir.write("m.obj", &obj);
        RayFeatures::of(&Scene::load(&path, options).unwrap())
    };
    let plain = LoadOptions::default();
    let none = RayFeatures::default();
    assert_eq!(features(&["plain"], &plain), none);
    let with = |f: fn(&mut RayFeatures)| {
        let mut r = none;
        f(&mut r);
        r
    };
    let cases: [(&str, RayFeatures); 6] = [
        ("glossy", with(|f| f.specular = true)),
        ("leaf", with(|f| f.cut_outs = true)),
        ("veil", with(|f| f.cut_outs = true)),
        ("glass", with(|f| f.transmission = true)),
        ("painted", with(|f| f.textures = true)),
        ("bumpy", with(|f| f.normal_maps = true)),
    ];
    for (material, expected) in cases {
        assert_eq!(
            features(&["plain", material], &plain),
            expected,
            "{material}"
        );
    }
    // The references' switches: Lambertian, no normal maps, the glass a straight mask.
    assert_eq!(
        features(&["glossy", "bumpy", "glass"], &LoadOptions::REFERENCE),
        with(|f| f.cut_outs = true)
    );
}

/// A scene whose buffers the device cannot bind is refused with the sizes named (a scene
/// with more triangles than a storage buffer's range holds is too slow to write and load
/// in a test, so the check is tested on its own).
#[test]
fn a_buffer_beyond_the_device_limit_is_refused_with_its_size() {
    let limit = 1u64 << 27;
    assert!(check_buffer_size("ray triangles", limit, limit, 16).is_ok());
    let error = check_buffer_size("ray triangles", limit + 16, limit, 16)
        .unwrap_err()
        .to_string();
    for part in [
        "ray triangles",
        "134217744 bytes",
        "134217728 bytes",
        "128.0 MiB",
        "maxTexelBufferElements",
    ] {
        assert!(error.contains(part), "{error:?} lacks {part:?}");
    }
}

/// The six faces of the cube from -`h` to `h` on each axis as OBJ text, its vertices
/// numbered from `first` (1-based); `open_front` leaves out the face at z = `h`.
fn cube_obj(h: f32, first: usize, material: &str, open_front: bool) -> String {
    let mut text = format!("usemtl {material}\n");
    for i in 0..8 {
        let at = |bit: usize| if i & bit != 0 { h } else { -h };
        text += &format!("v {} {} {}\n", at(1), at(2), at(4));
    }
    let faces: &[[usize; 4]] = &[
        [0, 2, 6, 4],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 3, 7, 6],
        [0, 1, 3, 2],
        [4, 5, 7, 6],
    ];
    for face in &faces[..if open_front { 5 } else { 6 }] {
        let [a, b, c, d] = face.map(|v| v + first);
        text += &format!("f {a} {b} {c} {d}\n");
    }
    text
}

/// [`bounce_rate`] of `obj` (materials `grey` 0.6, `white` 1, `black` 0) seen from
/// `position` towards the origin.
fn rate_of(obj: &str, position: Vec3) -> f32 {
    let dir = TempDir::new("bounce_rate");
    dir.write(
        "box.mtl",
        "newmtl grey\nKd 0.6 0.6 0.6\nnewmtl white\nKd 1 1 1\nnewmtl black\nKd 0 0 0\n",
    );
    dir.write("box.obj", &format!("mtllib box.mtl\n{obj}"));
    let scene = dir.write(
        "box.toml",
        &format!(
            "[camera]\nposition = [{}, {}, {}]\ntarget = [0, 0, 0]\nfov_y_deg = 60\n\
             [[mesh]]\npath = \"box.obj\"\n",
            position.x, position.y, position.z
        ),
    );
    bounce_rate(&Scene::load(&scene, &LoadOptions::default()).unwrap())
}

/// What a bounce passes on, measured along the camera's walks, against the cases whose
/// answer is known: a closed box of albedo 0.6 passes on 0.6 (every ray meets a wall); a
/// white plane under the sky nothing (every ray from it escapes); a white cube in a black
/// box nothing (its light meets only black, and the cube's inside, which no walk reaches,
/// does not count though it would pass on all); the grey box open at the front, seen from
/// outside, less than closed, more than half of it (a face's share of a cube's inside is
/// 0.2).
#[test]
fn bounce_rate_is_the_albedo_in_a_closed_box_and_nothing_in_the_open() {
    let closed = rate_of(&cube_obj(1.0, 1, "grey", false), Vec3::new(0.2, 0.1, 0.5));
    assert!((closed - 0.6).abs() < 0.005, "closed box {closed}");
    let plane = rate_of(
        "usemtl white\nv -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\nf 1 2 3 4\n",
        Vec3::new(0.0, 2.0, 0.1),
    );
    assert_eq!(plane, 0.0, "open plane");
    let cube_in_black = rate_of(
        &(cube_obj(2.0, 1, "black", false) + &cube_obj(0.3, 9, "white", false)),
        Vec3::new(0.3, 0.4, 1.5),
    );
    assert_eq!(cube_in_black, 0.0, "white cube in a black box");
    let open = rate_of(&cube_obj(1.0, 1, "grey", true), Vec3::new(0.1, 0.2, 3.0));
    eprintln!(
        "bounce rate: closed box {closed:.4}, plane {plane}, white cube in black \
         {cube_in_black}, open box {open:.4}"
    );
    assert!(open > 0.3 && open < 0.57, "open box {open}");
    assert_eq!(converged_bounces(plane), 1);
    assert_eq!(converged_bounces(closed), 10);
}
