#include "calib/fit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calib/nelder_mead.h"
#include "render/cpu/frame.h"
#include "render/mesh/bvh.h"

/* Coefficients outside this range are not materials the model is meant for (and the
 * diffusion estimators degenerate): the optimiser sees +inf there. mm^-1. */
#define SIGMA_MIN 1e-6
#define SIGMA_MAX 1e3

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

long lr_fit_object_mask(const lr_scene *s, int object, int w, int h, unsigned char *mask)
{
    long n = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            lr_vec3 o, d;
            lr_cpu_camera_ray(s, w, h, x, y, &o, &d);
            double best = INFINITY;
            int who = -1;
            lr_hit hit;
            for (int i = 0; i < lr_scene_object_count(s); i++)
                if (lr_bvh_intersect(lr_scene_object_at(s, i)->bvh, o, d, 0, best, &hit) &&
                    hit.t < best)
                    best = hit.t, who = i;
            for (int i = 0; i < lr_scene_receiver_count(s); i++)
                if (lr_bvh_intersect(lr_scene_receiver_at(s, i)->bvh, o, d, 0, best, &hit) &&
                    hit.t < best)
                    best = hit.t, who = -1;
            mask[(size_t)y * w + x] = who == object;
            n += who == object;
        }
    return n;
}

double lr_fit_rel_rmse(const lr_image *a, const lr_image *b, const unsigned char *mask,
                       double out[3])
{
    double se[3] = {0}, ss[3] = {0};
    for (size_t p = 0; p < (size_t)a->width * a->height; p++) {
        if (mask && !mask[p])
            continue;
        for (int c = 0; c < 3; c++) {
            double r = (double)a->rgb[3 * p + c] - b->rgb[3 * p + c];
            se[c] += r * r;
            ss[c] += (double)b->rgb[3 * p + c] * b->rgb[3 * p + c];
        }
    }
    for (int c = 0; c < 3 && out; c++)
        out[c] = ss[c] > 0 ? sqrt(se[c] / ss[c]) : INFINITY;
    double s = ss[0] + ss[1] + ss[2];
    return s > 0 ? sqrt((se[0] + se[1] + se[2]) / s) : INFINITY;
}

typedef struct ctx {
    const lr_fit_desc *d;
    int w, h;
    unsigned char *mask;
    double delta[3], tt[3]; /* Huber threshold, sum of target^2 over the mask, per band */
    int renders;
} ctx;

static int set_rgb(lr_scene *s, int object, const char *field, const double v[3], lr_err *e)
{
    char key[96], val[128];
    snprintf(key, sizeof key, "objects[%d].material.%s", object, field);
    snprintf(val, sizeof val, "%.17g,%.17g,%.17g", v[0], v[1], v[2]);
    return lr_scene_set(s, key, val, NULL, e);
}

static int set_material(lr_scene *s, int object, const double sa[3], const double ss[3],
                        lr_err *e)
{
    int rc = set_rgb(s, object, "sigma_a", sa, e);
    return rc ? rc : set_rgb(s, object, "sigma_s_prime", ss, e);
}

static bool in_domain(const double sa[3], const double ss[3])
{
    for (int c = 0; c < 3; c++)
        if (!(sa[c] >= SIGMA_MIN && sa[c] <= SIGMA_MAX && ss[c] >= SIGMA_MIN &&
              ss[c] <= SIGMA_MAX))
            return false;
    return true;
}

/* Renders the model at (sa, ss) into img (allocated by the renderer). half: 0 the full
 * sample count at the fit's seed; 1 or 2 half of it each at two independent seeds (the
 * pair's mean is the full-count render's equal in noise). */
