/* Growable vertex and index arrays for the procedural generators. */
#include "render/mesh/mesh_internal.h"

#include <stdlib.h>

static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 0;
    size_t c = *cap ? *cap : 256;
    while (c < need)
        c *= 2;
    void *n = realloc(*p, c * elem);
    if (!n)
        return -1;
    *p = n;
    *cap = c;
    return 0;
}

uint32_t lr_mb_vertex(lr_mesh_builder *b, lr_vec3 p, lr_vec3 n)
{
    size_t cap_p = b->cap_v, cap_n = b->cap_v;
    if (b->oom || grow((void **)&b->pos, &cap_p, 3 * (b->nv + 1), sizeof *b->pos) ||
        grow((void **)&b->nrm, &cap_n, 3 * (b->nv + 1), sizeof *b->nrm)) {
        b->oom = 1;
        return 0;
    }
    b->cap_v = cap_p < cap_n ? cap_p : cap_n;
    double *q = &b->pos[3 * b->nv], *m = &b->nrm[3 * b->nv];
    q[0] = p.x;
    q[1] = p.y;
    q[2] = p.z;
    m[0] = n.x;
    m[1] = n.y;
    m[2] = n.z;
    return (uint32_t)b->nv++;
}

void lr_mb_triangle(lr_mesh_builder *b, uint32_t a, uint32_t c, uint32_t d)
{
    if (b->oom || grow((void **)&b->idx, &b->cap_t, 3 * (b->nt + 1), sizeof *b->idx)) {
        b->oom = 1;
        return;
    }
    uint32_t *t = &b->idx[3 * b->nt++];
    t[0] = a;
    t[1] = c;
    t[2] = d;
}

void lr_mb_free(lr_mesh_builder *b)
{
    free(b->pos);
    free(b->nrm);
    free(b->idx);
    *b = (lr_mesh_builder){0};
}

int lr_mb_finish(lr_mesh_builder *b, const char *name, const lr_mesh_checks *checks,
                 lr_mesh **out, lr_err *e)
{
    int rc;
    if (b->oom) {
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    } else {
        lr_mesh_desc d = {
            .name = name,
            .vertex_count = b->nv,
            .positions = b->pos,
            .normals = b->nrm,
            .triangle_count = b->nt,
            .indices = b->idx,
        };
        if (checks)
            d.checks = *checks;
        rc = lr_mesh_create(&d, out, e);
    }
    lr_mb_free(b);
    return rc;
}
