//! The lightmap's coarser levels (Sedláček 2019, 4.2.3–4.2.4): mips 1 to 3 of the
//! lightmap, each texel the irradiance of one receiver standing for its block, so that the
//! receivers far from the camera need not all be computed.
//!
//! The thesis writes a receiver whose texel's coordinates are multiples of 2^k into mip k.
//! In an atlas that leaves mip texels empty where no receiver falls on those multiples
//! (chart borders, small charts), and a bilinear lookup there reads black. Here each mip
//! texel that holds receivers takes the one nearest its centre, and each empty texel that a
//! lookup inside a chart can reach (the 3 × 3 around a receiver's texel at that level) takes
//! its nearest filled neighbour's.
//!
//! Which texels a frame computes ([`LightmapLevels::work`]): a lookup from a surface whose
//! cluster is at level c reads mips c and above (the fragments' levels only reach level k
//! at the distance where clusters do), through the 3 × 3 texels around its own at each.
//! So a texel of mip k is computed where any receiver within those 3 × 3 has its cluster at
//! level k or finer, and a receiver is computed where its own texel is needed at mip 0 or
//! where it stands for a texel needed at a coarser mip. Everything else keeps what an
//! earlier frame wrote, and nothing reads it.

/// The lightmap's levels: 0 (the receivers' own texels) to `LEVELS - 1`.
pub const LEVELS: usize = 4;

/// Not a receiver.
const NONE: u32 = u32::MAX;

/// One mip level above 0: its size and the texels it holds.
#[derive(Clone, Debug, PartialEq)]
struct Level {
    width: u32,
    height: u32,
    /// Per texel a lookup can read: the texel (index, row by row) and the receiver whose
    /// irradiance it holds.
    texels: Vec<(u32, u32)>,
    /// Per receiver, the texel of this level its own texel lies in.
    receiver_texel: Vec<u32>,
}

/// The lightmap's coarser levels of a bake.
#[derive(Clone, Debug, PartialEq)]
pub struct LightmapLevels {
    width: u32,
    height: u32,
    /// Per lightmap receiver, its texel (index, row by row) and its cluster.
    texels: Vec<u32>,
    clusters: Vec<u32>,
    levels: Vec<Level>,
}

/// What a frame computes: the receivers, and the coarser levels' texels as
/// `[x | y << 16, receiver | level << 30]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Work {
    pub receivers: Vec<u32>,
    pub texels: Vec<[u32; 2]>,
}

/// The size of mip `level` of a `width` × `height` image (Vulkan's rule).
pub fn mip_size(width: u32, height: u32, level: usize) -> (u32, u32) {
    ((width >> level).max(1), (height >> level).max(1))
}

/// The texel of a `to`-wide level that holds the centre of texel `x` of a `from`-wide
/// one (the sampler's mapping: the same uv).
fn coarse(x: u32, from: u32, to: u32) -> u32 {
    ((((2 * x + 1) as u64) * to as u64 / (2 * from as u64)) as u32).min(to - 1)
}

impl LightmapLevels {
    /// The levels of a `size` lightmap whose receivers lie at `texels`, in `clusters`.
    pub fn new(size: [u32; 2], texels: &[[u32; 2]], clusters: &[u32]) -> Self {
        let [width, height] = size;
        assert!(texels.len() < 1 << 30, "receiver indices need 30 bits");
        let levels = (1..LEVELS)
            .map(|k| {
                let (w, h) = mip_size(width, height, k);
                let receiver_texel: Vec<u32> = texels
                    .iter()
                    .map(|&[x, y]| coarse(y, height, h) * w + coarse(x, width, w))
                    .collect();
                // Each texel's receiver nearest its centre, distances in level-0 texels.
                let centre =
                    |t: u32, n: u32, of: u32| (f64::from(t) + 0.5) * f64::from(of) / f64::from(n);
                let mut best = vec![(f64::INFINITY, NONE); (w * h) as usize];
                for (r, (&[x, y], &t)) in texels.iter().zip(&receiver_texel).enumerate() {
                    let dx = f64::from(x) + 0.5 - centre(t % w, w, width);
                    let dy = f64::from(y) + 0.5 - centre(t / w, h, height);
                    let d = dx * dx + dy * dy;
                    if d < best[t as usize].0 {
                        best[t as usize] = (d, r as u32);
                    }
                }
                let filled: Vec<bool> = best.iter().map(|b| b.1 != NONE).collect();
                // The empty texels around filled ones, from their nearest filled
                // neighbour (an edge before a corner, then the first in row order).
                let mut around = vec![(u32::MAX, NONE); (w * h) as usize];
                for t in (0..w * h).filter(|&t| filled[t as usize]) {
                    let (x, y) = ((t % w) as i64, (t / w) as i64);
                    for (dx, dy) in NEIGHBOURS {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= i64::from(w) || ny >= i64::from(h) {
                            continue;
                        }
                        let n = (ny * i64::from(w) + nx) as usize;
                        let d = (dx * dx + dy * dy) as u32;
                        if !filled[n] && d < around[n].0 {
                            around[n] = (d, best[t as usize].1);
                        }
                    }
                }
                let texels = (0..w * h)
                    .filter_map(|t| {
                        let r = if filled[t as usize] {
                            best[t as usize].1
                        } else {
                            around[t as usize].1
                        };
                        (r != NONE).then_some((t, r))
                    })
                    .collect();
                Level {
                    width: w,
                    height: h,
                    texels,
                    receiver_texel,
                }
            })
            .collect();
        Self {
            width,
            height,
            texels: texels.iter().map(|&[x, y]| y * width + x).collect(),
            clusters: clusters[..texels.len()].to_vec(),
            levels,
        }
    }

