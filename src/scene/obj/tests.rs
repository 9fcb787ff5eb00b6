use std::time::Instant;

use super::super::testing::{error_text, shared_dir, write_quad, TempDir};
use super::super::{Aabb, Scene, Texture, Vertex};
use super::*;

fn load(path: &Path, options: &LoadOptions) -> Result<(Vec<Mesh>, Vec<Material>, Vec<Texture>)> {
    let mut geometry = Geometry::default();
    geometry.add(&MeshEntry::bare(path), options)?;
    geometry.finish()
}

/// The MTL format's one-value colours (`Kd r`: g and b equal r), on which tobj panics.
#[test]
fn one_value_colours_are_grey() {
    let dir = TempDir::new("grey");
    dir.write("g.mtl", "newmtl grey\nKd 0.25\nKa 1\nKs 0.5\nKe 2\n");
    let obj = dir.write(
        "g.obj",
        "mtllib g.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl grey\nf 1 2 3\n",
    );
    let (_, materials, _) = load(&obj, &LoadOptions::default()).unwrap();
    assert_eq!(materials[0].albedo, Vec3::splat(0.25));
    assert_eq!(materials[0].emission, Vec3::splat(2.0));
}

#[test]
fn quad_materials_uvs_and_flat_normals() {
    let dir = TempDir::new("quad");
    let obj = write_quad(&dir.0);
    let (meshes, materials, textures) = load(&obj, &LoadOptions::default()).unwrap();
    assert_eq!(meshes.len(), 1);
    let mesh = &meshes[0];
    assert_eq!(mesh.indices.len(), 6);
    for v in &mesh.vertices {
        assert_eq!(v.normal, [0.0, 0.0, 1.0], "counter-clockwise seen from +Z");
        // OBJ v = 0 at the bottom of the image becomes row coordinate 1.
        assert_eq!(v.uv[1], 1.0 - v.position[1]);
    }
    let lamp = &materials[mesh.material as usize];
    assert_eq!(lamp.albedo, Vec3::splat(0.5));
    assert_eq!(lamp.emission, Vec3::new(2.0, 3.0, 4.0));
    assert_eq!(lamp.ior, 1.5);
    assert_eq!(lamp.dissolve, 0.75, "Tr = 1 - d");
    assert!((lamp.roughness - 0.02f32.sqrt()).abs() < 1e-6);
    assert_eq!(textures.len(), 2, "same file as map_Kd and map_d");
    assert_eq!(
        textures[lamp.albedo_texture.unwrap() as usize].kind,
        TextureKind::Albedo
    );
    assert_eq!(
        textures[lamp.coverage_texture.unwrap() as usize].kind,
        TextureKind::Coverage
    );
    assert_eq!(std::mem::size_of::<Vertex>(), 32);
}

#[test]
fn groups_without_material_share_one_grey() {
    let dir = TempDir::new("grey");
    let obj = dir.write(
        "two.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nvn 0 0 2\nvn 0 0 2\n\
         o a\nf 1//1 2//2 3//3\no b\nf 3//3 2//2 1//1\n",
    );
    let (meshes, materials, _) = load(&obj, &LoadOptions::default()).unwrap();
    assert_eq!(meshes.len(), 2);
    assert_eq!(materials, vec![Material::default_grey()]);
    assert!(meshes.iter().all(|m| m.material == 0));
    assert_eq!(
        meshes[0].vertices[0].normal,
        [0.0, 0.0, 1.0],
        "file normals, normalised"
    );
    assert_eq!(
        meshes[0].vertices.len(),
        3,
        "shared vertices when the file has normals"
    );
}

#[test]
fn zero_area_triangles_are_dropped() {
    let dir = TempDir::new("degenerate");
    let obj = dir.write(
        "d.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\no flat\nf 1 4 2\n",
    );
    let (meshes, _, _) = load(&obj, &LoadOptions::default()).unwrap();
    assert_eq!(
        meshes.len(),
        1,
        "the model of only a zero-area triangle is gone"
    );
    assert_eq!(meshes[0].indices.len(), 3);
    assert_eq!(meshes[0].local_bounds.max, Vec3::new(1.0, 1.0, 0.0));
}

#[test]
fn normal_maps_and_height_maps() {
    let dir = TempDir::new("bump");
    for name in ["h.png", "wall_nrm.png", "n.png"] {
        image::RgbaImage::new(1, 1).save(dir.0.join(name)).unwrap();
    }
    dir.write(
        "m.mtl",
        "newmtl height\nbump -bm 0.5 h.png\nnewmtl bump\nmap_Bump wall_nrm.png\n\
         newmtl norm\nnorm n.png\nmap_Bump h.png\n",
    );
    let obj = dir.write(
        "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl height\nf 1 2 3\n",
    );
    let (_, materials, textures) = load(&obj, &LoadOptions::default()).unwrap();
    assert_eq!(materials[0].normal_texture, None, "height maps are ignored");
    let file = |m: &Material| textures[m.normal_texture.unwrap() as usize].path.clone();
    assert!(file(&materials[1]).ends_with("wall_nrm.png"));
    assert!(file(&materials[2]).ends_with("n.png"));
    let options = LoadOptions {
        no_normal_maps: true,
        diffuse_only: true,
        no_refraction: true,
    };
    let (_, materials, textures) = load(&obj, &options).unwrap();
    assert!(textures.is_empty() && materials.iter().all(|m| m.normal_texture.is_none()));
}

