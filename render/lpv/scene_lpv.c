/* lamprig — the scene's light-propagation volume on the plane receivers (scene_lpv.h). */
#include "render/lpv/scene_lpv.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/area/emitter.h"
#include "render/area/frames.h"
#include "render/area/poisson_mesh.h"
#include "render/core/recv_grid.h"
#include "render/core/vpl.h"
#include "render/lpv/tpl.h"
#include "render/mesh/bvh.h"
#include "render/optics/optics.h"

#define EMITTER_POINTS 64
/* The objects are opaque to the volume: light crosses a translucent object only by
 * re-emission (the maps, VPLs and TPLs; a bounce's R). Their samples block with this many
 * times their area, so an interface that an object's surface covers by 1/8 or more is closed.
 * With their own area (1) a 7 mm votive wall at 17.5 mm cells passes the cavity's light to
 * the table beside the cup through the partly covered interfaces of its curved wall: fair
 * bench table near 1.14 of the reference, 1.01 with 8 (README "Figures"). */
#define OBJECT_BLOCK 8.0

typedef struct sample {
    lr_vec3 p, n;
    double area, refl[3]; /* the share of E sent back to the lit side */
    double trans[3];      /* objects with thickness_mm: the share sent through the wall */
    double thick;         /* thickness_mm (0: a solid body, no light through it) */
    double back;          /* the other face is at p - back n: thick for a wall meshed with
                           * both faces, 0 for a sheet meshed as one surface */
    bool two_sided;       /* a sheet meshed as one surface: lit, and emitting, on both sides */
    bool outer[2];        /* its front (n, at p) / back (-n, at p - back n) is the outermost
                           * surface facing out: the VPLs carry what it emits (tpl.h) */
    int group, object;
} sample;

typedef struct samples {
    sample *s;
    int n, cap;
} samples;

static int push(samples *ss, sample x)
{
    if (ss->n == ss->cap) {
        int cap = ss->cap ? 2 * ss->cap : 1024;
        sample *t = realloc(ss->s, sizeof *t * (size_t)cap);
        if (!t)
            return LR_ENOMEM;
        ss->s = t;
        ss->cap = cap;
    }
    ss->s[ss->n++] = x;
    return LR_OK;
}

static bool in_box(const lr_lpv *v, lr_vec3 p)
{
    int ijk[3];
    return lr_lpv_cell_of(v, p, ijk) == 0;
}

/* Direct irradiance per unit radiance at x (normal nx) from the emitter points, shadowed by
 * the scene's objects. */
static double direct(const lr_scene *s, const lr_area_emitter *em, const lr_vec3 *pts, lr_vec3 x,
                     lr_vec3 nx)
{
    double E = 0.0;
    lr_vec3 o = lr_v3_add(x, lr_v3_scale(nx, 1e-3));
    for (int j = 0; j < EMITTER_POINTS; j++) {
        lr_vec3 d = lr_v3_sub(pts[j], o);
        double dist = lr_v3_len(d);
        if (!(dist > 0.0))
            continue;
        lr_vec3 w = lr_v3_scale(d, 1.0 / dist);
        double cx = lr_v3_dot(w, nx);
        if (cx <= 0.0)
            continue;
        double I = lr_area_intensity_factor(em, lr_v3_scale(w, -1.0)) / EMITTER_POINTS;
        if (I <= 0.0)
            continue;
        bool hidden = false;
        for (int i = 0; i < lr_scene_object_count(s) && !hidden; i++)
            hidden = lr_bvh_occluded(lr_scene_object_at(s, i)->bvh, o, w, 1e-4, dist - 1e-4);
        if (!hidden)
            E += I * cx / (dist * dist);
    }
    return E;
}

static int receiver_samples(const lr_scene *s, const lr_lpv *v, samples *ss, int *count)
{
    double sp = lr_lpv_h(v) / 2.0;
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        const lr_receiver *rc = lr_scene_receiver_at(s, i);
        lr_recv_grid_frame f;
        if (!lr_recv_grid_frame_of(rc, &f))
            continue;
        int ns = (int)ceil(f.w / sp), nt = (int)ceil(f.h / sp);
        for (int a = 0; a < ns; a++)
            for (int b = 0; b < nt; b++) {
                double u = ((a + 0.5) / ns - 0.5) * f.w, t = ((b + 0.5) / nt - 0.5) * f.h;
                lr_vec3 p = lr_v3_add(f.c, lr_v3_add(lr_v3_scale(f.a, u), lr_v3_scale(f.b, t)));
                if (!in_box(v, p))
                    continue;
                sample x = {.p = p, .n = rc->normal, .area = (f.w / ns) * (f.h / nt),
                            .group = i};
                memcpy(x.refl, rc->albedo, sizeof x.refl);
                if (push(ss, x))
                    return LR_ENOMEM;
                (*count)++;
            }
    }
    return LR_OK;
}

