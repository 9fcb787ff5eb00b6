//! Image comparison as `shared/reference/compare.py` does it: LDR-FLIP and PSNR on the sRGB
//! encoding of clamp(x * 2^exposure), relative MSE and RMSE on linear values.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use serde::Serialize;

use crate::imageio::{load_rgb, srgb_encode, write_png_rgb, RgbImage};

#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct Metrics {
    pub reference: String,
    pub test: String,
    pub width: u32,
    pub height: u32,
    /// Mean LDR-FLIP (0 = identical); the number the issues quote.
    pub flip_ldr: f32,
    /// Mean of (ref - test)^2 / (ref^2 + 0.01) over pixels and channels; both inputs EXR.
    pub relmse_linear: Option<f32>,
    /// Root mean square of ref - test over pixels and channels; both inputs EXR.
    pub rmse_linear: Option<f32>,
    /// PSNR of the LDR images, data range 1; infinite (JSON `null`) for identical images.
    pub psnr_db: f32,
    /// With `CompareOptions::blocks`: the same per block of the image.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blocks: Option<BlockMetrics>,
}

/// Where in the image two renders differ: the image cut into `blocks`² blocks (rows top
/// to bottom, each row left to right).
#[derive(Serialize, Debug, Clone, PartialEq)]
pub struct BlockMetrics {
    /// Blocks per side.
    pub blocks: u32,
    /// Mean LDR-FLIP of each block.
    pub flip_ldr: Vec<Vec<f32>>,
    /// Mean linear brightness (mean of RGB) of the test over the reference's, per block;
    /// both inputs EXR (`null` for a black reference block).
    pub brightness_ratio: Option<Vec<Vec<Option<f32>>>>,
}

impl BlockMetrics {
    /// A table of `flip / ratio` per block, one line per row of blocks.
    pub fn table(&self) -> String {
        let mut text = String::new();
        for (y, row) in self.flip_ldr.iter().enumerate() {
            let cells: Vec<String> = row
                .iter()
                .enumerate()
                .map(|(x, flip)| {
                    let ratio = self.brightness_ratio.as_ref().map(|r| r[y][x]);
                    match ratio {
                        Some(Some(r)) => format!("{flip:5.3}/{r:4.2}"),
                        Some(None) => format!("{flip:5.3}/  - "),
                        None => format!("{flip:5.3}"),
                    }
                })
                .collect();
            text += &cells.join(" ");
            text.push('\n');
        }
        text
    }
}

#[derive(Clone, Debug, Default)]
pub struct CompareOptions {
    /// Stops applied to EXR inputs before the LDR metrics.
    pub exposure: f32,
    /// Where to write the LDR-FLIP error map (magma) as a PNG.
    pub flip_map: Option<PathBuf>,
    /// Also measure each block of an N×N grid over the image.
    pub blocks: Option<u32>,
}

/// flip_evaluator's default viewing conditions: 0.7 m from a 0.7 m wide, 3840 pixel wide
/// monitor (67.0206 ppd). nv-flip's own default is the rounded 67.0.
fn pixels_per_degree() -> f32 {
    nv_flip::pixels_per_degree(0.7, 3840.0, 0.7)
}

/// The LDR image compare.py measures: EXR → sRGB(clamp(x·2^ev)); PNG as stored.
pub fn ldr(img: &RgbImage, is_hdr: bool, exposure: f32) -> RgbImage {
    let scale = 2f32.powf(exposure);
    RgbImage {
        width: img.width,
        height: img.height,
        data: if is_hdr {
            img.data.iter().map(|&x| srgb_encode(x * scale)).collect()
        } else {
            img.data.clone()
        },
    }
}

fn check_sizes(reference: &RgbImage, test: &RgbImage) -> Result<()> {
    if (reference.width, reference.height) != (test.width, test.height) {
        bail!(
            "image sizes differ: reference {}x{}, test {}x{}",
            reference.width,
            reference.height,
            test.width,
            test.height
        );
    }
    Ok(())
}

