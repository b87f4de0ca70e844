/* lamprig — translucent planar lights (tpl.h). */
#include "render/lpv/tpl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/bvh.h"

typedef struct keyed {
    long key;
    int i;
} keyed;

static int by_key(const void *a, const void *b)
{
    const keyed *x = a, *y = b;
    if (x->key != y->key)
        return x->key < y->key ? -1 : 1;
    return x->i - y->i; /* stable: the merge order, hence the sums, are deterministic */
}

/* The dominant axis direction of n: 0..5 = +x, -x, +y, -y, +z, -z. */
static int face_of(lr_vec3 n)
{
    double a[3] = {n.x, n.y, n.z};
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(a[i]) > fabs(a[k]))
            k = i;
    return 2 * k + (a[k] < 0.0);
}

int lr_lpv_tpl_merge(const lr_lpv_tpl *in, int n, lr_vec3 origin, double cell, lr_lpv_tpl **out,
                     int *nout, lr_err *e)
{
    *out = NULL;
    *nout = 0;
    if (!(cell > 0.0) || !isfinite(cell))
        return lr_err_set(e, LR_EINVAL, "lpv tpl: cell %g mm (want > 0)", cell);
    keyed *k = malloc(sizeof *k * (size_t)(n > 0 ? n : 1));
    lr_lpv_tpl *t = malloc(sizeof *t * (size_t)(n > 0 ? n : 1));
    if (!k || !t) {
        free(k);
        free(t);
        return lr_err_set(e, LR_ENOMEM, "lpv tpl: out of memory for %d samples", n);
    }
    int m = 0;
    for (int i = 0; i < n; i++) {
        if (!(in[i].phi[0] + in[i].phi[1] + in[i].phi[2] > 0.0))
            continue;
        long c[3];
        lr_vec3 d = lr_v3_sub(in[i].p, origin);
        double q[3] = {d.x, d.y, d.z};
        for (int a = 0; a < 3; a++)
            c[a] = (long)floor(q[a] / cell) + 4096; /* any box of fewer than 8192 cells */
        k[m].key = (((long)in[i].object * 8192 + c[2]) * 8192 + c[1]) * 8192 + c[0];
        k[m].key = k[m].key * 6 + face_of(in[i].n);
        k[m].i = i;
        m++;
    }
    qsort(k, (size_t)m, sizeof *k, by_key);
    int nt = 0;
    for (int a = 0; a < m;) {
        int b = a;
        double w = 0.0;
        lr_vec3 p = lr_v3(0, 0, 0), nn = lr_v3(0, 0, 0);
        lr_lpv_tpl x;
        memset(&x, 0, sizeof x);
        x.object = in[k[a].i].object;
        for (; b < m && k[b].key == k[a].key; b++) {
            const lr_lpv_tpl *s = &in[k[b].i];
            double ws = s->phi[0] + s->phi[1] + s->phi[2];
            w += ws;
            p = lr_v3_add(p, lr_v3_scale(s->p, ws));
            nn = lr_v3_add(nn, lr_v3_scale(s->n, ws));
            x.area += s->area;
            for (int c = 0; c < 3; c++)
                x.phi[c] += s->phi[c];
        }
        x.p = lr_v3_scale(p, 1.0 / w);
        double len = lr_v3_len(nn);
        /* Opposite normals never share a key (face_of), so len > 0 unless they cancel
         * within one face class: keep the first sample's normal then. */
        x.n = len > 1e-12 ? lr_v3_scale(nn, 1.0 / len) : in[k[a].i].n;
        /* Lift the TPL onto the plane (normal x.n) that touches its outermost member: on a
         * convex patch the centroid lies under the surface (by the sagitta), and a shadow
         * ray to it would hit the surface it stands on. */
        double lift = 0.0;
        for (int j = a; j < b; j++)
            lift = fmax(lift, lr_v3_dot(lr_v3_sub(in[k[j].i].p, x.p), x.n));
        x.p = lr_v3_add(x.p, lr_v3_scale(x.n, lift));
        t[nt++] = x;
        a = b;
    }
    free(k);
    *out = t;
    *nout = nt;
    return LR_OK;
}

void lr_lpv_tpl_irradiance(const lr_scene *s, const lr_lpv_tpl *t, int n, double clip, lr_vec3 x,
                           lr_vec3 nx, double E[3])
{
    for (int k = 0; k < n; k++) {
        lr_vec3 d = lr_v3_sub(t[k].p, x);
        double d2 = lr_v3_dot(d, d), dist = sqrt(d2);
        if (!(dist > 0.0))
            continue;
        lr_vec3 w = lr_v3_scale(d, 1.0 / dist);
        double cx = lr_v3_dot(w, nx), ct = -lr_v3_dot(w, t[k].n);
        if (!(cx > 0.0) || !(ct > 0.0))
            continue;
        bool hidden = false;
        double tmax = dist - clip;
        for (int i = 0; i < lr_scene_object_count(s) && !hidden && tmax > 0.0; i++) {
            if (i == t[k].object)
                continue;
            const lr_scene_object *o = lr_scene_object_at(s, i);
            hidden = lr_bvh_occluded(o->bvh, x, w, 1e-6 * o->radius, tmax);
        }
        if (hidden)
            continue;
        double g = cx * ct / (M_PI * fmax(d2, t[k].area));
        for (int c = 0; c < 3; c++)
            E[c] += t[k].phi[c] * g;
    }
}
