/* lamprig calib — comparing a render with a capture of the mockup (issue 5 item 4): the
 * metrics and the masks, independent of where the two images came from (`lamprig compare`,
 * material fitting and tests call these).
 *
 * Inputs are two linear RGB images of the same size in the same units (the render's
 * W/(mm^2 sr), the capture linearised and divided by gain x exposure time: see
 * lr_compare_linearise) and per-pixel labels (lr_pixel_label from lr_camview_labels).
 *
 * Regions: OBJECT (translucent objects), RECEIVERS (table, wall) and ALL (both). A pixel is
 * compared when
 *   - its label is OBJECT or RECEIVER and every pixel within `edge_px` has the same label
 *     (boundary pixels mix surfaces, and a fraction of a pixel of misregistration there
 *     becomes a large error that says nothing about the material);
 *   - it is not excluded (saturated or in shadow in the capture: lr_compare_capture_mask).
 *
 * Metrics per region:
 *   rmse      RMSE in linear light, in the render's units (W/(mm^2 sr));
 *   rel_rmse  relative RMSE in linear light: sqrt(sum_px,c (C - R)^2 / sum_px,c R^2);
 *   ssim      Wang, Bovik, Sheikh, Simoncelli 2004 (IEEE TIP 13(4), Eq. 13) on luminance
 *             Y = 0.2126 R + 0.7152 G + 0.0722 B, 11 x 11 Gaussian window sigma 1.5
 *             (truncated and renormalised at the image border), K1 = 0.01, K2 = 0.03, L = 1,
 *             after scaling BOTH images by the common factor s = 1 / (99th percentile of the
 *             render's luminance over all compared pixels) and clipping to [0, 1]; the SSIM
 *             map is computed over the whole image and averaged over the region's pixels;
 *   delta_e   mean CIEDE2000 (lcms2's cmsCIE2000DeltaE, kL = kC = kH = 1) between the two
 *             images scaled by the same s, clipped to [0, 1], taken as linear sRGB (D65) and
 *             converted to CIELAB (D50, relative colorimetric: white (1,1,1) -> L* 100) by an
 *             lcms2 transform; delta_e_p95 its 95th percentile.
 */
#ifndef LR_CALIB_COMPARE_H
#define LR_CALIB_COMPARE_H

#include <stdint.h>

#include "calib/image.h"
#include "calib/rig.h"
#include "render/image/image.h"

enum lr_compare_region { LR_REGION_OBJECT = 0, LR_REGION_RECEIVERS, LR_REGION_ALL,
                         LR_REGION_COUNT };

typedef struct lr_compare_stats {
    long pixels;        /* compared */
    double rmse;        /* linear RMSE, render units: sqrt(sum (C - R)^2 / (3 pixels)) */
    double rel_rmse;
    double ssim;
    double delta_e;     /* mean */
    double delta_e_p95;
} lr_compare_stats;

typedef struct lr_compare_result {
    lr_compare_stats region[LR_REGION_COUNT];
    double scale;       /* s above */
    long excluded;      /* object/receiver pixels dropped as saturated or shadow */
    long edge;          /* dropped at label boundaries */
} lr_compare_result;

typedef struct lr_compare_desc {
    const lr_image *render;
    const lr_image *capture;
    const uint8_t *labels;  /* enum lr_pixel_label, width * height */
    const uint8_t *exclude; /* non-zero: excluded; may be NULL */
    int edge_px;            /* 0 -> 1; < 0: keep boundary pixels */
} lr_compare_desc;

/* delta_e_map (may be NULL): width * height per-pixel CIEDE2000, NaN where not compared. */
int lr_compare_run(const lr_compare_desc *d, lr_compare_result *out, float *delta_e_map,
                   lr_err *e);

/* "object", "receivers", "all". */
const char *lr_compare_region_name(int region);

/* ---- building blocks ------------------------------------------------------------------- */

/* CIEDE2000 colour difference of two CIELAB colours (cmsCIE2000DeltaE, kL = kC = kH = 1). */
double lr_ciede2000(const double lab1[3], const double lab2[3]);

/* Linear sRGB (D65, 0..1) to CIELAB D50 through lcms2, n pixels (rgb: 3n doubles in,
 * lab: 3n out). */
typedef struct lr_lab_xform lr_lab_xform;
int lr_lab_xform_create(lr_lab_xform **out, lr_err *e);
void lr_lab_xform_destroy(lr_lab_xform *x);
void lr_lab_xform_apply(const lr_lab_xform *x, const double *rgb, double *lab, int n);

/* SSIM map of two single-channel images with values in [0, L = 1] (parameters above). */
int lr_ssim_map(const float *a, const float *b, int w, int h, float *out, lr_err *e);

/* ---- captures -------------------------------------------------------------------------- */

/* Per pixel of one capture or an exposure stack (RGB, 8 or 16 bit, same size): 1 where
 * the pixel is saturated (some channel >= sat of full scale) in every image, or in shadow
 * (every channel <= dark of full scale) in every image; 0 elsewhere. sat 0 -> 250/255,
 * dark 0 -> 5/255. */
int lr_compare_capture_mask(const lr_img *images, int n, double sat, double dark,
                            uint8_t *exclude, lr_err *e);

/* A capture (n = 1) or an exposure stack (n > 1, 8-bit, times in seconds) in the render's
 * units: the rig's camera response (lr_rig_camera_response: camera_response.json, else the
 * gamma curve, rig->gamma or 2.2; the rule fit and lamprig-capsim use too) and colour matrix
 * (16-bit values are read as fractional 8-bit codes), the stack merged by lr_camresp_merge
 * (Debevec & Malik Eq. 6, hat weights), then divided by gain x time. */
int lr_compare_linearise(const lr_rig_calib *rig, const lr_img *images, const double *times,
                         int n, double gain, lr_image *out, lr_err *e);

/* Per-pixel map as PNG: values 0..vmax colour-mapped (dark blue -> red -> yellow), NaN grey,
 * with a colour bar and its scale on the right, `title` on top. Written atomically. */
int lr_heatmap_png(const char *path, const float *v, int w, int h, double vmax,
                   const char *title, lr_err *e);

#endif
