//! Every scene texture in one image, for shaders that look up a material at any hit
//! (`BINDING_RAY_ATLAS`): they filter it themselves, bilinearly with wrap-around, as the
//! path-traced references do (no mips). Each texture is stored at full resolution where
//! the atlas can hold them all; where it cannot, at the mip level that fits, as the
//! rasterizer does with a texture beyond the device's largest image.

use anyhow::{bail, Result};

use crate::scene::Texture;

/// Where the textures lie in the atlas.
pub struct Layout {
    pub width: u32,
    pub height: u32,
    /// Per texture: x, y, width, height in texels.
    pub rects: Vec<[u32; 4]>,
    /// Per texture: the mip level stored (0 = full resolution).
    pub levels: Vec<usize>,
}

/// Width and height of `texture`'s mip `level`.
fn level_size(texture: &Texture, level: usize) -> (u32, u32) {
    (
        (texture.width >> level).max(1),
        (texture.height >> level).max(1),
    )
}

/// Packs `textures` into a `max_side`² image: each at its first mip level within
/// `max_side`, and, where the atlas overflows, every texture one level smaller at a time
/// (with a warning), until they fit. Errors only when even their smallest levels do not.
pub fn pack(textures: &[Texture], max_side: u32) -> Result<Layout> {
    let fitting: Vec<usize> = textures
        .iter()
        .map(|t| {
            (0..t.mips.len())
                .find(|&l| {
                    let (w, h) = level_size(t, l);
                    w <= max_side && h <= max_side
                })
                .unwrap_or(t.mips.len() - 1)
        })
        .collect();
    let deepest = textures.iter().map(|t| t.mips.len()).max().unwrap_or(1);
    for drop in 0..deepest {
        let levels: Vec<usize> = textures
            .iter()
            .zip(&fitting)
            .map(|(t, &f)| (f + drop).min(t.mips.len() - 1))
            .collect();
        let sizes: Vec<(u32, u32)> = textures
            .iter()
            .zip(&levels)
            .map(|(t, &l)| level_size(t, l))
            .collect();
        if let Some((width, height, rects)) = shelves(&sizes, max_side) {
            if let Some((i, _)) = levels.iter().enumerate().find(|(_, &l)| l > 0) {
                log::warn!(
                    "ray casting reads some textures at lower resolution to fit the device's \
                     {max_side}x{max_side} atlas (texture {} at mip level {}, {} of {} \
                     textures reduced)",
                    textures[i].path.display(),
                    levels[i],
                    levels.iter().filter(|&&l| l > 0).count(),
                    textures.len()
                );
            }
            return Ok(Layout {
                width,
                height,
                rects,
                levels,
            });
        }
    }
    bail!(
        "the scene's {} textures do not fit one {max_side}x{max_side} atlas for ray casting \
         even at 1x1 texel each",
        textures.len()
    )
}

/// Rectangles of `sizes` on shelves `max_side` texels wide (the tallest first), each
/// shelf as tall as its first texture: the atlas's width, height and the rectangles, or
/// `None` when they do not fit a `max_side`² image.
fn shelves(sizes: &[(u32, u32)], max_side: u32) -> Option<(u32, u32, Vec<[u32; 4]>)> {
    let mut order: Vec<usize> = (0..sizes.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse((sizes[i].1, sizes[i].0)));
    let mut rects = vec![[0; 4]; sizes.len()];
    let (mut x, mut y, mut shelf, mut width) = (0u32, 0u32, 0u32, 1u32);
    for i in order {
        let (w, h) = sizes[i];
        if x + w > max_side {
            (x, y, shelf) = (0, y + shelf, 0);
        }
        if shelf == 0 {
            shelf = h;
        }
        rects[i] = [x, y, w, h];
        x += w;
        width = width.max(x);
    }
    let height = (y + shelf).max(1);
    (height <= max_side).then_some((width, height, rects))
}

/// The atlas's RGBA8 texels, row after row.
pub fn texels(textures: &[Texture], layout: &Layout) -> Vec<u8> {
    let row = layout.width as usize * 4;
    let mut out = vec![0u8; row * layout.height as usize];
    for ((texture, &[x, y, w, _]), &level) in textures.iter().zip(&layout.rects).zip(&layout.levels)
    {
        let src = &texture.mips[level];
        let src_row = w as usize * 4;
        for (j, line) in src.chunks_exact(src_row).enumerate() {
            let start = (y as usize + j) * row + x as usize * 4;
            out[start..start + src_row].copy_from_slice(line);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::TextureKind;

    /// A texture of `value` in every byte of its full mip chain; level `l` also marks its
    /// first byte with `l`, so that a test can tell which level was stored.
    fn texture(width: u32, height: u32, value: u8) -> Texture {
        let mut mips = Vec::new();
        let (mut w, mut h) = (width, height);
        loop {
            let mut level = vec![value; (w * h * 4) as usize];
            level[1] = mips.len() as u8;
            mips.push(level);
            if w == 1 && h == 1 {
                break;
            }
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
        }
        Texture {
            path: format!("{width}x{height}").into(),
            kind: TextureKind::Albedo,
            width,
            height,
            mips,
        }
    }

    /// The packed textures do not overlap, stay inside the atlas, and their texels land
    /// where their rectangles say.
    #[test]
    fn textures_are_packed_without_overlap() {
        let textures: Vec<Texture> = [(64, 32), (16, 16), (64, 64), (30, 10), (100, 5)]
            .iter()
            .enumerate()
            .map(|(i, &(w, h))| texture(w, h, i as u8 + 1))
            .collect();
        let layout = pack(&textures, 128).unwrap();
        let texels = texels(&textures, &layout);
        for (i, &[x, y, w, h]) in layout.rects.iter().enumerate() {
            assert!(x + w <= layout.width && y + h <= layout.height, "{i}");
            for (j, other) in layout.rects.iter().enumerate().skip(i + 1) {
                let apart = x + w <= other[0]
                    || other[0] + other[2] <= x
                    || y + h <= other[1]
                    || other[1] + other[3] <= y;
                assert!(apart, "textures {i} and {j} overlap");
            }
            let at = |tx: u32, ty: u32| texels[((ty * layout.width + tx) * 4) as usize];
            assert_eq!(at(x, y), i as u8 + 1);
            assert_eq!(at(x + w - 1, y + h - 1), i as u8 + 1);
        }
        assert!(
            layout.levels.iter().all(|&l| l == 0),
            "all fit at full size"
        );
    }

    /// A texture wider than the atlas is stored at its first level that fits; textures
    /// that overflow the atlas together are all stored one level smaller at a time.
    #[test]
    fn textures_too_large_are_stored_at_a_level_that_fits() {
        let wide = [texture(300, 1, 7)];
        let layout = pack(&wide, 128).unwrap();
        assert_eq!(layout.levels, [2]);
        assert_eq!(layout.rects[0], [0, 0, 75, 1]);
        assert_eq!(texels(&wide, &layout)[..2], [7, 2], "level 2's texels");

        let many: Vec<Texture> = (0..5).map(|_| texture(128, 64, 0)).collect();
        let layout = pack(&many, 128).unwrap();
        assert_eq!(
            layout.levels, [1; 5],
            "five 128x64 fit a 128x128 atlas at 64x32"
        );
        assert!(layout.height <= 128);
    }
}
