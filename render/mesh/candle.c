/* Pillar candle with a melt pool. */
#include <math.h>
#include <stdlib.h>

#include "render/mesh/mesh_internal.h"
#include "render/mesh/shapes.h"

static int bad(const char **field, const char *name, lr_err *e, const char *fmt, double v,
               double limit)
{
    *field = name;
    return lr_err_set(e, LR_EINVAL, fmt, limit, v);
}

static int check_count(const char **field, const char *name, int v, int lo, int hi, lr_err *e)
{
    if (v < lo || v > hi) {
        *field = name;
        return lr_err_set(e, LR_EINVAL, "must be between %d and %d, got %d", lo, hi, v);
    }
    return LR_OK;
}

int lr_candle_check(const lr_candle_desc *d, lr_candle_desc *r, const char **field, lr_err *e)
{
    *r = *d;
    if (r->radius == 0.0) r->radius = 35.0;
    if (r->height == 0.0) r->height = 120.0;
    if (r->segments == 0) r->segments = 64;
    if (r->pool_rings == 0) r->pool_rings = 12;
    if (!(r->radius > 0.0 && r->radius < 1e5))
        return bad(field, "radius", e, "must be > 0 and < %g mm, got %g", r->radius, 1e5);
    if (!(r->height > 0.0 && r->height < 1e5))
        return bad(field, "height", e, "must be > 0 and < %g mm, got %g", r->height, 1e5);
    if (!r->flat_top) {
        if (r->pool_depth == 0.0) r->pool_depth = fmin(8.0, 0.5 * r->height);
        if (r->pool_radius == 0.0) r->pool_radius = r->radius > 6.0 ? r->radius - 3.0 : 0.5 * r->radius;
        if (!(r->pool_depth > 0.0 && r->pool_depth < r->height))
            return bad(field, "pool_depth", e, "must be > 0 and < height (%g mm), got %g",
                       r->pool_depth, r->height);
        if (!(r->pool_radius > 0.0 && r->pool_radius <= r->radius))
            return bad(field, "pool_radius", e, "must be > 0 and <= radius (%g mm), got %g",
                       r->pool_radius, r->radius);
    }
    if (r->side_rings == 0) {
        double chord = 2.0 * M_PI * r->radius / r->segments;
        double s = round(r->height / chord);
        r->side_rings = s < 1.0 ? 1 : s > 256.0 ? 256 : (int)s;
    }
    int rc;
    if ((rc = check_count(field, "segments", r->segments, 3, LR_MAX_SEGMENTS, e)) ||
        (rc = check_count(field, "pool_rings", r->pool_rings, 1, LR_MAX_RINGS, e)) ||
        (rc = check_count(field, "side_rings", r->side_rings, 1, LR_MAX_RINGS, e)))
        return rc;
    return LR_OK;
}

int lr_mesh_candle(const lr_candle_desc *d, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    lr_candle_desc c;
    const char *field = NULL;
    int rc = lr_candle_check(d, &c, &field, e);
    if (rc)
        return lr_err_prefix(e, "candle: field '%s'", field);
    int n = c.segments, s = c.side_rings, m = c.pool_rings;
    double R = c.radius, H = c.height;
    double (*cs)[2] = lr_mb_angles(n);
    int cap = s + m + 8;
    double *rho = malloc((size_t)cap * sizeof *rho), *z = malloc((size_t)cap * sizeof *z),
           *nr = malloc((size_t)cap * sizeof *nr), *nz = malloc((size_t)cap * sizeof *nz);
    lr_mesh_builder b = {0};
    if (!cs || !rho || !z || !nr || !nz) {
        rc = lr_err_set(e, LR_ENOMEM, "candle: out of memory");
        goto done;
    }
    /* Bottom disc, outward = down: centre to edge. */
    rho[0] = 0.0; z[0] = 0.0; nr[0] = 0.0; nz[0] = -1.0;
    rho[1] = R;   z[1] = 0.0; nr[1] = 0.0; nz[1] = -1.0;
    lr_mb_revolve(&b, (const double (*)[2])cs, n, rho, z, nr, nz, 2);
    /* Side wall, bottom to top. The last ring is exactly H (H * s / s need not be). */
    for (int i = 0; i <= s; i++) {
        rho[i] = R;
        z[i] = i == s ? H : H * i / s;
        nr[i] = 1.0;
        nz[i] = 0.0;
    }
    lr_mb_revolve(&b, (const double (*)[2])cs, n, rho, z, nr, nz, s + 1);
    if (c.flat_top) {
        rho[0] = R;   z[0] = H; nr[0] = 0.0; nz[0] = 1.0;
        rho[1] = 0.0; z[1] = H; nr[1] = 0.0; nz[1] = 1.0;
        lr_mb_revolve(&b, (const double (*)[2])cs, n, rho, z, nr, nz, 2);
    } else {
        double a = c.pool_radius, dp = c.pool_depth;
        if (a < R) { /* flat wax rim, outside in */
            rho[0] = R; z[0] = H; nr[0] = 0.0; nz[0] = 1.0;
            rho[1] = a; z[1] = H; nr[1] = 0.0; nz[1] = 1.0;
            lr_mb_revolve(&b, (const double (*)[2])cs, n, rho, z, nr, nz, 2);
        }
        /* Pool: z = H - dp (1 - (rho/a)^2), from its edge to its centre; the outward normal
         * of the wax is the gradient of z - f(rho): (-f'(rho), 1), f' = 2 dp rho / a^2. */
        for (int k = 0; k <= m; k++) {
            double r = k == 0 ? a : k == m ? 0.0 : a * (m - k) / m;
            double q = r / a;
            rho[k] = r;
            z[k] = H - dp * (1.0 - q * q);
            nr[k] = -2.0 * dp * r / (a * a);
            nz[k] = 1.0;
        }
        lr_mb_revolve(&b, (const double (*)[2])cs, n, rho, z, nr, nz, m + 1);
    }
    rc = lr_mb_finish(&b, "candle", &c.checks, out, e);
done:
    lr_mb_free(&b);
    free(cs);
    free(rho);
    free(z);
    free(nr);
    free(nz);
    return rc;
}
