//! The bake's phases on the built-in Cornell box, against invariants measured
//! independently of the code that made them.

use glam::{Vec2, Vec3};

use super::lightmap::Lightmap;
use super::placement::Probes;
use super::receivers::{Receivers, NO_RECEIVER};
use crate::scene::testing::{error_text, TempDir};
use crate::scene::{LoadOptions, Scene};
use crate::testing::validating_context;

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
    let probes = Probes::place(
        &scene,
        &crate::ray::host::HostRays::of_static(&scene),
        &receivers.list,
        64,
        10,
    )
    .unwrap();
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
    let text = error_text(Probes::place(
        &scene,
        &crate::ray::host::HostRays::of_static(&scene),
        &receivers.list,
        16,
        4,
    ));
    assert!(text.contains("no free space"), "{text}");

    let moving = dir.write(
        "moving.toml",
        "[[mesh]]\npath = \"box.obj\"\nanimate = { kind = \"spin\", axis = [0, 1, 0], deg_per_s = 45.0 }\n",
    );
    let scene = Scene::load(&moving, &LoadOptions::default()).unwrap();
    let text = error_text(Lightmap::generate(&scene, 64));
    assert!(text.contains("no static triangles"), "{text}");
}

/// The bake of `scene` up to the transport, with the probes' λ from emission and sky.
struct Baked {
    scene: Scene,
    receivers: Receivers,
    probes: Probes,
    transport: super::transport::Transport,
    lambda: Vec<Vec3>,
}

fn bake_transport(
    ctx: &std::sync::Arc<crate::vk::Context>,
    scene: &Scene,
    size: u32,
    probes: u32,
    rays: usize,
) -> Baked {
    let scene = super::static_scene(scene);
    let lightmap = Lightmap::generate(&scene, size).unwrap();
    let mut receivers = Receivers::place(&scene, &lightmap);
    let host = crate::ray::host::HostRays::of_static(&scene);
    let offset = 1e-4 * super::placement::static_bounds(&scene).diagonal();
    receivers.shift_out_of_geometry(&host, 32, offset);
    let probes = Probes::place(&scene, &host, &receivers.list, probes, 8).unwrap();
    let scene_rays = crate::ray::SceneRays::new(ctx, &scene, 1).unwrap();
    let mut queries = crate::ray::query::RayQueries::new(ctx, &scene_rays, 1 << 16).unwrap();
    let triangles = crate::ray::Triangles::of(&scene, 0.0, |_| true);
    let views = super::casting::ProbeViews::cast(&mut queries, &probes.positions, 32).unwrap();
    let settings = super::transport::TransportSettings {
        order: 3,
        rays,
        overlaps: 8,
        offset,
    };
    let transport = super::transport::Transport::compute(
        &mut queries,
        &triangles,
        &receivers.list,
        &probes,
        &views,
        &settings,
    )
    .unwrap();
    let relight = super::casting::RelightRays::cast(&mut queries, &probes.positions, 32).unwrap();
    let basis = super::sh::Basis::new(3);
    let lambda = super::relight::emitted_lambda(
        &scene,
        &triangles,
        &relight,
        probes.positions.len(),
        &basis,
    );
    assert_eq!(ctx.validation_messages(), 0, "validation messages");
    Baked {
        scene,
        receivers,
        probes,
        transport,
        lambda,
    }
}

/// Furnace: inside a closed box whose walls emit radiance L (and reflect nothing), every
/// receiver's irradiance is π L: within 5 % at each (the bound).
#[test]
fn furnace_gives_every_receiver_the_walls_irradiance() {
    let ctx = validating_context();
    let dir = TempDir::new("probe_furnace");
    dir.write("box.mtl", "newmtl wall\nKd 0 0 0\nKe 0.5 0.5 0.5\n");
    let obj = "mtllib box.mtl\n\
        v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
        usemtl wall\nf 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n";
    let path = dir.write("box.obj", obj);
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    let baked = bake_transport(&ctx, &scene, 64, 27, 64);
    let expected = std::f32::consts::PI * 0.5;
    let mut worst = 0.0f32;
    for r in 0..baked.receivers.list.len() {
        let e = super::relight::irradiance(&baked.transport, &baked.lambda, baked.scene.sky, r);
        worst = worst.max((e.x / expected - 1.0).abs());
    }
    eprintln!(
        "furnace: {} receivers, {} probes, worst {:.2} %, unseen hits {} of {}",
        baked.receivers.list.len(),
        baked.probes.positions.len(),
        100.0 * worst,
        baked.transport.unseen,
        baked.transport.hits
    );
    assert!(worst <= 0.05, "a receiver {:.2} % off π L", 100.0 * worst);
}

/// The built-in box with every material glowing in a colour of its own (and reflecting
/// nothing): a radiance field that varies with direction and visibility.
fn glowing_cornell(dir: &TempDir) -> Scene {
    std::fs::copy(
        crate::cli::default_scene().with_file_name("cornell.obj"),
        dir.0.join("cornell.obj"),
    )
    .unwrap();
    dir.write(
        "cornell.mtl",
        "newmtl white\nKd 0 0 0\nKe 0.3 0.3 0.3\nnewmtl red\nKd 0 0 0\nKe 0.9 0.1 0.1\n\
         newmtl green\nKd 0 0 0\nKe 0.1 0.8 0.1\nnewmtl block\nKd 0 0 0\nKe 0.2 0.2 0.6\n\
         newmtl light\nKd 0 0 0\nKe 2 2 2\n",
    );
    Scene::load(&dir.0.join("cornell.obj"), &LoadOptions::default()).unwrap()
}

