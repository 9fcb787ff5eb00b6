//! The dense GI stages against their CPU twins (`reference.rs`), on the real device with
//! validation on.

use std::sync::Arc;

use super::super::reference;
use super::super::voxelize::Voxelizer;
use super::super::{
    auto_voxels, dense_bytes_per_voxel, dense_keeps_static_sums, ConeSettings, DirectionalFilter,
    Grid, Quality, Resolution, Store, CPU_VOXELS, LATTICE_CONES,
};
use super::Volume;
use crate::gi::bounces::converged_bounces;
use crate::gi::GiSettings;
use crate::gpu_layout as layout;
use crate::ray::host::bounce_rate;
use crate::renderer::Renderer;
use crate::scene::testing::shared_file;
use crate::scene::{LoadOptions, Scene};
use crate::testing::{
    cone_settings, dense, gi_settings, moving_cube_scene, render_frames, with_voxelizer,
};
use crate::vk::Context;

/// The dense grid with the default filter.
const DENSE: Store = Store::Dense {
    filter: DirectionalFilter::Pairs,
    planes: false,
};

/// Renders 64x64 frames of `scene` with `--gi dense --voxels n`, one at each time,
/// re-voxelizing the static meshes every frame with `full_update`.
fn render_at(scene: Scene, n: u32, times: &[f32], full_update: bool) -> (Arc<Context>, Renderer) {
    render_frames(scene, gi_settings(n, DENSE, full_update), times)
}

/// Renders one 64x64 frame of `scene` at time 0 with `--gi dense --voxels n`.
fn render(scene: Scene, n: u32) -> (Arc<Context>, Renderer) {
    render_at(scene, n, &[0.0], false)
}

fn occupancy(renderer: &Renderer) -> Vec<bool> {
    let bytes = dense(renderer).store().download(Volume::Albedo, 0).unwrap();
    bytes.chunks_exact(4).map(|t| t[3] > 0).collect()
}

/// Every voxel a triangle touches is occupied on the GPU, and the GPU's conservative
/// coverage adds none farther than one voxel from a triangle, with either voxelizer.
fn check_voxelization(scene: Scene, n: u32) {
    for voxelizer in [Voxelizer::Raster, Voxelizer::Compute] {
        check_voxelization_by(scene.clone(), n, voxelizer);
    }
}

fn check_voxelization_by(scene: Scene, n: u32, voxelizer: Voxelizer) {
    let triangles = reference::world_triangles(&scene);
    let settings = with_voxelizer(gi_settings(n, DENSE, false), voxelizer);
    let (ctx, renderer) = render_frames(scene, settings, &[0.0]);
    let grid: Grid = *dense(&renderer).grid();
    let gpu = occupancy(&renderer);
    let exact = reference::voxelize(&triangles, &grid);
    let near = reference::within_one_voxel(&triangles, &grid);
    let missing = exact.iter().zip(&gpu).filter(|(c, g)| **c && !**g).count();
    let extra = near.iter().zip(&gpu).filter(|(c, g)| !**c && **g).count();
    let cpu_count = exact.iter().filter(|c| **c).count();
    let gpu_count = gpu.iter().filter(|g| **g).count();
    eprintln!(
        "{n}^3, {voxelizer:?}: CPU {cpu_count} voxels, GPU {gpu_count}, missing {missing}, \
         too far {extra}"
    );
    assert!(cpu_count > 0);
    assert_eq!(missing, 0, "voxels the CPU marks but the GPU does not");
    assert_eq!(
        extra, 0,
        "GPU voxels farther than one voxel from every triangle"
    );
    assert_eq!(ctx.validation_messages(), 0);
}

#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn voxelization_matches_cpu_on_cornell_box() {
    let path = shared_file("scenes/cornell_box/CornellBox-Original.obj");
    for n in [32, 64] {
        check_voxelization(Scene::load(&path, &LoadOptions::default()).unwrap(), n);
    }
}

#[test]
fn voxelization_matches_cpu_on_a_rotated_thin_mesh() {
    // A 2 x 0.02 x 1.3 slab, thinner than a voxel, tilted on all three axes, inside a
    // unit box that sets the grid's extent.
    let obj = "v -1 -0.01 -0.65\nv 1 -0.01 -0.65\nv 1 0.01 -0.65\nv -1 0.01 -0.65\n\
               v -1 -0.01 0.65\nv 1 -0.01 0.65\nv 1 0.01 0.65\nv -1 0.01 0.65\n\
               f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n";
    let scene = scene_of("thin", obj, "rotate_deg = [23, 41, 17]\n");
    for n in [32, 64] {
        check_voxelization(scene.clone(), n);
    }
}

