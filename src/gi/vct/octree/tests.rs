//! The octree build against a CPU octree, on the real device with validation on.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use super::{Capacities, Octree};
use crate::gi::vct::reference;
use crate::gi::vct::voxelize::Voxelizer;
use crate::gi::vct::{ConeSettings, Store};
use crate::gpu_layout::{self as layout, OctreeCounters, OctreeLevel};
use crate::renderer::Renderer;
use crate::scene::testing::shared_file;
use crate::scene::{Light, LightKind, LoadOptions, Scene};
use crate::testing::{
    cone_settings, gi_settings, moving_cube_scene, octree, octree_mut, render_frames,
    render_frames_with, with_voxelizer,
};
use crate::vk::Context;

/// A renderer whose octree of `scene` is built at `depth`, after `frames` frames.
fn build_and_render(
    scene: Scene,
    depth: u32,
    capacities: Option<Capacities>,
    frames: usize,
) -> (Arc<Context>, Renderer) {
    let store = Store::Octree {
        capacities,
        planes: false,
    };
    render_frames(
        scene,
        gi_settings(1 << depth, store, false),
        &vec![0.0; frames],
    )
}

/// The octree without the planes (`Store::planes`), its pools from the estimate.
const OCTREE: Store = Store::Octree {
    capacities: None,
    planes: false,
};

fn build(scene: Scene, depth: u32, capacities: Option<Capacities>) -> (Arc<Context>, Renderer) {
    build_and_render(scene, depth, capacities, 0)
}

/// A voxel fragment as downloaded.
struct Fragment {
    position: u32,
    albedo: u32,
    normal: u32,
    emission: u32,
}

/// The octree as downloaded.
struct Downloaded {
    fragments: Vec<Fragment>,
    /// Per level: its static run and its appended run, (first node, count) each.
    runs: Vec<[(u32, u32); 2]>,
    /// Per level: its nodes, the static run's then the appended run's.
    levels: Vec<Vec<u32>>,
    /// Nodes of the static part (1, the root, after a build).
    static_nodes: u32,
    children: Vec<u32>,
    coords: Vec<[u32; 3]>,
    bricks: Vec<u32>,
    neighbours: Vec<u32>,
}

fn unpack(p: u32) -> [u32; 3] {
    [p & 0x3ff, (p >> 10) & 0x3ff, p >> 20]
}

/// The counters and level table as they are now (after the last frame's rebuild).
fn live_counters(svo: &Octree) -> (OctreeCounters, Vec<OctreeLevel>) {
    let words = svo.download_words(&svo.counters).unwrap();
    let bytes: &[u8] = bytemuck::cast_slice(&words);
    let head = std::mem::size_of::<OctreeCounters>();
    let levels = bytes[head..]
        .chunks_exact(std::mem::size_of::<OctreeLevel>())
        .take(svo.depth as usize)
        .map(bytemuck::pod_read_unaligned)
        .collect();
    (bytemuck::pod_read_unaligned(&bytes[..head]), levels)
}

fn download(svo: &Octree) -> Downloaded {
    let (counters, levels) = live_counters(svo);
    let p = &svo.pools;
    let stored = counters.fragment_count as usize;
    let voxels = svo.download_words(&svo.fragments.voxels).unwrap();
    let shading = svo.download_words(&svo.fragments.shading).unwrap();
    Downloaded {
        fragments: (0..stored)
            .map(|i| Fragment {
                position: voxels[i],
                albedo: voxels[svo.fragments.capacity as usize + i],
                normal: shading[2 * i],
                emission: shading[2 * i + 1],
            })
            .collect(),
        runs: levels
            .iter()
            .map(|l| [(l.first, l.count), (l.appended_first, l.appended_count)])
            .collect(),
        levels: levels
            .iter()
            .map(|l| {
                (l.first..l.first + l.count)
                    .chain(l.appended_first..l.appended_first + l.appended_count)
                    .collect()
            })
            .collect(),
        static_nodes: counters.static_node_count,
        children: svo.download_words(&p.nodes).unwrap(),
        coords: svo
            .download_words(&p.coords)
            .unwrap()
            .into_iter()
            .map(unpack)
            .collect(),
        bricks: svo.download_words(&p.bricks).unwrap(),
        neighbours: svo.download_words(&p.neighbours).unwrap(),
    }
}

/// The occupied nodes of each level (0 = root) of an octree over `voxels` of a 2^depth
/// grid: a node at level l covers voxels v with v >> (depth - l) equal to its coordinates.
fn cpu_octree(voxels: &HashSet<[u32; 3]>, depth: u32) -> Vec<HashSet<[u32; 3]>> {
    (0..depth)
        .map(|l| voxels.iter().map(|v| v.map(|c| c >> (depth - l))).collect())
        .collect()
}

