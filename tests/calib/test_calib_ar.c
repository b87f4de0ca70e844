/* Spatial AR (issue 5 item 7): the mockup's measured response (calib/albedo.h) from a
 * simulated Gray-code capture, and compensation (calib/spatial_ar.h) checked by simulating the
 * projection: projector levels -> the simulated rig (tests/support/calib_sim.h: projector
 * black, ambient, albedo, 8-bit camera with noise) -> camera. Also the projector-view
 * geometry: the warp from the symmetric render into projector pixels and the irradiance
 * factor cos(theta) / d^2. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "calib/albedo.h"
#include "calib/ar_frame.h"
#include "calib/camresp.h"
#include "calib/graycode.h"
#include "calib/pose.h"
#include "calib/procam.h"
#include "calib/spatial_ar.h"
#include "firmware/cli.h"
#include "firmware/commands/commands.h"
#include "firmware/rig/rig.h"
#include "render/base/json.h"
#include "render/base/mat4.h"
#include "tests/support/fs.h"
#include "tests/support/hal_test.h"
#include "tests/support/calib_sim.h"
#include "tests/support/near.h"

/* Camera 2:1 over the projector with ss = 1: camera pixel x sees projector position
 * (x - 0.5) / 2, which rounds to x / 2 -- every camera pixel sees exactly one projector
 * pixel, so albedo edges are not blurred by the rig and every projector pixel has 4 camera
 * pixels. */
enum { PW = 64, PH = 48, CW = 2 * PW, CH = 2 * PH };
#define WHITE_ALBEDO 0.9
#define STRIPE_ALBEDO 0.3
#define AMBIENT 0.02
#define GAIN 0.8
#define BLACK 0.02
#define NOISE_DN 1.0

static bool in_stripe(int px) { return px >= 24 && px < 34; }
static double albedo_at(int px) { return in_stripe(px) ? STRIPE_ALBEDO : WHITE_ALBEDO; }

static void build_rig(sim_scene *s)
{
    assert_int_equal(sim_scene_alloc(s, CW, CH, 1), 0);
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            sim_sample *p = sim_at(s, x, y, 0);
            p->px = (float)((x - 0.5) / 2);
            p->py = (float)((y - 0.5) / 2);
            p->albedo = (float)albedo_at(x / 2);
        }
    s->ambient = AMBIENT;
    s->gain = GAIN;
    s->black = BLACK;
    s->noise_dn = NOISE_DN;
    s->seed = 7;
}

static void to_linear(const lr_img *g, lr_image *out)
{
    assert_int_equal(lr_image_alloc(out, g->w, g->h, NULL), 0);
    const uint8_t *p = g->px;
    for (size_t i = 0; i < (size_t)g->w * g->h; i++)
        for (int c = 0; c < 3; c++)
            out->rgb[3 * i + c] = p[i] / 255.0f;
}

/* Captures a projector frame given as levels (0..1, channel 0 used: the rig is grey). */
static void capture(const sim_scene *s, const lr_image *levels, unsigned seed, double *dn)
{
    lr_img frame, cam;
    assert_int_equal(lr_img_alloc(&frame, PW, PH, 1, 1, NULL), 0);
    uint8_t *f = frame.px;
    for (int i = 0; i < PW * PH; i++) {
        double v = levels ? levels->rgb[3 * i] : 0;
        f[i] = (uint8_t)lrint(255 * (v < 0 ? 0 : v > 1 ? 1 : v));
    }
    assert_int_equal(sim_render(s, &frame, seed, &cam), 0);
    const uint8_t *c = cam.px;
    for (int i = 0; i < CW * CH; i++)
        dn[i] = c[i];
    lr_img_free(&frame);
    lr_img_free(&cam);
}

/* The measured response of the simulated mockup, through the whole chain: Gray-code
 * captures written as PNGs, decoded, white/black linearised, lr_albedo_measure. */
