//! glTF 2.0 scenes (`.gltf` with its buffers and images, or `.glb`) through the `gltf`
//! crate.
//!
//! - **Geometry**: the default scene's node hierarchy (TRS or matrix), baked into the
//!   vertices so that a file's meshes share one object space, as an OBJ's do (a node
//!   whose transform mirrors keeps its front faces by reversing the winding). Triangles,
//!   strips and fans, indexed or not; points and lines are skipped. Without normals a
//!   primitive gets flat ones, as the format prescribes.
//! - **Materials** (metallic-roughness): albedo = base colour x (1 - metallic), times the
//!   base colour texture; specular colour = mix(0.04, base colour factor, metallic) (the
//!   format's dielectric F0 of 0.04; metals take their colour from the factor, as
//!   voxcone's specular term has no texture); voxcone's roughness (the Beckmann slope
//!   `m`, see `Material::roughness`) = the glTF perceptual roughness squared, as in the
//!   format's GGX alpha. The metallic-roughness and occlusion textures are not used (the
//!   GI computes the occlusion).
//! - **Emission**: the emissive factor x `KHR_materials_emissive_strength`, in voxcone's
//!   radiance units (W/(m^2 sr), as MTL Ke), times the emissive texture.
//! - **Alpha**: `MASK` cuts out where base colour alpha x factor < `alphaCutoff`
//!   (`AlphaCutout`); `BLEND` becomes the transmission `d` = the factor's alpha, the
//!   texture's alpha a cut-out at one half.
//! - **Textures**: sRGB base colour and emissive, linear normal maps (the format's +Y up
//!   convention, as voxcone's OBJ normal maps; `scale` applied to the texels at load). `KHR_texture_transform` of the base colour
//!   texture (else the emissive, else the normal map) is baked into the vertices' one set
//!   of texture coordinates; a material whose textures differ in transform or set is
//!   loaded with a warning.
//! - **Cameras**: the first perspective camera of the file (by index) is the default view.
//! - **Lights** (`KHR_lights_punctual`): candela and lux are divided by 683 lm/W, the
//!   factor Blender's glTF importer uses, into W/sr and W/m^2. A spot's cone angles are
//!   `inner_deg`/`outer_deg`; `range` is not used (lights fall off with the inverse
//!   square only).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::{anyhow, bail, ensure, Context as _, Result};
use base64::Engine as _;
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use gltf::khr_lights_punctual::Kind as LightKindGltf;
use gltf::material::AlphaMode;
use gltf::mesh::Mode;

use super::file::folder;
use super::geometry::{
    model_geometry, FileSetup, Geometry, MeshEntry, ModelAttributes, ModelGeometry, TextureSource,
};
use super::{
    Adjust, AlphaCutout, Camera, Light, LightKind, LoadOptions, Material, Mesh, TextureKind,
};
use crate::progress::Progress;

/// Lumens per watt: glTF's photometric light units to voxcone's radiometric ones.
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The extensions whose content voxcone reads; a file that requires another is refused.
const SUPPORTED_EXTENSIONS: [&str; 3] = [
    "KHR_lights_punctual",
    "KHR_materials_emissive_strength",
    "KHR_texture_transform",
];

/// Reads the glTF of `entry` into `geometry`, with its first camera and its lights in
/// world space.
pub fn add(geometry: &mut Geometry, entry: &MeshEntry, options: &LoadOptions) -> Result<FileSetup> {
    let path = entry.path;
    load(geometry, entry, options).with_context(|| format!("in glTF {}", path.display()))
}

