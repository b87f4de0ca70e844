/* A photometric file resampled to the renderer's profile grid, its lookup and its sampler
 * (profile.h). */
#include <math.h>
#include <string.h>

#include "render/photometry/profile.h"

#define DEG (M_PI / 180.0)

static uint64_t fnv1a(const void *p, size_t n)
{
    const unsigned char *b = p;
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < n; i++)
        h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

/* The midpoint rule over the grid's own bilinear interpolant, fine enough (0.25 degree in
 * gamma, 1 in C) that its error is far below the grid's (as lr_luminaire_flux). */
static double integrate(const lr_light_profile *p, double gamma_max_deg)
{
    const int ng = (int)lrint(gamma_max_deg / 0.25), nc = 360;
    double sum = 0.0;
    for (int i = 0; i < ng; i++) {
        double g0 = i * 0.25 * DEG, g1 = (i + 1) * 0.25 * DEG;
        double dmu = cos(g0) - cos(g1), cg = cos(0.5 * (g0 + g1)), row = 0.0;
        for (int j = 0; j < nc; j++)
            row += lr_light_profile_at(p, cg, j + 0.5);
        sum += row * dmu * DEG;
    }
    return sum;
}

int lr_light_profile_from_luminaire(const lr_luminaire *lum, lr_light_profile *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    double mx = lr_luminaire_max_cd(lum);
    if (!(mx > 0.0) || !isfinite(mx))
        return lr_err_set(e, LR_EINVAL, "the file's intensities are all zero");
    for (int c = 0; c < LR_PROFILE_NC; c++)
        for (int g = 0; g < LR_PROFILE_NG; g++) {
            double v = lr_luminaire_cd(lum, c * LR_PROFILE_DC, g * LR_PROFILE_DG) / mx;
            out->rel[c * LR_PROFILE_NG + g] = (float)fmin(1.0, fmax(0.0, v));
        }
    out->on = true;
    out->max_cd = mx;
    out->lumens = lum->lumens > 0.0 ? lum->lumens : 0.0;
    out->omega = integrate(out, 180.0);
    out->omega_down = integrate(out, 90.0);
    out->hash = fnv1a(out->rel, sizeof out->rel);
    return LR_OK;
}

int lr_light_profile_load(const char *path, lr_light_profile *out, lr_err *e)
{
    lr_luminaire lum;
    int rc = lr_luminaire_load(path, &lum, e);
    if (rc)
        return rc;
    lr_err inner = {0};
    rc = lr_light_profile_from_luminaire(&lum, out, &inner);
    lr_luminaire_free(&lum);
    if (rc)
        return lr_err_set(e, rc, "%s: %s", path, inner.msg);
    return LR_OK;
}

double lr_light_profile_at(const lr_light_profile *p, double cos_gamma, double c_deg)
{
    double g = acos(fmin(1.0, fmax(-1.0, cos_gamma))) / (LR_PROFILE_DG * DEG);
    double c = fmod(c_deg, 360.0);
    if (c < 0.0)
        c += 360.0;
    c /= LR_PROFILE_DC;
    int g0 = (int)g, c0 = (int)c;
    if (g0 > LR_PROFILE_NG - 2)
        g0 = LR_PROFILE_NG - 2;
    if (c0 > LR_PROFILE_NC - 2)
        c0 = LR_PROFILE_NC - 2;
    double fg = g - g0, fc = c - c0;
    const float *r0 = p->rel + c0 * LR_PROFILE_NG, *r1 = r0 + LR_PROFILE_NG;
    double a = r0[g0] + fg * (r0[g0 + 1] - r0[g0]);
    double b = r1[g0] + fg * (r1[g0 + 1] - r1[g0]);
    return a + fc * (b - a);
}

double lr_light_profile_eval(const lr_light_profile *p, lr_vec3 d)
{
    /* Straight along the axis the C angle is undefined and every plane meets: atan2(0, 0) = 0
     * picks C0, which equals the others there for a file that is continuous at the poles. */
    return lr_light_profile_at(p, d.z, atan2(d.y, d.x) / DEG);
}

