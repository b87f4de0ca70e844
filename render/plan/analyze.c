/* lamprig planner — what an object of a scene needs, from its geometry.
 *
 *  - Receivers that see it. The VPLs of seed 003 (Sec. 3.4) carry the object's emergent light
 *    to the diffuse receivers; a receiver no point of the object's surface can see gets
 *    nothing from them, so an object no receiver sees needs no VPL pass. Checked by sampling:
 *    area-weighted quasi-random points on the object and on each receiver, a pair counts when
 *    both faces turn toward each other and the segment between them hits no object and no
 *    receiver (the BVHs of render/mesh/bvh.h).
 *  - Map coverage. Algorithm 1 of seed 003 composes a surface point from the maps that see
 *    it: map k (orthographic along d_k = lr_halton_sphere(k + 1), render/passes/PIPELINE.md)
 *    sees x when its normal faces d_k and the ray from x toward d_k leaves the object. On a
 *    convex object nothing occludes, so every point whose normal is within ~84 degrees of
 *    some d_k is seen, and a handful of well-spread directions cover the whole surface; a
 *    cavity (the candle's melt pool, the inside of a shade) is seen only from a narrow cone
 *    of directions and needs more. K_cover is the fewest maps that see what all 32 see.
 *  - Convexity: every vertex on the inner side of every face plane (closed meshes).
 *  - Features for matching a scene the table does not hold. */
#include "render/plan/plan.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/optics/optics.h"

#define COVER_SAMPLES 1024
#define SEE_OBJECT_SAMPLES 192
#define SEE_RECEIVER_SAMPLES 96
/* A map whose direction grazes the surface (n.d_k below this) sees it in too few texels to
 * count; cos 84 degrees. */
#define COVER_MIN_COS 0.1

bool lr_plan_mesh_convex(const lr_mesh *m, bool closed, double tol, double *violation)
{
    *violation = 0.0;
    if (!closed)
        return false;
    size_t nt = lr_mesh_triangle_count(m), nv = lr_mesh_vertex_count(m);
    /* Every vertex against every face plane: V x F (21 million for the candle), so the
     * vertices are copied once into three plain arrays the inner loop streams through
     * (vectorised; a call per vertex made this most of a re-planner's start-up). */
    double *xyz = malloc(3 * (nv ? nv : 1) * sizeof *xyz);
    if (!xyz) {
        *violation = INFINITY; /* cannot tell: not convex, the safe answer for the planner */
        return false;
    }
    double *X = xyz, *Y = xyz + nv, *Z = xyz + 2 * nv;
    for (size_t v = 0; v < nv; v++) {
        lr_vec3 q = lr_mesh_vertex(m, v);
        X[v] = q.x;
        Y[v] = q.y;
        Z[v] = q.z;
    }
    double worst = 0.0;
    for (size_t t = 0; t < nt; t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 n = lr_mesh_triangle_normal(m, t);
        double d0 = lr_v3_dot(n, p[0]), best = -INFINITY;
        for (size_t v = 0; v < nv; v++) {
            double d = n.x * X[v] + n.y * Y[v] + n.z * Z[v];
            best = d > best ? d : best;
        }
        if (best - d0 > worst)
            worst = best - d0;
    }
    free(xyz);
    *violation = worst;
    /* The whole loop even after the first vertex outside: the largest excess says how deep
     * the cavity is (a candle's melt pool), which the plan prints. */
    return *violation <= tol;
}

/* Area-weighted quasi-random surface samples (Halton bases 2, 3, 5: deterministic). */
typedef struct sampler {
    const lr_mesh *m;
    double *cdf;
    size_t n;
} sampler;

static int sampler_init(sampler *s, const lr_mesh *m, lr_err *e)
{
    s->m = m;
    s->n = lr_mesh_triangle_count(m);
    s->cdf = malloc(s->n * sizeof *s->cdf);
    if (!s->cdf)
        return lr_err_set(e, LR_ENOMEM, "planner: out of memory");
    double acc = 0.0;
    for (size_t t = 0; t < s->n; t++) {
        acc += lr_mesh_triangle_area(m, t);
        s->cdf[t] = acc;
    }
    return LR_OK;
}

static void sampler_point(const sampler *s, unsigned i, lr_vec3 *p, lr_vec3 *n)
{
    double u = lr_halton(i + 1, 2) * s->cdf[s->n - 1];
    size_t lo = 0, hi = s->n - 1;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (s->cdf[mid] < u)
            lo = mid + 1;
        else
            hi = mid;
    }
    double a = lr_halton(i + 1, 3), b = lr_halton(i + 1, 5);
    if (a + b > 1.0) {
        a = 1.0 - a;
        b = 1.0 - b;
    }
    lr_vec3 q[3];
    lr_mesh_triangle(s->m, lo, q);
    *p = lr_v3_add(q[0], lr_v3_add(lr_v3_scale(lr_v3_sub(q[1], q[0]), a),
                                   lr_v3_scale(lr_v3_sub(q[2], q[0]), b)));
    *n = lr_mesh_triangle_normal(s->m, lo);
}

static bool blocked(const lr_scene *s, lr_vec3 o, lr_vec3 d, double tmin, double tmax)
{
    for (int i = 0; i < lr_scene_object_count(s); i++)
        if (lr_bvh_occluded(lr_scene_object_at(s, i)->bvh, o, d, tmin, tmax))
            return true;
    for (int i = 0; i < lr_scene_receiver_count(s); i++)
        if (lr_bvh_occluded(lr_scene_receiver_at(s, i)->bvh, o, d, tmin, tmax))
            return true;
    return false;
}