fn load(geometry: &mut Geometry, entry: &MeshEntry, options: &LoadOptions) -> Result<FileSetup> {
    let path = entry.path;
    let start = Instant::now();
    let bytes = std::fs::read(path).context("cannot read it")?;
    // Parsed before it is validated, so that an unsupported required extension is named
    // as such rather than as a validation error.
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| anyhow!("cannot parse it: {e}"))?;
    for required in document.extensions_required() {
        ensure!(
            SUPPORTED_EXTENSIONS.contains(&required),
            "it requires extension {required}, which voxcone does not support (supported: {})",
            SUPPORTED_EXTENSIONS.join(", ")
        );
    }
    let document = gltf::Document::from_json(document.into_json())
        .map_err(|e| anyhow!("it is not valid glTF 2.0: {e}"))?;
    let base = folder(path);
    let buffers = load_buffers(&document, base, blob)?;
    let mut file = GltfFile {
        path,
        base,
        buffers: &buffers,
        images: HashMap::new(),
        materials: HashMap::new(),
        options,
        emission_scale: entry.emission_scale,
    };

    let scene = document
        .default_scene()
        .or_else(|| document.scenes().next())
        .ok_or_else(|| anyhow!("it has no scene"))?;
    let mut visited = vec![false; document.nodes().count()];
    // Depth first in document order: each node's children are pushed in reverse.
    let mut stack: Vec<(gltf::Node, Mat4)> = scene.nodes().map(|n| (n, Mat4::IDENTITY)).collect();
    stack.reverse();
    let mut meshes = Vec::new();
    let mut camera: Option<(usize, Camera)> = None;
    let mut lights = Vec::new();
    let node_count = document.nodes().count() as u64;
    let progress = Progress::new("reading glTF nodes", node_count);
    while let Some((node, parent)) = stack.pop() {
        ensure!(
            !std::mem::replace(&mut visited[node.index()], true),
            "node {} is reached twice: the node hierarchy must be a tree",
            node.index()
        );
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        ensure!(
            world.is_finite(),
            "node {} has a transform that is not finite",
            node.index()
        );
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                let name = format!(
                    "{} (mesh {}, primitive {})",
                    mesh.name().unwrap_or("unnamed"),
                    mesh.index(),
                    primitive.index()
                );
                if let Some(m) = file
                    .primitive(geometry, &primitive, world, &name)
                    .with_context(|| format!("in {name}"))?
                {
                    meshes.push(Mesh {
                        transform: entry.transform,
                        animation: entry.animation,
                        ..m
                    });
                }
            }
        }
        if let Some(c) = node.camera() {
            if camera.as_ref().is_none_or(|(i, _)| c.index() < *i) {
                if let Some(view) = node_camera(&c, entry.transform * world)? {
                    camera = Some((c.index(), view));
                }
            }
        }
        if let Some(light) = node.light() {
            lights.push(
                node_light(&light, entry.transform * world)
                    .with_context(|| format!("in light {}", light.index()))?,
            );
        }
        let first_child = stack.len();
        stack.extend(node.children().map(|c| (c, world)));
        stack[first_child..].reverse();
        progress.advance();
    }
    progress.finish();
    let triangles: usize = meshes.iter().map(|m: &Mesh| m.indices.len() / 3).sum();
    log::info!(
        "loading {}: {triangles} triangles, {} materials, {} lights ({:.2} s)",
        path.file_name()
            .unwrap_or(path.as_os_str())
            .to_string_lossy(),
        file.materials.len(),
        lights.len(),
        start.elapsed().as_secs_f64()
    );
    geometry.push_entry_meshes(meshes);
    Ok(FileSetup {
        camera: camera.map(|(_, c)| c),
        lights,
    })
}

/// The file's buffers: the `.glb`'s own, external files (checked first, to name a missing
/// one) and data URIs.
fn load_buffers(
    document: &gltf::Document,
    base: &Path,
    blob: Option<Vec<u8>>,
) -> Result<Vec<gltf::buffer::Data>> {
    for buffer in document.buffers() {
        if let gltf::buffer::Source::Uri(uri) = buffer.source() {
            if !uri.starts_with("data:") {
                let file = base.join(uri_path(uri));
                ensure!(
                    file.is_file(),
                    "buffer {} ({uri}) not found: {}",
                    buffer.index(),
                    file.display()
                );
            }
        }
    }
    let buffers = gltf::import_buffers(document, Some(base), blob)
        .map_err(|e| anyhow!("cannot load its buffers: {e}"))?;
    for (buffer, data) in document.buffers().zip(&buffers) {
        ensure!(
            data.len() >= buffer.length(),
            "buffer {} holds {} bytes, {} declared",
            buffer.index(),
            data.len(),
            buffer.length()
        );
    }
    Ok(buffers)
}

/// The file a relative URI names (percent-decoded).
fn uri_path(uri: &str) -> PathBuf {
    PathBuf::from(
        urlencoding::decode(uri)
            .map(|s| s.into_owned())
            .unwrap_or_else(|_| uri.to_string()),
    )
}