    /// The texels of mip `level` (1 to 3) a lookup can read, each with its receiver.
    pub fn texels(&self, level: usize) -> impl Iterator<Item = ([u32; 2], u32)> + '_ {
        let l = &self.levels[level - 1];
        l.texels
            .iter()
            .map(|&(t, r)| ([t % l.width, t / l.width], r))
    }

    /// What a frame whose clusters are at `cluster_level` computes.
    pub fn work(&self, cluster_level: &[u8]) -> Work {
        let receiver_level: Vec<u8> = self
            .clusters
            .iter()
            .map(|&c| cluster_level[c as usize])
            .collect();
        let mut computed = vec![false; self.texels.len()];
        // Per texel of a level: the finest level of the receivers whose lookups reach it.
        let reach = |w: u32, h: u32, at: &mut dyn Iterator<Item = (u32, u8)>| {
            let mut finest = vec![u8::MAX; (w * h) as usize];
            for (t, level) in at {
                let (x, y) = ((t % w) as i64, (t / w) as i64);
                for (dx, dy) in NEIGHBOURS.iter().chain(&[(0, 0)]) {
                    let (nx, ny) = (x + dx, y + dy);
                    if nx >= 0 && ny >= 0 && nx < i64::from(w) && ny < i64::from(h) {
                        let n = (ny * i64::from(w) + nx) as usize;
                        finest[n] = finest[n].min(level);
                    }
                }
            }
            finest
        };
        let finest = reach(
            self.width,
            self.height,
            &mut self
                .texels
                .iter()
                .copied()
                .zip(receiver_level.iter().copied()),
        );
        for (r, &t) in self.texels.iter().enumerate() {
            computed[r] = finest[t as usize] == 0;
        }
        let mut texels = Vec::new();
        for (k, l) in self.levels.iter().enumerate() {
            let level = k + 1;
            let finest = reach(
                l.width,
                l.height,
                &mut l
                    .receiver_texel
                    .iter()
                    .copied()
                    .zip(receiver_level.iter().copied()),
            );
            for &(t, r) in &l.texels {
                if usize::from(finest[t as usize]) <= level {
                    computed[r as usize] = true;
                    texels.push([
                        (t % l.width) | ((t / l.width) << 16),
                        r | ((level as u32) << 30),
                    ]);
                }
            }
        }
        let receivers = (0..self.texels.len() as u32)
            .filter(|&r| computed[r as usize])
            .collect();
        Work { receivers, texels }
    }

    /// The most texels of the coarser levels a frame computes.
    pub fn texel_count(&self) -> usize {
        self.levels.iter().map(|l| l.texels.len()).sum()
    }
}

