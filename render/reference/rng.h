/* lamprig — the reference renderer's random numbers: PCG32 streams (header-only, hot path).
 *
 * PCG32 is O'Neill 2014, "PCG: a family of simple fast space-efficient statistically good
 * algorithms for random number generation" (pcg32_random_r and pcg32_srandom_r of the
 * reference implementation). Every path owns one stream, keyed by (seed, stream id): results
 * then depend on which samples are drawn, never on which thread draws them.
 */
#ifndef LR_REF_RNG_H
#define LR_REF_RNG_H

#include <stdint.h>

typedef struct lr_ref_rng {
    uint64_t state, inc;
} lr_ref_rng;

/* SplitMix64 finaliser (Steele, Lea, Flood 2014): spreads counters into unrelated seeds. */
static inline uint64_t lr_ref_mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static inline uint32_t lr_ref_rng_u32(lr_ref_rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xorshifted = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31u));
}

/* Seeds the stream identified by (seed, stream); distinct pairs give independent streams. */
static inline void lr_ref_rng_seed(lr_ref_rng *r, uint64_t seed, uint64_t stream)
{
    /* The increment selects one of 2^63 sequences; the state start is decorrelated from it by
     * mixing both, so neighbouring stream ids do not start at related states. */
    r->state = 0;
    r->inc = (lr_ref_mix64(stream ^ 0x5851f42d4c957f2dULL) << 1u) | 1u;
    lr_ref_rng_u32(r);
    r->state += lr_ref_mix64(seed ^ lr_ref_mix64(stream));
    lr_ref_rng_u32(r);
}

/* Uniform in [0, 1) with 53 random bits (two draws). */
static inline double lr_ref_rng_uniform(lr_ref_rng *r)
{
    uint64_t a = lr_ref_rng_u32(r) >> 5, b = lr_ref_rng_u32(r) >> 6; /* 27 + 26 bits */
    return (double)(a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
}

#endif