/// What one file's loading keeps: its buffers and the voxcone indices of the images and
/// materials converted so far.
struct GltfFile<'a> {
    path: &'a Path,
    base: &'a Path,
    buffers: &'a [gltf::buffer::Data],
    images: HashMap<usize, TextureSource>,
    /// glTF material index to voxcone's, `None` for a material that is entirely cut out.
    materials: HashMap<usize, Option<u32>>,
    options: &'a LoadOptions,
    emission_scale: f32,
}

/// The texture-coordinate set and transform baked into a material's vertices.
#[derive(Clone, Copy, PartialEq)]
struct UvTransform {
    set: u32,
    /// uv' = offset + rotation * (scale * uv), as `KHR_texture_transform`.
    offset: Vec2,
    rotation: f32,
    scale: Vec2,
}

impl UvTransform {
    const NONE: Self = Self {
        set: 0,
        offset: Vec2::ZERO,
        rotation: 0.0,
        scale: Vec2::ONE,
    };

    fn of(info: &gltf::texture::Info) -> Self {
        match info.texture_transform() {
            None => Self {
                set: info.tex_coord(),
                ..Self::NONE
            },
            Some(t) => Self {
                set: t.tex_coord().unwrap_or(info.tex_coord()),
                offset: Vec2::from(t.offset()),
                rotation: t.rotation(),
                scale: Vec2::from(t.scale()),
            },
        }
    }

    /// The extension's offset x rotation x scale. The rotation is the one three.js,
    /// Cesium and Khronos' sample viewer apply, which the TextureTransformTest model
    /// checks: u' = cos u + sin v, v' = -sin u + cos v (v points down the image).
    fn apply(&self, uv: [f32; 2]) -> [f32; 2] {
        let s = Vec2::from(uv) * self.scale;
        let (sin, cos) = self.rotation.sin_cos();
        let r = Vec2::new(cos * s.x + sin * s.y, -sin * s.x + cos * s.y);
        (self.offset + r).to_array()
    }
}

