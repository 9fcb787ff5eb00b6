//! The cone tracer's error sources, each on its own, against an analytic case or the path
//! tracer's one-bounce image. Every render runs with validation and fails on any message.
//! Those marked `ignore` hold targets the tracer does not meet yet (the reason gives
//! today's figure); `cargo test --release --test cone_components -- --ignored` runs them.

mod common;

use std::path::{Path, PathBuf};

use common::{
    flat_plane, probe_furnace, render, render_256, render_path, shared, temp_dir, write,
    TEST_VOXELS,
};
use voxcone::compare::{compare, CompareOptions};
use voxcone::imageio::{load_rgb, RgbImage};

/// Mean over the channels of the centre 8x8 pixels.
fn centre(path: &Path) -> f32 {
    let (image, _) = load_rgb(path).unwrap();
    at_row(&image, image.height as usize / 2)
}

/// Mean over the channels of the 8x8 pixels centred on row `y` of the middle column.
fn at_row(image: &RgbImage, y: usize) -> f32 {
    let w = image.width as usize;
    let mut sum = 0.0;
    for y in y - 4..y + 4 {
        for x in w / 2 - 4..w / 2 + 4 {
            sum += image.data[(y * w + x) * 3..(y * w + x) * 3 + 3]
                .iter()
                .sum::<f32>();
        }
    }
    sum / 192.0
}

/// The ring of cones, `view`'s and `bench`'s default (`render`'s is the lattice).
const RING: &[&str] = &["--quality", "fast"];

fn dense(scene: &Path, voxels: u32, extra: &[&str], out: &Path) {
    let voxels = voxels.to_string();
    render_256(
        scene,
        &[&["--gi", "dense", "--voxels", &voxels], extra].concat(),
        out,
    );
}

/// A flat square emitter (radiance 1, albedo 0.5) alone under a black sky, seen from
/// above: with one bounce its pixel is 1 + 0.5 G, where G, the radiance it gathers, is
/// 0 (a plane sees none of itself). Its light is gathered through the voxels
/// (`--sampled-emitters 0`): sampled, as by default, it is not in the voxels and gathers
/// none of itself by construction, but a surface bright with light it receives gathers
/// itself as this emitter does (the furnace's quad below). The plane is the scene's bounds, so it lies on the
/// grid's middle plane, the bottom face of a cell at every level: the worst place.
/// Moved off it within its voxel (a black speck stretching the bounds), the same plane
/// gathers 0.000 below the middle plane and 0.155 to 0.173 within its lowest fifth of a
/// voxel above it (BENCHMARKS.md, session 28).
#[test]
#[ignore = "issue 20: the plane gathers 0.17 of its own radiance at 64³, 0.22 at 128³"]
fn flat_emitter_gathers_none_of_itself_with_the_ring() {
    flat_emitter_gathers_none_of_itself_with("components_plane", RING);
}

/// With `--snapped-cones`: 0.0000 at 64³ and 128³.
#[test]
fn flat_emitter_gathers_none_of_itself_with_snapped_cones() {
    flat_emitter_gathers_none_of_itself_with("components_plane_snapped", &["--snapped-cones"]);
}

/// With `render`'s default cones, the lattice (`--lattice-cones 72`): 0.0001 at 64³ and 128³.
#[test]
fn flat_emitter_gathers_none_of_itself() {
    flat_emitter_gathers_none_of_itself_with("components_plane_lattice", &[]);
}

fn flat_emitter_gathers_none_of_itself_with(name: &str, extra: &[&str]) {
    let dir = temp_dir(name);
    let scene = flat_plane(&dir, "Kd 0.5 0.5 0.5\nKe 1 1 1\n", 10.0, "");
    for voxels in [64, 128] {
        let out = dir.join(format!("plane_{voxels}.exr"));
        let args = [&["--bounces", "1", "--sampled-emitters", "0"], extra].concat();
        dense(&scene, voxels, &args, &out);
        let gathered = 2.0 * (centre(&out) - 1.0);
        eprintln!("flat emitter, {voxels}³: gathers {gathered:.4} of its radiance");
        assert!(gathered <= 0.02, "{voxels}³: gathers {gathered} of itself");
    }
}

/// A white square 20 wide, tilted `tilt_deg` about z, alone under a uniform sky of
/// radiance 1 (no lights), as a scene file in `dir`, seen along its normal from 0.8
/// above its centre (which is the grid's).
fn plane_under_sky(dir: &Path, tilt_deg: f64) -> PathBuf {
    use glam::DVec3;
    let a = tilt_deg.to_radians();
    let (n, u) = (
        DVec3::new(-a.sin(), a.cos(), 0.0),
        DVec3::new(a.cos(), a.sin(), 0.0),
    );
    let mut obj = String::from("mtllib sky.mtl\n");
    for (s, t) in [(-10.0, 10.0), (10.0, 10.0), (10.0, -10.0), (-10.0, -10.0)] {
        let v = s * u + t * DVec3::Z;
        obj += &format!("v {} {} {}\n", v.x, v.y, v.z);
    }
    obj += "usemtl white\nf 1 2 3 4\n";
    write(dir, "sky.mtl", "newmtl white\nKd 1 1 1\n");
    let name = format!("sky_{tilt_deg}.obj");
    write(dir, &name, &obj);
    let eye = 0.8 * n;
    write(
        dir,
        &format!("sky_{tilt_deg}.toml"),
        &format!(
            "[camera]\nposition = [{}, {}, 0.001]\ntarget = [0, 0, 0]\nfov_y_deg = 10\n\
             [sky]\nradiance = [1, 1, 1]\n[[mesh]]\npath = {name:?}\n",
            eye.x, eye.y
        ),
    )
}

/// An open plane under a uniform sky gathers the sky, 1, within 2 %, whatever its tilt:
/// nothing lies above it, so none of its cones may be stopped by the plane's own voxels.
/// Level (on the grid's middle plane, as the flat emitter above) and tilted 17 and 30
/// degrees (its staircase of voxels), at 64³ and 128³.
#[test]
#[ignore = "issue 20: 0.826 (level), 0.943 (17°) and 0.950 (30°) at 64³; 0.784, 0.931 and 0.938 at 128³"]
fn plane_under_the_sky_gathers_all_of_it_with_the_ring() {
    plane_under_the_sky_gathers_all_of_it_with("components_plane_under_sky", RING);
}

/// With `--snapped-cones`: 0.9995 (level), 0.9971 (17°) and 0.9947 (30°) at 64³ and 128³.
#[test]
fn plane_under_the_sky_gathers_all_of_it_with_snapped_cones() {
    plane_under_the_sky_gathers_all_of_it_with(
        "components_plane_under_sky_snapped",
        &["--snapped-cones"],
    );
}

/// With `render`'s default cones, the lattice (`--lattice-cones 72`): 0.9995 (level), 0.9976 (17°) and 0.9956 (30°) at 64³ and 128³.
#[test]
fn plane_under_the_sky_gathers_all_of_it() {
    plane_under_the_sky_gathers_all_of_it_with("components_plane_under_sky_lattice", &[]);
}

fn plane_under_the_sky_gathers_all_of_it_with(name: &str, extra: &[&str]) {
    let dir = temp_dir(name);
    let mut off = Vec::new();
    for tilt in [0.0, 17.0, 30.0] {
        let scene = plane_under_sky(&dir, tilt);
        for voxels in [64, 128] {
            let out = dir.join(format!("sky_{tilt}_{voxels}.exr"));
            dense(&scene, voxels, &[&["--bounces", "1"], extra].concat(), &out);
            let gathered = centre(&out);
            eprintln!("plane tilted {tilt}°, {voxels}³: gathers {gathered:.4} of the sky");
            if (gathered - 1.0).abs() > 0.02 {
                off.push((tilt, voxels, gathered));
            }
        }
    }
    assert!(off.is_empty(), "off by more than 2 %: {off:?}");
}

/// Inside a closed box whose walls emit L (albedo 0), a white quad gathers L at 64³,
/// 128³ and 256³, within 2 %. The walls' light is sampled, exact but for its visibility;
/// the excess is the quad gathering its own light (as the flat emitter above gathers
/// itself). Gathered through the voxels (`--sampled-emitters 0`) it was 0.953, 0.953
/// and 0.944.
#[test]
#[ignore = "issue 20: 1.153 of the walls' radiance at 64³"]
fn furnace_within_two_percent_at_every_resolution_with_the_ring() {
    furnace_within_two_percent_at_every_resolution_with(
        "components_furnace",
        RING,
        &[64, 128, 256],
    );
}

/// With `--snapped-cones`: 1.0000 and 1.0000 at 64³ and 128³ (0.9995 at 256³, measured
/// in session 42; left out of the test, whose 256³ render took two and a half minutes of
/// CI's thirty).
#[test]
fn furnace_within_two_percent_at_every_resolution_with_snapped_cones() {
    furnace_within_two_percent_at_every_resolution_with(
        "components_furnace_snapped",
        &["--snapped-cones"],
        &[64, 128],
    );
}

/// With `render`'s default cones, the lattice (`--lattice-cones 72`): 1.0000 at 64³ and 128³.
#[test]
fn furnace_within_two_percent_at_every_resolution() {
    furnace_within_two_percent_at_every_resolution_with(
        "components_furnace_lattice",
        &[],
        &[64, 128],
    );
}

fn furnace_within_two_percent_at_every_resolution_with(name: &str, extra: &[&str], voxels: &[u32]) {
    let dir = temp_dir(name);
    let scene = probe_furnace(&dir);
    for &voxels in voxels {
        let out = dir.join(format!("furnace_{voxels}.exr"));
        dense(&scene, voxels, extra, &out);
        let ratio = centre(&out) / 0.5;
        eprintln!("furnace, {voxels}³: {ratio:.4} of the walls' radiance");
        assert!((ratio - 1.0).abs() <= 0.02, "{voxels}³: {ratio}");
    }
}

/// The built-in Cornell box with every surface white (albedo 1) and emitting 1 under a sky
/// of 1, as a scene file in `dir`: whatever stops a cone, and wherever it leaves the box,
/// it meets radiance 1 (a face seen from behind is transparent to the cones), so with one
/// bounce every pixel that sees a surface gathers 1.
fn uniform_cornell(dir: &Path) -> PathBuf {
    let obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/cornell.obj");
    let materials: String = ["white", "red", "green", "block", "light"]
        .iter()
        .map(|m| format!("newmtl {m}\nKd 1 1 1\nKe 1 1 1\n"))
        .collect();
    write(dir, "cornell.mtl", &materials);
    write(dir, "cornell.obj", &std::fs::read_to_string(obj).unwrap());
    write(
        dir,
        "uniform.toml",
        "[camera]\nposition = [0.0, 1.0, 3.9]\ntarget = [0.0, 1.0, 0.0]\nfov_y_deg = 39.3\n\
         [sky]\nradiance = [1, 1, 1]\n[[mesh]]\npath = \"cornell.obj\"\n",
    )
}

/// In a world of uniform radiance the cones gather it whatever they cross: how much each
/// cell occludes may be wrong, but what it shows is the same radiance. The pixels that see
/// a surface (gathering over half: the others see the sky, and gather nothing beyond
/// it) gather 1 within 0.5 % on average, and fewer than 1 % of them under 0.99, at 64³ and
/// 128³ with `render`'s cones and at 64³ with the snapped ring. A plane the cone crossed
/// where it first met it stopped the rest of the cone's disc with radiance not yet read
/// (black): 0.989 to 0.992 on average, 30 to 36 % of the pixels under 0.99 (BENCHMARKS.md,
/// session 49).
#[test]
fn uniform_world_gathers_its_radiance_whatever_the_cones_cross() {
    let dir = temp_dir("components_uniform_world");
    let scene = uniform_cornell(&dir);
    let size = ["--size", "128x128"];
    let off = dir.join("off.exr");
    render(&scene, &[&size[..], &["--gi", "off"]].concat(), &off);
    let (off, _) = load_rgb(&off).unwrap();
    for (voxels, extra) in [
        ("64", &[][..]),
        ("128", &[][..]),
        ("64", &["--snapped-cones"][..]),
    ] {
        let out = dir.join(format!("uniform_{voxels}_{}.exr", extra.len()));
        let options = [
            "--gi",
            "dense",
            "--voxels",
            voxels,
            "--bounces",
            "1",
            "--sampled-emitters",
            "0",
        ];
        render(&scene, &[&size[..], &options, extra].concat(), &out);
        let (image, _) = load_rgb(&out).unwrap();
        let gathered: Vec<f32> = image
            .data
            .iter()
            .zip(&off.data)
            .map(|(v, o)| v - o)
            .filter(|&g| g > 0.5)
            .collect();
        let mean = gathered.iter().map(|&g| f64::from(g)).sum::<f64>() / gathered.len() as f64;
        let under = gathered.iter().filter(|&&g| g < 0.99).count() as f64 / gathered.len() as f64;
        eprintln!("{voxels}³ {extra:?}: gathered {mean:.4} on average, {under:.4} of the pixels under 0.99");
        assert!((mean - 1.0).abs() <= 0.005, "{voxels}³ {extra:?}: {mean}");
        assert!(under < 0.01, "{voxels}³ {extra:?}: {under}");
    }
}

