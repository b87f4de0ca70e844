/* Cache-key hashing: 64-bit FNV-1a (Fowler, Noll, Vo; offset basis 14695981039346656037,
 * prime 1099511628211, as in the FNV reference description draft-eastlake-fnv). Not
 * cryptographic: a key only has to tell scenes apart, and for n cached references the chance
 * of any collision is about n^2 / 2^65 (3e-12 for ten thousand). */
#include "render/reference/reference.h"

#include <string.h>

void lr_ref_hash_init(lr_ref_hash *h)
{
    h->h = 14695981039346656037ULL;
}

void lr_ref_hash_bytes(lr_ref_hash *h, const void *data, size_t n)
{
    const unsigned char *p = data;
    uint64_t x = h->h;
    for (size_t i = 0; i < n; i++) {
        x ^= p[i];
        x *= 1099511628211ULL;
    }
    h->h = x;
}

void lr_ref_hash_str(lr_ref_hash *h, const char *s)
{
    lr_ref_hash_bytes(h, s ? s : "", strlen(s ? s : "") + 1);
}

/* Little-endian bytes, so keys agree between hosts of either byte order. */
void lr_ref_hash_u64(lr_ref_hash *h, uint64_t v)
{
    unsigned char b[8];
    for (int i = 0; i < 8; i++)
        b[i] = (unsigned char)(v >> (8 * i));
    lr_ref_hash_bytes(h, b, sizeof b);
}

void lr_ref_hash_double(lr_ref_hash *h, double v)
{
    if (v == 0.0)
        v = 0.0; /* -0.0 == 0.0 renders the same: one key */
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    lr_ref_hash_u64(h, u);
}

void lr_ref_hash_vec3(lr_ref_hash *h, lr_vec3 v)
{
    lr_ref_hash_double(h, v.x);
    lr_ref_hash_double(h, v.y);
    lr_ref_hash_double(h, v.z);
}

uint64_t lr_ref_hash_of(const void *data, size_t n)
{
    lr_ref_hash h;
    lr_ref_hash_init(&h);
    lr_ref_hash_bytes(&h, data, n);
    return h.h;
}
