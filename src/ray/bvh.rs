//! The CPU side of ray casting: the scene's triangles in world space, and a compressed
//! wide BVH over them (CWBVH, Ylitie et al. 2017: eight children a node, their boxes
//! quantized to bytes in the node's frame), built with obvhs (a PLOC BVH2 with
//! reinsertion, Meister et al. 2018, 2021, collapsed into the wide one), its triangles
//! in leaf order.

use glam::{Mat3, Vec3};
use obvhs::aabb::Aabb;
use obvhs::cwbvh::node::CwBvhNode;
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
            let flags = u32::from(material.cut_out()) * layout::RAY_CUT_OUT
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
    /// The longest path from the root to a leaf's node, in nodes (0 for an empty BVH).
    pub depth: u32,
}

impl Bvh {
    /// The BVH of `triangles`, to sit at node `node_offset` and triangle `triangle_offset`
    /// of the GPU's buffers (its indices point there), the root first.
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
        let mut params = if fast {
            BvhBuildParams::very_fast_build()
        } else {
            BvhBuildParams::medium_build()
        };
        // The most a CWBVH leaf holds (its count is unary in three bits).
        params.max_prims_per_leaf = 3;
        let mut core_time = std::time::Duration::ZERO;
        let bvh = obvhs::cwbvh::builder::build_cwbvh(&aabbs, params, &mut core_time);
        let nodes: Vec<BvhNode> = bvh
            .nodes
            .iter()
            .map(|node| {
                let mut moved = *node;
                moved.child_base_idx += node_offset;
                moved.primitive_base_idx += triangle_offset;
                bytemuck::cast(moved)
            })
            .collect();
        let order = &bvh.primitive_indices;
        Self {
            depth: depth(&bvh.nodes),
            nodes,
            triangles: order
                .iter()
                .map(|&i| triangles.triangles[i as usize])
                .collect(),
            shading: order
                .iter()
                .map(|&i| triangles.shading[i as usize])
                .collect(),
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

/// The longest path from the root (node 0) to a node, in nodes.
fn depth(nodes: &[CwBvhNode]) -> u32 {
    let mut deepest = 0;
    let mut stack = vec![(0usize, 1u32)];
    while let Some((i, d)) = stack.pop() {
        deepest = deepest.max(d);
        let node = &nodes[i];
        for child in 0..8 {
            if !node.is_leaf(child) {
                stack.push((node.child_node_index(child) as usize, d + 1));
            }
        }
    }
    deepest
}
