//! glTF fixtures written by the tests: the JSON document by `serde_json::json!`, its
//! binary buffer packed here, as a `.gltf` + `.bin` pair or as one `.glb`.

use std::f32::consts::{FRAC_1_SQRT_2 as H, FRAC_PI_2};
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use super::super::testing::{error_text, shared_file, TempDir};
use super::super::{Scene, Texture};
use super::*;

/// A document's buffer views and accessors, and the one buffer behind them.
#[derive(Default)]
struct Fixture {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Fixture {
    fn view(&mut self, bytes: &[u8]) -> usize {
        while self.bin.len() % 4 != 0 {
            self.bin.push(0);
        }
        self.views.push(json!({
            "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()
        }));
        self.bin.extend_from_slice(bytes);
        self.views.len() - 1
    }

    /// Float vectors of `width` components (`VEC2`/`VEC3`).
    fn floats(&mut self, data: &[f32], width: usize) -> usize {
        let view = self.view(bytemuck::cast_slice(data));
        let ty = ["SCALAR", "VEC2", "VEC3"][width - 1];
        let mut accessor = json!({
            "bufferView": view, "componentType": 5126, "count": data.len() / width, "type": ty
        });
        if width == 3 {
            let axis =
                |k: usize, f: fn(f32, f32) -> f32| data.chunks(3).map(|v| v[k]).fold(data[k], f);
            accessor["min"] = json!([axis(0, f32::min), axis(1, f32::min), axis(2, f32::min)]);
            accessor["max"] = json!([axis(0, f32::max), axis(1, f32::max), axis(2, f32::max)]);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn indices(&mut self, data: &[u32]) -> usize {
        let view = self.view(bytemuck::cast_slice(data));
        self.accessors.push(json!({
            "bufferView": view, "componentType": 5125, "count": data.len(), "type": "SCALAR"
        }));
        self.accessors.len() - 1
    }

    /// The unit quad in z = 0 (counter-clockwise from +Z), uv (0, 0) at the corner (0, 1),
    /// as an indexed primitive of `material`.
    fn quad(&mut self, material: Option<usize>) -> Value {
        let positions = self.floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.], 3);
        let uvs = self.floats(&[0., 1., 1., 1., 1., 0., 0., 0.], 2);
        let indices = self.indices(&[0, 1, 2, 0, 2, 3]);
        let mut primitive = json!({
            "attributes": {"POSITION": positions, "TEXCOORD_0": uvs}, "indices": indices
        });
        if let Some(m) = material {
            primitive["material"] = json!(m);
        }
        primitive
    }

    /// `doc` with the buffers, views and accessors filled in, the buffer at `uri` (or the
    /// `.glb`'s own with `None`).
    fn document(&self, mut doc: Value, uri: Option<&str>) -> Value {
        doc["asset"] = json!({"version": "2.0"});
        doc["bufferViews"] = json!(self.views);
        doc["accessors"] = json!(self.accessors);
        let mut buffer = json!({"byteLength": self.bin.len()});
        if let Some(uri) = uri {
            buffer["uri"] = json!(uri);
        }
        doc["buffers"] = json!([buffer]);
        doc
    }

    /// `name.gltf` and `name.bin` in `dir`.
    fn write_gltf(&self, dir: &Path, name: &str, doc: Value) -> PathBuf {
        let bin = format!("{name}.bin");
        std::fs::write(dir.join(&bin), &self.bin).unwrap();
        let path = dir.join(format!("{name}.gltf"));
        let doc = self.document(doc, Some(&bin));
        std::fs::write(&path, serde_json::to_string_pretty(&doc).unwrap()).unwrap();
        path
    }

    /// `name.glb` in `dir`: the JSON chunk, then the buffer as the BIN chunk.
    fn write_glb(&self, dir: &Path, name: &str, doc: Value) -> PathBuf {
        let mut json = serde_json::to_vec(&self.document(doc, None)).unwrap();
        while json.len() % 4 != 0 {
            json.push(b' ');
        }
        let mut bin = self.bin.clone();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        let mut glb = Vec::new();
        let total = 12 + 8 + json.len() + 8 + bin.len();
        for word in [
            0x4654_6c67u32,
            2,
            total as u32,
            json.len() as u32,
            0x4e4f_534a,
        ] {
            glb.extend_from_slice(&word.to_le_bytes());
        }
        glb.extend_from_slice(&json);
        for word in [bin.len() as u32, 0x004e_4942] {
            glb.extend_from_slice(&word.to_le_bytes());
        }
        glb.extend_from_slice(&bin);
        let path = dir.join(format!("{name}.glb"));
        std::fs::write(&path, glb).unwrap();
        path
    }
}

fn png(rgba: [u8; 4]) -> Vec<u8> {
    let mut bytes = Vec::new();
    image::RgbaImage::from_pixel(2, 2, image::Rgba(rgba))
        .write_to(
            &mut std::io::Cursor::new(&mut bytes),
            image::ImageFormat::Png,
        )
        .unwrap();
    bytes
}

fn load(path: &Path) -> Result<(Geometry, FileSetup)> {
    load_with(path, &LoadOptions::default())
}

fn load_with(path: &Path, options: &LoadOptions) -> Result<(Geometry, FileSetup)> {
    let mut geometry = Geometry::default();
    let setup = geometry.add(&MeshEntry::bare(path), options)?;
    Ok((geometry, setup))
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).abs().max_element() < 1e-5
}

