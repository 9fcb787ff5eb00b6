//! Scene units: one scene built at scales from 1e-5 to 1e5, its camera and lights scaled
//! alike, renders the same image (issue 22, item 3). Near planes, shadow-map planes, the
//! voxel grid and every epsilon follow the scene, not an absolute constant.

mod common;

use std::path::{Path, PathBuf};

use common::{render, temp_dir};
use voxcone::compare::{compare, CompareOptions};
use voxcone::imageio::{load_rgb, RgbImage};

/// A floor, two walls (one red) and a box on the floor, at unit scale.
const ROOM_OBJ: &str = "mtllib room.mtl\nusemtl white\n\
    v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv -1 2 -1\nv 1 2 -1\nv -1 2 1\n\
    f 1 4 3 2\nf 1 2 6 5\nusemtl red\nf 1 5 7 4\nusemtl white\n\
    v -0.3 0 -0.3\nv 0.3 0 -0.3\nv 0.3 0 0.3\nv -0.3 0 0.3\n\
    v -0.3 0.6 -0.3\nv 0.3 0.6 -0.3\nv 0.3 0.6 0.3\nv -0.3 0.6 0.3\n\
    f 12 13 14 15\nf 8 9 13 12\nf 11 15 14 10\nf 8 12 15 11\nf 9 10 14 13\n";

const ROOM_MTL: &str = "newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.7 0.1 0.1\n";

const SKY: [f32; 3] = [0.1, 0.1, 0.12];

fn vec3(v: [f32; 3], s: f32) -> String {
    format!("[{:e}, {:e}, {:e}]", v[0] * s, v[1] * s, v[2] * s)
}

/// The room at `scale` with its camera at `camera` (unit-scale coordinates times
/// `camera_scale`), a point light (intensity times scale^2, so that its irradiance stays
/// the same), a sun and the sky.
fn room(dir: &Path, scale: f32, camera: [[f32; 3]; 2], camera_scale: f32) -> PathBuf {
    std::fs::write(dir.join("room.obj"), ROOM_OBJ).unwrap();
    std::fs::write(dir.join("room.mtl"), ROOM_MTL).unwrap();
    let intensity = 2.0 * scale * scale;
    let scene = format!(
        "[camera]\nposition = {}\ntarget = {}\nfov_y_deg = 45\n\n\
         [[mesh]]\npath = \"room.obj\"\nscale = {scale:e}\n\n\
         [[light]]\nkind = \"point\"\nposition = {}\nintensity = [{intensity:e}, {intensity:e}, {intensity:e}]\n\n\
         [[light]]\nkind = \"directional\"\ndirection = [0.3, -1.0, -0.5]\nirradiance = [0.5, 0.5, 0.5]\n\n\
         [sky]\nradiance = {}\n",
        vec3(camera[0], camera_scale),
        vec3(camera[1], camera_scale),
        vec3([0.5, 1.5, 0.8], scale),
        vec3(SKY, 1.0),
    );
    let path = dir.join(format!("room_{scale:e}_{camera_scale:e}.toml"));
    std::fs::write(&path, scene).unwrap();
    path
}

fn render_image(scene: &Path, options: &[&str], out: &Path) -> RgbImage {
    render(scene, &[&["--size", "64x64"], options].concat(), out);
    let image = load_rgb(out).unwrap().0;
    let bad = image
        .data
        .iter()
        .filter(|v| !v.is_finite() || **v < 0.0)
        .count();
    assert_eq!(bad, 0, "{}: non-finite or negative values", out.display());
    image
}

fn mean(image: &RgbImage) -> f32 {
    image.data.iter().map(|&v| f64::from(v)).sum::<f64>() as f32 / image.data.len() as f32
}

/// Measured before the fix: at 1e-4 the image was 9 % off in RMSE (near planes and the
/// voxel grid floored in absolute units), at 1e4 1 %; after it, within 3e-5 of the mean
/// from 1e-6 to 1e7, for every technique (BENCHMARKS.md).
#[test]
fn the_same_scene_at_every_scale_renders_the_same_image() {
    let dir = temp_dir("scale");
    let camera = [[0.2, 1.0, 3.0], [0.0, 0.5, 0.0]];
    for (gi, extra) in [("off", &[][..]), ("dense", &["--voxels", "32"][..])] {
        let options = [&["--gi", gi][..], extra].concat();
        let at = |scale: f32| {
            let scene = room(&dir, scale, camera, scale);
            let out = dir.join(format!("{gi}_{scale:e}.exr"));
            let image = render_image(&scene, &options, &out);
            (out, image)
        };
        let (unit, image) = at(1.0);
        let brightness = mean(&image);
        for scale in [1e-5, 1e-3, 1e3, 1e5] {
            let (out, _) = at(scale);
            let metrics = compare(&unit, &out, &CompareOptions::default()).unwrap();
            let relative = metrics.rmse_linear.unwrap() / brightness;
            eprintln!("--gi {gi}, scale {scale:e}: RMSE / mean {relative:.2e}");
            assert!(relative <= 1e-3, "--gi {gi} at scale {scale:e}: {relative}");
        }
    }
}

/// A camera 1.5 units above the floor of a room 20,000 units wide: the floor fills the
/// bottom of the image (a near plane of a thousandth of the scene clipped it away).
#[test]
fn a_camera_close_to_a_large_scene_keeps_its_foreground() {
    let dir = temp_dir("scale_near");
    let scale = 1e4;
    let camera = [[0.0, 1.5e-4, 0.9], [0.0, 1.0e-4, 0.0]];
    let image = render_image(
        &room(&dir, scale, camera, scale),
        &["--gi", "off"],
        &dir.join("near.exr"),
    );
    let w = image.width as usize;
    let bottom = &image.data[(image.height as usize - 1) * w * 3..];
    let sky = bottom
        .chunks_exact(3)
        .filter(|p| p.iter().zip(SKY).all(|(a, b)| (a - b).abs() < 1e-4))
        .count();
    assert_eq!(sky, 0, "{sky} of {w} pixels of the bottom row see the sky");
}