static void measure(sim_scene *s, lr_albedo *a)
{
    char *dir = sim_tempdir("ar_albedo");
    assert_non_null(dir);
    assert_int_equal(sim_write_graycode(s, PW, PH, dir), 0);
    lr_err e = {0};
    lr_gc_map *m;
    if (lr_gc_decode_dir(dir, 0, 0, NULL, NULL, &m, &e))
        fail_msg("decode: %s", e.msg);
    char path[4096];
    lr_img w8, b8;
    snprintf(path, sizeof path, "%s/white.png", dir);
    assert_int_equal(lr_img_read(path, LR_IMG_GRAY8, &w8, NULL), 0);
    snprintf(path, sizeof path, "%s/black.png", dir);
    assert_int_equal(lr_img_read(path, LR_IMG_GRAY8, &b8, NULL), 0);
    lr_image w, b;
    to_linear(&w8, &w);
    to_linear(&b8, &b);
    if (lr_albedo_measure(&w, &b, m, -1, a, &e))
        fail_msg("albedo: %s", e.msg);
    lr_image_free(&w);
    lr_image_free(&b);
    lr_img_free(&w8);
    lr_img_free(&b8);
    lr_gc_map_destroy(m);
    sim_rmdir(dir);
    free(dir);
}

static void test_albedo_measured(void **state)
{
    (void)state;
    sim_scene s;
    build_rig(&s);
    lr_albedo a;
    measure(&s, &a);
    assert_int_equal(a.response.width, PW);
    assert_int_equal(a.response.height, PH);
    assert_int_equal(a.measured_pixels, PW * PH);
    /* white - black = albedo * gain * (1 - black) * 255 DN, the scale its 99.5th percentile
     * (the white part): M = albedo / 0.9. Each projector pixel averages 4 camera pixels of
     * white - black, each with noise sqrt(2) x 1 DN and quantisation: sigma ~ 0.75 DN of
     * 0.9 x 0.8 x 0.98 x 255 = 180 DN, 0.4 %; 5 sigma = 2.1 % (3072 pixels: a 5-sigma
     * excursion has odds ~ 1e-3 of occurring anywhere), plus the scale's own bias: the
     * 99.5th percentile of the white pixels sits ~2.6 sigma = 1.1 % above their mean. */
    double tol = 0.03;
    for (int y = 0; y < PH; y++)
        for (int x = 0; x < PW; x++)
            for (int c = 0; c < 3; c++)
                assert_near(a.response.rgb[3 * (y * PW + x) + c], albedo_at(x) / WHITE_ALBEDO,
                            tol);
    assert_near_rel(a.scale, WHITE_ALBEDO * GAIN * (1 - BLACK), 0.02); /* 1.1 % + noise */

    /* file round trip, and a bad file refused naming it */
    char *dir = sim_tempdir("ar_file");
    char path[4096], pfm[4096];
    snprintf(path, sizeof path, "%s/albedo.json", dir);
    snprintf(pfm, sizeof pfm, "%s/albedo.pfm", dir);
    lr_err e = {0};
    if (lr_albedo_save(path, &a, &e))
        fail_msg("save: %s", e.msg);
    lr_albedo b;
    if (lr_albedo_load(path, &b, &e))
        fail_msg("load: %s", e.msg);
    assert_int_equal(b.response.width, PW);
    assert_int_equal(b.measured_pixels, a.measured_pixels);
    assert_memory_equal(b.response.rgb, a.response.rgb, sizeof(float) * PW * PH * 3);
    lr_albedo_free(&b);
    /* an image of another size than "size" */
    lr_image small;
    assert_int_equal(lr_image_alloc(&small, 8, 8, NULL), 0);
    memset(small.rgb, 0, sizeof(float) * 8 * 8 * 3);
    assert_int_equal(lr_image_write_pfm(pfm, &small, NULL), 0);
    assert_int_equal(lr_albedo_load(path, &b, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "field 'size'"));
    /* a negative value */
    a.response.rgb[5] = -1;
    assert_int_equal(lr_image_write_pfm(pfm, &a.response, NULL), 0);
    assert_int_equal(lr_albedo_load(path, &b, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "albedo.pfm: pixel (1, 0) channel 2"));
    lr_image_free(&small);
    sim_rmdir(dir);
    free(dir);
    lr_albedo_free(&a);
    sim_scene_free(&s);
}

/* The target: a glow, brightest near (40, 20) -- over the stripe's right edge -- in
 * projector pixels. */
static void make_target(lr_image *t)
{
    assert_int_equal(lr_image_alloc(t, PW, PH, NULL), 0);
    for (int y = 0; y < PH; y++)
        for (int x = 0; x < PW; x++) {
            double r2 = (x - 30.0) * (x - 30.0) + (y - 20.0) * (y - 20.0);
            double v = 0.2 + 0.8 * exp(-r2 / (2 * 15.0 * 15.0));
            for (int c = 0; c < 3; c++)
                t->rgb[3 * (y * PW + x) + c] = (float)v;
        }
}