/// Checks the GPU octree node for node against the CPU octree of its own fragments and
/// returns those fragments' voxels.
fn check_structure(svo: &Octree, d: &Downloaded) -> HashSet<[u32; 3]> {
    let depth = svo.depth;
    let voxels: HashSet<[u32; 3]> = d.fragments.iter().map(|f| unpack(f.position)).collect();
    let cpu = cpu_octree(&voxels, depth);
    // Level l + 1 holds a tile of 8 children under every occupied node of level l; each
    // level's appended run follows the level above's (the root's starts after the static
    // part).
    for (l, nodes) in d.levels.iter().enumerate() {
        let expected = if l == 0 { 1 } else { 8 * cpu[l - 1].len() };
        assert_eq!(nodes.len(), expected, "level {l}: node count");
        if l > 0 {
            let above = d.runs[l - 1][1];
            assert_eq!(
                d.runs[l][1].0,
                above.0 + above.1,
                "level {l} follows level {}",
                l - 1
            );
        }
    }
    let total: usize = d.levels.iter().map(Vec::len).sum();
    let counters = live_counters(svo).0;
    assert_eq!(total as u32, counters.node_count);
    let built = d.static_nodes <= 1;

    let mut by_coords: Vec<HashMap<[u32; 3], u32>> = Vec::new();
    let mut leaf_bricks = HashSet::new();
    let mut leaf_sums = Vec::new();
    let mut interior_bricks = HashSet::new();
    for (l, nodes) in d.levels.iter().enumerate() {
        let mut map = HashMap::new();
        for &node in nodes {
            let c = d.coords[node as usize];
            assert!(
                map.insert(c, node).is_none(),
                "level {l}: two nodes at {c:?}"
            );
            let occupied = cpu[l].contains(&c);
            let brick = d.bricks[node as usize];
            assert_eq!(
                brick != layout::OCTREE_NO_BRICK,
                occupied,
                "level {l} node {node} brick"
            );
            if occupied {
                let fresh = if l + 1 == depth as usize {
                    leaf_bricks.insert(brick)
                } else {
                    interior_bricks.insert(brick)
                };
                assert!(fresh, "brick {brick} given twice");
            }
            let tile = d.children[node as usize];
            assert_eq!(tile & layout::OCTREE_SUBDIVIDE, 0, "flag left set");
            if l + 1 == depth as usize {
                // A leaf: the mask of its occupied voxels, then the first of their sums.
                let mask = (0..8u32)
                    .filter(|o| {
                        let k = [o & 1, (o >> 1) & 1, o >> 2];
                        voxels.contains(&std::array::from_fn(|a| 2 * c[a] + k[a]))
                    })
                    .fold(0, |m, o| m | 1 << o);
                assert_eq!(tile & 0xff, mask, "leaf {node}: voxel mask");
                if mask != 0 {
                    leaf_sums.push((tile >> 8, mask.count_ones()));
                }
            } else if occupied {
                let run = d.runs[l + 1]
                    .into_iter()
                    .find(|&(first, count)| tile >= first && tile + 8 <= first + count);
                let Some((first, _)) = run else {
                    panic!(
                        "level {l} node {node}: children {tile} outside level {}",
                        l + 1
                    );
                };
                assert_eq!((tile - first) % 8, 0, "tiles of 8");
                for o in 0..8u32 {
                    let expected = [
                        2 * c[0] + (o & 1),
                        2 * c[1] + ((o >> 1) & 1),
                        2 * c[2] + (o >> 2),
                    ];
                    assert_eq!(d.coords[(tile + o) as usize], expected);
                }
            } else {
                assert_eq!(tile, 0, "level {l} node {node}: children without voxels");
            }
        }
        by_coords.push(map);
    }
    // After a frame, the static bricks and sums of the static leaves that moving meshes
    // reached lie unused: they are restored next frame.
    assert!(leaf_bricks.iter().all(|&b| b < counters.leaf_bricks));
    assert!(interior_bricks
        .iter()
        .all(|&b| b < counters.interior_bricks));
    // The leaves' sums tile the sums buffer without overlaps (nor gaps, after a build).
    leaf_sums.sort_unstable();
    let mut next = 0;
    for (first, count) in &leaf_sums {
        if built {
            assert_eq!(*first, next, "leaf sums leave a gap");
        }
        assert!(*first >= next, "leaf sums overlap");
        next = first + count;
    }
    assert!(next <= counters.leaf_voxels);
    if built {
        assert_eq!(leaf_bricks.len() as u32, counters.leaf_bricks);
        assert_eq!(counters.leaf_voxels as usize, voxels.len());
        assert_eq!(interior_bricks.len() as u32, counters.interior_bricks);
    }

    // The node grid: per cell, its node, or where the descent to it stops (the deepest
    // node above it, which has no children).
    let grid = svo.download_words(&svo.node_grid).unwrap();
    let g = depth - 1 - layout::OCTREE_NODE_GRID_ABOVE_LEAVES;
    let side = 1u32 << g;
    let mut gaps = 0;
    for (i, &entry) in grid.iter().enumerate() {
        let i = i as u32;
        let c = [i % side, (i / side) % side, i / (side * side)];
        let expected = match by_coords[g as usize].get(&c) {
            Some(&node) => node,
            None => {
                gaps += 1;
                let above = (0..g)
                    .rev()
                    .find(|&l| by_coords[l as usize].contains_key(&c.map(|x| x >> (g - l))))
                    .expect("the root holds every cell");
                layout::OCTREE_GRID_GAP + above
            }
        };
        assert_eq!(entry, expected, "node grid cell {c:?}");
    }
    eprintln!("node grid at level {g}: {} cells, {gaps} empty", grid.len());

    // Neighbours: the node at the next coordinates of the same level, and symmetric.
    let mut links = 0;
    for (l, map) in by_coords.iter().enumerate() {
        for (c, &node) in map {
            for dir in 0..6 {
                let axis = dir / 2;
                let mut n = c.map(i64::from);
                n[axis] += if dir % 2 == 0 { 1 } else { -1 };
                let expected = u32::try_from(n[axis])
                    .ok()
                    .and_then(|_| map.get(&n.map(|x| x as u32)).copied())
                    .unwrap_or(layout::OCTREE_NO_NODE);
                // A static node keeps its static links; one to an appended node is
                // missing (the passes that follow links search the octree there).
                let unlinked = |from: u32, to: u32| from < d.static_nodes && to >= d.static_nodes;
                let got = d.neighbours[6 * node as usize + dir];
                if got != expected || expected == layout::OCTREE_NO_NODE {
                    assert!(
                        got == expected
                            || (got == layout::OCTREE_NO_NODE && unlinked(node, expected)),
                        "level {l} node {node} neighbour {dir}: {got} instead of {expected}"
                    );
                    continue;
                }
                let back = d.neighbours[6 * got as usize + (dir ^ 1)];
                assert!(
                    back == node || (back == layout::OCTREE_NO_NODE && unlinked(got, node)),
                    "neighbour links are symmetric"
                );
                links += 1;
            }
        }
    }
    eprintln!(
        "depth {depth}: {} fragments, {} voxels, nodes per level {:?}, {} neighbour links",
        d.fragments.len(),
        voxels.len(),
        d.levels.iter().map(Vec::len).collect::<Vec<_>>(),
        links
    );
    voxels
}

