//! Shadow maps: one depth layer per light view (six cube faces for a point light, one
//! for a spot or directional light), rendered every frame and sampled with PCF.

use std::sync::Arc;

use anyhow::Result;
use ash::vk;
use glam::{Mat4, Vec3};

use crate::gpu_layout::{DrawPush, ShadowView};
use crate::scene::{Aabb, Light, LightKind, Scene};
use crate::scene_gpu::{SceneDraw, VERTEX_ATTRIBUTES};
use crate::vk::{
    image_barrier, set_viewport, Context, GraphicsDesc, Image, ImageDesc, ImageUse, OwnedView,
    Pipeline,
};

pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Cube faces are rendered a little wider than 90 degrees so that PCF taps near a face
/// edge still land inside the face.
const CUBE_FACE_FOV_DEG: f32 = 95.0;

/// Shadow map resolution (texels per side) of each light view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowResolution {
    /// Each view of a point or spot light.
    pub local: u32,
    /// A directional light's one view, which covers the whole scene.
    pub directional: u32,
}

impl Default for ShadowResolution {
    fn default() -> Self {
        Self {
            local: 1024,
            directional: 4096,
        }
    }
}

impl ShadowResolution {
    /// Of each view of `light`.
    pub fn of(&self, light: &Light) -> u32 {
        match light.kind {
            LightKind::Directional { .. } => self.directional,
            LightKind::Point | LightKind::Spot { .. } => self.local,
        }
    }

    /// Of the shadow map's layers: the largest of `scene`'s views.
    fn layers(&self, scene: &Scene) -> u32 {
        scene.lights.iter().map(|l| self.of(l)).max().unwrap_or(16)
    }
}

pub struct ShadowPass {
    pub map: Image,
    layer_views: Vec<OwnedView>,
    pipeline: Pipeline,
}

/// Number of shadow views a light needs.
pub fn view_count(light: &Light) -> u32 {
    match light.kind {
        LightKind::Point => 6,
        LightKind::Spot { .. } | LightKind::Directional { .. } => 1,
    }
}

fn perspective(fov_deg: f32, near: f32, far: f32) -> Mat4 {
    Mat4::perspective_rh(fov_deg.to_radians(), 1.0, near, far)
}

