//! Image comparison as `shared/reference/compare.py` does it: LDR-FLIP on the sRGB
//! encoding of clamp(x * 2^exposure), relative MSE and RMSE on linear values.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use serde::Serialize;

use crate::imageio::{load_rgb, srgb_encode, RgbImage};

#[derive(Serialize, Debug, Clone)]
pub struct Metrics {
    pub reference: String,
    pub test: String,
    pub width: u32,
    pub height: u32,
    /// Mean LDR-FLIP (0 = identical).
    pub flip_ldr: f32,
    /// Mean of (ref - test)^2 / (ref^2 + 0.01) over pixels and channels; both inputs EXR.
    pub relmse_linear: Option<f32>,
    pub rmse_linear: Option<f32>,
    /// PSNR of the LDR images, data range 1.
    pub psnr_db: f32,
}

#[derive(Clone, Debug, Default)]
pub struct CompareOptions {
    /// Stops applied to EXR inputs before the LDR metrics.
    pub exposure: f32,
    /// Where to write the FLIP error map (magma) as a PNG.
    pub flip_map: Option<PathBuf>,
}

/// The LDR image compare.py measures: EXR → sRGB(clamp(x·2^ev)); PNG as stored.
pub fn ldr(image: &RgbImage, is_hdr: bool, exposure: f32) -> RgbImage {
    let scale = 2f32.powf(exposure);
    RgbImage {
        width: image.width,
        height: image.height,
        data: if is_hdr {
            image.data.iter().map(|&x| srgb_encode(x * scale)).collect()
        } else {
            image.data.clone()
        },
    }
}

fn to_flip(image: &RgbImage) -> nv_flip::FlipImageRgb8 {
    let bytes: Vec<u8> = image
        .data
        .iter()
        .map(|&x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    nv_flip::FlipImageRgb8::with_data(image.width, image.height, &bytes)
}

fn check_sizes(a: &RgbImage, b: &RgbImage) -> Result<()> {
    if (a.width, a.height) != (b.width, b.height) {
        bail!(
            "image sizes differ: reference {}x{}, test {}x{}",
            a.width,
            a.height,
            b.width,
            b.height
        );
    }
    Ok(())
}

/// Mean FLIP of two sRGB-encoded images and the per-pixel error map.
pub fn flip_ldr(reference: &RgbImage, test: &RgbImage) -> Result<(f32, nv_flip::FlipImageFloat)> {
    check_sizes(reference, test)?;
    let map = nv_flip::flip(
        to_flip(reference),
        to_flip(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let pool = nv_flip::FlipPool::from_image(&map);
    Ok((pool.mean(), map))
}

pub fn compare(reference: &Path, test: &Path, options: &CompareOptions) -> Result<Metrics> {
    let (ref_image, ref_hdr) = load_rgb(reference)?;
    let (test_image, test_hdr) = load_rgb(test)?;
    check_sizes(&ref_image, &test_image)?;
    let ref_ldr = ldr(&ref_image, ref_hdr, options.exposure);
    let test_ldr = ldr(&test_image, test_hdr, options.exposure);
    let (flip, map) = flip_ldr(&ref_ldr, &test_ldr)?;
    if let Some(path) = &options.flip_map {
        let colored = map.apply_color_lut(&nv_flip::magma_lut());
        let rgb = image::RgbImage::from_raw(ref_image.width, ref_image.height, colored.to_vec())
            .expect("FLIP map has the image's size");
        rgb.save(path)
            .map_err(|e| anyhow::anyhow!("writing {}: {e}", path.display()))?;
    }
    let n = ref_image.data.len() as f64;
    let (relmse, rmse) = if ref_hdr && test_hdr {
        let mut rel = 0.0f64;
        let mut sq = 0.0f64;
        for (&r, &t) in ref_image.data.iter().zip(&test_image.data) {
            let d = f64::from(r - t);
            rel += d * d / (f64::from(r) * f64::from(r) + 1e-2);
            sq += d * d;
        }
        (Some((rel / n) as f32), Some((sq / n).sqrt() as f32))
    } else {
        (None, None)
    };
    let mse: f64 = ref_ldr
        .data
        .iter()
        .zip(&test_ldr.data)
        .map(|(&r, &t)| f64::from(r - t).powi(2))
        .sum::<f64>()
        / n;
    Ok(Metrics {
        reference: reference.display().to_string(),
        test: test.display().to_string(),
        width: ref_image.width,
        height: ref_image.height,
        flip_ldr: flip,
        relmse_linear: relmse,
        rmse_linear: rmse,
        psnr_db: (10.0 * (1.0 / mse.max(1e-20)).log10()) as f32,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shared() -> Option<PathBuf> {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared");
        if dir.join("reference").is_dir() {
            Some(dir)
        } else {
            eprintln!("skipped: ../shared/reference is absent");
            None
        }
    }

    #[test]
    fn identical_images_score_zero() {
        let image = RgbImage {
            width: 8,
            height: 8,
            data: (0..192).map(|i| (i % 17) as f32 / 17.0).collect(),
        };
        let (flip, _) = flip_ldr(&image, &image).unwrap();
        assert_eq!(flip, 0.0);
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let a = RgbImage {
            width: 2,
            height: 2,
            data: vec![0.0; 12],
        };
        let b = RgbImage {
            width: 2,
            height: 1,
            data: vec![0.0; 6],
        };
        let err = flip_ldr(&a, &b).map(|(mean, _)| mean).unwrap_err();
        assert!(format!("{err:#}").contains("2x1"));
    }

    /// compare.py scores these two references 0.5895 LDR-FLIP and 0.18797 relMSE
    /// (shared/reference/cmp_cornell_point_direct.json).
    #[test]
    fn matches_compare_py_on_the_references() {
        let Some(shared) = shared() else { return };
        let r = shared.join("reference");
        let m = compare(
            &r.join("cornell_point.exr"),
            &r.join("cornell_point_direct.exr"),
            &CompareOptions::default(),
        )
        .unwrap();
        assert!((m.flip_ldr - 0.5895).abs() < 0.005, "flip {}", m.flip_ldr);
        let relmse = m.relmse_linear.unwrap();
        assert!((relmse - 0.18797).abs() < 0.0019, "relmse {relmse}");
    }
}
