// Random numbers for Monte Carlo sampling: a PCG generator (O'Neill 2014) per pixel and
// sample, seeded by hashing both, so that a sample's numbers do not depend on how the
// samples are split between dispatches.
#ifndef RANDOM_GLSL
#define RANDOM_GLSL

// The PCG hash (Jarzynski & Olano 2020): one 32-bit word to a well-mixed other.
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The generator's state for sample `index` of `pixel` in the sequence `seed`.
uint random_seed(uvec2 pixel, uint index, uint seed) {
    return pcg_hash(pcg_hash(pcg_hash(pixel.x ^ pcg_hash(seed)) ^ pixel.y) ^ index);
}

// The next number in [0, 1), advancing `state`.
float random_next(inout uint state) {
    state = state * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    word = (word >> 22u) ^ word;
    return float(word >> 8u) * (1.0 / 16777216.0);
}
#endif
