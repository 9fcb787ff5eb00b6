//! Test support: a validating context and renderers that run frames offscreen.

use std::sync::Arc;

use ash::vk;

use crate::frontend::{Offscreen, LDR_FORMAT};
use crate::gi::vct::voxelize::Voxelizer;
use crate::gi::vct::{ConeTracing, Dense, Octree, Store, VctSettings};
use crate::gi::GiSettings;
pub use crate::ray::host::Random;
use crate::renderer::{OutputTarget, Renderer};
use crate::scene::Scene;
use crate::settings::RenderSettings;
use crate::vk::{Context, ContextOptions, ImageUse};

/// Cone tracing with default cones at `voxels` per axis in `store`.
pub fn gi_settings(voxels: u32, store: Store, full_update: bool) -> RenderSettings {
    RenderSettings {
        gi: GiSettings::ConeTracing(VctSettings {
            full_update,
            ..VctSettings::new(voxels, store)
        }),
        ..Default::default()
    }
}

/// The cone tracer's settings in `settings`.
pub fn cone_settings(settings: &mut RenderSettings) -> &mut VctSettings {
    match &mut settings.gi {
        GiSettings::ConeTracing(vct) => vct,
        _ => panic!("the settings have no cone tracing"),
    }
}

/// `settings` with the GI voxelized by `voxelizer`.
pub fn with_voxelizer(mut settings: RenderSettings, voxelizer: Voxelizer) -> RenderSettings {
    cone_settings(&mut settings).voxelizer = voxelizer;
    settings
}

/// The renderer's cone tracer over the dense grid.
pub fn dense(renderer: &Renderer) -> &ConeTracing<Dense> {
    renderer
        .gi_as()
        .expect("the renderer traces cones through a dense grid")
}

/// The renderer's cone tracer over the octree.
pub fn octree(renderer: &Renderer) -> &ConeTracing<Octree> {
    renderer
        .gi_as()
        .expect("the renderer traces cones through an octree")
}

/// The renderer's cone tracer over the octree.
pub fn octree_mut(renderer: &mut Renderer) -> &mut ConeTracing<Octree> {
    renderer
        .gi_as_mut()
        .expect("the renderer traces cones through an octree")
}

/// Renders 64x64 frames of `scene`, one at each of `times`, with validation on (its
/// messages go to the log, shown when a test fails; callers check the count).
pub fn render_frames(
    scene: Scene,
    settings: RenderSettings,
    times: &[f32],
) -> (Arc<Context>, Renderer) {
    render_frames_with(scene, settings, times, |_, _| {})
}

/// As [`render_frames`], with `before(renderer, i)` called before frame i is recorded
/// (to move a light, say).
/// A context with validation (and synchronization validation) on, the test log set up.
pub fn validating_context() -> Arc<Context> {
    let _ = env_logger::builder().is_test(true).try_init();
    Context::new(&ContextOptions {
        validation: true,
        ..Default::default()
    })
    .unwrap()
}

pub fn render_frames_with(
    scene: Scene,
    settings: RenderSettings,
    times: &[f32],
    mut before: impl FnMut(&mut Renderer, usize),
) -> (Arc<Context>, Renderer) {
    let ctx = validating_context();
    let extent = vk::Extent2D {
        width: 64,
        height: 64,
    };
    let offscreen = Offscreen::new(&ctx, extent).unwrap();
    let mut renderer = Renderer::new(&ctx, scene, settings, extent, LDR_FORMAT).unwrap();
    let target = OutputTarget {
        image: offscreen.image.raw,
        view: offscreen.image.view,
        extent,
        before: ImageUse::UNDEFINED,
        after: ImageUse::COLOR_ATTACHMENT,
    };
    for (i, &time) in times.iter().enumerate() {
        let target = OutputTarget {
            before: if i == 0 {
                ImageUse::UNDEFINED
            } else {
                ImageUse::discard_after(ImageUse::COLOR_ATTACHMENT)
            },
            ..target
        };
        before(&mut renderer, i);
        let frame = renderer.begin_frame().unwrap();
        renderer.record_frame(&frame, time, &target).unwrap();
        renderer.submit(frame, None, None).unwrap();
    }
    renderer.finish().unwrap();
    (ctx, renderer)
}

/// The Cornell box at `cornell` with a cube flying across it (x oscillating by 0.6 over 4
/// seconds), written into `dir`. With `glow` the cube is the only light (emitting
/// radiance 4) and the box's own light is off.
pub fn moving_cube_scene(cornell: &std::path::Path, dir: &std::path::Path, glow: bool) -> Scene {
    std::fs::create_dir_all(dir).unwrap();
    let material = if glow {
        std::fs::write(
            dir.join("cube.mtl"),
            "newmtl glow\nKd 0.5 0.5 0.5\nKe 4 4 4\n",
        )
        .unwrap();
        "mtllib cube.mtl\nusemtl glow\n"
    } else {
        ""
    };
    std::fs::write(
        dir.join("cube.obj"),
        format!(
            "{material}v -0.15 0.3 -0.15\nv 0.15 0.3 -0.15\nv 0.15 0.6 -0.15\nv -0.15 0.6 -0.15\n\
             v -0.15 0.3 0.15\nv 0.15 0.3 0.15\nv 0.15 0.6 0.15\nv -0.15 0.6 0.15\n\
             f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"
        ),
    )
    .unwrap();
    let scene_file = dir.join("moving.toml");
    std::fs::write(
        &scene_file,
        format!(
            "[[mesh]]\npath = {:?}\nemission_scale = {}\n[[mesh]]\npath = \"cube.obj\"\n\
             animate = {{ kind = \"oscillate\", axis = [1, 0, 0], amplitude = 0.6, period_s = 4 }}\n",
            cornell.to_string_lossy(),
            if glow { 0.0 } else { 1.0 }
        ),
    )
    .unwrap();
    Scene::load(&scene_file, &crate::scene::LoadOptions::default()).unwrap()
}