#[test]
fn node_hierarchy_materials_texture_transform_camera_and_lights() {
    let dir = TempDir::new("gltf-full");
    std::fs::write(dir.0.join("albedo.png"), png([255, 128, 0, 255])).unwrap();
    let mut f = Fixture::default();
    let quad = f.quad(Some(0));
    let transform = json!({"offset": [0.5, 0.25], "rotation": FRAC_PI_2, "scale": [2.0, 3.0]});
    let doc = json!({
        "extensionsUsed": ["KHR_lights_punctual", "KHR_texture_transform",
                           "KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 3]}],
        "nodes": [
            {"translation": [1.0, 2.0, 3.0], "scale": [2.0, 2.0, 2.0], "children": [1, 2, 4, 5]},
            // 90 degrees about +Y: +X goes to -Z, +Z to +X.
            {"rotation": [0.0, H, 0.0, H], "mesh": 0},
            {"extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,1,5,1], "camera": 1},
            // A light looking down: -Z turned to -Y by -90 degrees about X.
            {"rotation": [-H, 0.0, 0.0, H],
             "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"rotation": [-H, 0.0, 0.0, H], "camera": 0,
             "extensions": {"KHR_lights_punctual": {"light": 2}}},
        ],
        "cameras": [
            {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
            {"type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.1}},
        ],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 0.5, 0.25], "intensity": 683.0},
            {"type": "spot", "intensity": 1366.0,
             "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
            {"type": "directional", "intensity": 5464.0},
        ]}},
        "meshes": [{"primitives": [quad]}],
        "materials": [{
            "pbrMetallicRoughness": {
                "baseColorFactor": [0.5, 0.6, 0.7, 1.0],
                "baseColorTexture": {"index": 0,
                                     "extensions": {"KHR_texture_transform": transform}},
                "metallicFactor": 0.25, "roughnessFactor": 0.5
            },
            "emissiveFactor": [1.0, 2.0, 3.0],
            "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}},
            "emissiveTexture": {"index": 0,
                                "extensions": {"KHR_texture_transform": transform}},
            "normalTexture": {"index": 0, "scale": 0.5,
                              "extensions": {"KHR_texture_transform": transform}}
        }],
        "textures": [{"source": 0}],
        "images": [{"uri": "albedo.png"}],
    });
    let path = f.write_gltf(&dir.0, "full", doc);
    let (geometry, setup) = load(&path).unwrap();

    assert_eq!(geometry.meshes.len(), 1);
    let mesh = &geometry.meshes[0];
    // (x, y, 0) -> rotate about Y -> (0, y, -x) -> scale 2 -> translate (1, 2, 3).
    let world = |x: f32, y: f32| Vec3::new(1.0, 2.0 + 2.0 * y, 3.0 - 2.0 * x);
    let corners: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| Vec3::from(v.position))
        .collect();
    for expected in [world(0., 0.), world(1., 0.), world(1., 1.), world(0., 1.)] {
        assert!(
            corners.iter().any(|&c| close(c, expected)),
            "{expected} in {corners:?}"
        );
    }
    for v in &mesh.vertices {
        assert!(
            close(Vec3::from(v.normal), Vec3::X),
            "flat normal +Z turned to +X"
        );
        // KHR_texture_transform: scale, rotate, offset.
        let (u, w) = match (v.position[2] < 2.0, v.position[1] > 3.0) {
            (false, false) => (0.0, 1.0),
            (true, false) => (1.0, 1.0),
            (true, true) => (1.0, 0.0),
            (false, true) => (0.0, 0.0),
        };
        let s = Vec2::new(2.0 * u, 3.0 * w);
        let expected = Vec2::new(0.5 + s.y, 0.25 - s.x);
        assert!(
            (Vec2::from(v.uv) - expected).abs().max_element() < 1e-5,
            "{:?} for ({u}, {w})",
            v.uv
        );
    }
    assert_eq!(mesh.transform, Mat4::IDENTITY);

    let m = &geometry.materials[mesh.material as usize];
    assert!(
        close(m.albedo, Vec3::new(0.5, 0.6, 0.7) * 0.75),
        "{}",
        m.albedo
    );
    assert!(close(
        m.specular,
        Vec3::splat(0.04).lerp(Vec3::new(0.5, 0.6, 0.7), 0.25)
    ));
    assert!((m.roughness - 0.25).abs() < 1e-6, "perceptual 0.5 squared");
    assert!(
        close(m.emission, Vec3::new(4.0, 8.0, 12.0)),
        "factor x strength"
    );
    assert!(m.albedo_texture.is_some() && m.emission_texture.is_some());
    assert_eq!(
        m.albedo_texture, m.emission_texture,
        "one image, one sRGB texture"
    );
    // The same image as a normal map scaled by one half: a texture of its own.
    assert!(m.normal_texture.is_some() && m.normal_texture != m.albedo_texture);
    assert_eq!((m.dissolve, m.coverage_texture), (1.0, None));

    // Camera 0 (the first by index), on the node looking down.
    let camera = setup.camera.unwrap();
    assert!((camera.fov_y_deg - 0.5f32.to_degrees()).abs() < 1e-4);
    assert!(close(camera.position, Vec3::new(1.0, 2.0, 3.0)));
    assert!(close(camera.forward(), Vec3::NEG_Y), "{}", camera.forward());

    assert_eq!(setup.lights.len(), 3);
    let point = setup
        .lights
        .iter()
        .find(|l| l.kind == LightKind::Point)
        .unwrap();
    assert!(
        close(point.intensity, Vec3::new(1.0, 0.5, 0.25)),
        "683 cd = 1 W/sr"
    );
    assert!(close(point.position, Vec3::new(1.0, 2.0, 3.0)));
    let spot = setup
        .lights
        .iter()
        .find_map(|l| match l.kind {
            LightKind::Spot {
                direction,
                inner_deg,
                outer_deg,
            } => Some((l.intensity, direction, inner_deg, outer_deg)),
            _ => None,
        })
        .unwrap();
    assert!(close(spot.0, Vec3::splat(2.0)));
    assert!(close(spot.1, Vec3::NEG_Y), "{}", spot.1);
    assert!((spot.2 - 0.2f32.to_degrees()).abs() < 1e-4);
    assert!((spot.3 - 0.6f32.to_degrees()).abs() < 1e-4);
    let sun = setup
        .lights
        .iter()
        .find_map(|l| match l.kind {
            LightKind::Directional { direction } => Some((l.intensity, direction)),
            _ => None,
        })
        .unwrap();
    assert!(close(sun.0, Vec3::splat(8.0)), "5464 lx = 8 W/m^2");
    assert!(close(sun.1, Vec3::NEG_Y));
}

