//! Texture decoding and mip chains.
//!
//! Mips are built on the CPU so that each kind is filtered in the space where averaging
//! is meaningful: albedo in linear light, normals as unit vectors.

use std::path::{Path, PathBuf};

use anyhow::{ensure, Context as _, Result};
use glam::{Vec3, Vec4};
use image::DynamicImage;

use crate::imageio::{srgba8_decode, srgba8_encode, unorm8};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TextureKind {
    /// sRGB colour (map_Kd; glTF's base colour and emissive textures); alpha is linear.
    Albedo,
    /// Cut-out coverage (map_d), linear, in all four channels: the alpha channel when the
    /// image has one that is not entirely opaque, else the luminance (Rec. 601 luma, as
    /// PIL's `convert("L")` in the path-traced references).
    Coverage,
    /// Tangent-space normal map, linear: xyz = 2 * rgb - 1.
    Normal,
}

#[derive(Clone, Debug)]
pub struct Texture {
    pub path: PathBuf,
    pub kind: TextureKind,
    pub width: u32,
    pub height: u32,
    /// RGBA8 levels down to 1x1; `mips[0]` is full size and level `i + 1` is
    /// `max(1, floor(size_i / 2))` on each axis.
    pub mips: Vec<Vec<u8>>,
}

/// How a glTF alpha (`MASK`, and the texture of `BLEND`) becomes a cut-out coverage
/// texture: alpha x `factor`, mapped piecewise linearly so that `cutoff` lands on the
/// shaders' fixed threshold of one half (0 stays 0, 1 stays 1). The order of the values,
/// and so which texels pass, is kept, and the mips still average coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlphaCutout {
    pub factor: f32,
    pub cutoff: f32,
}

impl AlphaCutout {
    fn coverage(&self, alpha: f32) -> f32 {
        let a = (alpha * self.factor).clamp(0.0, 1.0);
        if a < self.cutoff {
            0.5 * a / self.cutoff
        } else if self.cutoff < 1.0 {
            0.5 + 0.5 * (a - self.cutoff) / (1.0 - self.cutoff)
        } else {
            0.5
        }
    }
}

/// A conversion of a texture's texels at load time, beyond its kind's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Adjust {
    /// A coverage texture from the image's alpha.
    Cutout(AlphaCutout),
    /// A normal map's tangent-plane components times this (glTF `normalTexture.scale`),
    /// renormalised, as the format's shaders do per sample.
    NormalScale(f32),
}

impl Adjust {
    /// The adjustment's identity, for telling textures apart.
    pub fn key(&self) -> [u32; 3] {
        match self {
            Adjust::Cutout(c) => [0, c.factor.to_bits(), c.cutoff.to_bits()],
            Adjust::NormalScale(scale) => [1, scale.to_bits(), 0],
        }
    }
}

impl Texture {
    /// Decodes image file `path` as `kind`, with `adjust`.
    pub fn load(path: &Path, kind: TextureKind, adjust: Option<Adjust>) -> Result<Texture> {
        let image = image::ImageReader::open(path)
            .and_then(|r| r.with_guessed_format())
            .with_context(|| format!("cannot read texture {}", path.display()))?
            .decode()
            .with_context(|| format!("cannot decode texture {}", path.display()))?;
        Self::checked(path, kind, adjust, &image)
    }

    /// Decodes the encoded image `bytes` (named `name` in messages).
    pub fn decode(
        name: &Path,
        bytes: &[u8],
        kind: TextureKind,
        adjust: Option<Adjust>,
    ) -> Result<Texture> {
        let image = image::load_from_memory(bytes)
            .with_context(|| format!("cannot decode texture {}", name.display()))?;
        Self::checked(name, kind, adjust, &image)
    }

    fn checked(
        path: &Path,
        kind: TextureKind,
        adjust: Option<Adjust>,
        image: &DynamicImage,
    ) -> Result<Texture> {
        ensure!(
            image.width() > 0 && image.height() > 0,
            "texture {} is empty",
            path.display()
        );
        Ok(Texture::from_image(path.to_path_buf(), kind, adjust, image))
    }

