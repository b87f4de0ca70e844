/* lamprig — translucent radiosity: the form-factor matrix F by ray casts.
 *
 * F_pq = (1/A_p) int_{A_p} int_{A_q} cos th_p cos th_q V / (pi r^2) dA_q dA_p (seed 000 Eq. 2's
 * F) is the probability that a ray leaving a uniformly chosen point of p in a cosine-
 * distributed direction first hits q. Rays from points spread over p (stratified by area) in
 * directions from a shifted Halton set, each counted at its first hit over every surface:
 * visibility is exact for the meshes, every row sums to 1 with the escape (rays that hit
 * nothing), so F never creates light, and a closed cavity's rows sum to 1 exactly. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/parallel.h"
#include "render/base/rng.h"

typedef struct ff_ctx {
    lr_tr *t;
    uint32_t **cols;
    float **vals;
    size_t *counts;
    int rays;
    double eps;
    int failed;
} ff_ctx;

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return x < y ? -1 : x > y;
}

static void frame_of(lr_vec3 n, lr_vec3 *t1, lr_vec3 *t2)
{
    lr_vec3 a = fabs(n.x) < 0.9 ? lr_v3(1, 0, 0) : lr_v3(0, 1, 0);
    *t1 = lr_v3_normalize(lr_v3_cross(a, n));
    *t2 = lr_v3_cross(n, *t1);
}

static void ff_item(void *vctx, long item)
{
    ff_ctx *c = vctx;
    lr_tr *t = c->t;
    size_t p = (size_t)item;
    int R = c->rays;
    size_t *hits = malloc((size_t)R * sizeof *hits);
    if (!hits) {
        c->failed = 1;
        return;
    }
    double jit[4];
    lr_tr_ff_jitter(t, p, jit);
    double ju = jit[0], jv = jit[1], jd1 = jit[2], jd2 = jit[3];
    size_t nh = 0, escaped = 0;
    int open = 0;
    for (int k = 0; k < R; k++) {
        lr_vec3 x, n, t1, t2;
        lr_tr_patch_point(t, p, (unsigned)k, (unsigned)R, ju, jv, &x, &n);
        /* A point inside a body standing on a plane is no surface (cover.c): the row is
         * over the cell's open part. */
        if (lr_tr_point_covered(t, p, x))
            continue;
        open++;
        frame_of(n, &t1, &t2);
        double u1 = lr_halton((unsigned)k + 1, 5) + jd1, u2 = lr_halton((unsigned)k + 1, 7) + jd2;
        u1 -= floor(u1);
        u2 -= floor(u2);
        /* Cosine-weighted: radius sqrt(u1) on the unit disk lifted to the hemisphere. */
        double r = sqrt(u1), phi = 2 * M_PI * u2, z = sqrt(fmax(0.0, 1 - u1));
        lr_vec3 d = lr_v3_add(lr_v3_add(lr_v3_scale(t1, r * cos(phi)), lr_v3_scale(t2, r * sin(phi))),
                              lr_v3_scale(n, z));
        lr_vec3 o = lr_v3_add(x, lr_v3_scale(n, c->eps));
        size_t q;
        double dist;
        if (!lr_tr_trace(t, o, d, INFINITY, &q, &dist))
            escaped++;
        else if (q != SIZE_MAX)
            hits[nh++] = q;
    }
    qsort(hits, nh, sizeof *hits, cmp_size);
    size_t distinct = 0;
    for (size_t i = 0; i < nh; i++)
        if (i == 0 || hits[i] != hits[i - 1])
            distinct++;
    c->cols[p] = malloc((distinct ? distinct : 1) * sizeof **c->cols);
    c->vals[p] = malloc((distinct ? distinct : 1) * sizeof **c->vals);
    if (!c->cols[p] || !c->vals[p]) {
        c->failed = 1;
        free(hits);
        return;
    }
    size_t w = 0;
    for (size_t i = 0; i < nh;) {
        size_t j = i;
        while (j < nh && hits[j] == hits[i])
            j++;
        c->cols[p][w] = (uint32_t)hits[i];
        c->vals[p][w] = (float)((double)(j - i) / open);
        w++;
        i = j;
    }
    c->counts[p] = w;
    t->escape[p] = open ? (double)escaped / open : 0;
    free(hits);
}

int lr_tr_build_form_factors(lr_tr *t, lr_err *e)
{
    size_t n = t->n;
    ff_ctx c = {.t = t, .rays = t->set.rays_per_patch, .eps = lr_tr_eps(t)};
    c.cols = calloc(n, sizeof *c.cols);
    c.vals = calloc(n, sizeof *c.vals);
    c.counts = calloc(n, sizeof *c.counts);
    t->escape = calloc(n, sizeof *t->escape);
    t->F.row = calloc(n + 1, sizeof *t->F.row);
    int rc = LR_OK;
    if (!c.cols || !c.vals || !c.counts || !t->escape || !t->F.row) {
        rc = lr_err_set(e, LR_ENOMEM, "transrad: out of memory (form factors, %zu patches)", n);
        goto done;
    }
    /* F depends on the geometry alone and is cached on disk: only a stop cuts it. */
    if (!lr_parallel_for_cancel((long)n, t->set.threads, ff_item, &c, t->set.cancel,
                                    LR_CANCEL_STOP)) {
        rc = lr_cancel_check_at(t->set.cancel, LR_CANCEL_STOP, "transrad: form factors", e);
        goto done;
    }
    if (c.failed) {
        rc = lr_err_set(e, LR_ENOMEM, "transrad: out of memory (form-factor rows)");
        goto done;
    }
    for (size_t p = 0; p < n; p++)
        t->F.row[p + 1] = t->F.row[p] + c.counts[p];
    size_t nnz = t->F.row[n];
    t->F.col = malloc((nnz ? nnz : 1) * sizeof *t->F.col);
    t->F.val = malloc((nnz ? nnz : 1) * sizeof *t->F.val);
    if (!t->F.col || !t->F.val) {
        rc = lr_err_set(e, LR_ENOMEM, "transrad: out of memory (form factors, %zu entries)", nnz);
        goto done;
    }
    for (size_t p = 0; p < n; p++) {
        memcpy(t->F.col + t->F.row[p], c.cols[p], c.counts[p] * sizeof *t->F.col);
        memcpy(t->F.val + t->F.row[p], c.vals[p], c.counts[p] * sizeof *t->F.val);
    }
done:
    lr_tr_row_lists_free(n, c.cols, c.vals, c.counts);
    return rc;
}

double lr_tr_form_factor(const lr_tr *t, size_t p, size_t q)
{
    if (p >= t->n)
        return 0;
    for (size_t i = t->F.row[p]; i < t->F.row[p + 1]; i++)
        if (t->F.col[i] == q)
            return t->F.val[i];
    return 0;
}

double lr_tr_escape(const lr_tr *t, size_t p)
{
    return p < t->n ? t->escape[p] : 0;
}

void lr_tr_row_lists_free(size_t n, uint32_t **cols, float **vals, size_t *counts)
{
    for (size_t p = 0; cols && p < n; p++)
        free(cols[p]);
    for (size_t p = 0; vals && p < n; p++)
        free(vals[p]);
    free(cols);
    free(vals);
    free(counts);
}