/// The octree of `scene` at `depth`: its structure against a CPU octree, its voxels
/// against the CPU reference voxelizer. Cut-out triangles (map_d) count only as places
/// where voxels may be: the CPU does not sample their textures.
fn check_octree(scene: Scene, depth: u32, voxelizer: Voxelizer) {
    let triangles = reference::world_triangles(&scene);
    let solid = reference::world_triangles_where(&scene, |m| m.coverage_texture.is_none());
    let settings = gi_settings(1 << depth, OCTREE, false);
    let settings = with_voxelizer(settings, voxelizer);
    let (ctx, renderer) = render_frames(scene, settings, &[]);
    let svo = octree(&renderer).store();
    let d = download(svo);
    let voxels = check_structure(svo, &d);

    // The fragments' voxels: every voxel a triangle touches (the CPU reference
    // voxelizer), and none farther than one voxel from a triangle.
    let grid = svo.grid;
    let exact = reference::voxelize(&solid, &grid);
    let near = reference::within_one_voxel(&triangles, &grid);
    let index = |v: &[u32; 3]| grid.index(v[0], v[1], v[2]);
    let mut cpu_voxels = HashSet::new();
    for k in 0..grid.resolution {
        for j in 0..grid.resolution {
            for i in 0..grid.resolution {
                if exact[grid.index(i, j, k)] {
                    cpu_voxels.insert([i, j, k]);
                }
            }
        }
    }
    let missing = cpu_voxels.difference(&voxels).count();
    let too_far = voxels.iter().filter(|v| !near[index(v)]).count();
    // The octree of the CPU reference voxels, level by level, against the GPU's (equal
    // unless a conservative extra voxel or a cut-out opens a node of its own).
    let cpu = cpu_octree(&cpu_voxels, svo.depth);
    let gpu = cpu_octree(&voxels, svo.depth);
    for (l, (c, g)) in cpu.iter().zip(&gpu).enumerate() {
        eprintln!(
            "level {l}: CPU reference octree {} occupied nodes, GPU {}",
            c.len(),
            g.len()
        );
        assert!(
            c.is_subset(g),
            "level {l}: a node of the CPU octree is missing"
        );
    }
    assert_eq!(missing, 0, "voxels the CPU marks but no fragment covers");
    assert_eq!(
        too_far, 0,
        "fragments farther than one voxel from every triangle"
    );
    assert_eq!(ctx.validation_messages(), 0);
}

fn cornell() -> Scene {
    let path = shared_file("scenes/cornell_box/CornellBox-Original.obj");
    Scene::load(&path, &LoadOptions::default()).unwrap()
}

/// The Cornell box of the point-light reference, as the reference renders it.
fn cornell_point() -> Scene {
    let path = shared_file("reference/cornell_point.scene.json");
    Scene::load(&path, &LoadOptions::REFERENCE).unwrap()
}

#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn octree_matches_cpu_octree_on_cornell_box() {
    let scene = cornell();
    for depth in [6, 7] {
        for voxelizer in [Voxelizer::Raster, Voxelizer::Compute] {
            check_octree(scene.clone(), depth, voxelizer);
        }
    }
}

#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn octree_matches_cpu_octree_on_sponza() {
    let path = shared_file("scenes/crytek_sponza/sponza.obj");
    let options = LoadOptions::REFERENCE;
    // The rasterizer only: lavapipe runs the compute voxelizer's 262,087 workgroups for
    // minutes (the Cornell box's test covers it).
    check_octree(Scene::load(&path, &options).unwrap(), 7, Voxelizer::Raster);
}

/// Unpacks an RGBA8 word.
fn rgba(v: u32) -> [f32; 4] {
    [v & 0xff, (v >> 8) & 0xff, (v >> 16) & 0xff, v >> 24].map(|c| c as f32)
}

/// Every leaf-brick voxel holds the mean of its fragments' albedo, normal and emission;
/// voxels without fragments are empty.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn leaf_bricks_average_their_fragments() {
    let scene = cornell();
    let (ctx, renderer) = build(scene, 6, None);
    let svo = octree(&renderer).store();
    let d = download(svo);
    let depth = svo.depth;
    let leaf_of: HashMap<[u32; 3], u32> = d.levels[depth as usize - 1]
        .iter()
        .map(|&n| (d.coords[n as usize], n))
        .collect();
    let side = svo.pools.leaf_side;
    let edge = side * layout::OCTREE_ATTRIBUTE_BRICK;
    let texel_of = |v: [u32; 3]| -> usize {
        let brick = d.bricks[leaf_of[&v.map(|c| c >> 1)] as usize];
        let origin = [brick % side, (brick / side) % side, brick / (side * side)];
        let t = [0, 1, 2].map(|a| origin[a] * layout::OCTREE_ATTRIBUTE_BRICK + (v[a] & 1));
        (t[0] + edge * (t[1] + edge * t[2])) as usize
    };
    let mut sums: HashMap<usize, ([[f64; 3]; 3], u32)> = HashMap::new();
    for f in &d.fragments {
        let entry = sums.entry(texel_of(unpack(f.position))).or_default();
        for (a, word) in [f.albedo, f.normal, f.emission].into_iter().enumerate() {
            for c in 0..3 {
                entry.0[a][c] += f64::from(rgba(word)[c]);
            }
        }
        entry.1 += 1;
    }
    let mut worst = [0.0f64; 3];
    for (a, name) in ["albedo", "normal", "emission"].iter().enumerate() {
        let texels = svo.download_leaf_attribute(a).unwrap();
        for (t, &word) in texels.iter().enumerate() {
            let got = rgba(word);
            match sums.get(&t) {
                None => assert_eq!(word, 0, "{name}: texel {t} without fragments is not empty"),
                Some((sum, count)) => {
                    assert_eq!(got[3] as u32, (*count).min(255), "{name}: fragment count");
                    for c in 0..3 {
                        let mean = sum[a][c] / f64::from(*count);
                        worst[a] = worst[a].max((f64::from(got[c]) - mean).abs());
                    }
                }
            }
        }
    }
    eprintln!(
        "{} voxels from {} fragments; largest difference from the CPU mean (of 255): albedo {:.2}, normal {:.2}, emission {:.2}",
        sums.len(),
        d.fragments.len(),
        worst[0],
        worst[1],
        worst[2]
    );
    // Exact sums, one rounding: within half a step of the exact mean.
    assert!(worst.iter().all(|w| *w <= 0.5), "{worst:?}");
    assert_eq!(ctx.validation_messages(), 0);
}