/// The furnace of `probe_furnace` in `dir`, with two black specks beyond its corners
/// (`speck.obj`) that stretch the scene's bounds and so put its walls inside the grid.
fn furnace_with_specks(dir: &Path) {
    probe_furnace(dir);
    specks(dir);
}

/// Two black specks beyond the corners of the cube [-1, 1]³, `speck.obj` in `dir`: a
/// mesh that puts the cube's faces inside the grid.
fn specks(dir: &Path) {
    write(dir, "speck.mtl", "newmtl black\nKd 0 0 0\n");
    write(
        dir,
        "speck.obj",
        "mtllib speck.mtl\nusemtl black\n\
         v -1.3 -1.3 -1.3\nv -1.299 -1.3 -1.3\nv -1.3 -1.299 -1.3\n\
         v 1.3 1.3 1.3\nv 1.299 1.3 1.3\nv 1.3 1.299 1.3\nf 1 2 3\nf 4 5 6\n",
    );
}

/// The furnace of `furnace_within_two_percent_at_every_resolution` with two black specks
/// beyond its corners, which stretch the scene's bounds: its walls lie inside the grid,
/// not on its faces, as a room's ceiling does in the cube around a wide scene
/// (`conference_main`'s). At the grid's faces the cones count nothing beyond them
/// (`cross_section_inside`); inside, their lookups reach past the walls into the empty
/// space behind. The walls' light is gathered (`--sampled-emitters 0`) with one bounce, so
/// the white quad shows the mean radiance its cones gather: the walls' 0.5 where they
/// let nothing through. Returns that share at each of `voxels`.
fn furnace_inside_the_grid(name: &str, extra: &[&str], voxels: &[u32]) -> Vec<f32> {
    let dir = temp_dir(name);
    furnace_with_specks(&dir);
    let scene = write(
        &dir,
        "inside.toml",
        "[camera]\nposition = [0, 0, 0.9]\ntarget = [0, 0, 0]\nfov_y_deg = 10\n\
         [[mesh]]\npath = \"box.obj\"\n[[mesh]]\npath = \"speck.obj\"\n",
    );
    voxels
        .iter()
        .map(|&v| {
            let out = dir.join(format!("inside_{v}.exr"));
            let args = [&["--sampled-emitters", "0", "--bounces", "1"], extra].concat();
            dense(&scene, v, &args, &out);
            let share = centre(&out) / 0.5;
            eprintln!("furnace inside the grid {extra:?}, {v}³: {share:.4} of the walls' radiance");
            share
        })
        .collect()
}

#[test]
#[ignore = "issue 20: 0.677, 0.647 and 0.623 of the walls' radiance at 64³, 128³ and 256³"]
fn furnace_inside_the_grid_within_two_percent_with_the_ring() {
    for share in furnace_inside_the_grid("components_furnace_inside", RING, &[64, 128, 256]) {
        assert!((share - 1.0).abs() <= 0.02, "{share}");
    }
}

/// `--snapped-cones` keeps that room closed: 0.999 and 0.998 of the walls' radiance at
/// 64³ and 128³ (0.993 at 256³ in session 42, left out of the test for CI's time; the
/// lattice's test below runs it), where the ring's trilinear lookups let a third of it
/// out, more as the voxels get finer (0.960, 0.946 and 0.968 while the snapped cells
/// blended two levels, before session 32).
#[test]
fn furnace_inside_the_grid_within_two_percent_with_snapped_cones() {
    let shares = furnace_inside_the_grid(
        "components_furnace_inside_snapped",
        &["--snapped-cones"],
        &[64, 128],
    );
    for share in shares {
        assert!((share - 1.0).abs() <= 0.02, "{share}");
    }
}

/// With `render`'s default cones, the lattice (`--lattice-cones 72`) and the planes:
/// 0.9980, 0.9976 and 0.9953 at 64³, 128³ and 256³ (without the planes 0.9961, 0.9976
/// and 0.9907; 48 cones, each 21 degrees wide near the normal, 0.898 at 64³ in the same
/// box seen whole). The planes cap only the cells of a plane the cone runs beside:
/// capping every plane by its disc's segment, those of walls met obliquely too, let
/// 0.012 / 0.035 / 0.047 of the light out (the cells before the crossing no longer closed
/// the cone, and past it they are empty).
#[test]
fn furnace_inside_the_grid_within_two_percent() {
    let shares = furnace_inside_the_grid("components_furnace_inside_lattice", &[], &[64, 128, 256]);
    for share in shares {
        assert!((share - 1.0).abs() <= 0.02, "{share}");
    }
}

/// The furnace's walls seen from inside, their corner in view, with the black specks
/// that put them inside the grid: each wall point gathers the other walls' radiance (0.5;
/// albedo 1 and one bounce, `--debug-view indirect`, the light gathered through the
/// voxels), within 2 % in the median pixel. Near the room's edges a cone running beside
/// one wall meets the far wall in coarse cells that reach past the room, partly covered,
/// and lets the rest out beyond the walls: inside a second emissive box around the room
/// (1.2 times as large) the cone along the normal (`--quality fast --snapped-cones
/// --cone 0`) gathers 0.992 of the radiance where alone it gathers 0.938 (BENCHMARKS.md,
/// session 42). Counting a wall the cone runs beside once (the planes) leaves more of the
/// cone to reach the far wall there, so more gets out.
#[test]
#[ignore = "issue 20: 0.957 of the walls' radiance in the median pixel at 64³ (0.969 without the planes; the path tracer's 0.987, the probe quad hiding the rest)"]
fn walls_of_a_closed_room_inside_the_grid_gather_its_radiance() {
    let dir = temp_dir("components_room_walls");
    furnace_with_specks(&dir);
    write(
        &dir,
        "box.mtl",
        "newmtl wall\nKd 1 1 1\nKe 0.5 0.5 0.5\nnewmtl probe\nKd 1 1 1\n",
    );
    let scene = write(
        &dir,
        "walls.toml",
        "[camera]\nposition = [0.6, 0.6, 0.6]\ntarget = [-1, -1, -1]\nfov_y_deg = 90\n\
         [[mesh]]\npath = \"box.obj\"\n[[mesh]]\npath = \"speck.obj\"\n",
    );
    for (extra, name) in [
        (&[][..], "planes"),
        (&["--no-plane-occlusion"][..], "no_planes"),
    ] {
        let out = dir.join(format!("walls_{name}.exr"));
        let args = [
            &[
                "--sampled-emitters",
                "0",
                "--bounces",
                "1",
                "--debug-view",
                "indirect",
            ][..],
            extra,
        ]
        .concat();
        dense(&scene, 64, &args, &out);
        let (image, _) = load_rgb(&out).unwrap();
        let mut pixels: Vec<f32> = image
            .data
            .chunks_exact(3)
            .map(|p| (p[0] + p[1] + p[2]) / 3.0)
            .collect();
        pixels.sort_by(f32::total_cmp);
        let share = pixels[pixels.len() / 2] / 0.5;
        eprintln!("walls of a closed room {extra:?}, 64³: the median pixel {share:.4} of the walls' radiance");
        assert!((share - 1.0).abs() <= 0.02, "{extra:?}: {share}");
    }
}

/// Two rooms side by side in a box 4 x 2 x 2: the left one's walls emit 1, the right
/// one's are black, and a white quad in the right room faces the left one. The light
/// it gathers through a wall between them (two-sided, no thickness, inside one voxel
/// at every resolution), as a share of what it gathers with the wall taken away.
fn wall_leak(voxels: u32, extra: &[&str]) -> f32 {
    let dir = temp_dir(&format!("components_wall_{voxels}{}", extra.concat()));
    write(
        &dir,
        "rooms.mtl",
        "newmtl lit\nKd 0 0 0\nKe 1 1 1\nnewmtl dark\nKd 0 0 0\nnewmtl probe\nKd 1 1 1\n",
    );
    // The wall at x = 0.02: inside voxel 32 of 64, 64 of 128 (the grid spans 4.16).
    let x = 0.02;
    let mut gathered = [0.0; 2];
    for (i, with_wall) in [false, true].into_iter().enumerate() {
        let mut obj = String::from("mtllib rooms.mtl\n");
        let mut quads: Vec<(&str, [[f32; 3]; 4])> = Vec::new();
        for (mat, x0, x1) in [("lit", -2.0, x), ("dark", x, 2.0)] {
            quads.push((
                mat,
                [[x0, -1., -1.], [x0, -1., 1.], [x1, -1., 1.], [x1, -1., -1.]],
            ));
            quads.push((
                mat,
                [[x0, 1., -1.], [x1, 1., -1.], [x1, 1., 1.], [x0, 1., 1.]],
            ));
            quads.push((
                mat,
                [[x0, -1., -1.], [x1, -1., -1.], [x1, 1., -1.], [x0, 1., -1.]],
            ));
            quads.push((
                mat,
                [[x0, -1., 1.], [x0, 1., 1.], [x1, 1., 1.], [x1, -1., 1.]],
            ));
        }
        quads.push((
            "lit",
            [
                [-2., -1., -1.],
                [-2., 1., -1.],
                [-2., 1., 1.],
                [-2., -1., 1.],
            ],
        ));
        quads.push((
            "dark",
            [[2., -1., -1.], [2., -1., 1.], [2., 1., 1.], [2., 1., -1.]],
        ));
        if with_wall {
            quads.push((
                "dark",
                [[x, -1., -1.], [x, -1., 1.], [x, 1., 1.], [x, 1., -1.]],
            ));
            quads.push((
                "dark",
                [[x, -1., -1.], [x, 1., -1.], [x, 1., 1.], [x, -1., 1.]],
            ));
        }
        let s = 0.15;
        quads.push((
            "probe",
            [[1., -s, -s], [1., -s, s], [1., s, s], [1., s, -s]],
        ));
        for (q, (mat, corners)) in quads.iter().enumerate() {
            for c in corners {
                obj += &format!("v {} {} {}\n", c[0], c[1], c[2]);
            }
            let v = 4 * q + 1;
            obj += &format!("usemtl {mat}\nf {} {} {} {}\n", v, v + 1, v + 2, v + 3);
        }
        write(&dir, "rooms.obj", &obj);
        let scene = write(
            &dir,
            "rooms.toml",
            "[camera]\nposition = [0.4, 0, 0]\ntarget = [1, 0, 0]\nfov_y_deg = 10\n\
             [[mesh]]\npath = \"rooms.obj\"\n",
        );
        let out = dir.join(format!("rooms_{with_wall}.exr"));
        dense(&scene, voxels, extra, &out);
        gathered[i] = centre(&out);
    }
    let leak = gathered[1] / gathered[0];
    eprintln!(
        "thin wall {extra:?}, {voxels}³: {:.4} without it, {:.4} through it: passes {leak:.4}",
        gathered[0], gathered[1]
    );
    leak
}

#[test]
#[ignore = "issue 20: the wall passes 0.136 of the light at 64³ (the lit room's walls are sampled emitters: their visibility cones leak; gathered through the voxels, 0.31)"]
fn thin_wall_passes_little_light_with_the_ring() {
    let coarse = wall_leak(64, RING);
    assert!(coarse <= 0.05, "64³: passes {coarse}");
    let fine = wall_leak(128, RING);
    assert!(fine < coarse, "128³ passes {fine}, 64³ {coarse}");
}

/// With `--snapped-cones` the wall passes 0.0008, 0.0016 and 0.0011 of the light at 64³,
/// 128³ and 256³ (0.122 at 64³ while the visibility cones read the base level
/// trilinearly, before session 32). Both are at the floor that the opacity clamp sets
/// (a sample of 0.9999 that counts half a footprint passes 1 %), so at 128³ the wall
/// may pass as much as at 64³ or up to that floor.
#[test]
fn thin_wall_passes_little_light_with_snapped_cones() {
    let coarse = wall_leak(64, &["--snapped-cones"]);
    assert!(coarse <= 0.05, "64³: passes {coarse}");
    let fine = wall_leak(128, &["--snapped-cones"]);
    assert!(fine <= coarse.max(0.01), "128³ passes {fine}, 64³ {coarse}");
}