static int model_half(ctx *c, const double sa[3], const double ss[3], lr_image *img, int half,
                      lr_err *e)
{
    const lr_fit_desc *d = c->d;
    int rc = set_material(d->scene, d->object, sa, ss, e);
    if (rc)
        return rc;
    lr_cpu_render_desc rd = {
        .scene = d->scene,
        .width = c->w,
        .height = c->h,
        .mode = LR_CPU_REFERENCE,
        .samples = (d->samples > 0 ? d->samples : 32) / (half ? 2 : 1),
        .vpl_count = d->vpl_count > 0 ? d->vpl_count : 64,
        .no_vpl = d->no_vpl,
        .seed = (d->seed ? d->seed : 1) + (half == 2 ? 7919u : 0u),
        .threads = d->threads,
    };
    c->renders++;
    if (rd.samples < 1)
        rd.samples = 1;
    return lr_cpu_render(&rd, img, NULL, NULL, e);
}

static int model(ctx *c, const double sa[3], const double ss[3], lr_image *img, lr_err *e)
{
    return model_half(c, sa, ss, img, 0, e);
}

/* sum_i 2 rho over the mask, band b, from two renders m1, m2 with independent seeds:
 * where the loss is quadratic the term is (m1_i - t_i)(m2_i - t_i), whose expectation is
 * (E m_i - t_i)^2 exactly, while E[(m - t)^2] = (E m - t)^2 + Var m. Without this the fit
 * drifts towards parameters whose estimate is quieter (darker, or lit nearer the surface),
 * which at a few dozen samples per pixel outweighs the signal. (Subtracting the render's
 * own variance estimate instead was tried: it overshoots, and the fit then seeks noise.)
 * Near a perfect fit the sum may go slightly negative. */
static double band_sum(const ctx *c, const lr_image *m1, const lr_image *m2, int b)
{
    const lr_image *t = c->d->target;
    double s = 0;
    for (size_t p = 0; p < (size_t)c->w * c->h; p++) {
        if (!c->mask[p])
            continue;
        double r1 = (double)m1->rgb[3 * p + b] - t->rgb[3 * p + b];
        double r2 = (double)m2->rgb[3 * p + b] - t->rgb[3 * p + b];
        double r = 0.5 * (r1 + r2), dl = c->delta[b];
        s += fabs(r) <= dl ? r1 * r2 : 2 * dl * fabs(r) - dl * dl;
    }
    return s;
}

static void from_log(const double *x, double *sa, double *ss)
{
    *sa = exp(x[0]);
    *ss = exp(x[1]);
}

/* The model's own relative noise at (sa, ss), all bands: two half-sample renders with
 * independent seeds differ by m1 - m2, whose variance is twice a half render's, i.e. four
 * times the full-sample render's; so sum ((m1 - m2) / 2)^2 / sum t^2 is the full render's
 * relative mean squared noise, the floor the residual cannot go below. */
static int noise_at(ctx *c, const double sa[3], const double ss[3], double *out, lr_err *e)
{
    lr_image m1 = {0}, m2 = {0};
    int rc = model_half(c, sa, ss, &m1, 1, e);
    if (!rc)
        rc = model_half(c, sa, ss, &m2, 2, e);
    if (!rc) {
        double se = 0;
        for (size_t p = 0; p < (size_t)c->w * c->h; p++)
            for (int b = 0; b < 3 && c->mask[p]; b++) {
                double dlt = 0.5 * ((double)m1.rgb[3 * p + b] - m2.rgb[3 * p + b]);
                se += dlt * dlt;
            }
        *out = sqrt(se / (c->tt[0] + c->tt[1] + c->tt[2]));
    }
    lr_image_free(&m1);
    lr_image_free(&m2);
    return rc;
}

/* Gauss-Newton standard errors of the log parameters per band, central differences of
 * +-h in log space (all bands moved together: they do not interact). */
