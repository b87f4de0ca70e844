/* Next-event connections from a vertex to an emitter, through smooth refractive boundaries.
 *
 * Why. A point light enclosed by a dielectric (the flame in a wax candle, the bulb in a shade)
 * reaches a scattering vertex x inside the material only along a refracted ray: the path
 * light -> y (boundary, specular) -> x. A unidirectional walk can never hit a point light, and
 * a shadow ray toward the light crosses the boundary unrefracted, so neither counts it: a
 * renderer that only "walks to the boundary" leaves such a candle black. We instead solve for
 * the connection, as manifold next-event estimation does (Hanika, Droske, Fascione 2015,
 * "Manifold next event estimation"), but parameterised by the emission direction w at the
 * light:
 *
 *   F(w) = where the ray leaving the light along w, refracted at each of the k interfaces the
 *          straight segment p -> x crosses, passes the plane through x perpendicular to it
 *          (or the same from x toward the light when x is the end in the thinner medium);
 *
 * Newton's method drives F(w) - x to zero from the straight-line guess. At the solution the
 * same 2x2 Jacobian J = dF/dw (mm per radian, in the plane perpendicular to the arriving ray)
 * is the ray-tube cross-section per unit solid angle at the light, so the flux density
 * arriving at x across the beam is exactly
 *
 *   E = I(w) * prod_i T_fresnel,i * exp(-sum of optical depths) / |det J|
 *
 * (with no interface, det J = |x - p|^2 and this is the inverse-square law). This is the
 * "generalised geometry term" of a specular chain (Hanika et al. Sec. 4; Jakob & Marschner
 * 2012), obtained here by finite differences of the traced chain so that it holds for any
 * shape behind the geometry interface (analytic or mesh). Radiance over n^2 conservation is
 * implied: E is a flux density, valid in any medium.
 *
 * Limits (documented in render/reference/README.md): the connection keeps the interface sequence
 * of the straight
 * segment, and one solution is found. Where refraction produces several (beyond a caustic of
 * a strongly curved, high-index boundary) or a different sequence, those paths are lost;
 * failures are counted in lr_ref_stats.nee_unsolved. In the dense media this rig renders the
 * connection is a few mean free paths long and the solution is unique. On faceted meshes the
 * refracted fans of adjacent facets leave dark wedges with no solution (counted as unsolved,
 * correctly contributing nothing); connections at a wedge's border are sometimes missed
 * (-0.13 % of the transmitted power measured on faceted cavities, tests/reference/test_reference_mesh.c). */
#include "render/reference/ref_priv.h"

#include "render/optics/optics.h"

/* Russian roulette below this transmittance estimate (exp(-tau_bound), see
 * lr_ref_chain_topology): a connection from deep inside a dense medium, or through a thick
 * one, is attempted with probability estimate / LR_REF_NEE_RR and weighted by the inverse
 * (unbiased). With k = 1 the estimate bounds the transmittance, so no weight exceeds
 * 1 / LR_REF_NEE_RR times it; through middle segments it is an estimate only. */
#define LR_REF_NEE_RR 1e-3
/* Newton: forward-difference step in the emission direction (radians) and iteration cap. */
#define NEWTON_H 1e-6
#define NEWTON_ITERS 40

static bool is_refractive(const lr_ref_scene *s, const lr_ref_object *ob)
{
    return s->media[ob->inside].eta != s->media[ob->outside].eta;
}

