//! The frame's passes around the global illumination, in the order data flows through
//! them: shadow maps -> G-buffer -> deferred direct lighting -> composite. Each has its
//! shaders in the `glsl/passes/` folder of the same name.

pub mod composite;
pub mod gbuffer;
pub mod lighting;
pub mod shadow;
