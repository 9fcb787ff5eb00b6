//! The bake's phases on the built-in Cornell box, against invariants measured
//! independently of the code that made them.

use glam::{Vec2, Vec3};

use super::lightmap::Lightmap;
use super::placement::Probes;
use super::receivers::{Receivers, NO_RECEIVER};
use crate::scene::testing::{error_text, TempDir};
use crate::scene::{LoadOptions, Scene};

fn cornell() -> Scene {
    Scene::load(&crate::cli::default_scene(), &LoadOptions::default()).unwrap()
}

/// The world corners of every static triangle, with its mesh and triangle index.
fn triangles(scene: &Scene) -> Vec<(usize, usize, [Vec3; 3])> {
    let mut out = Vec::new();
    for (m, mesh) in scene.meshes.iter().enumerate() {
        for (t, tri) in mesh.indices.chunks_exact(3).enumerate() {
            let p = |k: usize| {
                mesh.transform
                    .transform_point3(Vec3::from(mesh.vertices[tri[k] as usize].position))
            };
            out.push((m, t, [p(0), p(1), p(2)]));
        }
    }
    out
}

/// Every texel centre inside a triangle is one receiver: on planar charts their count is
/// the surface's area times the density squared (to the texels cut by the charts'
/// edges), and no texel is claimed by two places on the surfaces.
#[test]
fn receivers_cover_the_surface_at_the_atlas_density() {
    let scene = cornell();
    let lightmap = Lightmap::generate(&scene, 256).unwrap();
    let receivers = Receivers::place(&scene, &lightmap);
    let area: f32 = triangles(&scene)
        .iter()
        .map(|(_, _, [a, b, c])| 0.5 * (*b - *a).cross(*c - *a).length())
        .sum();
    let expected = area * lightmap.texels_per_unit.powi(2);
    let inside = receivers.inside() as f32;
    eprintln!(
        "{} charts, {} × {} texels, {:.2} texels per unit: {inside} receivers inside, \
         area × density² {expected:.0}, {} on the borders",
        lightmap.charts,
        lightmap.width,
        lightmap.height,
        lightmap.texels_per_unit,
        receivers.list.len() - receivers.inside()
    );
    assert_eq!(receivers.overlaps, 0, "charts overlap");
    assert!(
        (inside / expected - 1.0).abs() < 0.03,
        "{inside} receivers inside the charts, expected {expected:.0}"
    );
    for r in &receivers.list {
        assert!((r.normal.length() - 1.0).abs() < 1e-4);
        let i = (r.texel[1] * lightmap.width + r.texel[0]) as usize;
        assert_eq!(receivers.list[receivers.index[i] as usize], *r);
    }
}

/// The bilinear lookup of any point on a static surface reads four texels that are all
/// receivers, each within a texel and a half (in the lightmap) of the point, and at a
/// world distance the texel's footprint allows.
#[test]
fn every_bilinear_lookup_reads_receivers() {
    let scene = cornell();
    let lightmap = Lightmap::generate(&scene, 128).unwrap();
    let receivers = Receivers::place(&scene, &lightmap);
    let size = Vec2::new(lightmap.width as f32, lightmap.height as f32);
    let texel_world = 1.0 / lightmap.texels_per_unit;
    let mut lookups = 0;
    for (m, t, corners) in triangles(&scene) {
        let uv = |k: usize| Vec2::from(lightmap.corners[m][3 * t + k]) * size;
        // A lattice of points over the triangle, its corners and edges included.
        let n = 12;
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                let p = uv(0) + (uv(1) - uv(0)) * u + (uv(2) - uv(0)) * v;
                let world =
                    corners[0] + (corners[1] - corners[0]) * u + (corners[2] - corners[0]) * v;
                let base = (p - 0.5).floor();
                for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                    let texel = base + Vec2::new(dx, dy);
                    let (x, y) = (texel.x as i64, texel.y as i64);
                    assert!(
                        x >= 0 && y >= 0 && x < size.x as i64 && y < size.y as i64,
                        "lookup outside the lightmap"
                    );
                    let r = receivers.index[(y as u32 * lightmap.width + x as u32) as usize];
                    assert_ne!(r, NO_RECEIVER, "texel {x}, {y} of mesh {m} has no receiver");
                    let r = &receivers.list[r as usize];
                    let d = r.position.distance(world);
                    assert!(
                        d <= 2.0 * texel_world,
                        "a lookup of mesh {m} reads a receiver {d} away ({texel_world} a texel)"
                    );
                    lookups += 1;
                }
            }
        }
    }
    eprintln!("{lookups} texel reads, all receivers nearby");
}