void lr_ref_chain_topology(const lr_ref_scene *s, lr_vec3 p, int mp, lr_vec3 x, int mx,
                           lr_ref_topology *out)
{
    lr_vec3 dv = lr_v3_sub(x, p);
    double len = lr_v3_len(dv);
    lr_vec3 u = lr_v3_scale(dv, 1.0 / len);
    lr_vec3 o = p;
    int m = mp;
    double remaining = len;
    lr_vec3 first_p = p, first_n = u, last_p = p, last_n = u;
    double tau_last_cross[3] = {0, 0, 0}; /* tau up to the last refractive crossing so far */
    double tau_first_cross[3] = {0, 0, 0};
    out->k = 0;
    for (int b = 0; b < 3; b++)
        out->tau[b] = 0.0;
    double stop = lr_ref_eps(x); /* x may sit on a receiver: stop just short of it */
    for (;;) {
        lr_ref_surf h;
        double tmin = lr_ref_eps(o);
        if (remaining - stop <= tmin ||
            !lr_ref_scene_intersect(s, o, u, tmin, remaining - stop, &h)) {
            for (int b = 0; b < 3; b++)
                out->tau[b] += s->media[m].sigma_t[b] * remaining;
            break;
        }
        for (int b = 0; b < 3; b++)
            out->tau[b] += s->media[m].sigma_t[b] * h.t;
        remaining -= h.t;
        o = h.p;
        const lr_ref_object *ob = &s->objects[h.object];
        if (ob->kind != LR_REF_SURF_BOUNDARY) {
            out->k = -1;
            return;
        }
        bool front = lr_v3_dot(u, h.n) < 0.0;
        if ((front ? ob->outside : ob->inside) != m) {
            out->k = -1;
            return;
        }
        m = front ? ob->inside : ob->outside;
        if (is_refractive(s, ob)) {
            if (++out->k > LR_REF_MAX_CHAIN) {
                out->k = -1;
                return;
            }
            if (out->k == 1) {
                first_p = h.p;
                first_n = h.n;
                for (int b = 0; b < 3; b++)
                    tau_first_cross[b] = out->tau[b];
            }
            last_p = h.p;
            last_n = h.n;
            for (int b = 0; b < 3; b++)
                tau_last_cross[b] = out->tau[b];
        }
    }
    if (m != mx) {
        out->k = -1;
        return;
    }
    /* End segments: the depth of each end below the plane of its nearest crossing (a lower
     * bound on any refracted path's length there). Middle segments, between the first and
     * the last crossing: their straight-line optical depth, which the refracted path
     * approximates (not a bound; it only sets a roulette probability, see LR_REF_NEE_RR). */
    double dx = out->k ? fabs(lr_v3_dot(lr_v3_sub(x, last_p), last_n)) : 0.0;
    double dp = out->k ? fabs(lr_v3_dot(lr_v3_sub(p, first_p), first_n)) : 0.0;
    for (int b = 0; b < 3; b++)
        out->tau_bound[b] = out->k ? s->media[mx].sigma_t[b] * dx +
                                         s->media[mp].sigma_t[b] * dp +
                                         (tau_last_cross[b] - tau_first_cross[b])
                                   : out->tau[b];
}

/* The chain of exactly k refractions from p (medium mp) along w. */
typedef struct chain {
    lr_vec3 o, d;   /* last refraction point and the direction leaving it */
    lr_vec3 n;      /* geometric normal of the surface at o */
    int m;          /* medium after the last refraction */
    double T;       /* product of Fresnel transmittances */
    double tau[3];  /* optical depth of the segments before o */
} chain;

static bool chain_trace(const lr_ref_scene *s, lr_vec3 p, int mp, lr_vec3 w, int k, chain *c)
{
    c->o = p;
    c->d = w;
    c->m = mp;
    c->T = 1.0;
    for (int b = 0; b < 3; b++)
        c->tau[b] = 0.0;
    int crossed = 0;
    /* Index-matched crossings do not count; bound them so a degenerate scene cannot loop. */
    for (int guard = 0; crossed < k && guard < 64; guard++) {
        lr_ref_surf h;
        if (!lr_ref_scene_intersect(s, c->o, c->d, lr_ref_eps(c->o), INFINITY, &h))
            return false;
        const lr_ref_object *ob = &s->objects[h.object];
        if (ob->kind != LR_REF_SURF_BOUNDARY)
            return false;
        bool front = lr_v3_dot(c->d, h.n) < 0.0;
        int from = front ? ob->outside : ob->inside, to = front ? ob->inside : ob->outside;
        if (from != c->m)
            return false;
        for (int b = 0; b < 3; b++)
            c->tau[b] += s->media[from].sigma_t[b] * h.t;
        c->o = h.p;
        c->m = to;
        double n1 = s->media[from].eta, n2 = s->media[to].eta;
        if (n1 == n2)
            continue;
        lr_vec3 nf = front ? h.n : lr_v3_scale(h.n, -1.0);
        double cos_i = -lr_v3_dot(c->d, nf);
        lr_vec3 t;
        if (!lr_ref_refract(c->d, nf, n1 / n2, &t))
            return false; /* total internal reflection: not a refraction chain */
        c->T *= lr_fresnel_transmittance(cos_i, n2 / n1);
        c->d = t;
        c->n = h.n;
        crossed++;
    }
    return crossed == k;
}

/* Where the chain's final ray meets the plane through x with normal nrm, in the plane's
 * frame (e1, e2) relative to x. */
