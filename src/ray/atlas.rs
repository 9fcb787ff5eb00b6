//! Every scene texture's full-resolution level in one image, for shaders that look up a
//! material at any hit (`BINDING_RAY_ATLAS`): they filter it themselves, bilinearly with
//! wrap-around, as the path-traced references do (no mips).

use anyhow::{bail, Result};

use crate::scene::Texture;

/// Where the textures lie in the atlas.
pub struct Layout {
    pub width: u32,
    pub height: u32,
    /// Per texture: x, y, width, height in texels.
    pub rects: Vec<[u32; 4]>,
}

/// Packs `textures` on shelves `max_side` texels wide (the tallest first), each shelf as
/// tall as its first texture; errors when they do not fit a `max_side`² image.
pub fn pack(textures: &[Texture], max_side: u32) -> Result<Layout> {
    let mut order: Vec<usize> = (0..textures.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse((textures[i].height, textures[i].width)));
    let mut rects = vec![[0; 4]; textures.len()];
    let (mut x, mut y, mut shelf, mut width) = (0u32, 0u32, 0u32, 1u32);
    for i in order {
        let (w, h) = (textures[i].width, textures[i].height);
        if w > max_side {
            bail!(
                "texture {} is {w} texels wide, more than the {max_side} of the device's images",
                textures[i].path.display()
            );
        }
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
    if height > max_side {
        let texels: u64 = textures
            .iter()
            .map(|t| u64::from(t.width) * u64::from(t.height))
            .sum();
        bail!(
            "the scene's {} textures ({texels} texels) do not fit one {max_side}x{max_side} \
             atlas for ray casting",
            textures.len()
        );
    }
    Ok(Layout {
        width,
        height,
        rects,
    })
}

/// The atlas's RGBA8 texels, row after row.
pub fn texels(textures: &[Texture], layout: &Layout) -> Vec<u8> {
    let row = layout.width as usize * 4;
    let mut out = vec![0u8; row * layout.height as usize];
    for (texture, &[x, y, w, _]) in textures.iter().zip(&layout.rects) {
        let src = &texture.mips[0];
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

    fn texture(width: u32, height: u32, value: u8) -> Texture {
        Texture {
            path: format!("{width}x{height}").into(),
            kind: TextureKind::Albedo,
            width,
            height,
            mips: vec![vec![value; (width * height * 4) as usize]],
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
        let error = pack(&[texture(300, 1, 0)], 128).err().unwrap().to_string();
        assert!(error.contains("300 texels wide"), "{error}");
        let many: Vec<Texture> = (0..5).map(|_| texture(128, 64, 0)).collect();
        let error = pack(&many, 128).err().unwrap().to_string();
        assert!(error.contains("do not fit"), "{error}");
    }
}
