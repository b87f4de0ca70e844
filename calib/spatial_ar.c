#include "calib/spatial_ar.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/bvh.h"

/* R^T v: a projector-frame vector in world coordinates. */
static lr_vec3 to_world(const double R[9], double x, double y, double z)
{
    return lr_v3(R[0] * x + R[3] * y + R[6] * z, R[1] * x + R[4] * y + R[7] * z,
                 R[2] * x + R[5] * y + R[8] * z);
}

static lr_vec3 projector_centre(const lr_ar_pose *p)
{
    /* X_proj = 0  <=>  X_world = -R^T T */
    lr_vec3 c = to_world(p->R, p->T[0], p->T[1], p->T[2]);
    return lr_v3_scale(c, -1.0);
}

static int check_pose(const lr_ar_pose *p, lr_err *e)
{
    for (int i = 0; i < 9; i++)
        if (!isfinite(p->R[i]))
            return lr_err_set(e, LR_EINVAL, "projector pose: R is not finite");
    for (int i = 0; i < 3; i++)
        if (!isfinite(p->T[i]))
            return lr_err_set(e, LR_EINVAL, "projector pose: T is not finite");
    /* orthonormal rows: a non-rotation would shear the view */
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double d = 0;
            for (int k = 0; k < 3; k++)
                d += p->R[3 * a + k] * p->R[3 * b + k];
            if (fabs(d - (a == b)) > 1e-6)
                return lr_err_set(e, LR_EINVAL, "projector pose: R is not a rotation");
        }
    return LR_OK;
}

int lr_ar_view_camera(const lr_intrinsics *proj, const lr_ar_pose *pose, double margin,
                      lr_camera *cam, double *aspect, lr_err *e)
{
    int rc;
    if ((rc = lr_intrinsics_check(proj, "projector", e)) || (rc = check_pose(pose, e)))
        return rc;
    if (!(margin >= 0 && margin < 1))
        return lr_err_set(e, LR_EINVAL, "spatial AR: margin %g not in [0, 1)", margin);
    /* The widest undistorted ray over the image border (distortion is monotone in radius
     * over a calibrated field, so the border bounds the interior). Pixel edges, not centres:
     * the outermost pixel's footprint must be inside the render too. */
    double tx = 0, ty = 0;
    int w = proj->width, h = proj->height;
    for (int i = 0; i <= 2 * (w + h); i++) {
        double uv[2];
        if (i <= w) {
            uv[0] = i - 0.5, uv[1] = -0.5;
        } else if (i <= 2 * w) {
            uv[0] = (i - w) - 0.5, uv[1] = h - 0.5;
        } else if (i <= 2 * w + h) {
            uv[0] = -0.5, uv[1] = (i - 2 * w) - 0.5;
        } else {
            uv[0] = w - 0.5, uv[1] = (i - 2 * w - h) - 0.5;
        }
        double xy[2];
        if ((rc = lr_intrinsics_undistort(proj, uv, xy, e)))
            return lr_err_prefix(e, "spatial AR: projector border pixel (%.1f, %.1f)", uv[0],
                                 uv[1]);
        tx = fmax(tx, fabs(xy[0]));
        ty = fmax(ty, fabs(xy[1]));
    }
    tx *= 1 + margin;
    ty *= 1 + margin;
    if (!(tx > 0 && ty > 0 && atan(ty) < 1.5))
        return lr_err_set(e, LR_EINVAL, "spatial AR: projector field %g x %g is degenerate", tx,
                          ty);
    memset(cam, 0, sizeof *cam);
    lr_vec3 c = projector_centre(pose);
    lr_vec3 fwd = to_world(pose->R, 0, 0, 1);
    cam->orthographic = false;
    cam->position = c;
    cam->target = lr_v3_add(c, lr_v3_scale(fwd, 100.0));
    cam->up = to_world(pose->R, 0, -1, 0); /* image +Y is down in OpenCV's frame */
    cam->fov_deg = 2 * atan(ty) * (180.0 / M_PI);
    cam->near_mm = 10;
    cam->far_mm = 10000;
    *aspect = tx / ty;
    return LR_OK;
}

