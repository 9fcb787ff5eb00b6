//! The path tracer's materials beyond the references' (`--gi path` on scenes that ask for
//! them): the lighting pass's Blinn-Phong lobe against a quadrature of its integral, normal
//! maps and the lobe against the rasterized direct light, and refraction against Snell's
//! law. Every render runs with validation and fails on any message.

mod common;

use std::f64::consts::PI;
use std::path::Path;

use common::{furnace, render_path, temp_dir};
use voxcone::imageio::RgbImage;

/// The directional albedo of the lighting pass's specular lobe, Ks (e + 8) / (8 pi)
/// (n.h)^e, for light leaving at `view` radians from the normal: its integral times cos
/// over the hemisphere, by the midpoint rule.
fn lobe_albedo(ks: f64, e: f64, view: f64) -> f64 {
    let v = [view.sin(), 0.0, view.cos()];
    let (steps_theta, steps_phi) = (2000, 2000);
    let (d_theta, d_phi) = (PI / 2.0 / steps_theta as f64, 2.0 * PI / steps_phi as f64);
    let mut sum = 0.0;
    for i in 0..steps_theta {
        let theta = (i as f64 + 0.5) * d_theta;
        for j in 0..steps_phi {
            let phi = (j as f64 + 0.5) * d_phi;
            let l = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            let h = [l[0] + v[0], l[1] + v[1], l[2] + v[2]];
            let cos_h = h[2] / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            sum += cos_h.max(0.0).powf(e) * l[2] * theta.sin() * d_theta * d_phi;
        }
    }
    ks * (e + 8.0) / (8.0 * PI) * sum
}

fn mean(image: &RgbImage) -> f64 {
    image.data.iter().map(|&v| f64::from(v)).sum::<f64>() / image.data.len() as f64
}

/// A glossy furnace with direct light only (`--max-depth 2`): walls of Kd and of Ks with
/// exponent e = Ns that emit L everywhere show L (1 + Kd + the lobe's directional albedo)
/// towards the camera, at normal incidence and at 45 degrees, for a wide lobe and a narrow
/// one: the lobe's evaluation, its sampling and density, and their MIS weights against the
/// emitters' next-event estimation.
#[test]
fn glossy_furnace_gives_the_lobe_integral() {
    let dir = temp_dir("path_glossy_furnace");
    let (kd, ks, emitted) = (0.3f64, 0.5f64, 0.5f64);
    // Cameras with a one-degree view: at the centre facing the -Z wall, and near the +Z
    // wall looking at the -X wall at 45 degrees.
    let views = [
        (0.0f64, "[0.5, 0.5, 0.5]", "[0.5, 0.5, 0.0]"),
        (PI / 4.0, "[0.5, 0.5, 0.9]", "[0.0, 0.5, 0.4]"),
    ];
    for ns in [20.0f64, 200.0] {
        let walls = format!(
            "Kd {kd} {kd} {kd}\nKs {ks} {ks} {ks}\nNs {ns}\nKe {emitted} {emitted} {emitted}\n"
        );
        for (view, position, target) in views {
            let camera =
                format!("[camera]\nposition = {position}\ntarget = {target}\nfov_y_deg = 1\n");
            let scene = furnace(&dir, &walls, &camera);
            let out = dir.join(format!("glossy_{ns}_{view:.2}.exr"));
            let image = render_path(
                &scene,
                &["--size", "2x2", "--spp", "16384", "--max-depth", "2"],
                &out,
            );
            let lobe = lobe_albedo(ks, ns, view);
            let expected = emitted * (1.0 + kd + lobe);
            let got = mean(&image);
            eprintln!("Ns {ns}, view {view:.3}: lobe albedo {lobe:.4}, expected {expected:.4}, got {got:.4}");
            assert!(
                (got / expected - 1.0).abs() < 0.01,
                "Ns {ns}, view {view:.3}: {got}, expected {expected}"
            );
        }
    }
}

/// Writes a 16x16 tangent-space normal map whose normals lean along u and v in waves.
fn write_normal_map(path: &Path) {
    let image = image::RgbImage::from_fn(16, 16, |x, y| {
        let (u, v) = ((x as f32 + 0.5) / 16.0, (y as f32 + 0.5) / 16.0);
        let m = glam::Vec3::new(
            0.5 * (2.0 * std::f32::consts::PI * u).sin(),
            0.4 * (2.0 * std::f32::consts::PI * v).cos(),
            1.0,
        )
        .normalize();
        let c = (m * 0.5 + 0.5) * 255.0;
        image::Rgb([c.x.round() as u8, c.y.round() as u8, c.z.round() as u8])
    });
    image.save(path).unwrap();
}

