//! Shadow maps: one square tile per light view (six cube faces for a point light, one
//! for a spot or directional light), packed into the layers of one depth array within a
//! memory budget ([`ShadowAtlas`]), rendered every frame and sampled with PCF.

use std::sync::Arc;

use anyhow::{bail, Result};
use ash::vk;
use glam::{Mat4, Vec3};

use crate::gpu_layout::{DrawPush, ShadowView};
use crate::scene::{Aabb, Light, LightKind, Scene};
use crate::scene_gpu::{SceneDraw, VERTEX_ATTRIBUTES};
use crate::vk::{
    image_barrier, set_viewport_rect, Context, GraphicsDesc, Image, ImageDesc, ImageUse, OwnedView,
    Pipeline,
};

pub const DEPTH_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Cube faces are rendered a little wider than 90 degrees so that PCF taps near a face
/// edge still land inside the face.
const CUBE_FACE_FOV_DEG: f32 = 95.0;

/// The smallest side a view is cut to; below it a budget is refused.
pub const MIN_VIEW_RESOLUTION: u32 = 16;

/// Bytes per shadow-map texel (`DEPTH_FORMAT`).
const TEXEL_BYTES: u64 = 4;

/// Shadow map resolution (texels per side, powers of two) of each light view, and the
/// memory the map may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowResolution {
    /// Each view of a point or spot light.
    pub local: u32,
    /// A directional light's one view, which covers the whole scene.
    pub directional: u32,
    /// The most the shadow map may take, in MiB: the resolutions are cut to fit.
    pub budget_mib: u32,
}

impl Default for ShadowResolution {
    fn default() -> Self {
        Self::FRAMES
    }
}

impl ShadowResolution {
    /// For frames in real time (`view`, `bench`): a directional light's one view covers
    /// the whole scene, so it takes more texels than a point light's faces (on Sponza a
    /// 1024 map gave 4 cm texels and, with the PCF, 20 cm penumbrae; BENCHMARKS.md,
    /// session 7).
    pub const FRAMES: Self = Self {
        local: 1024,
        directional: 4096,
        budget_mib: 512,
    };
    /// For one image (`render`): the references' lights are points and a sun without
    /// extent, whose shadows are hard, where a shadow map's penumbra (its PCF kernel) and
    /// the normal offset that keeps a surface from shadowing itself both span a few of its
    /// texels; finer texels bring the direct light towards the path tracer's on every
    /// reference (BENCHMARKS.md, session 39). A point light's six faces at 4096 and the
    /// sun's view at 8192 each fit the default budget; more lights are cut to fit it.
    pub const ONE_IMAGE: Self = Self {
        local: 4096,
        directional: 8192,
        budget_mib: 512,
    };

    /// Of each view of `light`.
    pub fn of(&self, light: &Light) -> u32 {
        match light.kind {
            LightKind::Directional { .. } => self.directional,
            LightKind::Point | LightKind::Spot { .. } => self.local,
        }
    }
}

/// At most this many layers, whatever the device allows: each has its own image view,
/// and larger layers waste at most one layer's end.
const MAX_LAYERS: u32 = 64;

/// Where each view lies in the shadow map: a square tile of a power-of-two side in one
/// layer of `edge` x `edge` texels. Tiles are packed largest first, each layer filled in
/// Morton order, so every tile is aligned to its own size and the layers hold no gaps
/// but the last one's end. The layers are the smallest power of two (from the largest
/// view up) that keeps them within `MAX_LAYERS`. A scene of many lights gets its
/// resolutions halved (the class of lights taking the most memory first) until the map
/// fits its budget.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadowAtlas {
    /// Texels per side of every layer.
    pub edge: u32,
    /// Layers in use (at least one).
    pub layers: u32,
    /// The resolutions after the cut.
    pub resolution: ShadowResolution,
    /// Per view, in light order: its layer and the texel offset of its tile.
    places: Vec<(u32, [u32; 2])>,
}

