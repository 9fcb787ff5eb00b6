//! A thin layer over `ash`: device, memory, descriptors, pipelines, timeline sync,
//! timestamps and debug labels.

mod commands;
mod context;
mod descriptors;
mod memory;
mod pipeline;
mod swapchain;
mod sync;
mod timestamps;

pub use commands::{
    clear_to_zero, compute_to_compute, copies_to_host_barrier, copy_image_to_buffer, image_barrier,
    memory_barrier, read_back_buffer, read_back_image, stage_barrier, to_compute_write,
    update_buffer, ImageUse, OneShot, COLOR_TARGET_RANGE,
};
pub use context::{Context, ContextOptions, Features};
pub use descriptors::{Binding, DescriptorSets, SetWriter};
pub use memory::{
    is_depth_format, sampler_info, upload_buffer, Buffer, Image, ImageDesc, OwnedView, Sampler,
    TexelBuffer,
};
pub use pipeline::{groups_2d, groups_3d, set_viewport, set_viewport_rect, GraphicsDesc, Pipeline};
pub use swapchain::{Acquired, Swapchain};
pub use sync::{Frame, FrameRing};
pub use timestamps::GpuTimer;

/// SPIR-V of every shader under `glsl/`, named after its path.
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
