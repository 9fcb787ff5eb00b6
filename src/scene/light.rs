//! Lights in the references' units.

use glam::Vec3;

use super::Orbit;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightKind {
    /// Isotropic; intensity in W/sr.
    Point,
    /// Intensity in W/sr on the axis `direction` (normalised), full out to the half-angle
    /// `inner_deg` from the axis and fading to zero at the half-angle `outer_deg`.
    Spot {
        direction: Vec3,
        inner_deg: f32,
        outer_deg: f32,
    },
    /// Intensity is the irradiance in W/m^2 on a surface facing the light; `direction` is
    /// the (normalised) direction of travel, not the direction towards the light.
    Directional { direction: Vec3 },
}

#[derive(Clone, Debug, PartialEq)]
pub struct Light {
    pub kind: LightKind,
    /// Unused by directional lights.
    pub position: Vec3,
    /// W/sr per channel for point and spot lights; W/m^2 for directional ones.
    pub intensity: Vec3,
    /// Moves `position`; see [`Scene::light_at`](super::Scene::light_at).
    pub orbit: Option<Orbit>,
}