/// The clustered PCA against the transport it compresses: every cluster meets the
/// projection bound (or is too small to split), and the receivers' irradiance through
/// the clusters stays within 1 % (relative L1) of the full transport's; with no bound
/// and every vector kept, within float rounding.
#[test]
fn clustered_transport_reconstructs_the_irradiance() {
    use super::clusters::{ClusterSettings, Clusters};
    let ctx = validating_context();
    let dir = TempDir::new("probe_clusters");
    let baked = bake_transport(&ctx, &glowing_cornell(&dir), 64, 64, 64);
    let settings = ClusterSettings::default();
    let exact = ClusterSettings {
        max_error: 1e-9,
        max_basis: usize::MAX,
        ..settings
    };
    for (what, settings, bound) in [("default", settings, 0.01), ("every vector", exact, 1e-5)] {
        let clusters = Clusters::build(&baked.receivers.list, &baked.transport, &settings);
        let (mut difference, mut total) = (0.0f64, 0.0f64);
        for r in 0..baked.receivers.list.len() {
            let full = super::relight::irradiance(&baked.transport, &baked.lambda, Vec3::ZERO, r);
            let ours = clusters.irradiance(&baked.transport, &baked.lambda, Vec3::ZERO, r);
            difference += (ours - full).abs().element_sum() as f64;
            total += full.abs().element_sum() as f64;
        }
        let error = difference / total;
        let basis: usize = clusters.list.iter().map(|c| c.basis).sum();
        eprintln!(
            "{what}: {} receivers in {} clusters, {:.1} vectors each, transport error {:.4}, \
             irradiance error {:.5}",
            baked.receivers.list.len(),
            clusters.list.len(),
            basis as f64 / clusters.list.len() as f64,
            (clusters.residual / clusters.energy).sqrt(),
            error
        );
        assert!(error <= bound, "{what}: irradiance error {error}");
    }
}

/// The transport coefficients against a brute-force gather: many rays from the receiver
/// cast on the host (another ray caster), the radiance at each hit reconstructed from
/// the same probes' harmonics with the same visibility weights. The walls of the built-in
/// box glow in colours of their own, so the field varies with direction and visibility.
#[test]
fn transport_matches_a_brute_force_gather() {
    let ctx = validating_context();
    let dir = TempDir::new("probe_alpha");
    let baked = bake_transport(&ctx, &glowing_cornell(&dir), 64, 64, 64);
    let host = crate::ray::host::HostRays::of_static(&baked.scene);
    let basis = super::sh::Basis::new(3);
    let n = basis.count();
    let pattern = super::casting::cosine_directions(4096);
    let mut y = vec![0.0f64; n];
    let (mut sum_error, mut sum, mut count) = (0.0f64, 0.0f64, 0);
    for (i, r) in baked.receivers.list.iter().enumerate().step_by(97) {
        let ours = super::relight::irradiance(&baked.transport, &baked.lambda, Vec3::ZERO, i);
        let range = baked.transport.offsets[i] as usize..baked.transport.offsets[i + 1] as usize;
        let origin = r.position + r.normal * 1e-4;
        let mut e = 0.0f64;
        for d in super::casting::oriented(&pattern, r.normal, 0.0) {
            let Some(hit) = host.closest(origin, d, 0.0) else {
                continue;
            };
            let point = origin + d * hit.t;
            // The same weights as the transport's, with every supporting probe seeing the
            // point from the side it is seen (the box is convex but for the blocks).
            let (mut radiance, mut total) = (0.0f64, 0.0f64);
            for k in range.clone() {
                let p = baked.transport.probes[k] as usize;
                let offset = point - baked.probes.positions[p];
                let towards = offset.normalize();
                let w = super::placement::kernel(
                    r.position.distance(baked.probes.positions[p]) / baked.probes.radius,
                ) as f64;
                let back = host.closest(baked.probes.positions[p], towards, 0.0);
                let visible = back.is_some_and(|b| {
                    b.front == hit.front && (b.t - offset.length()).abs() <= 1e-3 * offset.length()
                });
                if !visible {
                    continue;
                }
                basis.eval_into(towards, &mut y);
                let l: f64 = (0..n)
                    .map(|j| baked.lambda[p * n + j].x as f64 * y[j])
                    .sum();
                radiance += w * l;
                total += w;
            }
            if total > 0.0 {
                e += radiance / total;
            }
        }
        e *= std::f64::consts::PI / pattern.len() as f64;
        sum_error += (ours.x as f64 - e).abs();
        sum += e;
        count += 1;
    }
    // Relative to the mean: a receiver on the floor under a block sees only the block's
    // inside, which no probe sees (the brute force gives it 0; the thesis shifts such
    // receivers out, 5.1.4).
    let error = sum_error / sum;
    eprintln!(
        "{count} receivers: Σ |ours − brute force| / Σ brute force {:.2} %",
        100.0 * error
    );
    assert!(error <= 0.03, "error {:.2} %", 100.0 * error);
}