/// The coverage volume of one frame of `scene` at `n`³ with `voxelizer` and the snapped
/// cones: per voxel, its coverage across x, y and z.
fn coverage(scene: Scene, n: u32, voxelizer: Voxelizer) -> (Grid, Vec<[f32; 3]>) {
    let mut settings = with_voxelizer(gi_settings(n, DENSE, false), voxelizer);
    // Taken only where a cone reads it: the snapped soft-shadow cones do.
    let vct = cone_settings(&mut settings);
    vct.cones.snapped_cones = true;
    vct.shadow_cones = true;
    let (ctx, renderer) = render_frames(scene, settings, &[0.0]);
    assert_eq!(ctx.validation_messages(), 0);
    let bytes = dense(&renderer)
        .store()
        .download(Volume::Coverage, 0)
        .unwrap();
    let texels = bytes
        .chunks_exact(4)
        .map(|t| [t[0], t[1], t[2]].map(|c| f32::from(c) / 255.0))
        .collect();
    (*dense(&renderer).grid(), texels)
}

/// A scene of `obj` alone (placed by `placement`, a scene file's mesh keys), loaded from a
/// fresh folder named after `name`.
fn scene_of(name: &str, obj: &str, placement: &str) -> Scene {
    let dir = std::env::temp_dir().join(format!("voxcone-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("mesh.obj"), obj).unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        format!("[[mesh]]\npath = \"mesh.obj\"\n{placement}"),
    )
    .unwrap();
    let scene = Scene::load(&dir.join("scene.toml"), &LoadOptions::default()).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    scene
}

/// Each voxel's coverage across an axis is the share of its cross-section that its
/// surfaces cover, seen along the axis, with either voxelizer: a level rectangle whose
/// edges lie inside voxels covers each voxel of its layer by the overlap of the two,
/// exactly (to the 8-bit quantum), and nothing across the other axes, though conservative
/// voxelization occupies every voxel its edges touch; a rectangle turned on all three
/// axes covers, summed over the voxels, its area projected along each axis.
#[test]
fn coverage_is_the_covered_share_of_each_voxel() {
    // The two small triangles at opposite corners set the grid: [-1, 1]³ and a little.
    let corners = "v -1 -1 -1\nv -0.99 -1 -1\nv -1 -0.99 -1\nv 1 1 1\nv 0.99 1 1\nv 1 0.99 1\n\
                   f 1 2 3\nf 4 5 6\n";
    let (x0, x1, y, z0, z1) = (-0.313f32, 0.271, 0.137, -0.229, 0.351);
    let level = format!(
        "{corners}v {x0} {y} {z0}\nv {x1} {y} {z0}\nv {x1} {y} {z1}\nv {x0} {y} {z1}\nf 7 10 9 8\n"
    );
    let level = scene_of("coverage-level", &level, "");
    let tilted = "v -0.65 0 -0.45\nv 0.65 0 -0.45\nv 0.65 0 0.45\nv -0.65 0 0.45\nf 1 4 3 2\n";
    let tilted = scene_of("coverage-tilted", tilted, "rotate_deg = [23, 41, 17]\n");
    for voxelizer in [Voxelizer::Raster, Voxelizer::Compute] {
        let (grid, got) = coverage(level.clone(), 32, voxelizer);
        let v = grid.voxel_size;
        let overlap = |lo: f32, hi: f32, i: u32, origin: f32| {
            let (a, b) = (origin + i as f32 * v, origin + (i + 1) as f32 * v);
            ((hi.min(b) - lo.max(a)) / v).max(0.0)
        };
        let layer = ((y - grid.origin.y) / v) as u32;
        let mut worst = 0.0f32;
        for k in 0..grid.resolution {
            for i in 0..grid.resolution {
                let want = overlap(x0, x1, i, grid.origin.x) * overlap(z0, z1, k, grid.origin.z);
                let c = got[grid.index(i, layer, k)];
                worst = worst.max((c[1] - want).abs());
                assert_eq!(
                    [c[0], c[2]],
                    [0.0, 0.0],
                    "({i}, {layer}, {k}), {voxelizer:?}"
                );
            }
        }
        eprintln!("level rectangle, {voxelizer:?}: worst coverage across y off by {worst:.4}");
        assert!(worst <= 1.0 / 255.0, "{voxelizer:?}: {worst}");

        let (grid, got) = coverage(tilted.clone(), 32, voxelizer);
        let area = reference::world_triangles(&tilted)
            .iter()
            .map(|t| 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).abs())
            .fold(glam::Vec3::ZERO, |a, b| a + b)
            / (grid.voxel_size * grid.voxel_size);
        let total = got
            .iter()
            .fold(glam::Vec3::ZERO, |a, c| a + glam::Vec3::from(*c));
        eprintln!(
            "turned rectangle, {voxelizer:?}: coverage summed {total}, projected area {area}"
        );
        // Each fragment's share is rounded to 1/255: a small projection, made of many
        // small shares, is off by more of itself.
        for a in 0..3 {
            assert!(
                (total[a] - area[a]).abs() <= 0.01 * area.max_element(),
                "{voxelizer:?}, axis {a}: {} against {}",
                total[a],
                area[a]
            );
        }
    }
}