/// With `render`'s default cones, the lattice (`--lattice-cones 72`): 0.0008 at 64³, 0.0016 at 128³.
#[test]
fn thin_wall_passes_little_light() {
    let coarse = wall_leak(64, &[]);
    assert!(coarse <= 0.05, "64³: passes {coarse}");
    let fine = wall_leak(128, &[]);
    assert!(fine <= coarse.max(0.01), "128³ passes {fine}, 64³ {coarse}");
}

/// An image's channels summed over 32x32 blocks.
fn block_sums(image: &RgbImage) -> Vec<f64> {
    let w = image.width as usize;
    let mut blocks = vec![0.0; (w / 32) * (image.height as usize / 32)];
    for (i, p) in image.data.chunks(3).enumerate() {
        let (x, y) = (i % w, i / w);
        blocks[(y / 32) * (w / 32) + x / 32] += f64::from(p.iter().sum::<f32>());
    }
    blocks
}

/// The indirect light (the image less its direct light) summed over 32x32 blocks.
fn block_indirect(image: &Path, direct: &Path) -> Vec<f64> {
    let image = block_sums(&load_rgb(image).unwrap().0);
    let direct = block_sums(&load_rgb(direct).unwrap().0);
    image.iter().zip(direct).map(|(a, b)| a - b).collect()
}

/// The blocks (index, `ours` / `reference`) whose reference is above 2 % of the
/// brightest block's.
fn block_ratios(ours: &[f64], reference: &[f64]) -> Vec<(usize, f64)> {
    let brightest = reference.iter().cloned().fold(0.0, f64::max);
    ours.iter()
        .zip(reference)
        .enumerate()
        .filter(|(_, (_, r))| **r > 0.02 * brightest)
        .map(|(i, (o, r))| (i, o / r))
        .collect()
}

/// Asserts that every block of `block_ratios` is within 10 % of the reference, naming
/// those that are not under `what`.
fn assert_blocks_within_10_percent(what: &str, ours: &[f64], reference: &[f64]) {
    let outside: Vec<(usize, f64)> = block_ratios(ours, reference)
        .into_iter()
        .filter(|(_, r)| (r - 1.0).abs() > 0.1)
        .collect();
    eprintln!("{what}: blocks off by more than 10 %: {outside:?}");
    assert!(
        outside.is_empty(),
        "{} blocks off: {outside:?}",
        outside.len()
    );
}

/// The Cornell box (point light) with one bounce, ours (`--bounces 1`: the voxels hold
/// direct light only) and the path tracer's (`--max-depth 3`), each less its own direct
/// light; and ours with all bounces against the 4096-spp reference.
struct CornellBounces {
    ours_one: Vec<f64>,
    ours_all: Vec<f64>,
    path_one: Vec<f64>,
    path_all: Vec<f64>,
}

fn cornell_bounces(name: &str, spp: u32) -> CornellBounces {
    let shared = shared();
    let scene = shared.join("reference/cornell_point.scene.json");
    let dir = temp_dir(name);
    let path = |f: &str| dir.join(f);
    render_256(&scene, &["--gi", "off"], &path("off.exr"));
    let dense = ["--gi", "dense", "--voxels", TEST_VOXELS];
    render_256(
        &scene,
        &[&dense[..], &["--bounces", "1"]].concat(),
        &path("one.exr"),
    );
    render_256(&scene, &dense, &path("all.exr"));
    let spp = spp.to_string();
    render_path(
        &scene,
        &["--size", "256x256", "--spp", &spp, "--max-depth", "3"],
        &path("path_one.exr"),
    );
    let direct = shared.join("reference/cornell_point_direct.exr");
    CornellBounces {
        ours_one: block_indirect(&path("one.exr"), &path("off.exr")),
        ours_all: block_indirect(&path("all.exr"), &path("off.exr")),
        path_one: block_indirect(&path("path_one.exr"), &direct),
        path_all: block_indirect(&shared.join("reference/cornell_point.exr"), &direct),
    }
}

/// One bounce, per 32x32 block of the Cornell view, within 10 % of the path tracer's
/// (blocks where its indirect light is above 2 % of the brightest block's).
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: 57 of the 64 blocks within 10 %, from 0.87 to 1.22 (render's defaults at 128³, TEST_VOXELS, with the planes; 48 without them, session 41)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn one_bounce_per_block_matches_the_path_tracer() {
    let b = cornell_bounces("components_one_bounce", 512);
    assert_blocks_within_10_percent("one bounce", &b.ours_one, &b.path_one);
}

/// The light of `cornell_area`'s ceiling emitter on the room, per 32x32 block, within
/// 10 % of the path tracer's direct light from it: ours is the sampled emitter's light
/// alone (`--debug-view emitter-light`: its exact irradiance times a visibility cone's),
/// against the path tracer's `--max-depth 2` less its `--max-depth 1` (the emitter
/// itself, antialiased alike). Where nothing shadows it, every block is within 2 % but
/// four along the ceiling's edge, where the upsample lends the top row of the back
/// wall's light to the unlit ceiling beside it (1.13 to 1.15). The emitter cut into
/// eight pieces (`render`'s default) gives the two blocks' shadows penumbrae, but the
/// blocks' voxels cast them too wide: the blocks off by 0.080 on average against one
/// piece's 0.102 (at 128³: 0.071 and 0.087; before the voxels' coverage 0.088 and
/// 0.072 with eight).
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: 41 of the 54 blocks within 10 % (39 before the voxels' coverage): the blocks' shadows too wide, as `block_shadow_is_as_wide_as_the_path_tracers` measures, the ceiling's edge 1.13 to 1.15"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn emitter_lights_the_room_as_the_path_tracer_does() {
    let scene = shared().join("reference/cornell_area.scene.json");
    let dir = temp_dir("components_emitter_light");
    let path = |f: &str| dir.join(f);
    dense(
        &scene,
        64,
        &["--debug-view", "emitter-light"],
        &path("ours.exr"),
    );
    for depth in ["1", "2"] {
        render_path(
            &scene,
            &["--size", "256x256", "--spp", "256", "--max-depth", depth],
            &path(&format!("path_{depth}.exr")),
        );
    }
    let ours = block_sums(&load_rgb(&path("ours.exr")).unwrap().0);
    let exact = block_indirect(&path("path_2.exr"), &path("path_1.exr"));
    assert_blocks_within_10_percent("emitter light", &ours, &exact);
}

/// All bounces over the first: the voxel bounces gather as the path tracer's do, within
/// 5 % (measured at `render`'s defaults at 128³, `TEST_VOXELS`, the lattice: 1.833 against
/// 1.864, 0.983; the ring at 64³, `--quality fast`: 1.908 against 1.866, 1.023).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn bounces_over_the_first_match_the_path_tracer() {
    let b = cornell_bounces("components_bounces", 128);
    let total = |v: &[f64]| v.iter().sum::<f64>();
    let ours = total(&b.ours_all) / total(&b.ours_one);
    let path = total(&b.path_all) / total(&b.path_one);
    eprintln!("all bounces over the first: ours {ours:.4}, path tracer {path:.4}");
    assert!(
        (ours / path - 1.0).abs() <= 0.05,
        "ours {ours}, path {path}"
    );
}

/// One image traces its bounces until under 1 % of the indirect light is left
/// (`converged_bounces`): in the conference room (a closed room of albedo 0.7, whose
/// bounces the camera's walks find to fall by 0.699 each: 13 bounces)
/// at 64³ the image's indirect light is within 1 % of 64 bounces'. Eight, the frames'
/// count and one image's before, leave more than that untraced (there its bounces after
/// the first fell 5 % short of the path tracer's at 256³; in the Cornell box, open at
/// the front, eight leave 0.4 %; BENCHMARKS.md, session 44).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn one_image_traces_its_bounces_until_they_converge() {
    let scene = shared().join("reference/conference_main.scene.json");
    let dir = temp_dir("components_converged_bounces");
    let path = |f: &str| dir.join(f);
    render_256(&scene, &["--gi", "off"], &path("off.exr"));
    let indirect = |bounces: Option<&str>| {
        let name = format!("bounces_{}.exr", bounces.unwrap_or("rule"));
        let args: Vec<&str> = bounces.map_or(vec![], |b| vec!["--bounces", b]);
        dense(&scene, 64, &args, &path(&name));
        block_indirect(&path(&name), &path("off.exr"))
            .iter()
            .sum::<f64>()
    };
    let most = indirect(Some("64"));
    let rule = 1.0 - indirect(None) / most;
    let eight = 1.0 - indirect(Some("8")) / most;
    eprintln!(
        "indirect light left untraced, of 64 bounces': the rule's {rule:.4}, eight {eight:.4}"
    );
    assert!(rule.abs() < 0.01, "{rule}");
    assert!(eight > 0.01, "{eight}");
}

/// A white floor 2 wide (x from -1 to 1) and 20 long between two black walls `height`
/// high, under a sky of radiance 1, seen from above the floor's middle, as a scene file
/// in `dir`.
fn canyon(dir: &Path, height: f32) -> PathBuf {
    write(
        dir,
        "canyon.mtl",
        "newmtl floor\nKd 1 1 1\nnewmtl wall\nKd 0 0 0\n",
    );
    let name = format!("canyon_{height}.obj");
    write(
        dir,
        &name,
        &format!(
            "mtllib canyon.mtl\n\
             v -1 0 10\nv 1 0 10\nv 1 0 -10\nv -1 0 -10\n\
             v -1 {height} 10\nv -1 {height} -10\nv 1 {height} 10\nv 1 {height} -10\n\
             usemtl floor\nf 1 2 3 4\nusemtl wall\nf 1 4 6 5\nf 2 7 8 3\n"
        ),
    );
    write(
        dir,
        &format!("canyon_{height}.toml"),
        &format!(
            "[camera]\nposition = [0, 0.5, 0.001]\ntarget = [0, 0, 0]\nfov_y_deg = 5\n\
             [sky]\nradiance = [1, 1, 1]\n[[mesh]]\npath = {name:?}\n"
        ),
    )
}

/// The floor of a canyon gathers the sky it sees, within 5 % of the path tracer's
/// (`--max-depth 2`; a long canyon's view factor, 1 / √(1 + (2h / w)²)), for walls half,
/// one, two and four times the floor's width high, at 64³, 128³ and 256³ with `render`'s
/// cones. Low walls let too much sky in and deep ones too little, both less at 256³ than
/// at 64³: the deepest gathers 0.81 of the sky it sees at 64³ (0.45 when the test was
/// written, session 38). A likely cause, not taken apart: the walls stop the same rays of
/// a rising cone all the way up, where the march composites their share of its disc in
/// cell after cell. Sponza's sunlit floor gathers 0.30 to 0.45 of its sky (BENCHMARKS.md,
/// session 38).
#[test]
#[ignore = "issue 20: walls half the width high 1.22 / 1.15 / 1.09 of the path tracer's at 64³ / 128³ / 256³, four times 0.81 / 0.75 / 0.80"]
fn canyon_floor_gathers_the_sky_it_sees() {
    let dir = temp_dir("components_canyon");
    let mut off = Vec::new();
    for height in [1.0, 2.0, 4.0, 8.0] {
        let scene = canyon(&dir, height);
        let path = dir.join(format!("path_{height}.exr"));
        let sky = render_path(
            &scene,
            &["--size", "32x32", "--spp", "256", "--max-depth", "2"],
            &path,
        );
        let exact = at_row(&sky, 16);
        for voxels in [64, 128, 256] {
            let out = dir.join(format!("canyon_{height}_{voxels}.exr"));
            dense(&scene, voxels, &["--bounces", "1"], &out);
            let ratio = centre(&out) / exact;
            eprintln!(
                "canyon {height} high, {voxels}³: {ratio:.3} of the path tracer's sky ({exact:.4})"
            );
            if (ratio - 1.0).abs() > 0.05 {
                off.push((height, voxels, ratio));
            }
        }
    }
    assert!(off.is_empty(), "off by more than 5 %: {off:?}");
}

