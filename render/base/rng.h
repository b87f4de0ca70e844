/* lamprig — counter-based random numbers for the CPU twin, the light paths and the models.
 * Every sample stream is a pure function of its key (seed, map, texel, frame, band), so
 * results do not depend on which thread ran what.
 * splitmix64 (Steele, Lea, Flood 2014) as hash and generator. Header-only. */
#ifndef LR_BASE_RNG_H
#define LR_BASE_RNG_H

#include <stdint.h>

typedef struct lr_rng {
    uint64_t s;
} lr_rng;

static inline uint64_t lr_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* A stream key from up to four numbers (e.g. seed, map, texel, frame). */
static inline uint64_t lr_rng_key(uint64_t a, uint64_t b, uint64_t c, uint64_t d)
{
    uint64_t h = lr_mix64(a + 0x9E3779B97F4A7C15ull);
    h = lr_mix64(h ^ (b + 0x632BE59BD9B4E019ull));
    h = lr_mix64(h ^ (c + 0x8CB92BA72F3D8DD7ull));
    return lr_mix64(h ^ (d + 0xD1B54A32D192ED03ull));
}

static inline lr_rng lr_rng_init(uint64_t key)
{
    return (lr_rng){lr_mix64(key ^ 0xA0761D6478BD642Full)};
}

/* Uniform in [0, 1) with 53 random bits. */
static inline double lr_rng_next(lr_rng *r)
{
    r->s += 0x9E3779B97F4A7C15ull;
    return (double)(lr_mix64(r->s) >> 11) * (1.0 / 9007199254740992.0);
}

#endif
