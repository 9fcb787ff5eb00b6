#version 460
// Cut-out surfaces (map_d) cast no shadow where they are cut.
#include "common/scene.glsl"
#include "common/mesh_push.glsl"

layout(location = 0) in vec2 in_uv;

void main() {
    if (material_coverage(materials[draw.material], in_uv) < CUTOUT_THRESHOLD) {
        discard;
    }
}