/// Sibenik's cathedral under a sky of 1 with its light off, from `sibenik_main`'s camera, as
/// a scene file in `dir`: with one bounce each pixel is its albedo times the share of its
/// cones' light that leaves the building, which the path tracer's `--max-depth 2` gives
/// exactly (what the windows let out).
fn sibenik_under_the_sky(dir: &Path) -> PathBuf {
    let obj = shared().join("scenes/sibenik/sibenik.obj");
    write(
        dir,
        "sibenik_sky.toml",
        &format!(
            "[camera]\nposition = [-18, -11, 0]\ntarget = [0, -9, 0]\nfov_y_deg = 60\n\
             [sky]\nradiance = [1, 1, 1]\n[[mesh]]\npath = {obj:?}\n"
        ),
    )
}

/// The cones stay inside a closed building: what they see of the outside, over Sibenik's
/// view, within 20 % of the path tracer's at 64³ and 128³ with `render`'s cones. They
/// leave it, and more as the voxels get finer (3.38 times at 256³), 13 to 21 times at
/// the nave's far end: a voxel seen from behind is transparent to the directional levels
/// (`facing`), so a wall whose voxels face away from the cone lets it through, and the
/// light the cones miss inside is most of Sibenik's first-bounce deficit (0.93 of the
/// path tracer's at every resolution; BENCHMARKS.md, session 48).
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: 2.04 / 2.64 times the path tracer's at 64³ / 128³ (3.38 at 256³, 256x256, session 48)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn cones_stay_inside_a_closed_building() {
    let dir = temp_dir("components_closed_building");
    let scene = sibenik_under_the_sky(&dir);
    let size = ["--size", "128x128"];
    let mean = |image: &RgbImage| image.data.iter().map(|&v| f64::from(v)).sum::<f64>();
    let exact = mean(&render_path(
        &scene,
        &[&size[..], &["--spp", "64", "--max-depth", "2"]].concat(),
        &dir.join("path.exr"),
    ));
    let mut off = Vec::new();
    for voxels in ["64", "128"] {
        let out = dir.join(format!("ours_{voxels}.exr"));
        render(
            &scene,
            &[
                &size[..],
                &["--gi", "dense", "--voxels", voxels, "--bounces", "1"],
            ]
            .concat(),
            &out,
        );
        let ratio = mean(&load_rgb(&out).unwrap().0) / exact;
        eprintln!("{voxels}³: the cones see {ratio:.3} times the path tracer's outside");
        if (ratio - 1.0).abs() > 0.2 {
            off.push((voxels, ratio));
        }
    }
    assert!(off.is_empty(), "off by more than 20 %: {off:?}");
}

/// A closed box [-1, 1]³ of grey walls (albedo 0.5) whose faces wind `inwards` or out, with
/// two black specks beyond its corners that put its walls inside the grid, under a sky of
/// 1 and without lights, seen from inside, as a scene file in `dir`: with one bounce each
/// pixel is 0.5 times the share of its cones' light that leaves the box, none.
fn closed_box_under_the_sky(dir: &Path, inwards: bool) -> PathBuf {
    write(dir, "box.mtl", "newmtl wall\nKd 0.5 0.5 0.5\n");
    specks(dir);
    let faces = if inwards {
        "f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 4 3 7 8\nf 1 4 8 5\nf 2 6 7 3\n"
    } else {
        "f 4 3 2 1\nf 6 7 8 5\nf 2 6 5 1\nf 8 7 3 4\nf 5 8 4 1\nf 3 7 6 2\n"
    };
    let name = if inwards { "in" } else { "out" };
    write(
        dir,
        &format!("box_{name}.obj"),
        &format!(
            "mtllib box.mtl\nusemtl wall\n\
             v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n\
             {faces}"
        ),
    );
    write(
        dir,
        &format!("box_{name}.toml"),
        &format!(
            "[camera]\nposition = [0.6, 0.4, 0.8]\ntarget = [-1, -0.5, -1]\nfov_y_deg = 90\n\
             [sky]\nradiance = [1, 1, 1]\n[[mesh]]\npath = \"box_{name}.obj\"\n\
             [[mesh]]\npath = \"speck.obj\"\n"
        ),
    )
}

/// A closed room lets none of its cones out, whichever way its walls' faces wind (2 % at
/// most at 64³, `render`'s cones, one bounce). The references' surfaces are two-sided
/// and a scene's winding is arbitrary, but a voxel seen from behind is transparent to
/// the directional levels (`facing`, which keeps a cone from occluding itself with its
/// own surface), and an unlit voxel keeps its winding's normal: walls wound outwards let
/// most of the cones out. Wound inwards, what leaves is the coarse cells at the room's
/// edges that reach past its walls (`walls_of_a_closed_room_inside_the_grid_gather_its_radiance`).
/// Sibenik's cathedral lets out 2.04 times what its windows do
/// (`cones_stay_inside_a_closed_building`).
#[test]
#[ignore = "issue 20: 0.038 of the cones' light leaves the room wound inwards, 0.702 wound outwards, at 64³"]
fn closed_room_keeps_its_cones_whichever_way_its_walls_wind() {
    let dir = temp_dir("components_closed_room_winding");
    let one_bounce = [
        "--size",
        "64x64",
        "--gi",
        "dense",
        "--voxels",
        "64",
        "--bounces",
        "1",
    ];
    let mut off = Vec::new();
    for inwards in [true, false] {
        let scene = closed_box_under_the_sky(&dir, inwards);
        let out = dir.join(format!("box_{inwards}.exr"));
        render(&scene, &one_bounce, &out);
        let (image, _) = load_rgb(&out).unwrap();
        let mean = image.data.iter().map(|&v| f64::from(v)).sum::<f64>() / image.data.len() as f64;
        let share = mean / 0.5;
        eprintln!("walls wound inwards {inwards}: {share:.4} of the cones' light leaves the room");
        if share > 0.02 {
            off.push((inwards, share));
        }
    }
    assert!(off.is_empty(), "more than 2 % out: {off:?}");
}

/// An emissive wall (radiance 1, x = 0, 2 high and 4 wide, facing +x) standing on a
/// white floor 2 deep, nothing else, as a scene file in `dir` with the `[camera]` table
/// `camera`.
fn wall_and_floor(dir: &Path, camera: &str) -> PathBuf {
    write(
        dir,
        "l.mtl",
        "newmtl emit\nKd 0 0 0\nKe 1 1 1\nnewmtl floor\nKd 1 1 1\n",
    );
    write(
        dir,
        "l.obj",
        "mtllib l.mtl\nv 0 0 -2\nv 0 2 -2\nv 0 2 2\nv 0 0 2\nv 2 0 2\nv 2 0 -2\n\
         usemtl emit\nf 1 2 3 4\nusemtl floor\nf 1 4 5 6\n",
    );
    write(
        dir,
        "l.toml",
        &format!("{camera}[[mesh]]\npath = \"l.obj\"\n"),
    )
}

/// A white floor beside an emissive wall (radiance 1), nothing else, under a black sky:
/// the floor at eleven points from the wall outwards, with one bounce, within 10 % of
/// the path tracer's direct light. The wall's light is sampled (the voxels hold the
/// floor's light only), exact but for its visibility; the excess is the floor gathering
/// its own light (gathered through the voxels instead: 0.84 to 1.04).
#[test]
#[ignore = "issue 20: 1.04 to 1.12 of the path tracer's along the floor"]
fn floor_beside_an_emissive_wall_matches_the_path_tracer_with_the_ring() {
    floor_beside_an_emissive_wall_matches_the_path_tracer_with("components_wall_floor", RING);
}

/// With `--snapped-cones`: 0.974 to 1.047.
#[test]
fn floor_beside_an_emissive_wall_matches_the_path_tracer_with_snapped_cones() {
    floor_beside_an_emissive_wall_matches_the_path_tracer_with(
        "components_wall_floor_snapped",
        &["--snapped-cones"],
    );
}

/// With `render`'s default cones, the lattice (`--lattice-cones 72`): 0.974 to 1.047.
#[test]
fn floor_beside_an_emissive_wall_matches_the_path_tracer() {
    floor_beside_an_emissive_wall_matches_the_path_tracer_with(
        "components_wall_floor_lattice",
        &[],
    );
}

fn floor_beside_an_emissive_wall_matches_the_path_tracer_with(name: &str, extra: &[&str]) {
    let dir = temp_dir(name);
    let scene = wall_and_floor(
        &dir,
        "[camera]\nposition = [1, 1.5, 0.001]\ntarget = [1, 0, 0]\nfov_y_deg = 60\n",
    );
    let (ours, path) = (dir.join("ours.exr"), dir.join("path.exr"));
    dense(&scene, 64, &[&["--bounces", "1"], extra].concat(), &ours);
    render_path(
        &scene,
        &["--size", "256x256", "--spp", "256", "--max-depth", "2"],
        &path,
    );
    let row = |p: &Path| {
        let (image, _) = load_rgb(p).unwrap();
        let w = image.width as usize;
        (8..256)
            .step_by(24)
            .map(|x| {
                let mut sum = 0.0;
                for y in 120..136 {
                    sum += image.data[(y * w + x) * 3..(y * w + x) * 3 + 3]
                        .iter()
                        .sum::<f32>();
                }
                sum / 48.0
            })
            .collect::<Vec<_>>()
    };
    let ratios: Vec<f32> = row(&ours)
        .iter()
        .zip(row(&path))
        .map(|(o, p)| o / p)
        .collect();
    eprintln!("floor beside an emissive wall, ours / path tracer from the wall out: {ratios:.3?}");
    for r in ratios {
        assert!((r - 1.0).abs() <= 0.1, "{r}");
    }
}

/// A white wall (x = 0, facing +x, 2 high, 6 wide) standing on a white floor 6 x 6, both
/// of albedo 0.8, under a black sky, lit from straight above by a directional light of
/// irradiance 3: the floor takes it all and the wall none, so what the wall shows is
/// one bounce of the floor's light. A camera 1.5 before the wall looks at it level with
/// its point at height 0.5, so that row 127.5 - 256 (y - 0.5) / (3 tan 25°) is height y.
fn wall_on_lit_floor(dir: &Path) -> PathBuf {
    write(
        dir,
        "c.mtl",
        "newmtl floor\nKd 0.8 0.8 0.8\nnewmtl wall\nKd 0.8 0.8 0.8\n",
    );
    write(
        dir,
        "c.obj",
        "mtllib c.mtl\nv 0 0 -3\nv 0 0 3\nv 6 0 3\nv 6 0 -3\nv 0 2 -3\nv 0 2 3\n\
         usemtl floor\nf 1 2 3 4\nusemtl wall\nf 1 5 6 2\n",
    );
    write(
        dir,
        "c.toml",
        "[camera]\nposition = [1.5, 0.5, 0]\ntarget = [0, 0.5, 0]\nfov_y_deg = 50\n\
         [[mesh]]\npath = \"c.obj\"\n\
         [[light]]\nkind = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [3, 3, 3]\n",
    )
}

/// The wall on the lit floor with one bounce, at heights from 0.03 to 0.8 above the
/// floor, within 10 % of the path tracer's: the corner between two surfaces, which every
/// room and every object standing on a floor has. Each cone running along the floor near
/// it reads the floor's voxels, seen edge-on, in cell after cell, and the march
/// composites them as if each cell blocked other rays, so the floor closes the whole
/// cone where it truly fills the half below the horizon (one lattice cone level with the
/// floor: 0.98 of the floor's radiance at 0.02, where half is due; BENCHMARKS.md,
/// session 36). The excess grows as the wall point nears the floor, at every resolution
/// alike: Loubet and Neyret's correlated occlusion, which linear filtering loses.
#[test]
#[ignore = "issue 20: 1.10 at 0.03 above the floor, falling to 0.84 at 0.4 and 0.79 at 0.8 (64³)"]
fn wall_on_a_lit_floor_matches_the_path_tracer_with_the_ring() {
    wall_on_a_lit_floor_matches_the_path_tracer_with("components_corner", RING);
}

/// With `--snapped-cones`, and so the planes: 0.902 at 0.03 above the floor, 1.00 to 1.07
/// above (without the planes 1.11 at 0.03 and at 0.6, 1.03 to 1.07 between).
#[test]
fn wall_on_a_lit_floor_matches_the_path_tracer_with_snapped_cones() {
    wall_on_a_lit_floor_matches_the_path_tracer_with(
        "components_corner_snapped",
        &["--snapped-cones"],
    );
}

/// With `render`'s default cones, the lattice (`--lattice-cones 72`), and the planes:
/// each cell keeps its surface plane, and the floor the cones run beside counts once, as
/// the growing segment of their discs beyond it, not cell after cell (measured 0.96 at
/// 0.03 above the floor, 1.01 to 1.05 above).
#[test]
fn wall_on_a_lit_floor_matches_the_path_tracer() {
    wall_on_a_lit_floor_matches_the_path_tracer_with("components_corner_lattice", &[]);
}