#[test]
fn errors_name_the_file() {
    let dir = TempDir::new("errors");
    let message = error_text(load(&dir.0.join("absent.obj"), &LoadOptions::default()));
    assert!(message.contains("absent.obj"), "{message}");

    let bad = dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 zz\n");
    let message = error_text(load(&bad, &LoadOptions::default()));
    assert!(
        message.contains("bad.obj") && message.contains("parse"),
        "{message}"
    );

    let infinite = dir.write("inf.obj", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n");
    let message = error_text(load(&infinite, &LoadOptions::default()));
    assert!(
        message.contains("inf.obj") && message.contains("finite"),
        "{message}"
    );

    let no_mtl = dir.write(
        "m.obj",
        "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let message = error_text(load(&no_mtl, &LoadOptions::default()));
    assert!(
        message.contains("nowhere.mtl") && message.contains("not found"),
        "{message}"
    );

    dir.write("broken.mtl", "newmtl x\nKd 1 one 1\n");
    let broken = dir.write(
        "b.obj",
        "mtllib broken.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let message = error_text(load(&broken, &LoadOptions::default()));
    assert!(
        message.contains("broken.mtl") && message.contains("parse"),
        "{message}"
    );

    for (line, expected) in [
        ("Kd 0.5 0.5", "not two"),
        ("Kd nan", "Kd NaN is not a finite number"),
        ("Kd inf 0 0", "Kd inf is not a finite number"),
        ("Ke -10", "Ke -10 is not a finite number"),
        ("Ns -1", "Ns -1 is not a finite number"),
    ] {
        dir.write("bad.mtl", &format!("newmtl x\n{line}\n"));
        let bad = dir.write(
            "bad.obj",
            "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        );
        let message = error_text(load(&bad, &LoadOptions::default()));
        assert!(
            message.contains("bad.mtl") && message.contains("line 2") && message.contains(expected),
            "{line}: {message}"
        );
    }

    dir.write("t.mtl", "newmtl brick\nmap_Kd gone.png\n");
    let texture = dir.write(
        "t.obj",
        "mtllib t.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl brick\nf 1 2 3\n",
    );
    let message = error_text(load(&texture, &LoadOptions::default()));
    for needle in ["gone.png", "brick", "not found", "t.obj"] {
        assert!(message.contains(needle), "{message} lacks {needle}");
    }

    std::fs::write(dir.0.join("junk.png"), b"not a png").unwrap();
    dir.write("j.mtl", "newmtl junk\nmap_Kd junk.png\n");
    let junk = dir.write(
        "j.obj",
        "mtllib j.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl junk\nf 1 2 3\n",
    );
    let message = error_text(load(&junk, &LoadOptions::default()));
    assert!(
        message.contains("junk.png") && message.contains("\"junk\""),
        "{message}"
    );
}

#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn cornell_box() {
    let shared = shared_dir();
    let obj = shared.join("scenes/cornell_box/CornellBox-Original.obj");
    let (meshes, materials, textures) = load(&obj, &LoadOptions::default()).unwrap();
    let triangles: usize = meshes.iter().map(|m| m.indices.len() / 3).sum();
    assert_eq!(triangles, 36);
    assert_eq!(meshes.len(), 8);
    assert_eq!(materials.len(), 8);
    assert!(textures.is_empty());
    let bounds = meshes
        .iter()
        .fold(Aabb::EMPTY, |b, m| b.union(&m.local_bounds));
    assert!(
        bounds.min.abs_diff_eq(Vec3::new(-1.0, 0.0, -1.0), 0.05),
        "{bounds:?}"
    );
    assert!(
        bounds.max.abs_diff_eq(Vec3::new(1.0, 2.0, 1.0), 0.05),
        "{bounds:?}"
    );
    let light = materials.iter().find(|m| m.emission != Vec3::ZERO).unwrap();
    assert_eq!(light.emission, Vec3::new(17.0, 12.0, 4.0));
    // The floor faces up (into the box) by its winding.
    let floor = meshes.iter().find(|m| m.name == "floor").unwrap();
    assert!(floor.vertices.iter().all(|v| v.normal[1] > 0.99));
}

#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn sponza() {
    let shared = shared_dir();
    let obj = shared.join("scenes/crytek_sponza/sponza.obj");
    let start = Instant::now();
    let (meshes, materials, textures) = load(&obj, &LoadOptions::default()).unwrap();
    eprintln!(
        "sponza: {} meshes, {} materials, {} textures, loaded in {:.2} s",
        meshes.len(),
        materials.len(),
        textures.len(),
        start.elapsed().as_secs_f64()
    );
    let triangles: usize = meshes.iter().map(|m| m.indices.len() / 3).sum();
    assert!((260_000..265_000).contains(&triangles), "{triangles}");
    assert!(materials.len() >= 24);
    assert!(textures.iter().any(|t| t.kind == TextureKind::Coverage));
    assert!(textures.iter().any(|t| t.kind == TextureKind::Normal));
    for t in &textures {
        let levels = 32 - t.width.max(t.height).leading_zeros();
        assert_eq!(t.mips.len(), levels as usize, "{}", t.path.display());
        assert_eq!(t.mips.last().unwrap().len(), 4);
    }
    assert!(meshes
        .iter()
        .all(|m| (m.material as usize) < materials.len()));
}

/// A textured material's mean albedo is its Kd times its texture's mean (the quad's
/// texture is sRGB (255, 128, 0), linear (1, 0.216, 0), under Kd 0.5).
#[test]
fn material_albedo_takes_the_textures_mean() {
    let dir = TempDir::new("albedo");
    let quad = write_quad(&dir.0);
    let scene = Scene::load(&quad, &LoadOptions::default()).unwrap();
    let albedo = scene.material_albedo(scene.meshes[0].material);
    let want = Vec3::new(0.5, 0.5 * 0.2158605, 0.0);
    assert!((albedo - want).abs().max_element() < 1e-4, "{albedo}");
}
