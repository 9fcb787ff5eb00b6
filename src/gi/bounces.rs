//! How many bounces one image traces where none are given, for every technique that
//! bounces light (the cone tracer's voxels, the probes' lightmap).

use crate::ray::host::bounce_rate;
use crate::scene::Scene;

/// The most light bounces a technique traces (`--bounces`, `--probe-bounces`, and
/// [`converged_bounces`]'s).
pub const MAX_BOUNCES: u32 = 64;

/// The share of the indirect light one image may leave in the bounces it does not trace.
const BOUNCE_REMAINDER: f32 = 0.01;

/// Bounces for one image where none are given: the fewest that leave under
/// [`BOUNCE_REMAINDER`] of the indirect light untraced where each bounce passes on `rate`
/// of the light it received ([`bounce_rate`], measured along diffuse walks in the scene).
/// With `bounces` the image holds that many bounces of indirect light (the cone tracer's
/// voxels one fewer and the screen's gather one more; the probes' lightmap all), and
/// bounce k carries rate^(k-1) of the first's light, so what is left is rate^bounces of
/// it all. Frames need no more than their default: each adds a bounce to the last
/// frame's light. One image at eight left the conference room's bounces after the first
/// 5 % short of the path tracer's at 256³ (its rate about 0.7: 13 bounces; BENCHMARKS.md,
/// session 44).
pub fn converged_bounces(rate: f32) -> u32 {
    if rate <= 0.0 {
        return 1;
    }
    if rate >= 1.0 {
        return MAX_BOUNCES;
    }
    // Finite and positive: both logarithms are negative.
    (BOUNCE_REMAINDER.ln() / rate.ln())
        .ceil()
        .clamp(1.0, MAX_BOUNCES as f32) as u32
}

/// [`converged_bounces`] for `scene`, logged with the reason.
pub fn bounces_for(scene: &Scene) -> u32 {
    let start = std::time::Instant::now();
    let rate = bounce_rate(scene);
    let bounces = converged_bounces(rate);
    let seconds = start.elapsed().as_secs_f32();
    if rate >= 1.0 {
        log::warn!(
            "bounces: {bounces}, the most: a bounce passes all the light on ({rate:.3}), \
             so no count of bounces leaves under {:.0} % of it untraced",
            BOUNCE_REMAINDER * 100.0
        );
    } else {
        log::info!(
            "bounces: {bounces} (one image: under {:.0} % of the indirect light left untraced \
             where each bounce passes on {rate:.3} of its light, measured along the camera's \
             diffuse walks in {seconds:.2} s)",
            BOUNCE_REMAINDER * 100.0
        );
    }
    bounces
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fewest bounces whose untraced rest, rate^bounces of the indirect light, is
    /// under the remainder: one fewer would leave more; one where nothing is passed on,
    /// the most where everything is.
    #[test]
    fn converged_bounces_leave_under_the_remainder() {
        assert_eq!(converged_bounces(0.7), 13);
        assert_eq!(converged_bounces(0.78), 19);
        for rate in [0.05, 0.3, 0.5, 0.7, 0.8, 0.9] {
            let bounces = converged_bounces(rate);
            assert!(rate.powi(bounces as i32) < BOUNCE_REMAINDER, "{rate}");
            assert!(rate.powi(bounces as i32 - 1) >= BOUNCE_REMAINDER, "{rate}");
        }
        assert_eq!(converged_bounces(0.0), 1);
        assert_eq!(converged_bounces(0.99), MAX_BOUNCES);
        assert_eq!(converged_bounces(1.0), MAX_BOUNCES);
    }
}