/// The lattice without the planes: every cell of the floor composited as if it blocked
/// other rays.
#[test]
#[ignore = "issue 20: 1.15 at 0.03 above the floor, 1.13 at 0.06, 1.10 at 0.1, 1.03 to 1.08 above (64³)"]
fn wall_on_a_lit_floor_matches_the_path_tracer_without_plane_occlusion() {
    wall_on_a_lit_floor_matches_the_path_tracer_with(
        "components_corner_no_planes",
        &["--no-plane-occlusion"],
    );
}

/// The image row (256 rows, 50° vertical field of view) that shows height `y` of a wall
/// seen square-on from `distance` before it, by a camera level with its height 0.5.
fn wall_row(y: f32, distance: f32) -> usize {
    (127.5 - 256.0 * (y - 0.5) / (2.0 * distance * 25f32.to_radians().tan())).round() as usize
}

/// The heights above the floor the corner's tests measure at.
const CORNER_HEIGHTS: [f32; 8] = [0.03, 0.06, 0.1, 0.2, 0.3, 0.4, 0.6, 0.8];

/// The wall on the lit floor with one bounce at `voxels`³: ours over the path tracer's at
/// each of `CORNER_HEIGHTS`.
fn wall_on_a_lit_floor_ratios(name: &str, voxels: u32, extra: &[&str]) -> Vec<f32> {
    let dir = temp_dir(name);
    let scene = wall_on_lit_floor(&dir);
    let (ours, path) = (dir.join("ours.exr"), dir.join("path.exr"));
    dense(
        &scene,
        voxels,
        &[&["--bounces", "1"], extra].concat(),
        &ours,
    );
    render_path(
        &scene,
        &["--size", "256x256", "--spp", "256", "--max-depth", "3"],
        &path,
    );
    let (ours, path) = (load_rgb(&ours).unwrap().0, load_rgb(&path).unwrap().0);
    let ratios: Vec<f32> = CORNER_HEIGHTS
        .iter()
        .map(|&y| at_row(&ours, wall_row(y, 1.5)) / at_row(&path, wall_row(y, 1.5)))
        .collect();
    eprintln!(
        "wall on a lit floor {extra:?}, {voxels}³, ours / path tracer at heights \
         {CORNER_HEIGHTS:?}: {ratios:.3?}"
    );
    ratios
}

fn wall_on_a_lit_floor_matches_the_path_tracer_with(name: &str, extra: &[&str]) {
    let ratios = wall_on_a_lit_floor_ratios(name, 64, extra);
    for (y, r) in CORNER_HEIGHTS.iter().zip(ratios) {
        assert!((r - 1.0).abs() <= 0.1, "at {y} above the floor: {r}");
    }
}

/// With the lattice and the directional levels filtered by rows, at 128³: within 5 % of
/// the path tracer from two voxels above the floor (0.1 and up; the grid spans 6).
/// Filtered by pairs, a level composites its children's averages as if each blocked
/// other rays, so the floor, seen edge-on, filled more of each cell than its voxels do,
/// whatever their size: 1.09 at 0.1 and 1.07 at 0.2 at 128³ as at 64³. By rows, the
/// excess falls as the voxels get finer (measured at 0.1 / 0.2: 1.075 / 1.047 at 64³,
/// 1.027 / 0.995 at 128³; nearer the floor than a voxel, the floor's own voxels stand
/// in the wall's: 1.13 at 0.03; BENCHMARKS.md, session 37).
#[test]
fn wall_on_a_lit_floor_matches_the_path_tracer_filtered_by_rows() {
    let ratios = wall_on_a_lit_floor_ratios(
        "components_corner_rows",
        128,
        &["--lattice-cones", "72", "--directional-filter", "rows"],
    );
    for (y, r) in CORNER_HEIGHTS.iter().zip(ratios) {
        if *y >= 0.1 {
            assert!((r - 1.0).abs() <= 0.05, "at {y} above the floor: {r}");
        }
    }
}

/// A white floor 6 x 6 under a square emitter 1 x 1 at height 1 (radiance 1, facing
/// down), with or without a black block 0.6 x 0.3 x 0.6 half-way between them, as a
/// scene file in `dir`, seen from above.
fn floor_under_emitter(dir: &Path, block: bool) -> PathBuf {
    let name = format!("e_{block}");
    let camera = "position = [0, 0.3, 0.001]\ntarget = [0, 0, 0]\nfov_y_deg = 10";
    emitter_over_floor(dir, &name, block.then_some([0.35, 0.65]), camera)
}

/// The unit square emitter 1 above a white floor 6 x 6 and, where `block` gives its
/// bottom and top, a black block 0.6 x 0.6 between them, as a scene `name` in `dir` seen
/// from `camera` (the scene file's `[camera]` keys).
fn emitter_over_floor(dir: &Path, name: &str, block: Option<[f64; 2]>, camera: &str) -> PathBuf {
    let mut obj = String::from(
        "mtllib e.mtl\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nv -3 0 -3\n\
         v -0.5 1 -0.5\nv 0.5 1 -0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n\
         usemtl floor\nf 1 2 3 4\nusemtl emit\nf 5 6 7 8\n",
    );
    if let Some(heights) = block {
        // Its six faces, from vertices 9 (the bottom) to 16 (the top).
        for y in heights {
            for (x, z) in [(-0.3, -0.3), (0.3, -0.3), (0.3, 0.3), (-0.3, 0.3)] {
                obj += &format!("v {x} {y} {z}\n");
            }
        }
        obj += "usemtl black\nf 9 10 11 12\nf 13 16 15 14\nf 9 13 14 10\nf 10 14 15 11\n\
                f 11 15 16 12\nf 12 16 13 9\n";
    }
    write(
        dir,
        "e.mtl",
        "newmtl floor\nKd 1 1 1\nnewmtl emit\nKd 0 0 0\nKe 1 1 1\nnewmtl black\nKd 0 0 0\n",
    );
    write(dir, &format!("{name}.obj"), &obj);
    write(
        dir,
        &format!("{name}.toml"),
        &format!("[camera]\n{camera}\n[[mesh]]\npath = \"{name}.obj\"\n"),
    )
}

/// The irradiance at `x` on the floor (normal +y) from the unit square emitter of
/// `floor_under_emitter`, by the midpoint rule over 400 x 400 cells.
fn square_irradiance(x: glam::DVec3) -> f64 {
    let n = 400;
    let cell = 1.0 / n as f64;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let p = glam::DVec3::new(
                -0.5 + (i as f64 + 0.5) * cell,
                1.0,
                -0.5 + (j as f64 + 0.5) * cell,
            );
            let d = p - x;
            let r2 = d.length_squared();
            // Both cosines: d.y / r at the floor and at the emitter (facing down).
            sum += (d.y * d.y) / (r2 * r2) * cell * cell;
        }
    }
    sum
}

/// The sampled emitter's light alone (`--debug-view emitter-light`) on a floor under it:
/// its exact irradiance (Lambert's formula) over π, within 2 % of the midpoint rule's,
/// where nothing stands between them (measured 0.9997); in the full shadow of a block
/// between them, below 5 % of it (measured 0.026 at 64³, 0.035 at 128³: a visibility
/// cone as wide as the emitter passed 0.18 and 0.29 through the block's one-voxel faces,
/// and one reading the directional volumes as a ray from the receiver, which see the
/// block's lit top from behind, passed all of it).
#[test]
fn floor_under_an_emitter_takes_its_irradiance_and_shadow() {
    let dir = temp_dir("components_floor_under_emitter");
    let exact = square_irradiance(glam::DVec3::ZERO) / std::f64::consts::PI;
    for voxels in [64, 128] {
        let mut shares = [0.0; 2];
        for (i, block) in [false, true].into_iter().enumerate() {
            let scene = floor_under_emitter(&dir, block);
            let out = dir.join(format!("e_{block}_{voxels}.exr"));
            // The view shows the emitter's light alone, which no bounce changes.
            let args = ["--debug-view", "emitter-light", "--bounces", "1"];
            dense(&scene, voxels, &args, &out);
            shares[i] = f64::from(centre(&out)) / exact;
        }
        eprintln!(
            "floor under an emitter, {voxels}³: {:.4} of the exact light, {:.4} in the block's shadow",
            shares[0], shares[1]
        );
        assert!((shares[0] - 1.0).abs() <= 0.02, "{voxels}³: {}", shares[0]);
        assert!(
            shares[1] <= 0.05,
            "{voxels}³: the shadow passes {}",
            shares[1]
        );
    }
}

/// The floor of `floor_under_emitter` with the black block lower (y 0.5 to 0.7), seen
/// from under it with a 120 degree view: the block's umbra and all of its penumbra.
fn floor_in_a_penumbra(dir: &Path) -> PathBuf {
    let camera = "position = [0, 0.45, 0.001]\ntarget = [0, 0, 0]\nfov_y_deg = 120";
    emitter_over_floor(dir, "penumbra", Some([0.5, 0.7]), camera)
}

/// The sampled emitter's light (`--debug-view emitter-light`) on a floor in a block's
/// penumbra, summed over the view, as a share of the path tracer's (`--max-depth 2` less
/// `--max-depth 1`), with `pieces` emitter pieces at 128³.
fn penumbra_share(name: &str, pieces: &[u32]) -> Vec<f64> {
    let dir = temp_dir(name);
    let scene = floor_in_a_penumbra(&dir);
    let path = |f: &str| dir.join(f);
    for depth in ["1", "2"] {
        render_path(
            &scene,
            &["--size", "256x256", "--spp", "64", "--max-depth", depth],
            &path(&format!("path_{depth}.exr")),
        );
    }
    let exact: f64 = block_indirect(&path("path_2.exr"), &path("path_1.exr"))
        .iter()
        .sum();
    pieces
        .iter()
        .map(|n| {
            let out = path(&format!("pieces_{n}.exr"));
            let n = n.to_string();
            let args = ["--debug-view", "emitter-light", "--bounces", "1"];
            dense(
                &scene,
                128,
                &[&args[..], &["--emitter-pieces", &n]].concat(),
                &out,
            );
            let ours: f64 = block_sums(&load_rgb(&out).unwrap().0).iter().sum();
            eprintln!(
                "penumbra, {n} emitter pieces, 128³: {:.4} of the path tracer's light",
                ours / exact
            );
            ours / exact
        })
        .collect()
}

/// An area emitter casts penumbrae: one visibility cone for the whole emitter shadows
/// the floor as from its centre, most of the view dark (0.44 of the path tracer's light
/// at 128³; 0.24 before the voxels' coverage), and `render`'s eight pieces, each with its
/// own cone, light the penumbra (0.90; 0.785 before). What they leave is
/// `block_shadow_is_as_wide_as_the_path_tracers`.
#[test]
fn emitter_pieces_cast_penumbrae() {
    let shares = penumbra_share("components_penumbra", &[1, 8]);
    assert!(shares[0] < 0.5, "one piece: {}", shares[0]);
    assert!(shares[1] > 0.85, "eight pieces: {}", shares[1]);
}

/// The penumbra's light within 5 % of the path tracer's. Counted whole, the voxels a
/// block's faces end in cast its shadow up to a voxel too wide on each side (0.785 at
/// 128³, 0.645 / 0.834 at 64³ / 256³); the narrow cones now read the base voxels across
/// their coverage (0.953 / 0.904 / 0.840), but the wider ones, which read the
/// directional levels, still count partial voxels whole, as their filter does, and the
/// top face at 0.7 lies in the voxel above the block's, read as if at its centre
/// (BENCHMARKS.md, session 47).
#[test]
#[ignore = "issue 20: 0.904 of the path tracer's light with eight pieces at 128³ (0.953 at 64³, 0.840 at 256³)"]
fn block_shadow_is_as_wide_as_the_path_tracers() {
    let share = penumbra_share("components_penumbra_width", &[8])[0];
    assert!((share - 1.0).abs() <= 0.05, "{share}");
}

