/* lamprig — the light-propagation volume's irradiance on the objects (objfield.h). */
#include "render/lpv/objfield.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/optics/optics.h"

struct lr_lpv_objfield {
    int n;
    lr_vec3 origin;
    double h;
    double *E;    /* (n+1)^3 interfaces x 6 (2 a + s) x 3 channels, summed */
    float *tex;   /* the texels (objfield.h), kept in step with E */
    bool lit;
};

int lr_lpv_objfield_create(lr_lpv_objfield **out, lr_err *e)
{
    lr_lpv_objfield *f = calloc(1, sizeof *f);
    if (!f)
        return lr_err_set(e, LR_ENOMEM, "lpv objects: out of memory");
    *out = f;
    return LR_OK;
}

void lr_lpv_objfield_destroy(lr_lpv_objfield *f)
{
    if (!f)
        return;
    free(f->E);
    free(f->tex);
    free(f);
}

static size_t ifaces(int n) { return (size_t)(n + 1) * (size_t)(n + 1) * (size_t)(n + 1); }

int lr_lpv_objfield_reset(lr_lpv_objfield *f, const lr_lpv *v, lr_err *e)
{
    int n = lr_lpv_n(v);
    if (n != f->n || !f->E) {
        free(f->E);
        free(f->tex);
        f->E = calloc(ifaces(n) * 18, sizeof *f->E);
        f->tex = calloc(ifaces(n) * 24, sizeof *f->tex);
        if (!f->E || !f->tex) {
            free(f->E);
            free(f->tex);
            f->E = NULL;
            f->tex = NULL;
            f->n = 0;
            return lr_err_set(e, LR_ENOMEM, "lpv objects: out of memory for %d^3 cells", n);
        }
    } else {
        memset(f->E, 0, ifaces(n) * 18 * sizeof *f->E);
        memset(f->tex, 0, ifaces(n) * 24 * sizeof *f->tex);
    }
    f->n = n;
    f->origin = lr_lpv_origin(v);
    f->h = lr_lpv_h(v);
    f->lit = false;
    return LR_OK;
}

void lr_lpv_objfield_clear(lr_lpv_objfield *f)
{
    free(f->E);
    free(f->tex);
    f->E = NULL;
    f->tex = NULL;
    f->n = 0;
    f->lit = false;
}

/* Texel of interface (i, j, k), field q = 2 a + s (objfield.h). */
static size_t texel(int n, int i, int j, int k, int q)
{
    size_t n1 = (size_t)n + 1;
    return (((size_t)k * 6 + (size_t)q) * n1 + (size_t)j) * n1 + (size_t)i;
}

void lr_lpv_objfield_add(lr_lpv_objfield *f, const lr_lpv *v)
{
    int n = f->n;
    lr_vec3 o = lr_lpv_origin(v);
    if (!f->E || lr_lpv_n(v) != n || lr_lpv_h(v) != f->h || o.x != f->origin.x ||
        o.y != f->origin.y || o.z != f->origin.z)
        return;
    const float *blk = lr_lpv_blocking(v);
    const double *ab = lr_lpv_absorbed(v);
    double h2 = f->h * f->h;
    int n1 = n + 1;
    for (int k = 0; k < n1; k++)
        for (int j = 0; j < n1; j++)
            for (int i = 0; i < n1; i++) {
                size_t iface = ((size_t)k * n1 + j) * n1 + i;
                for (int a = 0; a < 3; a++) {
                    double B = fmin(1.0, blk[iface * 4 + a]);
                    if (!(B > 0.0))
                        continue;
                    for (int s = 0; s < 2; s++) {
                        int q = 2 * a + s;
                        float *t = f->tex + 4 * texel(n, i, j, k, q);
                        for (int ch = 0; ch < 3; ch++) {
                            double *acc = &f->E[(iface * 6 + (size_t)q) * 3 + ch];
                            *acc += ab[(iface * 6 + (size_t)q) * 3 + ch] / (B * h2);
                            t[ch] = (float)*acc;
                            f->lit |= *acc > 0.0;
                        }
                        t[3] = 1.0f;
                    }
                }
            }
}

