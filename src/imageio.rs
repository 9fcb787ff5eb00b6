//! Reading and writing images: linear EXR radiance and sRGB PNG.

use std::path::Path;
use std::sync::LazyLock;

use anyhow::{bail, Context as _, Result};

/// An RGB float image, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    /// Three floats per pixel, rows top to bottom.
    pub data: Vec<f32>,
}

const SUPPORTED: &str = "supported: .exr (linear), .png or .jpg (sRGB)";

/// Whether a path's extension names linear radiance (EXR) or sRGB-encoded values.
fn is_hdr_path(path: &Path) -> Result<bool> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .unwrap_or_default();
    match ext.as_str() {
        "exr" => Ok(true),
        "png" | "jpg" | "jpeg" => Ok(false),
        _ => bail!(
            "{}: unknown image extension {ext:?} ({SUPPORTED})",
            path.display()
        ),
    }
}

/// Keeps the first three of every `channels` values, checking that `data` holds exactly
/// `width * height` pixels first: the encoders below would otherwise panic or write garbage.
fn rgb_of<T: Copy>(
    path: &Path,
    width: u32,
    height: u32,
    data: &[T],
    channels: usize,
) -> Result<Vec<T>> {
    let pixels = usize::try_from(u64::from(width) * u64::from(height))
        .with_context(|| format!("{}: {width}x{height} is too large", path.display()))?;
    if Some(data.len()) != pixels.checked_mul(channels) {
        bail!(
            "{}: {width}x{height} needs {pixels} pixels of {channels} channels, got {} values",
            path.display(),
            data.len()
        );
    }
    Ok(data
        .chunks_exact(channels)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect())
}

/// Writes raw linear radiance (no exposure, no tonemap) as RGB float32 OpenEXR; alpha is
/// dropped.
pub fn write_exr(path: &Path, width: u32, height: u32, rgba_linear: &[f32]) -> Result<()> {
    let rgb = rgb_of(path, width, height, rgba_linear, 4)?;
    let image = image::Rgb32FImage::from_raw(width, height, rgb)
        .with_context(|| format!("{}: image size does not match its data", path.display()))?;
    write_encoded(path, image, image::ImageFormat::OpenExr)
}

/// Writes already tonemapped sRGB RGBA bytes as an RGB PNG; alpha is dropped.
pub fn write_png(path: &Path, width: u32, height: u32, rgba8_srgb: &[u8]) -> Result<()> {
    let rgb = rgb_of(path, width, height, rgba8_srgb, 4)?;
    write_png_rgb(path, width, height, rgb)
}

/// Writes RGB bytes as a PNG.
pub(crate) fn write_png_rgb(path: &Path, width: u32, height: u32, rgb8: Vec<u8>) -> Result<()> {
    let image = image::RgbImage::from_raw(width, height, rgb8)
        .with_context(|| format!("{}: image size does not match its data", path.display()))?;
    write_encoded(path, image, image::ImageFormat::Png)
}

/// Encodes `image` in memory, then writes the file in one call whose error is seen: the
/// image crate's `save` writes through a buffer whose last write (a small PNG's only one)
/// happens when it is dropped, an error there lost (a full disk went unreported).
fn write_encoded(
    path: &Path,
    image: impl Into<image::DynamicImage>,
    format: image::ImageFormat,
) -> Result<()> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    image
        .into()
        .write_to(&mut bytes, format)
        .with_context(|| format!("encoding {}", path.display()))?;
    std::fs::write(path, bytes.into_inner()).with_context(|| format!("writing {}", path.display()))
}