/// nv-flip takes 8-bit sRGB only, so the [0, 1] values are rounded to bytes. It asserts on
/// short data and multiplies sizes in u32, hence the checks.
fn to_flip(image: &RgbImage) -> Result<nv_flip::FlipImageRgb8> {
    let values = u32::checked_mul(image.width, image.height)
        .and_then(|n| n.checked_mul(3))
        .with_context(|| format!("{}x{} is too large for FLIP", image.width, image.height))?;
    if values == 0 || image.data.len() != values as usize {
        bail!(
            "a {}x{} image needs {values} values, it has {}",
            image.width,
            image.height,
            image.data.len()
        );
    }
    let bytes: Vec<u8> = image
        .data
        .iter()
        .map(|&x| (x.clamp(0.0, 1.0) * 255.0).round() as u8)
        .collect();
    Ok(nv_flip::FlipImageRgb8::with_data(
        image.width,
        image.height,
        &bytes,
    ))
}

/// Mean LDR-FLIP of two sRGB-encoded [0, 1] images, and the per-pixel error (row-major,
/// top row first).
pub fn flip_ldr(reference_ldr: &RgbImage, test_ldr: &RgbImage) -> Result<(f32, Vec<f32>)> {
    check_sizes(reference_ldr, test_ldr)?;
    let reference = to_flip(reference_ldr).context("reference image")?;
    let test = to_flip(test_ldr).context("test image")?;
    let map = nv_flip::flip(reference, test, pixels_per_degree()).to_vec();
    let mean = map.iter().map(|&e| f64::from(e)).sum::<f64>() / map.len() as f64;
    Ok((mean as f32, map))
}

/// Writes the error map through FLIP's magma colour map, as compare.py's `--flip-map`.
fn write_flip_map(path: &Path, width: u32, height: u32, map: &[f32]) -> Result<()> {
    let colored = nv_flip::FlipImageFloat::with_data(width, height, map)
        .apply_color_lut(&nv_flip::magma_lut());
    write_png_rgb(path, width, height, colored.to_vec())
}

/// Mean of `f(ref, test)` over all pixels and channels, accumulated in f64.
fn mean_of(reference: &[f32], test: &[f32], f: impl Fn(f64, f64) -> f64) -> f64 {
    let sum: f64 = reference
        .iter()
        .zip(test)
        .map(|(&r, &t)| f(f64::from(r), f64::from(t)))
        .sum();
    sum / reference.len() as f64
}

/// Loads both images and measures them as compare.py does; `opts.flip_map` also writes the
/// error map. SSIM and HDR-FLIP, which compare.py also prints, are not computed.
pub fn compare(reference: &Path, test: &Path, opts: &CompareOptions) -> Result<Metrics> {
    let (ref_image, ref_hdr) = load_rgb(reference)?;
    let (test_image, test_hdr) = load_rgb(test)?;
    check_sizes(&ref_image, &test_image)
        .with_context(|| format!("comparing {} with {}", reference.display(), test.display()))?;
    let ref_ldr = ldr(&ref_image, ref_hdr, opts.exposure);
    let test_ldr = ldr(&test_image, test_hdr, opts.exposure);
    let (flip, map) = flip_ldr(&ref_ldr, &test_ldr)?;
    if let Some(path) = &opts.flip_map {
        write_flip_map(path, ref_image.width, ref_image.height, &map)?;
    }
    let (relmse, rmse) = if ref_hdr && test_hdr {
        let (r, t) = (&ref_image.data, &test_image.data);
        let relmse = mean_of(r, t, |r, t| (r - t).powi(2) / (r * r + 1e-2));
        let mse = mean_of(r, t, |r, t| (r - t).powi(2));
        (Some(relmse as f32), Some(mse.sqrt() as f32))
    } else {
        (None, None)
    };
    let ldr_mse = mean_of(&ref_ldr.data, &test_ldr.data, |r, t| (r - t).powi(2));
    let linear = (ref_hdr && test_hdr).then_some((&ref_image, &test_image));
    let blocks = opts
        .blocks
        .map(|n| block_metrics(n, &map, ref_image.width, ref_image.height, linear))
        .transpose()?;
    Ok(Metrics {
        reference: reference.display().to_string(),
        test: test.display().to_string(),
        width: ref_image.width,
        height: ref_image.height,
        flip_ldr: flip,
        relmse_linear: relmse,
        rmse_linear: rmse,
        psnr_db: (10.0 * (1.0 / ldr_mse).log10()) as f32,
        blocks,
    })
}