static bool residual(const chain *c, lr_vec3 x, lr_vec3 nrm, lr_vec3 e1, lr_vec3 e2,
                     double r[2])
{
    double den = lr_v3_dot(c->d, nrm);
    if (den < 1e-3) /* the ray runs along the plane or away from it */
        return false;
    double t = lr_v3_dot(lr_v3_sub(x, c->o), nrm) / den;
    if (!(t > 0.0))
        return false;
    lr_vec3 q = lr_v3_sub(lr_v3_add(c->o, lr_v3_scale(c->d, t)), x);
    r[0] = lr_v3_dot(q, e1);
    r[1] = lr_v3_dot(q, e2);
    return true;
}

static lr_vec3 tilt(lr_vec3 w, lr_vec3 tu, lr_vec3 tv, double a, double b)
{
    return lr_v3_normalize(lr_v3_add(w, lr_v3_add(lr_v3_scale(tu, a), lr_v3_scale(tv, b))));
}

/* The refraction point on the plane through y with normal n for the path p -> x (indices np
 * on p's side, nx on x's): Snell's law np sin(theta_p) = nx sin(theta_x) in the plane of
 * incidence, a monotonic equation in the distance u along the plane from p's foot toward
 * x's, solved by bisection to double precision. False when p and x are on the same side. */
static bool planar_point(lr_vec3 p, double np, lr_vec3 x, double nx, lr_vec3 y, lr_vec3 n,
                         lr_vec3 *out)
{
    double sp = lr_v3_dot(lr_v3_sub(p, y), n), sx = lr_v3_dot(lr_v3_sub(x, y), n);
    if (!(sp * sx < 0.0))
        return false;
    lr_vec3 pp = lr_v3_sub(p, lr_v3_scale(n, sp)), xp = lr_v3_sub(x, lr_v3_scale(n, sx));
    lr_vec3 dv = lr_v3_sub(xp, pp);
    double D = lr_v3_len(dv), hp = fabs(sp), hx = fabs(sx);
    if (!(D > 0.0)) {
        *out = pp; /* normal incidence */
        return true;
    }
    double lo = 0.0, hi = D;
    for (int i = 0; i < 64 && hi - lo > 1e-15 * D; i++) {
        double u = 0.5 * (lo + hi);
        double f = np * u / sqrt(u * u + hp * hp) - nx * (D - u) / sqrt((D - u) * (D - u) + hx * hx);
        if (f > 0.0)
            hi = u;
        else
            lo = u;
    }
    *out = lr_v3_add(pp, lr_v3_scale(dv, 0.5 * (lo + hi) / D));
    return true;
}

/* Newton on the emission direction; on success *wout is the emission direction, *c the
 * converged chain and *det the Jacobian determinant (mm^2 / sr) there.
 *
 * For one interface a planar phase goes first: aim at the exact refraction point of the
 * tangent plane where the current ray meets the surface, and repeat. Its fixed point is the
 * exact solution for any surface (Snell's law at y with y's own normal); on a faceted mesh it
 * is reached as soon as the aim stays on one facet, where Newton's finite differences would
 * straddle facet edges and oscillate. Newton then polishes (curved surfaces) and gives J. */
static bool solve_chain(const lr_ref_scene *s, lr_vec3 p, int mp, lr_vec3 x, int k, chain *c,
                        lr_vec3 *wout, double *det)
{
    lr_vec3 w = lr_v3_normalize(lr_v3_sub(x, p));
    double tol = 1e-9 * (1.0 + lr_v3_len(lr_v3_sub(x, p)));
    if (k == 1) {
        for (int it = 0; it < 16; it++) {
            lr_vec3 y;
            if (!chain_trace(s, p, mp, w, 1, c) ||
                !planar_point(p, s->media[mp].eta, x, s->media[c->m].eta, c->o, c->n, &y))
                break;
            if (lr_v3_len(lr_v3_sub(y, c->o)) <= tol)
                break;
            w = lr_v3_normalize(lr_v3_sub(y, p));
        }
    }
    for (int it = 0; it < NEWTON_ITERS; it++) {
        chain cu, cv;
        if (!chain_trace(s, p, mp, w, k, c))
            return false;
        lr_vec3 nrm = c->d, e1, e2, tu, tv;
        lr_ref_frame(nrm, &e1, &e2);
        lr_ref_frame(w, &tu, &tv);
        double r0[2], ru[2], rv[2];
        if (!residual(c, x, nrm, e1, e2, r0) ||
            !chain_trace(s, p, mp, tilt(w, tu, tv, NEWTON_H, 0.0), k, &cu) ||
            !chain_trace(s, p, mp, tilt(w, tu, tv, 0.0, NEWTON_H), k, &cv) ||
            !residual(&cu, x, nrm, e1, e2, ru) || !residual(&cv, x, nrm, e1, e2, rv))
            return false;
        double j00 = (ru[0] - r0[0]) / NEWTON_H, j01 = (rv[0] - r0[0]) / NEWTON_H;
        double j10 = (ru[1] - r0[1]) / NEWTON_H, j11 = (rv[1] - r0[1]) / NEWTON_H;
        double dj = j00 * j11 - j01 * j10;
        if (!(fabs(dj) > 0.0) || !isfinite(dj))
            return false;
        if (hypot(r0[0], r0[1]) <= tol) {
            *wout = w;
            *det = fabs(dj);
            return true;
        }
        double a = -(j11 * r0[0] - j01 * r0[1]) / dj;
        double b = -(-j10 * r0[0] + j00 * r0[1]) / dj;
        /* Damped: no step tilts the direction by more than 0.2 rad. */
        double step = hypot(a, b);
        if (step > 0.2) {
            a *= 0.2 / step;
            b *= 0.2 / step;
        }
        w = tilt(w, tu, tv, a, b);
    }
    return false;
}

