// RGBA8 moving averages in r32ui images (Crassin & Green 2012), so that overlapping
// samples of a voxel average.
#ifndef AVERAGE_GLSL
#define AVERAGE_GLSL
#include "gi/voxels.glsl"

// Defines `void NAME(ivec3 texel, vec3 value)`, which adds `value` (channels 0..255) to
// the running average in IMAGE; alpha counts the samples, saturating at 255. The retry
// loop is bounded: under heavy contention on a GPU a sample may be dropped rather than
// hang. GLSL cannot pass an r32ui image with its format to a function, hence one function
// per image.
#define DEFINE_AVERAGE(NAME, IMAGE)                                          \
    void NAME(ivec3 voxel, vec3 value) {                                     \
        uint written = pack_rgba8(vec4(value, 1.0));                         \
        uint expected = 0u;                                                  \
        for (int attempt = 0; attempt < 256; attempt++) {                    \
            uint found = imageAtomicCompSwap(IMAGE, voxel, expected, written); \
            if (found == expected) {                                         \
                return;                                                      \
            }                                                                \
            expected = found;                                                \
            vec4 current = unpack_rgba8(found);                              \
            float count = min(current.a + 1.0, 255.0);                       \
            vec3 mean = current.rgb + (value - current.rgb) / count;         \
            written = pack_rgba8(vec4(mean, count));                         \
        }                                                                    \
    }
#endif