/// Per block of an `n`×`n` grid over a `width`×`height` image: the mean of the LDR-FLIP
/// `map` and, given the linear reference and test images, the ratio of their mean
/// brightness.
fn block_metrics(
    n: u32,
    map: &[f32],
    width: u32,
    height: u32,
    linear: Option<(&RgbImage, &RgbImage)>,
) -> Result<BlockMetrics> {
    if n == 0 || n > width.min(height) {
        bail!(
            "--blocks {n}: the image ({width}x{height}) splits into 1 to {} blocks per side",
            width.min(height)
        );
    }
    let (w, h, n_us) = (width as usize, height as usize, n as usize);
    let span = |i: usize, size: usize| (i * size / n_us)..((i + 1) * size / n_us);
    let block_mean = |values: &[f32], channels: usize, bx: usize, by: usize| {
        let (mut sum, mut count) = (0.0f64, 0usize);
        for y in span(by, h) {
            let row = &values
                [(y * w + span(bx, w).start) * channels..(y * w + span(bx, w).end) * channels];
            sum += row.iter().map(|&v| f64::from(v)).sum::<f64>();
            count += row.len();
        }
        sum / count as f64
    };
    fn grid<T>(n: usize, f: impl Fn(usize, usize) -> T) -> Vec<Vec<T>> {
        (0..n)
            .map(|by| (0..n).map(|bx| f(bx, by)).collect())
            .collect()
    }
    let flip_ldr = grid(n_us, |bx, by| block_mean(map, 1, bx, by) as f32);
    let brightness_ratio = linear.map(|(reference, test)| {
        grid(n_us, |bx, by| {
            let r = block_mean(&reference.data, 3, bx, by);
            (r > 0.0).then(|| (block_mean(&test.data, 3, bx, by) / r) as f32)
        })
    });
    Ok(BlockMetrics {
        blocks: n,
        flip_ldr,
        brightness_ratio,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::imageio::write_exr;

    fn temp_path(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("voxcone-compare-{}-{name}", std::process::id()))
    }

    /// The reference renders.
    fn references() -> PathBuf {
        crate::scene::testing::shared_file("reference")
    }

    fn gradient(width: u32, height: u32, scale: f32) -> RgbImage {
        RgbImage {
            width,
            height,
            data: (0..width * height * 3)
                .map(|i| scale * (i % 23) as f32 / 11.0)
                .collect(),
        }
    }

    fn rgba_of(image: &RgbImage) -> Vec<f32> {
        image
            .data
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 1.0])
            .collect()
    }

    #[test]
    fn ppd_is_flip_evaluators_default() {
        assert!((pixels_per_degree() - 67.020_645).abs() < 1e-3);
    }

    #[test]
    fn ldr_encodes_only_hdr_inputs() {
        let image = RgbImage {
            width: 1,
            height: 1,
            data: vec![0.25, 0.5, 2.0],
        };
        let hdr = ldr(&image, true, 1.0);
        let expected = [srgb_encode(0.5), 1.0, 1.0];
        assert!(hdr
            .data
            .iter()
            .zip(expected)
            .all(|(a, b)| (a - b).abs() < 1e-6));
        assert_eq!(ldr(&image, false, 3.0), image);
    }

    #[test]
    fn identical_images_score_zero() {
        let image = gradient(16, 9, 1.3);
        let path = temp_path("same.exr");
        write_exr(&path, image.width, image.height, &rgba_of(&image)).unwrap();
        let metrics = compare(&path, &path, &CompareOptions::default());
        std::fs::remove_file(&path).ok();
        let metrics = metrics.unwrap();
        assert_eq!(metrics.flip_ldr, 0.0);
        assert_eq!(metrics.relmse_linear, Some(0.0));
        assert_eq!(metrics.rmse_linear, Some(0.0));
        assert_eq!(metrics.psnr_db, f32::INFINITY);
    }

    #[test]
    fn different_images_score_above_zero() {
        let (a, b) = (gradient(16, 9, 0.5), gradient(16, 9, 0.3));
        let (flip, map) = flip_ldr(&ldr(&a, true, 0.0), &ldr(&b, true, 0.0)).unwrap();
        assert_eq!(map.len(), 16 * 9);
        assert!(flip > 0.0 && map.iter().all(|e| (0.0..=1.0).contains(e)));
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let (a, b) = (gradient(4, 2, 1.0), gradient(2, 4, 1.0));
        let err = format!("{:#}", flip_ldr(&a, &b).unwrap_err());
        assert!(err.contains("4x2") && err.contains("2x4"), "{err}");

        let (pa, pb) = (temp_path("4x2.exr"), temp_path("2x4.exr"));
        write_exr(&pa, 4, 2, &rgba_of(&a)).unwrap();
        write_exr(&pb, 2, 4, &rgba_of(&b)).unwrap();
        let result = compare(&pa, &pb, &CompareOptions::default());
        std::fs::remove_file(&pa).ok();
        std::fs::remove_file(&pb).ok();
        let err = format!("{:#}", result.unwrap_err());
        assert!(err.contains("4x2") && err.contains("2x4.exr"), "{err}");
    }

    #[test]
    fn malformed_images_are_errors() {
        let empty = gradient(0, 0, 1.0);
        assert!(flip_ldr(&empty, &empty).is_err());
        let mut short = gradient(3, 3, 1.0);
        short.data.pop();
        assert!(flip_ldr(&short, &short).is_err());
        let huge = RgbImage {
            width: u32::MAX,
            height: 2,
            data: Vec::new(),
        };
        assert!(flip_ldr(&huge, &huge).is_err());
    }

    #[test]
    fn flip_map_is_written() {
        let (a, b) = (gradient(8, 4, 0.5), gradient(8, 4, 0.2));
        let (pa, pb, map) = (temp_path("a.exr"), temp_path("b.exr"), temp_path("map.png"));
        write_exr(&pa, 8, 4, &rgba_of(&a)).unwrap();
        write_exr(&pb, 8, 4, &rgba_of(&b)).unwrap();
        let opts = CompareOptions {
            flip_map: Some(map.clone()),
            ..Default::default()
        };
        let metrics = compare(&pa, &pb, &opts);
        let written = crate::imageio::load_rgb(&map);
        for path in [&pa, &pb, &map] {
            std::fs::remove_file(path).ok();
        }
        metrics.unwrap();
        let (image, _) = written.unwrap();
        assert_eq!((image.width, image.height), (8, 4));
    }

    /// Blocks locate a difference: a test twice as bright in its lower right quarter.
    #[test]
    fn blocks_locate_a_brighter_quarter() {
        let (w, h) = (128, 64);
        let a = gradient(w, h, 0.3);
        let mut b = a.clone();
        for y in h / 2..h {
            for x in w / 2..w {
                for c in 0..3 {
                    b.data[((y * w + x) * 3 + c) as usize] *= 2.0;
                }
            }
        }
        let (pa, pb) = (temp_path("quarter-a.exr"), temp_path("quarter-b.exr"));
        write_exr(&pa, w, h, &rgba_of(&a)).unwrap();
        write_exr(&pb, w, h, &rgba_of(&b)).unwrap();
        let opts = |blocks| CompareOptions {
            blocks: Some(blocks),
            ..Default::default()
        };
        let metrics = compare(&pa, &pb, &opts(2));
        let too_many = compare(&pa, &pb, &opts(65));
        for path in [&pa, &pb] {
            std::fs::remove_file(path).ok();
        }
        let blocks = metrics.unwrap().blocks.unwrap();
        let ratio = blocks.brightness_ratio.as_ref().unwrap();
        assert!((ratio[1][1].unwrap() - 2.0).abs() < 1e-6, "{:?}", ratio);
        // FLIP's spatial filters spread the difference a few pixels across the borders.
        let changed = blocks.flip_ldr[1][1];
        for (y, x) in [(0, 0), (0, 1), (1, 0)] {
            assert!((ratio[y][x].unwrap() - 1.0).abs() < 1e-6, "{:?}", ratio);
            assert!(
                blocks.flip_ldr[y][x] < 0.25 * changed,
                "{:?}",
                blocks.flip_ldr
            );
        }
        assert_eq!(blocks.table().lines().count(), 2);
        let error = too_many.unwrap_err().to_string();
        assert!(error.contains("--blocks 65"), "{error}");
    }

    fn assert_close(name: &str, got: f32, expected: f32, tolerance: f32) {
        assert!(
            (got - expected).abs() <= tolerance,
            "{name}: rust {got}, compare.py {expected}"
        );
    }

    /// Matches shared/reference/cmp_cornell_point_direct.json, written by compare.py.
    #[test]
    #[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
    fn matches_compare_py_exr_vs_exr() {
        let dir = references();
        let m = compare(
            &dir.join("cornell_point.exr"),
            &dir.join("cornell_point_direct.exr"),
            &CompareOptions::default(),
        )
        .unwrap();
        assert_close("flip_ldr", m.flip_ldr, 0.589_515_7, 0.005);
        assert_close("relmse", m.relmse_linear.unwrap(), 0.187_971_3, 0.001_88);
        assert_close("rmse", m.rmse_linear.unwrap(), 0.212_406, 0.002_12);
        assert_close("psnr", m.psnr_db, 14.324_428, 0.05);
    }

    /// compare.py sibenik_main.exr sibenik_main-modified.exr --exposure 2, on the copy this
    /// test writes: a darker left half plus a hashed per-pixel perturbation.
    #[test]
    #[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
    fn matches_compare_py_on_a_modified_copy() {
        let dir = references();
        let (image, _) = load_rgb(&dir.join("sibenik_main.exr")).unwrap();
        let width = image.width as usize;
        let modified: Vec<f32> = image
            .data
            .chunks_exact(3)
            .enumerate()
            .flat_map(|(i, p)| {
                let darken = if i % width < width / 2 { 0.6 } else { 1.0 };
                let hash = (i as u32).wrapping_mul(2_654_435_761) >> 24;
                let noise = 1.0 + (hash as f32 / 255.0 - 0.5) * 0.4;
                [p[0] * darken * noise, p[1] * darken, p[2] * noise, 1.0]
            })
            .collect();
        let copy = temp_path("sibenik_main-modified.exr");
        write_exr(&copy, image.width, image.height, &modified).unwrap();
        let opts = CompareOptions {
            exposure: 2.0,
            ..Default::default()
        };
        let m = compare(&dir.join("sibenik_main.exr"), &copy, &opts);
        std::fs::remove_file(&copy).ok();
        let m = m.unwrap();
        assert_close("flip_ldr", m.flip_ldr, 0.233_761_4, 0.005);
        assert_close("relmse", m.relmse_linear.unwrap(), 0.013_160_35, 0.000_132);
        assert_close("rmse", m.rmse_linear.unwrap(), 0.025_284_82, 0.000_253);
        assert_close("psnr", m.psnr_db, 24.379_886, 0.05);
    }

    /// compare.py cornell_area.png cornell_point.exr: PNG used as stored, no linear metrics.
    #[test]
    #[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
    fn matches_compare_py_png_vs_exr() {
        let dir = references();
        let m = compare(
            &dir.join("cornell_area.png"),
            &dir.join("cornell_point.exr"),
            &CompareOptions::default(),
        )
        .unwrap();
        assert_eq!((m.relmse_linear, m.rmse_linear), (None, None));
        assert_close("flip_ldr", m.flip_ldr, 0.754_727_7, 0.005);
        assert_close("psnr", m.psnr_db, 8.593_068, 0.05);
    }
}
