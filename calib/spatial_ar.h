/* lamprig calib — spatial AR (issue 5 item 7; seed 000 section 6.2): the projector lights a
 * white mockup of the lamp so that the mockup shows the rendered appearance of the real one.
 *
 * The projector is a camera with the light going the other way. Its frame is OpenCV's
 * (X_proj = Rp X_world + Tp, +Z forward, +Y down in the image, pixel (i, j) centred at (i, j)).
 *
 *   1. Target. The scene is rendered from the projector's centre (lr_ar_view_camera: a
 *      symmetric pinhole whose field covers the projector's whole, possibly lens-shifted and
 *      distorted, frustum), then each projector pixel looks up its own ray in that image
 *      (lr_ar_warp: undistort, then project into the render): the principal point, fx != fy
 *      and the lens distortion are handled by the warp, so the renderer needs no special
 *      projection.
 *   2. Geometry. Each projector pixel's ray is cast onto the mockup's geometry (the scene's
 *      objects) to get the irradiance factor g = cos(theta) / d^2 of the projector on the
 *      surface (projector radiant intensity taken uniform over its pixels), normalised by its
 *      largest value: g in (0, 1], 0 where the ray misses (lr_ar_geometry).
 *   3. Compensation. A Lambertian mockup of albedo rho lit with relative projector light l
 *      (0..1 of full white, black subtracted) looks to the camera like rho g l. To show the
 *      target radiance T the projector must send
 *          l = gain T / (rho g)                                                       (1)
 *      where gain maps the target's units to "full white on an albedo-1 surface at g = 1".
 *      l > 1 cannot be reached: it is clipped to 1, and the clip is reported as the fraction
 *      of lit pixels clipped and the fraction of the wanted light (sum of l over lit pixels)
 *      lost. Then the inverse projector response (lr_rig_projector_input) gives the level.
 *
 * rho g together is what the albedo calibration measures (calib/albedo.h: white minus black
 * capture per projector pixel); dividing by a measured rho g is (1) without any model of
 * the geometry. Where only rho is known (a synthetic or re-posed mockup) g comes from step 2.
 */
#ifndef LR_CALIB_SPATIAL_AR_H
#define LR_CALIB_SPATIAL_AR_H

#include <stdbool.h>

#include "calib/intrinsics.h"
#include "calib/rig.h"
#include "render/base/err.h"
#include "render/image/image.h"
#include "render/scene/scene.h"

typedef struct lr_ar_pose {
    double R[9]; /* X_proj = R X_world + T; row-major rotation */
    double T[3]; /* mm */
} lr_ar_pose;

/* A symmetric pinhole camera (scene camera fields) at the projector's centre, looking down
 * its optical axis, with +Y of the image down as the projector's, whose vertical field and
 * aspect cover every projector pixel's ray with a margin of `margin` (e.g. 0.02 = 2 %).
 * *aspect is the render's width / height to use. */
int lr_ar_view_camera(const lr_intrinsics *proj, const lr_ar_pose *pose, double margin,
                      lr_camera *cam, double *aspect, lr_err *e);

/* Per projector pixel, the render-image position (pixel centres at i + 0.5, rows from the
 * top) of its ray for a render of rw x rh made with that camera; map is proj w*h*2 floats
 * (allocated here; free()). Pixels whose ray does not undistort are set to -1. */
int lr_ar_warp_map(const lr_intrinsics *proj, const lr_camera *cam, int rw, int rh,
                   float **map, lr_err *e);
/* Resamples a render (bilinear) into projector pixels through map; out is proj w x h. */
int lr_ar_warp(const lr_image *render, const float *map, int pw, int ph, lr_image *out,
               lr_err *e);

/* g = cos(theta) / d^2 per projector pixel on the scene's objects, normalised to max 1
 * (out: pw x ph, the same value in all three channels; 0 where the ray misses). *lit is the
 * number of pixels that hit. The normaliser is returned in *g_max (mm^-2). */
int lr_ar_geometry(const lr_scene *scene, const lr_intrinsics *proj, const lr_ar_pose *pose,
                   lr_image *out, long *lit, double *g_max, lr_err *e);

typedef struct lr_ar_stats {
    long lit_pixels;       /* projector pixels where the mockup responds (rho g > floor) */
    long clipped_pixels;   /* of those, pixels where some channel wanted l > 1 */
    double clipped_fraction;     /* clipped_pixels / lit_pixels */
    double wanted_light, delivered_light; /* sum over lit pixels and channels of l, min(l,1) */
    double clipped_light_fraction;        /* 1 - delivered / wanted */
    double gain;           /* the gain used */
} lr_ar_stats;

typedef struct lr_ar_desc {
    const lr_image *target;    /* linear radiance per projector pixel (lr_ar_warp output) */
    const lr_image *response;  /* rho g per projector pixel, 0..1 (albedo map, or albedo x
                                * lr_ar_geometry) */
    double gain;               /* target units -> relative light; 0: 1 / (the largest target
                                * value over lit pixels), so the brightest target point is
                                * full white on a perfect white surface */
    double floor;              /* rho g below this is "not lit" (output 0); 0: 1e-3 */
    const lr_rig_calib *calib; /* projector response; NULL: identity */
} lr_ar_desc;

/* Equation (1), clip, inverse response: levels (0..1, pw x ph x 3) to show. */
int lr_ar_compensate(const lr_ar_desc *d, lr_image *levels, lr_ar_stats *stats, lr_err *e);

/* "clipped 3.2 % of pixels, 0.8 % of the light" */
void lr_ar_stats_format(const lr_ar_stats *s, char *buf, size_t cap);

#endif