    /// Converts a decoded, non-empty image for `kind` and builds its mips.
    fn from_image(
        path: PathBuf,
        kind: TextureKind,
        adjust: Option<Adjust>,
        image: &DynamicImage,
    ) -> Texture {
        let (width, height) = (image.width(), image.height());
        let level0 = match (kind, adjust) {
            (TextureKind::Coverage, Some(Adjust::Cutout(cutout))) => alpha_coverage(image, cutout),
            (TextureKind::Normal, Some(Adjust::NormalScale(scale))) => scaled_normals(image, scale),
            // Float images hold linear values; bytes of an albedo texture must be sRGB.
            (TextureKind::Albedo, _) if is_float(image) => rgba32f_to_srgb8(image),
            (TextureKind::Albedo | TextureKind::Normal, _) => image.to_rgba8().into_raw(),
            (TextureKind::Coverage, _) => coverage(image),
        };
        Texture {
            path,
            kind,
            width,
            height,
            mips: mip_chain(kind, width, height, level0),
        }
    }

    /// Bytes of all levels.
    pub fn bytes(&self) -> usize {
        self.mips.iter().map(Vec::len).sum()
    }
}

fn is_float(image: &DynamicImage) -> bool {
    matches!(
        image,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    )
}

fn rgba32f_to_srgb8(image: &DynamicImage) -> Vec<u8> {
    image
        .to_rgba32f()
        .pixels()
        .flat_map(|p| srgba8_encode(p.0))
        .collect()
}

/// Normals of a normal map with x and y times `scale`, renormalised (alpha kept).
fn scaled_normals(image: &DynamicImage, scale: f32) -> Vec<u8> {
    image
        .to_rgba8()
        .pixels()
        .flat_map(|p| {
            let v = decode(TextureKind::Normal, &p.0);
            let n = (v.truncate() * Vec3::new(scale, scale, 1.0)).normalize_or(Vec3::Z);
            encode(TextureKind::Normal, n.extend(v.w))
        })
        .collect()
}

/// The alpha channel (1 without one) through `cutout`, in every channel.
fn alpha_coverage(image: &DynamicImage, cutout: AlphaCutout) -> Vec<u8> {
    image
        .to_rgba8()
        .pixels()
        .flat_map(|p| [unorm8(cutout.coverage(f32::from(p[3]) / 255.0)); 4])
        .collect()
}

fn coverage(image: &DynamicImage) -> Vec<u8> {
    let rgba = image.to_rgba8();
    let use_alpha = image.color().has_alpha() && rgba.pixels().any(|p| p[3] < 255);
    rgba.pixels()
        .flat_map(|p| {
            let c = if use_alpha {
                p[3]
            } else {
                let [r, g, b, _] = p.0.map(f32::from);
                (0.299 * r + 0.587 * g + 0.114 * b).round() as u8
            };
            [c; 4]
        })
        .collect()
}

fn decode(kind: TextureKind, p: &[u8]) -> Vec4 {
    match kind {
        TextureKind::Albedo => Vec4::from_array(srgba8_decode([p[0], p[1], p[2], p[3]])),
        TextureKind::Coverage => unorm_vec4(p),
        TextureKind::Normal => {
            let v = unorm_vec4(p);
            (v.truncate() * 2.0 - 1.0).extend(v.w)
        }
    }
}

fn unorm_vec4(p: &[u8]) -> Vec4 {
    Vec4::from_array([p[0], p[1], p[2], p[3]].map(f32::from)) / 255.0
}

fn encode(kind: TextureKind, v: Vec4) -> [u8; 4] {
    match kind {
        TextureKind::Albedo => srgba8_encode(v.to_array()),
        TextureKind::Coverage => v.to_array().map(unorm8),
        TextureKind::Normal => {
            let n = v.truncate() * 0.5 + 0.5;
            [unorm8(n.x), unorm8(n.y), unorm8(n.z), unorm8(v.w)]
        }
    }
}

/// Box-filters a `w` x `h` level (texel `i` from `fetch`) to `max(1, w / 2)` x
/// `max(1, h / 2)`. Source coordinates are clamped, so a 1-texel axis averages with itself;
/// on odd axes the last row or column is left out, keeping every texel a 2x2 average.
fn halve(w: usize, h: usize, fetch: impl Fn(usize) -> Vec4) -> Vec<Vec4> {
    let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
    let mut out = Vec::with_capacity(nw * nh);
    for y in 0..nh {
        let rows = [(2 * y).min(h - 1), (2 * y + 1).min(h - 1)];
        for x in 0..nw {
            let cols = [(2 * x).min(w - 1), (2 * x + 1).min(w - 1)];
            let sum: Vec4 = rows
                .iter()
                .flat_map(|&r| cols.iter().map(move |&c| r * w + c))
                .map(&fetch)
                .sum();
            out.push(sum * 0.25);
        }
    }
    out
}

