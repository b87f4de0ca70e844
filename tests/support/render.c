/* lamprig tests — scenes and renderers for the render tests. */
#include "tests/support/render.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/cpu/frame.h"
#include "tests/support/near.h"

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

void lr_test_final_image_vs_twin(lr_gl *gl, lr_scene *s, int w, int h, const char *label,
                                 bool no_vpl, double recv_tol)
{
    lr_renderer *r = lr_test_renderer(gl, s, w, h, no_vpl, 3);
    lr_test_converge(r, 20);
    float *hdr = lr_test_hdr(r); /* rows bottom up */
    lr_cpu_render_desc d = {.scene = s, .width = w, .height = h, .mode = LR_CPU_PASS,
                            .no_vpl = no_vpl};
    lr_image twin, var;
    lr_cpu_render_stats st;
    lr_err e = {0};
    if (lr_cpu_render(&d, &twin, &var, &st, &e))
        fail_msg("%s", e.msg);
    double sum_g[2] = {0}, sum_c[2] = {0}, v[2] = {0};
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            lr_vec3 org, dir;
            lr_cpu_camera_ray(s, w, h, x, y, &org, &dir);
            lr_hit hit;
            int region = lr_bvh_intersect(lr_scene_object_at(s, 0)->bvh, org, dir, 0, INFINITY,
                                          &hit) ? 0 : 1;
            const float *gp = hdr + 3 * ((size_t)(h - 1 - y) * w + x);
            const float *cp = twin.rgb + 3 * ((size_t)y * w + x);
            const float *vp = var.rgb + 3 * ((size_t)y * w + x);
            for (int c = 0; c < 3; c++) {
                assert_true(isfinite(gp[c]) && gp[c] >= 0.0f);
                sum_g[region] += gp[c];
                sum_c[region] += cp[c];
                v[region] += 2.0 * vp[c];
            }
        }
    const char *names[2] = {"object", "receivers"};
    for (int i = 0; i < 2; i++) {
        print_message("%s%s, %s pixels: GPU %.5g, CPU twin %.5g (%+.2f %%, sigma %.2f %%)\n",
                      label, no_vpl ? " (no VPL)" : "", names[i], sum_g[i], sum_c[i],
                      100 * (sum_g[i] / sum_c[i] - 1), 100 * sqrt(v[i]) / sum_c[i]);
        assert_true(sum_c[i] > 0.0);
        if (i == 0)
            assert_near(sum_g[i], sum_c[i], 4.0 * sqrt(v[i]) + 0.05 * sum_c[i]);
        else
            assert_near_rel(sum_g[i], sum_c[i], no_vpl ? recv_tol : 0.20);
    }
    free(hdr);
    lr_image_free(&twin);
    lr_image_free(&var);
    lr_renderer_destroy(r);
}