/// Pools far too small are reported, grown and the build runs again, giving the octree
/// a build with room to spare gives.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn tiny_pools_grow_and_rebuild() {
    let scene = cornell();
    let tiny = Capacities {
        fragments: 64,
        nodes: 9,
        leaf_bricks: 1,
        interior_bricks: 1,
        leaf_voxels: 1,
    };
    let (ctx, grown) = build(scene.clone(), 6, Some(tiny));
    let (_, roomy) = build(scene, 6, None);
    let (a, b) = (octree(&grown).store(), octree(&roomy).store());
    let report = a.report().unwrap();
    eprintln!("{}", report.regrowths.join("\n"));
    assert!(!report.regrowths.is_empty());
    assert!(report.regrowths[0].contains("voxel-fragment list: 64 entries"));
    let named = [
        "node pool",
        "leaf brick pool",
        "interior brick pool",
        "leaf voxel sums",
    ];
    for pool in named {
        assert!(
            report.regrowths.iter().any(|r| r.contains(pool)),
            "no report names the {pool}"
        );
    }
    let (ca, cb) = (report.counters, b.report().unwrap().counters);
    assert_eq!(
        (
            ca.fragment_count,
            ca.node_count,
            ca.leaf_bricks,
            ca.interior_bricks
        ),
        (
            cb.fragment_count,
            cb.node_count,
            cb.leaf_bricks,
            cb.interior_bricks
        )
    );
    let (da, db) = (download(a), download(b));
    assert_eq!(da.levels, db.levels);
    check_structure(a, &da);
    assert_eq!(ctx.validation_messages(), 0);
}

fn halves(bytes: &[u8]) -> Vec<[f32; 4]> {
    bytes
        .chunks_exact(8)
        .map(|t| {
            std::array::from_fn(|i| half::f16::from_le_bytes([t[2 * i], t[2 * i + 1]]).to_f32())
        })
        .collect()
}

/// A radiance pool as downloaded: RGBA per texel of an image `width` x `edge` x `edge`.
struct Pool {
    texels: Vec<[f32; 4]>,
    width: u32,
    edge: u32,
}

impl Pool {
    fn at(&self, p: [u32; 3]) -> [f32; 4] {
        self.texels[(p[0] + self.width * (p[1] + self.edge * p[2])) as usize]
    }
}

/// Texel `t` (-1..=2 per axis: the voxels at 0 and 1, the border around) of brick `brick`
/// of a pool with `side` bricks per edge, direction `d`'s copy.
fn brick_texel(brick: u32, side: u32, t: [i32; 3], d: u32) -> [u32; 3] {
    let e = layout::OCTREE_RADIANCE_BRICK;
    let origin = [brick % side, (brick / side) % side, brick / (side * side)];
    std::array::from_fn(|a| {
        let shift = if a == 0 { d * side * e } else { 0 };
        (origin[a] * e + shift) as i32 + 1 + t[a]
    })
    .map(|c| c as u32)
}

/// Each voxel of each brick of `level`: (node, brick, node coordinates, voxel in the brick).
fn brick_voxels(
    d: &Downloaded,
    level: usize,
) -> impl Iterator<Item = (u32, u32, [u32; 3], [u32; 3])> + '_ {
    d.levels[level]
        .iter()
        .copied()
        .filter(|&node| d.bricks[node as usize] != layout::OCTREE_NO_BRICK)
        .flat_map(move |node| {
            (0..8u32).map(move |o| {
                let k = [o & 1, (o >> 1) & 1, o >> 2];
                (node, d.bricks[node as usize], d.coords[node as usize], k)
            })
        })
}

