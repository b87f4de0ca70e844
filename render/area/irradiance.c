/* Closed-form irradiance from Lambertian quads and disks (emitter.h). */
#include <math.h>

#include "render/area/emitter.h"

#define MAX_VERTS 520
/* Sides of the equal-area polygon that stands for a disk off its axis: the relative error of
 * an equal-area regular n-gon's irradiance is O(n^-2) (~1e-5 at 256 for points not closer to
 * the rim than a few mm). */
#define DISK_SIDES 256

double lr_area_disk_irradiance_axis(double L, double a, double h)
{
    return M_PI * L * a * a / (a * a + h * h);
}

/* Sutherland-Hodgman against the half-space n.(p - x) >= 0 (x's visible hemisphere). */
static int clip(const lr_vec3 *in, int n, lr_vec3 x, lr_vec3 nx, lr_vec3 *out)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        lr_vec3 a = in[i], b = in[(i + 1) % n];
        double da = lr_v3_dot(nx, lr_v3_sub(a, x)), db = lr_v3_dot(nx, lr_v3_sub(b, x));
        if (da >= 0.0 && m < MAX_VERTS)
            out[m++] = a;
        if ((da >= 0.0) != (db >= 0.0) && m < MAX_VERTS) {
            double t = da / (da - db);
            out[m++] = lr_v3_add(a, lr_v3_scale(lr_v3_sub(b, a), t));
        }
    }
    return m;
}

double lr_area_polygon_irradiance(const lr_vec3 *verts, int n, double L, lr_vec3 x,
                                  lr_vec3 n_x)
{
    if (n < 3 || n > MAX_VERTS)
        return 0.0;
    lr_vec3 c[MAX_VERTS];
    int m = clip(verts, n, x, n_x, c);
    if (m < 3)
        return 0.0;
    double sum = 0.0;
    for (int i = 0; i < m; i++) {
        lr_vec3 a = lr_v3_sub(c[i], x), b = lr_v3_sub(c[(i + 1) % m], x);
        double la = lr_v3_len(a), lb = lr_v3_len(b);
        if (!(la > 0.0 && lb > 0.0))
            continue;
        lr_vec3 cr = lr_v3_cross(a, b);
        double s = lr_v3_len(cr);
        if (!(s > 0.0))
            continue;
        /* theta_i = atan2(|a x b|, a.b): accurate for small and near-pi angles alike. */
        double theta = atan2(s, lr_v3_dot(a, b));
        sum += theta * lr_v3_dot(lr_v3_scale(cr, 1.0 / s), n_x);
    }
    return 0.5 * L * fabs(sum);
}

/* Whether x sees the emitting side. */
static bool faces(const lr_area_emitter *em, lr_vec3 x)
{
    double s = lr_v3_dot(em->normal, lr_v3_sub(x, em->center));
    return em->two_sided ? s != 0.0 : s > 0.0;
}

double lr_area_irradiance(const lr_area_emitter *em, double L, lr_vec3 x, lr_vec3 n_x)
{
    if (!faces(em, x))
        return 0.0;
    lr_vec3 v[DISK_SIDES];
    int n;
    if (em->kind == LR_AREA_QUAD) {
        lr_vec3 c = em->center;
        v[0] = lr_v3_sub(lr_v3_sub(c, em->u), em->v);
        v[1] = lr_v3_sub(lr_v3_add(c, em->u), em->v);
        v[2] = lr_v3_add(lr_v3_add(c, em->u), em->v);
        v[3] = lr_v3_add(lr_v3_sub(c, em->u), em->v);
        n = 4;
    } else {
        lr_vec3 d = lr_v3_sub(x, em->center);
        double h = lr_v3_dot(d, em->normal);
        lr_vec3 lat = lr_v3_sub(d, lr_v3_scale(em->normal, h));
        /* On the axis and facing the disk: the closed form. */
        if (lr_v3_len(lat) <= 1e-12 * em->radius && fabs(fabs(lr_v3_dot(n_x, em->normal)) - 1.0)
            < 1e-15 && lr_v3_dot(n_x, em->normal) * h < 0.0)
            return lr_area_disk_irradiance_axis(L, em->radius, h);
        /* The regular n-gon of the disk's area: circumradius a sqrt(2 pi / (n sin(2 pi/n))). */
        double rr = em->radius * sqrt(2.0 * M_PI / (DISK_SIDES * sin(2.0 * M_PI / DISK_SIDES)));
        for (int i = 0; i < DISK_SIDES; i++) {
            double phi = 2.0 * M_PI * i / DISK_SIDES;
            v[i] = lr_v3_add(em->center, lr_v3_add(lr_v3_scale(em->u, rr * cos(phi)),
                                                   lr_v3_scale(em->v, rr * sin(phi))));
        }
        n = DISK_SIDES;
    }
    return lr_area_polygon_irradiance(v, n, L, x, n_x);
}

double lr_area_irradiance_samples(const lr_area_emitter *em, const lr_vec3 *pts, int n,
                                  double L, lr_vec3 x, lr_vec3 n_x)
{
    if (n < 1)
        return 0.0;
    double sum = 0.0;
    for (int j = 0; j < n; j++) {
        lr_vec3 d = lr_v3_sub(x, pts[j]);
        double d2 = lr_v3_dot(d, d);
        if (!(d2 > 0.0))
            continue;
        lr_vec3 w = lr_v3_scale(d, 1.0 / sqrt(d2));
        double cx = -lr_v3_dot(n_x, w);
        if (cx > 0.0)
            sum += lr_area_intensity_factor(em, w) * cx / d2;
    }
    return L * sum / n;
}
