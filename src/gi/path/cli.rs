//! The path tracer's command-line options, flattened into every command's.

use clap::Args;

use super::PathSettings;
use crate::scene::GiOverrides;

#[derive(Args, Debug, Clone, Default)]
pub struct PathArgs {
    /// `--gi path`: samples per pixel [default: the scene file's, else 256].
    #[arg(long)]
    pub spp: Option<u32>,
    /// `--gi path`: the longest path, in vertices from the camera (as Mitsuba's
    /// max_depth): 2 is direct light only, 3 adds one bounce [default: the scene file's,
    /// else no limit, Russian roulette from depth 5].
    #[arg(long)]
    pub max_depth: Option<u32>,
    /// `--gi path`: seed of the random sequences (another seed: other noise, the same
    /// mean) [default: 0].
    #[arg(long)]
    pub seed: Option<u32>,
}

impl PathArgs {
    /// The options given, as their flags.
    pub fn given(&self) -> Vec<&'static str> {
        [
            (self.spp.is_some(), "--spp"),
            (self.max_depth.is_some(), "--max-depth"),
            (self.seed.is_some(), "--seed"),
        ]
        .into_iter()
        .filter_map(|(set, flag)| set.then_some(flag))
        .collect()
    }

    /// The path tracer's settings: the command line over the scene file's over the
    /// defaults; `reference`: the scene is a path-traced reference's, whose conventions the
    /// settings follow.
    pub fn settings(&self, scene: &GiOverrides, reference: bool) -> PathSettings {
        let d = PathSettings::default();
        PathSettings {
            spp: self.spp.or(scene.spp).unwrap_or(d.spp),
            max_depth: self.max_depth.or(scene.max_depth),
            seed: self.seed.unwrap_or(d.seed),
            opaque_shadow_cut_outs: reference,
            cone: None,
        }
    }
}