fn halves(bytes: &[u8]) -> Vec<[f32; 4]> {
    bytes
        .chunks_exact(8)
        .map(|t| {
            let h = |i: usize| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32();
            [h(0), h(1), h(2), h(3)]
        })
        .collect()
}

/// The voxels' packed RGBA8 normals as downloaded.
fn packed_normals(renderer: &Renderer) -> Vec<u32> {
    dense(renderer)
        .store()
        .download(Volume::Normal, 0)
        .unwrap()
        .chunks_exact(4)
        .map(|t| u32::from_le_bytes([t[0], t[1], t[2], t[3]]))
        .collect()
}

/// One frame of the reference Cornell box (point light) at `n`³ in `store`.
fn cornell_frame(n: u32, store: Store) -> (Arc<Context>, Renderer) {
    let path = shared_file("reference/cornell_point.scene.json");
    let scene = Scene::load(&path, &LoadOptions::REFERENCE).unwrap();
    render_frames(scene, gi_settings(n, store, false), &[0.0])
}

/// The base radiance as downloaded, as seen along each of the six directions (weighted
/// by which way each voxel's lit face looks).
fn base_seen(renderer: &Renderer) -> Vec<Vec<[f32; 4]>> {
    let gi = dense(renderer).store();
    let base = halves(&gi.download(Volume::Radiance, 0).unwrap());
    assert!(base.iter().any(|v| v[3] > 0.0), "empty radiance volume");
    let normals = packed_normals(renderer);
    (0..6)
        .map(|d| {
            base.iter()
                .zip(&normals)
                .map(|(v, n)| reference::seen_facing(*n, *v, d))
                .collect()
        })
        .collect()
}

/// The largest difference between `cpu` and `gpu`, relative to the CPU's value or 1 if
/// larger, asserted within `bound` (naming `what`).
fn worst_difference(cpu: &[[f32; 4]], gpu: &[[f32; 4]], bound: f32, what: &str) -> f32 {
    let mut worst = 0.0f32;
    for (c, g) in cpu.iter().zip(gpu) {
        for k in 0..4 {
            let err = (c[k] - g[k]).abs() / c[k].abs().max(1.0);
            worst = worst.max(err);
            assert!(err <= bound, "{what}: CPU {c:?} GPU {g:?}");
        }
    }
    worst
}

/// Each level of each directional volume equals the CPU filter applied to the level
/// below as downloaded (the first level: the base radiance, weighted by which way each
/// voxel's lit face looks), within half-float rounding.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn filter_matches_cpu() {
    let path = shared_file("reference/cornell_point.scene.json");
    let options = LoadOptions::REFERENCE;
    let n = 32;
    let (ctx, renderer) = render(Scene::load(&path, &options).unwrap(), n);
    let gi = dense(&renderer).store();
    let mut worst = 0.0f32;
    for (d, mut below) in base_seen(&renderer).into_iter().enumerate() {
        let mut size = n;
        // n/2 down to 2.
        for level in 0..n.trailing_zeros() - 1 {
            let cpu = reference::filter_directional(&below, size, d);
            let gpu = halves(&gi.download(Volume::Directional(d), level).unwrap());
            let what = format!("direction {d} level {level}");
            worst = worst.max(worst_difference(&cpu, &gpu, 2.0 / 1024.0, &what));
            below = gpu;
            size /= 2;
        }
    }
    eprintln!("filter: worst relative difference {worst:.2e}");
    assert_eq!(ctx.validation_messages(), 0);
}

