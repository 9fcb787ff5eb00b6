//! voxcone: real-time global illumination by voxel cone tracing on Vulkan.
//!
//! A frame flows one way through the passes listed in [`renderer`]; each pass is a
//! module here with its shaders in the `glsl/` folder of the same name.

pub mod cli;
pub mod compare;
pub mod composite;
pub mod frontend;
pub mod gbuffer;
pub mod gi;
pub mod gpu_layout;
pub mod imageio;
pub mod lighting;
pub mod renderer;
pub mod scene;
pub mod scene_gpu;
pub mod shadow;
pub mod svo;
#[cfg(test)]
mod testing;
pub mod vk;