/// Every interior brick equals the CPU filter (`gi::reference`) of the level below as
/// downloaded, the leaves' radiance seen through their normals' facing weights, and with
/// the planes (`Store::planes`) its planes and coverage equal the dense grid's CPU twin's; every
/// brick's border holds the voxels of the neighbouring bricks (zero where the octree is
/// empty, the edge voxel repeated at the grid's edge), in every slot.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn bricks_filter_and_borders_match_cpu() {
    let scene = cornell_point();
    let depth = 6;
    let store = Store::Octree {
        capacities: None,
        planes: true,
    };
    let (ctx, renderer) = render_frames(scene, gi_settings(1 << depth, store, false), &[0.0]);
    let svo = octree(&renderer).store();
    let d = download(svo);
    let p = &svo.pools;
    let read = |image: &crate::vk::Image| Pool {
        texels: halves(&read_radiance_image(svo, image)),
        width: image.desc.extent.width,
        edge: image.desc.extent.height,
    };
    let leaf = read(&p.leaf_radiance);
    let interior = read(&p.directional);
    // Every texel is finite, those of the bricks not in use too: the sampler fetches
    // beyond a brick's border, weighted 0, and 0 times a NaN is a NaN.
    for (name, pool) in [("leaf radiance", &leaf), ("interior bricks", &interior)] {
        let bad = pool
            .texels
            .iter()
            .flatten()
            .filter(|v| !v.is_finite())
            .count();
        assert_eq!(bad, 0, "{name}: {bad} values not finite");
    }
    let normals = svo.download_leaf_attribute(1).unwrap();
    let attribute_edge = p.leaf_side * layout::OCTREE_ATTRIBUTE_BRICK;

    // The packed normal of voxel k of leaf brick `brick`.
    let normal_word = |brick: u32, k: [u32; 3]| {
        let side = p.leaf_side;
        let a = [brick % side, (brick / side) % side, brick / (side * side)];
        let nt: [u32; 3] = std::array::from_fn(|i| a[i] * layout::OCTREE_ATTRIBUTE_BRICK + k[i]);
        normals[(nt[0] + attribute_edge * (nt[1] + attribute_edge * nt[2])) as usize]
    };
    // Level l's voxels as a dense grid of 2^(l+1) per axis (slot `dir` above the leaves;
    // the leaves seen along it through their facing weights with `facing`), from the
    // bricks; zero where there is no brick.
    let dense = |level: usize, dir: u32, facing: bool| -> Vec<[f32; 4]> {
        let n = 2u32 << level;
        let mut grid = vec![[0.0f32; 4]; (n as usize).pow(3)];
        let is_leaf = level + 1 == depth as usize;
        for (_, brick, c, k) in brick_voxels(&d, level) {
            let t = k.map(|x| x as i32);
            let value = if is_leaf {
                let v = leaf.at(brick_texel(brick, p.leaf_side, t, 0));
                // The filter sees a leaf voxel through its normal's facing weight.
                let word = normal_word(brick, k);
                if facing {
                    reference::seen_facing(word, v, dir as usize)
                } else {
                    v
                }
            } else {
                interior.at(brick_texel(brick, p.interior_side, t, dir))
            };
            let g: [u32; 3] = std::array::from_fn(|i| 2 * c[i] + k[i]);
            grid[(g[0] + n * (g[1] + n * g[2])) as usize] = value;
        }
        grid
    };

    let close = |a: [f32; 4], b: [f32; 4]| {
        a.iter()
            .zip(&b)
            .all(|(x, y)| (x - y).abs() <= 2e-3 + 2e-3 * y.abs())
    };
    let mut worst = 0.0f32;
    let mut checked = 0;
    for level in (0..depth as usize - 1).rev() {
        let n = 2u32 << level;
        for dir in 0..6u32 {
            let below = dense(level + 1, dir, true);
            let cpu = reference::filter_directional(&below, 2 * n, dir as usize);
            for (node, brick, c, k) in brick_voxels(&d, level) {
                let g: [u32; 3] = std::array::from_fn(|i| 2 * c[i] + k[i]);
                let expected = cpu[(g[0] + n * (g[1] + n * g[2])) as usize];
                let got = interior.at(brick_texel(
                    brick,
                    p.interior_side,
                    k.map(|x| x as i32),
                    dir,
                ));
                for (x, y) in got.iter().zip(&expected) {
                    worst = worst.max((x - y).abs());
                }
                assert!(close(got, expected), "level {level} node {node} voxel {k:?} direction {dir}: GPU {got:?}, CPU {expected:?}");
                checked += 1;
            }
        }
    }
    eprintln!("{checked} interior voxels x directions match the CPU filter, largest difference {worst:.2e}");

    // The planes and coverage: the first interior level from the leaves' opacity and
    // normals, each level above from the one below as downloaded.
    let leaves = 1u32 << depth;
    let mut opacity = vec![0.0f32; (leaves as usize).pow(3)];
    let mut leaf_normals = vec![0u32; opacity.len()];
    for (_, brick, c, k) in brick_voxels(&d, depth as usize - 1) {
        let g: [u32; 3] = std::array::from_fn(|i| 2 * c[i] + k[i]);
        let i = (g[0] + leaves * (g[1] + leaves * g[2])) as usize;
        opacity[i] = leaf.at(brick_texel(brick, p.leaf_side, k.map(|x| x as i32), 0))[3];
        leaf_normals[i] = normal_word(brick, k);
    }
    let (mut planes, coverage) = reference::filter_planes_base(&opacity, &leaf_normals, leaves);
    let mut coverage: Vec<[f32; 4]> = coverage.iter().map(|&c| [c, 0.0, 0.0, 0.0]).collect();
    let (mut planar, mut covered) = (0, 0);
    for level in (0..depth as usize - 1).rev() {
        let n = 2u32 << level;
        let gpu_planes = dense(level, layout::PLANE_SLOT, false);
        let gpu_coverage = dense(level, layout::COVERAGE_SLOT, false);
        for (node, _, c, k) in brick_voxels(&d, level) {
            let g: [u32; 3] = std::array::from_fn(|i| 2 * c[i] + k[i]);
            let i = (g[0] + n * (g[1] + n * g[2])) as usize;
            for (what, got, expected) in [
                ("plane", gpu_planes[i], planes[i]),
                ("coverage", gpu_coverage[i], coverage[i]),
            ] {
                for (x, y) in got.iter().zip(&expected) {
                    worst = worst.max((x - y).abs());
                }
                assert!(
                    close(got, expected),
                    "level {level} node {node} voxel {k:?} {what}: GPU {got:?}, CPU {expected:?}"
                );
            }
            let [x, y, z, _] = gpu_planes[i];
            if gpu_coverage[i][0] > 0.05 {
                covered += 1;
                planar += usize::from((x * x + y * y + z * z).sqrt() >= 0.9 * gpu_coverage[i][0]);
            }
        }
        planes = reference::filter_mean(&gpu_planes, n);
        coverage = reference::filter_mean(&gpu_coverage, n);
    }
    eprintln!(
        "the planes match the CPU filter too (largest difference so far {worst:.2e}); \
         {planar} of {covered} covered cells planar"
    );
    assert!(2 * planar > covered, "{planar} of {covered} cells planar");

    // Borders, at every level: the voxel of the dense grid there, clamped to the grid.
    let mut borders = 0;
    for level in 0..depth as usize {
        let is_leaf = level + 1 == depth as usize;
        let n = 2i32 << level;
        for dir in 0..if is_leaf { 1 } else { p.slots } {
            let grid = dense(level, dir, false);
            for &node in &d.levels[level] {
                let brick = d.bricks[node as usize];
                if brick == layout::OCTREE_NO_BRICK {
                    continue;
                }
                let c = d.coords[node as usize].map(|x| x as i32);
                for i in 0..64 {
                    let t = [i & 3, (i >> 2) & 3, i >> 4].map(|x| x - 1);
                    if t.iter().all(|x| (0..=1).contains(x)) {
                        continue;
                    }
                    let g: [i32; 3] = std::array::from_fn(|a| (2 * c[a] + t[a]).clamp(0, n - 1));
                    let expected = grid[(g[0] + n * (g[1] + n * g[2])) as usize];
                    let side = if is_leaf {
                        p.leaf_side
                    } else {
                        p.interior_side
                    };
                    let pool = if is_leaf { &leaf } else { &interior };
                    let got = pool.at(brick_texel(brick, side, t, dir));
                    assert_eq!(
                        got, expected,
                        "level {level} node {node} border {t:?} direction {dir}"
                    );
                    borders += 1;
                }
            }
        }
    }
    eprintln!("{borders} border texels hold their neighbours' voxels");
    assert!(checked > 0 && borders > 0);
    assert_eq!(ctx.validation_messages(), 0);
}

