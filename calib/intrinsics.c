#include "calib/intrinsics.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "calib/calfile.h"

int lr_intrinsics_check(const lr_intrinsics *k, const char *what, lr_err *e)
{
    if (k->width <= 0 || k->height <= 0 || k->width > 65536 || k->height > 65536)
        return lr_err_set(e, LR_EINVAL, "%s: image size %dx%d out of range", what, k->width,
                          k->height);
    if (!(isfinite(k->fx) && isfinite(k->fy) && k->fx > 0 && k->fy > 0 && k->fx < 1e6 &&
          k->fy < 1e6))
        return lr_err_set(e, LR_EINVAL, "%s: focal length (%g, %g) px out of range", what, k->fx,
                          k->fy);
    if (!(isfinite(k->cx) && isfinite(k->cy) && k->cx >= -k->width && k->cx <= 2.0 * k->width &&
          k->cy >= -k->height && k->cy <= 2.0 * k->height))
        return lr_err_set(e, LR_EINVAL, "%s: principal point (%g, %g) too far from the %dx%d image",
                          what, k->cx, k->cy, k->width, k->height);
    for (int i = 0; i < 5; i++)
        if (!(isfinite(k->dist[i]) && fabs(k->dist[i]) <= 1e3))
            return lr_err_set(e, LR_EINVAL, "%s: distortion coefficient %d = %g out of range",
                              what, i, k->dist[i]);
    return LR_OK;
}

/* Normalised (x', y') to distorted (x'', y''). */
static void distort(const double d[5], double x, double y, double *xd, double *yd)
{
    double r2 = x * x + y * y;
    double radial = 1 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
    *xd = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
    *yd = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
}

void lr_intrinsics_project(const lr_intrinsics *k, const double X[3], double uv[2])
{
    double xd, yd;
    distort(k->dist, X[0] / X[2], X[1] / X[2], &xd, &yd);
    uv[0] = k->fx * xd + k->cx;
    uv[1] = k->fy * yd + k->cy;
}

int lr_intrinsics_undistort(const lr_intrinsics *k, const double uv[2], double xy[2],
                            lr_err *e)
{
    double xd = (uv[0] - k->cx) / k->fx, yd = (uv[1] - k->cy) / k->fy;
    double x = xd, y = yd;
    /* x = (xd - tangential(x)) / radial(x): converges for the distortion levels real lenses
     * have inside their calibrated field; checked by re-distorting. */
    for (int it = 0; it < 100; it++) {
        double r2 = x * x + y * y;
        double radial = 1 + r2 * (k->dist[0] + r2 * (k->dist[1] + r2 * k->dist[4]));
        double dx = 2 * k->dist[2] * x * y + k->dist[3] * (r2 + 2 * x * x);
        double dy = k->dist[2] * (r2 + 2 * y * y) + 2 * k->dist[3] * x * y;
        if (!(radial > 0.1))
            break;
        double nx = (xd - dx) / radial, ny = (yd - dy) / radial;
        bool done = fabs(nx - x) < 1e-15 && fabs(ny - y) < 1e-15;
        x = nx;
        y = ny;
        if (done)
            break;
    }
    double cx, cy;
    distort(k->dist, x, y, &cx, &cy);
    if (!(fabs(cx - xd) * k->fx < 1e-6 && fabs(cy - yd) * k->fy < 1e-6))
        return lr_err_set(e, LR_EINVAL, "undistortion of pixel (%g, %g) did not converge", uv[0],
                          uv[1]);
    xy[0] = x;
    xy[1] = y;
    return LR_OK;
}

void lr_intrinsics_gl_projection(const lr_intrinsics *k, double znear, double zfar,
                                 float m[16])
{
    /* Image u in [-0.5, W - 0.5] maps to NDC x in [-1, 1]; image v in [-0.5, H - 0.5] to NDC y
     * in [1, -1] (row 0 at the top). With eye = (X, -Y, -Z) of the device frame and
     * clip.w = -z_eye = Z:  ndc.x = (2 fx / W) X/Z + 2 (cx + 0.5) / W - 1, and the same for y
     * with the sign flipped. */
    double W = k->width, H = k->height;
    memset(m, 0, 16 * sizeof *m);
    m[0] = (float)(2 * k->fx / W);
    m[8] = (float)(1 - 2 * (k->cx + 0.5) / W);
    m[5] = (float)(2 * k->fy / H);
    m[9] = (float)(2 * (k->cy + 0.5) / H - 1);
    m[10] = (float)(-(zfar + znear) / (zfar - znear));
    m[14] = (float)(-2 * zfar * znear / (zfar - znear));
    m[11] = -1.0f;
}

void lr_extrinsics_gl_view(const double R[9], const double T[3], float m[16])
{
    /* GL eye = diag(1, -1, -1) * (R X + T); column-major. */
    static const double flip[3] = {1, -1, -1};
    memset(m, 0, 16 * sizeof *m);
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            m[c * 4 + r] = (float)(flip[r] * R[r * 3 + c]);
        m[12 + r] = (float)(flip[r] * T[r]);
    }
    m[15] = 1.0f;
}

void lr_intrinsics_matrix(const lr_intrinsics *k, double K[9])
{
    double m[9] = {k->fx, 0, k->cx, 0, k->fy, k->cy, 0, 0, 1};
    memcpy(K, m, sizeof m);
}

void lr_intrinsics_write(lr_jw *w, const lr_intrinsics *k)
{
    double size[2] = {k->width, k->height};
    lr_jw_numbers(w, "image_size", size, 2);
    lr_jw_number(w, "fx", k->fx);
    lr_jw_number(w, "fy", k->fy);
    lr_jw_number(w, "cx", k->cx);
    lr_jw_number(w, "cy", k->cy);
    lr_jw_numbers(w, "dist", k->dist, 5);
}

int lr_intrinsics_read(const lr_json *j, lr_jnode obj, const char *prefix, lr_intrinsics *k,
                       lr_err *e)
{
    double size[2];
    int rc = lr_calfile_numbers(j, obj, prefix, "image_size", 2, 1, 65536, size, e);
    if (rc)
        return rc;
    if (size[0] != floor(size[0]) || size[1] != floor(size[1]))
        return lr_json_fail(j, lr_json_get(j, obj, "image_size"), "image_size", e, LR_EINVAL,
                            "must be whole pixels, got [%g, %g]", size[0], size[1]);
    k->width = (int)size[0];
    k->height = (int)size[1];
    if ((rc = lr_calfile_number(j, obj, prefix, "fx", 1e-3, 1e6, &k->fx, e)) ||
        (rc = lr_calfile_number(j, obj, prefix, "fy", 1e-3, 1e6, &k->fy, e)) ||
        (rc = lr_calfile_number(j, obj, prefix, "cx", -k->width, 2.0 * k->width, &k->cx, e)) ||
        (rc = lr_calfile_number(j, obj, prefix, "cy", -k->height, 2.0 * k->height, &k->cy, e)))
        return rc;
    /* Older tools write 4 (no k3) or OpenCV's longer models; this firmware uses exactly 5. */
    return lr_calfile_numbers(j, obj, prefix, "dist", 5, -1e3, 1e3, k->dist, e);
}
