//! glTF scenes rendered end to end, and emission textures (glTF's emissive texture, MTL
//! map_Ke) in the rasterized frame and in the path tracer. Every render runs with
//! validation and fails on any message.

mod common;

use std::path::Path;

use common::{render, render_path, shared, temp_dir, TEST_VOXELS};
use voxcone::compare::{compare, CompareOptions};
use voxcone::imageio::load_rgb;

/// The shared glTF Cornell box renders as the OBJ reference scene does: the same
/// geometry, camera and 3 W/sr light (2049 cd / 683). `--diffuse-only` stands for the
/// reference's Lambertian convention (the glTF's dielectric F0 of 0.04 otherwise adds a
/// specular lobe), which a `.scene.json` implies.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn cornell_point_gltf_renders_as_the_obj() {
    let shared = shared();
    let reference = shared.join("reference/cornell_point.exr");
    let dir = temp_dir("gltf_cornell");
    let (from_gltf, from_obj) = (dir.join("gltf.exr"), dir.join("obj.exr"));
    let size = ["--size", "256x256", "--voxels", TEST_VOXELS];
    render(
        &shared.join("scenes/gltf/cornell_point.gltf"),
        &[&size[..], &["--diffuse-only"]].concat(),
        &from_gltf,
    );
    render(
        &shared.join("reference/cornell_point.scene.json"),
        &size,
        &from_obj,
    );
    let options = CompareOptions::default();
    let flip_gltf = compare(&reference, &from_gltf, &options).unwrap().flip_ldr;
    let flip_obj = compare(&reference, &from_obj, &options).unwrap().flip_ldr;
    let rmse = compare(&from_obj, &from_gltf, &options)
        .unwrap()
        .rmse_linear
        .unwrap();
    eprintln!(
        "cornell_point LDR-FLIP: from glTF {flip_gltf:.4}, from OBJ {flip_obj:.4}; \
         glTF vs OBJ RMSE {rmse:.2e}"
    );
    assert!(rmse <= 1e-4, "glTF and OBJ renders differ: RMSE {rmse}");
    assert!((flip_gltf - flip_obj).abs() <= 1e-3);
}

/// A unit emitter quad facing +Z with `Ke` and `statements` (a map_Ke), in front of a
/// camera whose view it fills, as a TOML scene in `dir`.
fn emitter_facing_camera(dir: &Path, name: &str, statements: &str) -> std::path::PathBuf {
    std::fs::write(
        dir.join(format!("{name}.mtl")),
        format!("newmtl lamp\nKd 0 0 0\n{statements}"),
    )
    .unwrap();
    std::fs::write(
        dir.join(format!("{name}.obj")),
        format!(
            "mtllib {name}.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
             vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl lamp\nf 1/1 2/2 3/3 4/4\n"
        ),
    )
    .unwrap();
    let scene = dir.join(format!("{name}.toml"));
    std::fs::write(
        &scene,
        format!(
            "[camera]\nposition = [0, 0, 2]\ntarget = [0, 0, 0]\nfov_y_deg = 20\n\
             [[mesh]]\npath = \"{name}.obj\"\n"
        ),
    )
    .unwrap();
    scene
}

/// Seen by the camera, an emitter with a texture shows Ke x the texture's linear colour,
/// in the rasterized frame and in the path tracer alike.
#[test]
fn emission_textures_scale_the_emitted_radiance() {
    let dir = temp_dir("emission_texture_seen");
    // sRGB (255, 128, 0) is linear (1, 0.2158605, 0).
    image::RgbaImage::from_pixel(4, 4, image::Rgba([255, 128, 0, 255]))
        .save(dir.join("glow.png"))
        .unwrap();
    let scene = emitter_facing_camera(&dir, "seen", "Ke 2 3 4\nmap_Ke glow.png\n");
    let expected = [2.0, 3.0 * 0.2158605, 0.0];
    for gi in ["off", "path"] {
        let out = dir.join(format!("{gi}.exr"));
        let extra: &[&str] = if gi == "path" { &["--spp", "4"] } else { &[] };
        render(
            &scene,
            &[&["--gi", gi, "--size", "16x16"][..], extra].concat(),
            &out,
        );
        let image = load_rgb(&out).unwrap().0;
        for (i, pixel) in image.data.chunks(3).enumerate() {
            for c in 0..3 {
                assert!(
                    (pixel[c] - expected[c]).abs() <= 2e-3 * expected[0],
                    "--gi {gi}, pixel {i}: {pixel:?}, expected {expected:?}"
                );
            }
        }
    }
}

/// A textured emitter lights a floor through the path tracer's next-event estimation and
/// its BSDF-sampled hits as an untextured one of the texture's mean does: the map's two
/// texels (white, black) average to one half over the quad, and the view is symmetric
/// about the line where the texture's halves meet.
#[test]
fn path_traced_light_of_a_textured_emitter() {
    let dir = temp_dir("emission_texture_light");
    image::RgbaImage::from_fn(2, 1, |x, _| {
        let v = if x == 0 { 255 } else { 0 };
        image::Rgba([v, v, v, 255])
    })
    .save(dir.join("half.png"))
    .unwrap();
    let floor_and_lamp = |name: &str, lamp: &str| {
        std::fs::write(
            dir.join(format!("{name}.mtl")),
            format!("newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\n{lamp}"),
        )
        .unwrap();
        // The floor at y = 0 facing up; the lamp at y = 1 facing down, its texture's
        // halves split along x = 0.
        std::fs::write(
            dir.join(format!("{name}.obj")),
            format!(
                "mtllib {name}.mtl\n\
                 v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\n\
                 v -0.5 1 -0.5\nv -0.5 1 0.5\nv 0.5 1 0.5\nv 0.5 1 -0.5\n\
                 vt 0 0\nvt 0 1\nvt 1 1\nvt 1 0\n\
                 usemtl floor\nf 4 3 2 1\nusemtl lamp\nf 5/1 8/4 7/3 6/2\n"
            ),
        )
        .unwrap();
        let scene = dir.join(format!("{name}.toml"));
        std::fs::write(
            &scene,
            format!(
                "[camera]\nposition = [0, 0.5, 0]\ntarget = [0, 0, 0]\nup = [0, 0, -1]\n\
                 fov_y_deg = 90\n[[mesh]]\npath = \"{name}.obj\"\n"
            ),
        )
        .unwrap();
        scene
    };
    let mean = |scene: &Path, name: &str| {
        let out = dir.join(format!("{name}.exr"));
        let image = render_path(scene, &["--size", "32x32", "--spp", "256"], &out);
        image.data.iter().map(|&v| f64::from(v)).sum::<f64>() / image.data.len() as f64
    };
    let textured = mean(
        &floor_and_lamp("textured", "Ke 4 4 4\nmap_Ke half.png\n"),
        "textured",
    );
    let plain = mean(&floor_and_lamp("plain", "Ke 2 2 2\n"), "plain");
    eprintln!("floor under a textured emitter {textured:.5}, under its mean {plain:.5}");
    assert!(plain > 0.05, "the floor is lit: {plain}");
    assert!(
        (textured / plain - 1.0).abs() < 0.02,
        "textured {textured} vs plain {plain}"
    );
}