/* Whether any sampled receiver point sees any sampled object point. */
static int receiver_sees(const lr_scene *s, const lr_scene_object *o, const sampler *so,
                         const lr_receiver *r, bool *sees, lr_err *e)
{
    sampler sr;
    int rc = sampler_init(&sr, r->mesh, e);
    if (rc)
        return rc;
    /* Offsets off the surfaces: well above float rounding of positions a metre out
     * (~1e-4 mm), well below any feature of a scene. */
    const double eps = 1e-2;
    *sees = false;
    for (unsigned j = 0; j < SEE_RECEIVER_SAMPLES && !*sees; j++) {
        lr_vec3 pr, nr;
        sampler_point(&sr, j, &pr, &nr);
        for (unsigned i = 0; i < SEE_OBJECT_SAMPLES; i++) {
            lr_vec3 po, no;
            sampler_point(so, i, &po, &no);
            lr_vec3 d = lr_v3_sub(po, pr);
            double len = lr_v3_len(d);
            if (len <= 4 * eps)
                continue;
            d = lr_v3_scale(d, 1.0 / len);
            /* Receivers are lit on their front; light leaves a closed object through its
             * outward side, an open surface through either. */
            if (lr_v3_dot(nr, d) <= 0.0 || (o->closed && lr_v3_dot(no, d) >= 0.0))
                continue;
            if (!blocked(s, pr, d, eps, len - eps)) {
                *sees = true;
                break;
            }
        }
    }
    free(sr.cdf);
    return LR_OK;
}

static void coverage(const lr_scene_object *o, const sampler *so, lr_plan_analysis *a)
{
    int count[LR_PLAN_KMAX] = {0};
    lr_vec3 dir[LR_PLAN_KMAX];
    for (int k = 0; k < LR_PLAN_KMAX; k++)
        dir[k] = lr_halton_sphere((unsigned)k + 1);
    const double eps = 1e-3 * o->radius;
    for (unsigned i = 0; i < COVER_SAMPLES; i++) {
        lr_vec3 p, n;
        sampler_point(so, i, &p, &n);
        for (int k = 0; k < LR_PLAN_KMAX; k++) {
            double c = lr_v3_dot(n, dir[k]);
            lr_vec3 nk = n;
            if (!o->closed && c < 0.0) { /* an open surface is seen from both sides */
                c = -c;
                nk = lr_v3_scale(n, -1.0);
            }
            if (c < COVER_MIN_COS)
                continue;
            lr_vec3 start = lr_v3_add(p, lr_v3_scale(nk, eps));
            if (!lr_bvh_occluded(o->bvh, start, dir[k], 0.0, 4.0 * o->radius)) {
                count[k]++; /* first map that sees it */
                break;
            }
        }
    }
    int acc = 0;
    for (int k = 0; k < LR_PLAN_KMAX; k++) {
        acc += count[k];
        a->coverage[k] = (double)acc / COVER_SAMPLES;
    }
    a->K_cover = LR_PLAN_KMAX;
    for (int k = 0; k < LR_PLAN_KMAX; k++)
        if (a->coverage[k] >= a->coverage[LR_PLAN_KMAX - 1] - 0.002) {
            a->K_cover = k + 1;
            break;
        }
}

static void features(const lr_scene *s, int index, lr_plan_features *f, double *violation)
{
    const lr_scene_object *o = lr_scene_object_at(s, index);
    int obj = -1;
    f->enclosed = lr_scene_light_count(s) > 0 &&
                  lr_scene_light_enclosure(s, 0, &obj) != LR_ENCLOSURE_NONE && obj == index;
    /* Thin shell: mean thickness 2 V / A (exact for a uniform thin wall, whose volume is
     * about half its two-sided area times the thickness) below a tenth of the object's
     * radius; an open surface is a shell by construction. */
    double vol = lr_mesh_volume(o->mesh), area = lr_mesh_area(o->mesh);
    f->shell = !o->closed || 2.0 * vol / area < 0.1 * o->radius;
    double tol = 1e-5 * o->radius + 1e-4; /* float positions */
    f->convex = lr_plan_mesh_convex(o->mesh, o->closed, tol, violation);
    f->size_tr = lr_plan_size_tr(o);
}

double lr_plan_size_tr(const lr_scene_object *o)
{
    double str = (o->coeffs.sigma_tr[0] + o->coeffs.sigma_tr[1] + o->coeffs.sigma_tr[2]) / 3.0;
    return o->radius * str;
}

void lr_plan_features_of(const lr_scene *s, int index, lr_plan_features *out)
{
    double v;
    features(s, index, out, &v);
}

int lr_plan_analyze(const lr_scene *s, int index, lr_plan_analysis *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (index < 0 || index >= lr_scene_object_count(s))
        return lr_err_set(e, LR_EINVAL, "planner: no object %d", index);
    int nr = lr_scene_receiver_count(s);
    if (nr > 32) /* one bit each in receivers_seeing; scenes hold at most 16 */
        return lr_err_set(e, LR_EINVAL, "planner: %d receivers, at most 32", nr);
    const lr_scene_object *o = lr_scene_object_at(s, index);
    features(s, index, &out->features, &out->convex_violation_mm);
    sampler so;
    int rc = sampler_init(&so, o->mesh, e);
    if (rc)
        return rc;
    coverage(o, &so, out);
    out->receivers_checked = nr;
    for (int i = 0; i < nr && !rc; i++) {
        bool sees;
        if (!(rc = receiver_sees(s, o, &so, lr_scene_receiver_at(s, i), &sees, e)) && sees)
            out->receivers_seeing |= 1u << i;
    }
    free(so.cdf);
    return rc;
}
