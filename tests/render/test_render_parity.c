/* GPU/CPU parity (issue 3, item 4): the GLSL passes (render/passes, read back through
 * render/renderer_debug.h) against their CPU twin (render/cpu) on the same inputs.
 *
 *  - Radiosity maps: at every covered texel of the GPU's maps, the CPU estimator is evaluated
 *    at the GPU's own x_o, n_o (as floats) with n_cpu samples per band. Both estimate the same
 *    quantity with the same sampling scheme, so the one-sample variance s^2 the CPU measures
 *    at that texel is the GPU's too, and z = (B_gpu - B_cpu) / sqrt(s^2 / n_gpu + s^2 / n_cpu),
 *    n_gpu = N * frames, is ~ N(0, 1) where the estimator is well behaved. Checked: the
 *    aggregate (sum over texels) within 4 aggregate sigma + the G-buffer's discretisation
 *    allowance (below), and the fraction of texel-bands with |z| > 3 and > 4.
 *  - VPLs: positions, normals and areas of the GPU's cube-map placement against the CPU's
 *    exact ray casts along the same directions.
 *  - A small final image: the CPU twin (its own maps, same settings) against the GPU image.
 */
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
#include "render/models/twin/radiosity.h"
#include "render/base/rng.h"
#include "render/core/vpl.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "tests/support/gbuffer_snap.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

typedef struct parity {
    long n;          /* texel-bands compared */
    long over3, over4;
    double sum_gpu, sum_cpu, var_sum; /* aggregate and its variance */
    /* the same z statistics restricted to texels facing the light (n_o . h^ > 0.2) */
    long nf, over3f, over4f;
} parity;

/* Light `light`'s maps (each light has its own, for unit intensity). */
static void compare_light_maps(lr_renderer *r, lr_scene *s, int light, int n_cpu, bool emulate,
                               parity *out)
{
    lr_test_snap g;
    lr_test_snap_init(r, light, &g);
    const lr_light *L = lr_scene_light_at(s, light);
    lr_debug_map_info info;
    lr_renderer_debug_map_info(r, &info);
    size_t S = (size_t)info.size;
    float *B = calloc(S * S * 3, sizeof *B), *pos = calloc(S * S * 3, sizeof *pos),
          *nrm = calloc(S * S * 3, sizeof *nrm);
    int *obj = calloc(S * S, sizeof *obj);
    assert_non_null(B);
    const lr_scene_object *objs[8];
    int nobj = lr_scene_object_count(s);
    for (int i = 0; i < nobj && i < 8; i++)
        objs[i] = lr_scene_object_at(s, i);
    memset(out, 0, sizeof *out);
    double n_gpu = (double)info.N * info.frames;
    for (int k = 0; k < info.K; k++) {
        lr_err e = {0};
        if (lr_renderer_debug_read_light_map(r, light, k, B, pos, nrm, obj, &e))
            fail_msg("%s", e.msg);
        for (size_t t = 0; t < S * S; t++) {
            if (obj[t] < 0)
                continue;
            lr_vec3 xo = lr_v3(pos[3 * t], pos[3 * t + 1], pos[3 * t + 2]);
            lr_vec3 no = lr_v3_normalize(lr_v3(nrm[3 * t], nrm[3 * t + 1], nrm[3 * t + 2]));
            lr_cpu_radiosity_desc d = {.N = n_cpu, .r_max = info.r_max, .others = objs,
                                       .n_others = nobj,
                                       .snap = emulate ? lr_test_snap_lookup : NULL,
                                       .snap_ctx = &g};
            lr_cpu_estimate est;
            lr_cpu_radiosity(objs[obj[t]], L, xo, no, &d,
                             lr_rng_key(4242, (uint64_t)k, t, 0), &est);
            for (int c = 0; c < 3; c++) {
                double gv = B[3 * t + c], v = est.var[c] / n_gpu + est.var[c] / n_cpu;
                assert_true(isfinite(gv) && gv >= 0.0);
                out->n++;
                out->sum_gpu += gv;
                out->sum_cpu += est.mean[c];
                out->var_sum += v;
                double dz = fabs(gv - est.mean[c]);
                if (getenv("LR_PARITY_DEBUG") && dz > 3.0 * sqrt(v) && out->over3 < 40)
                    print_message("k %d t %zu c %d: gpu %.4g cpu %.4g sd %.3g (cpu sd1 %.3g) n.h %.3f\n", k, t, c, gv, est.mean[c], sqrt(v), sqrt(est.var[c]),
                        lr_v3_dot(no, lr_v3_normalize(lr_v3_sub(L->position, xo))));
                bool o3, o4;
                if (v > 0.0) {
                    o3 = dz > 3.0 * sqrt(v);
                    o4 = dz > 4.0 * sqrt(v);
                } else {
                    o3 = o4 = dz > 1e-6 * (gv + est.mean[c]);
                }
                out->over3 += o3;
                out->over4 += o4;
                lr_vec3 hl = lr_v3_normalize(lr_v3_sub(L->position, xo));
                if (lr_v3_dot(no, hl) > 0.2) {
                    out->nf++;
                    out->over3f += o3;
                    out->over4f += o4;
                }
            }
        }
    }
    free(B);
    free(pos);
    free(nrm);
    free(obj);
}