int lr_ar_warp_map(const lr_intrinsics *proj, const lr_camera *cam, int rw, int rh,
                   float **map, lr_err *e)
{
    if (rw <= 0 || rh <= 0)
        return lr_err_set(e, LR_EINVAL, "spatial AR: render size %d x %d", rw, rh);
    int w = proj->width, h = proj->height;
    float *m = malloc((size_t)w * h * 2 * sizeof *m);
    if (!m)
        return lr_err_set(e, LR_ENOMEM, "spatial AR: warp map %d x %d", w, h);
    double ty = tan(cam->fov_deg * (M_PI / 360.0));
    double tx = ty * rw / rh; /* the renderer's aspect is its viewport's */
    for (int v = 0; v < h; v++)
        for (int u = 0; u < w; u++) {
            double uv[2] = {u, v}, xy[2];
            float *o = m + 2 * ((size_t)v * w + u);
            if (lr_intrinsics_undistort(proj, uv, xy, NULL)) {
                o[0] = o[1] = -1;
                continue;
            }
            /* NDC x = x / tx (right), NDC y = -y / ty (projector +Y is down); image column
             * (ndc_x + 1) / 2 * rw, row from the top (1 - ndc_y) / 2 * rh. */
            o[0] = (float)((xy[0] / tx + 1) * 0.5 * rw);
            o[1] = (float)((xy[1] / ty + 1) * 0.5 * rh);
        }
    *map = m;
    return LR_OK;
}

int lr_ar_warp(const lr_image *render, const float *map, int pw, int ph, lr_image *out,
               lr_err *e)
{
    int rc;
    if ((rc = lr_image_alloc(out, pw, ph, e)))
        return rc;
    int rw = render->width, rh = render->height;
    for (size_t p = 0; p < (size_t)pw * ph; p++) {
        float *o = out->rgb + 3 * p;
        o[0] = o[1] = o[2] = 0;
        /* continuous position with pixel centres at integers */
        double x = map[2 * p] - 0.5, y = map[2 * p + 1] - 0.5;
        if (!(x >= -0.5 && y >= -0.5 && x <= rw - 0.5 && y <= rh - 0.5))
            continue;
        int x0 = (int)floor(x), y0 = (int)floor(y);
        double fx = x - x0, fy = y - y0;
        for (int k = 0; k < 4; k++) {
            int xi = x0 + (k & 1), yi = y0 + (k >> 1);
            xi = xi < 0 ? 0 : xi >= rw ? rw - 1 : xi;
            yi = yi < 0 ? 0 : yi >= rh ? rh - 1 : yi;
            double wgt = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
            const float *s = render->rgb + 3 * ((size_t)yi * rw + xi);
            for (int c = 0; c < 3; c++)
                o[c] += (float)(wgt * s[c]);
        }
    }
    return LR_OK;
}

int lr_ar_geometry(const lr_scene *scene, const lr_intrinsics *proj, const lr_ar_pose *pose,
                   lr_image *out, long *lit, double *g_max, lr_err *e)
{
    int rc;
    if ((rc = lr_intrinsics_check(proj, "projector", e)) || (rc = check_pose(pose, e)))
        return rc;
    int w = proj->width, h = proj->height;
    if ((rc = lr_image_alloc(out, w, h, e)))
        return rc;
    lr_vec3 o = projector_centre(pose);
    double gmax = 0;
    long n = 0;
    for (int v = 0; v < h; v++)
        for (int u = 0; u < w; u++) {
            float *px = out->rgb + 3 * ((size_t)v * w + u);
            px[0] = px[1] = px[2] = 0;
            double uv[2] = {u, v}, xy[2];
            if (lr_intrinsics_undistort(proj, uv, xy, NULL))
                continue;
            lr_vec3 d = lr_v3_normalize(to_world(pose->R, xy[0], xy[1], 1));
            double best = INFINITY;
            lr_vec3 normal = lr_v3(0, 0, 0);
            for (int i = 0; i < lr_scene_object_count(scene); i++) {
                const lr_scene_object *ob = lr_scene_object_at(scene, i);
                lr_hit hit;
                if (lr_bvh_intersect(ob->bvh, o, d, 1e-6, best, &hit) && hit.t < best) {
                    best = hit.t;
                    normal = lr_mesh_triangle_normal(ob->mesh, hit.triangle);
                }
            }
            if (!isfinite(best))
                continue;
            /* irradiance from a source of uniform intensity: E = I cos(theta) / d^2 */
            double g = fabs(lr_v3_dot(normal, d)) / (best * best);
            px[0] = px[1] = px[2] = (float)g;
            gmax = fmax(gmax, g);
            n++;
        }
    if (n == 0) {
        lr_image_free(out);
        return lr_err_set(e, LR_EINVAL,
                          "spatial AR: no projector pixel reaches the mockup (the scene's "
                          "objects): check the projector pose");
    }
    for (size_t p = 0; p < (size_t)w * h * 3; p++)
        out->rgb[p] = (float)(out->rgb[p] / gmax);
    *lit = n;
    *g_max = gmax;
    return LR_OK;
}

