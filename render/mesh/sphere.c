/* Geodesic sphere: an icosahedron whose faces are split in four, new vertices pushed out to
 * the sphere, `subdivisions` times. */
#include <math.h>
#include <stdlib.h>

#include "render/mesh/mesh_internal.h"
#include "render/mesh/shapes.h"

int lr_sphere_check(const lr_sphere_desc *d, lr_sphere_desc *r, const char **field, lr_err *e)
{
    *r = *d;
    if (r->radius == 0.0) r->radius = 50.0;
    if (r->subdivisions == 0) r->subdivisions = 4;
    if (!(r->radius > 0.0 && r->radius < 1e5)) {
        *field = "radius";
        return lr_err_set(e, LR_EINVAL, "must be > 0 and < 1e5 mm, got %g", r->radius);
    }
    if (!lr_v3_isfinite(r->center) || lr_v3_len(r->center) > 1e6) {
        *field = "center";
        return lr_err_set(e, LR_EINVAL, "must be finite and within 1e6 mm of the origin");
    }
    /* 0 means the default, so the bare icosahedron is not available: it is too coarse for
     * any use here (its area is 24 % below the sphere's). */
    if (r->subdivisions < 1 || r->subdivisions > 7) {
        *field = "subdivisions";
        return lr_err_set(e, LR_EINVAL, "must be between 1 and 7, got %d", r->subdivisions);
    }
    return LR_OK;
}

/* Open-addressing map from an edge (two vertex ids) to its midpoint vertex. */
typedef struct edge_map {
    uint64_t *key;
    uint32_t *val;
    size_t cap;
} edge_map;

static uint32_t midpoint(edge_map *em, lr_vec3 **pts, size_t *np, uint32_t a, uint32_t b)
{
    uint64_t k = a < b ? ((uint64_t)a << 32 | b) : ((uint64_t)b << 32 | a);
    size_t h = (size_t)((k * 0x9E3779B97F4A7C15ull) >> 20) & (em->cap - 1);
    while (em->key[h] != UINT64_MAX) {
        if (em->key[h] == k)
            return em->val[h];
        h = (h + 1) & (em->cap - 1);
    }
    /* (a + b) / 2 rounds the same for either order, so both faces of the edge agree. */
    lr_vec3 m = lr_v3_normalize(lr_v3_add((*pts)[a], (*pts)[b]));
    (*pts)[*np] = m;
    em->key[h] = k;
    em->val[h] = (uint32_t)*np;
    return (uint32_t)(*np)++;
}

int lr_mesh_sphere(const lr_sphere_desc *d, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    lr_sphere_desc s;
    const char *field = NULL;
    int rc = lr_sphere_check(d, &s, &field, e);
    if (rc)
        return lr_err_prefix(e, "sphere: field '%s'", field);
    const double t = (1.0 + sqrt(5.0)) / 2.0;
    static const double iv[12][3] = {{-1, 1, 0}, {1, 1, 0}, {-1, -1, 0}, {1, -1, 0},
                                     {0, -1, 1}, {0, 1, 1}, {0, -1, -1}, {0, 1, -1},
                                     {1, 0, -1}, {1, 0, 1}, {-1, 0, -1}, {-1, 0, 1}};
    static const uint32_t ifc[20][3] = {
        {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    size_t nt_final = (size_t)20 << (2 * s.subdivisions);
    size_t nv_final = nt_final / 2 + 2; /* Euler: V - E + F = 2, E = 3F/2 */
    lr_vec3 *pts = malloc(nv_final * sizeof *pts);
    uint32_t *tri = malloc(3 * nt_final * sizeof *tri), *next = malloc(3 * nt_final * sizeof *next);
    edge_map em = {0};
    em.cap = 1;
    while (em.cap < 2 * 3 * nt_final / 2)
        em.cap <<= 1;
    em.key = malloc(em.cap * sizeof *em.key);
    em.val = malloc(em.cap * sizeof *em.val);
    lr_mesh_builder b = {0};
    if (!pts || !tri || !next || !em.key || !em.val) {
        rc = lr_err_set(e, LR_ENOMEM, "sphere: out of memory");
        goto done;
    }
    size_t np = 12, nt = 20;
    for (int i = 0; i < 12; i++) {
        double x = iv[i][0], y = iv[i][1], z = iv[i][2];
        /* The table holds (+-1, +-1, 0) patterns; put the golden ratio in the right slot. */
        lr_vec3 p = i < 4 ? lr_v3(x, y * t, 0) : i < 8 ? lr_v3(0, y, z * t) : lr_v3(x * t, 0, z);
        pts[i] = lr_v3_normalize(p);
    }
    for (size_t f = 0; f < 20; f++)
        for (int k = 0; k < 3; k++)
            tri[3 * f + k] = ifc[f][k];
    for (int level = 0; level < s.subdivisions; level++) {
        for (size_t i = 0; i < em.cap; i++)
            em.key[i] = UINT64_MAX;
        for (size_t f = 0; f < nt; f++) {
            uint32_t a = tri[3 * f], bb = tri[3 * f + 1], c = tri[3 * f + 2];
            uint32_t ab = midpoint(&em, &pts, &np, a, bb), bc = midpoint(&em, &pts, &np, bb, c),
                     ca = midpoint(&em, &pts, &np, c, a);
            uint32_t *o = &next[12 * f];
            uint32_t q[12] = {a, ab, ca, bb, bc, ab, c, ca, bc, ab, bc, ca};
            for (int k = 0; k < 12; k++)
                o[k] = q[k];
        }
        nt *= 4;
        uint32_t *sw = tri;
        tri = next;
        next = sw;
    }
    for (size_t v = 0; v < np; v++)
        lr_mb_vertex(&b, lr_v3_add(s.center, lr_v3_scale(pts[v], s.radius)), pts[v]);
    for (size_t f = 0; f < nt; f++)
        lr_mb_triangle(&b, tri[3 * f], tri[3 * f + 1], tri[3 * f + 2]);
    rc = lr_mb_finish(&b, "sphere", &s.checks, out, e);
done:
    lr_mb_free(&b);
    free(pts);
    free(tri);
    free(next);
    free(em.key);
    free(em.val);
    return rc;
}