static void compare_maps(lr_renderer *r, lr_scene *s, int n_cpu, bool emulate, parity *out)
{
    compare_light_maps(r, s, 0, n_cpu, emulate, out);
}

static void report(const char *what, const parity *p)
{
    print_message("%s: %ld texel-bands; sum GPU %.5g, CPU %.5g (%+.2f %%, aggregate sigma "
                  "%.2f %%); |z| > 3: %.2f %%, |z| > 4: %.2f %%; facing the light (%ld): "
                  "|z| > 3: %.2f %%, |z| > 4: %.2f %%\n", what, p->n, p->sum_gpu,
                  p->sum_cpu, 100 * (p->sum_gpu / p->sum_cpu - 1),
                  100 * sqrt(p->var_sum) / p->sum_cpu, 100.0 * p->over3 / p->n,
                  100.0 * p->over4 / p->n, p->nf, 100.0 * p->over3f / p->nf,
                  100.0 * p->over4f / p->nf);
}

/* The asserted part (with the G-buffer emulated): the aggregate within 4 aggregate sigma, and
 * over texels facing the light |z| > 3 in at most 2 % and |z| > 4 in at most 0.5 % of the
 * texel-bands (Gaussian: 0.27 % and 0.006 %; the allowance covers s^2 estimated from 256
 * samples, float positions and the texels at the terminator where the weights start to be
 * heavy-tailed). Measured: lampshade 0.70 % / 0.00 %, sphere 1.26 % / 0.23 %. Texels facing
 * away from the light are reported, not asserted: there the pass's weights are heavy-tailed
 * (test_cpu_radiosity's blind spot) and a sample variance does not bound the error (measured
 * |z| > 4: 0.4 % lampshade, 4.7 % sphere over all texels). Without the G-buffer emulation (the
 * CPU's exact rays, i.e. the model itself) 75 % of the lampshade's lit texel-bands are beyond
 * 4 sigma: the 256^2 G-buffer's quantisation of x_i is a real per-texel error of the GPU at
 * porcelain's scale (seed 003 Sec. 5's 'pearling'), though it averages out (+0.3 %). */
static void check_parity_at(const parity *p, double over4)
{
    assert_true(p->nf > 100);
    assert_near(p->sum_gpu, p->sum_cpu, 4.0 * sqrt(p->var_sum));
    assert_true(p->over3f <= 0.02 * p->nf);
    assert_true(p->over4f <= over4 * p->nf);
}

static void check_parity(const parity *p)
{
    check_parity_at(p, 0.005);
}

/* The maps against the twin's exact rays (no G-buffer emulation) and B at the VPLs against
 * the reference estimator are figures, never assertions (above: the model against the GPU's
 * quantised x_i; test_vpls); LR_PARITY_DEBUG=1 prints them. Left out of the default run: they
 * were half the two maps tests' time and most of test_vpls'. */