/// The bake file: a second bake reads what the first wrote, bit for bit; a truncated,
/// damaged, older or other scene's file is not used, with the reason, and baked again.
#[test]
fn bake_file_round_trips_and_rejects_damage() {
    use super::{load_or_bake, BakeSettings, Origin};
    let ctx = validating_context();
    let dir = TempDir::new("bake_file");
    let scene = cornell();
    let settings = BakeSettings {
        lightmap_size: 64,
        probes: 32,
        overlaps: 8,
        probe_side: 16,
        receiver_rays: 16,
        sh_order: 2,
        ..BakeSettings::default()
    };
    let path = dir.0.join("cornell.bake");
    let bake =
        |settings: &BakeSettings| load_or_bake(&ctx, &scene, settings, &path, false, None).unwrap();
    let first = bake(&settings);
    assert_eq!(first.origin, Origin::Computed(None));
    let second = bake(&settings);
    assert_eq!(second.origin, Origin::Cached);
    assert!(
        second.data == first.data,
        "the file does not give back what was baked"
    );
    assert_eq!(second.report, first.report);

    let bytes = std::fs::read(&path).unwrap();
    let reason = |origin: Origin| match origin {
        Origin::Computed(Some(why)) => why,
        other => panic!("expected a rebake with a reason, got {other:?}"),
    };
    std::fs::write(&path, &bytes[..bytes.len() - 100]).unwrap();
    let why = reason(bake(&settings).origin);
    assert!(why.contains("truncated"), "{why}");
    let mut damaged = bytes.clone();
    let middle = damaged.len() / 2;
    damaged[middle] ^= 0x40;
    std::fs::write(&path, &damaged).unwrap();
    let why = reason(bake(&settings).origin);
    assert!(why.contains("damaged"), "{why}");
    let mut older = bytes.clone();
    older[8..12].copy_from_slice(&0u32.to_le_bytes());
    std::fs::write(&path, &older).unwrap();
    let why = reason(bake(&settings).origin);
    assert!(why.contains("bake format 0"), "{why}");
    std::fs::write(&path, b"not a bake").unwrap();
    let why = reason(bake(&settings).origin);
    assert!(why.contains("not a voxcone bake"), "{why}");
    // Other settings under the same name: another key.
    let why = reason(
        bake(&BakeSettings {
            probes: 27,
            ..settings
        })
        .origin,
    );
    assert!(
        why.contains("another version of the scene or other settings"),
        "{why}"
    );
    assert_eq!(
        bake(&BakeSettings {
            probes: 27,
            ..settings
        })
        .origin,
        Origin::Cached
    );
}

/// Receivers inside geometry move out of it (5.1.4): on the built-in box, every floor
/// receiver under a block (a ray along its normal meets the block's top from inside)
/// moves, and from where it goes that ray no longer meets a back face; the walls'
/// receivers, in the open, stay put.
#[test]
fn receivers_inside_geometry_move_out() {
    let scene = cornell();
    let lightmap = Lightmap::generate(&scene, 128).unwrap();
    let mut receivers = Receivers::place(&scene, &lightmap);
    let before = receivers.list.clone();
    let host = crate::ray::host::HostRays::of_static(&scene);
    let offset = 1e-4 * super::placement::static_bounds(&scene).diagonal();
    // On the floor, and the block's top seen from inside straight above (the ceiling's
    // texels above the one-sided light see its back too, but the rest of the room
    // besides, and stay).
    let inside = |r: &super::receivers::Receiver| {
        r.normal.y > 0.99
            && r.position.y < 0.01
            && host
                .closest(r.position + r.normal * offset, r.normal, 0.0)
                .is_some_and(|h| !h.front)
    };
    let buried = before.iter().filter(|r| inside(r)).count();
    let moved = receivers.shift_out_of_geometry(&host, 32, offset);
    eprintln!("{buried} receivers inside the blocks, {moved} moved");
    assert!(buried > 0, "no receiver under a block to test");
    for (old, new) in before.iter().zip(&receivers.list) {
        if inside(old) {
            assert_ne!(old.position, new.position, "{old:?} stayed inside");
            assert!(!inside(new), "{old:?} moved to {new:?}, still inside");
        } else if old.inside && old.normal.y.abs() < 0.01 && old.position.y > 0.01 {
            // The room's walls touch nothing (the ceiling's texels above the light,
            // which covers most of their hemisphere 0.02 below, move under it).
            let wall = old.position.x.abs() > 0.999 || old.position.z < -0.999;
            if wall {
                assert_eq!(old.position, new.position, "{old:?} moved from the open");
            }
        }
    }
}

/// One frame of `--gi probes` with `settings` on `scene` (64 × 64), validation clean.
fn render_probes(
    scene: &Scene,
    settings: &super::frame::ProbeSettings,
) -> (
    std::sync::Arc<crate::vk::Context>,
    crate::renderer::Renderer,
) {
    let render = crate::settings::RenderSettings {
        gi: crate::gi::GiSettings::Probes(settings.clone()),
        ..Default::default()
    };
    let (ctx, renderer) = crate::testing::render_frames(scene.clone(), render, &[0.0]);
    assert_eq!(ctx.validation_messages(), 0);
    (ctx, renderer)
}

