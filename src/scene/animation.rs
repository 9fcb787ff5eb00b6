//! Simple scene animation: spinning or oscillating meshes, orbiting lights.

use glam::{Mat4, Quat, Vec3};

use super::Aabb;

/// Motion of a mesh, applied in object space before its scene-file transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Animation {
    /// Rotation about the mesh's bounds centre.
    Spin { axis: Vec3, deg_per_s: f32 },
    /// Translation `amplitude * sin(2 pi t / period_s)` along `axis`.
    Oscillate {
        axis: Vec3,
        amplitude: f32,
        period_s: f32,
    },
}

impl Animation {
    pub fn matrix(&self, local_bounds: &Aabb, t: f32) -> Mat4 {
        match *self {
            Animation::Spin { axis, deg_per_s } => {
                let c = local_bounds.center();
                let rotation =
                    Quat::from_axis_angle(axis.normalize(), (deg_per_s * t).to_radians());
                Mat4::from_translation(c) * Mat4::from_quat(rotation) * Mat4::from_translation(-c)
            }
            Animation::Oscillate {
                axis,
                amplitude,
                period_s,
            } => {
                let phase = std::f32::consts::TAU * t / period_s;
                Mat4::from_translation(axis.normalize() * amplitude * phase.sin())
            }
        }
    }
}

/// A light position rotating about `center` around `axis`, once per `period_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub center: Vec3,
    pub axis: Vec3,
    pub period_s: f32,
}

impl Orbit {
    pub fn apply(&self, position: Vec3, t: f32) -> Vec3 {
        let angle = std::f32::consts::TAU * t / self.period_s;
        self.center + Quat::from_axis_angle(self.axis.normalize(), angle) * (position - self.center)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_spin_and_zero_time_are_identity() {
        let bounds = Aabb {
            min: Vec3::new(1.0, 2.0, 3.0),
            max: Vec3::new(2.0, 4.0, 5.0),
        };
        let spin = Animation::Spin {
            axis: Vec3::Y,
            deg_per_s: 90.0,
        };
        assert!(spin.matrix(&bounds, 4.0).abs_diff_eq(Mat4::IDENTITY, 1e-5));
        let wobble = Animation::Oscillate {
            axis: Vec3::X,
            amplitude: 0.5,
            period_s: 2.0,
        };
        assert!(wobble
            .matrix(&bounds, 0.0)
            .abs_diff_eq(Mat4::IDENTITY, 1e-6));
        let orbit = Orbit {
            center: Vec3::ZERO,
            axis: Vec3::Y,
            period_s: 4.0,
        };
        assert!(orbit.apply(Vec3::X, 1.0).abs_diff_eq(Vec3::NEG_Z, 1e-5));
    }
}