int lr_ar_compensate(const lr_ar_desc *d, lr_image *levels, lr_ar_stats *stats, lr_err *e)
{
    const lr_image *t = d->target, *r = d->response;
    if (!t || !r || !t->rgb || !r->rgb)
        return lr_err_set(e, LR_EINVAL, "spatial AR: target and response are required");
    if (t->width != r->width || t->height != r->height)
        return lr_err_set(e, LR_EINVAL,
                          "spatial AR: target is %d x %d but the mockup response (albedo map) "
                          "is %d x %d projector pixels",
                          t->width, t->height, r->width, r->height);
    double floor_ = d->floor > 0 ? d->floor : 1e-3;
    size_t n = (size_t)t->width * t->height;
    double gain = d->gain;
    if (!(gain >= 0 && isfinite(gain)))
        return lr_err_set(e, LR_EINVAL, "spatial AR: gain %g", gain);
    if (gain == 0) {
        double tmax = 0;
        for (size_t p = 0; p < n; p++)
            for (int c = 0; c < 3; c++)
                if (r->rgb[3 * p + c] > floor_ && isfinite(t->rgb[3 * p + c]))
                    tmax = fmax(tmax, t->rgb[3 * p + c]);
        gain = tmax > 0 ? 1.0 / tmax : 0;
    }
    int rc;
    if ((rc = lr_image_alloc(levels, t->width, t->height, e)))
        return rc;
    lr_ar_stats s = {.gain = gain};
    for (size_t p = 0; p < n; p++) {
        const float *tp = t->rgb + 3 * p, *rp = r->rgb + 3 * p;
        double light[3] = {0, 0, 0}, level[3];
        bool lit = false, clipped = false;
        for (int c = 0; c < 3; c++) {
            if (!(rp[c] > floor_))
                continue;
            lit = true;
            double want = tp[c] > 0 && isfinite(tp[c]) ? gain * tp[c] / rp[c] : 0; /* (1) */
            s.wanted_light += want;
            s.delivered_light += fmin(want, 1.0);
            if (want > 1)
                clipped = true;
            light[c] = fmin(want, 1.0);
        }
        s.lit_pixels += lit;
        s.clipped_pixels += clipped;
        if (d->calib) {
            lr_rig_projector_input(d->calib, light, level);
        } else {
            memcpy(level, light, sizeof level);
        }
        for (int c = 0; c < 3; c++)
            levels->rgb[3 * p + c] = (float)level[c];
    }
    s.clipped_fraction = s.lit_pixels ? (double)s.clipped_pixels / s.lit_pixels : 0;
    s.clipped_light_fraction =
        s.wanted_light > 0 ? 1 - s.delivered_light / s.wanted_light : 0;
    if (stats)
        *stats = s;
    return LR_OK;
}

void lr_ar_stats_format(const lr_ar_stats *s, char *buf, size_t cap)
{
    snprintf(buf, cap, "clipped %.1f %% of pixels, %.1f %% of the light",
             100 * s->clipped_fraction, 100 * s->clipped_light_fraction);
}