/* Whether a surface point x of normal n faces out from the outermost surface of o along the
 * ray from its bounding-box centre c (the VPLs' placement, render/core/vpl.h): n . u > 0 and
 * no object beyond x along u = (x - c) / |x - c|. */
static bool outermost(const lr_scene *s, const lr_scene_object *o, lr_vec3 x, lr_vec3 n)
{
    lr_vec3 lo, hi;
    lr_mesh_bounds(o->mesh, &lo, &hi);
    lr_vec3 u = lr_v3_sub(x, lr_v3_scale(lr_v3_add(lo, hi), 0.5));
    double len = lr_v3_len(u);
    if (!(len > 0.0) || !(lr_v3_dot(u, n) > 0.0))
        return false;
    u = lr_v3_scale(u, 1.0 / len);
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *b = lr_scene_object_at(s, i);
        if (lr_bvh_occluded(b->bvh, x, u, 1e-3 * b->radius, INFINITY))
            return false;
    }
    return true;
}

static int object_samples(const lr_scene *s, const lr_lpv *v, int group, samples *ss,
                          int *count, lr_err *e)
{
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        double R[3], T[3];
        lr_lpv_object_totals(o, R, T);
        /* r_min = h / 3, but at most 1/16 of the object's largest extent: a volume widened
         * to a wall (build_box) has cells of a third of a votive, and the TPLs' midpoint
         * rule over a cup lit from 22 mm away then lost a quarter of the emergent flux. */
        lr_vec3 lo, hi;
        lr_mesh_bounds(o->mesh, &lo, &hi);
        lr_vec3 ext = lr_v3_sub(hi, lo);
        double rmin = fmin(lr_lpv_h(v) / 3.0, fmax(ext.x, fmax(ext.y, ext.z)) / 16.0);
        lr_poisson_set set = {0};
        int rc = lr_poisson_mesh(o->mesh, rmin, 200000, 2000, 0x1F5u + (unsigned)i, &set, e);
        if (rc)
            return rc;
        for (int k = 0; k < set.n; k++) {
            if (!in_box(v, set.s[k].p))
                continue;
            sample x = {.p = set.s[k].p, .n = set.s[k].n, .area = set.s[k].area,
                        .thick = o->thickness_mm > 0.0 ? o->thickness_mm : 0.0, .group = group,
                        .object = i};
            memcpy(x.refl, R, sizeof x.refl);
            memcpy(x.trans, T, sizeof x.trans);
            /* A thin wall meshed with both faces (a votive's cup) meets its other face
             * within twice its thickness behind p; a sheet meshed as one surface (a globe
             * or shade with thickness_mm) does not, and is lit on both sides. */
            lr_vec3 behind = lr_v3_scale(x.n, -1.0);
            lr_hit hit;
            bool other = x.thick > 0.0 && lr_bvh_intersect(o->bvh, x.p, behind, 1e-3 * o->radius,
                                                           2.0 * x.thick, &hit);
            x.two_sided = x.thick > 0.0 && !other;
            x.back = other ? hit.t : 0.0; /* the other face itself (a floor may be thicker) */
            x.outer[0] = outermost(s, o, x.p, x.n);
            x.outer[1] = x.thick > 0.0 &&
                         outermost(s, o, lr_v3_add(x.p, lr_v3_scale(behind, x.back)), behind);
            if (push(ss, x)) {
                lr_poisson_set_free(&set);
                return LR_ENOMEM;
            }
            (*count)++;
        }
        lr_poisson_set_free(&set);
    }
    return LR_OK;
}

static int cpu_propagate(void *ctx, lr_lpv *v, int steps, lr_err *e)
{
    (void)ctx;
    return lr_lpv_propagate(v, steps, e);
}