/// The occupied leaf voxels (with albedo) and the index of each one's texel in the leaf
/// attribute images, sorted by voxel; with the albedo image.
fn leaf_texels(svo: &Octree, d: &Downloaded) -> (Vec<([u32; 3], usize)>, Vec<u32>) {
    let albedo = svo.download_leaf_attribute(0).unwrap();
    let side = svo.pools.leaf_side;
    let edge = side * layout::OCTREE_ATTRIBUTE_BRICK;
    let mut voxels = Vec::new();
    for (_, brick, c, k) in brick_voxels(d, svo.depth as usize - 1) {
        let o = [brick % side, (brick / side) % side, brick / (side * side)];
        let t: [u32; 3] = std::array::from_fn(|a| o[a] * layout::OCTREE_ATTRIBUTE_BRICK + k[a]);
        let i = (t[0] + edge * (t[1] + edge * t[2])) as usize;
        if albedo[i] != 0 {
            voxels.push((std::array::from_fn(|a| 2 * c[a] + k[a]), i));
        }
    }
    voxels.sort_unstable();
    (voxels, albedo)
}

/// A radiance image of the octree (RGBA half floats), as downloaded.
fn read_radiance_image(svo: &Octree, image: &crate::vk::Image) -> Vec<u8> {
    crate::vk::read_back_image(
        &svo.ctx,
        image,
        0,
        image.desc.extent,
        8,
        super::RADIANCE_USE,
    )
    .unwrap()
}

/// Nodes per level, and the leaf voxels with their packed albedo (sorted), as they are
/// after the last frame.
#[allow(clippy::type_complexity)]
fn leaf_snapshot(r: &Renderer) -> (Vec<u32>, Vec<([u32; 3], u32)>) {
    let svo = octree(r).store();
    let d = download(svo);
    let (texels, albedo) = leaf_texels(svo, &d);
    let voxels = texels.into_iter().map(|(v, i)| (v, albedo[i])).collect();
    let nodes: Vec<u32> = d.levels.iter().map(|l| l.len() as u32).collect();
    (nodes, voxels)
}

/// A mesh moving across the box leaves no nodes or voxels behind: after frames at three
/// times, the octree (nodes per level, leaf voxels and their albedo) equals a fresh build
/// at the last time and a full rebuild (`--full-update`), and differs from the first
/// time's. Its structure matches a CPU octree of the static and moving fragments, and
/// the static part is as its build left it: the same runs of nodes per level, and every
/// static node's entry restored but where the moving cube reached it. With either
/// voxelizer.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn moving_mesh_leaves_no_nodes_behind() {
    let cornell = shared_file("scenes/cornell_box/CornellBox-Original.obj");
    let dir = std::env::temp_dir().join(format!("voxcone-svo-moving-{}", std::process::id()));
    let scene = moving_cube_scene(&cornell, &dir, false);
    for voxelizer in [Voxelizer::Raster, Voxelizer::Compute] {
        check_moving_mesh(scene.clone(), voxelizer);
    }
    std::fs::remove_dir_all(&dir).ok();
}

fn check_moving_mesh(scene: Scene, voxelizer: Voxelizer) {
    let structure = OCTREE;
    let settings = |full_update| with_voxelizer(gi_settings(64, structure, full_update), voxelizer);
    let (ctx, moved) = render_frames(scene.clone(), settings(false), &[0.0, 0.5, 1.0]);
    let (_, fresh) = render_frames(scene.clone(), settings(false), &[1.0]);
    let (_, full) = render_frames(scene.clone(), settings(true), &[1.0]);
    let (_, start) = render_frames(scene, settings(false), &[0.0]);

    let svo = octree(&moved).store();
    let d = download(svo);
    check_structure(svo, &d);
    let statics = &svo.statics;
    let report = svo.report().unwrap();
    assert!(statics.saved);
    assert_eq!(statics.nodes, report.counters.node_count);
    assert_eq!(d.static_nodes, statics.nodes);
    for (l, runs) in d.runs.iter().enumerate() {
        assert_eq!(runs[0], statics.levels[l], "level {l}: static run");
    }
    let kept = svo.download_words(&svo.pools.static_children).unwrap();
    let leaf_level = svo.depth as usize - 1;
    let mut reached = [0; 2];
    for (l, nodes) in d.levels.iter().enumerate() {
        for &node in nodes.iter().filter(|&&n| n < statics.nodes) {
            let (now, was) = (d.children[node as usize], kept[node as usize]);
            if now == was {
                continue;
            }
            if l == leaf_level {
                // Copied on write: its static voxels and more, new sums and brick.
                assert_eq!(
                    now & was & 0xff,
                    was & 0xff,
                    "leaf {node} lost static voxels"
                );
                assert!(d.bricks[node as usize] >= statics.leaf_bricks);
                assert!(now >> 8 >= statics.leaf_voxels);
                reached[0] += 1;
            } else {
                // Empty in the static part; children appended now.
                assert_eq!(was, 0, "level {l} node {node}: static children replaced");
                assert!(now >= statics.nodes);
                reached[1] += 1;
            }
        }
    }
    eprintln!(
        "static part: {} nodes, runs {:?}; reached by the cube: {} static leaves, {} empty \
         static nodes",
        statics.nodes, statics.levels, reached[0], reached[1]
    );
    assert!(reached[0] > 0, "the cube reached no static leaf");

    let (moved, fresh, full, start) = (
        leaf_snapshot(&moved),
        leaf_snapshot(&fresh),
        leaf_snapshot(&full),
        leaf_snapshot(&start),
    );
    eprintln!(
        "nodes per level: moved {:?}, fresh {:?}, full {:?}, start {:?}; leaf voxels {} / {} / \
         {} / {}",
        moved.0,
        fresh.0,
        full.0,
        start.0,
        moved.1.len(),
        fresh.1.len(),
        full.1.len(),
        start.1.len()
    );
    assert_ne!(start.1, fresh.1, "the cube did not move");
    for (name, other) in [("a fresh build", &fresh), ("a full rebuild", &full)] {
        assert_eq!(moved.0, other.0, "nodes per level differ from {name}");
        assert!(
            moved.1 == other.1,
            "leaf voxels or albedo differ from {name}"
        );
    }
    assert_eq!(ctx.validation_messages(), 0);
}

