/* lamprig — a whole image of a scene's camera view on the CPU, in two modes:
 *
 *   LR_CPU_PASS       the CPU twin of the GPU renderer: per object and light, K radiosity maps
 *                     accumulated over `frames` frames (maps.h), Algorithm 1 per camera pixel
 *                     (with render.surface_cache: at the refined vertices of surface.h,
 *                     interpolated at the hit, as the GPU), L_o = I F_t(w_o) B / pi; receivers lit directly (shadow rays) and by the
 *                     scene's N_vpl VPLs with B from Algorithm 1 (vpl.h), on plane receivers
 *                     through the GPU's receiver irradiance grid (recv_grid.h: E_vpl at its
 *                     texel centres, bilinear in between).
 *   LR_CPU_REFERENCE  the converged reference of the same model: per pixel x_o is ray-cast and B
 *                     is evaluated there with the untruncated estimator (radiosity.h,
 *                     `samples` per band), no maps; receivers by direct light plus many VPLs
 *                     (default 1024) whose B comes from the same estimator.
 *
 * Output: linear radiance per band, W/(mm^2 sr) for the scene's light intensities (exposure
 * is not applied), rows top to bottom (lr_image), and the variance of each pixel's estimate
 * (Monte Carlo error of B, propagated; the VPL discretisation is a model choice and not in it).
 * Background pixels are 0. Flicker is taken at t = 0 (factor 1, no offset) -- it is ignored.
 */
#ifndef LR_CPU_FRAME_H
#define LR_CPU_FRAME_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/base/progress.h"
#include "render/models/twin/radiosity.h"
#include "render/image/image.h"
#include "render/scene/scene.h"

typedef struct lr_cpu_render_desc {
    const lr_scene *scene;
    int width, height;          /* 0: 160 x 120 */
    enum lr_cpu_sampler mode;   /* LR_CPU_PASS (twin) or LR_CPU_REFERENCE */
    int frames;                 /* PASS: frames accumulated; 0: render.frames */
    int samples;                /* REFERENCE: samples per band per pixel and VPL; 0: 1024 */
    int vpl_count;              /* 0: render.N_vpl (PASS) or 1024 (REFERENCE) */
    int K, map_size, N;         /* PASS: 0: the scene's render settings */
    bool no_vpl;                /* receivers get direct light only */
    unsigned seed;              /* 0: 1 */
    int threads;                /* 0: all CPUs */
    const lr_progress *progress; /* may be NULL: "cpu maps" per object and light (PASS),
                                  * "cpu pixels" in sixteenths of the image */
} lr_cpu_render_desc;

typedef struct lr_cpu_render_stats {
    double seconds;          /* wall time */
    double samples;          /* estimator samples drawn (per band counted once per band) */
    double samples_per_s;
    long object_pixels;      /* pixels showing a translucent object */
    long fallback_pixels;    /* PASS: pixels no map saw (Algorithm 1's fallback) */
    int vpls;                /* valid VPLs over all objects */
} lr_cpu_render_stats;

/* Renders into rgb (allocated here) and, when var is not NULL, the variance image. */
int lr_cpu_render(const lr_cpu_render_desc *d, lr_image *rgb, lr_image *var,
                  lr_cpu_render_stats *stats, lr_err *e);

/* The camera ray through the centre of pixel (px, py), py counted from the top. */
void lr_cpu_camera_ray(const lr_scene *s, int width, int height, int px, int py, lr_vec3 *org,
                       lr_vec3 *dir);

#endif
