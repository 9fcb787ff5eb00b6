//! The grid the voxels tile, the same for both stores (the octree's is its effective
//! grid).

use glam::Vec3;

use crate::scene::{Aabb, Scene};

/// The cube the voxels tile: voxel (i, j, k) covers origin + [i, i+1) x [j, j+1) x [k, k+1)
/// times `voxel_size`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub origin: Vec3,
    pub voxel_size: f32,
    pub resolution: u32,
}

impl Grid {
    /// Linear index of voxel (i, j, k): x fastest, then y, then z (the GPU's layout).
    pub fn index(&self, i: u32, j: u32, k: u32) -> usize {
        let n = self.resolution as usize;
        i as usize + n * (j as usize + n * k as usize)
    }

    /// A cube around the scene's bounds over all times (moving meshes never leave it),
    /// with a little room so that surfaces on the bounds are not cut by the grid's edge.
    pub fn around(scene: &Scene, resolution: u32) -> Self {
        let bounds = scene.swept_bounds();
        let size = cube_edge(&bounds);
        Self {
            origin: bounds.center() - Vec3::splat(size * 0.5),
            voxel_size: size / resolution as f32,
            resolution,
        }
    }

    /// The edge of the cube [`Grid::around`] puts around the scene.
    pub fn extent_around(scene: &Scene) -> f32 {
        cube_edge(&scene.swept_bounds())
    }

    /// The voxels (first and last, each axis) that `bounds` touches, one more around
    /// (conservative voxelization dilates triangles by up to a voxel); `None` for empty
    /// bounds.
    pub fn voxels_of(&self, bounds: &Aabb) -> Option<[[i32; 3]; 2]> {
        if bounds.is_empty() {
            return None;
        }
        let voxel = |p: Vec3, extra: f32| {
            let v = ((p - self.origin) / self.voxel_size).floor() + Vec3::splat(extra);
            v.clamp(Vec3::splat(-2.0), Vec3::splat(self.resolution as f32 + 1.0))
                .as_ivec3()
                .to_array()
        };
        Some([voxel(bounds.min, -1.0), voxel(bounds.max, 1.0)])
    }
}

/// The edge of the cube around `bounds`: their largest extent with a little room. No floor
/// in scene units (the scene may be in kilometres or micrometres), only a grid for a scene
/// that is a single point.
fn cube_edge(bounds: &Aabb) -> f32 {
    let extent = (bounds.max - bounds.min).max_element();
    (if extent > 0.0 { extent } else { 1.0 }) * 1.04
}