/// Per occupied leaf voxel, its direct light (RGBA half floats), sorted by voxel.
fn leaf_direct(r: &Renderer) -> Vec<([u32; 3], [u16; 4])> {
    let svo = octree(r).store();
    let bytes = read_radiance_image(svo, &svo.pools.leaf_direct);
    let direct: &[[u16; 4]] = bytemuck::cast_slice(&bytes);
    let (texels, _) = leaf_texels(svo, &download(svo));
    texels.into_iter().map(|(v, i)| (v, direct[i])).collect()
}

/// Around a moving mesh, voxel shading shades again only the voxels whose light can have
/// changed (in new bricks, or with a light's path through where the mesh was or is),
/// yet misses none: after frames of a cube moving through the box, lit by a point light
/// (a cube of shadow maps) and a directional light through the open side, every leaf
/// voxel's direct light equals what shading every voxel every frame gives, bit for bit;
/// with shadow maps and with soft-shadow cones (a ray march through the voxels).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn shading_what_moving_meshes_change_misses_nothing() {
    let cornell = shared_file("scenes/cornell_box/CornellBox-Original.obj");
    let dir = std::env::temp_dir().join(format!("voxcone-svo-cull-{}", std::process::id()));
    let mut scene = moving_cube_scene(&cornell, &dir, false);
    scene.lights.push(Light {
        kind: LightKind::Point,
        position: glam::Vec3::new(0.2, 1.5, 0.1),
        intensity: glam::Vec3::splat(1.5),
        orbit: None,
    });
    scene.lights.push(Light {
        kind: LightKind::Directional {
            direction: glam::Vec3::new(0.3, -0.5, -1.0).normalize(),
        },
        position: glam::Vec3::ZERO,
        intensity: glam::Vec3::splat(2.0),
        orbit: None,
    });
    let times = [0.0, 0.3, 0.6, 0.9, 1.2, 1.5];
    for shadow_cones in [false, true] {
        let mut settings = gi_settings(64, OCTREE, false);
        cone_settings(&mut settings).shadow_cones = shadow_cones;
        let run = |every: bool| {
            render_frames_with(scene.clone(), settings.clone(), &times, |r, _| {
                octree_mut(r).store_mut().shade_every_voxel = every;
            })
        };
        let (ctx, culled) = run(false);
        let (_, every) = run(true);
        assert_eq!(
            octree(&culled).store().culled_frames as usize,
            times.len() - 1,
            "voxel shading culled in every frame after the first"
        );
        let (a, b) = (leaf_direct(&culled), leaf_direct(&every));
        assert_eq!(a.len(), b.len());
        let lit = b.iter().filter(|(_, t)| t[..3] != [0; 3]).count();
        let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        eprintln!(
            "shadow cones {shadow_cones}: {differ} of {} leaf voxels' direct light differ ({lit} \
             lit)",
            b.len()
        );
        assert!(lit > b.len() / 4);
        assert_eq!(differ, 0, "culled voxel shading missed a change");
        assert_eq!(ctx.validation_messages(), 0);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// `--full-update` voxelizes every mesh and rebuilds the octree every frame: the same
/// octree as the build that keeps it.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn full_update_rebuilds_the_same_octree() {
    let scene = cornell_point();
    let structure = OCTREE;
    let (ctx, full) = render_frames(scene.clone(), gi_settings(64, structure, true), &[0.0, 0.5]);
    let (_, kept) = render_frames(scene, gi_settings(64, structure, false), &[0.0, 0.5]);
    let (full, kept) = (leaf_snapshot(&full), leaf_snapshot(&kept));
    eprintln!("nodes per level {:?}, {} leaf voxels", full.0, full.1.len());
    assert_eq!(full.0, kept.0);
    assert!(full.1 == kept.1, "leaf voxels or albedo differ");
    assert_eq!(ctx.validation_messages(), 0);
}

/// Around moving meshes every frame gives their nodes (and the static leaves they reach)
/// new bricks, and the light each voxel gathered is carried over by voxel: frames at a fixed time add one bounce
/// each and converge to what one frame with every bounce gives.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn carried_light_converges_to_all_bounces() {
    let cornell = shared_file("scenes/cornell_box/CornellBox-Original.obj");
    let dir = std::env::temp_dir().join(format!("voxcone-svo-carry-{}", std::process::id()));
    let scene = moving_cube_scene(&cornell, &dir, false);
    let settings = gi_settings(64, OCTREE, false);
    let (ctx, carried) = render_frames(scene.clone(), settings.clone(), &[1.0; 9]);
    let (_, once) = render_frames(scene, settings, &[1.0]);
    // Total leaf radiance (the bounces add light; direct light is the same in both).
    let total = |r: &Renderer| -> [f64; 3] {
        let svo = octree(r).store();
        let d = download(svo);
        let image = &svo.pools.leaf_radiance;
        let bytes = read_radiance_image(svo, image);
        let pool = Pool {
            texels: halves(&bytes),
            width: image.desc.extent.width,
            edge: image.desc.extent.height,
        };
        let mut sum = [0.0f64; 3];
        for (_, brick, _, k) in brick_voxels(&d, svo.depth as usize - 1) {
            let v = pool.at(brick_texel(
                brick,
                svo.pools.leaf_side,
                k.map(|x| x as i32),
                0,
            ));
            for c in 0..3 {
                sum[c] += f64::from(v[c]);
            }
        }
        sum
    };
    let (a, b) = (total(&carried), total(&once));
    eprintln!("total leaf radiance: carried over 9 frames {a:?}, one frame of all bounces {b:?}");
    for c in 0..3 {
        assert!((a[c] / b[c] - 1.0).abs() < 0.03, "{a:?} against {b:?}");
    }
    assert_eq!(ctx.validation_messages(), 0);
    std::fs::remove_dir_all(&dir).ok();
}