/// With the planes (`Store::planes`), each level of the cells' planes and coverage equals the CPU
/// filter applied to the level below as downloaded (the first level: the base opacity
/// and normals), within half-float rounding; and the planes are planes: most covered
/// cells of the Cornell box (walls, floor, blocks) hold one, |mean opacity x normal| at
/// least 0.9 of the mean opacity.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn filter_planes_match_cpu() {
    let n = 32;
    let (ctx, renderer) = cornell_frame(
        n,
        Store::Dense {
            filter: DirectionalFilter::Pairs,
            planes: true,
        },
    );
    let gi = dense(&renderer).store();
    let opacity: Vec<f32> = halves(&gi.download(Volume::Radiance, 0).unwrap())
        .iter()
        .map(|v| v[3])
        .collect();
    let normals = packed_normals(&renderer);
    let plane_slot = layout::PLANE_SLOT as usize;
    let coverage_slot = layout::COVERAGE_SLOT as usize;
    let (mut planes, coverage) = reference::filter_planes_base(&opacity, &normals, n);
    let mut coverage: Vec<[f32; 4]> = coverage.iter().map(|&c| [c, 0.0, 0.0, 0.0]).collect();
    let mut worst = 0.0f32;
    let (mut covered, mut planar) = (0, 0);
    let mut size = n / 2;
    for level in 0..n.trailing_zeros() - 1 {
        let gpu_planes = halves(&gi.download(Volume::Directional(plane_slot), level).unwrap());
        let gpu_coverage = halves(
            &gi.download(Volume::Directional(coverage_slot), level)
                .unwrap(),
        );
        let what = format!("planes level {level}");
        worst = worst.max(worst_difference(&planes, &gpu_planes, 2.0 / 1024.0, &what));
        let what = format!("coverage level {level}");
        worst = worst.max(worst_difference(
            &coverage,
            &gpu_coverage,
            2.0 / 1024.0,
            &what,
        ));
        if level == 0 {
            for (p, c) in gpu_planes.iter().zip(&gpu_coverage) {
                if c[0] > 0.05 {
                    covered += 1;
                    let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                    planar += usize::from(len >= 0.9 * c[0]);
                }
            }
        }
        planes = reference::filter_mean(&gpu_planes, size);
        coverage = reference::filter_mean(&gpu_coverage, size);
        size /= 2;
    }
    eprintln!(
        "filter's planes: worst relative difference {worst:.2e}; {planar} of {covered} \
         covered cells planar at the first level"
    );
    assert!(2 * planar > covered, "{planar} of {covered} cells planar");
    assert_eq!(ctx.validation_messages(), 0);
}

/// With `--directional-filter rows`, each level of each directional volume equals the
/// filter's definition applied to the base radiance as downloaded (each cell's rows of
/// voxels, as seen along the direction, composited whole, then averaged), within the
/// half-float rounding of the rows kept at every level below (measured: 1.2e-3 at worst).
/// And a surface seen edge-on, the reason for the filter: at least one cell whose rows
/// hold less than half the opacity the pairs filter gives it.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn filter_by_rows_matches_cpu() {
    let n = 32;
    let (ctx, renderer) = cornell_frame(
        n,
        Store::Dense {
            filter: DirectionalFilter::Rows,
            planes: false,
        },
    );
    let gi = dense(&renderer).store();
    let mut worst = 0.0f32;
    let mut thinner = 0;
    for (d, seen) in base_seen(&renderer).into_iter().enumerate() {
        let mut pairs = seen.clone();
        for level in 0..n.trailing_zeros() - 1 {
            let width = 2 << level;
            pairs = reference::filter_directional(&pairs, n / (width / 2), d);
            let cpu = reference::filter_rows(&seen, n, width, d);
            let gpu = halves(&gi.download(Volume::Directional(d), level).unwrap());
            let what = format!("direction {d} level {level}");
            worst = worst.max(worst_difference(&cpu, &gpu, 3.0 / 1024.0, &what));
            thinner += cpu
                .iter()
                .zip(&pairs)
                .filter(|(c, p)| p[3] > 0.05 && c[3] < 0.5 * p[3])
                .count();
        }
    }
    eprintln!(
        "filter by rows: worst relative difference {worst:.2e}; {thinner} cells under half \
         the pairs' opacity"
    );
    assert!(
        thinner > 0,
        "no cell the rows see through more than the pairs"
    );
    assert_eq!(ctx.validation_messages(), 0);
}