/// Möller–Trumbore: the distance along `dir` to the triangle, and whether its winding
/// faces the ray's origin.
fn hit(origin: Vec3, dir: Vec3, [a, b, c]: [Vec3; 3]) -> Option<(f32, bool)> {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-9 {
        return None;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = dir.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 1e-5).then_some((t, e1.cross(e2).dot(dir) < 0.0))
}

/// The desired number of probes, all in the room's free space: every ray from a probe
/// first meets a surface from its front, or leaves through the open side; and the radius
/// gives a typical receiver close to N_OVERLAPS probes.
#[test]
fn probes_lie_in_free_space_and_support_every_receiver() {
    let scene = cornell();
    let lightmap = Lightmap::generate(&scene, 128).unwrap();
    let receivers = Receivers::place(&scene, &lightmap);
    let probes = Probes::place(&scene, &receivers.list, 64, 10).unwrap();
    assert_eq!(
        probes.positions.len(),
        64,
        "{} candidates",
        probes.candidates
    );
    let tris = triangles(&scene);
    let directions = super::sh::sphere_directions(256);
    for p in &probes.positions {
        for d in &directions {
            let first = tris
                .iter()
                .filter_map(|(_, _, t)| hit(*p, *d, *t))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((_, front)) = first {
                assert!(front, "probe {p} sees the back of a surface along {d}");
            }
        }
    }
    let support: Vec<usize> = receivers
        .list
        .iter()
        .map(|r| probes.support(r.position, 10).len())
        .collect();
    let mean = support.iter().sum::<usize>() as f64 / support.len() as f64;
    eprintln!(
        "{} candidates, radius {:.3}, spacing {:.3}, mean support {mean:.2}",
        probes.candidates, probes.radius, probes.spacing
    );
    assert!(support.iter().all(|&n| n > 0), "a receiver without probes");
    assert!((7.0..=10.0).contains(&mean), "mean support {mean}");
}

/// The thinning keeps the probes apart: on a dense lattice of candidates, no two kept
/// probes are closer than half the spacing, and every candidate lies within 1.5 spacings
/// of a kept probe (a cubic lattice of the same density covers within 0.87; the greedy
/// rule keeps the sparse edges' candidates first and leaves corners a little farther).
#[test]
fn thinning_spreads_the_probes_evenly() {
    let mut candidates = Vec::new();
    for z in 0..12 {
        for y in 0..12 {
            for x in 0..12 {
                candidates.push(Vec3::new(x as f32, y as f32, z as f32) * 0.25);
            }
        }
    }
    let spacing = (3.0f32 * 3.0 * 3.0 / 27.0).cbrt();
    let kept = super::placement::thin(&candidates, 27, spacing);
    assert_eq!(kept.len(), 27);
    let mut closest_pair = f32::MAX;
    for (i, a) in kept.iter().enumerate() {
        for b in &kept[i + 1..] {
            closest_pair = closest_pair.min(a.distance(*b));
        }
    }
    let farthest = candidates
        .iter()
        .map(|c| kept.iter().map(|k| k.distance(*c)).fold(f32::MAX, f32::min))
        .fold(0.0, f32::max);
    eprintln!(
        "closest pair {closest_pair:.3}, farthest candidate {farthest:.3}, spacing {spacing:.3}"
    );
    assert!(
        closest_pair >= 0.5 * spacing,
        "two probes {closest_pair} apart"
    );
    assert!(
        farthest <= 1.5 * spacing,
        "a candidate {farthest} from every probe"
    );
}

#[test]
fn a_scene_without_free_space_or_static_triangles_says_so() {
    let dir = TempDir::new("probes");
    // A closed box whose faces all point outwards: inside it every cell lies behind them.
    let obj =
        "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
        f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
    dir.write("box.obj", obj);
    let scene = Scene::load(&dir.0.join("box.obj"), &LoadOptions::default()).unwrap();
    let lightmap = Lightmap::generate(&scene, 64).unwrap();
    let receivers = Receivers::place(&scene, &lightmap);
    let text = error_text(Probes::place(&scene, &receivers.list, 16, 4));
    assert!(text.contains("no free space"), "{text}");

    let moving = dir.write(
        "moving.toml",
        "[[mesh]]\npath = \"box.obj\"\nanimate = { kind = \"spin\", axis = [0, 1, 0], deg_per_s = 45.0 }\n",
    );
    let scene = Scene::load(&moving, &LoadOptions::default()).unwrap();
    let text = error_text(Lightmap::generate(&scene, 64));
    assert!(text.contains("no static triangles"), "{text}");
}