impl GltfFile<'_> {
    /// One primitive as a mesh in the file's space, or `None` when it has no triangles or
    /// its material cuts it out entirely.
    fn primitive(
        &mut self,
        geometry: &mut Geometry,
        primitive: &gltf::Primitive,
        world: Mat4,
        name: &str,
    ) -> Result<Option<Mesh>> {
        let mode = primitive.mode();
        if !matches!(
            mode,
            Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
        ) {
            log::info!("{name}: {mode:?} are not surfaces, skipped");
            return Ok(None);
        }
        let material = primitive.material();
        let (material_index, uv) = match material.index() {
            None => (Some(geometry.default_material()), UvTransform::NONE),
            Some(i) => {
                let uv = material_uv(&material, name);
                let index = match self.materials.get(&i) {
                    Some(&index) => index,
                    None => {
                        let index = self
                            .material(geometry, &material)
                            .with_context(|| format!("in material {i}"))?;
                        self.materials.insert(i, index);
                        index
                    }
                };
                (index, uv)
            }
        };
        let Some(material_index) = material_index else {
            return Ok(None);
        };

        for (_, accessor) in primitive.attributes() {
            self.check_accessor(&accessor)?;
        }
        if let Some(indices) = primitive.indices() {
            self.check_accessor(&indices)?;
        }
        let buffers = self.buffers;
        let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
        let positions: Vec<Vec3> = reader
            .read_positions()
            .ok_or_else(|| anyhow!("it has no POSITION attribute"))?
            .map(|p| world.transform_point3(Vec3::from(p)))
            .collect();
        // Normals by the inverse transpose; a singular transform leaves them to the
        // winding.
        let normal_matrix = Mat3::from_mat4(world).inverse().transpose();
        let normals: Vec<Vec3> = match reader.read_normals() {
            Some(n) if normal_matrix.is_finite() => {
                n.map(|n| normal_matrix * Vec3::from(n)).collect()
            }
            _ => Vec::new(),
        };
        let uvs: Vec<[f32; 2]> = reader
            .read_tex_coords(uv.set)
            .map(|t| t.into_f32().map(|c| uv.apply(c)).collect())
            .unwrap_or_default();
        // glTF gives the second UV set no meaning of its own; engines (Unity, Godot,
        // three.js) take it for the lightmap, as the probes' bake does.
        let lightmap_uvs: Vec<[f32; 2]> = reader
            .read_tex_coords(1)
            .map(|t| t.into_f32().collect())
            .unwrap_or_default();
        let count = positions.len() as u32;
        let vertices: Vec<u32> = match reader.read_indices() {
            Some(i) => i.into_u32().collect(),
            None => (0..count).collect(),
        };
        let mut indices = triangle_list(mode, &vertices);
        if Mat3::from_mat4(world).determinant() < 0.0 {
            for t in indices.chunks_exact_mut(3) {
                t.swap(1, 2);
            }
        }
        let attributes = ModelAttributes {
            name,
            positions: &positions,
            normals: &normals,
            uvs: &uvs,
            lightmap_uvs: &lightmap_uvs,
            indices: &indices,
        };
        let Some(ModelGeometry {
            vertices,
            indices,
            bounds,
            lightmap_uvs,
        }) = model_geometry(&attributes)?
        else {
            return Ok(None);
        };
        Ok(Some(Mesh {
            name: name.to_string(),
            vertices,
            indices,
            material: material_index,
            transform: Mat4::IDENTITY,
            animation: None,
            local_bounds: bounds,
            object_bounds: bounds,
            lightmap_uvs,
        }))
    }

    /// That `accessor`'s elements lie inside its buffer view, and the view inside its
    /// buffer (the reader would otherwise fail or read past them).
    fn check_accessor(&self, accessor: &gltf::Accessor) -> Result<()> {
        let i = accessor.index();
        if let Some(view) = accessor.view() {
            let element = accessor.size();
            let stride = view.stride().unwrap_or(element);
            let count = accessor.count();
            let end = match count {
                0 => 0,
                n => accessor.offset() + stride * (n - 1) + element,
            };
            ensure!(
                end <= view.length(),
                "accessor {i}: its {count} elements end at byte {end} of buffer view {}, which \
                 has {} bytes",
                view.index(),
                view.length()
            );
            self.check_view(&view)?;
        }
        if let Some(sparse) = accessor.sparse() {
            let indices = sparse.indices();
            let width = match indices.index_type() {
                gltf::accessor::sparse::IndexType::U8 => 1,
                gltf::accessor::sparse::IndexType::U16 => 2,
                gltf::accessor::sparse::IndexType::U32 => 4,
            };
            let values = sparse.values();
            for (view, offset, bytes) in [
                (indices.view(), indices.offset(), width * sparse.count()),
                (
                    values.view(),
                    values.offset(),
                    accessor.size() * sparse.count(),
                ),
            ] {
                ensure!(
                    offset + bytes <= view.length(),
                    "accessor {i}: its sparse data end at byte {} of buffer view {}, which has \
                     {} bytes",
                    offset + bytes,
                    view.index(),
                    view.length()
                );
                self.check_view(&view)?;
            }
        }
        Ok(())
    }

    fn check_view(&self, view: &gltf::buffer::View) -> Result<()> {
        let buffer = view.buffer().index();
        let length = self.buffers.get(buffer).map_or(0, |d| d.len());
        let end = view.offset() + view.length();
        ensure!(
            end <= length,
            "buffer view {} ends at byte {end} of buffer {buffer}, which has {length} bytes",
            view.index()
        );
        Ok(())
    }

    /// The voxcone material of `m`, or `None` when `MASK` cuts all of it.
    fn material(&mut self, geometry: &mut Geometry, m: &gltf::Material) -> Result<Option<u32>> {
        let name = m.name().map_or_else(
            || format!("material {}", m.index().unwrap_or(0)),
            str::to_string,
        );
        let pbr = m.pbr_metallic_roughness();
        let base = Vec4::from(pbr.base_color_factor());
        ensure!(base.is_finite(), "baseColorFactor must be finite");
        let metallic = pbr.metallic_factor().clamp(0.0, 1.0);
        let roughness = pbr.roughness_factor().clamp(0.0, 1.0);
        let emissive = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
        ensure!(
            emissive.is_finite() && emissive.min_element() >= 0.0,
            "the emission (emissiveFactor x emissive_strength) must be finite and non-negative"
        );
        let base_texture = pbr.base_color_texture();
        let (dissolve, cutout) = match m.alpha_mode() {
            AlphaMode::Opaque => (1.0, None),
            AlphaMode::Mask => {
                let cutoff = m.alpha_cutoff().unwrap_or(0.5);
                if base_texture.is_none() && base.w < cutoff {
                    log::info!(
                        "{name}: alpha {} below the cutoff {cutoff}, not drawn",
                        base.w
                    );
                    return Ok(None);
                }
                (
                    1.0,
                    Some(AlphaCutout {
                        factor: base.w,
                        cutoff,
                    }),
                )
            }
            AlphaMode::Blend => (
                base.w.clamp(0.0, 1.0),
                Some(AlphaCutout {
                    factor: 1.0,
                    cutoff: 0.5,
                }),
            ),
        };
        let mut texture = |this: &mut Self, t: gltf::Texture, kind, adjust| -> Result<u32> {
            let source = this.image(&t.source())?;
            Ok(geometry.textures.request(source, kind, adjust, &name))
        };
        let albedo_texture = base_texture
            .as_ref()
            .map(|t| texture(self, t.texture(), TextureKind::Albedo, None))
            .transpose()?;
        let coverage_texture = match (&base_texture, cutout) {
            (Some(t), Some(cutout)) => Some(texture(
                self,
                t.texture(),
                TextureKind::Coverage,
                Some(Adjust::Cutout(cutout)),
            )?),
            _ => None,
        };
        let emission_texture = m
            .emissive_texture()
            .map(|t| texture(self, t.texture(), TextureKind::Albedo, None))
            .transpose()?;
        let normal_texture = match m.normal_texture() {
            Some(n) if !self.options.no_normal_maps => {
                ensure!(
                    n.scale().is_finite(),
                    "normalTexture.scale must be finite, got {}",
                    n.scale()
                );
                let scale = (n.scale() != 1.0).then_some(Adjust::NormalScale(n.scale()));
                Some(texture(self, n.texture(), TextureKind::Normal, scale)?)
            }
            _ => None,
        };
        if pbr.metallic_roughness_texture().is_some() {
            log::info!("{name}: the metallic-roughness texture is not used (its factors are)");
        }
        let specular = if self.options.diffuse_only {
            Vec3::ZERO
        } else {
            Vec3::splat(0.04).lerp(base.truncate(), metallic)
        };
        geometry.materials.push(Material {
            name,
            albedo: base.truncate() * (1.0 - metallic),
            albedo_texture,
            specular,
            roughness: (roughness * roughness).clamp(0.02, 1.0),
            emission: emissive * self.emission_scale,
            emission_texture,
            dissolve,
            coverage_texture,
            normal_texture,
            // BLEND lets light through straight, as a mask.
            ior: 1.0,
        });
        Ok(Some(geometry.materials.len() as u32 - 1))
    }

    /// Where image `image`'s encoded bytes are: a file beside the glTF, a buffer view, or a
    /// data URI.
    fn image(&mut self, image: &gltf::Image) -> Result<TextureSource> {
        if let Some(source) = self.images.get(&image.index()) {
            return Ok(source.clone());
        }
        let i = image.index();
        let name = PathBuf::from(format!("{}#image{i}", self.path.display()));
        let source = match image.source() {
            gltf::image::Source::View { view, .. } => {
                self.check_view(&view)?;
                let data = &self.buffers[view.buffer().index()];
                let bytes = &data[view.offset()..view.offset() + view.length()];
                TextureSource::Memory {
                    name,
                    bytes: Arc::from(bytes),
                }
            }
            gltf::image::Source::Uri { uri, .. } if uri.starts_with("data:") => {
                let (_, payload) = uri
                    .split_once(";base64,")
                    .ok_or_else(|| anyhow!("image {i}: a data URI that is not base64"))?;
                let bytes = base64::engine::general_purpose::STANDARD
                    .decode(payload)
                    .map_err(|e| anyhow!("image {i}: its data URI is not valid base64: {e}"))?;
                TextureSource::Memory {
                    name,
                    bytes: Arc::from(bytes),
                }
            }
            gltf::image::Source::Uri { uri, .. } => {
                let file = self.base.join(uri_path(uri));
                if file.is_dir() {
                    bail!("image {i}: {} is a directory, not an image", file.display());
                }
                ensure!(
                    file.is_file(),
                    "image {i} ({uri}) not found: {}",
                    file.display()
                );
                TextureSource::File(file.canonicalize().unwrap_or(file))
            }
        };
        self.images.insert(i, source.clone());
        Ok(source)
    }
}

