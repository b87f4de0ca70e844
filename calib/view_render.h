/* lamprig calib — render the calibrated camera's view of a scene (calib/camview.h) with the
 * GPU renderer (EGL surfaceless or whatever lr_gl_create opens) or the CPU twin
 * (render/cpu/frame.h, LR_CPU_PASS), and resample it into the camera's pixels. Shared by the
 * capture simulator (tools/capsim), `lamprig compare` and material fitting.
 *
 * The scene's camera is replaced by the pinhole camera the view needs (lr_camview_apply);
 * everything else in the scene is used as is. Output: linear radiance, W/(mm^2 sr), camera
 * pixels (lr_camview_size), rows top to bottom; exposure is not applied.
 */
#ifndef LR_CALIB_VIEW_RENDER_H
#define LR_CALIB_VIEW_RENDER_H

#include <stdbool.h>

#include "calib/camview.h"
#include "render/base/progress.h"
#include "render/image/image.h"
#include "render/scene/scene.h"

typedef struct lr_view_render_desc {
    lr_scene *scene;          /* its camera is changed */
    const lr_camview *view;
    bool cpu;                 /* the CPU twin instead of the GPU renderer */
    int frames;               /* progressive frames; 0: render.frames (until converged) */
    unsigned seed;            /* 0: 1 */
    int threads;              /* CPU: 0 = all */
    const lr_progress *progress; /* may be NULL: "render frame" i of N (GPU; N the frames or
                                  * render.frames), the CPU twin's stages (render/cpu/frame.h) */
} lr_view_render_desc;

/* *seconds (may be NULL): wall time of the render itself (context and remap excluded). */
int lr_view_render(const lr_view_render_desc *d, lr_image *out, double *seconds, lr_err *e);

#endif
