/* lamprig tests — scenes and renderers for the render tests. */
#include "tests/support/render.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/mat4.h"

const char *const lr_test_small_settings[] = {
    "render.K=6",          "render.N=4",           "render.map_size=48", "render.gbuffer_size=64",
    "render.vpl_map_size=16", "render.N_vpl=48", "render.frames=2", NULL};

static void apply(lr_scene *s, const char *const *sets)
{
    lr_err e = {0};
    for (; sets && *sets; sets++)
        if (lr_scene_set_assignment(s, *sets, NULL, &e))
            fail_msg("%s: %s", *sets, e.msg);
}

lr_scene *lr_test_scene(const char *name, const char *const *sets1, const char *const *sets2)
{
    char path[256];
    snprintf(path, sizeof path, "configs/scenes/%s.json", name);
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    apply(s, sets1);
    apply(s, sets2);
    return s;
}

lr_scene *lr_test_scene_text(const char *text, const char *const *sets)
{
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_parse(text, strlen(text), "configs/scenes/test.json", NULL, &s, &e))
        fail_msg("%s", e.msg);
    apply(s, sets);
    return s;
}

lr_renderer *lr_test_renderer(lr_gl *gl, lr_scene *s, int w, int h, bool no_vpl, unsigned seed)
{
    lr_renderer *r = NULL;
    lr_err e = {0};
    lr_renderer_desc d = {.gl = gl, .scene = s, .width = w, .height = h, .no_vpl = no_vpl, .seed = seed};
    if (lr_renderer_create(&d, &r, &e))
        fail_msg("lr_renderer_create: %s", e.msg);
    return r;
}

lr_renderer *lr_test_renderer_desc(const lr_renderer_desc *d)
{
    lr_renderer *r = NULL;
    lr_err e = {0};
    if (lr_renderer_create(d, &r, &e))
        fail_msg("lr_renderer_create: %s", e.msg);
    return r;
}

lr_frame_stats lr_test_frame(lr_renderer *r)
{
    lr_frame_stats st;
    lr_err e = {0};
    if (lr_renderer_frame(r, &st, &e))
        fail_msg("lr_renderer_frame: %s", e.msg);
    return st;
}

int lr_test_converge(lr_renderer *r, int max)
{
    int n = 0;
    while (lr_renderer_needs_frame(r) && n < max) {
        lr_test_frame(r);
        n++;
    }
    return n;
}

void lr_test_set(lr_scene *s, lr_renderer *r, const char *key, const char *value)
{
    unsigned dirty = 0;
    lr_err e = {0};
    if (lr_scene_set(s, key, value, &dirty, &e))
        fail_msg("%s=%s: %s", key, value, e.msg);
    lr_renderer_invalidate(r, dirty);
}

float *lr_test_hdr(lr_renderer *r)
{
    int w, h;
    lr_renderer_size(r, &w, &h);
    float *rgb = malloc((size_t)w * h * 3 * sizeof *rgb);
    lr_err e = {0};
    if (!rgb || lr_renderer_read_hdr(r, rgb, &e))
        fail_msg("read_hdr: %s", e.msg);
    return rgb;
}

bool lr_test_project(const lr_scene *s, int w, int h, lr_vec3 p, int *x, int *y)
{
    double view[16], proj[16], vp[16];
    lr_camera_view(lr_scene_camera(s), view);
    lr_camera_projection(lr_scene_camera(s), (double)w / h, proj);
    lr_mat4_mul(proj, view, vp);
    lr_vec3 n = lr_mat4_project(vp, p);
    double fx = (n.x * 0.5 + 0.5) * w, fy = (n.y * 0.5 + 0.5) * h;
    if (!(fx >= 0 && fx < w && fy >= 0 && fy < h))
        return false;
    *x = (int)fx;
    *y = (int)fy;
    return true;
}

lr_vec3 lr_test_pixel_on_plane(const lr_scene *s, int w, int h, int x, int y, lr_vec3 c, lr_vec3 n)
{
    double view[16], proj[16], vp[16], inv[16];
    lr_camera_view(lr_scene_camera(s), view);
    lr_camera_projection(lr_scene_camera(s), (double)w / h, proj);
    lr_mat4_mul(proj, view, vp);
    lr_mat4_inverse(vp, inv);
    double nx = (x + 0.5) / w * 2.0 - 1.0, ny = (y + 0.5) / h * 2.0 - 1.0;
    lr_vec3 a = lr_mat4_project(inv, lr_v3(nx, ny, -1.0)), b = lr_mat4_project(inv, lr_v3(nx, ny, 1.0));
    lr_vec3 d = lr_v3_sub(b, a);
    double t = lr_v3_dot(lr_v3_sub(c, a), n) / lr_v3_dot(d, n);
    return lr_v3_add(a, lr_v3_scale(d, t));
}