/// The RGB of each texel of mip `level` of the probes' half-float `image` (a lightmap or
/// the grid), row by row (slice by slice).
fn read_rgb(
    ctx: &std::sync::Arc<crate::vk::Context>,
    image: &crate::vk::Image,
    level: usize,
) -> Vec<Vec3> {
    let e = image.desc.extent;
    let (width, height) = super::levels::mip_size(e.width, e.height, level);
    let extent = ash::vk::Extent3D {
        width,
        height,
        depth: e.depth,
    };
    let bytes = crate::vk::read_back_image(
        ctx,
        image,
        level as u32,
        extent,
        8,
        super::frame::LIGHTMAP_USE,
    )
    .unwrap();
    bytes
        .chunks_exact(8)
        .map(|t| {
            let c = |i: usize| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32();
            Vec3::new(c(0), c(1), c(2))
        })
        .collect()
}

/// The irradiance of receiver `r` from the bake's clusters, given the probes' `lambda`
/// and the sky's radiance: the host twin of `probe_basis` and `probe_receivers`.
fn reconstructed(data: &super::file::BakeData, lambda: &[Vec3], sky: Vec3, r: usize) -> Vec3 {
    let n = super::sh::coefficient_count(data.sh_order);
    let c = data.receiver_clusters[r] as usize;
    let probes = &data.cluster_probes
        [data.cluster_probe_starts[c] as usize..data.cluster_probe_starts[c + 1] as usize];
    let width = probes.len() * n;
    let mut e = sky * data.receiver_sky[r];
    for i in 0..data.cluster_basis[c] as usize {
        let row =
            &data.projections[data.cluster_projection_starts[c] as usize + i * width..][..width];
        let mut b = Vec3::ZERO;
        for (k, &p) in probes.iter().enumerate() {
            for j in 0..n {
                b += lambda[p as usize * n + j] * row[k * n + j];
            }
        }
        e += b * data.coordinates[data.receiver_offsets[r] as usize + i];
    }
    e
}

/// The host twin tests' settings: a small bake into `dir`, one bounce, and the level of
/// detail with levels from `lod_distances` (`None`: off).
fn twin_settings(dir: &TempDir, lod_distances: Option<[f32; 3]>) -> super::frame::ProbeSettings {
    super::frame::ProbeSettings {
        bake: super::BakeSettings {
            lightmap_size: 64,
            probes: 32,
            overlaps: 8,
            probe_side: 32,
            receiver_rays: 32,
            sh_order: 3,
            ..super::BakeSettings::default()
        },
        bake_file: Some(dir.0.join("box.bake")),
        bounces: 1,
        converge_bounces: false,
        lod: lod_distances.is_some(),
        lod_distances,
    }
}

/// The bake `settings` made of `scene`, and its probes' λ as the host computes them
/// from the emission and the sky their rays meet.
fn host_lambda(
    scene: &Scene,
    settings: &super::frame::ProbeSettings,
) -> (super::file::BakeData, Vec<Vec3>) {
    let key = super::file::content_key(scene, &settings.bake);
    let data = super::file::BakeData::read(settings.bake_file.as_ref().unwrap(), key).unwrap();
    let statics = super::static_scene(scene);
    let triangles = crate::ray::Triangles::of(&statics, 0.0, |_| true);
    let relight = super::casting::RelightRays {
        side: data.relight_side as usize,
        hits: data.relight_hits.clone(),
    };
    let basis = super::sh::Basis::new(data.sh_order);
    let lambda =
        super::relight::emitted_lambda(&statics, &triangles, &relight, data.probes.len(), &basis);
    (data, lambda)
}

/// The glowing box with no lights under a coloured sky, rendered with `--gi probes` and
/// no bounces: the lightmap the GPU's relight, projection, basis and receivers passes
/// write holds every receiver's irradiance / π as the host computes it from the same
/// bake (the emission and sky each probe ray meets, projected onto the harmonics,
/// through the clusters), within the lightmap's half-float rounding. With a small moving
/// copy of the tall block in the room, the grid holds the same for the spatial receivers
/// of the points around it, and nothing (its clear) everywhere else.
#[test]
fn the_frames_lightmap_and_grid_match_the_host_twin() {
    use super::frame::ProbeGi;
    let dir = TempDir::new("probe_frame_twin");
    let mut scene = glowing_cornell(&dir);
    scene.lights.clear();
    scene.sky = Vec3::new(0.2, 0.4, 0.8);
    let mut moving = scene.meshes[scene.meshes.len() - 1].clone();
    let centre = moving.local_bounds.center();
    moving.transform = glam::Mat4::from_translation(Vec3::new(0.3, 1.2, 0.4))
        * glam::Mat4::from_scale(Vec3::splat(0.3))
        * glam::Mat4::from_translation(-centre);
    moving.animation = Some(crate::scene::Animation::Spin {
        axis: Vec3::Y,
        deg_per_s: 10.0,
    });
    scene.triangle_count += moving.indices.len() / 3;
    scene.meshes.push(moving);
    let settings = twin_settings(&dir, None);
    let (ctx, renderer) = render_probes(&scene, &settings);
    let probes: &ProbeGi = renderer.gi_as().unwrap();
    let w = probes.lightmap_size()[0];
    let lightmap = read_rgb(&ctx, probes.lightmap(), 0);
    let (data, lambda) = host_lambda(&scene, &settings);
    let (mut worst, mut total) = (0.0f32, 0.0f32);
    for r in 0..data.receiver_texels.len() {
        let expected = reconstructed(&data, &lambda, scene.sky, r) / std::f32::consts::PI;
        let [x, y] = data.receiver_texels[r];
        let got = lightmap[(y * w + x) as usize];
        let error = (got - expected).abs().max_element() / expected.max_element().max(1e-3);
        worst = worst.max(error);
        total += expected.max_element();
    }
    eprintln!(
        "{} receivers, mean irradiance / π {:.3}, worst relative difference {:.4}",
        data.receiver_texels.len(),
        total / data.receiver_texels.len() as f32,
        worst
    );
    assert!(
        worst < 0.005,
        "a receiver's texel is {:.2} % off the host's",
        100.0 * worst
    );
    let values = read_rgb(&ctx, probes.grid(), 0);
    let [min, max] = data.grid_bounds.map(Vec3::from);
    let grid = super::grid::Grid {
        size: glam::UVec3::from_array(data.grid_size),
        min,
        max,
    };
    let m = scene.meshes.len() - 1;
    let bounds = scene.meshes[m]
        .local_bounds
        .transformed(scene.mesh_transform(m, 0.0));
    let active: Vec<usize> = grid.points_in(grid.footprint(&bounds).unwrap()).collect();
    let points = grid.point_count();
    assert!(
        !active.is_empty() && active.len() < points / 4,
        "{} of {points} points around the moving block",
        active.len()
    );
    let (mut worst, mut zero) = (0.0f32, true);
    for d in 0..6 {
        for p in 0..points {
            let got = values[d * points + p];
            if active.contains(&p) {
                let r = data.receiver_texels.len() + d * points + p;
                let expected = reconstructed(&data, &lambda, scene.sky, r) / std::f32::consts::PI;
                let error = (got - expected).abs().max_element() / expected.max_element().max(1e-3);
                worst = worst.max(error);
            } else {
                zero &= got == Vec3::ZERO;
            }
        }
    }
    eprintln!(
        "grid {:?}: {} of {points} points computed, worst relative difference {worst:.4}",
        grid.size,
        active.len()
    );
    assert!(
        worst < 0.005,
        "a spatial receiver is {:.2} % off the host's",
        100.0 * worst
    );
    assert!(zero, "the grid was computed away from the moving mesh");
}