fn up_for(direction: Vec3) -> Vec3 {
    if direction.normalize().y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// The views of `light` (already placed at time t) over a scene with world `bounds`.
pub fn light_views(
    light: &Light,
    bounds: &Aabb,
    resolution: u32,
    first_layer: u32,
) -> Vec<ShadowView> {
    let radius = (bounds.max - bounds.min).length() * 0.5;
    let center = (bounds.max + bounds.min) * 0.5;
    let res = resolution as f32;
    let perspective_view = |view: Mat4, fov_deg: f32, layer: u32| {
        let far = (light.position - center).length() + radius;
        let near = (far * 1e-4).max(1e-3);
        ShadowView {
            view_proj: (perspective(fov_deg, near, far) * view).to_cols_array_2d(),
            origin: light.position.extend(0.0).to_array(),
            texel_size: 2.0 * (fov_deg.to_radians() * 0.5).tan() / res,
            layer,
            near,
            far,
            resolution,
            ..Default::default()
        }
    };
    match light.kind {
        LightKind::Point => {
            let faces = [
                (Vec3::X, Vec3::NEG_Y),
                (Vec3::NEG_X, Vec3::NEG_Y),
                (Vec3::Y, Vec3::Z),
                (Vec3::NEG_Y, Vec3::NEG_Z),
                (Vec3::Z, Vec3::NEG_Y),
                (Vec3::NEG_Z, Vec3::NEG_Y),
            ];
            faces
                .iter()
                .enumerate()
                .map(|(i, &(dir, up))| {
                    let view = Mat4::look_to_rh(light.position, dir, up);
                    perspective_view(view, CUBE_FACE_FOV_DEG, first_layer + i as u32)
                })
                .collect()
        }
        LightKind::Spot {
            direction,
            outer_deg,
            ..
        } => {
            let view = Mat4::look_to_rh(light.position, direction, up_for(direction));
            let fov = (2.0 * outer_deg + 4.0).min(170.0);
            vec![perspective_view(view, fov, first_layer)]
        }
        LightKind::Directional { direction } => {
            let eye = center - direction * (radius * 2.0);
            let view = Mat4::look_to_rh(eye, direction, up_for(direction));
            let proj =
                Mat4::orthographic_rh(-radius, radius, -radius, radius, radius, radius * 3.0);
            vec![ShadowView {
                view_proj: (proj * view).to_cols_array_2d(),
                origin: direction.extend(1.0).to_array(),
                texel_size: 2.0 * radius / res,
                layer: first_layer,
                near: radius,
                far: radius * 3.0,
                resolution,
                ..Default::default()
            }]
        }
    }
}

/// All shadow views of the scene at time t, in light order. They cover the scene's
/// bounds over all times, so that only moving lights move them: a moving mesh changes
/// only the texels it covers or covered.
pub fn scene_views(scene: &Scene, time_s: f32, resolution: ShadowResolution) -> Vec<ShadowView> {
    let bounds = scene.swept_bounds();
    let mut views = Vec::new();
    for i in 0..scene.lights.len() {
        let light = scene.light_at(i, time_s);
        let first = views.len() as u32;
        views.extend(light_views(&light, &bounds, resolution.of(&light), first));
    }
    views
}

impl ShadowPass {
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        resolution: ShadowResolution,
        set_layouts: &[vk::DescriptorSetLayout],
    ) -> Result<Self> {
        let layers: u32 = scene.lights.iter().map(view_count).sum::<u32>().max(1);
        let edge = resolution.layers(scene);
        let mut desc = ImageDesc::d2(
            DEPTH_FORMAT,
            edge,
            edge,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
        );
        // At least two layers, so that the image's view is a 2D array (the shaders sample a
        // sampler2DArrayShadow) even when one light has one view.
        desc.layers = layers.max(2);
        let map = Image::new(ctx, "shadow map", desc)?;
        let layer_views = (0..layers)
            .map(|l| map.layer_view(l, 0))
            .collect::<Result<_>>()?;
        let pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "shadow",
                vertex: crate::vk::shaders::PASSES_SHADOW_SHADOW_VERT,
                geometry: None,
                fragment: Some(crate::vk::shaders::PASSES_SHADOW_SHADOW_FRAG),
                vertex_stride: std::mem::size_of::<crate::scene::Vertex>() as u32,
                // Position and uv (for cut-outs); the shadow pass has no use for normals.
                attributes: &[VERTEX_ATTRIBUTES[0], VERTEX_ATTRIBUTES[2]],
                set_layouts,
                push_constant_bytes: std::mem::size_of::<DrawPush>() as u32,
                color_formats: &[],
                depth_format: Some(DEPTH_FORMAT),
                cull: vk::CullModeFlags::NONE,
                dynamic_depth_bias: true,
                depth_clamp: ctx.features.depth_clamp,
            },
        )?;
        Ok(Self {
            map,
            layer_views,
            pipeline,
        })
    }

    /// The layout and stages the lighting pass leaves the map in.
    pub const FINAL_USE: ImageUse = ImageUse::DEPTH_READ;

    /// Renders every view.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        draw: &SceneDraw,
        views: &[ShadowView],
    ) {
        image_barrier(
            ctx,
            cmd,
            self.map.raw,
            self.map.full_range(),
            ImageUse::discard_after(Self::FINAL_USE),
            ImageUse::DEPTH_ATTACHMENT,
        );
        for (index, view) in views.iter().enumerate() {
            // The view fills the corner of its layer that its resolution asks for.
            let extent = vk::Extent2D {
                width: view.resolution,
                height: view.resolution,
            };
            let depth = vk::RenderingAttachmentInfo::default()
                .image_view(self.layer_views[view.layer as usize].raw)
                .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: 1.0,
                        stencil: 0,
                    },
                });
            let rendering = vk::RenderingInfo::default()
                .render_area(vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent,
                })
                .layer_count(1)
                .depth_attachment(&depth);
            unsafe { ctx.device.cmd_begin_rendering(cmd, &rendering) };
            set_viewport(ctx, cmd, extent);
            // Slope-scaled bias removes acne on surfaces at grazing angles to the light;
            // the lighting pass adds a normal offset for the rest.
            unsafe { ctx.device.cmd_set_depth_bias(cmd, 0.0, 0.0, 1.5) };
            draw.draw_meshes(ctx, cmd, &self.pipeline, index as u32, None, |_| true);
            unsafe { ctx.device.cmd_end_rendering(cmd) };
        }
        image_barrier(
            ctx,
            cmd,
            self.map.raw,
            self.map.full_range(),
            ImageUse::DEPTH_ATTACHMENT,
            Self::FINAL_USE,
        );
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::testing::{write_quad, TempDir};
    use crate::scene::{LoadOptions, Scene};

    /// The views cover the scene's bounds over all times, so they stay put while its
    /// meshes move (the lights held still): the shadow maps of the static geometry need
    /// not be redrawn.
    #[test]
    fn views_stay_put_while_meshes_move() {
        let dir = TempDir::new("shadow_views");
        write_quad(&dir.0);
        let path = dir.write(
            "scene.toml",
            "[[mesh]]\npath = \"quad.obj\"\nanimate = { kind = \"spin\", axis = [0, 1, 0], \
             deg_per_s = 45 }\n[[mesh]]\npath = \"quad.obj\"\nscale = [1, 2, 3]\nanimate = \
             { kind = \"oscillate\", axis = [1, 0, 0], amplitude = 0.5, period_s = 4 }\n\
             [[light]]\nkind = \"point\"\nposition = [0, 1.5, 0]\nintensity = [3, 3, 3]\n\
             [[light]]\nkind = \"spot\"\nposition = [0, 2, 0]\ndirection = [0, -2, 0]\n\
             intensity = [10, 10, 10]\ninner_deg = 20\nouter_deg = 30\n[[light]]\nkind = \
             \"directional\"\ndirection = [0.25, -1, 0.1]\nirradiance = [8, 7.6, 7]\n",
        );
        let scene = Scene::load(&path, &LoadOptions::default()).unwrap();
        assert!(scene.is_animated());
        let views = |t| super::scene_views(&scene, t, Default::default());
        assert_eq!(
            bytemuck::cast_slice::<_, u8>(&views(0.0)),
            bytemuck::cast_slice::<_, u8>(&views(1.0))
        );
    }
}