static int build_box(const lr_scene *s, int n, lr_lpv **out, lr_err *e)
{
    lr_vec3 lo = lr_v3(INFINITY, INFINITY, INFINITY), hi = lr_v3(-INFINITY, -INFINITY, -INFINITY);
    for (int i = 0; i < lr_scene_object_count(s); i++) {
        lr_vec3 a, b;
        lr_mesh_bounds(lr_scene_object_at(s, i)->mesh, &a, &b);
        lo = lr_v3(fmin(lo.x, a.x), fmin(lo.y, a.y), fmin(lo.z, a.z));
        hi = lr_v3(fmax(hi.x, b.x), fmax(hi.y, b.y), fmax(hi.z, b.z));
    }
    if (lr_scene_object_count(s) == 0)
        return lr_err_set(e, LR_EINVAL, "lpv: the scene has no objects to place the volume");
    lr_vec3 ext = lr_v3_sub(hi, lo);
    double E = fmax(ext.x, fmax(ext.y, ext.z)), margin = 1.25 * E;
    /* At least 1.25 extents: a wall or table near the lamp lies a few cells inside the box
     * (light that reaches the border leaves; a receiver on it would gather nothing). A plane
     * receiver within 3 extents of the objects' box widens it to one cell beyond the plane:
     * margin = d + h with h = (E + 2 margin) / n, so that the table and the wall behind a
     * lamp both take part (table <-> wall interreflection, issue 12 part 4). */
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        const lr_receiver *r = lr_scene_receiver_at(s, i);
        if (r->type != LR_RECEIVER_PLANE)
            continue;
        double dmin = INFINITY, dmax = -INFINITY;
        for (int k = 0; k < 8; k++) {
            lr_vec3 q = lr_v3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
            double t = lr_v3_dot(lr_v3_sub(q, r->center), r->normal);
            dmin = fmin(dmin, t);
            dmax = fmax(dmax, t);
        }
        double dist = dmin > 0.0 ? dmin : dmax < 0.0 ? -dmax : 0.0;
        if (n > 4 && dist <= 3.0 * E)
            margin = fmax(margin, (dist + E / n) / (1.0 - 2.0 / n));
    }
    lr_lpv_desc d;
    int rc = lr_lpv_desc_around(lo, hi, margin, n, &d, e);
    return rc ? rc : lr_lpv_create(&d, out, e);
}

/* Adds the volume's irradiance at every plane receiver's grid texels (but group g's own). */
static void gather_receivers(const lr_scene *s, const lr_lpv *v, int g, double *const *out,
                             double gathered[3])
{
    size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    for (int i = 0; i < lr_scene_receiver_count(s); i++) {
        lr_recv_grid_frame f;
        const lr_receiver *r = lr_scene_receiver_at(s, i);
        if (i == g || !out[i] || !lr_recv_grid_frame_of(r, &f))
            continue;
        double ta = f.w * f.h / (double)texels;
        for (int t = 0; t < LR_RECV_GRID; t++)
            for (int q = 0; q < LR_RECV_GRID; q++) {
                double E[3];
                lr_lpv_irradiance(v, lr_recv_grid_point(&f, q, t), r->normal, E);
                for (int c = 0; c < 3; c++) {
                    out[i][((size_t)t * LR_RECV_GRID + q) * 3 + c] += E[c];
                    gathered[c] += E[c] * ta;
                }
            }
    }
}

/* One side of a sample: the point and normal its light leaves from (side 0: p, n; side 1: the
 * wall's other face, p - back n, -n). */
static lr_vec3 side_p(const sample *x, int side)
{
    return side ? lr_v3_sub(x->p, lr_v3_scale(x->n, x->back)) : x->p;
}
static lr_vec3 side_n(const sample *x, int side) { return side ? lr_v3_scale(x->n, -1.0) : x->n; }

/* What an object sample sends out of each side when its sides receive E[side] (W/mm^2 per
 * channel): the reflected share R E back out of the lit side, the transmitted share T E out
 * of the other (thin walls; the multipole's totals, so R + T <= 1 of what arrived). */
static void object_out(const sample *x, const double E[2][3], double out[2][3])
{
    for (int c = 0; c < 3; c++)
        for (int side = 0; side < 2; side++)
            out[side][c] = (x->refl[c] * E[side][c] + x->trans[c] * E[!side][c]) * x->area;
}