/// A mesh moving across the Cornell box leaves no voxel behind: after frames at several
/// times, with the static voxels kept from the first frame, the voxels (occupancy and
/// albedo) equal a fresh voxelization at the last time and a full re-voxelization of
/// every frame, with either voxelizer.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn moving_mesh_leaves_no_voxels_behind() {
    let cornell = shared_file("scenes/cornell_box/CornellBox-Original.obj");
    let dir = std::env::temp_dir().join(format!("voxcone-moving-{}", std::process::id()));
    let scene = moving_cube_scene(&cornell, &dir, false);
    for voxelizer in [Voxelizer::Raster, Voxelizer::Compute] {
        check_moving_mesh(scene.clone(), voxelizer);
    }
    std::fs::remove_dir_all(&dir).ok();
}

fn check_moving_mesh(scene: Scene, voxelizer: Voxelizer) {
    let render_at = |scene: Scene, times: &[f32], full_update| {
        let settings = gi_settings(32, DENSE, full_update);
        render_frames(scene, with_voxelizer(settings, voxelizer), times)
    };
    let times = [0.0, 0.5, 1.0];
    let (ctx, moved) = render_at(scene.clone(), &times, false);
    let moved_voxels = occupancy(&moved);
    let (_, fresh) = render_at(scene.clone(), &[1.0], false);
    let fresh_voxels = occupancy(&fresh);
    let (_, full) = render_at(scene.clone(), &times, true);
    let (_, start) = render_at(scene, &[0.0], false);
    let start_voxels = occupancy(&start);
    assert_ne!(start_voxels, fresh_voxels, "the cube did not move");
    assert_eq!(
        moved_voxels, fresh_voxels,
        "voxels left behind or missing after the move"
    );
    let albedo = |r: &Renderer| dense(r).store().download(Volume::Albedo, 0).unwrap();
    assert!(
        albedo(&moved) == albedo(&fresh),
        "albedo differs from a fresh voxelization"
    );
    assert!(
        albedo(&moved) == albedo(&full),
        "albedo differs from --full-update"
    );
    assert_eq!(ctx.validation_messages(), 0);
}

/// Static geometry is voxelized once: later frames only shade it (a moving light needs
/// no voxelization), unless every frame is a full update.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn static_voxels_are_voxelized_once() {
    let path = shared_file("reference/cornell_point.scene.json");
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    let passes = |full_update| {
        let (ctx, renderer) = render_at(scene.clone(), 32, &[0.0, 0.5], full_update);
        assert_eq!(ctx.validation_messages(), 0);
        renderer
            .timings
            .iter()
            .map(|(name, _)| name.clone())
            .collect::<Vec<_>>()
    };
    let kept = passes(false);
    assert!(!kept.iter().any(|p| p == "voxelize"), "{kept:?}");
    assert!(kept.iter().any(|p| p == "inject"), "{kept:?}");
    let full = passes(true);
    assert!(full.iter().any(|p| p == "voxelize"), "{full:?}");
}

/// The voxels' albedo, normal and emission do not depend on the order in which the
/// fragments arrive: the same triangles drawn in the opposite order (meshes and the
/// triangles within each) give bit-identical volumes. A running RGBA8 average rounds
/// differently in each order.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn voxel_means_do_not_depend_on_fragment_order() {
    let path = shared_file("reference/cornell_point.scene.json");
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    let mut reversed = scene.clone();
    reversed.meshes.reverse();
    for mesh in &mut reversed.meshes {
        let triangles: Vec<[u32; 3]> = mesh
            .indices
            .chunks_exact(3)
            .rev()
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        mesh.indices = triangles.concat();
    }
    let volumes = |scene: Scene| {
        let (ctx, renderer) = render(scene, 64);
        assert_eq!(ctx.validation_messages(), 0);
        let gi = dense(&renderer).store();
        [Volume::Albedo, Volume::Normal, Volume::Emission].map(|v| gi.download(v, 0).unwrap())
    };
    let (first, second) = (volumes(scene), volumes(reversed));
    for (name, (a, b)) in ["albedo", "normal", "emission"]
        .iter()
        .zip(first.iter().zip(&second))
    {
        let occupied = a.chunks_exact(4).filter(|t| t[3] > 0).count();
        let differ = a
            .chunks_exact(4)
            .zip(b.chunks_exact(4))
            .filter(|(x, y)| x != y)
            .count();
        eprintln!("{name}: {differ} of {occupied} occupied voxels differ");
        assert!(occupied > 0);
        assert_eq!(differ, 0, "voxel {name} depends on the fragments' order");
    }
}

