//! Lights in the references' units.

use glam::Vec3;

use super::Orbit;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Isotropic; intensity in W/sr.
    Point,
    /// Intensity in W/sr on the axis, fading between the half-angles `inner_deg` and
    /// `outer_deg` from the axis.
    Spot {
        direction: Vec3,
        inner_deg: f32,
        outer_deg: f32,
    },
    /// Intensity is the irradiance in W/m^2 on a surface facing the light; `direction` is
    /// the direction of travel.
    Directional { direction: Vec3 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    pub position: Vec3,
    pub intensity: Vec3,
    pub orbit: Option<Orbit>,
}