/// The lightmap's levels (Sedláček 2019, 4.2.3) with the level of detail on, in the
/// glowing box of the host twin's test (one frame, one bounce, every receiver's irradiance
/// above zero) with levels 1 to 3 beginning 3.6, 4.2 and 4.8 from the camera: every texel
/// that a lookup from a surface can read at its cluster's level or coarser (the 3 × 3
/// texels around the surface's own at each such level) was written this frame (the
/// lightmap starts cleared to zero) with the irradiance its receiver's own texel holds,
/// and the receivers of clusters at level 0 (all bands, all rays) hold the host twin's,
/// though the frame computes only part of the receivers. (Farther clusters read fewer
/// bands of probes relit from fewer rays: the twin, with all of them, is no reference
/// there.) Once with the scene's camera, which sees the whole box, and once with it
/// turned 45° to the left, where the box's right part lies beside the view and takes
/// coarser levels sooner (the zones of 4.2.1).
#[test]
fn the_lightmaps_levels_hold_what_lookups_read() {
    levels_hold_what_lookups_read(false);
    levels_hold_what_lookups_read(true);
}

/// The camera the level of detail sees in a `render_probes` frame (64 × 64) of `scene`.
fn lod_camera(scene: &Scene) -> super::frame::LodCamera {
    let c = &scene.camera;
    super::frame::LodCamera::from_matrices(c.position, c.view(), c.proj(1.0))
}

/// The box of the receivers of `cluster`.
fn cluster_box(data: &super::file::BakeData, cluster: u32) -> crate::scene::Aabb {
    let [min, max] = data.cluster_bounds[cluster as usize];
    crate::scene::Aabb {
        min: Vec3::from(min),
        max: Vec3::from(max),
    }
}

/// The level of `bounds` by its distance from `camera` alone, without the zones.
fn level_by_distance(
    camera: &super::frame::LodCamera,
    bounds: &crate::scene::Aabb,
    distances: &[f32; 3],
) -> usize {
    let nearest = camera.position.clamp(bounds.min, bounds.max);
    super::frame::level_at(camera.position.distance(nearest), distances)
}

