#version 460
// Cut-out surfaces (map_d) cast no shadow where they are cut, or, under the references'
// conventions (OPAQUE_CUT_OUTS), a whole shadow: their Mitsuba integrator ignores masks on
// the rays of next-event estimation.
#include "common/scene.glsl"
#include "common/mesh_push.glsl"

layout(constant_id = SPEC_SHADOW_OPAQUE_CUT_OUTS) const bool OPAQUE_CUT_OUTS = false;

layout(location = 0) in vec2 in_uv;

void main() {
    if (!OPAQUE_CUT_OUTS && material_coverage(materials[draw.material], in_uv) < CUTOUT_THRESHOLD) {
        discard;
    }
}
