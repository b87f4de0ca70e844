/* Camera matrices for GL (float) and the CPU reference (double). */
#include <math.h>

#include "render/base/mat4.h"
#include "render/scene/scene.h"

void lr_camera_view(const lr_camera *c, double out[16])
{
    if (lr_mat4_look_at(c->position, c->target, c->up, out) != 0)
        lr_mat4_identity(out); /* unreachable for a scene's camera: checked on every change */
}

void lr_camera_projection(const lr_camera *c, double aspect, double out[16])
{
    if (c->orthographic) {
        double h = c->height_mm / 2.0, w = h * aspect;
        lr_mat4_ortho(-w, w, -h, h, c->near_mm, c->far_mm, out);
    } else {
        lr_mat4_perspective(c->fov_deg * (M_PI / 180.0), aspect, c->near_mm, c->far_mm, out);
    }
}

void lr_camera_view_f(const lr_camera *c, float out[16])
{
    double m[16];
    lr_camera_view(c, m);
    lr_mat4_to_float(m, out);
}

void lr_camera_projection_f(const lr_camera *c, double aspect, float out[16])
{
    double m[16];
    lr_camera_projection(c, aspect, m);
    lr_mat4_to_float(m, out);
}