/// All levels of an RGBA8 image. Averages are carried in f32 from level to level, so
/// rounding does not accumulate down the chain.
fn mip_chain(kind: TextureKind, width: u32, height: u32, level0: Vec<u8>) -> Vec<Vec<u8>> {
    let (mut w, mut h) = (width as usize, height as usize);
    let mut mips = vec![level0];
    let mut previous: Vec<Vec4> = Vec::new();
    while w > 1 || h > 1 {
        let mut next = if previous.is_empty() {
            let texels = &mips[0];
            halve(w, h, |i| decode(kind, &texels[4 * i..4 * i + 4]))
        } else {
            halve(w, h, |i| previous[i])
        };
        if kind == TextureKind::Normal {
            // Averaged unit vectors are shorter than one; +Z (unperturbed) where they cancel.
            for v in &mut next {
                *v = v.truncate().normalize_or(Vec3::Z).extend(v.w);
            }
        }
        mips.push(next.iter().flat_map(|&v| encode(kind, v)).collect());
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
        previous = next;
    }
    mips
}

#[cfg(test)]
mod tests {
    use image::{Rgba, RgbaImage};

    use super::super::testing::TempDir;
    use super::*;

    fn texture(kind: TextureKind, image: RgbaImage) -> Texture {
        Texture::from_image(
            PathBuf::from("test.png"),
            kind,
            None,
            &DynamicImage::ImageRgba8(image),
        )
    }

    #[test]
    fn albedo_mips_average_in_linear_space() {
        let checker = RgbaImage::from_fn(4, 4, |x, y| {
            let v = if (x + y) % 2 == 0 { 255 } else { 0 };
            Rgba([v, v, v, 255])
        });
        let t = texture(TextureKind::Albedo, checker);
        assert_eq!(t.mips.len(), 3);
        // Linear 0.5 is sRGB 0.7354, byte 188 (a gamma-space average would give 128).
        assert_eq!(t.mips[1], [188, 188, 188, 255].repeat(4));
        assert_eq!(t.mips[2], [188, 188, 188, 255]);
    }

    #[test]
    fn odd_sizes_give_full_chains() {
        let t = texture(
            TextureKind::Coverage,
            RgbaImage::from_pixel(5, 3, Rgba([10, 20, 30, 255])),
        );
        let sizes: Vec<usize> = t.mips.iter().map(Vec::len).collect();
        assert_eq!(sizes, vec![5 * 3 * 4, 2 * 4, 4]);
        let t = texture(TextureKind::Albedo, RgbaImage::new(1, 6));
        let sizes: Vec<usize> = t.mips.iter().map(Vec::len).collect();
        assert_eq!(sizes, vec![6 * 4, 3 * 4, 4]);
    }

    #[test]
    fn coverage_from_alpha_else_luminance() {
        let cut = RgbaImage::from_fn(2, 1, |x, _| {
            Rgba([255, 255, 255, if x == 0 { 0 } else { 200 }])
        });
        let t = texture(TextureKind::Coverage, cut);
        assert_eq!(t.mips[0], [0, 0, 0, 0, 200, 200, 200, 200]);
        assert_eq!(t.mips[1], [100; 4], "linear average");
        // Opaque alpha says nothing: the luminance is the mask.
        let mask = RgbaImage::from_fn(2, 1, |x, _| {
            if x == 0 {
                Rgba([0, 0, 0, 255])
            } else {
                Rgba([0, 255, 0, 255])
            }
        });
        let t = texture(TextureKind::Coverage, mask);
        assert_eq!(t.mips[0], [0, 0, 0, 0, 150, 150, 150, 150]);
        let grey = DynamicImage::ImageLuma8(image::GrayImage::from_pixel(1, 1, image::Luma([77])));
        let t = Texture::from_image(PathBuf::new(), TextureKind::Coverage, None, &grey);
        assert_eq!(t.mips[0], [77; 4]);
    }