bool lr_lpv_objfield_lit(const lr_lpv_objfield *f) { return f->lit; }
int lr_lpv_objfield_n(const lr_lpv_objfield *f) { return f->E ? f->n : 0; }
lr_vec3 lr_lpv_objfield_origin(const lr_lpv_objfield *f) { return f->origin; }
double lr_lpv_objfield_h(const lr_lpv_objfield *f) { return f->h; }
const float *lr_lpv_objfield_texels(const lr_lpv_objfield *f) { return f->E ? f->tex : NULL; }

typedef struct texel_ctx {
    const float *tex;
    int N;
} texel_ctx;

/* Side s of interface idx along a from the texels, where covered (alpha > 0). */
static bool texel_face(const void *ctx, const int idx[3], int a, int s, double out[3])
{
    const texel_ctx *c = ctx;
    const float *t = c->tex + 4 * texel(c->N, idx[0], idx[1], idx[2], 2 * a + s);
    if (!(t[3] > 0.0f))
        return false;
    for (int ch = 0; ch < 3; ch++)
        out[ch] = t[ch];
    return true;
}

void lr_lpv_objfield_eval(const float *tex, int N, lr_vec3 origin, double h, lr_vec3 x,
                          lr_vec3 n, double E[3])
{
    /* lr_lpv_irradiance's gather (lr_lpv_face_gather) over the texels. */
    E[0] = E[1] = E[2] = 0.0;
    if (!tex || N < 2 || !(h > 0.0))
        return;
    double uu[3] = {(x.x - origin.x) / h, (x.y - origin.y) / h, (x.z - origin.z) / h};
    texel_ctx c = {tex, N};
    lr_lpv_face_gather(N, uu, n, texel_face, &c, E);
}

void lr_lpv_objfield_irradiance(const lr_lpv_objfield *f, lr_vec3 x, lr_vec3 n, double E[3])
{
    lr_lpv_objfield_eval(lr_lpv_objfield_texels(f), f->n, f->origin, f->h, x, n, E);
}

void lr_lpv_object_totals(const lr_scene_object *o, double R[3], double T[3])
{
    T[0] = T[1] = T[2] = 0.0;
    if (o->thickness_mm > 0.0)
        lr_multipole_total(&o->coeffs, o->thickness_mm, R, T);
    else
        lr_dipole_rd_total(&o->coeffs, R);
}

double lr_lpv_fresnel_diffuse(double eta)
{
    /* 2 int_0^1 F_t(mu) mu dmu = int_0^1 F_t(sqrt(v)) dv, v = mu^2. */
    enum { M = 1024 };
    double sum = 0.0;
    for (int k = 0; k < M; k++)
        sum += lr_fresnel_transmittance(sqrt((k + 0.5) / M), eta);
    return sum / M;
}

void lr_lpv_object_factors(const lr_scene_object *o, double kR[3], double kT[3])
{
    double R[3], T[3], ft = lr_lpv_fresnel_diffuse(o->coeffs.eta);
    lr_lpv_object_totals(o, R, T);
    for (int c = 0; c < 3; c++) {
        kR[c] = ft * R[c];
        kT[c] = ft * T[c];
    }
}

double lr_lpv_profile_r2(const lr_coeffs *c, int ch)
{
    /* Per source at depth z of Jensen et al. 2001's R_d, z (1 + s d) e^{-s d} / d^3 with
     * d^2 = r^2 + z^2: int 2 pi r dr of it is 2 pi e^{-s z}, and of r^2 times it
     * 2 pi z int_z^inf (d^2 - z^2)(1 + s d) e^{-s d} / d^2 dd = 4 pi z e^{-s z} / s
     * ((1 + s d) e^{-s d} / d^2 = d/dd (-e^{-s d} / d)). */
    double s = c->sigma_tr[ch], zr = c->z_r[ch], zv = c->z_v[ch];
    if (!(s > 0.0))
        return INFINITY;
    double er = exp(-s * zr), ev = exp(-s * zv);
    return 2.0 / s * (zr * er + zv * ev) / (er + ev);
}