typedef struct errs {
    double comp, uncomp, predicted_uncomp, noise_bound;
} errs;

/* Relative RMSE of the projected signal (capture - capture of black) against the signal the
 * mockup should show: WHITE_ALBEDO x gain x (1 - black) x 255 x (gain_ar T), i.e. the
 * target on a mockup of uniform white albedo, clipped at full white where it must clip. */
static errs run_case(double gain_ar, lr_ar_stats *st)
{
    sim_scene s;
    build_rig(&s);
    lr_albedo a;
    measure(&s, &a);
    lr_image t, comp, uncomp;
    make_target(&t);
    lr_ar_desc d = {.target = &t, .response = &a.response, .gain = gain_ar};
    lr_err e = {0};
    if (lr_ar_compensate(&d, &comp, st, &e))
        fail_msg("compensate: %s", e.msg);
    /* uncompensated: the target as is (the albedo taken as uniform white, M = 1) */
    lr_image ones;
    assert_int_equal(lr_image_alloc(&ones, PW, PH, NULL), 0);
    for (int i = 0; i < PW * PH * 3; i++)
        ones.rgb[i] = 1;
    d.response = &ones;
    assert_int_equal(lr_ar_compensate(&d, &uncomp, NULL, &e), 0);

    double *black = malloc(sizeof(double) * CW * CH), *cc = malloc(sizeof(double) * CW * CH),
           *cu = malloc(sizeof(double) * CW * CH);
    capture(&s, NULL, 101, black);
    capture(&s, &comp, 102, cc);
    capture(&s, &uncomp, 103, cu);
    double full = WHITE_ALBEDO * GAIN * (1 - BLACK) * 255;
    double se_c = 0, se_u = 0, se_p = 0, ss = 0;
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            int i = y * CW + x, p = (y / 2) * PW + x / 2;
            double a_rel = albedo_at(x / 2) / WHITE_ALBEDO;
            /* what the projector can reach here: l <= 1, so the mockup shows at most a_rel */
            double want = gain_ar * t.rgb[3 * p];
            double reach = fmin(want, a_rel);
            double target = full * reach;
            se_c += (cc[i] - black[i] - target) * (cc[i] - black[i] - target);
            se_u += (cu[i] - black[i] - target) * (cu[i] - black[i] - target);
            /* uncompensated shows a_rel x min(want, 1) */
            double pu = full * (a_rel * fmin(want, 1) - reach);
            se_p += pu * pu;
            ss += target * target;
        }
    errs r = {sqrt(se_c / ss), sqrt(se_u / ss), sqrt(se_p / ss), 0};
    /* Noise floor of the compensated signal, per camera pixel: camera noise 1 DN on the
     * capture and on the black capture (sqrt 2), 8-bit quantisation of both (sqrt(2/12)), the
     * projector's 8-bit levels (+-0.5/255 of full, < 0.29 DN rms), the measured M's error
     * (~0.4 %, test above) on a signal <= full: sqrt(2 + 0.17 + 0.08) + 0.004 full. */
    r.noise_bound = (sqrt(2.0 + 2.0 / 12 + 0.08) + 0.004 * full) / sqrt(ss / (CW * CH));
    free(black);
    free(cc);
    free(cu);
    lr_image_free(&t);
    lr_image_free(&comp);
    lr_image_free(&uncomp);
    lr_image_free(&ones);
    lr_albedo_free(&a);
    sim_scene_free(&s);
    return r;
}

static void test_compensation_within_reach(void **state)
{
    (void)state;
    /* gain so that the brightest target (1.0) is 0.93 x 0.3 / 0.9 of full white: reachable
     * on the dark stripe too (the measured M is within 3 %, test above), nothing clips. */
    lr_ar_stats st;
    errs r = run_case(STRIPE_ALBEDO / WHITE_ALBEDO * 0.93, &st);
    assert_int_equal(st.clipped_pixels, 0);
    assert_int_equal(st.lit_pixels, PW * PH);
    /* The uncompensated error is what the albedo contrast predicts (the stripe shows 1/3 of
     * the target), within the noise floor. */
    assert_near(r.uncomp, r.predicted_uncomp, 1.5 * r.noise_bound);
    assert_true(r.predicted_uncomp > 0.2);
    /* Compensated: down to the noise floor (1.5x: the floor's terms are rms estimates over
     * 12288 pixels, a few % each), and below the uncompensated error by the margin the
     * albedo contrast gives (the whole predicted error less twice the noise floor). */
    assert_true(r.comp < 1.5 * r.noise_bound);
    assert_true(r.comp < r.uncomp - (r.predicted_uncomp - 2 * r.noise_bound));
    print_message("within reach: compensated %.4f, uncompensated %.4f (predicted %.4f), "
                  "noise floor %.4f\n",
                  r.comp, r.uncomp, r.predicted_uncomp, r.noise_bound);
}

