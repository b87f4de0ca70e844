/* The light G-buffer's cameras (gbuffer_camera.h): moved out of gbuffer.c unchanged so that the
 * GPU pass and the CPU twin share them. */
#include "render/core/gbuffer_camera.h"

#include <math.h>

#include "render/area/frames.h"
#include "render/base/mat4.h"

void lr_cube_face_vp(lr_vec3 at, int f, double znear, double zfar, double out[16])
{
    static const double dir[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const double up[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    double view[16], proj[16];
    lr_vec3 target = lr_v3_add(at, lr_v3(dir[f][0], dir[f][1], dir[f][2]));
    lr_mat4_look_at(at, target, lr_v3(up[f][0], up[f][1], up[f][2]), view);
    lr_mat4_perspective(M_PI / 2.0, 1.0, znear, zfar, proj);
    lr_mat4_mul(proj, view, out);
}

static lr_vec3 up_for(lr_vec3 dir)
{
    return fabs(dir.z) > 0.99 ? lr_v3(0.0, 1.0, 0.0) : lr_v3(0.0, 0.0, 1.0);
}

void lr_gb_camera_make(const lr_light *light, lr_vec3 c, double R, bool enclosed,
                       lr_gb_camera *out)
{
    R = fmax(R, 1e-3);
    lr_vec3 dir = lr_v3_normalize(light->direction);
    double dist = lr_v3_len(lr_v3_sub(c, light->position));
    if (light->type == LR_LIGHT_DIRECTIONAL)
        out->mode = LR_GB_ORTHO;
    else if ((light->type == LR_LIGHT_POINT || lr_light_is_area(light)) &&
             (enclosed || dist < 1.05 * R))
        out->mode = LR_GB_CUBE;
    else
        out->mode = LR_GB_PERSPECTIVE;

    if (out->mode == LR_GB_CUBE) {
        double znear = fmax(1e-4 * R, 1e-3), zfar = dist + 3.0 * R;
        out->views = 6;
        for (int f = 0; f < 6; f++)
            lr_cube_face_vp(light->position, f, znear, zfar, out->vp[f]);
        return;
    }
    double view[16], proj[16];
    if (out->mode == LR_GB_ORTHO) {
        lr_vec3 eye = lr_v3_sub(c, lr_v3_scale(dir, 2.0 * R));
        lr_mat4_look_at(eye, c, up_for(dir), view);
        lr_mat4_ortho(-R, R, -R, R, 0.5 * R, 3.5 * R, proj);
    } else if (light->type == LR_LIGHT_SPOT) {
        lr_mat4_look_at(light->position, lr_v3_add(light->position, dir), up_for(dir), view);
        double fov = fmin(2.0 * light->outer_deg * M_PI / 180.0 * 1.02, 170.0 * M_PI / 180.0);
        lr_mat4_perspective(fov, 1.0, fmax(1e-3 * R, 1e-3), dist + 3.0 * R, proj);
    } else {
        lr_vec3 axis = lr_v3_normalize(lr_v3_sub(c, light->position));
        lr_mat4_look_at(light->position, c, up_for(axis), view);
        double fov = 2.0 * asin(fmin(R / dist, 1.0)) * 1.05;
        lr_mat4_perspective(fmin(fov, 170.0 * M_PI / 180.0), 1.0, fmax(0.5 * (dist - R), 1e-3),
                            dist + 2.0 * R, proj);
    }
    out->views = 1;
    lr_mat4_mul(proj, view, out->vp[0]);
}

void lr_gb_camera_scene(const lr_scene *s, int l, lr_gb_camera *out)
{
    lr_gb_camera_scene_frame(s, l, 0, out);
}

void lr_gb_camera_scene_frame(const lr_scene *s, int l, long frame, lr_gb_camera *out)
{
    lr_vec3 c;
    double R;
    lr_scene_bounds(s, &c, &R);
    enum lr_enclosure enc = lr_scene_light_enclosure(s, l, NULL);
    lr_light at;
    lr_light_at_frame(lr_scene_light_at(s, l), frame, &at);
    lr_gb_camera_make(&at, c, R, enc != LR_ENCLOSURE_NONE, out);
}