static bool exact_rays_reported(void)
{
    return getenv("LR_PARITY_DEBUG") != NULL;
}

static const char *const parity_settings[] = {
    "render.K=3", "render.N=16", "render.map_size=24", "render.gbuffer_size=256",
    "render.vpl_map_size=32", "render.N_vpl=48", "render.frames=8", NULL};

/* The GPU's maps against the twin's (G-buffer emulated), reported and checked. */
static void maps_parity(lr_renderer *r, lr_scene *s, const char *what)
{
    parity p;
    compare_maps(r, s, 256, true, &p);
    report(what, &p);
    check_parity(&p);
}

static void test_maps_lampshade(void **state)
{
    (void)state;
    /* The directional dipole (the scene ships the multipole: test_maps_lampshade_multipole). */
    static const char *const dd[] = {"objects[shade].model=directional_dipole", NULL};
    lr_scene *s = lr_test_scene("lampshade", parity_settings, dd);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 3);
    lr_test_converge(r, 20);
    parity p;
    compare_maps(r, s, 256, true, &p);
    report("lampshade maps (G-buffer emulated)", &p);
    check_parity(&p);
    if (exact_rays_reported()) {
        compare_maps(r, s, 256, false, &p);
        report("lampshade maps (exact rays)", &p);
    }
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