static void test_compensation_clips(void **state)
{
    (void)state;
    /* gain 0.8: the stripe (M = 1/3) can show at most 1/3 of full; the glow asks for up to
     * 0.8 there. Clipping must be reported exactly as the wanted light says. */
    lr_ar_stats st;
    double gain_ar = 0.8;
    errs r = run_case(gain_ar, &st);
    /* expected from the target and the true M (the measured one is within 3 %, so pixels
     * whose wanted l is within 3 % of 1 may go either way) */
    lr_image t;
    make_target(&t);
    long sure = 0, maybe = 0;
    double wanted = 0, delivered = 0;
    for (int y = 0; y < PH; y++)
        for (int x = 0; x < PW; x++) {
            double l = gain_ar * t.rgb[3 * (y * PW + x)] / (albedo_at(x) / WHITE_ALBEDO);
            sure += l > 1.03;
            maybe += l > 0.97;
            wanted += 3 * l;
            delivered += 3 * fmin(l, 1);
        }
    assert_true(sure > 0);
    assert_in_range(st.clipped_pixels, sure, maybe);
    assert_near(st.clipped_fraction, (double)st.clipped_pixels / (PW * PH), 1e-12);
    assert_near(st.clipped_light_fraction, 1 - delivered / wanted, 0.01);
    char msg[128];
    lr_ar_stats_format(&st, msg, sizeof msg);
    assert_non_null(strstr(msg, "clipped "));
    /* still better than not compensating: the error is measured against what the projector
     * can reach, so clipping costs nothing beyond the floor */
    assert_true(r.comp < 1.5 * r.noise_bound);
    assert_true(r.uncomp > r.predicted_uncomp - 1.5 * r.noise_bound);
    print_message("clipping: %s; compensated %.4f, uncompensated %.4f\n", msg, r.comp,
                  r.uncomp);
    lr_image_free(&t);
}

/* A projector with lens shift, fx != fy and distortion, at a pose looking at the origin. */
static void make_projector(lr_intrinsics *k, lr_ar_pose *p)
{
    *k = (lr_intrinsics){.width = 80, .height = 60, .fx = 110, .fy = 105, .cx = 42,
                         .cy = 52, .dist = {-0.08, 0.02, 0.001, -0.0005, 0}};
    /* centre at (0, -400, 150) looking at (0, 0, 0): forward f, image x = right, y = down */
    lr_vec3 c = lr_v3(0, -400, 150);
    lr_vec3 f = lr_v3_normalize(lr_v3_sub(lr_v3(0, 0, 0), c));
    lr_vec3 r = lr_v3_normalize(lr_v3_cross(f, lr_v3(0, 0, 1)));
    lr_vec3 d = lr_v3_cross(f, r);
    lr_vec3 rows[3] = {r, d, f};
    for (int i = 0; i < 3; i++) {
        p->R[3 * i] = rows[i].x, p->R[3 * i + 1] = rows[i].y, p->R[3 * i + 2] = rows[i].z;
        p->T[i] = -lr_v3_dot(rows[i], c);
    }
}