impl ShadowAtlas {
    /// The atlas for `scene`'s lights at the resolutions `wanted`, cut to fit
    /// `wanted.budget_mib` with layers of at most `max_edge` texels and at most
    /// `max_layers` of them (the device's limits); an error naming the budget when even
    /// the smallest views do not fit.
    pub fn plan(
        scene: &Scene,
        wanted: ShadowResolution,
        max_layers: u32,
        max_edge: u32,
    ) -> Result<Self> {
        let budget = u64::from(wanted.budget_mib) << 20;
        let max_layers = max_layers.min(MAX_LAYERS);
        let mut resolution = wanted;
        loop {
            let atlas = Self::pack(scene, resolution, max_layers, max_edge);
            if let Some(atlas) = atlas.filter(|a| a.bytes() <= budget) {
                if resolution != wanted {
                    let mut cut = Vec::new();
                    if resolution.local != wanted.local {
                        cut.push(format!("{}^2 texels for point and spot", resolution.local));
                    }
                    if resolution.directional != wanted.directional {
                        cut.push(format!("{}^2 for directional", resolution.directional));
                    }
                    log::warn!(
                        "{} lights: shadow views cut to {} to fit the {} MiB budget \
                         (--shadow-budget)",
                        scene.lights.len(),
                        cut.join(" and "),
                        wanted.budget_mib
                    );
                }
                return Ok(atlas);
            }
            let bytes_of = |directional: bool| -> u64 {
                scene
                    .lights
                    .iter()
                    .filter(|l| matches!(l.kind, LightKind::Directional { .. }) == directional)
                    .map(|l| u64::from(view_count(l)) * u64::from(resolution.of(l)).pow(2))
                    .sum()
            };
            let can_cut = |r: u32| r > MIN_VIEW_RESOLUTION;
            let (local, directional) = (bytes_of(false), bytes_of(true));
            if can_cut(resolution.local)
                && (local >= directional || !can_cut(resolution.directional))
            {
                resolution.local /= 2;
            } else if can_cut(resolution.directional) {
                resolution.directional /= 2;
            } else {
                let views: u32 = scene.lights.iter().map(view_count).sum();
                let least = (local + directional) * TEXEL_BYTES;
                bail!(
                    "{} lights need {views} shadow views: at {MIN_VIEW_RESOLUTION}^2 texels \
                     each that is {:.1} MiB, over the {} MiB budget (--shadow-budget) or the \
                     device's {max_layers} layers of {max_edge}^2; raise the budget or use \
                     fewer lights",
                    scene.lights.len(),
                    least as f64 / f64::from(1 << 20),
                    wanted.budget_mib
                );
            }
        }
    }

    /// The packing at `resolution`, or `None` where no layer size up to `max_edge` keeps
    /// the layers within `max_layers`.
    fn pack(
        scene: &Scene,
        resolution: ShadowResolution,
        max_layers: u32,
        max_edge: u32,
    ) -> Option<Self> {
        let sides: Vec<u32> = scene
            .lights
            .iter()
            .flat_map(|l| std::iter::repeat_n(resolution.of(l), view_count(l) as usize))
            .collect();
        let area: u64 = sides.iter().map(|&s| u64::from(s).pow(2)).sum();
        let largest = sides.iter().copied().max().unwrap_or(MIN_VIEW_RESOLUTION);
        let edge = std::iter::successors(Some(largest), |e| e.checked_mul(2))
            .take_while(|&e| e <= max_edge)
            .find(|&e| area.div_ceil(u64::from(e).pow(2)) <= u64::from(max_layers))?;
        let mut order: Vec<usize> = (0..sides.len()).collect();
        order.sort_by_key(|&v| std::cmp::Reverse(sides[v]));
        let mut places = vec![(0, [0, 0]); sides.len()];
        let (mut layer, mut used) = (0u32, 0u64);
        let layer_area = u64::from(edge).pow(2);
        for v in order {
            let tile = u64::from(sides[v]).pow(2);
            if used + tile > layer_area {
                layer += 1;
                used = 0;
            }
            // `used` is a multiple of this tile's area (every earlier tile was as large or
            // larger, all powers of two): the next slot of its size in Morton order.
            let [x, y] = morton_decode(used / tile);
            places[v] = (layer, [x * sides[v], y * sides[v]]);
            used += tile;
        }
        Some(Self {
            edge,
            layers: layer + 1,
            resolution,
            places,
        })
    }

    /// The depth image's size: at least two layers, so that its view is a 2D array (the
    /// shaders sample a sampler2DArrayShadow) even when one light has one view.
    pub fn bytes(&self) -> u64 {
        u64::from(self.layers.max(2)) * u64::from(self.edge).pow(2) * TEXEL_BYTES
    }
}

/// (x, y) of Morton index `i`: x from its even bits, y from its odd ones.
fn morton_decode(i: u64) -> [u32; 2] {
    let mut xy = [0u32; 2];
    for bit in 0..32 {
        xy[0] |= (((i >> (2 * bit)) & 1) as u32) << bit;
        xy[1] |= (((i >> (2 * bit + 1)) & 1) as u32) << bit;
    }
    xy
}

