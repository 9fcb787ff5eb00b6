//! Reading and writing images: linear EXR radiance and sRGB PNG.

use std::path::Path;

use anyhow::{bail, Context as _, Result};

/// An RGB float image, row 0 at the top.
#[derive(Clone, Debug)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    /// Three floats per pixel.
    pub data: Vec<f32>,
}

fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default()
}

/// Writes raw linear radiance (no exposure, no tonemap) as RGB float32 OpenEXR.
pub fn write_exr(path: &Path, width: u32, height: u32, rgba_linear: &[f32]) -> Result<()> {
    let rgb: Vec<f32> = rgba_linear
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let image = image::Rgb32FImage::from_raw(width, height, rgb)
        .context("image size does not match its data")?;
    image
        .save_with_format(path, image::ImageFormat::OpenExr)
        .with_context(|| format!("writing {}", path.display()))
}

/// Writes sRGB-encoded RGBA bytes as an RGB PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba8_srgb: &[u8]) -> Result<()> {
    let rgb: Vec<u8> = rgba8_srgb
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let image = image::RgbImage::from_raw(width, height, rgb)
        .context("image size does not match its data")?;
    image
        .save_with_format(path, image::ImageFormat::Png)
        .with_context(|| format!("writing {}", path.display()))
}

/// Loads an image: `.exr` as linear floats (`true`), `.png`/`.jpg` as sRGB-encoded values
/// in [0, 1] (`false`).
pub fn load_rgb(path: &Path) -> Result<(RgbImage, bool)> {
    let hdr = match extension(path).as_str() {
        "exr" => true,
        "png" | "jpg" | "jpeg" => false,
        other => bail!(
            "{}: unsupported image type {other:?} (supported: .exr, .png, .jpg)",
            path.display()
        ),
    };
    let image = image::open(path).with_context(|| format!("reading {}", path.display()))?;
    let rgb = image.to_rgb32f();
    Ok((
        RgbImage {
            width: rgb.width(),
            height: rgb.height(),
            data: rgb.into_raw(),
        },
        hdr,
    ))
}

/// Clamps to [0, 1] and applies the sRGB OETF.
pub fn srgb_encode(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encode_known_values() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_encode(0.5) - 0.735_356_7).abs() < 1e-5);
        assert_eq!(srgb_encode(7.0), srgb_encode(1.0));
        assert_eq!(srgb_encode(-1.0), 0.0);
    }

    #[test]
    fn exr_round_trip_is_exact() {
        let path = std::env::temp_dir().join(format!("voxcone-exr-{}.exr", std::process::id()));
        let rgba: Vec<f32> = (0..2 * 3 * 4).map(|i| i as f32 * 0.37 + 1e-3).collect();
        write_exr(&path, 2, 3, &rgba).unwrap();
        let (image, hdr) = load_rgb(&path).unwrap();
        std::fs::remove_file(&path).ok();
        assert!(hdr);
        let expected: Vec<f32> = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        assert_eq!(image.data, expected);
    }

    #[test]
    fn unknown_extension_is_explained() {
        let err = load_rgb(Path::new("x.bmpx")).unwrap_err();
        assert!(format!("{err:#}").contains("supported"));
    }
}
