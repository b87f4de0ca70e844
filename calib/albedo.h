/* lamprig calib — the mockup's measured response for spatial AR (issue 5 item 7):
 * `lamprig calib albedo`.
 *
 * The projector shows full white and full black on the white mockup (the white.png and
 * black.png of a Gray-code capture, calib/graycode.h, whose decoding says which projector
 * pixel each camera pixel sees). Per projector pixel, the camera's linear white minus black
 * (ambient and projector black cancel) is the surface's response to that pixel's full light:
 *     M = rho g        (albedo x the projector's irradiance factor cos(theta) / d^2)
 * up to one constant, normalised here so that the 99.5th percentile of M over the measured
 * pixels is 1 (a few specular or mis-decoded pixels do not set the scale), values above 1
 * kept up to 4. Compensation divides the wanted light by M (calib/spatial_ar.h, Eq. 1); for
 * an ideal white mockup M is g alone, and M / g (lr_ar_geometry) is the albedo itself.
 *
 * Projector pixels no camera pixel decoded to (the camera has fewer pixels on the mockup
 * than the projector, or the pixel is off the mockup) get the mean of their measured
 * 8-neighbours, repeated `fill_passes` times; what is left is 0: not on the mockup, and
 * compensation leaves it dark.
 *
 * File: albedo.json (kind "mockup_albedo", version 1) beside its image:
 *   {"version": 1, "kind": "mockup_albedo", "image": "albedo.pfm" (relative to the JSON),
 *    "size": [W, H] (projector pixels), "scale": linear camera units of M = 1,
 *    "measured_pixels": N, "filled_pixels": N}
 * The PFM holds M per projector pixel, RGB, rows top to bottom. Loading checks the image's
 * size against "size" and every value (finite, 0..4).
 */
#ifndef LR_CALIB_ALBEDO_H
#define LR_CALIB_ALBEDO_H

#include "calib/graycode.h"
#include "render/base/err.h"
#include "render/image/image.h"

#define LR_ALBEDO_KIND "mockup_albedo"
#define LR_RIG_ALBEDO "albedo.json"
#define LR_ALBEDO_MAX 4.0

typedef struct lr_albedo {
    lr_image response;    /* M per projector pixel (owned) */
    double scale;         /* linear camera units of M = 1 */
    long measured_pixels; /* projector pixels seen by at least one camera pixel */
    long filled_pixels;   /* filled from neighbours */
} lr_albedo;

/* white and black: linear camera images (lr_rig_camera_to_linear of the captures), the
 * camera size of map; map: their Gray-code decoding. fill_passes: < 0 for the default 2. */
int lr_albedo_measure(const lr_image *white, const lr_image *black, const lr_gc_map *map,
                      int fill_passes, lr_albedo *out, lr_err *e);
void lr_albedo_free(lr_albedo *a);

/* Writes IMAGE.pfm beside path (path's name with .json replaced by .pfm) and then path, each
 * atomically, the JSON only after it parsed back and validated. */
int lr_albedo_save(const char *path, const lr_albedo *a, lr_err *e);
int lr_albedo_load(const char *path, lr_albedo *out, lr_err *e);

#endif