static int uncertainty(ctx *c, const double sa[3], const double ss[3], const lr_image *at,
                       bool shared, double se[3][2], double cond[3], lr_err *e)
{
    const double h = 0.05;
    lr_image plus[2], minus[2];
    memset(plus, 0, sizeof plus);
    memset(minus, 0, sizeof minus);
    int rc = LR_OK;
    for (int k = 0; k < 2 && !rc; k++) {
        double a1[3], s1[3], a2[3], s2[3];
        for (int b = 0; b < 3; b++) {
            a1[b] = sa[b] * (k == 0 ? exp(h) : 1);
            s1[b] = ss[b] * (k == 1 ? exp(h) : 1);
            a2[b] = sa[b] * (k == 0 ? exp(-h) : 1);
            s2[b] = ss[b] * (k == 1 ? exp(-h) : 1);
        }
        if ((rc = model(c, a1, s1, &plus[k], e)) == LR_OK)
            rc = model(c, a2, s2, &minus[k], e);
        lr_progress_report(c->d->progress, "uncertainty", 2 * k + 4, 6);
    }
    if (!rc) {
        /* per band (or pooled over bands when the parameters are shared) */
        double JJ[3][3] = {{0}}, rr[3] = {0};
        long m[3] = {0};
        const lr_image *t = c->d->target;
        for (size_t p = 0; p < (size_t)c->w * c->h; p++) {
            if (!c->mask[p])
                continue;
            for (int b = 0; b < 3; b++) {
                int g = shared ? 0 : b;
                double j0 = (plus[0].rgb[3 * p + b] - minus[0].rgb[3 * p + b]) / (2 * h);
                double j1 = (plus[1].rgb[3 * p + b] - minus[1].rgb[3 * p + b]) / (2 * h);
                double r = (double)at->rgb[3 * p + b] - t->rgb[3 * p + b];
                JJ[g][0] += j0 * j0;
                JJ[g][1] += j0 * j1;
                JJ[g][2] += j1 * j1;
                rr[g] += r * r;
                m[g]++;
            }
        }
        for (int g = 0; g < 3; g++) {
            double det = JJ[g][0] * JJ[g][2] - JJ[g][1] * JJ[g][1];
            /* eigenvalues of the symmetric 2 x 2 J^T J: their ratio says how much flatter the
             * residual is along one parameter combination than along the other */
            double tr = JJ[g][0] + JJ[g][2], disc = sqrt(fmax(0.0, tr * tr / 4 - det));
            double lmax = tr / 2 + disc, lmin = tr / 2 - disc;
            cond[g] = shared && g ? 0 : lmin > 0 ? lmax / lmin : INFINITY;
            if (m[g] <= 2 || !(det > 0)) {
                se[g][0] = se[g][1] = shared && g ? 0 : INFINITY;
                continue;
            }
            double s2 = rr[g] / (m[g] - 2);
            se[g][0] = sqrt(s2 * JJ[g][2] / det);
            se[g][1] = sqrt(s2 * JJ[g][0] / det);
        }
    }
    for (int k = 0; k < 2; k++) {
        lr_image_free(&plus[k]);
        lr_image_free(&minus[k]);
    }
    return rc;
}