double lr_light_profile_cone_omega(const lr_light_profile *p, double inner_deg, double outer_deg)
{
    double ci = cos(inner_deg * DEG), co = cos(outer_deg * DEG), sum = 0.0;
    int nt = (int)ceil(outer_deg / 0.5);
    double dt = outer_deg / nt * DEG;
    for (int i = 0; i < nt; i++) {
        double t0 = i * dt, t1 = (i + 1) * dt, tm = 0.5 * (t0 + t1), c = cos(tm);
        double cone = c >= ci ? 1.0 : c <= co ? 0.0 : (c - co) / (ci - co);
        if (c < ci && c > co)
            cone = cone * cone * (3.0 - 2.0 * cone);
        double row = 0.0;
        for (int j = 0; j < 72; j++)
            row += lr_light_profile_at(p, c, (j + 0.5) * 5.0);
        sum += cone * row * (cos(t0) - cos(t1)) * (2.0 * M_PI / 72.0);
    }
    return sum;
}

void lr_light_profile_frame(lr_vec3 n, lr_vec3 c0_hint, lr_vec3 *x, lr_vec3 *y, lr_vec3 *z)
{
    *z = n;
    lr_vec3 h = c0_hint;
    lr_vec3 t = lr_v3_sub(h, lr_v3_scale(n, lr_v3_dot(h, n)));
    if (!(lr_v3_len(t) > 1e-6 * (lr_v3_len(h) + 1e-300))) {
        h = fabs(n.x) < 0.9 ? lr_v3(1.0, 0.0, 0.0) : lr_v3(0.0, 1.0, 0.0);
        t = lr_v3_sub(h, lr_v3_scale(n, lr_v3_dot(h, n)));
    }
    *x = lr_v3_normalize(t);
    *y = lr_v3_cross(*x, n);
}

int lr_profile_sampler_init(const lr_light_profile *p, bool lower_only, lr_profile_sampler *s,
                            lr_err *e)
{
    const int nc = LR_PROFILE_NC - 1, ng = lower_only ? (LR_PROFILE_NG - 1) / 2 : LR_PROFILE_NG - 1;
    double acc = 0.0;
    memset(s, 0, sizeof *s);
    s->gamma_cells = ng;
    for (int c = 0; c < nc; c++)
        for (int g = 0; g < ng; g++) {
            const float *r0 = p->rel + c * LR_PROFILE_NG, *r1 = r0 + LR_PROFILE_NG;
            double mean = 0.25 * ((double)r0[g] + r0[g + 1] + r1[g] + r1[g + 1]);
            double omega = LR_PROFILE_DC * DEG *
                           (cos(g * LR_PROFILE_DG * DEG) - cos((g + 1) * LR_PROFILE_DG * DEG));
            acc += mean * omega;
            s->cdf[c * ng + g] = acc;
        }
    s->total = acc;
    if (!(acc > 0.0))
        return lr_err_set(e, LR_EINVAL, "the profile sends no light %s",
                          lower_only ? "below its horizon (gamma < 90)" : "anywhere");
    return LR_OK;
}

lr_vec3 lr_profile_sample(const lr_profile_sampler *s, double u1, double u2, double u3,
                          double *pdf)
{
    const int ng = s->gamma_cells, n = (LR_PROFILE_NC - 1) * ng;
    double target = u3 * s->total;
    int lo = 0, hi = n - 1;
    while (lo < hi) { /* the first cell whose running sum exceeds the target */
        int mid = (lo + hi) / 2;
        if (s->cdf[mid] > target)
            hi = mid;
        else
            lo = mid + 1;
    }
    int c = lo / ng, g = lo % ng;
    double w = s->cdf[lo] - (lo ? s->cdf[lo - 1] : 0.0);
    double mu0 = cos(g * LR_PROFILE_DG * DEG), mu1 = cos((g + 1) * LR_PROFILE_DG * DEG);
    double omega = LR_PROFILE_DC * DEG * (mu0 - mu1);
    /* Uniform in solid angle within the cell: uniform in cos(gamma) and in C. */
    double mu = mu0 + u1 * (mu1 - mu0), phi = (c + u2) * LR_PROFILE_DC * DEG;
    double sn = sqrt(fmax(0.0, 1.0 - mu * mu));
    *pdf = w / s->total / omega;
    return lr_v3(sn * cos(phi), sn * sin(phi), mu);
}