/// A table under a black sky, lit from straight above by a directional light of
/// irradiance 3: a floor 6 x 6 of albedo 0.5 and over its middle at height 0.5 a top
/// 2 x 2 of albedo 0.8, two faces 0.004 apart (inside one voxel at 64³ and 128³). A low
/// camera looks under the top at the floor's middle. With one bounce, what the floor
/// shows there, in the top's shadow (row 128), and in the light before the table (row
/// 208), as shares of the lit top's radiance 2.4 / π.
fn table(voxels: u32, gi: &[&str]) -> (f32, f32) {
    let dir = temp_dir(&format!("components_table_{voxels}"));
    write(
        &dir,
        "t.mtl",
        "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl top\nKd 0.8 0.8 0.8\n",
    );
    write(
        &dir,
        "t.obj",
        "mtllib t.mtl\n\
         v -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\n\
         v -1 0.502 -1\nv -1 0.502 1\nv 1 0.502 1\nv 1 0.502 -1\n\
         v -1 0.498 -1\nv 1 0.498 -1\nv 1 0.498 1\nv -1 0.498 1\n\
         usemtl floor\nf 1 2 3 4\nusemtl top\nf 5 6 7 8\nf 9 10 11 12\n",
    );
    let scene = write(
        &dir,
        "t.toml",
        "[camera]\nposition = [0, 0.25, -2.9]\ntarget = [0, 0, 0]\nfov_y_deg = 20\n\
         [[mesh]]\npath = \"t.obj\"\n\
         [[light]]\nkind = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [3, 3, 3]\n",
    );
    let out = dir.join("table.exr");
    render_256(&scene, &[gi, &["--bounces", "1"]].concat(), &out);
    let (image, _) = load_rgb(&out).unwrap();
    let top = 2.4 / std::f32::consts::PI;
    (at_row(&image, 128) / top, at_row(&image, 208) / top)
}

/// Under a table top thinner than a voxel, the floor sees only the top's unlit underside
/// and the black sky (a plane sees none of itself), so it gathers nothing; the lit floor
/// before the table sees the same and shows its direct light alone, 1.5 / π (0.625 of
/// the top's). The voxel holding both faces of the top shows its light only to cones
/// that look at its lit face; the bounds leave what the side volumes show of the top
/// edge-on (half of it, to cones from below as from above: BENCHMARKS.md, session 27).
/// A voxel facing every way gave 0.38 under the table at 64³ and 0.72 before it.
#[test]
fn floor_under_a_table_top_sees_its_underside() {
    for voxels in [64, 128] {
        let v = voxels.to_string();
        for (gi, what) in [
            (["--gi", "dense", "--voxels", &v], "dense"),
            (["--gi", "octree", "--voxels", &v], "octree"),
        ] {
            let (under, before) = table(voxels, &gi);
            eprintln!(
                "table, {what} {voxels}³: under it {under:.3}, before it {before:.3} of the top's radiance"
            );
            assert!(under <= 0.15, "{what} {voxels}³: under the table {under}");
            assert!(
                (before / 0.625 - 1.0).abs() <= 0.1,
                "{what} {voxels}³: before the table {before}"
            );
        }
    }
}

/// A white wall (x = 0, facing +x) beside a white block 1 to 2 from it (2 wide, 0.5 high)
/// on a black floor, under a sun from straight above: only the block's top is lit, so the
/// wall below the top's plane sees nothing lit, and with one bounce shows nothing (the
/// block's sides and the floor are dark). A camera 0.9 before the wall looks at it level
/// with height 0.5, so that row 127.5 - 256 (y - 0.5) / (1.8 tan 25°) is height y.
/// Returns what the wall shows at 0.15, 0.3 and 0.4 above the floor, as shares of the lit
/// top's radiance 2.4 / π.
fn wall_below_a_lit_top(voxels: u32) -> Vec<f32> {
    let dir = temp_dir(&format!("components_lit_top_{voxels}"));
    write(
        &dir,
        "b.mtl",
        "newmtl black\nKd 0 0 0\nnewmtl white\nKd 0.8 0.8 0.8\n",
    );
    write(
        &dir,
        "b.obj",
        "mtllib b.mtl\n\
         v 0 0 -3\nv 0 0 3\nv 6 0 3\nv 6 0 -3\nv 0 2 -3\nv 0 2 3\n\
         v 1 0 -1\nv 2 0 -1\nv 2 0 1\nv 1 0 1\n\
         v 1 0.5 -1\nv 2 0.5 -1\nv 2 0.5 1\nv 1 0.5 1\n\
         usemtl black\nf 1 2 3 4\nusemtl white\nf 1 5 6 2\n\
         f 11 14 13 12\nf 7 10 14 11\nf 8 12 13 9\nf 7 11 12 8\nf 10 9 13 14\n",
    );
    let scene = write(
        &dir,
        "b.toml",
        "[camera]\nposition = [0.9, 0.5, 0]\ntarget = [0, 0.5, 0]\nfov_y_deg = 50\n\
         [[mesh]]\npath = \"b.obj\"\n\
         [[light]]\nkind = \"directional\"\ndirection = [0, -1, 0]\nirradiance = [3, 3, 3]\n",
    );
    let out = dir.join("wall.exr");
    dense(&scene, voxels, &["--bounces", "1"], &out);
    let (image, _) = load_rgb(&out).unwrap();
    let top = 2.4 / std::f32::consts::PI;
    [0.15, 0.3, 0.4]
        .iter()
        .map(|&y| at_row(&image, wall_row(y, 0.9)) / top)
        .collect()
}

/// Below the plane of a lit surface nothing sees its light (the path tracer's image is
/// black there): within 0.2 % of the lit top's radiance at 64³ and 128³. Two sources,
/// each about half of it at 128³ (BENCHMARKS.md, session 43): the voxels along the top's
/// edges hold the top and the block's side, lit as a mixture (inject.comp,
/// voxel_attenuation), and show that light to every side their mean normal faces; and the
/// top's own cells, seen edge-on, show half of their light along the axes they lie in
/// (anisotropic.glsl, facing) to cones from below the top's plane as from above it.
#[test]
#[ignore = "issue 20: 0.025, 0.037 and 0.041 of the top's radiance at 0.15, 0.3 and 0.4 at 64³; 0.014, 0.021 and 0.024 at 128³"]
fn wall_below_a_lit_top_sees_none_of_it() {
    for voxels in [64, 128] {
        let shares = wall_below_a_lit_top(voxels);
        eprintln!("wall below a lit top, {voxels}³, at 0.15 / 0.3 / 0.4: {shares:.4?}");
        for share in shares {
            assert!(share <= 0.002, "{voxels}³: {share}");
        }
    }
}

/// The path tracer's cone component (`--cone K`) against the same cone integrated here
/// by Monte Carlo: a white floor point 0.3 from an emissive wall (radiance 1, 2 high,
/// 4 wide), nothing else; each cone of the default gather (the normal, +y, and five at
/// 57.5 degrees, the first towards -z) sees the wall in the share of its solid angle
/// whose rays cross x = 0 inside the wall, with `--cosine-cones` each ray counting by
/// its cosine to the normal over the cosine's mean over the cone.
#[test]
fn cone_component_is_the_cone_integral() {
    for cosine in [false, true] {
        cone_component_matches(cosine);
    }
}

fn cone_component_matches(cosine: bool) {
    let dir = temp_dir("components_cone_integral");
    let d = 0.3f64;
    let scene = wall_and_floor(
        &dir,
        &format!("[camera]\nposition = [{d}, 1, 0.001]\ntarget = [{d}, 0, 0]\nfov_y_deg = 1\n"),
    );
    let (n, t, b) = (glam::DVec3::Y, glam::DVec3::NEG_Z, glam::DVec3::NEG_X);
    let cos_half = 30f64.to_radians().cos();
    let mut state = 1u64;
    let mut random = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for k in 0..6 {
        let axis = if k == 0 {
            n
        } else {
            let phi = std::f64::consts::TAU * f64::from(k - 1) / 5.0;
            (0.5373 * n + 0.8434 * (phi.cos() * t + phi.sin() * b)).normalize()
        };
        let (u, v) = (axis.any_orthonormal_pair().0, axis.any_orthonormal_pair().1);
        let samples = 200_000;
        let mean_cos = axis.dot(n) * 0.5 * (1.0 + cos_half);
        let mut hits = 0.0;
        for _ in 0..samples {
            let c = 1.0 - random() * (1.0 - cos_half);
            let s = (1.0 - c * c).max(0.0).sqrt();
            let phi = std::f64::consts::TAU * random();
            let w = s * phi.cos() * u + s * phi.sin() * v + c * axis;
            if w.x < 0.0 {
                let along = d / -w.x;
                if along * w.y <= 2.0 && (along * w.z).abs() <= 2.0 {
                    hits += if cosine { w.dot(n) / mean_cos } else { 1.0 };
                }
            }
        }
        let exact = hits / f64::from(samples);
        let out = dir.join(format!("cone{k}_{cosine}.exr"));
        let k = k.to_string();
        let args = [
            "--gi",
            "path",
            "--size",
            "64x64",
            "--spp",
            "256",
            "--max-depth",
            "3",
            "--cone",
            &k,
        ];
        let weighting: &[&str] = if cosine { &["--cosine-cones"] } else { &[] };
        render(&scene, &[&args[..], weighting].concat(), &out);
        let traced = f64::from(centre(&out));
        eprintln!(
            "cone {k}, cosine {cosine}: path tracer {traced:.4}, Monte Carlo here {exact:.4}"
        );
        assert!(
            (traced - exact).abs() <= 0.01 + 0.02 * exact,
            "cone {k}: {traced} against {exact}"
        );
    }
}

/// The ring's gather is the weighted sum of its cones, each as `--cone K` traces it alone:
/// 1 : 1/2 along the normal and in the ring by default; with `--cosine-cones` each
/// cone by its region's share of the cosine-weighted hemisphere, 1/4 along the normal
/// and 3/20 for each of the five in the ring (the weights the path tracer's exact cones
/// are summed with in `exact_cosine_cones`). The floor beside an emissive wall, seen
/// from above at an angle, gathers from different cones across the image; the wall's
/// light is gathered (`--sampled-emitters 0`), as `--cone` traces never add the sampled
/// emitters'.
#[test]
fn gather_weighs_its_cones_by_their_shares() {
    let dir = temp_dir("components_gather_weights");
    let scene = wall_and_floor(
        &dir,
        "[camera]\nposition = [1.8, 1.5, 1.5]\ntarget = [0.6, 0, -0.3]\nfov_y_deg = 60\n",
    );
    let load = |p: &Path| load_rgb(p).unwrap().0.data;
    let off = dir.join("off.exr");
    render_256(&scene, &["--gi", "off"], &off);
    let off = load(&off);
    for (cosine, centre, ring) in [(false, 1.0 / 3.5, 0.5 / 3.5), (true, 0.25, 0.15)] {
        let weighting: &[&str] = if cosine { &["--cosine-cones"] } else { &[] };
        let indirect = |k: Option<u32>| {
            let out = dir.join(format!("{cosine}_{k:?}.exr"));
            let cone = k.map(|k| k.to_string());
            let only: Vec<&str> = cone.iter().flat_map(|k| ["--cone", k.as_str()]).collect();
            dense(
                &scene,
                64,
                &[
                    &["--bounces", "1", "--sampled-emitters", "0"],
                    RING,
                    weighting,
                    &only,
                ]
                .concat(),
                &out,
            );
            load(&out)
                .iter()
                .zip(&off)
                .map(|(a, b)| a - b)
                .collect::<Vec<f32>>()
        };
        let gather = indirect(None);
        let mut sum = vec![0.0f32; gather.len()];
        for k in 0..6 {
            let w = if k == 0 { centre } else { ring };
            for (s, c) in sum.iter_mut().zip(indirect(Some(k))) {
                *s += w * c;
            }
        }
        let mean = gather.iter().sum::<f32>() / gather.len() as f32;
        let worst = gather
            .iter()
            .zip(&sum)
            .map(|(g, s)| (g - s).abs())
            .fold(0.0f32, f32::max);
        eprintln!("cosine {cosine}: mean indirect {mean:.4}, worst pixel off by {worst:.5}");
        assert!(mean > 0.01, "the floor gathers nothing: {mean}");
        assert!(worst <= 0.01 * mean, "a pixel off by {worst}, mean {mean}");
    }
}