fn levels_hold_what_lookups_read(turned: bool) {
    use super::frame::ProbeGi;
    use super::levels::{mip_size, LightmapLevels, LEVELS};
    use crate::gi::Technique;
    let dir = TempDir::new("probe_levels");
    let mut scene = glowing_cornell(&dir);
    scene.lights.clear();
    scene.sky = Vec3::new(0.2, 0.4, 0.8);
    if turned {
        let c = &mut scene.camera;
        let forward = c.forward();
        let left = -c.right();
        c.target = c.position + (forward + left).normalize();
    }
    let distances = [3.6f32, 4.2, 4.8];
    let settings = twin_settings(&dir, Some(distances));
    let (ctx, renderer) = render_probes(&scene, &settings);
    let probes: &ProbeGi = renderer.gi_as().unwrap();
    let mips: Vec<Vec<Vec3>> = (0..LEVELS)
        .map(|k| read_rgb(&ctx, probes.lightmap(), k))
        .collect();
    let stats = probes.stats().unwrap();
    let stat = |name: &str| stats.iter().find(|(k, _)| k == name).unwrap().1;
    let (data, lambda) = host_lambda(&scene, &settings);
    let receivers = data.receiver_texels.len();
    let expected: Vec<Vec3> = (0..receivers)
        .map(|r| reconstructed(&data, &lambda, scene.sky, r) / std::f32::consts::PI)
        .collect();
    let levels = LightmapLevels::new(
        data.lightmap,
        &data.receiver_texels,
        &data.receiver_clusters,
    );
    let [width, height] = data.lightmap;
    let camera = lod_camera(&scene);
    let bounds = |r: usize| cluster_box(&data, data.receiver_clusters[r]);
    let cluster_level = |r: usize| camera.box_level(&bounds(r), &distances);
    // How many receivers' clusters their zone makes coarser than their distance alone.
    let coarser = (0..receivers)
        .filter(|&r| cluster_level(r) > level_by_distance(&camera, &bounds(r), &distances))
        .count();
    let (mut worst, mut checked, mut per_level) = (0.0f32, [0usize; LEVELS], [0usize; LEVELS]);
    let (mut unwritten, mut miscopied) = (Vec::new(), Vec::new());
    for k in 0..LEVELS {
        let (w, h) = mip_size(width, height, k);
        // Each texel of this level and the receiver whose irradiance it holds.
        let held: std::collections::HashMap<[u32; 2], u32> = if k == 0 {
            (0..receivers as u32)
                .map(|r| (data.receiver_texels[r as usize], r))
                .collect()
        } else {
            levels.texels(k).collect()
        };
        let mut read = std::collections::HashSet::new();
        for r in (0..receivers).filter(|&r| cluster_level(r) <= k) {
            per_level[k] += 1;
            let [x, y] = data.receiver_texels[r];
            // The texel of this level that holds the receiver's texel's centre.
            let (x, y) = (
                i64::from((2 * x + 1) * w / (2 * width)),
                i64::from((2 * y + 1) * h / (2 * height)),
            );
            for (dx, dy) in (-1..=1).flat_map(|dx| (-1..=1).map(move |dy| (dx, dy))) {
                let (tx, ty) = (x + dx, y + dy);
                if tx >= 0 && ty >= 0 && tx < i64::from(w) && ty < i64::from(h) {
                    read.insert([tx as u32, ty as u32]);
                }
            }
        }
        for t in read {
            if let Some(&r) = held.get(&t) {
                let got = mips[k][(t[1] * w + t[0]) as usize];
                let [x, y] = data.receiver_texels[r as usize];
                let own = mips[0][(y * width + x) as usize];
                if got == Vec3::ZERO {
                    unwritten.push((k, t));
                } else if got != own {
                    miscopied.push((k, t, got, own));
                }
                if cluster_level(r as usize) == 0 {
                    let want = expected[r as usize];
                    let error = (got - want).abs().max_element() / want.max_element().max(1e-3);
                    worst = worst.max(error);
                }
                checked[k] += 1;
            }
        }
    }
    let computed = stat("lod_receivers");
    eprintln!(
        "camera turned: {turned}; receivers at their cluster's level or finer, per level \
         {per_level:?}, {coarser} coarser by their zone; texels checked {checked:?}, worst \
         relative difference {worst:.4}; {computed} of {receivers} receivers computed"
    );
    assert_eq!(
        coarser > 0,
        turned,
        "{coarser} receivers' clusters coarser by their zone"
    );
    assert!(
        per_level[0] > 0 && per_level[0] < receivers,
        "the levels {per_level:?} do not split the box"
    );
    assert!(
        unwritten.is_empty(),
        "{} texels a lookup reads were not written this frame: {:?}",
        unwritten.len(),
        &unwritten[..unwritten.len().min(8)]
    );
    assert!(
        miscopied.is_empty(),
        "{} texels differ from their receiver's: {:?}",
        miscopied.len(),
        &miscopied[..miscopied.len().min(8)]
    );
    assert!(
        worst < 0.005,
        "a texel a lookup reads is {:.2} % off the host's",
        100.0 * worst
    );
    assert!(
        computed < receivers as f64,
        "{computed} of {receivers} receivers computed"
    );
}

