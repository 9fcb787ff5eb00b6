//! Pinhole look-at camera (right-handed, +Y up).

use glam::{Mat4, Vec3};

use super::Aabb;

#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    /// Full vertical field of view.
    pub fov_y_deg: f32,
    pub near: f32,
    pub far: f32,
}

impl Camera {
    pub fn view(&self) -> Mat4 {
        Mat4::look_at_rh(self.position, self.target, self.up)
    }

    /// View to Vulkan clip space: depth 0..1, and y flipped so that image row 0 is the top.
    pub fn proj(&self, aspect: f32) -> Mat4 {
        let mut p = Mat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, self.near, self.far);
        p.y_axis.y = -p.y_axis.y;
        p
    }

    pub fn forward(&self) -> Vec3 {
        (self.target - self.position).normalize()
    }

    pub fn right(&self) -> Vec3 {
        self.forward().cross(self.up).normalize()
    }

    /// Near and far planes that hold `bounds` seen from the camera.
    pub fn fit_clip_planes(&mut self, bounds: &Aabb) {
        let diagonal = bounds.size().length().max(1e-3);
        self.near = (diagonal * 1e-3).max(1e-4);
        self.far = 4.0 * ((bounds.center() - self.position).length() + diagonal);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn projection_puts_up_at_the_top() {
        let camera = Camera {
            position: Vec3::new(0.0, 1.0, 3.9),
            target: Vec3::new(0.0, 1.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 39.3,
            near: 0.01,
            far: 100.0,
        };
        let vp = camera.proj(1.0) * camera.view();
        let ahead = vp.project_point3(Vec3::new(0.0, 1.0, 0.0));
        assert!(ahead.x.abs() < 1e-5 && ahead.y.abs() < 1e-5);
        let above = vp.project_point3(Vec3::new(0.0, 1.5, 0.0));
        assert!(above.y < 0.0, "row 0 is the top, so up is negative NDC y");
        let right = vp.project_point3(Vec3::new(0.5, 1.0, 0.0));
        assert!(right.x > 0.0);
    }
}