/// The set and transform of the texture coordinates a material's vertices get: those of
/// its base colour texture, else its emissive texture, else its normal map.
fn material_uv(m: &gltf::Material, name: &str) -> UvTransform {
    let pbr = m.pbr_metallic_roughness();
    let mut uses: Vec<UvTransform> = Vec::new();
    uses.extend(pbr.base_color_texture().map(|t| UvTransform::of(&t)));
    uses.extend(m.emissive_texture().map(|t| UvTransform::of(&t)));
    if let Some(n) = m.normal_texture() {
        // A normal texture's info carries its set, without a transform reader of its own.
        let set = n.tex_coord();
        uses.push(UvTransform {
            set,
            ..uses.first().copied().unwrap_or(UvTransform::NONE)
        });
    }
    let first = uses.first().copied().unwrap_or(UvTransform::NONE);
    if uses.iter().any(|u| *u != first) {
        log::warn!(
            "{name}: its textures use different texture coordinates or transforms; all use \
             those of the first (voxcone keeps one set per vertex)"
        );
    }
    first
}

/// Triangle corner indices of a primitive of `mode` over `vertices` (glTF 2.0 §3.7.2.1).
fn triangle_list(mode: Mode, vertices: &[u32]) -> Vec<u32> {
    let n = vertices.len();
    match mode {
        Mode::TriangleStrip => (0..n.saturating_sub(2))
            .flat_map(|i| {
                let (b, c) = if i % 2 == 0 {
                    (i + 1, i + 2)
                } else {
                    (i + 2, i + 1)
                };
                [vertices[i], vertices[b], vertices[c]]
            })
            .collect(),
        Mode::TriangleFan => (1..n.saturating_sub(1))
            .flat_map(|i| [vertices[i], vertices[i + 1], vertices[0]])
            .collect(),
        _ => vertices[..n - n % 3].to_vec(),
    }
}