/// Loads an image as RGB floats. `.exr` gives linear radiance (first three channels) and
/// `true`; `.png`/`.jpg` give the stored sRGB-encoded values scaled to [0, 1], not decoded,
/// and `false`, as `compare.py` reads them.
pub fn load_rgb(path: &Path) -> Result<(RgbImage, bool)> {
    let is_hdr = is_hdr_path(path)?;
    let reader =
        image::ImageReader::open(path).with_context(|| format!("opening {}", path.display()))?;
    let image = reader
        .with_guessed_format()
        .with_context(|| format!("reading {}", path.display()))?;
    // The contents pick the decoder (as PIL does for compare.py), but the extension is
    // what says whether the values are linear, so the two must agree on that.
    let exr_contents = image.format() == Some(image::ImageFormat::OpenExr);
    if exr_contents != is_hdr {
        bail!(
            "{}: contents are {:?}, which its extension does not name",
            path.display(),
            image.format()
        );
    }
    let rgb = image
        .decode()
        .with_context(|| format!("decoding {}", path.display()))?
        .into_rgb32f();
    Ok((
        RgbImage {
            width: rgb.width(),
            height: rgb.height(),
            data: rgb.into_raw(),
        },
        is_hdr,
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

/// The inverse of [`srgb_encode`] on [0, 1].
pub fn srgb_decode(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.040_45 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// Shrinks an RGBA image `width` x `height` by `factor` along each axis, each output
/// pixel the mean of its `factor` x `factor` block (a box filter). The sizes must be
/// multiples of `factor`.
pub fn box_downsample(rgba: &[f32], width: u32, height: u32, factor: u32) -> Vec<f32> {
    let (w, h, k) = (width as usize, height as usize, factor as usize);
    assert!(k > 0 && w % k == 0 && h % k == 0 && rgba.len() == w * h * 4);
    let (out_w, out_h) = (w / k, h / k);
    let scale = 1.0 / (k * k) as f32;
    let mut out = vec![0.0; out_w * out_h * 4];
    for y in 0..h {
        for x in 0..w {
            let to = ((y / k) * out_w + x / k) * 4;
            let from = (y * w + x) * 4;
            for c in 0..4 {
                out[to + c] += rgba[from + c] * scale;
            }
        }
    }
    out
}

/// A [0, 1] value as a byte, rounded; NaN maps to 0 through the saturating cast.
pub fn unorm8(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// A linear value as an sRGB-encoded byte, computed exactly (a table indexed by the
/// linear value would lose the dark end).
pub fn srgb8_encode(x: f32) -> u8 {
    unorm8(srgb_encode(x))
}

/// An sRGB-encoded byte as a linear value: a table, as every texel of every albedo
/// texture's first level passes here.
pub fn srgb8_decode(byte: u8) -> f32 {
    static TABLE: LazyLock<[f32; 256]> =
        LazyLock::new(|| std::array::from_fn(|i| srgb_decode(i as f32 / 255.0)));
    TABLE[usize::from(byte)]
}

/// An RGBA8 pixel with sRGB-encoded colour and linear alpha, in linear values.
pub fn srgba8_decode(p: [u8; 4]) -> [f32; 4] {
    [
        srgb8_decode(p[0]),
        srgb8_decode(p[1]),
        srgb8_decode(p[2]),
        f32::from(p[3]) / 255.0,
    ]
}

/// The inverse of [`srgba8_decode`].
pub fn srgba8_encode(v: [f32; 4]) -> [u8; 4] {
    [
        srgb8_encode(v[0]),
        srgb8_encode(v[1]),
        srgb8_encode(v[2]),
        unorm8(v[3]),
    ]
}

/// [`box_downsample`] of an 8-bit sRGB-encoded RGBA image, averaging in linear light:
/// averaging the encoded values would darken every edge.
pub fn box_downsample_srgb8(rgba8: &[u8], width: u32, height: u32, factor: u32) -> Vec<u8> {
    let linear: Vec<f32> = rgba8
        .chunks_exact(4)
        .flat_map(|p| srgba8_decode([p[0], p[1], p[2], p[3]]))
        .collect();
    box_downsample(&linear, width, height, factor)
        .chunks_exact(4)
        .flat_map(|v| srgba8_encode([v[0], v[1], v[2], v[3]]))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_path(name: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("voxcone-imageio-{}-{name}", std::process::id()))
    }

    /// A full disk is reported for a small PNG too, whose one write the image crate's
    /// buffered `save` made only when dropped, its error lost (Linux's /dev/full).
    #[cfg(target_os = "linux")]
    #[test]
    fn a_full_disk_is_reported() {
        let full = Path::new("/dev/full");
        let error = write_png(full, 2, 2, &[128; 16]).unwrap_err();
        assert!(format!("{error:#}").contains("/dev/full"), "{error:#}");
        let error = write_exr(full, 2, 2, &[0.5; 16]).unwrap_err();
        assert!(format!("{error:#}").contains("/dev/full"), "{error:#}");
    }

    #[test]
    fn srgb_encode_known_values() {
        assert_eq!(srgb_encode(0.0), 0.0);
        assert_eq!(srgb_encode(-1.0), 0.0);
        assert!((srgb_encode(0.001) - 0.012_92).abs() < 1e-7);
        assert!((srgb_encode(0.003_130_8) - 0.040_449_936).abs() < 1e-6);
        assert!((srgb_encode(0.18) - 0.461_356_1).abs() < 1e-5);
        assert!((srgb_encode(0.5) - 0.735_356_7).abs() < 1e-5);
        assert!((srgb_encode(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(srgb_encode(7.0), srgb_encode(1.0));
    }

    #[test]
    fn srgb_decode_inverts_encode() {
        for i in 0..=100 {
            let x = i as f32 / 100.0;
            assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-5, "{x}");
        }
        assert_eq!(srgb_decode(2.0), 1.0);
    }

    #[test]
    fn srgb_round_trips_every_byte() {
        for b in 0..=255u8 {
            assert_eq!(srgb8_encode(srgb8_decode(b)), b);
        }
        assert_eq!(srgb8_encode(f32::NAN), 0);
        assert_eq!(srgb8_encode(7.0), 255);
    }

    #[test]
    fn box_downsample_means_each_block() {
        // 4x2 pixels, factor 2: two output pixels, each the mean of a 2x2 block.
        let rgba: Vec<f32> = (0..8)
            .flat_map(|i| [i as f32, 1.0, 2.0 * i as f32, 1.0])
            .collect();
        let out = box_downsample(&rgba, 4, 2, 2);
        // Block one holds pixels 0, 1, 4, 5; block two 2, 3, 6, 7.
        assert_eq!(out, vec![2.5, 1.0, 5.0, 1.0, 4.5, 1.0, 9.0, 1.0]);
        assert_eq!(box_downsample(&rgba, 4, 2, 1), rgba);
    }

    #[test]
    fn srgb8_downsample_averages_in_linear_light() {
        // Black and white side by side: half the light, encoded 188, not the encoded
        // values' mean 128.
        let rgba8 = [0, 0, 0, 255, 255, 255, 255, 255];
        let out = box_downsample_srgb8(&rgba8, 2, 1, 1);
        assert_eq!(out, rgba8.to_vec());
        let rgba8 = [
            0, 0, 0, 255, 255, 255, 255, 255, 0, 0, 0, 255, 255, 255, 255, 255,
        ];
        let out = box_downsample_srgb8(&rgba8, 2, 2, 2);
        assert_eq!(out, vec![188, 188, 188, 255]);
    }

    #[test]
    fn exr_round_trip_is_bit_exact() {
        let path = temp_path("round-trip.exr");
        let (width, height) = (5, 3);
        // Denormal, half-float overflow and huge values must all survive as float32.
        let mut rgba: Vec<f32> = (0..width * height * 4)
            .map(|i| (i as f32 * 0.37 + 1e-3).powf(1.7) - 2.0)
            .collect();
        rgba[..3].copy_from_slice(&[f32::MIN_POSITIVE / 4.0, 6.5e4, 1.0e30]);
        write_exr(&path, width, height, &rgba).unwrap();
        let loaded = load_rgb(&path);
        std::fs::remove_file(&path).ok();
        let (image, is_hdr) = loaded.unwrap();
        assert!(is_hdr);
        assert_eq!((image.width, image.height), (width, height));
        let expected: Vec<u32> = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .map(f32::to_bits)
            .collect();
        let got: Vec<u32> = image.data.iter().map(|v| v.to_bits()).collect();
        assert_eq!(got, expected);
    }

    #[test]
    fn png_loads_as_stored_srgb_values() {
        let path = temp_path("bytes.png");
        let rgba = [0, 128, 255, 7, 10, 20, 30, 0];
        write_png(&path, 2, 1, &rgba).unwrap();
        let loaded = load_rgb(&path);
        std::fs::remove_file(&path).ok();
        let (image, is_hdr) = loaded.unwrap();
        assert!(!is_hdr);
        let bytes: Vec<u8> = image
            .data
            .iter()
            .map(|v| (v * 255.0).round() as u8)
            .collect();
        assert_eq!(bytes, [0, 128, 255, 10, 20, 30]);
    }

    #[test]
    fn bad_input_is_an_error() {
        let err = load_rgb(Path::new("picture.bmpx")).unwrap_err();
        let text = format!("{err:#}");
        assert!(text.contains("picture.bmpx") && text.contains(".exr") && text.contains(".png"));

        let missing = temp_path("missing.exr");
        assert!(format!("{:#}", load_rgb(&missing).unwrap_err()).contains("missing.exr"));

        let not_png = temp_path("not-really.png");
        std::fs::write(&not_png, b"plain text").unwrap();
        let err = load_rgb(&not_png);
        std::fs::remove_file(&not_png).ok();
        assert!(format!("{:#}", err.unwrap_err()).contains("not-really.png"));

        let short = temp_path("short.exr");
        let err = write_exr(&short, 4, 4, &[0.0; 12]).unwrap_err();
        assert!(format!("{err:#}").contains("short.exr"));
        assert!(!short.exists());
        assert!(write_png(&temp_path("huge.png"), u32::MAX, u32::MAX, &[]).is_err());
    }
}