bool lr_ref_connect(const lr_ref_scene *s, const lr_ref_emitter *em, lr_vec3 x, int mx,
                    int mask, lr_ref_rng *rr, lr_ref_stats *st, double E[3], lr_vec3 *w_in)
{
    for (int b = 0; b < 3; b++)
        E[b] = 0.0;
    if (st)
        st->nee++;
    lr_ref_topology topo;
    lr_ref_chain_topology(s, em->p, em->medium, x, mx, &topo);
    if (topo.k < 0)
        return false;
    lr_vec3 w;        /* emission direction */
    double geom;      /* 1 / (ray-tube area per steradian) */
    double T = 1.0;   /* Fresnel transmittance and roulette weight */
    double tau[3];
    if (topo.k == 0) {
        lr_vec3 dv = lr_v3_sub(x, em->p);
        double d2 = lr_v3_dot(dv, dv);
        w = lr_v3_scale(dv, 1.0 / sqrt(d2));
        *w_in = lr_v3_scale(w, -1.0);
        geom = 1.0 / d2;
        for (int b = 0; b < 3; b++)
            tau[b] = topo.tau[b];
    } else {
        if (st)
            st->nee_refracted++;
        if (rr) {
            double bound = 0.0;
            for (int b = 0; b < 3; b++)
                if (mask & (1 << b))
                    bound = fmax(bound, exp(-topo.tau_bound[b]));
            if (bound < LR_REF_NEE_RR) {
                double q = bound / LR_REF_NEE_RR;
                if (!(lr_ref_rng_uniform(rr) < q))
                    return false;
                T /= q;
            }
        }
        /* Newton runs from the end in the optically thinner medium: rays leaving it refract
         * into the denser side under any angle, while rays leaving the dense side meet total
         * internal reflection beyond the critical angle, which would make the straight-line
         * start fail (a vertex inside wax connecting to the camera, say). Solved backwards,
         * the ray tube's Jacobian converts by etendue conservation (n^2 dA dw along a
         * pencil): det J_{p->x} = (n_p / n_x)^2 det J_{x->p}. */
        double np = s->media[em->medium].eta, nx = s->media[mx].eta;
        bool back = nx < np;
        chain c;
        double det;
        lr_vec3 w0;
        if (back ? !solve_chain(s, x, mx, em->p, topo.k, &c, &w0, &det)
                 : !solve_chain(s, em->p, em->medium, x, topo.k, &c, &w0, &det)) {
            if (st)
                st->nee_unsolved++;
            return false;
        }
        /* The final segment, from the last refraction to the far end: clear of anything but
         * index-matched boundaries, and ending in that end's medium. */
        lr_ref_topology fin;
        if (back)
            lr_ref_chain_topology(s, c.o, c.m, em->p, em->medium, &fin);
        else
            lr_ref_chain_topology(s, c.o, c.m, x, mx, &fin);
        if (fin.k != 0)
            return false;
        w = back ? lr_v3_scale(c.d, -1.0) : w0;
        *w_in = back ? w0 : lr_v3_scale(c.d, -1.0);
        geom = back ? (nx / np) * (nx / np) / det : 1.0 / det;
        T *= c.T;
        for (int b = 0; b < 3; b++)
            tau[b] = c.tau[b] + fin.tau[b];
    }
    bool any = false;
    for (int b = 0; b < 3; b++) {
        if (!(mask & (1 << b)))
            continue;
        E[b] = lr_ref_emitter_intensity(em, w, b) * T * exp(-tau[b]) * geom;
        any = any || E[b] > 0.0;
    }
    return any;
}
