//! What a frame computes and how it is shown: the terms, the tonemap, the shadow maps,
//! the global-illumination technique and the debug views.

use crate::gi::{DebugView, GiSettings};
use crate::passes::shadow::ShadowResolution;

/// How the final image is mapped to the display.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Tonemap {
    /// clamp(x), then sRGB: the convention of the reference PNGs.
    #[default]
    Clamp,
    /// Filmic curve (Narkowicz's ACES fit), then sRGB.
    Aces,
}

/// The terms of the final image; each can be switched.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Terms {
    pub direct: bool,
    pub emission: bool,
    pub indirect_diffuse: bool,
    pub indirect_specular: bool,
    pub transmission: bool,
    /// Multiply the indirect light by ambient occlusion. Off by default: the light the
    /// cone tracer gathers is already occluded by the same voxels, so this darkens twice
    /// (BENCHMARKS.md, the dense grid's quality history); it is the classic contact-shadow
    /// look, not the physically based image.
    pub ambient_occlusion: bool,
}

impl Default for Terms {
    fn default() -> Self {
        Self {
            direct: true,
            emission: true,
            indirect_diffuse: true,
            indirect_specular: true,
            transmission: true,
            ambient_occlusion: false,
        }
    }
}

/// Settings that change what a frame computes.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    /// Add the specular lobe of MTL Ks.
    pub specular: bool,
    /// Use tangent-space normal maps.
    pub normal_maps: bool,
    /// Exposure in stops applied before the tonemap (not to EXR output).
    pub exposure_ev: f32,
    pub tonemap: Tonemap,
    /// Texels per side of each light view's shadow map.
    pub shadow_resolution: ShadowResolution,
    /// Keep the shadow maps while no light and no mesh moves.
    pub cache_shadows: bool,
    /// Filter the materials' textures anisotropically on a CPU driver too (one image:
    /// grazing textures as sharp as the references' many samples per pixel make them).
    /// Off, a CPU driver filters them trilinearly: its anisotropic filter took 480 of the
    /// G-buffer's 760 ms on Sponza at 1280×720 (lavapipe). GPUs always filter them
    /// anisotropically.
    pub anisotropy_on_cpu: bool,
    /// Cut-outs (map_d) cast whole shadows from the lights, whatever their coverage: the
    /// references' convention (their Mitsuba integrator ignores its masks on the rays of
    /// next-event estimation, as the path tracer does under the same switch), implied by a
    /// reference `*.scene.json`. Off: they cast none where cut.
    pub opaque_shadow_cut_outs: bool,
    /// The global-illumination technique and its settings.
    pub gi: GiSettings,
    pub terms: Terms,
    /// Needs a technique that offers the view ([`crate::gi::Technique::debug_views`]).
    pub debug_view: DebugView,
    /// Mip level of the voxel debug views.
    pub debug_level: u32,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            specular: true,
            normal_maps: true,
            exposure_ev: 0.0,
            tonemap: Tonemap::Clamp,
            shadow_resolution: ShadowResolution::default(),
            cache_shadows: true,
            anisotropy_on_cpu: true,
            opaque_shadow_cut_outs: false,
            gi: GiSettings::Off,
            terms: Terms::default(),
            debug_view: DebugView::None,
            debug_level: 0,
        }
    }
}
