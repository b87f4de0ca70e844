/* lamprig calib — one compensated projector frame for spatial AR (issue 5 item 7), the whole
 * chain of calib/spatial_ar.h from a calibration folder:
 *
 *   projector intrinsics (projector.json) and its scene pose (pose.json's "projector", from
 *   `lamprig calib pose --projector`)  ->  the scene rendered from the projector's centre
 *   (lr_ar_view_camera; the CPU reference, render/cpu/frame.h)  ->  warped into projector
 *   pixels (lr_ar_warp)  ->  divided by the mockup's response (albedo.json from
 *   `lamprig calib albedo`, or, without one, the irradiance factor g of an ideal white
 *   mockup of the scene's geometry, lr_ar_geometry)  ->  clipped, inverse projector response
 *   (projector_response.json)  ->  levels.
 *
 * The scene's camera is replaced for the render and restored afterwards.
 */
#ifndef LR_CALIB_AR_FRAME_H
#define LR_CALIB_AR_FRAME_H

#include "calib/rig.h"
#include "calib/spatial_ar.h"

typedef struct lr_ar_frame_desc {
    lr_scene *scene;
    const lr_rig_calib *calib;  /* has_procam and a pose with the projector are required */
    const lr_image *response;   /* mockup response per projector pixel; NULL: geometry */
    int render_width;           /* 0: the projector's width */
    int samples;                /* CPU reference samples per band per pixel; 0: 64 */
    bool no_vpl;
    unsigned seed;
    int threads;
    double gain;                /* lr_ar_desc.gain */
} lr_ar_frame_desc;

/* levels: projector w x h, 0..1. target (may be NULL): the warped target radiance. */
int lr_ar_frame(const lr_ar_frame_desc *d, lr_image *levels, lr_image *target,
                lr_ar_stats *stats, lr_err *e);

/* Sets the scene's camera (position, target, up, fov, near, far) through lr_scene_set. */
int lr_ar_set_camera(lr_scene *s, const lr_camera *c, lr_err *e);

#endif
