gpu_layout! {
    constants {
        /// Descriptor set: per-frame data (uniforms, lights, shadow maps).
        SET_FRAME = 0;
        /// Descriptor set: the scene's materials and textures.
        SET_SCENE = 1;
        /// Descriptor set: inputs and outputs of one pass (lighting, composite, the dense
        /// filter's levels).
        SET_PASS = 2;

        /// set 0: `FrameUniforms` uniform buffer.
        BINDING_FRAME_UNIFORMS = 0;
        /// set 0: `GpuLight[]` storage buffer.
        BINDING_LIGHTS = 1;
        /// set 0: `ShadowView[]` storage buffer.
        BINDING_SHADOW_VIEWS = 2;
        /// set 0: shadow map layers, `sampler2DArrayShadow`.
        BINDING_SHADOW_MAP = 3;

        /// set 1: `GpuMaterial[]` storage buffer.
        BINDING_MATERIALS = 0;
        /// set 1 (one set per material): albedo texture, `sampler2D` (white if none).
        BINDING_ALBEDO_TEXTURE = 1;
        /// set 1: cut-out coverage texture, `sampler2D` (white if none).
        BINDING_COVERAGE_TEXTURE = 2;
        /// set 1: tangent-space normal map, `sampler2D` (white if none).
        BINDING_NORMAL_TEXTURE = 3;
        /// set 1: emission texture, `sampler2D` (white if none).
        BINDING_EMISSION_TEXTURE = 4;
        /// A material's texture index meaning "no texture".
        NO_TEXTURE = 0xFFFFFFFF;

        /// lighting pass (set 2): G-buffer albedo, `rgba8` storage image.
        BINDING_LIGHTING_ALBEDO = 0;
        /// lighting pass (set 2): G-buffer normal + roughness, `rgba16f` storage image.
        BINDING_LIGHTING_NORMAL = 1;
        /// lighting pass (set 2): G-buffer emission + specular, `rgba16f` storage image.
        BINDING_LIGHTING_EMISSION = 2;
        /// lighting pass (set 2): depth, `sampler2D`.
        BINDING_LIGHTING_DEPTH = 3;
        /// lighting pass (set 2): HDR radiance out, `rgba32f` storage image.
        BINDING_LIGHTING_OUT = 4;
        /// Workgroup edge of the 2D compute passes.
        SCREEN_GROUP_SIZE = 8;

        /// composite pass (set 2): HDR radiance in, `sampler2D`.
        BINDING_COMPOSITE_HDR = 0;

        /// Descriptor set of the GI passes that work on the screen: the screen contract every
        /// technique writes and the upsample reads (`gi::screen`).
        SET_SCREEN = 2;
        /// Descriptor set of a GI technique's own resources (the voxel cone tracer's: the
        /// shared bindings `BINDING_VCT_*`, then its voxel store's).
        SET_GI = 3;

        /// Screen contract (set 2): `ScreenUniforms` uniform buffer.
        BINDING_SCREEN_UNIFORMS = 0;
        /// Screen contract (set 2): screen radiance, written by the lighting pass (or not, when
        /// the technique shades the direct light), read and added to by the upsample, `rgba32f` storage.
        BINDING_SCREEN_RADIANCE = 1;
        /// Screen contract (set 2): G-buffer albedo (rgb) and specular (a), `rgba16f` storage.
        BINDING_SCREEN_ALBEDO = 2;
        /// Screen contract (set 2): G-buffer normal and roughness, `rgba16f` storage.
        BINDING_SCREEN_NORMAL = 3;
        /// Screen contract (set 2): G-buffer depth, `sampler2D`.
        BINDING_SCREEN_DEPTH = 4;
        /// Screen contract (set 2): G-buffer transmittance (r) and index of refraction (g), `rg16f` storage.
        BINDING_SCREEN_TRANSMISSION = 5;
        /// Screen contract (set 2): G-buffer emission, `rgba16f` storage (the upsample shades the
        /// pixels itself when the technique shades the direct light, and the lighting pass does not run).
        BINDING_SCREEN_EMISSION = 6;
        /// Screen contract (set 2): gathered indirect radiance (rgb) and ambient occlusion (a) at
        /// reduced resolution, `rgba16f` storage.
        BINDING_SCREEN_INDIRECT = 7;
        /// Screen contract (set 2): the visibility of every light at reduced resolution, when the
        /// technique shades the direct light, `rgba16f` storage: lights 4k..4k+3 in the channels of
        /// the k-th band of rows, each band as tall as the reduced-resolution image.
        BINDING_SCREEN_SHADOW = 8;
        /// Screen contract (set 2): specular radiance (rgb, before Ks) at reduced resolution, `rgba16f` storage.
        BINDING_SCREEN_SPECULAR = 9;
        /// Screen contract (set 2): radiance refracted through transmissive surfaces (rgb) at reduced
        /// resolution, and 1 in alpha where the sampled pixel is transmissive (0 elsewhere), `rgba16f` storage.
        BINDING_SCREEN_TRANSMITTED = 10;
        /// Screen contract (set 2): G-buffer triangle, its index in the scene plus one (0 where no
        /// triangle was drawn, or where the device cannot number them: no geometry-shader
        /// feature for `gl_PrimitiveID`), `r32ui` storage.
        BINDING_SCREEN_TRIANGLE = 11;

        /// Voxel cone tracing (set 3): `VctUniforms` uniform buffer.
        BINDING_VCT_UNIFORMS = 0;
        /// Voxel cone tracing (set 3): voxel albedo, RGBA8 mean packed in `r32ui` (the dense grid's
        /// volume; the octree's leaf attribute bricks, here and in the next two).
        BINDING_VCT_ALBEDO = 1;
        /// Voxel cone tracing (set 3): voxel normal (xyz * 0.5 + 0.5), RGBA8 mean in `r32ui`.
        BINDING_VCT_NORMAL = 2;
        /// Voxel cone tracing (set 3): voxel emission / `VctUniforms.emission_range`, RGBA8 in `r32ui`.
        BINDING_VCT_EMISSION = 3;
        /// Voxel cone tracing (set 3): voxel radiance, premultiplied by opacity, `rgba16f` storage
        /// (the octree: its leaf radiance bricks).
        BINDING_VCT_RADIANCE = 4;
        /// Voxel cone tracing (set 3): the same voxel radiance, `sampler3D`.
        BINDING_VCT_RADIANCE_SAMPLED = 5;
        /// Voxel cone tracing (set 3): the directional radiance, `sampler3D`: the dense grid's six
        /// mip volumes side by side along x (+X -X +Y -Y +Z -Z); the octree's interior bricks, likewise.
        BINDING_VCT_DIRECTIONAL = 6;
        /// Voxel cone tracing (set 3): voxel direct radiance (before bounces), `rgba16f` storage.
        BINDING_VCT_DIRECT = 7;
        /// Voxel cone tracing (set 3): the occupied voxels, `VoxelList` storage buffer (also the
        /// indirect dispatch arguments of the passes that run over them).
        BINDING_VCT_VOXEL_LIST = 8;
        /// Workgroup size of the passes that run over the voxel list.
        VOXEL_LIST_GROUP_SIZE = 64;
        /// Compute voxelization (set 3): the scene's vertices (`scene::Vertex`: position, normal, uv), `float[]` storage buffer.
        BINDING_VCT_VERTICES = 9;
        /// Compute voxelization (set 3): the scene's indices, `uint[]` storage buffer.
        BINDING_VCT_INDICES = 10;
        /// Workgroup size of the compute voxelization: the lanes that walk one triangle's pixels.
        VOXELIZE_GROUP_SIZE = 32;
        /// Voxel cone tracing (set 3): the emitters whose light is sampled instead of gathered
        /// (`gi::vct::emitters`), `VctEmitter[]` storage buffer (`VctUniforms.emitter_count` of them).
        BINDING_VCT_EMITTERS = 11;
        /// Voxel cone tracing (set 3): the sampled emitters' triangles, `VctEmitterTriangle[]` storage buffer.
        BINDING_VCT_EMITTER_TRIANGLES = 12;
        /// Voxel cone tracing (set 3): one bit per material (bit m % 32 of word m / 32), set where its
        /// emission is sampled and so left out of the voxels, `uint[]` storage buffer.
        BINDING_VCT_SAMPLED_MATERIALS = 13;

        /// Dense grid (set 3, after the shared bindings): per voxel, the sums of its fragments'
        /// albedo, normal, emission and coverage (RGB, 0..255 each) and their count, `VOXEL_SUM_WORDS` texels
        /// of an `r32ui` storage image of 2n x n x 7n texels (`glsl/gi/vct/sums.glsl`), from which the
        /// compact pass takes the means. Atomic adds are exact and commutative, so the means do not
        /// depend on the order in which fragments arrive.
        BINDING_DENSE_SUMS = 14;
        /// Dense grid (set 3): the static meshes' fragment sums, laid out as `BINDING_DENSE_SUMS`
        /// (read when `VctUniforms.static_sums` is 1).
        BINDING_DENSE_STATIC_SUMS = 15;
        /// Dense filter pass (its own set 2, one per level): the base radiance, read by the first level, `rgba16f` storage.
        BINDING_FILTER_BASE = 0;
        /// Dense filter pass (its own set 2, one per level): the directional level read (levels after the first), `rgba16f` storage.
        BINDING_FILTER_SRC = 1;
        /// Dense filter pass (its own set 2, one per level): the directional level written, `rgba16f` storage.
        BINDING_FILTER_DST = 2;
        /// Dense filter pass (its own set 2, one per level): the voxel normals, oriented to the lit side by injection.
        BINDING_FILTER_NORMAL = 3;
        /// Dense filter pass by rows (`--directional-filter rows`): the rows of the level below, each composited along the direction's axis, `rgba16f` storage (`glsl/gi/vct/dense/filter_rows.comp`).
        BINDING_FILTER_ROWS_SRC = 4;
        /// Dense filter pass by rows: the rows of the level written, `rgba16f` storage.
        BINDING_FILTER_ROWS_DST = 5;
        /// Workgroup edge of the 3D compute passes.
        VOXEL_GROUP_SIZE = 4;
        /// Slots of the directional volumes (the dense grid's texture, the octree's interior bricks), side by side along x: the six directions +X -X +Y -Y +Z -Z, and with the planes (`Store::planes`) two more, the cells' surface planes (`PLANE_SLOT`) and coverage (`COVERAGE_SLOT`).
        DIRECTIONAL_SLOTS = 6;
        /// The slots the planes (`Store::planes`) add to the directional volumes.
        PLANE_SLOTS = 2;
        /// Slot of the directional volumes holding each cell's surface plane, premultiplied by coverage: xyz the mean of its voxels' opacity times normal, w the mean of opacity times the plane constant dot(normal, position) (position in grid units, 0..1 across the grid, less 0.5).
        PLANE_SLOT = 6;
        /// Slot of the directional volumes holding each cell's coverage: r the mean of its voxels' opacity.
        COVERAGE_SLOT = 7;

        /// Octree (set 3, after the shared bindings, in which the octree binds its pools where the
        /// dense grid binds volumes): `OctreeCounters` then `OctreeLevel[OCTREE_MAX_LEVELS]`,
        /// storage buffer.
        BINDING_OCTREE_COUNTERS = 14;
        /// Octree (set 3): the voxel-fragment list, first half: the fragments' voxels (x | y << 10 | z << 20), then their RGBA8 albedos, alpha the coverage across x (from `OctreeCounters.fragment_capacity` on; the octree's passes read only the voxels), `uint[]` storage buffer. (Two halves of 8 bytes, so that each fits the 128 MiB that lavapipe binds at depth 9.)
        BINDING_OCTREE_FRAGMENTS = 15;
        /// Octree (set 3): the voxel-fragment list, second half: per fragment its RGBA8 normal (xyz * 0.5 + 0.5) and emission / `VctUniforms.emission_range`, alpha the coverage across y and z, `uvec2[]` storage buffer.
        BINDING_OCTREE_FRAGMENT_SHADING = 16;
        /// Octree (set 3): per node, its first child (children come in tiles of 8; 0 = none) with `OCTREE_SUBDIVIDE` set while flagged; for a leaf, which of its 8 voxels hold fragments (bits 0-7, voxel x | y << 1 | z << 2) and the first of their sums (bits 8-31; a leaf is flagged in its coordinates instead, `OCTREE_LEAF_FLAGGED`), `uint[]` storage buffer.
        BINDING_OCTREE_NODES = 17;
        /// Octree (set 3): per node, its coordinates among its level's nodes (x | y << 10 | z << 20), `uint[]` storage buffer.
        BINDING_OCTREE_NODE_COORDS = 18;
        /// Octree (set 3): per node, its brick (`OCTREE_NO_BRICK` for an empty node), in the leaf pools for leaves, in the interior pool otherwise, `uint[]` storage buffer.
        BINDING_OCTREE_NODE_BRICKS = 19;
        /// Octree (set 3): per node, its six neighbours at its level (+X -X +Y -Y +Z -Z; `OCTREE_NO_NODE` where none), `uint[]` storage buffer.
        BINDING_OCTREE_NEIGHBOURS = 20;
        /// Octree (set 3): the interior bricks' six directional radiances, `rgba16f` storage (sampled at `BINDING_VCT_DIRECTIONAL`).
        BINDING_OCTREE_DIRECTIONAL_STORAGE = 21;
        /// Octree (set 3): per occupied leaf voxel, the sums of its fragments' albedo, normal, emission and coverage (RGB, 0..255 each) and their count, `VOXEL_SUM_WORDS` words of a `uint[]` storage buffer: atomic adds are exact and commutative, so the averages do not depend on the order the fragments were listed in.
        BINDING_OCTREE_SUMS = 22;
        /// Octree (set 3): the light each leaf voxel in a new brick gathered in the last frame, for the same voxel in the next frame's octree rebuilt around moving meshes (which gives it a new brick again): two hash tables of `carry_capacity` entries (key = voxel x | y << 10 | z << 20, plus 1; then the RGB floats), `uint[]` storage buffer.
        BINDING_OCTREE_CARRY = 23;
        /// Octree (set 3): the static part's child entries as the static build left them (Dřínovský 2013, 5.7): each frame restores them, and a static leaf that a moving mesh's fragments reach reads its own voxels' mask and sums from here, `uint[]` storage buffer.
        BINDING_OCTREE_STATIC_NODES = 24;
        /// Octree (set 3): per brick (the leaf bricks', then the interior bricks'), `OCTREE_CHANGED` and `OCTREE_BORDER` bits while the filter's update lists are built, `uint[]` storage buffer.
        BINDING_OCTREE_CHANGES = 25;
        /// Octree (set 3): the filter's update lists (Dřínovský 2013, 5.5): `OctreeUpdateList[OCTREE_UPDATE_LISTS]`, `OctreeBounceDispatch`, then each list's nodes (`OctreeCounters.update_capacity` each), `uint[]` storage buffer.
        BINDING_OCTREE_UPDATES = 26;
        /// Octree (set 3): the node grid, a dense index into the octree at level `depth - 1 - OCTREE_NODE_GRID_ABOVE_LEAVES` (`glsl/gi/vct/octree/nodes/grid.comp`): per cell, its node there, or `OCTREE_GRID_GAP` plus the level of the childless node above where its cube is empty; cone samples start their descent from it, `uint[]` storage buffer.
        BINDING_OCTREE_NODE_GRID = 27;
        /// Words of a voxel's fragment sums (dense grid and octree alike): albedo RGB, normal
        /// XYZ, emission RGB, coverage XYZ, then the fragment count (`glsl/gi/vct/sums.glsl`).
        VOXEL_SUM_WORDS = 13;
        /// Voxel cone tracing (set 3, numbered after both stores' own): each voxel's coverage, the
        /// share of its cross-section across x, y and z that its surfaces cover (RGB; alpha 1 where
        /// occupied), `rgba8` storage (the octree: leaf coverage bricks laid out as its leaf radiance
        /// bricks, borders included).
        BINDING_VCT_COVERAGE = 28;
        /// Voxel cone tracing (set 3): the same coverage, `sampler3D`.
        BINDING_VCT_COVERAGE_SAMPLED = 29;
        /// Levels between the node grid and the leaves: samples of the finest levels descend at most this far from the grid (from the root, 7 more at depth 10).
        OCTREE_NODE_GRID_ABOVE_LEAVES = 3;
        /// A node grid entry at or above this is no node: the cell is empty from level (entry - `OCTREE_GRID_GAP`) down.
        OCTREE_GRID_GAP = 0xFFFFFF00;
        /// Update lists: nodes whose radiance changed, at levels of even and odd parity (0, 1), and nodes whose border must be copied again (2, 3).
        OCTREE_UPDATE_LISTS = 4;
        /// Bit of a brick's change word: its voxels' radiance changed (it is in a changed list).
        OCTREE_CHANGED = 1;
        /// Bit of a brick's change word: a voxel of it or of a neighbour changed (it is in a border list).
        OCTREE_BORDER = 2;
        /// `OctreePush.over`: every node of the level.
        OCTREE_OVER_LEVEL = 0;
        /// `OctreePush.over`: the level's appended nodes only.
        OCTREE_OVER_APPENDED = 1;
        /// `OctreePush.over`: the nodes of update list `OctreePush.list`.
        OCTREE_OVER_LIST = 2;
        /// Edge of a leaf attribute brick (albedo, normal, emission, direct light): the leaf's 2x2x2 voxels.
        OCTREE_ATTRIBUTE_BRICK = 2;
        /// Edge of a radiance brick: the node's 2x2x2 voxels and a border of one voxel copied from the neighbours, so that trilinear filtering inside the node needs no other brick.
        OCTREE_RADIANCE_BRICK = 4;
        /// Octree levels the level table has room for (depth 10 uses 10).
        OCTREE_MAX_LEVELS = 16;
        /// Specialization constant id of the octree's depth (log2 of the effective grid's resolution), given to every pipeline of voxel cone tracing. As a uniform it would be inlined by lavapipe (Mesa 22.3 `update_inline_shader_state`): a pipeline whose loops it bounds is compiled anew at every bind, and the old code is never freed (1.25 MiB per frame of the octree's voxel bounce).
        SPEC_OCTREE_DEPTH = 0;
        /// Specialization constant id, given to every pipeline of voxel cone tracing: 1 where the cones read the directional volumes snapped along each volume's axis, in cells half their diameter, the ring cones clear of their own surface and the cone along the normal as four sub-cones (`--snapped-cones`); 0 for trilinear lookups in cells as wide as the cone. A uniform there, tested in branches, was inlined by lavapipe as the depth was, and its passes grew resident memory by a megabyte a frame.
        SPEC_SNAPPED_CONES = 1;
        /// Specialization constant id, given to every pipeline of voxel cone tracing: the cones of the screen's diffuse gather's lattice (`--lattice-cones`), spread evenly over the cosine-weighted hemisphere; 0 for the ring of `diffuse_cones`. A constant for the reason `SPEC_SNAPPED_CONES` is one; the ring's gather also ran 0.5 % slower on lavapipe with the lattice's branch on a uniform.
        SPEC_LATTICE_CONES = 2;
        /// Specialization constant id, given to every pipeline of voxel cone tracing: 1 where the voxel store (the dense grid or the octree) keeps each cell's surface plane and the snapped cones count a plane they run beside as the same rays from cell to cell (`Store::planes`, `PLANE_SLOT`); 0 where every cell's opacity is composited as uncorrelated. A constant for the reason `SPEC_SNAPPED_CONES` is one.
        SPEC_PLANE_OCCLUSION = 3;
        /// Specialization constant id, given to every pipeline of voxel cone tracing: 1 where the voxelization takes each voxel's coverage (`BINDING_VCT_COVERAGE`) for the snapped cones that read the base voxels (the sampled emitters' visibility, the specular and refraction cones, the soft-shadow cones); 0 where nothing reads it and an occupied voxel counts as covered across every axis. A constant: lavapipe ran the clipping that takes it even behind a uniform branch not taken (Sponza's voxelization 0.97 s without the code, 2.87 s with it).
        SPEC_VOXEL_COVERAGE = 4;
        /// Specialization constant id of the shadow pass: 1 where cut-outs cast whole shadows whatever their coverage (`RenderSettings::opaque_shadow_cut_outs`, the references' convention), 0 where they cast none where cut.
        SPEC_SHADOW_OPAQUE_CUT_OUTS = 0;
        /// Workgroup size of the passes over fragments and over a level's nodes.
        OCTREE_GROUP_SIZE = 64;
        /// Workgroups along y of a dispatch over an update list: the border transfer, filter and spread passes share each node's work (texels, children, neighbours) among them, so that a short list still fills the GPU (1 on a CPU driver, where a workgroup costs more than the work it shares).
        OCTREE_LIST_SLICES = 8;
        /// Bit of a node's child entry: the node is to be subdivided.
        OCTREE_SUBDIVIDE = 0x80000000;
        /// Bit of a leaf's coordinates (above x | y << 10 | z << 20): fragments of the current insertion reached the leaf; set by the flag pass, cleared by the alloc pass (the leaf's child entry has no bit to spare: its first sum takes bits 8-31, for up to 2^24 leaf voxels).
        OCTREE_LEAF_FLAGGED = 0x40000000;
        /// A missing node (neighbour pointers, look-ups).
        OCTREE_NO_NODE = 0xFFFFFFFF;
        /// A node without a brick (it holds no voxel).
        OCTREE_NO_BRICK = 0xFFFFFFFF;
        /// `OctreeCounters.overflow` bit: the voxel-fragment list was too small.
        OCTREE_OVERFLOW_FRAGMENTS = 1;
        /// `OctreeCounters.overflow` bit: the node pool was too small.
        OCTREE_OVERFLOW_NODES = 2;
        /// `OctreeCounters.overflow` bit: the leaf brick pool was too small.
        OCTREE_OVERFLOW_LEAF_BRICKS = 4;
        /// `OctreeCounters.overflow` bit: the interior brick pool was too small.
        OCTREE_OVERFLOW_INTERIOR_BRICKS = 8;
        /// `OctreeCounters.overflow` bit: the leaf voxels' sums buffer was too small.
        OCTREE_OVERFLOW_LEAF_VOXELS = 16;

        /// `GpuLight.kind`: point light, intensity in W/sr.
        LIGHT_POINT = 0;
        /// `GpuLight.kind`: spot light, intensity in W/sr on its axis.
        LIGHT_SPOT = 1;
        /// `GpuLight.kind`: directional light, irradiance in W/m^2.
        LIGHT_DIRECTIONAL = 2;

        /// `FrameUniforms.flags`: add the specular lobe.
        FLAG_SPECULAR = 1;
        /// `FrameUniforms.flags`: filmic (ACES) tonemap instead of a plain clamp.
        FLAG_TONEMAP_ACES = 4;
        /// `FrameUniforms.flags`: add the direct light of the scene's lights.
        FLAG_DIRECT = 8;
        /// `FrameUniforms.flags`: add emitted radiance (and the sky seen directly).
        FLAG_EMISSION = 16;
        /// `FrameUniforms.flags`: add albedo x cone-traced indirect diffuse light.
        FLAG_INDIRECT_DIFFUSE = 32;
        /// `FrameUniforms.flags`: add the cone-traced specular reflection.
        FLAG_INDIRECT_SPECULAR = 64;
        /// `FrameUniforms.flags`: add light refracted through transmissive surfaces.
        FLAG_TRANSMISSION = 128;
        /// `FrameUniforms.flags`: multiply the indirect light by ambient occlusion.
        FLAG_AO = 256;
        /// `FrameUniforms.flags`: soft-shadow cones through the voxels instead of shadow maps.
        FLAG_SHADOW_CONES = 512;

        /// `FrameUniforms.debug_view`: the composited image.
        DEBUG_NONE = 0;
        /// `FrameUniforms.debug_view`: indirect light only (diffuse + specular + transmission).
        DEBUG_INDIRECT = 1;
        /// `FrameUniforms.debug_view`: ambient occlusion only.
        DEBUG_AO = 2;
        /// `FrameUniforms.debug_view`: voxel albedo at mip `debug_level`.
        DEBUG_VOXEL_ALBEDO = 3;
        /// `FrameUniforms.debug_view`: voxel normal (xyz * 0.5 + 0.5) at mip `debug_level`.
        DEBUG_VOXEL_NORMAL = 4;
        /// `FrameUniforms.debug_view`: voxel radiance at mip `debug_level`.
        DEBUG_VOXEL_RADIANCE = 5;
        /// `FrameUniforms.debug_view`: the octree's occupied nodes at depth `debug_level` below the leaves, edges drawn (`--gi svo`).
        DEBUG_OCTREE_NODES = 6;
        /// `FrameUniforms.debug_view`: the probes' lightmap (irradiance / π) at each pixel, its nearest texel (`--gi probes`).
        DEBUG_LIGHTMAP = 7;
        /// `FrameUniforms.debug_view`: each receiver's cluster in its own colour (`--gi probes`).
        DEBUG_CLUSTERS = 8;
        /// `FrameUniforms.debug_view`: the probes as small spheres showing the mean radiance each sees, over the indirect light (`--gi probes`).
        DEBUG_PROBES = 9;
        /// `FrameUniforms.debug_view`: the cone tracer's sampled emitters' light alone, times the albedo (`--gi dense`, `--gi octree`).
        DEBUG_EMITTER_LIGHT = 10;

        /// Scene ray casting (the first bindings of a set 3 that casts rays,
        /// `glsl/ray/rays.glsl`): `RayUniforms` uniform buffer.
        BINDING_RAY_UNIFORMS = 0;
        /// Ray casting (set 3): the BVHs' nodes, `BvhNode`s as a `usamplerBuffer` of five
        /// texels each: the static meshes' BVH from node 0, the moving meshes' after it
        /// (`RayUniforms.moving_root`), each node's inner children contiguous.
        BINDING_RAY_NODES = 1;
        /// Ray casting (set 3): the triangles in the BVHs' leaf order (in the scene's order where a
        /// pass looks them up by their index in the scene, `ray::surfaces`), `RayTriangle`s as a
        /// `usamplerBuffer` of three texels each: a vertex, two edges and the material, as
        /// the intersection test reads them.
        BINDING_RAY_TRIANGLES = 2;
        /// Ray casting (set 3): the triangles' shading attributes, `RayShading`s as a
        /// `usamplerBuffer` of four texels each, in the same order.
        BINDING_RAY_SHADING = 3;
        /// Ray casting (set 3): the scene's materials, `GpuMaterial`s as a `usamplerBuffer` of
        /// four texels each.
        BINDING_RAY_MATERIALS = 4;
        /// Ray casting (set 3): every scene texture's full-resolution level in one atlas,
        /// `sampler2D` read with `texelFetch` (filtered in the shader: dynamic indexing of
        /// texture arrays is an optional feature that lavapipe lacks); albedo sRGB-encoded.
        BINDING_RAY_ATLAS = 5;
        /// Ray casting (set 3): where each texture lies in the atlas, a `usamplerBuffer` of a
        /// texel each (x, y, width, height in texels).
        BINDING_RAY_TEXTURES = 6;
        /// Ray casting (set 3): the emissive triangles for next-event estimation, `RayEmitter`s
        /// as a `usamplerBuffer` of a texel each, sampled by power through their cumulative
        /// distribution.
        BINDING_RAY_EMITTERS = 7;
        /// A BVH node index meaning "none" (`RayUniforms.moving_root` without moving meshes),
        /// and a triangle index meaning "no hit".
        RAY_NONE = 0xFFFFFFFF;
        /// `RayTriangle.e2.w` bit: the material is cut out (`RayShading` then holds the uvs its
        /// coverage is looked up at).
        RAY_CUT_OUT = 1;
        /// `RayTriangle.e2.w` bit: a moving mesh's (not among the emitters next-event
        /// estimation samples).
        RAY_MOVING = 2;
        /// Entries of the traversal stack: one group of children per level at most.
        RAY_STACK_SIZE = 32;
        /// Workgroup size of the batched ray queries.
        RAY_GROUP_SIZE = 64;
        /// A cut-out seed (`glsl/ray/rays.glsl`) for rays that cut-outs stop whatever their
        /// coverage.
        RAY_OPAQUE = 0xFFFFFFFF;
        /// Specialization constant id of the passes that cast rays (`RayFeatures`): 1 where
        /// some triangle is cut out (`RAY_CUT_OUT`), 0 where the traversal has no coverage
        /// to look up. Features a scene lacks are constants, not uniforms: a CPU driver runs
        /// the code of every branch an invocation group meets, taken or not (Mesa 22.3's
        /// gallivm masks lanes, it never jumps), and the coverage lookup in the traversal's
        /// loop cost Cornell's path tracer 1.8x its time.
        SPEC_RAY_CUT_OUTS = 0;
        /// Specialization constant id of the passes that cast rays: 1 where the scene has
        /// moving meshes, whose BVH the rays traverse after the static one.
        SPEC_RAY_MOVING = 1;
        /// Specialization constant id of the path tracer: 1 where some material has an albedo
        /// or emission texture. The path tracer's constants, like `SPEC_RAY_CUT_OUTS`, leave
        /// out the code of what the scene does not have.
        SPEC_PATH_TEXTURES = 2;
        /// Specialization constant id of the path tracer: 1 where some material has a normal map.
        SPEC_PATH_NORMAL_MAPS = 3;
        /// Specialization constant id of the path tracer: 1 where some material has a specular
        /// lobe (Ks > 0).
        SPEC_PATH_SPECULAR = 4;
        /// Specialization constant id of the path tracer: 1 where some material refracts (d < 1, Ni > 1).
        SPEC_PATH_TRANSMISSION = 5;
        /// Specialization constant id of the path tracer: 1 where next-event estimation has
        /// emissive triangles to sample.
        SPEC_PATH_EMITTERS = 6;
        /// Specialization constant id of the path tracer: 1 for the cone component (`--cone`).
        SPEC_PATH_CONE = 7;
        /// `RayQuery.kind`: the closest hit.
        RAY_CLOSEST = 0;
        /// `RayQuery.kind`: any hit (visibility).
        RAY_ANY = 1;

        /// Batched ray queries (set 3, after the ray-casting bindings): `RayQuery[]` storage buffer.
        BINDING_QUERY_RAYS = 8;
        /// Batched ray queries (set 3): `RayHit[]` storage buffer, one per query.
        BINDING_QUERY_HITS = 9;

        /// Path tracer (set 3, after the ray-casting bindings): `PathUniforms` uniform buffer.
        BINDING_PATH_UNIFORMS = 8;
        /// Path tracer (set 3): the mean of the samples so far (rgb) and their count (a) per
        /// pixel, `rgba32f` storage image (a mean rather than a sum: a sum of a hundred
        /// thousand samples in 32-bit floats loses the last digits that matter).
        BINDING_PATH_MEAN = 9;
        /// Path tracer (set 3): rays cast since the counter was cleared, `uint[]` storage buffer
        /// (one word).
        BINDING_PATH_RAYS = 10;

        /// Irradiance probes (set 3, after the surfaces' bindings `BINDING_RAY_TRIANGLES` to
        /// `BINDING_RAY_TEXTURES`, the triangles in the scene's order): `ProbeUniforms` uniform buffer.
        BINDING_PROBE_UNIFORMS = 8;
        /// Irradiance probes (set 3): what each probe's rays met, a `usamplerBuffer` of a texel per
        /// ray (`RayHit`: the scene's triangle or `RAY_NONE`, distance, barycentrics), probe after
        /// probe, each through the texels of its equal-area octahedral map.
        BINDING_PROBE_HITS = 9;
        /// Irradiance probes (set 3): the harmonics of every probe ray's direction times its solid
        /// angle, a `samplerBuffer` of one float per ray texel and coefficient (the same for
        /// every probe).
        BINDING_PROBE_SH = 10;
        /// Irradiance probes (set 3): the probes' radiance in harmonics (λ), `vec4[]` storage buffer
        /// of `coefficients` RGB entries per probe.
        BINDING_PROBE_LAMBDA = 11;
        /// Irradiance probes (set 3): per basis vector of every cluster, a `usamplerBuffer` texel:
        /// the cluster's first probe in `BINDING_PROBE_CLUSTER_PROBES`, its probe count, the
        /// vector's row in `BINDING_PROBE_PROJECTIONS`, and the cluster.
        BINDING_PROBE_VECTORS = 12;
        /// Irradiance probes (set 3): each cluster's probes, a `usamplerBuffer` of one index each.
        BINDING_PROBE_CLUSTER_PROBES = 13;
        /// Irradiance probes (set 3): the clusters' (Σ V^T)_k rows, a `samplerBuffer` of floats.
        BINDING_PROBE_PROJECTIONS = 14;
        /// Irradiance probes (set 3): the clusters' basis vectors b this frame, `vec4[]` storage
        /// buffer, one RGB entry per basis vector.
        BINDING_PROBE_BASIS = 15;
        /// Irradiance probes (set 3): per receiver, a `usamplerBuffer` texel: its lightmap texel
        /// (x | y << 16), where its coordinates start, its cluster's first basis vector, its
        /// basis count.
        BINDING_PROBE_RECEIVERS = 16;
        /// Irradiance probes (set 3): the receivers' coordinates (rows of U_k) and, after them, each
        /// receiver's sky factor, a `samplerBuffer` of floats.
        BINDING_PROBE_COORDINATES = 17;
        /// Irradiance probes (set 3): this frame's lightmap, the irradiance / π of each receiver,
        /// `rgba16f` storage image.
        BINDING_PROBE_LIGHTMAP = 18;
        /// Irradiance probes (set 3): the same lightmap, `sampler2D` (bilinear).
        BINDING_PROBE_LIGHTMAP_SAMPLED = 19;
        /// Irradiance probes (set 3): last frame's lightmap, `sampler2D` (bilinear): the bounces.
        BINDING_PROBE_LIGHTMAP_PREVIOUS = 20;
        /// Irradiance probes (set 3): the lightmap uvs of every triangle's corners in the scene's
        /// order, a `samplerBuffer` of two floats each (negative for a moving mesh's).
        BINDING_PROBE_CORNER_UVS = 21;
        /// Irradiance probes (set 3): the probes' positions, a `samplerBuffer` of `vec4`s (xyz).
        BINDING_PROBE_POSITIONS = 22;
        /// Irradiance probes (set 3): what each probe ray met, decoded once (`surfaces.comp`), two
        /// `uvec4`s per ray: position and albedo (RGBA8; alpha 0 for a miss); the normal towards
        /// the probe (octahedral snorm16), the lightmap uv (unorm16, all ones for none) and the
        /// emitted radiance (half floats), `uimageBuffer` (rgba32ui) storage texel buffer.
        BINDING_PROBE_SURFACES = 23;
        /// Irradiance probes (set 3): the same buffer read by the relight, a `usamplerBuffer`.
        BINDING_PROBE_SURFACES_READ = 24;
        /// Irradiance probes (set 3): each lightmap texel's receiver's cluster (`RAY_NONE`: no
        /// receiver), a `usamplerBuffer` of one index each, row by row (the clusters' debug view).
        BINDING_PROBE_TEXEL_CLUSTERS = 25;
        /// Irradiance probes (set 3): the grid of spatial receivers' irradiance / π, an
        /// `rgba16f` 3D storage image of the grid's points, its six directions' slabs one above
        /// the other along z (`gi::probes::grid::DIRECTIONS`).
        BINDING_PROBE_GRID = 26;
        /// Irradiance probes (set 3): the same image sampled (linear, clamped to the edge).
        BINDING_PROBE_GRID_SAMPLED = 27;
        /// Irradiance probes (set 3): what this frame computes of the grid, `uint[]` storage
        /// buffer: the count of the spatial clusters' basis vectors listed, the count of the
        /// spatial receivers listed, then the vectors' indices and the receivers'.
        BINDING_PROBE_GRID_ACTIVE = 28;
        /// Irradiance probes (set 3): this frame's level of detail (Sedláček 2019, 4.2), `uint[]`
        /// storage buffer: per probe, the harmonic coefficients its relight projects onto
        /// (low 16 bits) and the stride of its rays along each axis of its map (high 16 bits);
        /// then (from `probe_count` on) per cluster, the coefficients of each probe its basis
        /// vectors read.
        BINDING_PROBE_LOD = 29;
        /// Irradiance probes (set 3): mips 1 to 3 of this frame's lightmap (Sedláček 2019,
        /// 4.2.3), an array of three `rgba16f` storage images.
        BINDING_PROBE_LIGHTMAP_LEVELS = 30;
        /// Irradiance probes (set 3): what this frame computes of the lightmap
        /// (`gi::probes::levels`), `uint[]` storage buffer: the counts of the receivers and of
        /// the coarser levels' texels listed, then the receivers' indices, then per texel its
        /// coordinates (x | y << 16) and its receiver with its level (receiver | level << 30).
        BINDING_PROBE_WORK = 31;
        /// Irradiance probes (set 3): `ProbeView` uniform buffer.
        BINDING_PROBE_VIEW = 32;
        /// Irradiance probes (set 3): the same λ as `BINDING_PROBE_LAMBDA`, as a `samplerBuffer`
        /// of an RGB texel each, for the basis pass.
        BINDING_PROBE_LAMBDA_TEXELS = 33;
        /// Workgroup size of the probe passes.
        PROBE_GROUP_SIZE = 64;

    }

    /// Per-frame constants.
    struct FrameUniforms {
        /// World to view.
        mat4 view,
        /// View to clip (Vulkan depth 0..1, row 0 at the top).
        mat4 proj,
        /// World to clip.
        mat4 view_proj,
        /// Clip to world.
        mat4 inv_view_proj,
        /// xyz camera position, w time in seconds.
        vec4 camera_position,
        /// rgb constant sky radiance, w exposure as a linear scale.
        vec4 sky_radiance,
        /// Render target width in pixels.
        uint width,
        /// Render target height in pixels.
        uint height,
        /// Number of entries in the light buffer.
        uint light_count,
        /// `FLAG_*` bits.
        uint flags,
        /// `DEBUG_*`: what the image shows.
        uint debug_view,
        /// Mip level of the voxel debug views (0 = the voxels themselves).
        uint debug_level,
        /// Unused.
        uint pad0,
        /// Unused.
        uint pad1,
    }

    /// One light.
    struct GpuLight {
        /// xyz position (point, spot).
        vec4 position,
        /// rgb W/sr (point, spot) or W/m^2 (directional).
        vec4 intensity,
        /// xyz direction of travel (directional) or spot axis; w cosine of the outer angle.
        vec4 direction,
        /// `LIGHT_*`.
        uint kind,
        /// First `ShadowView` of this light.
        uint first_shadow_view,
        /// Number of shadow views: 0 (no shadow), 1 (spot, directional) or 6 (point).
        uint shadow_view_count,
        /// Cosine of the spot's inner angle.
        float cos_inner,
    }

    /// One shadow-map layer: a camera looking from a light.
    struct ShadowView {
        /// World to the layer's clip space.
        mat4 view_proj,
        /// xyz light position or, for orthographic views, the direction of travel; w 1 if orthographic.
        vec4 origin,
        /// World size of one texel at distance 1 (perspective) or everywhere (orthographic).
        float texel_size,
        /// Shadow map layer index.
        uint layer,
        /// Texels of the view along each side (views of different lights may have different resolutions; the layers fit the largest).
        uint resolution,
        /// Texel column of the view's tile in its layer (ShadowAtlas).
        uint offset_x,
        /// Texel row of the view's tile in its layer.
        uint offset_y,
        /// Unused.
        uint pad0,
        /// Unused.
        uint pad1,
        /// Unused.
        uint pad2,
    }

    /// One material.
    struct GpuMaterial {
        /// rgb Kd albedo, a dissolve (opacity).
        vec4 albedo,
        /// rgb Ks, a roughness.
        vec4 specular,
        /// rgb emitted radiance, a index of refraction.
        vec4 emission,
        /// Index of the albedo texture, or `NO_TEXTURE`.
        uint albedo_texture,
        /// Cut-out coverage texture or `NO_TEXTURE`.
        uint coverage_texture,
        /// Tangent-space normal map or `NO_TEXTURE`.
        uint normal_texture,
        /// Emission texture (multiplies `emission.rgb`) or `NO_TEXTURE`.
        uint emission_texture,
    }

    /// The voxel grid (dense, or the octree's effective grid) and the cone settings.
    struct VctUniforms {
        /// xyz world position of the grid's minimum corner, w voxel size.
        vec4 origin,
        /// Voxels per axis.
        uint resolution,
        /// Mip levels of the directional volumes (resolution / 2 down to 2).
        uint directional_levels,
        /// Emission is stored divided by this (the scene's largest emitted radiance).
        float emission_range,
        /// Step of the cones gathering light for the pixels (diffuse, specular, refraction), as a fraction of the cone diameter.
        float step_factor,
        /// Step of the voxel bounce's diffuse cones, as a fraction of the cone diameter.
        float bounce_step_factor,
        /// Step of the soft-shadow cones, as a fraction of the cone diameter.
        float shadow_step_factor,
        /// tan of half the diffuse cone aperture.
        float diffuse_tan_half,
        /// Cones stop after this distance in world units.
        float max_distance,
        /// Cones of the diffuse gather: one along the normal, the rest in a ring at 57.5 degrees.
        uint diffuse_cones,
        /// tan of half the aperture of the soft-shadow cones.
        float shadow_tan_half,
        /// Occluders this far away (world units) occlude half as much as adjacent ones.
        float ao_distance,
        /// 1: the diffuse (wide) cones step level by level, each sample twice as wide as the last (Dřínovský 2013, 5.6); 0: by their step factor of their diameter (`step_factor` for the pixels, `bounce_step_factor` in the voxel bounce), as the other cones.
        uint wide_steps_by_level,
        /// 1: the dense grid's compact pass adds the static meshes' fragment sums (`BINDING_DENSE_STATIC_SUMS`) to this frame's (a scene with moving meshes, static meshes voxelized once).
        uint static_sums,
        /// The one diffuse cone the screen's gather traces, its radiance alone (`--cone`: 0 along the normal, 1.. the ring's), or 0xffffffff for the whole gather.
        uint only_cone,
        /// 1: the diffuse gather weighs its cones by the cosine (`--cosine-cones`): the ring cones' sub-cones by their axes' cosine to the normal, each cone by its region's share of the cosine-weighted hemisphere; 0: each cone's plain mean, 1 along the normal and 1/2 in the ring.
        uint cosine_cones,
        /// Entries of `BINDING_VCT_EMITTERS`: the emitters whose light the cones' passes sample.
        uint emitter_count,
    }

    /// A planar group of emissive triangles whose light voxel cone tracing samples: their exact unoccluded irradiance, times one soft-shadow cone's visibility (`glsl/gi/vct/emitters.glsl`).
    struct VctEmitter {
        /// xyz the unit normal the triangles emit along (their winding's), w its plane's offset: points x of the plane have dot(xyz, x) = w.
        vec4 plane,
        /// rgb the emitted radiance (Ke times the scene's scale), a unused.
        vec4 radiance,
        /// The first of its triangles in `BINDING_VCT_EMITTER_TRIANGLES`.
        uint first_triangle,
        /// How many triangles it has.
        uint triangle_count,
        /// On the first piece of an emitter cut into pieces (`--emitter-pieces`), how many pieces it was cut into, this one and those right after it; 0 on the others.
        uint group_pieces,
        /// Unused.
        uint pad0,
    }

    /// A triangle of a sampled emitter, in world space, wound so that it emits along its emitter's plane normal.
    struct VctEmitterTriangle {
        /// xyz the first vertex, w unused.
        vec4 v0,
        /// xyz the second vertex, w unused.
        vec4 v1,
        /// xyz the third vertex, w unused.
        vec4 v2,
    }

    /// What the upsample needs to know of the reduced-resolution terms a technique gathered.
    struct ScreenUniforms {
        /// The terms are sampled at one pixel of each `indirect_scale`² block.
        uint indirect_scale,
        /// The world distance off a pixel's plane at which a sample's weight falls to 1/e (the technique's spatial resolution: two voxels for the cone tracer).
        float plane_tolerance,
        /// Unused.
        uint pad0,
        /// Unused.
        uint pad1,
    }

    /// Head of the occupied-voxel list; the voxels follow as `uint` (x | y << 10 | z << 20).
    struct VoxelListHeader {
        /// Indirect dispatch: workgroups of `VOXEL_LIST_GROUP_SIZE` covering `count`.
        uint groups_x,
        /// Indirect dispatch: 1.
        uint groups_y,
        /// Indirect dispatch: 1.
        uint groups_z,
        /// Voxels in the list.
        uint count,
    }

    /// The counters of the sparse voxel octree's pools; the level table follows.
    struct OctreeCounters {
        /// Indirect dispatch over the stored fragments: workgroups of `OCTREE_GROUP_SIZE`.
        uint fragment_groups_x,
        /// Indirect dispatch: 1.
        uint fragment_groups_y,
        /// Indirect dispatch: 1.
        uint fragment_groups_z,
        /// Fragments produced (more than `fragment_capacity` when the list overflowed).
        uint fragment_count,
        /// Records the fragment list holds.
        uint fragment_capacity,
        /// Nodes allocated (more than `node_capacity` after an overflow).
        uint node_count,
        /// Nodes the node pool holds.
        uint node_capacity,
        /// `OCTREE_OVERFLOW_*` bits.
        uint overflow,
        /// Leaf bricks allocated.
        uint leaf_bricks,
        /// Leaf bricks the leaf pool holds.
        uint leaf_brick_capacity,
        /// Interior bricks allocated.
        uint interior_bricks,
        /// Interior bricks the interior pool holds.
        uint interior_brick_capacity,
        /// Bricks per edge of the leaf pool image: brick i sits at (i % side, i / side % side, i / side²).
        uint leaf_pool_side,
        /// Bricks per row and per column of the interior pool image.
        uint interior_pool_side,
        /// Occupied leaf voxels given sums (of their fragments' attributes).
        uint leaf_voxels,
        /// Leaf voxels the sums buffer holds.
        uint leaf_voxel_capacity,
        /// Entries of each of the two carry tables (a power of two; 0: no carry).
        uint carry_capacity,
        /// The carry table this frame writes (the other holds last frame's).
        uint carry_parity,
        /// The first fragment the octree passes read: 0 in a build, the static fragments' count in a frame (only the moving meshes' fragments are inserted).
        uint fragment_base,
        /// Nodes of the static part (built once, restored every frame; the dynamic part's follow). A static leaf that a frame's fragments reach is copied to a new brick and new sums.
        uint static_node_count,
        /// Leaf bricks of the static part: their attributes are kept; later bricks are filled every frame.
        uint static_leaf_bricks,
        /// Nodes each update list holds.
        uint update_capacity,
        /// 1: voxel shading and the bounces store every change of a leaf's radiance, however small (the frame after a build, which computes every bounce from scratch, as the dense grid does); 0: only changes beyond `RADIANCE_CHANGE` (later frames, so that converged bounces stop).
        uint exact_stores,
        /// Unused.
        uint pad4,
    }

    /// One level of the octree: its nodes in two contiguous runs of the node pool, the static part's (built once) and those appended since (a build appends every level but the root; a frame appends the moving meshes' nodes after the static part).
    struct OctreeLevel {
        /// Indirect dispatch over the level's nodes, both runs: workgroups of `OCTREE_GROUP_SIZE`.
        uint groups_x,
        /// Indirect dispatch: 1.
        uint groups_y,
        /// Indirect dispatch: 1.
        uint groups_z,
        /// Index of the level's first static node.
        uint first,
        /// Static nodes in the level.
        uint count,
        /// Index of the level's first appended node.
        uint appended_first,
        /// Appended nodes in the level.
        uint appended_count,
        /// Unused.
        uint pad0,
        /// Indirect dispatch over the appended nodes only.
        uint appended_groups_x,
        /// Indirect dispatch: 1.
        uint appended_groups_y,
        /// Indirect dispatch: 1.
        uint appended_groups_z,
        /// Unused.
        uint pad1,
    }

    /// One update list's head: its nodes follow in `BINDING_OCTREE_UPDATES`.
    struct OctreeUpdateList {
        /// Indirect dispatch over the list: workgroups of `OCTREE_GROUP_SIZE`.
        uint groups_x,
        /// Indirect dispatch: `OCTREE_LIST_SLICES` (1 on a CPU driver).
        uint groups_y,
        /// Indirect dispatch: 1.
        uint groups_z,
        /// Nodes in the list.
        uint count,
    }

    /// Push constants of voxel shading.
    struct InjectPush {
        /// 1: store the radiance (0: a bounce rewrites it before the next filter).
        uint store_radiance,
        /// Octree, 1: shade only the voxels whose light can have changed since they were last shaded (the lights and shadow views are as then): in new bricks, or with a light's path through the region.
        uint cull,
        /// Octree around moving meshes, 1: a stored radiance keeps the light the voxel's bounces gathered (0 in the frame after a build).
        uint keep_indirect,
        /// Unused.
        uint pad0,
        /// With `cull`: the first voxel (xyz) of the region where moving meshes were last frame or are now.
        ivec4 region_min,
        /// With `cull`: the last voxel (xyz) of that region (below `region_min`: none).
        ivec4 region_max,
    }

    /// The bounce's dispatch in a static octree, after the update lists' heads: the voxel list's while anything changed since the last bounce, none once the bounces have converged.
    struct OctreeBounceDispatch {
        /// Indirect dispatch: the voxel list's workgroups, or 0.
        uint groups_x,
        /// Indirect dispatch: 1.
        uint groups_y,
        /// Indirect dispatch: 1.
        uint groups_z,
        /// 1: a node's radiance or a voxel's direct light changed since the last bounce.
        uint changed,
    }

    /// Push constants of the octree passes that work on one level.
    struct OctreePush {
        /// The level.
        uint level,
        /// Which of the level's nodes: `OCTREE_OVER_LEVEL`, `OCTREE_OVER_APPENDED` or `OCTREE_OVER_LIST`.
        uint over,
        /// With `OCTREE_OVER_LIST`: the update list.
        uint list,
        /// Unused.
        uint pad2,
        /// `mark.comp`: the first voxel (xyz) of the region where moving meshes were or are.
        ivec4 region_min,
        /// `mark.comp`: the last voxel (xyz) of that region (below `region_min`: none).
        ivec4 region_max,
    }

    /// A node of a compressed wide BVH (CWBVH, Ylitie et al. 2017; obvhs's `CwBvhNode`, byte for byte): eight children, their boxes quantized to bytes in the node's frame.
    struct BvhNode {
        /// xyz the frame's origin (the node's box minimum, float bits); w the frame's scale per axis as three exponent bytes, then the mask of the children that are inner nodes.
        uvec4 origin_scale,
        /// x the first inner child's node, y the first triangle of the children's leaves, zw the children's eight meta bytes (an inner child's slot + 24 with the bits 001 above; a leaf's first triangle, relative to y, with its count in unary above).
        uvec4 children,
        /// The children's quantized box bounds in x: eight minimum bytes (xy), eight maximum bytes (zw).
        uvec4 bounds_x,
        /// The same in y.
        uvec4 bounds_y,
        /// The same in z.
        uvec4 bounds_z,
    }

    /// A triangle as the intersection test reads it.
    struct RayTriangle {
        /// xyz the first vertex (world space), w its material (the bits of a uint).
        vec4 v0,
        /// xyz the second vertex minus the first, w the triangle's index in the scene (meshes in order, triangles in index order; the bits of a uint).
        vec4 e1,
        /// xyz the third vertex minus the first, w `RAY_CUT_OUT` and `RAY_MOVING` bits (the bits of a uint).
        vec4 e2,
    }

    /// A triangle's shading attributes: its vertices' normals (world space) and uvs.
    struct RayShading {
        /// xyz the first vertex's normal, w its u.
        vec4 n0,
        /// xyz the second vertex's normal, w its v.
        vec4 n1,
        /// xyz the third vertex's normal, w the second vertex's u.
        vec4 n2,
        /// The second vertex's v, the third vertex's u and v; w unused.
        vec4 uv,
    }

    /// An emissive triangle for next-event estimation.
    struct RayEmitter {
        /// The triangle (an index into `BINDING_RAY_TRIANGLES`).
        uint triangle,
        /// The cumulative distribution up to and including this emitter: power over the total power (the last is 1).
        float cdf,
        /// Unused.
        uint pad0,
        /// Unused.
        uint pad1,
    }

    /// What every ray cast needs beyond the buffers.
    struct RayUniforms {
        /// The static meshes' BVH's root: node 0, or `RAY_NONE` when every mesh moves.
        uint static_root,
        /// The moving meshes' BVH's root, after the static meshes' nodes, or `RAY_NONE` without moving meshes.
        uint moving_root,
        /// Entries of `BINDING_RAY_EMITTERS`.
        uint emitter_count,
        /// The emitters' total power (sum of area x largest emitted radiance).
        float emitter_power,
        /// World distance rays start from their surface: a small fraction of the scene's size.
        float epsilon,
        /// Unused.
        uint pad0,
        /// Unused.
        uint pad1,
        /// Unused.
        uint pad2,
    }

    /// One batched ray query.
    struct RayQuery {
        /// xyz origin, w the smallest distance counted.
        vec4 origin_tmin,
        /// xyz direction (unit length), w the largest distance counted.
        vec4 direction_tmax,
        /// `RAY_CLOSEST` or `RAY_ANY`.
        uint kind,
        /// Unused.
        uint pad0,
        /// Unused.
        uint pad1,
        /// Unused.
        uint pad2,
    }

    /// A batched query's answer.
    struct RayHit {
        /// The triangle hit (its index in the scene, `RayTriangle.e1.w`), `RAY_NONE` for none; for `RAY_ANY`, 0 where something was hit.
        uint triangle,
        /// Distance along the ray.
        float t,
        /// Barycentric coordinate of the second vertex.
        float u,
        /// Barycentric coordinate of the third vertex.
        float v,
    }

    /// The path tracer's settings.
    struct PathUniforms {
        /// Longest path in vertices counted from the camera (Mitsuba's `max_depth`: 2 is direct light only); 0 for no limit.
        uint max_depth,
        /// Russian roulette starts at this depth.
        uint rr_depth,
        /// The random sequence's seed.
        uint seed,
        /// 1: cut-outs stop shadow rays whatever their coverage (the references' convention: their next-event estimation ignores Mitsuba's masks).
        uint opaque_shadow_cut_outs,
        /// The cone component (`--cone`): the camera's hit gathers albedo times the mean radiance within the cone tracer's diffuse cone `cone` (0 along the normal, 1..`ring` the ring's), weighted by the cosine to the normal where `cone_cosine` is 1, instead of its light; 0xffffffff for none.
        uint cone,
        /// Cones in the diffuse gather's ring.
        uint ring,
        /// cos of the diffuse cones' half aperture.
        float cone_cos_half,
        /// 1: the cone component weighs its rays by the cosine to the normal, as `--cosine-cones` weighs the gather's cones; 0: their plain mean.
        uint cone_cosine,
    }

    /// Push constants of the dense grid's filter by pairs: one level, every direction, per dispatch.
    struct FilterPush {
        /// The directional level written: 0 is the first above the base, each cell 2 << level voxels wide.
        uint level,
        /// 1: also the cells' surface planes and coverage (`Store::planes`, `PLANE_SLOT`).
        uint planes,
    }

    /// Push constants of the dense grid's filter by rows: one level of one direction per dispatch.
    struct FilterRowsPush {
        /// The directional level written: 0 is the first above the base, each cell 2 << level voxels wide.
        uint level,
        /// The direction filtered, 0..5: +X -X +Y -Y +Z -Z.
        uint direction,
    }

    /// Push constants of cone tracing: the lattice cones (`--lattice-cones`) this dispatch traces; the first dispatch also traces every other cone of the pass.
    struct ConeTracePush {
        /// The first lattice cone of this dispatch. The first dispatch (first cone 0, no emitters) starts the gather afresh; later dispatches add to what the ones before left in `BINDING_SCREEN_INDIRECT`.
        uint first_cone,
        /// Lattice cones this dispatch traces.
        uint cone_count,
        /// The first sampled emitter whose light this dispatch adds.
        uint first_emitter,
        /// Sampled emitters whose light this dispatch adds (each with its visibility cone).
        uint emitter_count,
    }

    /// Push constants of the path tracer: this dispatch's share of the samples.
    struct PathPush {
        /// Samples already in `BINDING_PATH_MEAN`: 0 starts afresh.
        uint samples_done,
        /// Samples each pixel takes in this dispatch (0: only the mean so far is written).
        uint samples_now,
        /// Unused.
        uint pad0,
        /// Unused.
        uint pad1,
    }

    /// The irradiance probes' counts, as their passes read them.
    struct ProbeUniforms {
        /// Probes.
        uint probe_count,
        /// Relight rays per probe (the texels of all its relight maps).
        uint rays_per_probe,
        /// Harmonic coefficients per colour channel, (order + 1)².
        uint coefficients,
        /// Receivers.
        uint receiver_count,
        /// Basis vectors of the lightmap's clusters (the grid's follow them).
        uint vector_count,
        /// Where the receivers' sky factors start in `BINDING_PROBE_COORDINATES`.
        uint sky_offset,
        /// 1: the relight adds last frame's lightmap times albedo (the bounces).
        uint bounces,
        /// The radius of the spheres the probes' debug view draws, in world units.
        float debug_radius,
        /// Per level of detail, where the relight map it reads begins among a probe's rays.
        uvec4 relight_first,
        /// Per level of detail, the side of the relight map it reads.
        uvec4 relight_side,
        /// The grid of spatial receivers: its points along x, y and z, and their count (0: no grid); the receivers of direction d and point p are receiver `receiver_count + d * grid_size.w + p`.
        uvec4 grid_size,
        /// The grid's box's least corner (xyz).
        vec4 grid_min,
        /// One over the grid's box's extent (xyz; 0 along a flat axis).
        vec4 grid_inverse_extent,
    }

    /// Where this frame's and the last frame's lightmaps are fine (Sedláček 2019, 4.2.4).
    struct ProbeView {
        /// This frame's camera (xyz) and whether the level of detail is on (w: 1 or 0).
        vec4 camera,
        /// The last frame's, the same way.
        vec4 previous_camera,
        /// This frame's view direction (xyz, unit) and the cosine of the half-angle of the cone around it that holds the view frustum (w): the level of detail's zones.
        vec4 forward,
        /// The last frame's, the same way.
        vec4 previous_forward,
        /// The distances where the lightmap's levels 1, 2 and 3 begin (xyz).
        vec4 distances,
    }

    /// Push constants of every mesh draw.
    struct DrawPush {
        /// Object to world.
        mat4 model,
        /// Index into the material buffer.
        uint material,
        /// Index into the shadow view buffer (shadow pass only).
        uint shadow_view,
        /// The mesh's first index in the index buffer (`BINDING_VCT_INDICES` in compute voxelization; a third of it is the mesh's first triangle's index in the scene).
        uint first_index,
        /// Added to the mesh's indices (compute voxelization only).
        uint vertex_offset,
    }
}