/// The eight neighbours of a texel, the edges first.
const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, 0),
    (1, 0),
    (0, -1),
    (0, 1),
    (-1, -1),
    (1, -1),
    (-1, 1),
    (1, 1),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Two charts on a 16 × 16 page: an 8 × 5 block at (1, 1) and a 3 × 3 one at (11, 9).
    fn page() -> (Vec<[u32; 2]>, Vec<u32>) {
        let mut texels = Vec::new();
        let mut clusters = Vec::new();
        for y in 1..6 {
            for x in 1..9 {
                texels.push([x, y]);
                clusters.push(u32::from(x >= 5));
            }
        }
        for y in 9..12 {
            for x in 11..14 {
                texels.push([x, y]);
                clusters.push(2);
            }
        }
        (texels, clusters)
    }

    /// Every texel a bilinear lookup inside a chart reads, at every level, holds a
    /// receiver of its own block or of a neighbouring one, the one nearest the block's
    /// centre where the block has receivers.
    #[test]
    fn every_lookup_inside_a_chart_reads_a_held_texel() {
        let (texels, clusters) = page();
        let levels = LightmapLevels::new([16, 16], &texels, &clusters);
        for k in 1..LEVELS {
            let (w, h) = mip_size(16, 16, k);
            let held: std::collections::HashMap<[u32; 2], u32> = levels.texels(k).collect();
            for &[x, y] in &texels {
                // A lookup anywhere in the texel, at mip k: the sampler's taps.
                for (fx, fy) in [(0.01, 0.01), (0.99, 0.01), (0.01, 0.99), (0.99, 0.99)] {
                    let u = (f64::from(x) + fx) / 16.0 * f64::from(w) - 0.5;
                    let v = (f64::from(y) + fy) / 16.0 * f64::from(h) - 0.5;
                    for (tx, ty) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
                        let tap = [
                            ((u.floor() + tx).max(0.0) as u32).min(w - 1),
                            ((v.floor() + ty).max(0.0) as u32).min(h - 1),
                        ];
                        let r = held.get(&tap).unwrap_or_else(|| {
                            panic!("level {k}: texel {tap:?} read from ({x}, {y}) is empty")
                        });
                        let [rx, ry] = texels[*r as usize];
                        let block = [rx >> k, ry >> k];
                        let apart = block[0].abs_diff(tap[0]).max(block[1].abs_diff(tap[1]));
                        assert!(apart <= 1, "level {k}: {tap:?} holds ({rx}, {ry})");
                    }
                }
            }
            // A block with receivers holds the one nearest its centre.
            for ([tx, ty], r) in levels.texels(k) {
                // Squared distance from a texel's centre to the block's, in level-0 texels.
                let c = |t: u32| (f64::from(t) + 0.5) * f64::from(1u32 << k);
                let d = |[x, y]: [u32; 2]| {
                    (f64::from(x) + 0.5 - c(tx)).powi(2) + (f64::from(y) + 0.5 - c(ty)).powi(2)
                };
                let nearest = texels
                    .iter()
                    .filter(|&&[x, y]| [x >> k, y >> k] == [tx, ty])
                    .map(|&t| d(t))
                    .min_by(|a, b| a.partial_cmp(b).unwrap());
                if let Some(nearest) = nearest {
                    assert_eq!(d(texels[r as usize]), nearest, "level {k} at {tx}, {ty}");
                }
            }
        }
    }

    /// At level 0 everywhere every receiver and every held texel is computed; with the
    /// clusters at levels 0, 1 and 3, a texel is computed exactly where a lookup from a
    /// cluster at its level or finer reaches it, and a receiver where its texel or a texel
    /// it stands for is.
    #[test]
    fn a_frame_computes_what_its_lookups_read() {
        let (texels, clusters) = page();
        let levels = LightmapLevels::new([16, 16], &texels, &clusters);
        let all = levels.work(&[0, 0, 0]);
        assert_eq!(all.receivers.len(), texels.len());
        assert_eq!(all.texels.len(), levels.texel_count());
        let cluster_level = [0u8, 1, 3];
        let work = levels.work(&cluster_level);
        let computed: std::collections::HashSet<u32> = work.receivers.iter().copied().collect();
        let at_level: std::collections::HashSet<(usize, [u32; 2])> = work
            .texels
            .iter()
            .map(|&[t, r]| ((r >> 30) as usize, [t & 0xFFFF, t >> 16]))
            .collect();
        for k in 0..LEVELS {
            let near = |[tx, ty]: [u32; 2]| {
                texels.iter().zip(&clusters).any(|(&[x, y], &c)| {
                    let ([bx, by], level) = ([x >> k, y >> k], cluster_level[c as usize]);
                    usize::from(level) <= k && bx.abs_diff(tx) <= 1 && by.abs_diff(ty) <= 1
                })
            };
            if k == 0 {
                for (r, &t) in texels.iter().enumerate() {
                    assert_eq!(
                        computed.contains(&(r as u32)),
                        near(t) || work.texels.iter().any(|e| e[1] & 0x3FFF_FFFF == r as u32),
                        "receiver {r}"
                    );
                }
                continue;
            }
            for (t, r) in levels.texels(k) {
                let on = at_level.contains(&(k, t));
                assert_eq!(on, near(t), "level {k} texel {t:?}");
                if on {
                    assert!(
                        computed.contains(&r),
                        "level {k} texel {t:?}: its receiver {r} is not computed"
                    );
                }
            }
        }
        // The far chart's cluster, at level 3, computes only what stands for its blocks.
        let far = texels.len() - 9;
        let far_computed = work
            .receivers
            .iter()
            .filter(|&&r| r as usize >= far)
            .count();
        assert!(
            far_computed < 9,
            "{far_computed} of the far chart's 9 receivers computed"
        );
        // The chart at levels 0 and 1 computes all its receivers at level 0 and their
        // neighbours, and only block representatives beyond.
        assert!(work.receivers.len() < texels.len());
    }
}
