/* Area emitters: construction, emission profile and point sets (emitter.h). */
#include <math.h>
#include <stdlib.h>

#include "render/area/emitter.h"
#include "render/base/rng.h"

int lr_area_quad(lr_vec3 center, lr_vec3 half_u, lr_vec3 half_v, bool two_sided,
                 lr_area_emitter *out, lr_err *e)
{
    lr_vec3 c = lr_v3_cross(half_u, half_v);
    double a = lr_v3_len(c);
    if (!(lr_v3_isfinite(center) && lr_v3_isfinite(half_u) && lr_v3_isfinite(half_v)) ||
        !(a > 1e-12) || !(a > 1e-9 * lr_v3_dot(half_u, half_u)) ||
        !(a > 1e-9 * lr_v3_dot(half_v, half_v)))
        return lr_err_set(e, LR_EINVAL, "area light: a quad needs finite, non-parallel "
                          "half-edges");
    *out = (lr_area_emitter){.kind = LR_AREA_QUAD, .center = center, .u = half_u, .v = half_v,
                             .normal = lr_v3_scale(c, 1.0 / a), .area = 4.0 * a,
                             .two_sided = two_sided};
    return LR_OK;
}

int lr_area_disk(lr_vec3 center, lr_vec3 normal, double radius, bool two_sided,
                 lr_area_emitter *out, lr_err *e)
{
    double nl = lr_v3_len(normal);
    if (!lr_v3_isfinite(center) || !(nl > 1e-12) || !isfinite(nl) || !(radius > 0.0) ||
        !isfinite(radius))
        return lr_err_set(e, LR_EINVAL, "area light: a disk needs a finite centre, a non-zero "
                          "normal and a radius > 0");
    lr_vec3 n = lr_v3_scale(normal, 1.0 / nl);
    /* Any tangent frame: the disk is symmetric about n. */
    lr_vec3 a = fabs(n.x) < 0.9 ? lr_v3(1, 0, 0) : lr_v3(0, 1, 0);
    lr_vec3 u = lr_v3_normalize(lr_v3_cross(a, n));
    lr_vec3 v = lr_v3_cross(n, u);
    *out = (lr_area_emitter){.kind = LR_AREA_DISK, .center = center, .u = u, .v = v,
                             .normal = n, .radius = radius, .area = M_PI * radius * radius,
                             .two_sided = two_sided};
    return LR_OK;
}

double lr_area_intensity_factor(const lr_area_emitter *em, lr_vec3 w)
{
    double c = lr_v3_dot(em->normal, w);
    if (em->two_sided)
        c = fabs(c);
    return c > 0.0 ? em->area * c : 0.0;
}

lr_vec3 lr_area_point(const lr_area_emitter *em, double u1, double u2)
{
    if (em->kind == LR_AREA_QUAD)
        return lr_v3_add(em->center, lr_v3_add(lr_v3_scale(em->u, 2.0 * u1 - 1.0),
                                               lr_v3_scale(em->v, 2.0 * u2 - 1.0)));
    /* Shirley & Chiu 1997, "A low distortion map between disk and square". */
    double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0, r, phi;
    if (a == 0.0 && b == 0.0) {
        r = 0.0;
        phi = 0.0;
    } else if (fabs(a) > fabs(b)) {
        r = a;
        phi = (M_PI / 4.0) * (b / a);
    } else {
        r = b;
        phi = M_PI / 2.0 - (M_PI / 4.0) * (a / b);
    }
    r *= em->radius;
    return lr_v3_add(em->center, lr_v3_add(lr_v3_scale(em->u, r * cos(phi)),
                                           lr_v3_scale(em->v, r * sin(phi))));
}

void lr_area_stratified(const lr_area_emitter *em, int n, uint64_t seed, lr_vec3 *out)
{
    if (n < 1)
        return;
    int g = (int)floor(sqrt((double)n));
    while (g > 1 && n % g)
        g--;
    int h = n / g;
    lr_rng rng = lr_rng_init(lr_rng_key(seed, (uint64_t)n, 0x57A7, 0));
    for (int i = 0; i < g; i++)
        for (int j = 0; j < h; j++) {
            double u1 = (i + lr_rng_next(&rng)) / g, u2 = (j + lr_rng_next(&rng)) / h;
            out[i * h + j] = lr_area_point(em, u1, u2);
        }
}

double lr_area_poisson_radius(double area, int n)
{
    return n > 0 && area > 0.0 ? sqrt(2.0 * area / (M_PI * n)) : 0.0;
}

/* Toroidal distance^2 in the parameter square with axis scales (sx, sy). */
static double torus_d2(const double a[2], const double b[2], double sx, double sy)
{
    double dx = fabs(a[0] - b[0]), dy = fabs(a[1] - b[1]);
    dx = fmin(dx, 1.0 - dx) * sx;
    dy = fmin(dy, 1.0 - dy) * sy;
    return dx * dx + dy * dy;
}

void lr_area_poisson_uv(double sx, double sy, double r_min, int cap, int max_fails,
                        uint64_t seed, double (*uv)[2], int *n)
{
    lr_rng rng = lr_rng_init(lr_rng_key(seed, 0x9015, 0, 0));
    double r2 = r_min * r_min;
    int fails = 0, count = 0;
    /* Few points on an emitter (tens to a few thousand): a linear scan is simple enough. */
    while (count < cap && fails < max_fails) {
        double c[2] = {lr_rng_next(&rng), lr_rng_next(&rng)};
        bool ok = true;
        for (int i = 0; i < count && ok; i++)
            ok = torus_d2(c, uv[i], sx, sy) >= r2;
        if (ok) {
            uv[count][0] = c[0];
            uv[count][1] = c[1];
            count++;
            fails = 0;
        } else {
            fails++;
        }
    }
    *n = count;
}

void lr_area_param_scales(const lr_area_emitter *em, double *sx, double *sy)
{
    if (em->kind == LR_AREA_QUAD) {
        *sx = 2.0 * lr_v3_len(em->u);
        *sy = 2.0 * lr_v3_len(em->v);
    } else {
        *sx = *sy = 2.0 * em->radius;
    }
}

int lr_area_poisson(const lr_area_emitter *em, double r_min, int cap, int max_fails,
                    uint64_t seed, lr_vec3 *out, int *n, lr_err *e)
{
    *n = 0;
    if (!(r_min > 0.0) || !isfinite(r_min) || cap < 1 || max_fails < 1)
        return lr_err_set(e, LR_EINVAL, "area light: Poisson-disk radius must be > 0 and the "
                          "capacity and attempts >= 1 (got %g, %d, %d)", r_min, cap, max_fails);
    double (*uv)[2] = malloc((size_t)cap * sizeof *uv);
    if (!uv)
        return lr_err_set(e, LR_ENOMEM, "area light: out of memory for %d points", cap);
    double sx, sy;
    lr_area_param_scales(em, &sx, &sy);
    lr_area_poisson_uv(sx, sy, r_min, cap, max_fails, seed, uv, n);
    for (int i = 0; i < *n; i++)
        out[i] = lr_area_point(em, uv[i][0], uv[i][1]);
    free(uv);
    return LR_OK;
}
