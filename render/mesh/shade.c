/* Truncated-cone lamp shade with real wall thickness. */
#include <math.h>
#include <stdlib.h>

#include "render/mesh/mesh_internal.h"
#include "render/mesh/shapes.h"

static int bad(const char **field, const char *name, lr_err *e, const char *msg, double v)
{
    *field = name;
    return lr_err_set(e, LR_EINVAL, "%s, got %g", msg, v);
}

double lr_shade_radial_offset(const lr_shade_desc *r)
{
    /* The facet planes sit at the apothem r cos(pi/n) of each ring; their profile slants by
     * phi with tan(phi) = (radius_top - radius_bottom) cos(pi/n) / height. Moving every vertex
     * radius in by delta moves each facet plane by delta cos(pi/n) cos(phi) along its normal;
     * solve that for the thickness. */
    double c = cos(M_PI / r->segments);
    double dr = (r->radius_top - r->radius_bottom) * c;
    double cos_phi = r->height / hypot(r->height, dr);
    return r->thickness / (c * cos_phi);
}

int lr_shade_check(const lr_shade_desc *d, lr_shade_desc *r, const char **field, lr_err *e)
{
    *r = *d;
    if (r->radius_bottom == 0.0) r->radius_bottom = 100.0;
    if (r->radius_top == 0.0) r->radius_top = 60.0;
    if (r->height == 0.0) r->height = 150.0;
    if (r->thickness == 0.0 && !r->single_surface) r->thickness = 1.5;
    if (r->single_surface) r->thickness = 0.0;
    if (r->segments == 0) r->segments = 96;
    if (!(r->radius_bottom > 0.0 && r->radius_bottom < 1e5))
        return bad(field, "radius_bottom", e, "must be > 0 and < 1e5 mm", r->radius_bottom);
    if (!(r->radius_top > 0.0 && r->radius_top < 1e5))
        return bad(field, "radius_top", e, "must be > 0 and < 1e5 mm", r->radius_top);
    if (!(r->height > 0.0 && r->height < 1e5))
        return bad(field, "height", e, "must be > 0 and < 1e5 mm", r->height);
    if (r->segments < 3 || r->segments > LR_MAX_SEGMENTS) {
        *field = "segments";
        return lr_err_set(e, LR_EINVAL, "must be between 3 and %d, got %d", LR_MAX_SEGMENTS,
                          r->segments);
    }
    if (!r->single_surface) {
        if (!(r->thickness > 0.0))
            return bad(field, "thickness", e, "must be > 0 mm (0 means a single surface)",
                       r->thickness);
        double delta = lr_shade_radial_offset(r);
        double rmin = fmin(r->radius_bottom, r->radius_top);
        /* Leave at least a tenth of the smaller radius open inside. */
        if (!(delta < 0.9 * rmin)) {
            *field = "thickness";
            return lr_err_set(e, LR_EINVAL, "%g mm leaves no opening inside the %g mm radius",
                              r->thickness, rmin);
        }
    }
    if (r->rings == 0) {
        double slant = hypot(r->height, r->radius_top - r->radius_bottom);
        double chord = 2.0 * M_PI * fmax(r->radius_bottom, r->radius_top) / r->segments;
        double s = round(slant / chord);
        r->rings = s < 1.0 ? 1 : s > 256.0 ? 256 : (int)s;
    }
    if (r->rings < 1 || r->rings > LR_MAX_RINGS) {
        *field = "rings";
        return lr_err_set(e, LR_EINVAL, "must be between 1 and %d, got %d", LR_MAX_RINGS,
                          r->rings);
    }
    return LR_OK;
}

int lr_mesh_shade(const lr_shade_desc *d, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    lr_shade_desc s;
    const char *field = NULL;
    int rc = lr_shade_check(d, &s, &field, e);
    if (rc)
        return lr_err_prefix(e, "shade: field '%s'", field);
    int n = s.segments, k = s.rings;
    double Rb = s.radius_bottom, Rt = s.radius_top, h = s.height;
    double delta = s.single_surface ? 0.0 : lr_shade_radial_offset(&s);
    double (*cs)[2] = lr_mb_angles(n);
    double *rho = malloc((size_t)(k + 1) * sizeof *rho), *z = malloc((size_t)(k + 1) * sizeof *z),
           *nr = malloc((size_t)(k + 1) * sizeof *nr), *nz = malloc((size_t)(k + 1) * sizeof *nz);
    lr_mesh_builder b = {0};
    if (!cs || !rho || !z || !nr || !nz) {
        rc = lr_err_set(e, LR_ENOMEM, "shade: out of memory");
        goto done;
    }
    /* Outward normal of the wall in the meridian plane: perpendicular to (Rt - Rb, h). */
    double wn_r = h, wn_z = -(Rt - Rb);
    /* Outer wall, bottom to top; the ends are exact so that rims meet them bit for bit. */
    for (int i = 0; i <= k; i++) {
        rho[i] = i == 0 ? Rb : i == k ? Rt : Rb + (Rt - Rb) * i / k;
        z[i] = i == 0 ? 0.0 : i == k ? h : h * i / k;
        nr[i] = wn_r;
        nz[i] = wn_z;
    }
    lr_mb_revolve(&b, (const double (*)[2])cs, n, rho, z, nr, nz, k + 1);
    if (!s.single_surface) {
        /* Inner wall, top to bottom, facing the axis. */
        for (int i = 0; i <= k; i++) {
            int j = k - i;
            double ro = j == 0 ? Rb : j == k ? Rt : Rb + (Rt - Rb) * j / k;
            rho[i] = ro - delta;
            z[i] = j == 0 ? 0.0 : j == k ? h : h * j / k;
            nr[i] = -wn_r;
            nz[i] = -wn_z;
        }
        lr_mb_revolve(&b, (const double (*)[2])cs, n, rho, z, nr, nz, k + 1);
        if (!s.no_rims) {
            double r2[2], z2[2], n0[2] = {0.0, 0.0}, up[2] = {1.0, 1.0}, down[2] = {-1.0, -1.0};
            r2[0] = Rt; r2[1] = Rt - delta; z2[0] = z2[1] = h;   /* top rim, outside in */
            lr_mb_revolve(&b, (const double (*)[2])cs, n, r2, z2, n0, up, 2);
            r2[0] = Rb - delta; r2[1] = Rb; z2[0] = z2[1] = 0.0; /* bottom rim, inside out */
            lr_mb_revolve(&b, (const double (*)[2])cs, n, r2, z2, n0, down, 2);
        }
    }
    lr_mesh_checks checks = s.checks;
    checks.flags |= LR_MESH_OPEN_OK; /* a shade is open at top and bottom by design */
    rc = lr_mb_finish(&b, "shade", &checks, out, e);
done:
    lr_mb_free(&b);
    free(cs);
    free(rho);
    free(z);
    free(nr);
    free(nz);
    return rc;
}