#[test]
fn alpha_modes_become_cutouts_and_transmission() {
    let dir = TempDir::new("gltf-alpha");
    std::fs::write(dir.0.join("leaf.png"), png([10, 200, 10, 100])).unwrap();
    let mut f = Fixture::default();
    let primitives: Vec<Value> = (0..4).map(|m| f.quad(Some(m))).collect();
    let textured = json!({"index": 0});
    let doc = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": primitives}],
        "materials": [
            {"alphaMode": "MASK", "alphaCutoff": 0.3,
             "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8], "baseColorTexture": textured}},
            {"alphaMode": "MASK", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.2]}},
            {"alphaMode": "BLEND", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.4]}},
            {"alphaMode": "OPAQUE", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.1]}},
        ],
        "textures": [{"source": 0}],
        "images": [{"uri": "leaf.png"}],
    });
    let path = f.write_gltf(&dir.0, "alpha", doc);
    let (geometry, _) = load(&path).unwrap();
    assert_eq!(
        geometry.meshes.len(),
        3,
        "the MASK primitive below its cutoff is not drawn"
    );
    let material = |i: usize| geometry.materials[geometry.meshes[i].material as usize].clone();
    let mask = material(0);
    assert_eq!(mask.dissolve, 1.0);
    let blend = material(1);
    assert_eq!((blend.dissolve, blend.coverage_texture), (0.4, None));
    let opaque = material(2);
    assert_eq!((opaque.dissolve, opaque.coverage_texture), (1.0, None));

    let (_, _, textures) = geometry.finish().unwrap();
    let coverage = &textures[mask.coverage_texture.unwrap() as usize];
    assert_eq!(coverage.kind, TextureKind::Coverage);
    // alpha 100 / 255 x 0.8 = 0.314, just above the cutoff 0.3: kept.
    let c = coverage.mips[0][0] as f32 / 255.0;
    assert!((0.5..0.55).contains(&c), "{c}");
}