static void test_projector_view_warp(void **state)
{
    (void)state;
    lr_intrinsics k;
    lr_ar_pose pose;
    make_projector(&k, &pose);
    lr_camera cam;
    double aspect;
    lr_err e = {0};
    if (lr_ar_view_camera(&k, &pose, 0.02, &cam, &aspect, &e))
        fail_msg("view: %s", e.msg);
    int rw = 200, rh = (int)ceil(rw / aspect);
    float *map;
    assert_int_equal(lr_ar_warp_map(&k, &cam, rw, rh, &map, &e), 0);
    double V[16], P[16], VP[16];
    lr_camera_view(&cam, V);
    lr_camera_projection(&cam, (double)rw / rh, P);
    lr_mat4_mul(P, V, VP);
    /* A world point seen by projector pixel (u, v) (projected with the calibrated model,
     * distortion included) must land where the warp map says in the render (projected with
     * the render camera's GL matrices): tolerance 1e-3 px (float map, undistortion to 1e-9). */
    int checked = 0;
    for (int v = 0; v < k.height; v += 7)
        for (int u = 0; u < k.width; u += 9) {
            double uv[2] = {u, v}, xy[2];
            assert_int_equal(lr_intrinsics_undistort(&k, uv, xy, NULL), 0);
            double X[3] = {xy[0] * 300, xy[1] * 300, 300}; /* projector frame, 300 mm out */
            double back[2];
            lr_intrinsics_project(&k, X, back);
            assert_near(back[0], u, 1e-6);
            lr_vec3 w = lr_v3(0, 0, 0);
            for (int i = 0; i < 3; i++) { /* R^T (X - T) */
                double s = X[i] - pose.T[i];
                w.x += pose.R[3 * i] * s, w.y += pose.R[3 * i + 1] * s,
                    w.z += pose.R[3 * i + 2] * s;
            }
            lr_vec3 ndc = lr_mat4_project(VP, w);
            double col = (ndc.x + 1) * 0.5 * rw, row = (1 - ndc.y) * 0.5 * rh;
            const float *m = map + 2 * (v * k.width + u);
            assert_near(m[0], col, 1e-3);
            assert_near(m[1], row, 1e-3);
            /* inside the render */
            assert_true(col > 0 && col < rw && row > 0 && row < rh);
            checked++;
        }
    assert_true(checked > 50);
    /* lr_ar_warp samples it: a render that is its own column index comes back as the map */
    lr_image render, out;
    assert_int_equal(lr_image_alloc(&render, rw, rh, NULL), 0);
    for (int y = 0; y < rh; y++)
        for (int x = 0; x < rw; x++)
            for (int c = 0; c < 3; c++)
                render.rgb[3 * (y * rw + x) + c] = (float)(x + 0.5);
    assert_int_equal(lr_ar_warp(&render, map, k.width, k.height, &out, NULL), 0);
    for (int i = 0; i < k.width * k.height; i++)
        assert_near(out.rgb[3 * i], map[2 * i], 1e-3); /* bilinear on a linear ramp */
    lr_image_free(&render);
    lr_image_free(&out);
    free(map);
}

static void test_geometry_factor(void **state)
{
    (void)state;
    /* a 1 m wide box whose face z = -... faces the projector squarely at 500 mm */
    static const char scene_text[] =
        "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": \"box\", "
        "\"size\": [1000, 1000, 100]}, \"transform\": {\"translate\": [0, 0, -50]}}],"
        " \"lights\": [{\"type\": \"point\", \"position\": [0, 0, 100], \"intensity\": 1}],"
        " \"camera\": {\"position\": [0, -300, 300], \"target\": [0, 0, 0]}}";
    lr_scene *sc;
    lr_err e = {0};
    if (lr_scene_parse(scene_text, sizeof scene_text - 1, "box.json", NULL, &sc, &e))
        fail_msg("scene: %s", e.msg);
    /* projector 500 mm above the top face (z = 0), looking straight down, no distortion */
    lr_intrinsics k = {.width = 40, .height = 30, .fx = 50, .fy = 50, .cx = 19.5, .cy = 14.5};
    lr_ar_pose p = {.R = {1, 0, 0, 0, -1, 0, 0, 0, -1}, .T = {0, 0, 500}};
    lr_image g;
    long lit;
    double gmax;
    if (lr_ar_geometry(sc, &k, &p, &g, &lit, &gmax, &e))
        fail_msg("geometry: %s", e.msg);
    assert_int_equal(lit, 40 * 30);
    /* a plane at distance D: d = D / cos(theta), so g = cos^3(theta) / D^2, largest on the
     * axis; the normalised value is cos^3(theta) / cos^3(theta_min) (the pixels nearest the
     * principal point are half a pixel off it). Exact up to float storage. */
    double c_min = 1 / sqrt(1 + 2 * (0.5 / 50) * (0.5 / 50));
    assert_near_rel(gmax, pow(c_min, 3) / (500.0 * 500.0), 1e-9);
    for (int v = 0; v < 30; v++)
        for (int u = 0; u < 40; u++) {
            double x = (u - 19.5) / 50, y = (v - 14.5) / 50;
            double cth = 1 / sqrt(1 + x * x + y * y);
            assert_near_rel(g.rgb[3 * (v * 40 + u)], pow(cth / c_min, 3), 1e-5);
        }
    lr_image_free(&g);
    /* turned away: nothing reached is an error, not an empty map */
    lr_ar_pose away = {.R = {1, 0, 0, 0, 1, 0, 0, 0, 1}, .T = {0, 0, -500}};
    assert_int_equal(lr_ar_geometry(sc, &k, &away, &g, &lit, &gmax, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "no projector pixel reaches the mockup"));
    lr_scene_destroy(sc);
}