/// The first bounce's total over the conference view (the image less its direct light,
/// ours with `--bounces 1`, the path tracer's with `--max-depth 3` less `--max-depth 2`)
/// at 64³ and at 256³: each within 5 % of the path tracer's. With the ring (`--quality
/// fast`) the room lost light as the voxels got finer (1.026 and 0.869) where the Cornell
/// box barely did (0.982 at 256³).
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: 1.261 of the path tracer's at 64³, 1.031 at 256³ (render's default, the lattice with the planes; without them 1.283 and 1.041)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn first_bounce_holds_its_total_as_the_voxels_get_finer() {
    let scene = shared().join("reference/conference_main.scene.json");
    let dir = temp_dir("components_conference_bounce");
    let path = |f: &str| dir.join(f);
    let traced = |depth: &str, out: &Path| {
        render_path(
            &scene,
            &["--size", "256x256", "--spp", "64", "--max-depth", depth],
            out,
        );
    };
    traced("2", &path("path_direct.exr"));
    traced("3", &path("path_one.exr"));
    render_256(&scene, &["--gi", "off"], &path("off.exr"));
    let total = |v: Vec<f64>| v.iter().sum::<f64>();
    let exact = total(block_indirect(
        &path("path_one.exr"),
        &path("path_direct.exr"),
    ));
    let mut ratios = Vec::new();
    for voxels in [64, 256] {
        let out = path(&format!("one_{voxels}.exr"));
        dense(&scene, voxels, &["--bounces", "1"], &out);
        ratios.push(total(block_indirect(&out, &path("off.exr"))) / exact);
    }
    eprintln!("first bounce over the path tracer's, 64³ and 256³: {ratios:.3?}");
    for r in ratios {
        assert!((r - 1.0).abs() <= 0.05, "{r}");
    }
}

/// Every bounce over the first, as `bounces_over_the_first_match_the_path_tracer`
/// measures it on the Cornell box, on a reference scene `name` at 64³ and 256³ with
/// `--snapped-cones`: ours (all bounces over `--bounces 1`, each less `--gi off`) over
/// the path tracer's (the reference over `--max-depth 3`, each less `--max-depth 2`).
fn bounces_over_the_first_with_snapped_cones(name: &str) -> Vec<f64> {
    let scene = shared().join(format!("reference/{name}.scene.json"));
    let dir = temp_dir(&format!("components_bounces_{name}"));
    let path = |f: &str| dir.join(f);
    for depth in ["2", "3"] {
        render_path(
            &scene,
            &["--size", "256x256", "--spp", "64", "--max-depth", depth],
            &path(&format!("path_{depth}.exr")),
        );
    }
    render_256(&scene, &["--gi", "off"], &path("off.exr"));
    let total = |v: Vec<f64>| v.iter().sum::<f64>();
    let exact = total(block_indirect(
        &shared().join(format!("reference/{name}.exr")),
        &path("path_2.exr"),
    )) / total(block_indirect(&path("path_3.exr"), &path("path_2.exr")));
    let mut ratios = Vec::new();
    for voxels in [64, 256] {
        let one = path(&format!("one_{voxels}.exr"));
        let all = path(&format!("all_{voxels}.exr"));
        dense(&scene, voxels, &["--snapped-cones", "--bounces", "1"], &one);
        dense(&scene, voxels, &["--snapped-cones"], &all);
        let ours = total(block_indirect(&all, &path("off.exr")))
            / total(block_indirect(&one, &path("off.exr")));
        ratios.push(ours / exact);
    }
    eprintln!(
        "{name}: every bounce over the first, over the path tracer's, 64³ and 256³: {ratios:.3?}"
    );
    ratios
}

/// On `conference_main`, within 5 % at 64³ and at 256³: 1.025 and 0.960 since one image
/// traces its bounces until they converge (13 there; eight left 0.995 and 0.933 with the
/// planes, 1.027 and 0.959 without; BENCHMARKS.md, session 44). With the planes the
/// voxels' bounce gathers less of a closed room: in the furnace of
/// `walls_of_a_closed_room_inside_the_grid_gather_its_radiance` with walls of albedo
/// 0.5, 0.954 of the walls' radiance where it gathered 0.970 (session 42).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn conference_bounces_over_the_first_match_the_path_tracer_with_snapped_cones() {
    for r in bounces_over_the_first_with_snapped_cones("conference_main") {
        assert!((r - 1.0).abs() <= 0.05, "{r}");
    }
}

/// On `sibenik_main`, the same (0.987 and 0.950 with its six bounces; 0.990 and 0.951
/// with eight, 0.990 and 0.952 with 19: its light leaves through the nave's openings;
/// 0.982 and 0.944 while the snapped cells blended two levels, session 31).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn sibenik_bounces_over_the_first_match_the_path_tracer_with_snapped_cones() {
    for r in bounces_over_the_first_with_snapped_cones("sibenik_main") {
        assert!((r - 1.0).abs() <= 0.05, "{r}");
    }
}

/// `conference_main`'s point light, as a scene file in `dir` with the `[camera]` table
/// `camera`.
fn conference_with_camera(dir: &Path, camera: &str) -> PathBuf {
    let obj = shared().join("scenes/conference/conference.obj");
    write(
        dir,
        "conference.toml",
        &format!(
            "{camera}[[mesh]]\npath = {obj:?}\n[[light]]\nkind = \"point\"\n\
             position = [330, 600, -190]\nintensity = [400000, 400000, 400000]\n"
        ),
    )
}

/// The floor under the conference table, in its shadow, 70 from the table's edge: what
/// the cone along its normal gathers (`--cone 0`, one bounce), against the path tracer's
/// exact cone (0.003: it sees the table's unlit underside and the frame below it). Above
/// the table, the ceiling over the light is lit about 150 times as brightly as the floor,
/// so whatever of the table the cone sees through shows.
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: 0.35 at 64³ and 0.17 at 256³, against 0.003 (session 27)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn floor_under_the_conference_table_sees_through_none_of_it() {
    let dir = temp_dir("components_conference_table");
    let scene = conference_with_camera(
        &dir,
        "[camera]\nposition = [141.8, 100, -140]\ntarget = [141.8, -1.6, -146.1]\nfov_y_deg = 10\n",
    );
    let path = dir.join("path.exr");
    render_path(
        &scene,
        &[
            "--size",
            "64x64",
            "--spp",
            "1024",
            "--max-depth",
            "3",
            "--cone",
            "0",
        ],
        &path,
    );
    let exact = centre(&path);
    for voxels in [64, 256] {
        let out = dir.join(format!("cone_{voxels}.exr"));
        render(
            &scene,
            &[
                "--size",
                "64x64",
                "--gi",
                "dense",
                "--voxels",
                &voxels.to_string(),
                "--bounces",
                "1",
                "--cone",
                "0",
            ],
            &out,
        );
        let ours = centre(&out);
        eprintln!("floor under the table, {voxels}³: cone 0 gathers {ours:.4}, the path tracer {exact:.4}");
        assert!(ours - exact <= 0.03, "{voxels}³: {ours} against {exact}");
    }
}

/// `conference_main`'s walls (rows 64 to 128 of the view, at 128x128): what the cone along
/// their normal gathers with one bounce (`--cone 0`), within 10 % of the path tracer's
/// exact cone. It looks across the room, so it reads the coarsest levels, whose cells
/// are taller than the room.
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: 0.562 of the path tracer's at 64³, 0.464 at 256³ (session 27)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn conference_walls_cone_along_the_normal_matches_the_path_tracer() {
    let scene = shared().join("reference/conference_main.scene.json");
    let dir = temp_dir("components_conference_walls");
    let size = ["--size", "128x128"];
    let rows = |p: &Path| {
        let (image, _) = load_rgb(p).unwrap();
        image.data[32 * 128 * 3..64 * 128 * 3]
            .iter()
            .map(|&c| f64::from(c))
            .sum::<f64>()
    };
    let path = dir.join("path.exr");
    render_path(
        &scene,
        &[
            &size[..],
            &["--spp", "64", "--max-depth", "3", "--cone", "0"],
        ]
        .concat(),
        &path,
    );
    let off = dir.join("off.exr");
    render(&scene, &[&size[..], &["--gi", "off"]].concat(), &off);
    let exact = rows(&path);
    for voxels in [64, 256] {
        let out = dir.join(format!("cone_{voxels}.exr"));
        let v = voxels.to_string();
        render(
            &scene,
            &[
                &size[..],
                &[
                    "--gi",
                    "dense",
                    "--voxels",
                    &v,
                    "--bounces",
                    "1",
                    "--cone",
                    "0",
                ],
            ]
            .concat(),
            &out,
        );
        let ratio = (rows(&out) - rows(&off)) / exact;
        eprintln!("conference walls, {voxels}³: cone 0 gathers {ratio:.3} of the path tracer's");
        assert!((ratio - 1.0).abs() <= 0.1, "{voxels}³: {ratio}");
    }
}

/// Convergence: LDR-FLIP against each reference at 128³ is no higher than at 64³ (within
/// 0.003), `--gi dense` with the ring of cones at its default settings but the
/// resolution.
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: cornell_point 0.0994 → 0.1044, cornell_area 0.1901 → 0.1925, conference_main 0.2007 → 0.2292"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn flip_does_not_rise_as_the_voxels_get_finer_with_the_ring() {
    flip_does_not_rise_as_the_voxels_get_finer_with("components_convergence", RING);
}

/// The same with `--snapped-cones`.
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: sponza_main 0.1479 → 0.1532, sibenik_main 0.0580 → 0.0645 (session 35; the others hold)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn flip_does_not_rise_as_the_voxels_get_finer_with_snapped_cones() {
    flip_does_not_rise_as_the_voxels_get_finer_with(
        "components_convergence_snapped",
        &["--snapped-cones"],
    );
}

/// The same with `render`'s defaults (the lattice of 72 cones, `render`'s shadow maps,
/// the planes, bounces until they converge): cornell_point 0.0848 → 0.0765, cornell_area
/// 0.0644 → 0.0571, sponza_main 0.1426 → 0.1263, sibenik_main 0.0559 → 0.0565,
/// conference_main 0.1751 → 0.0999 (session 44; Sibenik rose 0.0542 → 0.0573 at session
/// 39, before a turned plane's voxels took its light).
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn flip_does_not_rise_as_the_voxels_get_finer() {
    flip_does_not_rise_as_the_voxels_get_finer_with("components_convergence_lattice", &[]);
}

fn flip_does_not_rise_as_the_voxels_get_finer_with(name: &str, extra: &[&str]) {
    flip_does_not_rise_as_the_voxels_get_finer_on(
        name,
        extra,
        &[
            "cornell_point",
            "cornell_area",
            "sponza_main",
            "sibenik_main",
            "conference_main",
        ],
    );
}

fn flip_does_not_rise_as_the_voxels_get_finer_on(name: &str, extra: &[&str], scenes: &[&str]) {
    let dir = temp_dir(name);
    let mut rising = Vec::new();
    for &name in scenes {
        let reference = shared().join(format!("reference/{name}.exr"));
        let scene = shared().join(format!("reference/{name}.scene.json"));
        let flip = |voxels: u32| {
            let out = dir.join(format!("{name}_{voxels}.exr"));
            dense(&scene, voxels, extra, &out);
            compare(&reference, &out, &CompareOptions::default())
                .unwrap()
                .flip_ldr
        };
        let (coarse, fine) = (flip(64), flip(128));
        eprintln!("{name}: LDR-FLIP {coarse:.4} at 64³, {fine:.4} at 128³");
        if fine > coarse + 0.003 {
            rising.push((name, coarse, fine));
        }
    }
    assert!(rising.is_empty(), "rises: {rising:?}");
}

/// A white receiver (0.3 square at the origin, facing +y) and a square emitter (side 1,
/// radiance 1, facing the receiver) 3.5 away in the direction `theta` from the normal and
/// `phi` round it from the first ring cone's azimuth (-z), as a scene file in `dir`. Two
/// black specks at ±8 set the grid, so that the emitter lies far inside it (the grid's
/// face reads differently: session 23). A narrow camera above the receiver shows what it
/// gathers in its centre pixels.
fn emitter_around_receiver(dir: &Path, theta: f64, phi: f64) -> PathBuf {
    use glam::DVec3;
    let (theta, phi) = (theta.to_radians(), phi.to_radians());
    let d = theta.cos() * DVec3::Y
        + theta.sin() * (phi.cos() * DVec3::NEG_Z + phi.sin() * DVec3::NEG_X);
    let (u, v) = d.any_orthonormal_pair();
    let mut corners: Vec<DVec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(a, b)| 3.5 * d + 0.5 * (a * u + b * v))
        .collect();
    // Wound so that the emitting face looks at the receiver.
    if (corners[1] - corners[0])
        .cross(corners[2] - corners[0])
        .dot(d)
        > 0.0
    {
        corners.reverse();
    }
    let mut obj = String::from("mtllib a.mtl\n");
    for c in &corners {
        obj += &format!("v {} {} {}\n", c.x, c.y, c.z);
    }
    obj += "v -0.15 0 0.15\nv 0.15 0 0.15\nv 0.15 0 -0.15\nv -0.15 0 -0.15\n\
            v -8 -8 -8\nv -7.99 -8 -8\nv -8 -7.99 -8\nv 8 8 8\nv 7.99 8 8\nv 8 7.99 8\n\
            usemtl emit\nf 1 2 3 4\nusemtl receiver\nf 5 6 7 8\nusemtl black\nf 9 10 11\nf 12 13 14\n";
    write(
        dir,
        "a.mtl",
        "newmtl emit\nKd 0 0 0\nKe 1 1 1\nnewmtl receiver\nKd 1 1 1\nnewmtl black\nKd 0 0 0\n",
    );
    write(dir, "a.obj", &obj);
    write(
        dir,
        "a.toml",
        "[camera]\nposition = [0, 1, 0.01]\ntarget = [0, 0, 0]\nfov_y_deg = 6\n[[mesh]]\npath = \"a.obj\"\n",
    )
}

