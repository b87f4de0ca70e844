/* Energy on the GPU (issue 3): "a closed sphere of non-absorbing material around a point light
 * emits the light's power within 5 %". configs/scenes/sphere_shell.json (R 40, 2 mm wall,
 * sigma_a = 0, eta 1.5, light at the centre), rendered by the GLES passes; the power leaving
 * the outer surface is integrated from the GPU's own radiosity maps:
 *
 *   Phi = gain T_hem int B dA,   int B dA = sum_k sum_texels B h^2 / sum_j max(0, n . d_j)
 *
 * (a texel of map k covers h^2 / (n . d_k) of surface; weighting map k by (n . d_k) / sum_j
 * max(0, n . d_j) counts every point of the convex outer surface once over the maps that see
 * it), with `gain` the cavity gain composition applies (render/core/cavity.h). The CPU side of
 * the same requirement is tests/cpu/test_cpu_energy.c. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/optics/optics.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

/* Phi / (4 pi I) per band from the GPU's maps (see the top), and the gain composition uses. */
static void outer_power(lr_renderer *r, const lr_scene *s, double P[3], double gain[3])
{
    lr_debug_map_info info;
    lr_renderer_debug_map_info(r, &info);
    size_t S = (size_t)info.size;
    float *B = calloc(S * S * 3, sizeof *B), *nrm = calloc(S * S * 3, sizeof *nrm);
    int *obj = calloc(S * S, sizeof *obj);
    assert_true(B && nrm && obj);
    double h = 2.0 * info.radius / (double)S, sum[3] = {0};
    for (int k = 0; k < info.K; k++) {
        lr_err e = {0};
        if (lr_renderer_debug_read_map(r, k, B, NULL, nrm, obj, &e))
            fail_msg("%s", e.msg);
        for (size_t t = 0; t < S * S; t++) {
            if (obj[t] < 0)
                continue;
            lr_vec3 n = lr_v3_normalize(lr_v3(nrm[3 * t], nrm[3 * t + 1], nrm[3 * t + 2]));
            double cover = 0.0;
            for (int j = 0; j < info.K; j++)
                cover += fmax(0.0, lr_v3_dot(n, lr_renderer_debug_map_dir(r, j)));
            if (!(cover > 0.0))
                continue;
            for (int c = 0; c < 3; c++)
                sum[c] += B[3 * t + c] * h * h / cover;
        }
    }
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    double T = lr_hemi_transmittance(o->coeffs.eta);
    lr_renderer_debug_cavity_gain(r, 0, gain);
    for (int c = 0; c < 3; c++)
        P[c] = gain[c] * T * sum[c] / (4.0 * M_PI);
    free(B);
    free(nrm);
    free(obj);
}

static void test_sphere_shell_emits_light_power(void **state)
{
    (void)state;
    /* 16 maps of 48^2, 16 samples x 8 frames per texel and band: about 2e6 samples per band
     * over the outer surface; the estimate's own noise is well below 1 % (the twin's pass
     * sampler has a 2.5 % standard error at 32 points x 4000 samples, 1.3e5). */
    static const char *const sets[] = {"render.K=16", "render.N=16", "render.map_size=48",
                                       "render.gbuffer_size=128", "render.frames=8",
                                       "render.N_vpl=16", "render.vpl_map_size=16", NULL};
    lr_scene *s = lr_test_scene("sphere_shell", sets, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, 64, 48, true, 1);
    lr_test_converge(r, 8);
    double P[3], gain[3];
    outer_power(r, s, P, gain);
    for (int c = 0; c < 3; c++) {
        print_message("sphere_shell band %d: cavity gain %.3f, Phi_out %.4f x 4 pi I (GPU maps)\n",
                      c, gain[c], P[c]);
        assert_true(gain[c] > 2.0 && gain[c] < 4.0); /* 2.6-3.5 measured on the CPU */
        assert_near(P[c], 1.0, 0.05);
    }
    /* Without the closure and the normalisation (the published model): far from 4 pi I. */
    lr_test_set(s, r, "objects[globe].normalize", "false");
    lr_test_converge(r, 8);
    outer_power(r, s, P, gain);
    for (int c = 0; c < 3; c++) {
        print_message("raw model band %d: gain %.3f, Phi_out %.4f x 4 pi I\n", c, gain[c], P[c]);
        assert_true(gain[c] == 1.0);
        assert_true(P[c] < 0.6);
    }
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* The same shell with the slab multipole (issue 12): "thickness_mm": 2 (the wall) and "model":
 * "multipole". The closure's A is the slab's exact R + T total (1 here, sigma_a = 0), so the
 * outer surface still emits 4 pi I within 5 %. */
static void test_sphere_shell_multipole(void **state)
{
    (void)state;
    static const char *const sets[] = {"render.K=16", "render.N=16", "render.map_size=48",
                                       "render.gbuffer_size=128", "render.frames=8",
                                       "render.N_vpl=16", "render.vpl_map_size=16",
                                       "objects[globe].thickness_mm=2",
                                       "objects[globe].model=multipole", NULL};
    lr_scene *s = lr_test_scene("sphere_shell", sets, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, 64, 48, true, 1);
    lr_test_converge(r, 8);
    double P[3], gain[3];
    outer_power(r, s, P, gain);
    for (int c = 0; c < 3; c++) {
        print_message("sphere_shell multipole band %d: cavity gain %.3f, Phi_out %.4f x 4 pi I "
                      "(GPU maps)\n", c, gain[c], P[c]);
        assert_true(gain[c] > 1.0);
        assert_near(P[c], 1.0, 0.05);
    }
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

int main(void)
{
    if (getenv("LR_TEST_FILTER"))
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_shell_emits_light_power),
        cmocka_unit_test(test_sphere_shell_multipole),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
