//! voxcone: real-time global illumination on Vulkan, several techniques side by side.
//!
//! A frame flows one way through the passes listed in [`renderer`]: those of [`passes`]
//! around a global-illumination technique of [`gi`]. Each module has its shaders in the
//! `glsl/` folder of the same name.

pub mod cli;
pub mod compare;
pub mod frame_data;
pub mod frontend;
pub mod gi;
pub mod gpu_layout;
pub mod imageio;
pub mod passes;
pub mod progress;
pub mod ray;
pub mod renderer;
pub mod scene;
pub mod scene_gpu;
pub mod settings;
#[cfg(test)]
mod testing;
pub mod vk;