/* The whole frame from a calibration: the projector above a lit box, no mockup response
 * file (an ideal white mockup: the response is the geometry factor g). Each level must be
 * gain x target / g where unclipped (Eq. 1; float storage: 1e-5 relative), the scene's
 * camera must come back unchanged, and without a projector pose the error says what is
 * missing. */
static void test_ar_frame(void **state)
{
    (void)state;
    static const char scene_text[] =
        "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": \"box\", "
        "\"size\": [300, 300, 100]}, \"transform\": {\"translate\": [0, 0, -50]}}],"
        " \"lights\": [{\"type\": \"point\", \"position\": [20, 0, 30], \"intensity\": 1}],"
        " \"camera\": {\"position\": [0, -300, 300], \"target\": [0, 0, 0]}}";
    lr_scene *sc;
    lr_err e = {0};
    if (lr_scene_parse(scene_text, sizeof scene_text - 1, "box.json", NULL, &sc, &e))
        fail_msg("scene: %s", e.msg);
    lr_camera before = *lr_scene_camera(sc);
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    cal->has_procam = true;
    cal->procam.proj = (lr_intrinsics){.width = 32, .height = 24, .fx = 40, .fy = 40,
                                       .cx = 17, .cy = 11};
    lr_ar_frame_desc d = {.scene = sc, .calib = cal, .samples = 8, .no_vpl = true,
                          .threads = 2};
    lr_image levels, target;
    lr_ar_stats st;
    assert_int_equal(lr_ar_frame(&d, &levels, &target, &st, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "no projector pose"));
    cal->has_pose = true;
    cal->pose.has_projector = true;
    /* 400 mm above, looking down, image +x along scene +x */
    lr_pose p = {.R = {1, 0, 0, 0, -1, 0, 0, 0, -1}, .T = {0, 0, 400}};
    cal->pose.projector = p;
    if (lr_ar_frame(&d, &levels, &target, &st, &e))
        fail_msg("frame: %s", e.msg);
    lr_camera after = *lr_scene_camera(sc);
    assert_near(after.position.y, before.position.y, 1e-9);
    assert_near(after.fov_deg, before.fov_deg, 1e-9);
    assert_near(after.target.z, before.target.z, 1e-9);
    lr_image g;
    long lit;
    double gmax;
    lr_ar_pose ap = {.R = {1, 0, 0, 0, -1, 0, 0, 0, -1}, .T = {0, 0, 400}};
    assert_int_equal(lr_ar_geometry(sc, &cal->procam.proj, &ap, &g, &lit, &gmax, NULL), 0);
    /* the outermost projector pixels miss the 300 mm box (+-0.4 x 400 mm = 160 mm) */
    assert_int_equal(st.lit_pixels, lit);
    assert_true(lit > 32 * 24 / 2 && lit < 32 * 24);
    double tmax = 0;
    for (int i = 0; i < 32 * 24 * 3; i++)
        tmax = fmax(tmax, target.rgb[i]);
    assert_true(tmax > 0);
    assert_near_rel(st.gain, 1 / tmax, 1e-6);
    long unclipped = 0;
    for (int i = 0; i < 32 * 24 * 3; i++) {
        if (g.rgb[i] == 0) { /* off the mockup: dark */
            assert_true(levels.rgb[i] == 0);
            continue;
        }
        double want = st.gain * target.rgb[i] / g.rgb[i];
        if (want < 1) {
            assert_near(levels.rgb[i], want, 1e-5 * fmax(1, want) + 1e-7);
            unclipped++;
        } else {
            assert_near(levels.rgb[i], 1, 1e-6);
        }
    }
    assert_true(unclipped > 32 * 24);
    lr_image_free(&g);
    lr_image_free(&levels);
    lr_image_free(&target);
    free(cal);
    lr_scene_destroy(sc);
}

/* `lamprig calib albedo` on a simulated capture folder writes a file `calib check` accepts,
 * holding the same response as the library call; bad arguments exit 2, a folder without
 * captures 1. */