#[test]
fn glb_with_embedded_image_strips_fans_and_mirroring() {
    let dir = TempDir::new("gltf-glb");
    let mut f = Fixture::default();
    let image_view = f.view(&png([0, 255, 0, 255]));
    let quad = f.quad(Some(0));
    // The same quad as a strip (0 1 3 2) and as a fan (0 1 2 3), not indexed.
    let strip = f.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.], 3);
    let fan = f.floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.], 3);
    let lines = f.floats(&[0., 0., 0., 1., 0., 0.], 3);
    let doc = json!({
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"mesh": 0, "scale": [-1.0, 1.0, 1.0]}],
        "meshes": [{"primitives": [
            quad,
            {"attributes": {"POSITION": strip}, "mode": 5},
            {"attributes": {"POSITION": fan}, "mode": 6},
            {"attributes": {"POSITION": lines}, "mode": 1},
        ]}],
        "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        "textures": [{"source": 0}],
        "images": [{"bufferView": image_view, "mimeType": "image/png"}],
    });
    let path = f.write_glb(&dir.0, "embedded", doc);
    let (geometry, setup) = load(&path).unwrap();
    assert!(setup.camera.is_none() && setup.lights.is_empty());
    assert_eq!(
        geometry.meshes.len(),
        6,
        "three surfaces on two nodes; lines skipped"
    );
    for mesh in &geometry.meshes {
        assert_eq!(mesh.indices.len(), 6, "{}", mesh.name);
        for v in &mesh.vertices {
            // Front faces stay front faces under the mirror.
            assert!(
                close(Vec3::from(v.normal), Vec3::Z),
                "{}: {:?}",
                mesh.name,
                v.normal
            );
        }
    }
    let mirrored = geometry
        .meshes
        .iter()
        .filter(|m| m.local_bounds.min.x < -0.5)
        .count();
    assert_eq!(mirrored, 3);
    let albedo = geometry.materials[geometry.meshes[0].material as usize].albedo_texture;
    let (_, _, textures) = geometry.finish().unwrap();
    let texture: &Texture = &textures[albedo.unwrap() as usize];
    assert_eq!((texture.width, texture.height), (2, 2));
    assert_eq!(texture.mips[0][..4], [0, 255, 0, 255]);
    assert!(texture
        .path
        .to_string_lossy()
        .ends_with("embedded.glb#image0"));
}

/// TEXCOORD_1 becomes the mesh's lightmap UVs, vertex for vertex (without
/// `KHR_texture_transform`, which is the textures'); a primitive without it has none.
#[test]
fn the_second_uv_set_is_the_lightmap_uvs() {
    let dir = TempDir::new("gltf-uv1");
    let mut f = Fixture::default();
    let mut with = f.quad(None);
    let second = [0.1f32, 0.2, 0.4, 0.2, 0.4, 0.6, 0.1, 0.6];
    with["attributes"]["TEXCOORD_1"] = json!(f.floats(&second, 2));
    let without = f.quad(None);
    let doc = json!({
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [with, without]}],
    });
    let path = f.write_gltf(&dir.0, "uv1", doc);
    let (geometry, _) = load(&path).unwrap();
    let [a, b] = &geometry.meshes[..] else {
        panic!("{} meshes", geometry.meshes.len());
    };
    // Without normals each corner gets a vertex of its own (flat shading), in the
    // indices' order 0 1 2 0 2 3.
    let expected: Vec<[f32; 2]> = [0, 1, 2, 0, 2, 3]
        .map(|i| [second[2 * i], second[2 * i + 1]])
        .to_vec();
    assert_eq!(a.lightmap_uvs, expected);
    assert_eq!(a.lightmap_uvs.len(), a.vertices.len());
    assert!(b.lightmap_uvs.is_empty());
}

