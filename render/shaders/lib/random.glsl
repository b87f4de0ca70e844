// Per-texel pseudo-random numbers. Seeds come from the texel index, the map index and the
// frame number (seed 003 Sec. 3.2) hashed together; each draw advances a PCG state
// (O'Neill 2014, the RXS-M-XS output of "Hash Functions for GPU Rendering", JCGT 2020).

uint lr_hash(uint x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

uint lr_seed(uint texel, uint map, uint frame, uint base)
{
    return lr_hash(texel ^ lr_hash(map + 0x9e3779b9u * lr_hash(frame ^ lr_hash(base))));
}

// Uniform in [0, 1) with 24 bits.
float lr_rand(inout uint state)
{
    state = state * 747796405u + 2891336453u;
    uint w = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    w = (w >> 22u) ^ w;
    return float(w >> 8u) * (1.0 / 16777216.0);
}