/// What the receiver gathers from the emitter at (`theta`, `phi`) with one bounce at
/// `voxels`³, over the path tracer's direct light from it (the same integral).
fn small_emitter_response(dir: &Path, theta: f64, phi: f64, voxels: u32, extra: &[&str]) -> f32 {
    let scene = emitter_around_receiver(dir, theta, phi);
    let (ours, path) = (dir.join("ours.exr"), dir.join("path.exr"));
    let voxels = voxels.to_string();
    let args = [
        "--gi",
        "dense",
        "--voxels",
        &voxels,
        "--bounces",
        "1",
        "--size",
        "32x32",
    ];
    render(&scene, &[&args[..], extra].concat(), &ours);
    render_path(
        &scene,
        &["--size", "32x32", "--spp", "64", "--max-depth", "2"],
        &path,
    );
    centre(&ours) / centre(&path)
}

/// A small emitter (16 degrees across) lights the receiver with the cosine's share
/// whatever its direction, within 15 %, at 256³ (the ring of cones gathering): its light is sampled, exactly but for
/// the visibility cone and the receiver gathering its own light (measured 1.032 to
/// 1.038). Directions from the normal to 80
/// degrees, on a ring cone's azimuth and half-way to the next one. Gathered through the
/// voxels instead (`--sampled-emitters 0`), the six cones' quadrature sees 0.414 (45°,
/// between the normal's cone and a ring cone) to 1.533 (80°, under a ring cone) of it.
#[test]
fn small_emitter_is_gathered_in_the_cosines_share_from_every_direction() {
    let dir = temp_dir("components_small_emitter_directions");
    let mut off = Vec::new();
    for theta in [0.0, 30.0, 45.0, 57.5, 70.0, 80.0] {
        for phi in [0.0, 36.0] {
            let r = small_emitter_response(&dir, theta, phi, 256, RING);
            eprintln!("small emitter at {theta}°, azimuth {phi}°: {r:.3} of the path tracer's");
            if (r - 1.0).abs() > 0.15 {
                off.push((theta, phi, r));
            }
        }
    }
    assert!(off.is_empty(), "off by more than 15 %: {off:?}");
}

/// The same emitter gathered through the voxels (`--sampled-emitters 0`), as a bounce's
/// light is: the gather's own response to a small source, which with exact cones would
/// follow their discs. With `--lattice-cones 72` it stays within 0.45 and 1.5 of the
/// cosine's share from the normal to 70 degrees, at 256³ (0.50 at 70 degrees to 1.27
/// along the normal, which the voxelization's widening by up to a voxel explains). Before
/// the cones marched cell by cell, the emitter straight above, met where they change
/// level, was gathered twice (1.96); the ring with `--snapped-cones` gave 3.6 along the
/// normal and 0.15 at 30 degrees, its cones reading pencils of their discs (BENCHMARKS.md,
/// sessions 34 and 35).
#[test]
fn lattice_gathers_a_small_voxel_emitter_in_the_cosines_share() {
    let dir = temp_dir("components_small_emitter_lattice");
    let mut off = Vec::new();
    for theta in [0.0, 15.0, 30.0, 45.0, 60.0, 70.0] {
        for phi in [0.0, 36.0] {
            let gather = ["--sampled-emitters", "0", "--lattice-cones", "72"];
            let r = small_emitter_response(&dir, theta, phi, 256, &gather);
            eprintln!(
                "small voxel emitter at {theta}°, azimuth {phi}°: {r:.3} of the path tracer's"
            );
            if !(0.45..=1.5).contains(&r) {
                off.push((theta, phi, r));
            }
        }
    }
    assert!(off.is_empty(), "outside 0.45 and 1.5: {off:?}");
}

/// The same emitter straight above: at 64³ (4 voxels across) it gives what it gives at
/// 256³, within 10 % (measured 1.009 and 1.038 of the path tracer's: sampled, it does
/// not depend on its voxelization; gathered, 0.675 and 0.587, a conservative
/// voxelization widening it by up to a voxel).
#[test]
fn small_emitter_keeps_its_share_as_the_voxels_get_coarser() {
    let dir = temp_dir("components_small_emitter_resolution");
    let coarse = small_emitter_response(&dir, 0.0, 0.0, 64, RING);
    let fine = small_emitter_response(&dir, 0.0, 0.0, 256, RING);
    eprintln!("small emitter above: {coarse:.3} at 64³, {fine:.3} at 256³ of the path tracer's");
    assert!(
        (coarse / fine - 1.0).abs() <= 0.1,
        "{coarse} against {fine}"
    );
}

/// The Cornell box's one bounce per 32x32 block, from the path tracer (`--max-depth 3`,
/// less the direct-light reference), and as the cone set itself gives it with every cone
/// exact: the path tracer's cone components (`--cone K` with `--cosine-cones`, the
/// cosine-weighted mean radiance in each cone times the albedo) weighted as the gather
/// with `--cosine-cones` weighs them (the cone along the normal 1/4, each of the five in
/// the ring 3/20).
fn exact_cosine_cones(name: &str) -> (Vec<f64>, Vec<f64>) {
    let shared = shared();
    let scene = shared.join("reference/cornell_point.scene.json");
    let dir = temp_dir(name);
    let direct = shared.join("reference/cornell_point_direct.exr");
    render_path(
        &scene,
        &["--size", "256x256", "--spp", "512", "--max-depth", "3"],
        &dir.join("one.exr"),
    );
    let one = block_indirect(&dir.join("one.exr"), &direct);
    let mut cones = vec![0.0; one.len()];
    for k in 0..6 {
        let out = dir.join(format!("cone{k}.exr"));
        let image = render_path(
            &scene,
            &[
                "--size",
                "256x256",
                "--spp",
                "128",
                "--max-depth",
                "3",
                "--cosine-cones",
                "--cone",
                &k.to_string(),
            ],
            &out,
        );
        let weight = if k == 0 { 0.25 } else { 0.15 };
        for (sum, block) in cones.iter_mut().zip(block_sums(&image)) {
            *sum += weight * block;
        }
    }
    (cones, one)
}

/// The cone set's quadrature, with every cone exact, gives the path tracer's one bounce
/// over the Cornell view within 2 % and per block within 17 % (measured 1.004, 0.855 to
/// 1.06). Each cone's plain mean, weighted 1 : 1/2 as the default gather weighs them,
/// gives 0.968 and 0.89 to 1.39: it weighs a cone's grazing side, where the floor lies
/// for the short block's front face, as much as the side towards the normal. An analysis
/// of the ring's `--cosine-cones` quadrature, not of a tracer: its seven path-traced
/// images take five minutes of CI's thirty, so it runs with `--ignored`.
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "analysis of the ring's quadrature, about 5 minutes: passes (1.004, blocks 0.855 to 1.06)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn exact_cosine_cones_integrate_the_first_bounce() {
    let (cones, one) = exact_cosine_cones("components_cosine_quadrature");
    let total = cones.iter().sum::<f64>() / one.iter().sum::<f64>();
    let worst = block_ratios(&cones, &one)
        .iter()
        .map(|(_, r)| (r - 1.0).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "exact cosine cones over the one bounce: total {total:.3}, worst block off by {worst:.3}"
    );
    assert!((total - 1.0).abs() <= 0.02, "total {total}");
    assert!(worst <= 0.17, "a block off by {worst}");
}

/// The cone set itself, with every cone exact, gives the path tracer's one bounce per
/// block within 10 %. Where it does not, a tracer whose cones read exactly these discs
/// cannot pass `one_bounce_per_block_matches_the_path_tracer` either.
#[test]
#[cfg_attr(
    voxcone_shared,
    ignore = "issue 20: 61 of the 64 blocks within 10 %, from 0.85 to 1.06 (54, from 0.89 to 1.39, with the default's plain means)"
)]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn exact_cones_weighted_as_the_gather_give_the_first_bounce_per_block() {
    let (cones, one) = exact_cosine_cones("components_exact_cones");
    let total = |v: &[f64]| v.iter().sum::<f64>();
    eprintln!(
        "exact cones over the one bounce: total {:.3}",
        total(&cones) / total(&one)
    );
    assert_blocks_within_10_percent("exact cones over the one bounce", &cones, &one);
}

/// The voxels' direct light on a plane turned off the axes, against the same plane along
/// them (analytic: ρ/π × 3 W/m², lit along its normal either way): a 4 x 4 plane (albedo
/// 0.8) turned 45 degrees to two axes and one turned 55 degrees to all three, each lit by
/// a sun along its normal, their base voxels seen along the normal (`--debug-view
/// voxel-radiance`, one bounce: the voxels' direct light alone), within 2 % of a plane
/// along the axes, on the dense grid and the octree at 64³. Before session 40 the
/// shadow lookup moved a voxel's centre half a voxel out, which left most of a turned
/// plane's centres behind it, in its own shadow, and the per-axis weighting of the
/// light (Villegas) took a single turned plane for a mixture of axis faces: 0.050 and 0.503
/// of the plane along the axes at 45 and 55 degrees (0.707 and 0.577 with the first
/// fixed, 1.000 and 0.998 with both).
#[test]
fn turned_planes_light_their_voxels_as_planes_along_the_axes() {
    let dir = temp_dir("components_turned_planes");
    write(&dir, "plane.mtl", "newmtl plane\nKd 0.8 0.8 0.8\n");
    // A 4 x 4 square through the origin with unit normal n, lit and seen along n (the
    // camera's up along one of its sides).
    let square = |name: &str, n: [f32; 3]| {
        let n = glam::Vec3::from(n).normalize();
        let u = n.any_orthonormal_vector() * 2.0;
        let v = n.cross(u);
        let corners = [u + v, -u + v, -u - v, u - v];
        let mut obj = String::from("mtllib plane.mtl\n");
        for c in corners {
            obj += &format!("v {} {} {}\n", c.x, c.y, c.z);
        }
        obj += "usemtl plane\nf 1 2 3 4\n";
        write(&dir, &format!("{name}.obj"), &obj);
        let eye = n * 3.0;
        let travel = -n;
        write(
            &dir,
            &format!("{name}.toml"),
            &format!(
                "[camera]\nposition = [{}, {}, {}]\ntarget = [0, 0, 0]\nup = [{}, {}, {}]\n\
                 fov_y_deg = 20\n\
                 [[mesh]]\npath = \"{name}.obj\"\n\
                 [[light]]\nkind = \"directional\"\ndirection = [{}, {}, {}]\n\
                 irradiance = [3, 3, 3]\n",
                eye.x, eye.y, eye.z, u.x, u.y, u.z, travel.x, travel.y, travel.z
            ),
        )
    };
    let planes = [
        ("along", [0.0, 1.0, 0.0]),
        ("turned_45", [-1.0, 1.0, 0.0]),
        ("turned_55", [1.0, 1.0, 1.0]),
    ];
    for gi in ["dense", "octree"] {
        let mut light = Vec::new();
        for (name, n) in planes {
            let scene = square(name, n);
            let out = dir.join(format!("{name}_{gi}.exr"));
            render(
                &scene,
                &[
                    "--gi",
                    gi,
                    "--voxels",
                    "64",
                    "--size",
                    "32x32",
                    "--bounces",
                    "1",
                    "--debug-view",
                    "voxel-radiance",
                ],
                &out,
            );
            light.push(centre(&out));
        }
        eprintln!(
            "{gi}: voxels' light along the axes {:.4} (analytic {:.4}), turned 45° {:.4}, \
             turned 55° {:.4}",
            light[0],
            2.4 / std::f32::consts::PI,
            light[1],
            light[2]
        );
        for (turned, name) in light[1..].iter().zip(["45", "55"]) {
            assert!(
                (turned / light[0] - 1.0).abs() <= 0.02,
                "{gi}: the plane turned {name}° takes {turned}, the plane along the axes {}",
                light[0]
            );
        }
    }
}