#[test]
fn bad_files_name_the_file_and_the_cause() {
    let dir = TempDir::new("gltf-bad");
    type Writer = Box<dyn Fn(&Path) -> PathBuf>;
    let cases: Vec<(&str, Writer, &str)> = vec![
        (
            "broken.gltf",
            Box::new(|d: &Path| {
                std::fs::write(d.join("broken.gltf"), "{\"asset\": ").unwrap();
                d.join("broken.gltf")
            }),
            "cannot parse",
        ),
        (
            "nobin.gltf",
            Box::new(|d: &Path| {
                let mut f = Fixture::default();
                let quad = f.quad(None);
                let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                                 "meshes": [{"primitives": [quad]}]});
                let path = f.write_gltf(d, "nobin", doc);
                std::fs::remove_file(d.join("nobin.bin")).unwrap();
                path
            }),
            "nobin.bin) not found",
        ),
        (
            "notexture.gltf",
            Box::new(|d: &Path| {
                let mut f = Fixture::default();
                let quad = f.quad(Some(0));
                let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                    "meshes": [{"primitives": [quad]}],
                    "materials": [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
                    "textures": [{"source": 0}], "images": [{"uri": "absent.png"}]});
                f.write_gltf(d, "notexture", doc)
            }),
            "absent.png) not found",
        ),
        (
            "draco.gltf",
            Box::new(|d: &Path| {
                let mut f = Fixture::default();
                let quad = f.quad(None);
                let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                    "meshes": [{"primitives": [quad]}],
                    "extensionsUsed": ["KHR_draco_mesh_compression"],
                    "extensionsRequired": ["KHR_draco_mesh_compression"]});
                f.write_gltf(d, "draco", doc)
            }),
            "requires extension KHR_draco_mesh_compression",
        ),
        (
            "range.gltf",
            Box::new(|d: &Path| {
                let mut f = Fixture::default();
                let quad = f.quad(None);
                f.accessors[0]["count"] = json!(400);
                let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                                 "meshes": [{"primitives": [quad]}]});
                f.write_gltf(d, "range", doc)
            }),
            "accessor 0: its 400 elements end at byte",
        ),
        (
            "index.gltf",
            Box::new(|d: &Path| {
                let mut f = Fixture::default();
                let positions = f.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], 3);
                let indices = f.indices(&[0, 1, 7]);
                let doc = json!({"scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                    "meshes": [{"primitives": [{"attributes": {"POSITION": positions},
                                                "indices": indices}]}]});
                f.write_gltf(d, "index", doc)
            }),
            "indexes a vertex that does not exist",
        ),
        (
            "cycle.gltf",
            Box::new(|d: &Path| {
                let mut f = Fixture::default();
                let quad = f.quad(None);
                let doc = json!({"scenes": [{"nodes": [0]}],
                    "nodes": [{"mesh": 0, "children": [1]}, {"children": [0]}],
                    "meshes": [{"primitives": [quad]}]});
                f.write_gltf(d, "cycle", doc)
            }),
            "must be a tree",
        ),
    ];
    for (name, write, cause) in cases {
        let path = write(&dir.0);
        let message = error_text(load(&path));
        assert!(message.contains(name), "{name}: {message}");
        assert!(message.contains(cause), "{name}: {message}");
    }
}

/// The shared glTF Cornell box is the OBJ's geometry, light and camera.
#[test]
#[cfg_attr(not(voxcone_shared), ignore = "needs ../shared")]
fn cornell_point_gltf_matches_the_obj() {
    let gltf = Scene::load(
        &shared_file("scenes/gltf/cornell_point.gltf"),
        &LoadOptions::REFERENCE,
    )
    .unwrap();
    let obj = Scene::load(
        &shared_file("reference/cornell_point.scene.json"),
        &LoadOptions::REFERENCE,
    )
    .unwrap();
    assert_eq!(gltf.triangle_count, obj.triangle_count);
    assert_eq!(gltf.bounds(0.0), obj.bounds(0.0));
    assert!(close(gltf.camera.position, obj.camera.position));
    assert!(close(gltf.camera.forward(), obj.camera.forward()));
    assert!((gltf.camera.fov_y_deg - obj.camera.fov_y_deg).abs() < 1e-3);
    assert_eq!(gltf.lights.len(), 1);
    assert!(close(gltf.lights[0].position, obj.lights[0].position));
    assert!(
        (gltf.lights[0].intensity - obj.lights[0].intensity)
            .abs()
            .max_element()
            < 1e-3
    );
    // The same albedo per triangle area.
    let albedo_area = |s: &Scene| -> Vec3 {
        s.meshes
            .iter()
            .map(|m| {
                let area: f32 = m
                    .indices
                    .chunks(3)
                    .map(|t| {
                        let p: Vec<Vec3> = t
                            .iter()
                            .map(|&i| Vec3::from(m.vertices[i as usize].position))
                            .collect();
                        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
                    })
                    .sum();
                s.materials[m.material as usize].albedo * area
            })
            .sum()
    };
    assert!(close(albedo_area(&gltf), albedo_area(&obj)));
}
