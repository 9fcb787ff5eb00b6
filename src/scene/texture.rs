//! Texture decoding and mip chains.

use std::path::{Path, PathBuf};

use anyhow::{Context as _, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureKind {
    /// sRGB colour (map_Kd).
    Albedo,
    /// Cut-out coverage (map_d): the alpha channel if the image has one, else its
    /// luminance, in all four channels, linear.
    Coverage,
    /// Tangent-space normal map, linear.
    Normal,
}

#[derive(Clone, Debug)]
pub struct Texture {
    pub path: PathBuf,
    pub kind: TextureKind,
    pub width: u32,
    pub height: u32,
    /// RGBA8 levels down to 1x1; `mips[0]` is full size.
    pub mips: Vec<Vec<u8>>,
}

fn srgb_to_linear_lut() -> [f32; 256] {
    let mut lut = [0.0; 256];
    for (i, v) in lut.iter_mut().enumerate() {
        let c = i as f32 / 255.0;
        *v = if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        };
    }
    lut
}

fn linear_to_srgb_byte(x: f32) -> u8 {
    (crate::imageio::srgb_encode(x) * 255.0).round() as u8
}

/// Halves an RGBA image (floor, at least 1), averaging the up-to-2x2 source texels in the
/// space given by `decode`/`encode` per channel (alpha always linear).
fn downsample(
    src: &[u8],
    w: u32,
    h: u32,
    decode: &dyn Fn(usize, u8) -> f32,
    encode: &dyn Fn(usize, f32) -> u8,
) -> (Vec<u8>, u32, u32) {
    let nw = (w / 2).max(1);
    let nh = (h / 2).max(1);
    let mut out = vec![0u8; (nw * nh * 4) as usize];
    for y in 0..nh {
        for x in 0..nw {
            let xs = [(2 * x).min(w - 1), (2 * x + 1).min(w - 1)];
            let ys = [(2 * y).min(h - 1), (2 * y + 1).min(h - 1)];
            for c in 0..4 {
                let mut sum = 0.0;
                for &sy in &ys {
                    for &sx in &xs {
                        sum += decode(c, src[((sy * w + sx) * 4) as usize + c]);
                    }
                }
                out[((y * nw + x) * 4) as usize + c] = encode(c, sum / 4.0);
            }
        }
    }
    (out, nw, nh)
}

impl Texture {
    pub fn load(path: &Path, kind: TextureKind) -> Result<Texture> {
        let image =
            image::open(path).with_context(|| format!("cannot read texture {}", path.display()))?;
        let has_alpha = image.color().has_alpha();
        let mut rgba = image.to_rgba8();
        let (width, height) = rgba.dimensions();
        if kind == TextureKind::Coverage {
            for p in rgba.pixels_mut() {
                let c = if has_alpha {
                    p[3]
                } else {
                    (0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2]))
                        .round() as u8
                };
                p.0 = [c; 4];
            }
        }
        let mut mips = vec![rgba.into_raw()];
        let lut = srgb_to_linear_lut();
        let (mut w, mut h) = (width, height);
        while w > 1 || h > 1 {
            let src = mips.last().unwrap();
            let (next, nw, nh) = match kind {
                TextureKind::Albedo => downsample(
                    src,
                    w,
                    h,
                    &|c, v| {
                        if c < 3 {
                            lut[v as usize]
                        } else {
                            f32::from(v) / 255.0
                        }
                    },
                    &|c, x| {
                        if c < 3 {
                            linear_to_srgb_byte(x)
                        } else {
                            (x * 255.0).round() as u8
                        }
                    },
                ),
                TextureKind::Coverage | TextureKind::Normal => {
                    downsample(src, w, h, &|_, v| f32::from(v) / 255.0, &|_, x| {
                        (x * 255.0).round() as u8
                    })
                }
            };
            mips.push(next);
            w = nw;
            h = nh;
        }
        if kind == TextureKind::Normal {
            // Averaged normals shrink; renormalise each level's vectors.
            for level in mips.iter_mut().skip(1) {
                for p in level.chunks_exact_mut(4) {
                    let v = glam::Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 127.5 - 1.0;
                    let n = v.normalize_or_zero();
                    for c in 0..3 {
                        p[c] = ((n[c] + 1.0) * 127.5).round().clamp(0.0, 255.0) as u8;
                    }
                }
            }
        }
        Ok(Texture {
            path: path.to_path_buf(),
            kind,
            width,
            height,
            mips,
        })
    }

    /// Bytes of all levels.
    pub fn bytes(&self) -> usize {
        self.mips.iter().map(Vec::len).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_png(name: &str, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 4]) -> PathBuf {
        let path =
            std::env::temp_dir().join(format!("voxcone-tex-{}-{name}.png", std::process::id()));
        image::RgbaImage::from_fn(w, h, |x, y| image::Rgba(f(x, y)))
            .save(&path)
            .unwrap();
        path
    }

    #[test]
    fn albedo_mips_average_in_linear_space() {
        let path = write_png("checker", 4, 4, |x, y| {
            let v = if (x + y) % 2 == 0 { 255 } else { 0 };
            [v, v, v, 255]
        });
        let t = Texture::load(&path, TextureKind::Albedo).unwrap();
        std::fs::remove_file(&path).ok();
        assert_eq!(t.mips.len(), 3);
        // Linear 0.5 encodes to sRGB 188.
        assert_eq!(t.mips[2][0], 188);
    }

    #[test]
    fn odd_sizes_give_full_chains() {
        let path = write_png("odd", 5, 3, |_, _| [10, 20, 30, 255]);
        let t = Texture::load(&path, TextureKind::Coverage).unwrap();
        std::fs::remove_file(&path).ok();
        let sizes: Vec<usize> = t.mips.iter().map(Vec::len).collect();
        assert_eq!(sizes, vec![5 * 3 * 4, 2 * 4, 4]);
        // Opaque image: coverage comes from alpha.
        assert_eq!(t.mips[0][0], 255);
    }
}