/// The dynamic level of detail (Sedláček 2019, 4.2) against `--probe-lod off`, on the
/// built-in box lit by its point light through 8 bounces, with levels 1 to 3 beginning
/// 3.6, 4.2 and 4.8 from the camera (the box spans 2.9 to 5.2), a 128² lightmap: at each
/// receiver, the texel of its cluster's level that holds it against the same receiver's
/// texel with the level of detail off. Near the camera (level 0) they agree within
/// 1.5 %: the probes' relight there is the same, and only the bounces from farther
/// surfaces differ, read from coarser texels (1.3 % here, 2.2 % with a 64² lightmap:
/// the error falls with the texel's size). Each farther level's error is reported (3.7,
/// 5.2 and 6.5 %; 3.7, 6.2 and 6.8 % when the far levels' relight read every other
/// texel of the finest map instead of coarser maps' centres, and level 0's 1.2 %).
#[test]
fn the_level_of_detail_keeps_the_lightmap_near_the_camera() {
    use super::frame::{ProbeGi, ProbeSettings};
    use crate::gi::Technique;
    let dir = TempDir::new("probe_lod");
    let scene = cornell();
    let distances = [3.6f32, 4.2, 4.8];
    let bake = super::BakeSettings {
        lightmap_size: 128,
        probes: 64,
        probe_side: 32,
        relight_side: 32,
        receiver_rays: 32,
        spatial_receivers: 0,
        ..super::BakeSettings::default()
    };
    let lightmap = |lod: bool| {
        let settings = ProbeSettings {
            bake,
            bake_file: Some(dir.0.join("box.bake")),
            bounces: 8,
            converge_bounces: false,
            lod,
            lod_distances: Some(distances),
        };
        let (ctx, renderer) = render_probes(&scene, &settings);
        let probes: &ProbeGi = renderer.gi_as().unwrap();
        let stats = probes.stats().unwrap();
        let mips: Vec<Vec<Vec3>> = (0..super::levels::LEVELS)
            .map(|k| read_rgb(&ctx, probes.lightmap(), k))
            .collect();
        (mips, probes.lightmap_size(), stats)
    };
    let (on, [width, height], stats) = lightmap(true);
    let (off, _, _) = lightmap(false);
    let levels: Vec<_> = stats
        .iter()
        .filter(|(k, _)| k.starts_with("lod_probes"))
        .collect();
    let data = super::file::BakeData::read(
        &dir.0.join("box.bake"),
        super::file::content_key(&scene, &bake),
    )
    .unwrap();
    let camera = lod_camera(&scene);
    let levels_of = super::levels::LightmapLevels::new(
        data.lightmap,
        &data.receiver_texels,
        &data.receiver_clusters,
    );
    // Per level, each texel's receiver.
    let held: Vec<std::collections::HashMap<[u32; 2], u32>> = (1..super::levels::LEVELS)
        .map(|k| levels_of.texels(k).collect())
        .collect();
    let (mut sum, mut count) = ([0.0f64; 4], [0usize; 4]);
    for (r, &[x, y]) in data.receiver_texels.iter().enumerate() {
        let bounds = cluster_box(&data, data.receiver_clusters[r]);
        let level = camera.box_level(&bounds, &distances);
        let (got, standing_for) = if level == 0 {
            (on[0][(y * width + x) as usize], [x, y])
        } else {
            let (w, h) = super::levels::mip_size(width, height, level);
            let t = [
                (2 * x + 1) * w / (2 * width),
                (2 * y + 1) * h / (2 * height),
            ];
            let s = held[level - 1][&t] as usize;
            (
                on[level][(t[1] * w + t[0]) as usize],
                data.receiver_texels[s],
            )
        };
        let reference = off[0][(standing_for[1] * width + standing_for[0]) as usize];
        sum[level] +=
            f64::from((got - reference).abs().max_element() / reference.max_element().max(1e-3));
        count[level] += 1;
    }
    let mean: Vec<f64> = (0..4).map(|l| sum[l] / count[l].max(1) as f64).collect();
    eprintln!("probes per level {levels:?}; receivers per level {count:?}, mean relative difference {mean:.4?}");
    assert!(
        count[0] > 0 && count[1..].iter().sum::<usize>() > 0,
        "the levels {count:?} do not split the box"
    );
    assert!(
        mean[0] <= 0.015,
        "the receivers near the camera are {:.2} % off",
        100.0 * mean[0]
    );
}

/// The scene's own lightmap UVs (glTF's TEXCOORD_1) are the lightmap where every static
/// mesh has them: given the atlas the bake would make (its texels placed on a square
/// page) as each vertex's second UV set, the bake keeps it exactly, at the same density
/// within 1 %, with as many receivers.
/// UVs that put two places under one texel (the box's floor and ceiling on the same
/// square) are reported and replaced by the atlas.
#[test]
fn the_scenes_own_lightmap_uvs_are_kept_unless_they_overlap() {
    let scene = cornell();
    let made = Lightmap::generate(&scene, 128).unwrap();
    assert!(!made.authored);
    // The atlas's page is as tall as its charts need: its texels on the 128² page.
    let square = |[u, v]: [f32; 2]| {
        [
            u * made.width as f32 / 128.0,
            v * made.height as f32 / 128.0,
        ]
    };
    let corners: Vec<Vec<[f32; 2]>> = made
        .corners
        .iter()
        .map(|c| c.iter().map(|&uv| square(uv)).collect())
        .collect();
    let mut own = scene.clone();
    for (m, mesh) in own.meshes.iter_mut().enumerate() {
        let mut uvs = vec![None; mesh.vertices.len()];
        for (&i, &uv) in mesh.indices.iter().zip(&corners[m]) {
            let slot = &mut uvs[i as usize];
            assert!(slot.is_none_or(|s| s == uv), "a vertex in two charts");
            *slot = Some(uv);
        }
        mesh.lightmap_uvs = uvs.into_iter().map(|uv| uv.unwrap_or([0.0; 2])).collect();
    }
    let mut kept = Lightmap::generate(&own, 128).unwrap();
    assert!(kept.authored);
    assert_eq!(kept.corners, corners);
    let density = kept.texels_per_unit / made.texels_per_unit;
    assert!((density - 1.0).abs() < 0.01, "density {density}");
    let receivers = super::place_receivers(&own, &mut kept, 128).unwrap();
    assert!(kept.authored, "valid UVs were replaced");
    assert_eq!(
        receivers.list.len(),
        Receivers::place(&scene, &made).list.len()
    );

    // Every surface projected from above onto the whole page: the floor, the ceiling and
    // the blocks' tops over each other.
    let mut overlapping = scene.clone();
    let bounds = super::placement::static_bounds(&scene);
    for mesh in &mut overlapping.meshes {
        mesh.lightmap_uvs = mesh
            .vertices
            .iter()
            .map(|v| {
                let p = (Vec3::from(v.position) - bounds.min) / bounds.size();
                [p.x.clamp(0.0, 1.0), p.z.clamp(0.0, 1.0)]
            })
            .collect();
    }
    let mut replaced = Lightmap::generate(&overlapping, 128).unwrap();
    assert!(replaced.authored);
    let receivers = super::place_receivers(&overlapping, &mut replaced, 128).unwrap();
    assert!(!replaced.authored, "overlapping UVs were kept");
    assert_eq!(receivers.overlaps, 0);
}