/// The view of a perspective camera node (`None`, with a warning, for orthographic ones:
/// voxcone's camera is a pinhole).
fn node_camera(camera: &gltf::Camera, world: Mat4) -> Result<Option<Camera>> {
    let gltf::camera::Projection::Perspective(p) = camera.projection() else {
        log::warn!("camera {} is orthographic, not used", camera.index());
        return Ok(None);
    };
    let fov_y_deg = p.yfov().to_degrees();
    ensure!(
        fov_y_deg > 0.0 && fov_y_deg < 180.0,
        "camera {}: yfov must be in (0, pi), got {}",
        camera.index(),
        p.yfov()
    );
    // A camera looks down its node's -Z with +Y up.
    let position = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z);
    let up = world.transform_vector3(Vec3::Y);
    ensure!(
        forward.length_squared() > 0.0 && forward.cross(up).length_squared() > 0.0,
        "camera {}: its node's transform is singular",
        camera.index()
    );
    Ok(Some(Camera::look_at(
        position,
        position + forward.normalize(),
        up.normalize(),
        fov_y_deg,
    )))
}

/// A punctual light in voxcone's units (module docs).
fn node_light(light: &gltf::khr_lights_punctual::Light, world: Mat4) -> Result<Light> {
    let colour = Vec3::from(light.color());
    let intensity = colour * light.intensity() / LUMENS_PER_WATT;
    ensure!(
        intensity.is_finite() && intensity.min_element() >= 0.0,
        "color x intensity must be finite and non-negative"
    );
    if light.range().is_some() {
        log::info!(
            "light {}: range is not used (the inverse square only)",
            light.index()
        );
    }
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world.transform_vector3(Vec3::NEG_Z);
    let axis = || {
        ensure!(
            direction.length_squared() > 0.0,
            "its node's transform is singular"
        );
        Ok(direction.normalize())
    };
    let kind = match light.kind() {
        LightKindGltf::Point => LightKind::Point,
        LightKindGltf::Directional => LightKind::Directional { direction: axis()? },
        LightKindGltf::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => {
            // voxcone's cone stays below a hemisphere (its shadow view is a perspective).
            let outer = outer_cone_angle.to_degrees().min(89.9);
            let inner = inner_cone_angle.to_degrees().clamp(0.0, outer);
            ensure!(
                outer >= 0.0,
                "outerConeAngle must be positive, got {outer_cone_angle}"
            );
            LightKind::Spot {
                direction: axis()?,
                inner_deg: inner,
                outer_deg: outer,
            }
        }
    };
    Ok(Light {
        kind,
        position,
        intensity,
        orbit: None,
    })
}

#[cfg(test)]
mod tests;