int lr_lpv_scene_indirect(const lr_scene *s, int light, const lr_lpv_scene_desc *d,
                          double *const *out, lr_lpv_scene_stats *stats, lr_err *e)
{
    lr_lpv_scene_stats st;
    memset(&st, 0, sizeof st);
    int n = d && d->n ? d->n : 32;
    if (light < 0 || light >= lr_scene_light_count(s))
        return lr_err_set(e, LR_EINVAL, "lpv: light %d of %d", light, lr_scene_light_count(s));
    int nrec = lr_scene_receiver_count(s);
    size_t texels = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    for (int i = 0; i < nrec; i++)
        if (out[i])
            memset(out[i], 0, texels * 3 * sizeof *out[i]);
    const lr_light *li = lr_scene_light_at(s, light);
    bool area = lr_light_is_area(li);
    if (d && d->objects)
        lr_lpv_objfield_clear(d->objects);
    if (!area && li->type != LR_LIGHT_POINT && li->type != LR_LIGHT_SPOT) {
        if (stats)
            *stats = st;
        return LR_OK;
    }
    lr_area_emitter em;
    lr_vec3 pts[EMITTER_POINTS];
    memset(&em, 0, sizeof em);
    memset(pts, 0, sizeof pts);
    int rc = LR_OK;
    if (area) {
        if ((rc = lr_area_from_light(li, &em, e)))
            return rc;
        lr_area_stratified(&em, EMITTER_POINTS, 0x1B0u + (unsigned)light, pts);
    }
    lr_lpv *v = NULL;
    if ((rc = build_box(s, n, &v, e)))
        return rc;
    st.cell_mm = lr_lpv_h(v);
    lr_lpv_objfield *of = d ? d->objects : NULL;
    if (of && (rc = lr_lpv_objfield_reset(of, v, e))) {
        lr_lpv_destroy(v);
        return rc;
    }
    samples ss = {0};
    rc = receiver_samples(s, v, &ss, &st.samples_receivers);
    if (rc)
        lr_err_set(e, rc, "lpv: out of memory for receiver samples");
    if (!rc)
        rc = object_samples(s, v, nrec, &ss, &st.samples_objects, e);
    for (int k = 0; k < ss.n && !rc; k++)
        rc = lr_lpv_add_blocker(v, ss.s[k].p, ss.s[k].n,
                                ss.s[k].area * (ss.s[k].group == nrec ? OBJECT_BLOCK : 1.0), e);
    /* phi: the lobe each sample injects, per side (receivers: side 0 only). */
    size_t ns = (size_t)(ss.n ? ss.n : 1);
    double *phi = rc ? NULL : calloc(6 * ns, sizeof *phi);
    double *next = rc ? NULL : calloc(6 * ns, sizeof *next);
    lr_lpv_tpl *tpl = rc ? NULL : calloc(2 * ns, sizeof *tpl);
    if (!rc && (!phi || !next || !tpl))
        rc = lr_err_set(e, LR_ENOMEM, "lpv: out of memory");
    /* Direct light on every sample (the gathering of Eq. 3b). Point and spot lights: I cos /
     * d^2 per unit intensity with the spot's cone, 0 when an object is in the way: the shadow
     * test of the renderer's direct light (the light G-buffer's, done with rays as in the CPU
     * twin). */
    double *Ed = rc ? NULL : calloc(ns, sizeof *Ed);
    if (!rc && !Ed)
        rc = lr_err_set(e, LR_ENOMEM, "lpv: out of memory");
    int ntpl = 0;
    for (int k = 0; k < ss.n && !rc; k++) {
        const sample *x = &ss.s[k];
        double E[2][3] = {{0}};
        for (int side = 0; side < (x->two_sided ? 2 : 1); side++) {
            lr_vec3 nn = side_n(x, side);
            double Es = area ? direct(s, &em, pts, x->p, nn)
                             : lr_direct_irradiance(s, li, x->p, nn);
            for (int c = 0; c < 3; c++)
                E[side][c] = Es;
        }
        Ed[k] = E[0][0];
        if (x->group < nrec) {
            st.direct_receivers += E[0][0] * x->area;
            continue;
        }
        /* An object: what leaves a side the VPLs cover (the outermost surface, facing out)
         * reaches the receivers by the VPLs already; it becomes a TPL, whose light the
         * receivers' samples gather and reflect (Eq. 6b). What leaves any other side (a
         * cavity's inner wall) reaches them through nothing else: a lobe (Eq. 3b-4). */
        double o[2][3];
        object_out(x, E, o);
        for (int side = 0; side < 2; side++) {
            if (x->outer[side]) {
                lr_lpv_tpl *t = &tpl[ntpl++];
                t->p = side_p(x, side);
                t->n = side_n(x, side);
                t->area = x->area;
                t->object = x->object;
                memcpy(t->phi, o[side], sizeof t->phi);
                for (int c = 0; c < 3; c++)
                    st.emergent[c] += o[side][c];
            } else {
                memcpy(&phi[6 * k + 3 * side], o[side], sizeof o[side]);
            }
        }
    }
    /* The receivers: rho (E + E_TPL) A (Eq. 3b and 6b). */
    lr_lpv_tpl *merged = NULL;
    int nmerged = 0;
    if (!rc)
        rc = lr_lpv_tpl_merge(tpl, ntpl, lr_lpv_origin(v), 2.0 * lr_lpv_h(v), &merged, &nmerged,
                              e);
    st.tpls = nmerged;
    for (int k = 0; k < ss.n && !rc; k++) {
        const sample *x = &ss.s[k];
        if (x->group >= nrec)
            continue;
        double Et[3] = {0, 0, 0};
        lr_lpv_tpl_irradiance(s, merged, nmerged, 0.01 * lr_lpv_h(v), x->p, x->n, Et);
        for (int c = 0; c < 3; c++) {
            phi[6 * k + c] = x->refl[c] * Ed[k] * x->area;
            st.injected_receivers[c] += phi[6 * k + c];
            double pe = x->refl[c] * Et[c] * x->area;
            st.injected_emergent[c] += pe;
            phi[6 * k + c] += pe;
        }
    }
    free(merged);
    free(tpl);
    free(Ed);
    lr_lpv_propagate_fn prop = d && d->propagate ? d->propagate : cpu_propagate;
    void *ctx = d ? d->ctx : NULL;
    int bounces = d && d->bounces > 0 ? d->bounces : 0;
    bool transmit = d && d->transmit;
    for (int b = 0; b <= bounces && !rc; b++) {
        for (int g = b == 0 ? 0 : nrec; g <= nrec && !rc; g++) {
            lr_lpv_clear_light(v);
            bool any = false;
            for (int k = 0; k < ss.n && !rc; k++) {
                const sample *x = &ss.s[k];
                if (x->group != g)
                    continue;
                for (int side = 0; side < 2 && !rc; side++) {
                    const double *f = &phi[6 * k + 3 * side];
                    if (!(f[0] + f[1] + f[2] > 0.0))
                        continue;
                    rc = lr_lpv_inject_lobe(v, side_p(x, side), side_n(x, side), f, e);
                    for (int c = 0; c < 3; c++)
                        st.injected[c] += f[c];
                    any = true;
                }
            }
            if (rc || !any)
                continue;
            if ((rc = prop(ctx, v, 4 * n, e)))
                break;
            /* The objects lit by the receivers' reflection (objfield.h). */
            if (of && g < nrec)
                lr_lpv_objfield_add(of, v);
            double got[3] = {0, 0, 0};
            gather_receivers(s, v, g, out, got);
            for (int c = 0; c < 3; c++) {
                st.gathered[c] += got[c];
                if (g == nrec)
                    st.gathered_objects[c] += got[c];
            }
            /* The objects gather what this volume delivered to each side (the objects lit
             * by the receivers and by their own cavity), for the next bounce. */
            for (int k = 0; k < ss.n && b < bounces; k++) {
                const sample *x = &ss.s[k];
                if (x->group != nrec)
                    continue;
                for (int side = 0; side < (x->two_sided ? 2 : 1); side++) {
                    double E[3];
                    lr_lpv_irradiance(v, x->p, side_n(x, side), E);
                    for (int c = 0; c < 3; c++) {
                        next[6 * k + 3 * side + c] += E[c];
                        st.object_irradiance[c] += E[c] * x->area;
                    }
                }
            }
        }
        /* The next bounce: the objects reflect (R) what the volume delivered to them back
         * to the side it came from, and with d->transmit thin walls send T of it out of
         * their other face. None of it is in the maps or VPLs, so every side injects. (Off
         * by default: the votive's near table overshoots to 1.47 of the reference with it,
         * 1.14 without, while its outer glow from the maps alone is already 0.98; README
         * "Figures".) */
        for (int k = 0; k < ss.n && next; k++) {
            const sample *x = &ss.s[k];
            double E[2][3], o[2][3] = {{0}};
            memcpy(E, &next[6 * k], sizeof E);
            if (x->group == nrec && transmit)
                object_out(x, E, o);
            else if (x->group == nrec)
                for (int c = 0; c < 3; c++)
                    for (int side = 0; side < 2; side++)
                        o[side][c] = x->refl[c] * E[side][c] * x->area;
            memcpy(&phi[6 * k], o, sizeof o);
            memset(&next[6 * k], 0, sizeof E);
        }
    }
    free(next);
    free(phi);
    free(ss.s);
    lr_lpv_destroy(v);
    if (stats)
        *stats = st;
    return rc;
}