static void test_cli_albedo(void **state)
{
    (void)state;
    sim_scene s;
    build_rig(&s);
    char *dir = sim_tempdir("ar_cli");
    assert_int_equal(sim_write_graycode(&s, PW, PH, dir), 0);
    char out[4096], calib[4096], resp[4200];
    snprintf(out, sizeof out, "%s/albedo.json", dir);
    /* The simulated camera is linear (tests/support/calib_sim.h): say so with its response,
     * or the captures are read with the rig's default, gamma 2.2 (calib/rig.h). */
    snprintf(calib, sizeof calib, "%s/calib", dir);
    assert_int_equal(mkdir(calib, 0700), 0);
    snprintf(resp, sizeof resp, "%s/camera_response.json", calib);
    lr_camresp lin;
    lr_camresp_gamma(&lin, 1.0);
    assert_int_equal(lr_camresp_save(resp, &lin, NULL), 0);
    char *argv[] = {"calib", "albedo", "--captures", dir, "--out", out, "--calib", calib, NULL};
    assert_int_equal(lr_cmd_calib(8, argv), LR_EXIT_OK);
    char *check[] = {"calib", "check", out, NULL};
    assert_int_equal(lr_cmd_calib(3, check), LR_EXIT_OK);
    lr_albedo a;
    lr_err e = {0};
    if (lr_albedo_load(out, &a, &e))
        fail_msg("load: %s", e.msg);
    assert_int_equal(a.measured_pixels, PW * PH);
    /* the stripe, as in test_albedo_measured */
    assert_near(a.response.rgb[3 * (10 * PW + 28)], STRIPE_ALBEDO / WHITE_ALBEDO, 0.03);
    assert_near(a.response.rgb[3 * (10 * PW + 8)], 1, 0.03);
    lr_albedo_free(&a);
    char *bad[] = {"calib", "albedo", "--captures", dir, NULL};
    assert_int_equal(lr_cmd_calib(4, bad), LR_EXIT_USAGE);
    char *missing[] = {"calib", "albedo", "--captures", "/nonexistent", "--out", out, NULL};
    assert_int_equal(lr_cmd_calib(6, missing), LR_EXIT_FAIL);
    sim_rmdir(dir);
    free(dir);
    sim_scene_free(&s);
}

/* `lamprig calib ar-frame` on a calibration folder written by the calibration savers:
 * without pose.json it names what is missing (exit 1); with it, a frame and the clip report. */
/* A calibration folder for a 32 x 24 projector 400 mm above a box (pose.json only when
 * with_pose), and the box scene; returns the scene path (static buffer). */
static const char *write_ar_calib(const char *dir, bool with_pose)
{
    static char scene[4096];
    char path[4096];
    lr_err e = {0};
    lr_procam pc;
    memset(&pc, 0, sizeof pc);
    pc.cam = (lr_intrinsics){.width = 64, .height = 48, .fx = 80, .fy = 80, .cx = 32, .cy = 24};
    pc.proj = (lr_intrinsics){.width = 32, .height = 24, .fx = 40, .fy = 40, .cx = 17, .cy = 11};
    double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(pc.R, I, sizeof I);
    pc.T[0] = 100;
    pc.board = (lr_board){.cols = 9, .rows = 6, .square_mm = 25};
    pc.decode = (lr_gc_params){.contrast = 5, .shadow = 40};
    pc.local = (lr_gc_local_params){.half_window = 23, .min_points = 50, .ransac_px = 2};
    snprintf(path, sizeof path, "%s/projector.json", dir);
    if (lr_procam_save(path, &pc, &e))
        fail_msg("procam save: %s", e.msg);
    snprintf(scene, sizeof scene, "%s/box.json", dir);
    FILE *f = fopen(scene, "w");
    fputs("{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": \"box\", "
          "\"size\": [400, 400, 100]}, \"transform\": {\"translate\": [0, 0, -50]}}],"
          " \"lights\": [{\"type\": \"point\", \"position\": [20, 0, 30], \"intensity\": 1}],"
          " \"camera\": {\"position\": [0, -300, 300], \"target\": [0, 0, 0]}}",
          f);
    fclose(f);
    if (with_pose) {
        lr_rig_pose rp;
        memset(&rp, 0, sizeof rp);
        lr_pose down = {.R = {1, 0, 0, 0, -1, 0, 0, 0, -1}, .T = {0, 0, 400}};
        rp.camera = down;
        rp.camera.T[0] = -100;
        rp.has_projector = true;
        rp.projector = down;
        rp.points = 6;
        snprintf(rp.source, sizeof rp.source, "points");
        snprintf(path, sizeof path, "%s/pose.json", dir);
        if (lr_rig_pose_save(path, &rp, &e))
            fail_msg("pose save: %s", e.msg);
    }
    return scene;
}