/// The level of detail's zones (Sedláček 2019, 4.2.1, Figure 4.8) never make a lookup read
/// a level finer than its cluster computed: for cameras, boxes and points in the boxes
/// drawn at random, the level a point reads (`LodCamera::point_level`, the shaders' rule)
/// is at least its box's (`LodCamera::box_level`, the clusters'). And the zones scale as
/// stated: a box in view keeps its distance's level, one behind the camera takes the level
/// of four times its distance.
#[test]
fn a_lookup_reads_no_finer_level_than_its_cluster() {
    use super::frame::LodCamera;
    use crate::scene::Aabb;
    let mut random = crate::testing::Random(0x2545_f491_4f6c_dd1d);
    let distances = [1.0f32, 2.0, 4.0];
    let mut zoned = 0;
    for _ in 0..2000 {
        let camera = LodCamera {
            position: Vec3::new(random.unit(), random.unit(), random.unit()) * 4.0 - 2.0,
            forward: random.direction(),
            cos_frustum: 0.5 + 0.45 * random.unit(),
        };
        let centre = Vec3::new(random.unit(), random.unit(), random.unit()) * 8.0 - 4.0;
        let half = Vec3::new(random.unit(), random.unit(), random.unit()) * 1.5;
        let bounds = Aabb {
            min: centre - half,
            max: centre + half,
        };
        let level = camera.box_level(&bounds, &distances);
        let by_distance = level_by_distance(&camera, &bounds, &distances);
        assert!(level >= by_distance, "a zone made a box finer");
        zoned += usize::from(level > by_distance);
        for _ in 0..20 {
            let p = bounds.min
                + (bounds.max - bounds.min)
                    * Vec3::new(random.unit(), random.unit(), random.unit());
            assert!(
                camera.point_level(p, &distances) >= level,
                "{camera:?}: a point of {bounds:?} reads level {} below its box's {level}",
                camera.point_level(p, &distances)
            );
        }
    }
    assert!(
        zoned > 100,
        "only {zoned} of 2000 boxes coarser by their zone"
    );
    let camera = LodCamera {
        position: Vec3::ZERO,
        forward: Vec3::NEG_Z,
        cos_frustum: 0.8,
    };
    let small = |at: Vec3| Aabb {
        min: at - 0.01,
        max: at + 0.01,
    };
    assert_eq!(
        camera.box_level(&small(Vec3::new(0.0, 0.0, -1.5)), &distances),
        1
    );
    assert_eq!(
        camera.box_level(&small(Vec3::new(0.0, 0.0, 1.5)), &distances),
        3
    );
    assert_eq!(
        camera.box_level(&small(Vec3::new(1.5, 0.0, -0.2)), &distances),
        2
    );
}

/// One image without a given count of bounces takes the rule's for its scene (the built-in
/// box: seven, not the frames' eight) when the renderer resolves its settings; a given
/// count stays.
#[test]
fn converged_bounces_reach_the_probes() {
    use super::frame::ProbeSettings;
    use crate::gi::bounces::converged_bounces;
    use crate::gi::GiSettings;
    use crate::ray::host::bounce_rate;

    let scene = Scene::load(&crate::cli::default_scene(), &LoadOptions::default()).unwrap();
    let want = converged_bounces(bounce_rate(&scene));
    assert_ne!(want, ProbeSettings::default().bounces);
    let ctx = validating_context();
    let resolved = |converge_bounces: bool| {
        let settings = GiSettings::Probes(ProbeSettings {
            converge_bounces,
            ..Default::default()
        });
        match settings.on(&ctx, &scene) {
            GiSettings::Probes(probes) => probes,
            _ => panic!("no probes"),
        }
    };
    let converged = resolved(true);
    assert_eq!(converged.bounces, want);
    assert!(!converged.converge_bounces);
    assert_eq!(resolved(false).bounces, ProbeSettings::default().bounces);
    assert_eq!(ctx.validation_messages(), 0);
}

/// The relight's surfaces are refused, naming the settings to lower, where they would not
/// fit the device's texel buffers: lavapipe's 128 Mi texels hold 12,000 probes at the
/// default side, not 13,000. They are written as texels too: through a storage buffer,
/// lavapipe's 128 MiB binding held only 780 probes' at the default, and past it the
/// surfaces pass wrote with no message unless validation was on.
#[test]
fn relight_rays_beyond_the_devices_bindings_are_refused() {
    use super::casting::RelightRays;
    use super::frame::check_relight_rays;
    let texels = 128 << 20;
    let rays = |probes: u64, side: usize| probes * RelightRays::per_probe(side) as u64;
    check_relight_rays(rays(256, 128), texels).unwrap();
    check_relight_rays(rays(12_000, 64), texels).unwrap();
    let err = check_relight_rays(rays(13_000, 64), texels).unwrap_err();
    let message = format!("{err:#}");
    for needle in ["texels", "--probes", "--relight-side"] {
        assert!(message.contains(needle), "{message}");
    }
}