int lr_fit_run(const lr_fit_desc *d, lr_fit_result *r, lr_err *e)
{
    memset(r, 0, sizeof *r);
    double t0 = now_s();
    if (!d->scene || !d->target || !d->target->rgb)
        return lr_err_set(e, LR_EINVAL, "fit: scene and target are required");
    if (d->object < 0 || d->object >= lr_scene_object_count(d->scene))
        return lr_err_set(e, LR_EINVAL, "fit: object %d: the scene has %d objects", d->object,
                          lr_scene_object_count(d->scene));
    ctx c = {.d = d, .w = d->target->width, .h = d->target->height};
    if (c.w < 2 || c.h < 2)
        return lr_err_set(e, LR_EINVAL, "fit: target %d x %d is too small", c.w, c.h);
    c.mask = malloc((size_t)c.w * c.h);
    if (!c.mask)
        return lr_err_set(e, LR_ENOMEM, "fit: out of memory");
    long n = lr_fit_object_mask(d->scene, d->object, c.w, c.h, c.mask);
    r->object_pixels = n;
    double mean[3] = {0};
    for (size_t p = 0; p < (size_t)c.w * c.h; p++) {
        if (!c.mask[p])
            continue;
        bool ok = true;
        for (int b = 0; b < 3; b++)
            ok = ok && isfinite(d->target->rgb[3 * p + b]);
        if (!ok) {
            c.mask[p] = 0;
            n--;
            continue;
        }
        for (int b = 0; b < 3; b++) {
            double t = d->target->rgb[3 * p + b];
            mean[b] += fabs(t);
            c.tt[b] += t * t;
        }
    }
    int min_px = d->min_pixels > 0 ? d->min_pixels : 16;
    const char *oname = lr_scene_object_at(d->scene, d->object)->name;
    int rc = LR_OK;
    lr_image best_img = {0};
    if (n < min_px) {
        rc = lr_err_set(e, LR_EINVAL,
                        "fit: object '%s' covers %ld pixels of the camera's %d x %d view (at "
                        "least %d needed): no visible object to fit -- check the scene's "
                        "camera and the object's placement",
                        oname, n, c.w, c.h, min_px);
        goto done;
    }
    for (int b = 0; b < 3; b++) {
        if (!(c.tt[b] > 0)) {
            rc = lr_err_set(e, LR_EINVAL,
                            "fit: the captures are black over object '%s' in band %d: nothing "
                            "to fit (was the light on?)",
                            oname, b);
            goto done;
        }
        c.delta[b] = (d->huber > 0 ? d->huber : 0.1) * mean[b] / n;
    }
    r->mask_pixels = n;

    const lr_medium *m0 = &lr_scene_object_at(d->scene, d->object)->material.medium;
    double sa0[3], ss0[3];
    for (int b = 0; b < 3; b++) {
        bool given = d->mode == LR_FIT_SIGMA && d->sigma_a_start[0] > 0;
        sa0[b] = given ? d->sigma_a_start[b] : m0->sigma_a[b];
        ss0[b] = given ? d->sigma_s_start[b] : m0->sigma_s_prime[b];
        /* a zero coefficient has no logarithm: start from the domain's floor */
        sa0[b] = fmax(sa0[b], 10 * SIGMA_MIN);
        ss0[b] = fmax(ss0[b], 10 * SIGMA_MIN);
    }
    int max_evals = d->max_evals > 0 ? d->max_evals : 200;
    int restarts = d->restarts > 0 ? d->restarts : d->restarts < 0 ? 0 : 2;
    /* steps: a factor of 2 (ln 2) per coordinate; tolerances: 1e-4 relative in the loss,
     * 1e-3 in log sigma (0.1 %, far below what the noise lets one resolve) */
    const double step[2] = {M_LN2, M_LN2};
    lr_nm nm[3];
    int runs = d->mode == LR_FIT_SCALE ? 1 : 3;
    double sc0[2] = {d->scale_start[0] > 0 ? d->scale_start[0] : 1,
                     d->scale_start[1] > 0 ? d->scale_start[1] : 1};
    for (int k = 0; k < runs; k++) {
        double x0[2] = {log(sa0[k]), log(ss0[k])};
        if (d->mode == LR_FIT_SCALE)
            x0[0] = log(sc0[0]), x0[1] = log(sc0[1]);
        lr_nm_init(&nm[k], 2, x0, step, 1e-4, 1e-3, max_evals, restarts);
    }
    /* the start's error, for the report */
    {
        double sa[3], ss[3];
        for (int b = 0; b < 3; b++) {
            double f = d->mode == LR_FIT_SCALE ? sc0[0] : 1, g = d->mode == LR_FIT_SCALE ? sc0[1] : 1;
            sa[b] = sa0[b] * f, ss[b] = ss0[b] * g;
        }
        lr_image img = {0};
        if ((rc = model(&c, sa, ss, &img, e)))
            goto done;
        r->start_rel_rmse = lr_fit_rel_rmse(&img, d->target, c.mask, NULL);
        lr_image_free(&img);
    }
    /* a run stops once max_evals are spent, but the simplex step under way may take two more
     * (reflection, contraction, the first point of a shrink) */
    int evaluation = 0, eval_bound = max_evals + 2;
    lr_progress_report(d->progress, "evaluations", 0, eval_bound);
    for (;;) {
        double x[3][2], sa[3], ss[3];
        bool active[3] = {false, false, false}, any = false;
        for (int k = 0; k < runs; k++) {
            active[k] = lr_nm_ask(&nm[k], x[k]);
            if (!active[k])
                lr_nm_best(&nm[k], x[k]);
            any = any || active[k];
        }
        if (!any)
            break;
        for (int b = 0; b < 3; b++) {
            if (d->mode == LR_FIT_SCALE) {
                sa[b] = sa0[b] * exp(x[0][0]);
                ss[b] = ss0[b] * exp(x[0][1]);
            } else {
                from_log(x[b], &sa[b], &ss[b]);
            }
        }
        double f[3] = {INFINITY, INFINITY, INFINITY};
        if (in_domain(sa, ss)) {
            lr_image img = {0}, img2 = {0}; /* the two half renders */
            lr_err me = {0};
            int mrc = model_half(&c, sa, ss, &img, 1, &me);
            if (!mrc)
                mrc = model_half(&c, sa, ss, &img2, 2, &me);
            if (mrc == LR_ENOMEM) {
                rc = lr_err_set(e, mrc, "%s", me.msg);
                goto done;
            }
            if (!mrc) {
                if (d->mode == LR_FIT_SCALE) {
                    double s = 0;
                    for (int b = 0; b < 3; b++)
                        s += band_sum(&c, &img, &img2, b);
                    f[0] = s / (c.tt[0] + c.tt[1] + c.tt[2]);
                } else {
                    for (int b = 0; b < 3; b++)
                        f[b] = band_sum(&c, &img, &img2, b) / c.tt[b];
                }
            }
            lr_image_free(&img);
            lr_image_free(&img2);
        }
        for (int k = 0; k < runs; k++)
            if (active[k])
                lr_nm_tell(&nm[k], f[k]);
        lr_progress_report(d->progress, "evaluations", ++evaluation, eval_bound);
    }
    /* the optimiser stopped (converged, usually before max_evals): the stage ends here */
    lr_progress_report(d->progress, "evaluations", evaluation, evaluation);
    for (int k = 0; k < runs; k++) {
        double x[2];
        double f2 = lr_nm_best(&nm[k], x); /* the optimiser minimised L^2 (signed) */
        r->loss[k] = isfinite(f2) ? sqrt(fmax(0.0, f2)) : INFINITY;
        r->iterations[k] = nm[k].iterations;
        r->evals[k] = nm[k].evals;
        if (d->mode == LR_FIT_SCALE) {
            r->scale[0] = exp(x[0]), r->scale[1] = exp(x[1]);
            for (int b = 0; b < 3; b++) {
                r->sigma_a[b] = sa0[b] * r->scale[0];
                r->sigma_s_prime[b] = ss0[b] * r->scale[1];
                r->loss[b] = r->loss[0];
            }
        } else {
            from_log(x, &r->sigma_a[k], &r->sigma_s_prime[k]);
        }
    }
    if (!isfinite(r->loss[0]) || !isfinite(r->loss[1]) || !isfinite(r->loss[2])) {
        rc = lr_err_set(e, LR_EINVAL,
                        "fit: the model could not be evaluated anywhere the optimiser looked "
                        "(coefficients outside %g..%g mm^-1?)",
                        SIGMA_MIN, SIGMA_MAX);
        goto done;
    }
    lr_progress_report(d->progress, "uncertainty", 0, 6);
    if ((rc = model(&c, r->sigma_a, r->sigma_s_prime, &best_img, e)))
        goto done;
    r->rel_rmse_all = lr_fit_rel_rmse(&best_img, d->target, c.mask, r->rel_rmse);
    if ((rc = noise_at(&c, r->sigma_a, r->sigma_s_prime, &r->noise_rel, e)))
        goto done;
    lr_progress_report(d->progress, "uncertainty", 2, 6);
    if ((rc = uncertainty(&c, r->sigma_a, r->sigma_s_prime, &best_img, d->mode == LR_FIT_SCALE,
                          r->stderr_log, r->cond, e)))
        goto done;
    /* leave the scene at the result */
    rc = set_material(d->scene, d->object, r->sigma_a, r->sigma_s_prime, e);
done:
    lr_image_free(&best_img);
    r->renders = c.renders;
    r->seconds = now_s() - t0;
    free(c.mask);
    return rc;
}