static void test_cli_ar_frame(void **state)
{
    (void)state;
    char *dir = sim_tempdir("ar_frame");
    char out[4096], scene[4096];
    snprintf(scene, sizeof scene, "%s", write_ar_calib(dir, false));
    snprintf(out, sizeof out, "%s/levels.png", dir);
    char *argv[] = {"calib", "ar-frame", "--scene", scene, "--calib", dir, "--out", out,
                    "--samples", "4", NULL};
    assert_int_equal(lr_cmd_calib(10, argv), LR_EXIT_FAIL);
    write_ar_calib(dir, true);
    assert_int_equal(lr_cmd_calib(10, argv), LR_EXIT_OK);
    lr_img img;
    assert_int_equal(lr_img_read(out, LR_IMG_RGB8, &img, NULL), 0);
    assert_int_equal(img.w, 32);
    assert_int_equal(img.h, 24);
    lr_img_free(&img);
    char *bad[] = {"calib", "ar-frame", "--scene", scene, "--out", out, NULL};
    assert_int_equal(lr_cmd_calib(6, bad), LR_EXIT_USAGE);
    sim_rmdir(dir);
    free(dir);
}

/* `lamprig run` with "calib": a compensated projector frame at start and after each change
 * of the scene (a scripted dimmer), written to the out dir, reported in the log and in the
 * stats; a folder without the projector's pose fails the config, naming the field. */
static void test_rig_ar(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    const char *scene = write_ar_calib(dir, true);
    char text[2048];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s\", \"calib\": \"%s\", \"ar_samples\": 4,\n"
             " \"devices\": [{\"type\": \"sim\", \"text\": \"0.5 dimmer absolute 0.9\\n\"}],\n"
             " \"controls\": [{\"control\": \"dimmer\", \"param\": \"light.intensity\", "
             "\"range\": [0, 2]}],\n"
             " \"output\": {\"width\": 32, \"height\": 24, \"fps\": 50, \"renderer\": "
             "\"preview\"}}\n",
             scene, dir);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    char *stats = lr_test_path(dir, "stats.json");
    char *frames = lr_test_path(dir, "frames");
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .stats_path = stats, .out_dir = frames, .headless = true,
                     .duration_s = 1.2, .no_signals = true, .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_rig_run(r, &e), LR_OK);
    lr_rig_destroy(r);
    /* the start (the first frame, well before the dimmer at 0.5 s) and the dimmer change:
     * two frames, each logged with its clip report */
    assert_int_equal(lr_test_log_count(&log, "spatial AR frame"), 2);
    assert_int_equal(lr_test_log_count(&log, "% of the light"), 2);
    char path[4096];
    for (int i = 0; i < 2; i++) {
        snprintf(path, sizeof path, "%s/ar_%06d.png", frames, i);
        lr_img img;
        assert_int_equal(lr_img_read(path, LR_IMG_RGB8, &img, NULL), 0);
        assert_int_equal(img.w, 32);
        lr_img_free(&img);
    }
    lr_json *j = NULL;
    if (lr_json_load(stats, &j, &e))
        fail_msg("%s", e.msg);
    lr_jnode ar = lr_json_get(j, lr_json_root(j), "ar");
    assert_int_not_equal(ar, LR_JNONE);
    long ar_frames = 0;
    assert_int_equal(lr_json_get_int(j, ar, "frames", true, &ar_frames, &e), LR_OK);
    assert_int_equal(ar_frames, 2);
    lr_json_destroy(j);
    /* without pose.json */
    snprintf(path, sizeof path, "%s/pose.json", dir);
    assert_int_equal(unlink(path), 0);
    assert_int_not_equal(lr_rig_create(&o, &r, &e), LR_OK);
    assert_non_null(strstr(e.msg, "field 'calib'"));
    assert_non_null(strstr(e.msg, "pose.json"));
    free(cfg);
    free(stats);
    free(frames);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_albedo_measured),
        cmocka_unit_test(test_compensation_within_reach),
        cmocka_unit_test(test_compensation_clips),
        cmocka_unit_test(test_projector_view_warp),
        cmocka_unit_test(test_geometry_factor),
        cmocka_unit_test(test_cli_albedo),
        cmocka_unit_test(test_ar_frame),
        cmocka_unit_test(test_cli_ar_frame),
        cmocka_unit_test(test_rig_ar),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