pub struct ShadowPass {
    pub map: Image,
    pub atlas: ShadowAtlas,
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

/// Reverse Z to infinity, as the camera's (`Camera::proj`): depth precision relative to
/// the distance from the light, whatever the scene's units and however close to the light
/// the nearest caster is.
fn perspective(fov_deg: f32, near: f32) -> Mat4 {
    Mat4::perspective_infinite_reverse_rh(fov_deg.to_radians(), 1.0, near)
}

fn up_for(direction: Vec3) -> Vec3 {
    if direction.normalize().y.abs() > 0.99 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// The views of `light` (already placed at time t) over a scene with world `bounds`, in
/// their tiles `places` (layer, texel offset) of `resolution` texels per side.
pub fn light_views(
    light: &Light,
    bounds: &Aabb,
    resolution: u32,
    places: &[(u32, [u32; 2])],
) -> Vec<ShadowView> {
    let radius = (bounds.max - bounds.min).length() * 0.5;
    let center = (bounds.max + bounds.min) * 0.5;
    let res = resolution as f32;
    let perspective_view = |view: Mat4, fov_deg: f32, (layer, offset): (u32, [u32; 2])| {
        let far = (light.position - center).length() + radius;
        let near = far * 1e-6;
        ShadowView {
            view_proj: (perspective(fov_deg, near) * view).to_cols_array_2d(),
            origin: light.position.extend(0.0).to_array(),
            texel_size: 2.0 * (fov_deg.to_radians() * 0.5).tan() / res,
            layer,
            resolution,
            offset_x: offset[0],
            offset_y: offset[1],
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
                    perspective_view(view, CUBE_FACE_FOV_DEG, places[i])
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
            vec![perspective_view(view, fov, places[0])]
        }
        LightKind::Directional { direction } => {
            let eye = center - direction * (radius * 2.0);
            let view = Mat4::look_to_rh(eye, direction, up_for(direction));
            // Near and far swapped: reverse Z, as the perspective views, so that one depth
            // compare serves every view.
            let proj =
                Mat4::orthographic_rh(-radius, radius, -radius, radius, radius * 3.0, radius);
            vec![ShadowView {
                view_proj: (proj * view).to_cols_array_2d(),
                origin: direction.extend(1.0).to_array(),
                texel_size: 2.0 * radius / res,
                layer: places[0].0,
                resolution,
                offset_x: places[0].1[0],
                offset_y: places[0].1[1],
                ..Default::default()
            }]
        }
    }
}

/// All shadow views of the scene at time t, in light order. They cover the scene's
/// bounds over all times, so that only moving lights move them: a moving mesh changes
/// only the texels it covers or covered.
pub fn scene_views(scene: &Scene, time_s: f32, atlas: &ShadowAtlas) -> Vec<ShadowView> {
    let bounds = scene.swept_bounds();
    let mut views = Vec::new();
    for i in 0..scene.lights.len() {
        let light = scene.light_at(i, time_s);
        let places = &atlas.places[views.len()..views.len() + view_count(&light) as usize];
        let resolution = atlas.resolution.of(&light);
        views.extend(light_views(&light, &bounds, resolution, places));
    }
    views
}

impl ShadowPass {
    pub fn new(
        ctx: &Arc<Context>,
        scene: &Scene,
        resolution: ShadowResolution,
        opaque_cut_outs: bool,
        set_layouts: &[vk::DescriptorSetLayout],
    ) -> Result<Self> {
        let limits = &ctx.properties.limits;
        let max_edge = limits.max_image_dimension2_d;
        let wanted = ShadowResolution {
            local: resolution.local.min(max_edge),
            directional: resolution.directional.min(max_edge),
            ..resolution
        };
        let atlas = ShadowAtlas::plan(scene, wanted, limits.max_image_array_layers, max_edge)?;
        let layers = atlas.layers;
        let mut desc = ImageDesc::d2(
            DEPTH_FORMAT,
            atlas.edge,
            atlas.edge,
            vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
        );
        // See ShadowAtlas::bytes.
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
                constants: &[u32::from(opaque_cut_outs)],
            },
        )?;
        Ok(Self {
            map,
            atlas,
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
            let tile = vk::Rect2D {
                offset: vk::Offset2D {
                    x: view.offset_x as i32,
                    y: view.offset_y as i32,
                },
                extent: vk::Extent2D {
                    width: view.resolution,
                    height: view.resolution,
                },
            };
            let depth = vk::RenderingAttachmentInfo::default()
                .image_view(self.layer_views[view.layer as usize].raw)
                .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(vk::AttachmentStoreOp::STORE)
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue {
                        depth: crate::passes::gbuffer::DEPTH_CLEAR,
                        stencil: 0,
                    },
                });
            // The clear covers the render area only: the view's tile.
            let rendering = vk::RenderingInfo::default()
                .render_area(tile)
                .layer_count(1)
                .depth_attachment(&depth);
            unsafe { ctx.device.cmd_begin_rendering(cmd, &rendering) };
            set_viewport_rect(ctx, cmd, tile);
            // Slope-scaled bias removes acne on surfaces at grazing angles to the light;
            // the lighting pass adds a normal offset for the rest. Negative: under reverse
            // Z, away from the light is towards 0.
            unsafe { ctx.device.cmd_set_depth_bias(cmd, 0.0, 0.0, -1.5) };
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
    use super::{ShadowAtlas, ShadowResolution};
    use crate::scene::testing::{write_quad, TempDir};
    use crate::scene::{LoadOptions, Scene};

    /// A quad lit by `points` point lights and, where `sun`, a directional light.
    fn lit_quad(name: &str, points: usize, sun: bool) -> Scene {
        let dir = TempDir::new(name);
        write_quad(&dir.0);
        let mut text = String::from("[[mesh]]\npath = \"quad.obj\"\n");
        for i in 0..points {
            let x = i as f32 * 0.001;
            text += &format!(
                "[[light]]\nkind = \"point\"\nposition = [{x}, 1, 0]\nintensity = [1, 1, 1]\n"
            );
        }
        if sun {
            text += "[[light]]\nkind = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [1, 1, 1]\n";
        }
        let path = dir.write("scene.toml", &text);
        Scene::load(&path, &LoadOptions::default()).unwrap()
    }

    /// Every view's tile lies inside its layer, none overlaps another, and each has the
    /// resolution of its light.
    fn check_tiles(scene: &Scene, atlas: &ShadowAtlas) {
        let views = super::scene_views(scene, 0.0, atlas);
        assert_eq!(views.len(), atlas.places.len());
        let mut texels = std::collections::HashSet::new();
        for v in &views {
            assert!(v.layer < atlas.layers);
            assert!(v.offset_x + v.resolution <= atlas.edge);
            assert!(v.offset_y + v.resolution <= atlas.edge);
            assert_eq!(
                v.offset_x % v.resolution,
                0,
                "tiles are aligned to their size"
            );
            // One texel per 16 x 16 block is enough to see overlaps: every side is >= 16.
            for y in (v.offset_y..v.offset_y + v.resolution).step_by(16) {
                for x in (v.offset_x..v.offset_x + v.resolution).step_by(16) {
                    assert!(texels.insert((v.layer, x, y)), "tiles overlap at {x}, {y}");
                }
            }
        }
    }

    /// 1000 point lights asked for 6000 layers of 1024^2 (25 GB, refused by the
    /// allocator): their views are cut to fit the budget, and the map is allocatable.
    #[test]
    fn a_thousand_lights_fit_the_budget() {
        let scene = lit_quad("atlas_1000", 1000, true);
        let atlas = ShadowAtlas::plan(&scene, ShadowResolution::default(), 2048, 16384).unwrap();
        assert!(atlas.bytes() <= 512 << 20, "{} bytes", atlas.bytes());
        assert_eq!(atlas.resolution.local, 128);
        assert_eq!(atlas.resolution.directional, 4096);
        check_tiles(&scene, &atlas);
    }

    /// A sun and ten point lights: the 60 point-light faces share layers of the sun's
    /// 4096^2, 16 to a layer, instead of taking one each (61 x 64 MiB before).
    #[test]
    fn small_views_share_the_large_views_layers() {
        let scene = lit_quad("atlas_sun", 10, true);
        let atlas = ShadowAtlas::plan(&scene, ShadowResolution::default(), 2048, 16384).unwrap();
        assert_eq!((atlas.edge, atlas.layers), (4096, 5));
        assert_eq!(atlas.resolution, ShadowResolution::default());
        check_tiles(&scene, &atlas);
    }

    #[test]
    fn a_budget_too_small_for_the_smallest_views_is_refused() {
        let scene = lit_quad("atlas_small", 1000, false);
        let wanted = ShadowResolution {
            budget_mib: 1,
            ..Default::default()
        };
        let err = ShadowAtlas::plan(&scene, wanted, 2048, 16384)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("6000 shadow views") && err.contains("--shadow-budget"),
            "{err}"
        );
    }

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
        let atlas = super::ShadowAtlas::plan(&scene, Default::default(), 2048, 16384).unwrap();
        let views = |t| super::scene_views(&scene, t, &atlas);
        assert_eq!(
            bytemuck::cast_slice::<_, u8>(&views(0.0)),
            bytemuck::cast_slice::<_, u8>(&views(1.0))
        );
    }
}
