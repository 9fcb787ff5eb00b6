//! Simple scene animation: spinning or oscillating meshes, orbiting lights.

use std::f32::consts::TAU;

use glam::{Mat4, Quat, Vec3};

use super::Aabb;

/// Motion of a mesh, applied in object space before its scene-file transform.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Animation {
    /// Rotation about `axis` through the centre of the object's bounds.
    Spin { axis: Vec3, deg_per_s: f32 },
    /// Translation `amplitude * sin(2 pi t / period_s)` along `axis`.
    Oscillate {
        axis: Vec3,
        amplitude: f32,
        period_s: f32,
    },
}

impl Animation {
    /// Object-space motion at time `t` of an object whose bounds are `local_bounds`.
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
            } => Mat4::from_translation(axis.normalize() * amplitude * (TAU * t / period_s).sin()),
        }
    }

    /// Object-space bounds that hold `part` (bounds of a part of an object whose bounds
    /// are `object_bounds`) at every time of the motion: a spin sweeps the sphere about
    /// the object's centre through the part's farthest corner, an oscillation the part at
    /// both ends of its stroke.
    pub fn swept(&self, part: &Aabb, object_bounds: &Aabb) -> Aabb {
        if part.is_empty() {
            return *part;
        }
        match *self {
            Animation::Spin { .. } => {
                let c = object_bounds.center();
                let r = (part.min - c).abs().max((part.max - c).abs()).length();
                Aabb {
                    min: c - Vec3::splat(r),
                    max: c + Vec3::splat(r),
                }
            }
            Animation::Oscillate {
                axis, amplitude, ..
            } => {
                let stroke = axis.normalize() * amplitude;
                part.transformed(Mat4::from_translation(stroke))
                    .union(&part.transformed(Mat4::from_translation(-stroke)))
            }
        }
    }
}

/// A light position rotating about `center` around `axis` (right-handed), once per
/// `period_s`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub center: Vec3,
    pub axis: Vec3,
    pub period_s: f32,
}

impl Orbit {
    pub fn apply(&self, position: Vec3, t: f32) -> Vec3 {
        let rotation = Quat::from_axis_angle(self.axis.normalize(), TAU * t / self.period_s);
        self.center + rotation * (position - self.center)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOUNDS: Aabb = Aabb {
        min: Vec3::new(1.0, 2.0, 3.0),
        max: Vec3::new(2.0, 4.0, 5.0),
    };

    #[test]
    fn spin_turns_about_the_bounds_centre() {
        let spin = Animation::Spin {
            axis: Vec3::new(0.0, 2.0, 0.0),
            deg_per_s: 90.0,
        };
        assert!(
            spin.matrix(&BOUNDS, 4.0).abs_diff_eq(Mat4::IDENTITY, 1e-5),
            "360 degrees"
        );
        let quarter = spin.matrix(&BOUNDS, 1.0);
        let c = BOUNDS.center();
        assert!(quarter.transform_point3(c).abs_diff_eq(c, 1e-5));
        // A quarter turn about +Y takes +X to -Z.
        let p = quarter.transform_point3(c + Vec3::X);
        assert!(p.abs_diff_eq(c - Vec3::Z, 1e-5), "{p}");
    }

    #[test]
    fn oscillate_starts_at_rest_position() {
        let wobble = Animation::Oscillate {
            axis: Vec3::X,
            amplitude: 0.5,
            period_s: 2.0,
        };
        assert!(wobble
            .matrix(&BOUNDS, 0.0)
            .abs_diff_eq(Mat4::IDENTITY, 1e-6));
        let peak = wobble.matrix(&BOUNDS, 0.5).transform_point3(Vec3::ZERO);
        assert!(peak.abs_diff_eq(Vec3::new(0.5, 0.0, 0.0), 1e-6), "{peak}");
    }

    #[test]
    fn swept_bounds_hold_the_part_at_all_times() {
        let part = Aabb {
            min: Vec3::new(1.5, 2.0, 3.0),
            max: Vec3::new(2.0, 3.0, 4.0),
        };
        let motions = [
            Animation::Spin {
                axis: Vec3::new(1.0, 1.0, 0.0),
                deg_per_s: 37.0,
            },
            Animation::Oscillate {
                axis: Vec3::new(0.0, 1.0, 1.0),
                amplitude: 0.7,
                period_s: 3.0,
            },
        ];
        for motion in motions {
            let swept = motion.swept(&part, &BOUNDS);
            for i in 0..200 {
                let now = part.transformed(motion.matrix(&BOUNDS, i as f32 * 0.05));
                assert!(
                    now.min.cmpge(swept.min - 1e-5).all() && now.max.cmple(swept.max + 1e-5).all(),
                    "{motion:?} at step {i}: {now:?} outside {swept:?}"
                );
            }
        }
    }

    #[test]
    fn orbit_turns_once_per_period() {
        let orbit = Orbit {
            center: Vec3::new(0.0, 1.0, 0.0),
            axis: Vec3::Y,
            period_s: 4.0,
        };
        let start = Vec3::new(1.0, 1.0, 0.0);
        assert!(orbit
            .apply(start, 1.0)
            .abs_diff_eq(Vec3::new(0.0, 1.0, -1.0), 1e-5));
        assert!(orbit.apply(start, 4.0).abs_diff_eq(start, 1e-5));
    }
}
