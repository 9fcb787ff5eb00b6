//! Pinhole look-at camera (right-handed, +Y up).

use glam::{Mat4, Vec3};

use super::Aabb;

/// The near plane's distance per unit of the scene's diagonal.
const NEAR_PER_DIAGONAL: f32 = 1e-6;

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Full vertical field of view.
    pub fov_y_deg: f32,
    /// The near plane; there is no far plane (reverse Z to infinity, see [`Camera::proj`]).
    pub near: f32,
}

impl Camera {
    /// A camera with a placeholder near plane, to be set by [`Camera::fit_clip_planes`].
    pub fn look_at(position: Vec3, target: Vec3, up: Vec3, fov_y_deg: f32) -> Self {
        Self {
            position,
            target,
            up,
            fov_y_deg,
            near: 0.01,
        }
    }

    /// World to view. Built in f64 and rounded once, so that it depends on the direction
    /// to the target and not on its distance: in f32, normalising (0, 0, -3.9) gave a
    /// forward a unit in the last place off (0, 0, -1), which moved which of two surfaces
    /// meeting at a corner a pixel on the corner shows (a glTF and an OBJ camera of the
    /// same view differed by 4e-4 RMSE).
    pub fn view(&self) -> Mat4 {
        glam::DMat4::look_at_rh(
            self.position.as_dvec3(),
            self.target.as_dvec3(),
            self.up.as_dvec3(),
        )
        .as_mat4()
    }

    /// View to Vulkan clip space with reverse Z to infinity: depth 1 at the near plane,
    /// falling as near / distance towards 0 at infinity (the sky's cleared depth), and y
    /// flipped so that image row 0 is the top (Vulkan's NDC y points down the
    /// framebuffer). A float depth buffer then keeps the same relative precision at every
    /// distance, so neither a near plane far inside the scene nor a far plane short of it
    /// is needed, whatever the scene's units.
    pub fn proj(&self, aspect: f32) -> Mat4 {
        let mut p =
            Mat4::perspective_infinite_reverse_rh(self.fov_y_deg.to_radians(), aspect, self.near);
        p.y_axis.y = -p.y_axis.y;
        p
    }

    pub fn forward(&self) -> Vec3 {
        (self.target - self.position).normalize()
    }

    /// The image's +x axis, as in the references' convention cross(forward, up).
    pub fn right(&self) -> Vec3 {
        self.forward().cross(self.up).normalize()
    }

    /// The near plane for a scene with world `bounds`: a millionth of its size, so that
    /// it follows the scene's units and the camera can come that close to a wall (reverse
    /// Z keeps depth precision relative to the distance, whatever the near plane).
    pub fn fit_clip_planes(&mut self, bounds: &Aabb) {
        self.near = bounds.diagonal().max(f32::MIN_POSITIVE) * NEAR_PER_DIAGONAL;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cornell_camera() -> Camera {
        Camera::look_at(
            Vec3::new(0.0, 1.0, 3.9),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::Y,
            39.3,
        )
    }

    #[test]
    fn view_depends_on_the_direction_to_the_target_only() {
        let near = Camera::look_at(
            Vec3::new(0.0, 1.0, 3.9),
            Vec3::new(0.0, 1.0, 2.9),
            Vec3::Y,
            40.0,
        );
        let far = Camera::look_at(
            Vec3::new(0.0, 1.0, 3.9),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::Y,
            40.0,
        );
        assert_eq!(near.view(), far.view());
        assert_eq!(far.view().row(2).truncate(), Vec3::Z, "forward exactly -Z");
    }

    #[test]
    fn projection_puts_up_at_the_top() {
        let camera = cornell_camera();
        let vp = camera.proj(1.0) * camera.view();
        let ahead = vp.project_point3(camera.target);
        assert!(ahead.x.abs() < 1e-5 && ahead.y.abs() < 1e-5, "{ahead}");
        assert!((0.0..1.0).contains(&ahead.z));
        let above = vp.project_point3(Vec3::new(0.0, 1.5, 0.0));
        assert!(
            above.y < 0.0,
            "row 0 is the top, so up is negative NDC y: {above}"
        );
        let right = vp.project_point3(camera.target + camera.right());
        assert!(right.x > 0.0, "{right}");
        assert!(camera.right().abs_diff_eq(Vec3::X, 1e-6));
        // Half the vertical field of view below the target lands on the bottom edge.
        let half = (camera.fov_y_deg * 0.5).to_radians().tan() * 3.9;
        let edge = vp.project_point3(camera.target - Vec3::Y * half);
        assert!((edge.y - 1.0).abs() < 1e-4, "{edge}");
    }

    #[test]
    fn depth_runs_from_one_at_near_to_zero_at_infinity() {
        let mut camera = cornell_camera();
        camera.fit_clip_planes(&Aabb {
            min: Vec3::new(-1.0, 0.0, -1.0),
            max: Vec3::new(1.0, 2.0, 1.0),
        });
        assert!((camera.near - 12f32.sqrt() * 1e-6).abs() < 1e-12);
        // In view space, to keep the camera's world position out of the rounding.
        let depth = |d: f32| camera.proj(1.5).project_point3(Vec3::new(0.0, 0.0, -d)).z;
        assert!(
            (depth(camera.near) - 1.0).abs() < 1e-6,
            "{}",
            depth(camera.near)
        );
        for d in [1.0, 1e3, 1e6] {
            let expected = camera.near / d;
            assert!(
                (depth(d) / expected - 1.0).abs() < 1e-5,
                "{d}: {}",
                depth(d)
            );
        }
        assert!((0.0..1e-30).contains(&depth(1e30)), "{}", depth(1e30));
    }
}