/// After frames of `scene` at `times` (with `before` run ahead of each), the levels the
/// update lists filtered (and every brick's border) equal what a full filter of the
/// leaves as stored gives, bit for bit; with each node's work shared by one workgroup
/// (as on a CPU driver) and by `OCTREE_LIST_SLICES` (as on a GPU).
fn check_update_lists(
    scene: Scene,
    times: &[f32],
    bounces: u32,
    mut before: impl FnMut(&mut Renderer, usize),
    what: &str,
) {
    for slices in [1, layout::OCTREE_LIST_SLICES] {
        check_update_lists_sliced(scene.clone(), times, bounces, &mut before, what, slices);
    }
}

fn check_update_lists_sliced(
    scene: Scene,
    times: &[f32],
    bounces: u32,
    before: &mut impl FnMut(&mut Renderer, usize),
    what: &str,
    slices: u32,
) {
    let mut settings = gi_settings(64, OCTREE, false);
    cone_settings(&mut settings).cones.bounces = bounces;
    let what = format!("{what}, {slices} workgroups a node");
    let (ctx, renderer) = render_frames_with(scene, settings, times, |r, i| {
        octree_mut(r).store_mut().bricks.list_slices = slices;
        before(r, i);
    });
    let gi = octree(&renderer);
    let svo = gi.store();
    let images = || {
        [&svo.pools.leaf_radiance, &svo.pools.directional]
            .map(|image| read_radiance_image(svo, image))
    };
    let listed = images();
    svo.full_filter(renderer.first_frame_set(), gi.set())
        .unwrap();
    let full = images();
    for (name, (a, b)) in ["leaf radiance", "directional"]
        .iter()
        .zip(listed.iter().zip(&full))
    {
        let a: &[u16] = bytemuck::cast_slice(a);
        let b: &[u16] = bytemuck::cast_slice(b);
        let differ = a.iter().zip(b).filter(|(x, y)| x != y).count();
        let nonzero = b.iter().filter(|&&x| x != 0).count();
        eprintln!(
            "{what}: {name}: {differ} of {} values differ from a full filter ({nonzero} \
             nonzero)",
            a.len()
        );
        assert_eq!(differ, 0, "{what}: {name}: the update lists missed changes");
        assert!(nonzero > 0);
    }
    assert_eq!(ctx.validation_messages(), 0);
}

/// The update lists filter only what changed, yet leave the filtered levels exactly as a
/// full filter would: after frames whose light moved, and after frames with it still.
/// The first frames add bounces too.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn update_lists_filter_what_changed() {
    let scene = cornell_point();
    for still in [0, 3] {
        let moved = |renderer: &mut Renderer, i: usize| {
            if i < 6 - still {
                renderer.scene.lights[0].position.x += 0.05;
            }
        };
        let what = format!("light still for {still} frames");
        let bounces = ConeSettings::default().bounces;
        check_update_lists(scene.clone(), &[0.0; 6], bounces, moved, &what);
    }
}

/// Around a moving mesh the update lists also take the nodes where it was and is: the
/// nodes it leaves are filtered again, and their neighbours' borders copied again.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn update_lists_follow_moving_meshes() {
    let cornell = shared_file("scenes/cornell_box/CornellBox-Original.obj");
    let dir = std::env::temp_dir().join(format!("voxcone-svo-lists-{}", std::process::id()));
    for glow in [false, true] {
        let scene = moving_cube_scene(&cornell, &dir, glow);
        let times = [0.0, 0.3, 0.6, 0.9, 1.2, 1.2, 1.2];
        // The glowing cube lights nothing else without bounces: only the octree's
        // changes mark where it was.
        let bounces = if glow {
            1
        } else {
            ConeSettings::default().bounces
        };
        let what = format!("cube (glowing: {glow}, bounces {bounces}) moved, then still");
        check_update_lists(scene, &times, bounces, |_, _| {}, &what);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// In a static scene the bounces stop once they have converged (nothing on the update
/// lists, no voxel's direct light changed: the same light would be stored again), and a
/// light that moves starts them again.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn bounces_stop_once_converged() {
    let scene = cornell_point();
    let settings = gi_settings(64, OCTREE, false);
    let frames = 40;
    let mut dispatched = Vec::new();
    let (ctx, renderer) = render_frames_with(scene, settings, &vec![0.0; frames], |r, i| {
        if i + 1 == frames {
            r.scene.lights[0].position.x += 0.05;
        }
        if i > 0 {
            r.finish().unwrap();
            let svo = octree(r).store();
            let words = svo.download_words(&svo.pools.updates).unwrap();
            dispatched.push(words[(super::pools::BOUNCE_DISPATCH_OFFSET / 4) as usize]);
        }
    });
    let svo = octree(&renderer).store();
    let words = svo.download_words(&svo.pools.updates).unwrap();
    dispatched.push(words[(super::pools::BOUNCE_DISPATCH_OFFSET / 4) as usize]);
    eprintln!("bounce workgroups per frame: {dispatched:?}");
    let converged = dispatched.iter().position(|&g| g == 0);
    assert!(converged.is_some(), "the bounces never stopped");
    let still = &dispatched[converged.unwrap()..frames - 2];
    assert!(
        still.iter().all(|&g| g == 0),
        "the bounces started again by themselves"
    );
    assert!(
        *dispatched.last().unwrap() > 0,
        "the moved light did not start the bounces"
    );
    assert_eq!(ctx.validation_messages(), 0);
}
