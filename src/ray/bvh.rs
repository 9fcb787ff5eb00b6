//! The CPU side of ray casting: the scene's triangles in world space, a BVH2 over them
//! built with obvhs (PLOC, with reinsertion and leaf collapsing: Meister et al. 2018,
//! 2021), flattened into the GPU's layout with each leaf's triangles contiguous.

use glam::{Mat3, Vec3};
use obvhs::aabb::Aabb;
use obvhs::BvhBuildParams;

use crate::gpu_layout::{self as layout, BvhNode, RayShading, RayTriangle, RAY_NONE};
use crate::scene::{Mesh, Scene};

/// Triangles in world space, each with its intersection and shading data.
#[derive(Default)]
pub struct Triangles {
    pub corners: Vec<[Vec3; 3]>,
    pub triangles: Vec<RayTriangle>,
    pub shading: Vec<RayShading>,
}

impl Triangles {
    /// The triangles of the meshes `keep` accepts, at scene time `time_s`. Each keeps its
    /// index in the scene (meshes in order, triangles in index order, whether kept or not).
    pub fn of(scene: &Scene, time_s: f32, keep: impl Fn(&Mesh) -> bool) -> Self {
        let mut out = Self::default();
        let mut index = 0u32;
        for (m, mesh) in scene.meshes.iter().enumerate() {
            let count = (mesh.indices.len() / 3) as u32;
            if !keep(mesh) {
                index += count;
                continue;
            }
            let material = &scene.materials[mesh.material as usize];
            let cut_out = material.coverage_texture.is_some()
                || (material.dissolve < 1.0 && !material.refracts());
            let flags = u32::from(cut_out) * layout::RAY_CUT_OUT
                + u32::from(mesh.animation.is_some()) * layout::RAY_MOVING;
            let transform = scene.mesh_transform(m, time_s);
            let normals = Mat3::from_mat4(transform).inverse().transpose();
            for corners in mesh.indices.chunks_exact(3) {
                let v = [0, 1, 2].map(|k| mesh.vertices[corners[k] as usize]);
                let p = v.map(|v| transform.transform_point3(Vec3::from(v.position)));
                let n = v.map(|v| (normals * Vec3::from(v.normal)).normalize_or_zero());
                let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
                out.corners.push(p);
                out.triangles.push(RayTriangle {
                    v0: p[0].extend(f32::from_bits(mesh.material)).to_array(),
                    e1: e1.extend(f32::from_bits(index)).to_array(),
                    e2: e2.extend(f32::from_bits(flags)).to_array(),
                });
                out.shading.push(RayShading {
                    n0: n[0].extend(v[0].uv[0]).to_array(),
                    n1: n[1].extend(v[0].uv[1]).to_array(),
                    n2: n[2].extend(v[1].uv[0]).to_array(),
                    uv: [v[1].uv[1], v[2].uv[0], v[2].uv[1], 0.0],
                });
                index += 1;
            }
        }
        out
    }

    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
}

/// A BVH in the GPU's layout, its triangles in leaf order.
#[derive(Default)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    pub triangles: Vec<RayTriangle>,
    pub shading: Vec<RayShading>,
    /// The longest path from the root to a leaf, in nodes (0 for an empty BVH).
    pub depth: u32,
}

impl Bvh {
    /// The BVH of `triangles`, to sit at node `node_offset` and triangle `triangle_offset`
    /// of the GPU's buffers (its indices point there), laid out depth first: every inner
    /// node is followed by its first child, and the second child sits at the first's
    /// escape index, so a node's children are found from one read.
    /// `fast`: a quicker build of lower quality, for what is rebuilt every frame.
    pub fn build(
        triangles: &Triangles,
        node_offset: u32,
        triangle_offset: u32,
        fast: bool,
    ) -> Self {
        if triangles.is_empty() {
            return Self::default();
        }
        let aabbs: Vec<Aabb> = triangles
            .corners
            .iter()
            .map(|p| {
                let lo = p[0].min(p[1]).min(p[2]);
                let hi = p[0].max(p[1]).max(p[2]);
                Aabb::new(lo.to_array().into(), hi.to_array().into())
            })
            .collect();
        let params = if fast {
            BvhBuildParams::very_fast_build()
        } else {
            BvhBuildParams::medium_build()
        };
        let mut core_time = std::time::Duration::ZERO;
        let bvh = obvhs::bvh2::builder::build_bvh2(&aabbs, params, &mut core_time);
        let order: Vec<usize> = bvh.primitive_indices.iter().map(|&i| i as usize).collect();
        // Depth first, each node followed by its first child's subtree, then its second's;
        // each node's escape is where traversal goes on when it misses the node's box or
        // has tested its leaf: the node after its subtree (none after the last).
        let sizes = subtree_sizes(&bvh.nodes);
        let mut nodes: Vec<BvhNode> = Vec::with_capacity(bvh.nodes.len());
        let mut depth = 0;
        let mut stack = vec![(0usize, 1u32)];
        while let Some((i, d)) = stack.pop() {
            depth = depth.max(d);
            let node = &bvh.nodes[i];
            let next = nodes.len() + sizes[i];
            let escape = if next >= bvh.nodes.len() {
                RAY_NONE
            } else {
                next as u32 + node_offset
            };
            let leaf = if node.prim_count > 0 {
                (node.first_index + triangle_offset)
                    | node.prim_count << layout::RAY_LEAF_FIRST_BITS
            } else {
                let first = node.first_index as usize;
                stack.extend([(first + 1, d + 1), (first, d + 1)]);
                0
            };
            nodes.push(BvhNode {
                min_escape: Vec3::from(node.aabb.min.to_array())
                    .extend(f32::from_bits(escape))
                    .to_array(),
                max_leaf: Vec3::from(node.aabb.max.to_array())
                    .extend(f32::from_bits(leaf))
                    .to_array(),
            });
        }
        Self {
            nodes,
            triangles: order.iter().map(|&i| triangles.triangles[i]).collect(),
            shading: order.iter().map(|&i| triangles.shading[i]).collect(),
            depth,
        }
    }

    /// The root's index in the GPU's buffers, `RAY_NONE` for an empty BVH.
    pub fn root(&self, node_offset: u32) -> u32 {
        if self.nodes.is_empty() {
            RAY_NONE
        } else {
            node_offset
        }
    }
}

/// The number of nodes in each node's subtree, itself included.
fn subtree_sizes(nodes: &[obvhs::bvh2::node::Bvh2Node]) -> Vec<usize> {
    let mut sizes = vec![1; nodes.len()];
    // Post-order: a node's size once both children's are known.
    let mut stack = vec![(0usize, false)];
    while let Some((i, children_done)) = stack.pop() {
        let node = &nodes[i];
        if node.prim_count > 0 {
            continue;
        }
        let first = node.first_index as usize;
        if children_done {
            sizes[i] = 1 + sizes[first] + sizes[first + 1];
        } else {
            stack.extend([(i, true), (first, false), (first + 1, false)]);
        }
    }
    sizes
}