/// The occupied-voxel list that the bounces run over holds each occupied voxel once and
/// nothing else, and its dispatch covers it (synchronization validation cannot see
/// storage-buffer hazards, so the buffer passes are checked by their result).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn voxel_list_holds_exactly_the_occupied_voxels() {
    let path = shared_file("reference/cornell_point.scene.json");
    let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
    let n = 32;
    let (ctx, renderer) = render_at(scene, n, &[0.0, 0.5], true);
    let gi = dense(&renderer).store();
    let occupied = occupancy(&renderer);
    let mut listed = vec![false; occupied.len()];
    for [x, y, z] in gi.download_voxel_list().unwrap() {
        let i = gi.grid.index(x, y, z);
        assert!(!listed[i], "voxel ({x}, {y}, {z}) listed twice");
        listed[i] = true;
    }
    let count = occupied.iter().filter(|&&o| o).count();
    eprintln!("voxel list: {count} occupied voxels");
    assert!(count > 0);
    assert_eq!(listed, occupied);
    assert_eq!(ctx.validation_messages(), 0);
}

/// One image without a given count of bounces takes the rule's for its scene (the built-in
/// box: seven, not the frames' eight) and keeps the count in its settings.
#[test]
fn converged_bounces_reach_the_renderer() {
    let scene = Scene::load(&crate::cli::default_scene(), &LoadOptions::default()).unwrap();
    let want = converged_bounces(bounce_rate(&scene));
    assert_ne!(want, ConeSettings::default().bounces);
    let mut settings = gi_settings(CPU_VOXELS, DENSE, false);
    cone_settings(&mut settings).converge_bounces = true;
    let (ctx, renderer) = render_frames(scene, settings, &[0.0]);
    assert_eq!(ctx.validation_messages(), 0);
    let GiSettings::ConeTracing(kept) = &renderer.settings.gi else {
        panic!("no cone tracing");
    };
    assert_eq!(kept.cones.bounces, want);
    assert!(!kept.converge_bounces);
}

/// Without a given resolution the renderer applies the rule for its device, keeps the
/// count in its settings (the viewer's panel shows it) and builds the grid at it: on a
/// CPU driver in real time 64³, with or without a wanted voxel size, snapped cones or not;
/// for one image with the lattice, the most its memory holds.
#[test]
fn the_default_resolution_reaches_the_grid() {
    let scene = Scene::load(&crate::cli::default_scene(), &LoadOptions::default()).unwrap();
    let extent = Grid::extent_around(&scene);
    let cases = [
        (None, false, Quality::Fast),
        (None, true, Quality::Fast),
        (Some(extent / 512.0), false, Quality::Fast),
        (None, true, Quality::Accurate),
    ];
    for (size, lattice, quality) in cases {
        let mut settings = gi_settings(0, DENSE, false);
        let vct = cone_settings(&mut settings);
        vct.voxels = Resolution::Auto { size, quality };
        if lattice {
            vct.cones.lattice_cones = LATTICE_CONES;
            vct.cones.snapped_cones = true;
        }
        vct.cones.bounces = 1;
        let full_update = vct.full_update;
        let (ctx, renderer) = render_frames(scene.clone(), settings, &[0.0]);
        assert_eq!(ctx.validation_messages(), 0);
        assert!(ctx.is_cpu(), "the rule's GPU branch is tested on its own");
        let want = match quality {
            Quality::Fast => CPU_VOXELS,
            Quality::Accurate => {
                let bytes = dense_bytes_per_voxel(dense_keeps_static_sums(&scene, full_update));
                auto_voxels(Some(ctx.device_local_bytes()), bytes, extent, size, true)
            }
        };
        let GiSettings::ConeTracing(kept) = &renderer.settings.gi else {
            panic!("no cone tracing");
        };
        assert_eq!(kept.voxels, Resolution::Count(want), "{size:?} {quality:?}");
        assert_eq!(dense(&renderer).grid().resolution, want);
    }
}