    #[test]
    fn alpha_cutout_puts_the_cutoff_on_one_half() {
        let cutout = AlphaCutout {
            factor: 1.0,
            cutoff: 0.25,
        };
        // Alpha bytes around the cutoff (0.25 = byte 63.75): those at or above it must
        // reach the shaders' threshold 0.5, those below must not.
        let alphas = [0u8, 63, 64, 128, 255];
        let image = RgbaImage::from_fn(5, 1, |x, _| Rgba([9, 9, 9, alphas[x as usize]]));
        let t = Texture::from_image(
            PathBuf::new(),
            TextureKind::Coverage,
            Some(Adjust::Cutout(cutout)),
            &DynamicImage::ImageRgba8(image),
        );
        let kept: Vec<bool> = t.mips[0]
            .chunks(4)
            .map(|p| p[0] as f32 / 255.0 >= 0.5)
            .collect();
        assert_eq!(kept, [false, false, true, true, true]);
        assert_eq!((t.mips[0][0], t.mips[0][16]), (0, 255), "0 and 1 stay");
        // The factor scales alpha first: 0.5 x 255 falls below a cutoff of 0.6.
        let half = AlphaCutout {
            factor: 0.5,
            cutoff: 0.6,
        };
        assert!(half.coverage(1.0) < 0.5 && half.coverage(0.0) == 0.0);
        let all = AlphaCutout {
            factor: 1.0,
            cutoff: 0.0,
        };
        assert!(all.coverage(0.0) >= 0.5, "cutoff 0 keeps everything");
    }

    #[test]
    fn normal_scale_tilts_the_normals() {
        // A normal tilted 45 degrees towards +X; scale 0 flattens it, 2 tilts it further.
        let image = RgbaImage::from_pixel(1, 1, Rgba([218, 128, 218, 255]));
        let tilt = |scale: f32| {
            let t = Texture::from_image(
                PathBuf::new(),
                TextureKind::Normal,
                Some(Adjust::NormalScale(scale)),
                &DynamicImage::ImageRgba8(image.clone()),
            );
            let v = decode(TextureKind::Normal, &t.mips[0]);
            v.x.atan2(v.z).to_degrees()
        };
        assert!(tilt(0.0).abs() < 0.5, "{}", tilt(0.0));
        assert!((tilt(1.0) - 45.0).abs() < 1.0, "{}", tilt(1.0));
        assert!(
            (tilt(2.0) - 2f32.atan().to_degrees()).abs() < 1.0,
            "{}",
            tilt(2.0)
        );
    }

    #[test]
    fn normal_mips_are_renormalised() {
        // +X and +Z side by side average to their bisector, not to a shorter vector.
        let normals = RgbaImage::from_fn(2, 1, |x, _| {
            if x == 0 {
                Rgba([255, 128, 128, 255])
            } else {
                Rgba([128, 128, 255, 255])
            }
        });
        let t = texture(TextureKind::Normal, normals);
        let [x, y, z, a] = t.mips[1][..] else {
            panic!("one texel")
        };
        let n = Vec3::new(x as f32, y as f32, z as f32) / 127.5 - 1.0;
        assert!((n.length() - 1.0).abs() < 0.02, "{n}");
        assert!((n.x - n.z).abs() < 0.02 && n.x > 0.69, "{n}");
        assert_eq!(a, 255);
    }

    #[test]
    fn float_albedo_is_encoded_to_srgb() {
        let image = DynamicImage::ImageRgb32F(image::Rgb32FImage::from_pixel(
            1,
            1,
            image::Rgb([0.5, 0.0, 1.0]),
        ));
        let t = Texture::from_image(PathBuf::new(), TextureKind::Albedo, None, &image);
        assert_eq!(t.mips[0], [188, 0, 255, 255]);
    }

    #[test]
    fn load_reads_files_and_names_bad_ones() {
        let dir = TempDir::new("texture");
        let path = dir.0.join("t.png");
        RgbaImage::from_pixel(3, 2, Rgba([1, 2, 3, 4]))
            .save(&path)
            .unwrap();
        let t = Texture::load(&path, TextureKind::Albedo, None).unwrap();
        assert_eq!((t.width, t.height, t.mips.len()), (3, 2, 2));
        assert_eq!(t.bytes(), 3 * 2 * 4 + 4);
        let junk = dir.write("junk.png", "not an image");
        let message = format!(
            "{:#}",
            Texture::load(&junk, TextureKind::Albedo, None).unwrap_err()
        );
        assert!(message.contains("junk.png"), "{message}");
    }
}
