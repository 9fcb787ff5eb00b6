#version 460
// variant: OCTREE
// Debug views of the voxels: each pixel marches its camera ray through the grid in
// cells of 2^debug_level voxels and shows the first cell that holds geometry: its mean
// albedo, mean normal (xyz * 0.5 + 0.5), or radiance composited front to back from the
// anisotropic level facing the ray (the base voxels at level 0). With OCTREE the
// voxels are looked up in the octree, whose nodes at that level the octree view draws,
// each in its own colour, darker towards its edges.
#include "gi/vct/cones.glsl"

layout(local_size_x = SCREEN_GROUP_SIZE, local_size_y = SCREEN_GROUP_SIZE) in;
layout(set = SET_GI, binding = BINDING_VCT_ALBEDO, r32ui) uniform readonly uimage3D voxel_albedo;
layout(set = SET_GI, binding = BINDING_VCT_NORMAL, r32ui) uniform readonly uimage3D voxel_normal;
layout(set = SET_SCREEN, binding = BINDING_SCREEN_RADIANCE, rgba32f) uniform writeonly image2D screen_radiance;

// Mean albedo or normal of the occupied voxels of `cell` (edge `size` voxels), from at
// most 4^3 of them; alpha is the fraction occupied.
vec4 cell_mean(ivec3 cell, int size, bool normal) {
    int stride = max(size / 4, 1);
    vec3 sum = vec3(0.0);
    float occupied = 0.0;
    float count = 0.0;
    for (int z = 0; z < size; z += stride) {
        for (int y = 0; y < size; y += stride) {
            for (int x = 0; x < size; x += stride) {
                ivec3 v = cell * size + ivec3(x, y, z);
                count += 1.0;
#ifdef OCTREE
                ivec3 texel;
                if (!leaf_texel(uvec3(v), texel)) {
                    continue;
                }
#else
                ivec3 texel = v;
#endif
                vec4 albedo = unpack_rgba8(imageLoad(voxel_albedo, texel).r);
                if (albedo.a > 0.0) {
                    occupied += 1.0;
                    sum += normal ? unpack_rgba8(imageLoad(voxel_normal, texel).r).rgb : albedo.rgb;
                }
            }
        }
    }
    return occupied > 0.0 ? vec4(sum / (255.0 * occupied), occupied / count) : vec4(0.0);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= int(frame.width) || pixel.y >= int(frame.height)) {
        return;
    }
    vec3 eye = frame.camera_position.xyz;
    vec3 dir = normalize(pixel_position(pixel, 1.0) - eye);
    int level = min(int(frame.debug_level), int(vct.directional_levels));
    int size = 1 << level;
    float cell = vct.origin.w * float(size);
    int cells = int(vct.resolution) / size;
    vec3 lo = vct.origin.xyz;
    vec3 hi = lo + vct.origin.w * float(vct.resolution);
    // Where the ray meets the grid's cube.
    vec3 inv = 1.0 / dir;
    vec3 t0 = (lo - eye) * inv;
    vec3 t1 = (hi - eye) * inv;
    float t_in = max(max(min(t0.x, t1.x), min(t0.y, t1.y)), max(min(t0.z, t1.z), 0.0));
    float t_out = min(min(max(t0.x, t1.x), max(t0.y, t1.y)), max(t0.z, t1.z));
    vec4 acc = vec4(0.0);
    float grid_size = vct.origin.w * float(vct.resolution);
    for (float t = t_in + 0.25 * cell; t < t_out && acc.a < 0.99; t += 0.25 * cell) {
        vec3 at = eye + dir * t;
        ivec3 c = clamp(ivec3(floor((at - lo) / cell)), ivec3(0), ivec3(cells - 1));
#ifdef OCTREE
        if (frame.debug_view == DEBUG_OCTREE_NODES) {
            // debug_level 0 shows the leaves, 1 their parents, and so on up.
            uint node_level = octree_depth() - 1u - min(uint(level), octree_depth() - 1u);
            uint shift = octree_depth() - node_level;
            uvec3 v = uvec3(clamp(ivec3(floor((at - lo) / vct.origin.w)), ivec3(0), ivec3(int(vct.resolution) - 1)));
            uint node = find_node((v >> shift) << shift, node_level);
            if (node != OCTREE_NO_NODE && node_bricks[node] != OCTREE_NO_BRICK) {
                float node_size = vct.origin.w * float(1u << shift);
                vec3 local = fract((at - lo) / node_size);
                vec3 edge = min(local, 1.0 - local);
                int near_edges = int(edge.x < 0.06) + int(edge.y < 0.06) + int(edge.z < 0.06);
                uint h = node * 2654435761u;
                vec3 colour = 0.35 + 0.65 * vec3(h & 0xffu, (h >> 8) & 0xffu, (h >> 16) & 0xffu) / 255.0;
                acc = vec4(near_edges >= 2 ? colour * 0.15 : colour, 1.0);
            }
            continue;
        }
#endif
        if (frame.debug_view == DEBUG_VOXEL_RADIANCE) {
            // The cell's centre, so that the view shows the cells unfiltered.
            vec3 uvw = (vec3(c) + 0.5) * cell / grid_size;
            // At level 0 the voxels themselves, opaque where occupied: a cone meets them
            // across their coverage (sample_base_snapped), through which a thin ray
            // passing a turned plane's voxels at their corners would see nothing.
            vec4 s = level == 0 ? sample_base(uvw) : sample_voxels(uvw, dir, float(level));
            float a = 1.0 - pow(1.0 - clamp(s.a, 0.0, 0.9999), 0.25);
            acc.rgb += (1.0 - acc.a) * (s.a > 1e-4 ? s.rgb * (a / s.a) : vec3(0.0));
            acc.a += (1.0 - acc.a) * a;
        } else {
            vec4 mean = cell_mean(c, size, frame.debug_view == DEBUG_VOXEL_NORMAL);
            if (mean.a > 0.0) {
                acc = vec4(mean.rgb, 1.0);
            }
        }
    }
    imageStore(screen_radiance, pixel, vec4(acc.rgb, 1.0));
}