/// Direct light on a normal-mapped glossy floor, path-traced (`--max-depth 2`) and
/// rasterized (`--gi off`, the lighting pass's shading of the same BRDF and normal map):
/// within 3 % over the floor's middle, where the normal map moves the light by far more.
#[test]
fn normal_maps_and_lobe_match_the_rasterized_direct_light() {
    let dir = temp_dir("path_normal_map");
    write_normal_map(&dir.join("n.png"));
    std::fs::write(
        dir.join("floor.mtl"),
        "newmtl floor\nKd 0.7 0.7 0.7\nKs 0.3 0.3 0.3\nNs 30\nnorm n.png\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("floor.obj"),
        "mtllib floor.mtl\nusemtl floor\nv -2 0 2\nv 2 0 2\nv 2 0 -2\nv -2 0 -2\n\
         vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\nf 1/1/1 2/2/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    let scene = dir.join("floor.toml");
    std::fs::write(
        &scene,
        "[camera]\nposition = [0.0, 2.5, 2.5]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = 40\n\
         [[mesh]]\npath = \"floor.obj\"\n\
         [[light]]\nkind = \"point\"\nposition = [0.4, 1.2, 0.3]\nintensity = [1.0, 1.0, 1.0]\n",
    )
    .unwrap();
    let render = |gi: &str, extra: &[&str], name: &str| {
        let out = dir.join(name);
        common::render(
            &scene,
            &[&["--gi", gi, "--size", "64x64"], extra].concat(),
            &out,
        );
        voxcone::imageio::load_rgb(&out).unwrap().0
    };
    let traced = render("path", &["--max-depth", "2", "--spp", "1024"], "traced.exr");
    let rasterized = render("off", &[], "rasterized.exr");
    let flat = render(
        "path",
        &["--max-depth", "2", "--spp", "1024", "--no-normal-maps"],
        "flat.exr",
    );
    // The mean relative difference over the middle 32x32 pixels, all on the floor.
    let difference = |a: &RgbImage, b: &RgbImage| {
        let mut sum = 0.0f64;
        for y in 16..48 {
            for x in 16..48 {
                for c in 0..3 {
                    let i = (y * 64 + x) * 3 + c;
                    let (p, q) = (f64::from(a.data[i]), f64::from(b.data[i]));
                    sum += (p - q).abs() / q.max(1e-6);
                }
            }
        }
        sum / (32.0 * 32.0 * 3.0)
    };
    let against_raster = difference(&traced, &rasterized);
    let map_effect = difference(&flat, &rasterized);
    eprintln!("traced vs rasterized: {against_raster:.4}; without the normal map: {map_effect:.4}");
    assert!(
        against_raster < 0.03,
        "traced and rasterized differ by {against_raster}"
    );
    assert!(
        map_effect > 0.1,
        "the normal map changes the light by only {map_effect}"
    );
}

/// A scene of an emitting wall behind a transmissive quad (Kd 0, d and Ni as given), seen
/// from `camera` (TOML lines): files in `dir`; the wall at z = -1 emits 1 over x in
/// `strip` and nothing elsewhere.
fn glass_scene(dir: &Path, d: f32, ni: f32, strip: (f32, f32), camera: &str) -> std::path::PathBuf {
    std::fs::write(
        dir.join("glass.mtl"),
        format!("newmtl glass\nKd 0 0 0\nd {d}\nNi {ni}\nnewmtl glow\nKd 0 0 0\nKe 1 1 1\n"),
    )
    .unwrap();
    let (a, b) = strip;
    std::fs::write(
        dir.join("glass.obj"),
        format!(
            "mtllib glass.mtl\nusemtl glass\nv -3 -3 0\nv 3 -3 0\nv 3 3 0\nv -3 3 0\nf 1 2 3 4\n\
             usemtl glow\nv {a} -3 -1\nv {b} -3 -1\nv {b} 3 -1\nv {a} 3 -1\nf 5 6 7 8\n"
        ),
    )
    .unwrap();
    let scene = dir.join("glass.toml");
    std::fs::write(&scene, format!("{camera}[[mesh]]\npath = \"glass.obj\"\n")).unwrap();
    scene
}

/// Transmission: a quad of d = 0.25 and Ni = 1.5 before an emitting wall passes 1 - d of
/// its light; and at 45 degrees a quad of d = 0 bends the view by Snell's law onto a strip
/// of the wall (x = tan(asin(sin 45 / 1.5)) = 0.53 at the wall) that the unbent view (at x
/// = 1) misses, which a quad of Ni = 1 then shows.
#[test]
fn transmission_refracts_by_snells_law() {
    let dir = temp_dir("path_transmission");
    let facing = "[camera]\nposition = [0, 0, 1]\ntarget = [0, 0, 0]\nfov_y_deg = 20\n";
    let scene = glass_scene(&dir, 0.25, 1.5, (-3.0, 3.0), facing);
    let image = render_path(
        &scene,
        &["--size", "4x4", "--spp", "1024"],
        &dir.join("through.exr"),
    );
    let through = mean(&image);
    eprintln!("d = 0.25: {through:.4} of the wall's light passes");
    assert!((through - 0.75).abs() < 0.015, "{through} passes, not 0.75");

    let oblique = "[camera]\nposition = [-1, 0, 1]\ntarget = [0, 0, 0]\nfov_y_deg = 1\n";
    for (ni, expected) in [(1.5f32, 1.0f64), (1.0, 0.0)] {
        let scene = glass_scene(&dir, 0.0, ni, (0.3, 0.75), oblique);
        let out = dir.join(format!("bent_{ni}.exr"));
        let image = render_path(&scene, &["--size", "2x2", "--spp", "64"], &out);
        let seen = mean(&image);
        eprintln!("Ni {ni}: the strip seen through the quad: {seen:.4}");
        assert!(
            (seen - expected).abs() < 1e-3,
            "Ni {ni}: {seen}, expected {expected}"
        );
    }
}