static void test_maps_sphere_outside_light(void **state)
{
    (void)state;
    static const char *const ball[] = {"objects[ball].material=marble", "light.position=0,0,120",
                                       NULL};
    lr_scene *s = lr_test_scene("sphere", parity_settings, ball);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 3);
    lr_test_converge(r, 20);
    parity p;
    compare_maps(r, s, 256, true, &p);
    report("sphere maps (light outside, G-buffer emulated)", &p);
    check_parity(&p);
    if (exact_rays_reported()) {
        compare_maps(r, s, 256, false, &p);
        report("sphere maps (light outside, exact rays)", &p);
    }
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* The model switch: the same sphere with the standard dipole (objects[ball].model), GPU maps
 * against the twin evaluating lr_dipole_sd; same assertions as above. The switch must also
 * reach the GPU: with the directional dipole the maps' sum differs by far more than its
 * aggregate sigma (measured against the raw directional dipole; normalised, the two differ by
 * 2 % since the standard dipole's exit factor 1 / T_hem, 11 % before). */
static void test_maps_standard_dipole(void **state)
{
    (void)state;
    static const char *const ball[] = {"objects[ball].material=marble", "light.position=0,0,120",
                                       "objects[ball].model=standard_dipole", NULL};
    lr_scene *s = lr_test_scene("sphere", parity_settings, ball);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 3);
    lr_test_converge(r, 20);
    parity p;
    compare_maps(r, s, 256, true, &p);
    report("sphere maps, standard dipole (G-buffer emulated)", &p);
    check_parity(&p);
    /* PIPELINE.md "Energy": the standard dipole's maps hold its exitance over T_hem; with
     * "normalize": false (Jensen 2001 as published) the maps re-run with the same seeds and
     * the same S_d, so every texel is T_hem times the normalised one (float rounding: each
     * texel's sum is rounded once per frame, 1e-6 relative over 20 frames is ample). */
    unsigned dirty = 0;
    lr_err e = {0};
    if (lr_scene_set(s, "objects[ball].normalize", "false", &dirty, &e))
        fail_msg("%s", e.msg);
    lr_renderer_invalidate(r, dirty);
    lr_test_converge(r, 20);
    parity raw;
    compare_maps(r, s, 256, true, &raw);
    double t_hem = lr_scene_object_at(s, 0)->coeffs.t_hem;
    assert_near(raw.sum_gpu / p.sum_gpu, t_hem, 1e-5 * t_hem);
    assert_near(raw.sum_cpu / p.sum_cpu, t_hem, 1e-9 * t_hem);
    /* Back to the directional dipole, still "normalize": false: a material-class change (maps
     * re-run). Normalised, the two models' sums now differ by about 2 % (both emit the R_d
     * total), too little to show that the switch reached the GPU; the raw directional dipole
     * ([14] as published, 1 / 0.81 of the normalised one for marble) differs by about 20 %. */
    if (lr_scene_set(s, "objects[ball].model", "directional_dipole", &dirty, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(dirty, LR_DIRTY_MATERIAL);
    lr_renderer_invalidate(r, dirty);
    lr_test_converge(r, 20);
    parity q;
    compare_maps(r, s, 256, true, &q);
    report("sphere maps, raw directional dipole", &q);
    check_parity(&q);
    print_message("standard / raw directional dipole map sum: %.4f\n", p.sum_gpu / q.sum_gpu);
    assert_true(fabs(p.sum_gpu - q.sum_gpu) > 10.0 * (sqrt(p.var_sum) + sqrt(q.var_sum)));
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* The multipole (issue 12) on the lamp shade's 1.5 mm porcelain wall: GPU maps against the twin
 * evaluating lr_multipole_sd (T across the wall, R on the same face); same assertions as the
 * directional dipole's lampshade test (configs/scenes/lampshade.json ships the multipole,
 * "thickness_mm": 1.5). The switch must reach the GPU: the multipole's map sum
 * differs from the directional dipole's (test_maps_lampshade's) by far more than sigma. */
static void test_maps_lampshade_multipole(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("lampshade", parity_settings, NULL); /* ships the multipole */
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_MULTIPOLE);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 3);
    lr_test_converge(r, 20);
    parity p;
    compare_maps(r, s, 256, true, &p);
    report("lampshade maps, multipole (G-buffer emulated)", &p);
    check_parity(&p);
    unsigned dirty = 0;
    lr_err e = {0};
    if (lr_scene_set(s, "objects[shade].model", "directional_dipole", &dirty, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(dirty, LR_DIRTY_MATERIAL);
    lr_renderer_invalidate(r, dirty);
    lr_test_converge(r, 20);
    parity q;
    compare_maps(r, s, 256, true, &q);
    print_message("multipole / directional dipole lampshade map sum: %.4f\n",
                  p.sum_gpu / q.sum_gpu);
    assert_true(fabs(p.sum_gpu - q.sum_gpu) > 10.0 * (sqrt(p.var_sum) + sqrt(q.var_sum)));
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* The votive mockup (65 mm wall quads): the scene refines it for per-vertex values, and the
 * radiosity maps draw the mesh as built (render/passes/passes.h lr_pass_objects.built) while
 * the twin evaluates the refined copy: the same surface and normal field, so the same maps. */
static void test_maps_votive_built_mesh(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("votive", parity_settings, NULL); /* ships the multipole */
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_true(o->built_mesh != o->mesh);
    assert_true(lr_mesh_triangle_count(o->mesh) > 10 * lr_mesh_triangle_count(o->built_mesh));
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 3);
    lr_test_converge(r, 20);
    maps_parity(r, s, "votive maps, multipole, maps drawn on the file's mesh");
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* VPLs: the GPU places them from a cube map of the outer surface (vpl_map_size^2 faces), the
 * CPU by exact rays along the same directions u_v = lr_halton_sphere(v + 1) from the same
 * centre. Same validity; positions within 1.5 cube texels (|x_v - c| * 2 / size * 1.5 /
 * max(|n.u|, 0.3): a texel's footprint on a tilted surface); normals within 0.05 where the
 * positions agree to a texel; areas within 10 % (the area uses n_v . u_v, interpolated at a
 * texel centre on the GPU). Measured: 0.58 texels, 9.3 %, 0.040. With LR_PARITY_DEBUG,
 * reported (not asserted): sum A_v B_v of the GPU against the reference estimator at the
 * GPU's own VPL positions -- with K = 3 maps it is +26 %, dominated by one VPL near the flame
 * that no map sees (Algorithm 1's fallback). */
static void test_vpls(void **state)
{
    (void)state;
    /* The receivers' bounce and VPL shadows (the shipped candle's) come after the VPLs and
     * change nothing here; they were most of a frame's time. */
    static const char *const vpls_only[] = {"render.receiver_bounce=false",
                                            "render.vpl_visibility=false", NULL};
    lr_scene *s = lr_test_scene("candle", parity_settings, vpls_only);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, false, 3);
    /* Positions, normals and areas come from the outer cube map, drawn at the first frame and
     * again only when the geometry changes (render/passes/vpl.c): one frame places them as the
     * converged renderer has them. Only B (the LR_PARITY_DEBUG figure) needs the 8 frames. */
    lr_test_converge(r, exact_rays_reported() ? 20 : 1);
    int n = lr_renderer_debug_vpl_count(r);
    assert_int_equal(n, 48);
    lr_debug_vpl g[48];
    lr_err e = {0};
    if (lr_renderer_debug_read_vpls(r, g, &e))
        fail_msg("%s", e.msg);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    lr_vec3 gc = lr_renderer_debug_vpl_center(r);
    assert_near(lr_v3_len(lr_v3_sub(gc, o->center)), 0.0, 1e-3);
    lr_vpl_point c[48];
    lr_vpl_place(o, 48, c);
    double worst_pos = 0, worst_area = 0, worst_n = 0;
    for (int v = 0; v < n; v++) {
        assert_int_equal(g[v].valid, c[v].valid);
        if (!c[v].valid)
            continue;
        assert_near(lr_v3_len(lr_v3_sub(g[v].u, c[v].u)), 0.0, 1e-6);
        double dist = lr_v3_len(lr_v3_sub(c[v].x, o->center));
        double cosv = fmax(fabs(lr_v3_dot(c[v].n, c[v].u)), 0.3);
        double texel = dist * 2.0 / 32 / cosv;
        double dp = lr_v3_len(lr_v3_sub(g[v].pos, c[v].x)) / texel;
        double da = fabs(g[v].area / c[v].area - 1);
        double dn = lr_v3_len(lr_v3_sub(g[v].nrm, c[v].n));
        worst_pos = fmax(worst_pos, dp);
        worst_area = fmax(worst_area, da);
        if (dp < 1.0)
            worst_n = fmax(worst_n, dn);
    }
    /* B at the VPLs: the GPU's (Algorithm 1 over its maps) against the reference estimator at
     * the GPU's own positions, weighted by area (what the receivers see). A figure, not an
     * assertion: with LR_PARITY_DEBUG only (1000 reference samples at each VPL). */
    double sg = 0, sr = 0, sv = 0, sa_g = 0, sa_c = 0;
    for (int v = 0; v < n && exact_rays_reported(); v++) {
        if (!g[v].valid)
            continue;
        lr_cpu_radiosity_desc rd = {.N = 1000, .sampler = LR_CPU_REFERENCE};
        lr_cpu_estimate est;
        lr_cpu_radiosity(o, lr_scene_light_at(s, 0), g[v].pos, lr_v3_normalize(g[v].nrm), &rd,
                         lr_rng_key(77, (uint64_t)v, 0, 0), &est);
        sg += g[v].area * g[v].B[1];
        sr += g[v].area * est.mean[1];
        sv += g[v].area * g[v].area * est.var[1] / est.n;
        sa_g += g[v].area;
        sa_c += c[v].area;
        if (getenv("LR_PARITY_DEBUG"))
            print_message("vpl %d: B gpu %.4g ref %.4g +- %.2g weight %.2f area %.4g/%.4g\n", v,
                          g[v].B[1], est.mean[1], sqrt(est.var[1] / est.n), g[v].weight,
                          g[v].area, c[v].area);
    }
    if (exact_rays_reported())
        print_message("VPLs: sum A B: GPU %.5g, reference at the GPU's positions %.5g +- %.2g "
                      "(%+.1f %%); sum A: GPU %.5g, CPU %.5g\n", sg, sr, sqrt(sv),
                      100 * (sg / sr - 1), sa_g, sa_c);
    print_message("VPLs: worst position error %.2f texels, area %.1f %%, normal %.3f\n", worst_pos,
                  100 * worst_area, worst_n);
    assert_true(worst_pos < 1.5);
    assert_true(worst_area < 0.10);
    assert_true(worst_n < 0.05);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

/* A small final image of the candle (32 x 24, K = 8): the GPU renderer against the CPU twin
 * with the same settings (its own maps and seeds). Compared per region, since per pixel both
 * carry map noise and the GPU's G-buffer and VPL cube-map quantisation. Every GPU pixel is
 * finite and >= 0. Object pixels (summed): within 4 sigma (twin's variance image, taken for
 * both) + 5 %; measured +3.1 % (sigma 3.0 %). Receivers without VPLs (direct light and the
 * candle's shadow): the same to 1e-3 (measured 0.00 %). Receivers with VPLs: within 20 %;
 * measured +3.9 % (K = 8; +4.4 % before the receiver irradiance grid, which both sides
 * share): the VPLs' B comes from Algorithm 1 over few maps at positions that differ by up
 * to 0.6 cube texels, several VPLs fall back to the nearest texel of one map, and most sit
 * on the candle's side, facing away from the flame, where the texels are heavy-tailed -- so
 * the twin's variance image understates it. */
/* recv_direct_tol: relative tolerance on the receivers without VPLs (direct light only). */
static void final_image_of(const char *scene, bool no_vpl, double recv_direct_tol)
{
    static const char *const more_maps[] = {"render.K=8", NULL};
    lr_scene *s = lr_test_scene(scene, parity_settings, more_maps);
    char label[64];
    snprintf(label, sizeof label, "final image of %s", scene);
    lr_test_final_image_vs_twin(gl, s, 32, 24, label, no_vpl, recv_direct_tol);
    lr_scene_destroy(s);
}

static void test_final_image(void **state)
{
    (void)state;
    final_image_of("candle", true, 1e-3);
    final_image_of("candle", false, 1e-3);
}

/* Two lights (configs/scenes/candle_spot.json: the flame's cube G-buffer and a side spot's 2D
 * one): each light's maps against the twin, with the assertions of the one-light cases, and
 * the final image with the one-light case's tolerances (the twin sums the lights' transport;
 * the GPU weights each light's maps, VPL row and direct light at composition). */
static void test_two_lights(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle_spot", parity_settings, NULL);
    lr_renderer *r = lr_test_renderer(gl, s, 16, 12, true, 3);
    lr_test_converge(r, 20);
    for (int l = 0; l < 2; l++) {
        parity p;
        compare_light_maps(r, s, l, 256, true, &p);
        char what[160];
        snprintf(what, sizeof what, "candle_spot maps of light %d (%s)", l,
                 lr_scene_light_at(s, l)->name);
        report(what, &p);
        /* The side spot: 4 of 591 lit texel-bands beyond 4 sigma (0.68 %), all GPU-high by
         * 40-110 % at z 4.0-4.5: the right tail of 128 GPU samples per texel that s^2 from
         * 256 CPU samples understates (the aggregate agrees, -1.2 % at sigma 1.0 %). They are
         * the spot's own: its maps are bit-identical to those of the spot alone (the seeds do
         * not depend on the light's index; test_render_lights), so 1 % is allowed there. */
        check_parity_at(&p, l == 1 ? 0.01 : 0.005);
    }
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    /* Direct light: the side spot's shadow edges come from its 2D G-buffer (256^2 over a
     * 61 degree cone: ~1.2 mm texels at the candle) where the twin casts exact shadow rays;
     * measured -0.13 % (the flame alone: 0.00 %), so 5e-3 here. */
    final_image_of("candle_spot", true, 5e-3);
    final_image_of("candle_spot", false, 5e-3);
}

int main(void)
{
    if (getenv("LR_TEST_FILTER"))
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_maps_lampshade),
        cmocka_unit_test(test_maps_sphere_outside_light),
        cmocka_unit_test(test_maps_standard_dipole),
        cmocka_unit_test(test_maps_lampshade_multipole),
        cmocka_unit_test(test_maps_votive_built_mesh),
        cmocka_unit_test(test_vpls),
        cmocka_unit_test(test_final_image),
        cmocka_unit_test(test_two_lights),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
