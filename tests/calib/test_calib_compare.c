/* Comparison runs (calib/compare.h, `lamprig compare`): CIEDE2000 against Sharma, Wu and
 * Dalal 2005's test data; the lcms2 Lab transform's white point; SSIM = 1, dE = 0 and
 * relative RMSE = 0 for identical images; boundary erosion; a simulated capture of the same
 * render compares with the error its injected noise predicts, and a capture of another
 * material (marble for candle_wax) with clearly larger error; the CLI writes a report and
 * refuses bad inputs (size mismatch, missing calibration) with clear messages. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "calib/camcal.h"
#include "calib/camview.h"
#include "calib/capture_sim.h"
#include "calib/compare.h"
#include "calib/pose.h"
#include "calib/view_render.h"
#include "firmware/commands/commands.h"
#include "render/base/file.h"
#include "render/base/json.h"
#include "render/scene/scene.h"
#include "tests/support/calib_sim.h"
#include "tests/support/cli.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"

/* Sharma, Wu, Dalal, "The CIEDE2000 color-difference formula: implementation notes,
 * supplementary test data, and mathematical observations", Color Res. Appl. 30(1), 2005,
 * Table 1: pairs 1, 2, 3, 7, 17 and 25 (hue wrap, grey axis, large difference). */
static void test_ciede2000_sharma(void **state)
{
    (void)state;
    static const double rows[][7] = {
        {50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425},
        {50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615},
        {50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412},
        {50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669},
        {50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492},
        {60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        /* The table gives 4 decimals: 1e-4 is its rounding (5e-5) with float slack. */
        assert_near(lr_ciede2000(rows[i], rows[i] + 3), rows[i][6], 1e-4);
        assert_near(lr_ciede2000(rows[i] + 3, rows[i]), rows[i][6], 1e-4); /* symmetric */
    }
}

/* Linear sRGB white maps to L* = 100, a* = b* = 0 (relative colorimetric, D65 adapted to
 * D50); black to 0; mid grey 0.18 to L* = 116 * 0.18^(1/3) - 16 = 49.50. lcms2's float
 * pipeline is exact to ~1e-4 here; 1e-2 leaves room for its adaptation matrix rounding. */
static void test_lab_transform(void **state)
{
    (void)state;
    lr_lab_xform *x;
    lr_err e = {0};
    assert_int_equal(lr_lab_xform_create(&x, &e), LR_OK);
    double rgb[9] = {1, 1, 1, 0, 0, 0, 0.18, 0.18, 0.18}, lab[9];
    lr_lab_xform_apply(x, rgb, lab, 3);
    assert_near(lab[0], 100, 1e-2);
    assert_near(lab[1], 0, 1e-2);
    assert_near(lab[2], 0, 1e-2);
    assert_near(lab[3], 0, 1e-2);
    assert_near(lab[6], 116 * cbrt(0.18) - 16, 1e-2);
    assert_near(lab[7], 0, 1e-2);
    lr_lab_xform_destroy(x);
}

/* A w x h test image with structure (SSIM of a flat image is trivially 1). */
static void pattern(lr_image *img, int w, int h, double gain)
{
    lr_err e = {0};
    assert_int_equal(lr_image_alloc(img, w, h, &e), LR_OK);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++)
                img->rgb[3 * (y * w + x) + c] =
                    (float)(gain * (0.2 + 0.15 * sin(0.3 * x + c) * cos(0.21 * y) + 0.01 * c));
}

/* Labels: an object square in the middle, receivers elsewhere, background in the top rows. */
static uint8_t *labels_for(int w, int h)
{
    uint8_t *l = malloc((size_t)w * h);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            l[y * w + x] = y < 5 ? LR_LABEL_BACKGROUND
                           : (x >= 20 && x < 40 && y >= 15 && y < 35) ? LR_LABEL_OBJECT
                                                                      : LR_LABEL_RECEIVER;
    return l;
}

static void test_identical_images(void **state)
{
    (void)state;
    const int W = 64, H = 48;
    lr_image a, b;
    pattern(&a, W, H, 1e-3);
    pattern(&b, W, H, 1e-3);
    uint8_t *labels = labels_for(W, H);
    lr_compare_result r;
    lr_err e = {0};
    float *demap = malloc(W * H * sizeof *demap);
    lr_compare_desc d = {.render = &a, .capture = &b, .labels = labels};
    assert_int_equal(lr_compare_run(&d, &r, demap, &e), LR_OK);
    for (int g = 0; g < LR_REGION_COUNT; g++) {
        assert_true(r.region[g].pixels > 0);
        assert_near(r.region[g].rel_rmse, 0, 0);
        assert_near(r.region[g].rmse, 0, 0);
        assert_near(r.region[g].ssim, 1, 1e-6); /* float accumulation of the local moments */
        assert_near(r.region[g].delta_e, 0, 1e-9);
    }
    /* Erosion by one pixel: the object square 20 x 20 keeps 18 x 18. Receivers lose the
     * ring around the object (22 x 22 - 20 x 20 = 84), the image border and the row next to
     * the background. */
    assert_int_equal(r.region[LR_REGION_OBJECT].pixels, 18 * 18);
    long recv = (long)(W - 2) * (H - 5 - 2) - 22 * 22;
    assert_int_equal(r.region[LR_REGION_RECEIVERS].pixels, recv);
    assert_int_equal(r.region[LR_REGION_ALL].pixels, 18 * 18 + recv);
    assert_true(isnan(demap[0])); /* background is not compared */

    /* A 10 % brighter capture: relative RMSE exactly 0.1 (every channel scaled by 1.1). */
    for (int i = 0; i < W * H * 3; i++)
        b.rgb[i] = a.rgb[i] * 1.1f;
    assert_int_equal(lr_compare_run(&d, &r, NULL, &e), LR_OK);
    assert_near(r.region[LR_REGION_ALL].rel_rmse, 0.1, 1e-6);
    /* rmse = 0.1 x the RMS of the render's values over the compared pixels. */
    {
        double ss = 0;
        long m = 0;
        for (int y = 1; y < H - 1; y++)
            for (int x = 1; x < W - 1; x++) {
                bool in = true;
                for (int dy = -1; dy <= 1; dy++)
                    for (int dx = -1; dx <= 1; dx++)
                        in = in && labels[(y + dy) * W + x + dx] == labels[y * W + x];
                if (!in || labels[y * W + x] == LR_LABEL_BACKGROUND)
                    continue;
                for (int c = 0; c < 3; c++)
                    ss += (double)a.rgb[3 * (y * W + x) + c] * a.rgb[3 * (y * W + x) + c];
                m++;
            }
        assert_int_equal(m, r.region[LR_REGION_ALL].pixels);
        assert_near_rel(r.region[LR_REGION_ALL].rmse, 0.1 * sqrt(ss / (3.0 * m)), 1e-5);
    }
    assert_true(r.region[LR_REGION_ALL].delta_e > 0.5);
    assert_true(r.region[LR_REGION_ALL].ssim < 1.0);

    /* Size mismatch is an error naming both sizes. */
    lr_image c;
    pattern(&c, W, H - 1, 1e-3);
    d.capture = &c;
    assert_int_equal(lr_compare_run(&d, &r, NULL, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "64x48"));
    assert_non_null(strstr(e.msg, "64x47"));
    /* Everything excluded: an error, not NaN metrics. */
    uint8_t *ex = malloc(W * H);
    memset(ex, 1, W * H);
    d.capture = &b;
    d.exclude = ex;
    assert_int_equal(lr_compare_run(&d, &r, NULL, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "no pixel"));
    free(ex);
    lr_image_free(&c);
    free(demap);
    free(labels);
    lr_image_free(&a);
    lr_image_free(&b);
}

/* ---- with a scene ------------------------------------------------------------------------ */

#define CW 96
#define CH 72

/* The candle scene's own camera as a calibrated camera: 96 x 72, fy from its 35 degree field,
 * an off-centre principal point and mild barrel distortion. */
static void candle_camera(lr_intrinsics *k, lr_pose *p)
{
    double fy = 0.5 * CH / tan(17.5 * M_PI / 180);
    *k = (lr_intrinsics){.width = CW, .height = CH, .fx = fy, .fy = fy, .cx = 48.5, .cy = 35.0,
                         .dist = {-0.05, 0.01, 0, 0, 0}};
    double C[3] = {0, -450, 230}, T[3] = {0, 40, 70}, f[3], r[3], d[3];
    double n = 0;
    for (int i = 0; i < 3; i++)
        f[i] = T[i] - C[i], n += f[i] * f[i];
    for (int i = 0; i < 3; i++)
        f[i] /= sqrt(n);
    r[0] = f[1], r[1] = -f[0], r[2] = 0; /* f x (0,0,1) */
    n = sqrt(r[0] * r[0] + r[1] * r[1]);
    r[0] /= n, r[1] /= n;
    d[0] = f[1] * r[2] - f[2] * r[1], d[1] = f[2] * r[0] - f[0] * r[2],
    d[2] = f[0] * r[1] - f[1] * r[0];
    for (int i = 0; i < 3; i++)
        p->R[i] = r[i], p->R[3 + i] = d[i], p->R[6 + i] = f[i];
    for (int i = 0; i < 3; i++)
        p->T[i] = -(p->R[3 * i] * C[0] + p->R[3 * i + 1] * C[1] + p->R[3 * i + 2] * C[2]);
}

static const char *const small_settings[4][2] = {
    {"render.K", "4"}, {"render.N", "4"}, {"render.map_size", "64"}, {"render.N_vpl", "16"}};

static lr_image render_candle(const char *material, const lr_camview *v, uint8_t *labels)
{
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_load(LR_SOURCE_CONFIGS "/scenes/candle.json", NULL, &s, &e))
        fail_msg("%s", e.msg);
    if (material && lr_scene_set(s, "objects[0].material", material, NULL, &e))
        fail_msg("%s", e.msg);
    /* Small maps keep the CPU twin at a few seconds under ASan; the comparison does not
     * care how converged the render is, only that capture and render agree. */
    for (int i = 0; i < 4; i++)
        if (lr_scene_set(s, small_settings[i][0], small_settings[i][1], NULL, &e))
            fail_msg("%s", e.msg);
    lr_image img;
    /* CPU twin, 2 frames: deterministic for a seed, so the same call gives the same image. */
    lr_view_render_desc d = {.scene = s, .view = v, .cpu = true, .frames = 2, .threads = 2};
    if (lr_view_render(&d, &img, NULL, &e))
        fail_msg("%s", e.msg);
    if (labels && lr_camview_labels(v, s, labels, &e))
        fail_msg("%s", e.msg);
    lr_scene_destroy(s);
    return img;
}

static double sensor_gain(void)
{
    lr_scene *s;
    lr_err e = {0};
    assert_int_equal(lr_scene_load(LR_SOURCE_CONFIGS "/scenes/candle.json", NULL, &s, &e), 0);
    double g = lr_scene_render(s)->exposure;
    lr_scene_destroy(s);
    return g;
}

/* The same render, captured through the sensor model with noise and linearised back: the
 * relative RMSE must match the noise the sensor injected. Per channel value with exposure
 * X = g t L (gamma 2.2 response, X_sat = (255/128)^2.2, full well FW, read noise r):
 *   var(X) = (X_sat / FW)^2 (e + r^2) + (dX/dz)^2 / 12,   e = X FW / X_sat,
 *   dX/dz = 2.2 X / z   (quantisation of z = 255 (X ref)^(1/2.2), half-step uniform),
 * so the expected rel RMSE is sqrt(sum var(X) / sum X^2) over the compared pixels. The
 * measured one is an average over thousands of values; +-25 % covers its sampling spread
 * and the rounding of the uniform-quantisation model near z ~ 10. A capture of marble instead of
 * candle_wax must be at least 3x worse and have a larger mean dE. */
static void test_simulated_capture(void **state)
{
    (void)state;
    lr_intrinsics k;
    lr_pose pose;
    candle_camera(&k, &pose);
    lr_camview *v;
    lr_err e = {0};
    assert_int_equal(lr_camview_create(&k, &pose, 0, &v, &e), LR_OK);
    uint8_t *labels = malloc(CW * CH);
    lr_image wax = render_candle(NULL, v, labels);
    long nobj = 0, nrec = 0;
    for (int i = 0; i < CW * CH; i++)
        nobj += labels[i] == LR_LABEL_OBJECT, nrec += labels[i] == LR_LABEL_RECEIVER;
    assert_true(nobj > 100 && nrec > 1000);

    double gain = sensor_gain(), t = 4.0; /* brighter than default: the table is dim */
    lr_sensor s = {.exposure_s = t, .gain = gain, .full_well_e = 20000, .read_noise_e = 5,
                   .seed = 11};
    lr_img cap;
    assert_int_equal(lr_sensor_capture(&s, &wax, &cap, &e), LR_OK);
    lr_rig_calib *rig = calloc(1, sizeof *rig); /* no response / colour files: gamma 2.2 */
    lr_image lin;
    uint8_t *ex = malloc(CW * CH);
    assert_int_equal(lr_compare_linearise(rig, &cap, &t, 1, gain, &lin, &e), LR_OK);
    assert_int_equal(lr_compare_capture_mask(&cap, 1, 0, 0, ex, &e), LR_OK);
    lr_compare_desc d = {.render = &wax, .capture = &lin, .labels = labels, .exclude = ex};
    lr_compare_result same;
    assert_int_equal(lr_compare_run(&d, &same, NULL, &e), LR_OK);

    /* The prediction over the same pixels (ALL region: interior, not excluded). */
    double sat = lr_sensor_saturation(&s, 0), num = 0, den = 0;
    for (int y = 1; y < CH - 1; y++)
        for (int x = 1; x < CW - 1; x++) {
            int i = y * CW + x;
            bool keep = !ex[i] && (labels[i] == LR_LABEL_OBJECT || labels[i] == LR_LABEL_RECEIVER);
            for (int dy = -1; dy <= 1 && keep; dy++)
                for (int dx = -1; dx <= 1; dx++)
                    keep = keep && labels[(y + dy) * CW + x + dx] == labels[i];
            if (!keep)
                continue;
            for (int c = 0; c < 3; c++) {
                double X = gain * t * wax.rgb[3 * i + c];
                double el = X / sat * s.full_well_e;
                double z = lr_sensor_encode(&s, c, X);
                double dq = z > 0.5 ? 2.2 * X / z : 0;
                double var = (sat / s.full_well_e) * (sat / s.full_well_e) * (el + 25.0) +
                             dq * dq / 12;
                num += var / (gain * t) / (gain * t);
                den += wax.rgb[3 * i + c] * wax.rgb[3 * i + c];
            }
        }
    double predicted = sqrt(num / den);
    double measured = same.region[LR_REGION_ALL].rel_rmse;
    printf("same material: rel RMSE %.4f (predicted %.4f), SSIM %.4f, dE %.3f; excluded %ld\n",
           measured, predicted, same.region[LR_REGION_ALL].ssim,
           same.region[LR_REGION_ALL].delta_e, same.excluded);
    assert_true(measured > 0.75 * predicted && measured < 1.25 * predicted);

    /* An exposure stack (1, 4, 16 s) merged to HDR collects more light where the single
     * 4 s capture is shot-noise and quantisation limited (the dim table), and keeps the
     * highlights from the short exposure: its error must be lower. */
    {
        double times[3] = {1, 4, 16};
        lr_img stack[3];
        for (int i = 0; i < 3; i++) {
            lr_sensor si = s;
            si.exposure_s = times[i];
            si.seed = 100 + (uint64_t)i;
            assert_int_equal(lr_sensor_capture(&si, &wax, &stack[i], &e), LR_OK);
        }
        lr_image hdr;
        uint8_t *ex3 = malloc(CW * CH);
        assert_int_equal(lr_compare_linearise(rig, stack, times, 3, gain, &hdr, &e), LR_OK);
        assert_int_equal(lr_compare_capture_mask(stack, 3, 0, 0, ex3, &e), LR_OK);
        lr_compare_desc d3 = {.render = &wax, .capture = &hdr, .labels = labels, .exclude = ex3};
        lr_compare_result r3;
        assert_int_equal(lr_compare_run(&d3, &r3, NULL, &e), LR_OK);
        printf("exposure stack 1/4/16 s: rel RMSE %.4f, dE %.3f, excluded %ld\n",
               r3.region[LR_REGION_ALL].rel_rmse, r3.region[LR_REGION_ALL].delta_e, r3.excluded);
        assert_true(r3.region[LR_REGION_ALL].rel_rmse < measured);
        assert_true(r3.excluded <= same.excluded);
        free(ex3);
        lr_image_free(&hdr);
        for (int i = 0; i < 3; i++)
            lr_img_free(&stack[i]);
    }

    /* Marble: a different material seen through the same sensor. */
    lr_image marble = render_candle("marble", v, NULL);
    lr_img cap2;
    lr_image lin2;
    assert_int_equal(lr_sensor_capture(&s, &marble, &cap2, &e), LR_OK);
    assert_int_equal(lr_compare_linearise(rig, &cap2, &t, 1, gain, &lin2, &e), LR_OK);
    assert_int_equal(lr_compare_capture_mask(&cap2, 1, 0, 0, ex, &e), LR_OK);
    d.capture = &lin2;
    lr_compare_result other;
    assert_int_equal(lr_compare_run(&d, &other, NULL, &e), LR_OK);
    printf("marble vs candle_wax: object rel RMSE %.4f, SSIM %.4f, dE %.3f (same: %.4f, %.4f, "
           "%.3f)\n",
           other.region[LR_REGION_OBJECT].rel_rmse, other.region[LR_REGION_OBJECT].ssim,
           other.region[LR_REGION_OBJECT].delta_e, same.region[LR_REGION_OBJECT].rel_rmse,
           same.region[LR_REGION_OBJECT].ssim, same.region[LR_REGION_OBJECT].delta_e);
    assert_true(other.region[LR_REGION_OBJECT].rel_rmse >
                3 * same.region[LR_REGION_OBJECT].rel_rmse);
    assert_true(other.region[LR_REGION_OBJECT].delta_e > same.region[LR_REGION_OBJECT].delta_e);

    lr_image_free(&lin2);
    lr_img_free(&cap2);
    lr_image_free(&marble);
    lr_image_free(&lin);
    lr_img_free(&cap);
    free(ex);
    free(rig);
    lr_image_free(&wax);
    free(labels);
    lr_camview_destroy(v);
}

/* The GPU renderer's view (EGL surfaceless) against the CPU twin's through the same camera
 * view: the two estimate the same model with different sample streams, so per-pixel values
 * differ by Monte Carlo noise, but the images must line up. Correlation of luminance over the
 * image > 0.9 (measured ~0.99); the GPU image flipped upside down (a row-order bug) correlates
 * far less, which the second assertion checks the test can see. */
static void test_gpu_view_matches_cpu(void **state)
{
    (void)state;
    lr_intrinsics k;
    lr_pose pose;
    candle_camera(&k, &pose);
    lr_camview *v;
    lr_err e = {0};
    assert_int_equal(lr_camview_create(&k, &pose, 0, &v, &e), LR_OK);
    /* Load and pin the GL driver first: lr_view_render opens and closes its own context,
     * and Mesa unloads the driver at the end, which would hide its leaks from lsan.supp. */
    lr_gl *gl;
    if (lr_test_gl_create(&gl))
        fail_msg("no GL context");
    lr_gl_destroy(gl);
    lr_image cpu = render_candle(NULL, v, NULL);
    lr_scene *s;
    if (lr_scene_load(LR_SOURCE_CONFIGS "/scenes/candle.json", NULL, &s, &e))
        fail_msg("%s", e.msg);
    for (int i = 0; i < 4; i++)
        if (lr_scene_set(s, small_settings[i][0], small_settings[i][1], NULL, &e))
            fail_msg("%s", e.msg);
    lr_image gpu;
    double secs = -1;
    lr_view_render_desc d = {.scene = s, .view = v, .frames = 2};
    if (lr_view_render(&d, &gpu, &secs, &e))
        fail_msg("%s", e.msg);
    assert_true(secs >= 0);
    assert_int_equal(gpu.width, CW);
    assert_int_equal(gpu.height, CH);
    double corr[2];
    for (int flip = 0; flip < 2; flip++) {
        double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
        int n = CW * CH;
        for (int y = 0; y < CH; y++)
            for (int x = 0; x < CW; x++) {
                int ya = flip ? CH - 1 - y : y;
                const float *p = cpu.rgb + 3 * (y * CW + x), *q = gpu.rgb + 3 * (ya * CW + x);
                double a = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                double b = 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
                sa += a, sb += b, saa += a * a, sbb += b * b, sab += a * b;
            }
        double ca = saa / n - (sa / n) * (sa / n), cb = sbb / n - (sb / n) * (sb / n);
        corr[flip] = (sab / n - sa / n * sb / n) / sqrt(ca * cb);
    }
    printf("GPU vs CPU twin view: correlation %.4f (flipped %.4f), GPU render %.2f s\n", corr[0],
           corr[1], secs);
    assert_true(corr[0] > 0.9);
    assert_true(corr[1] < corr[0] - 0.1);
    lr_image_free(&gpu);
    lr_image_free(&cpu);
    lr_scene_destroy(s);
    lr_camview_destroy(v);
}

/* ---- the CLI ------------------------------------------------------------------------------ */

static int run_compare(const char *const *args, int n)
{
    char *argv[32];
    argv[0] = "compare";
    for (int i = 0; i < n; i++)
        argv[i + 1] = (char *)args[i];
    return lr_cmd_compare(n + 1, argv);
}

static void write_rig(const char *dir, const lr_intrinsics *k, const lr_pose *pose)
{
    char path[640];
    lr_err e = {0};
    lr_camcal cc;
    memset(&cc, 0, sizeof cc);
    cc.k = *k;
    cc.rms = 0.1;
    cc.board = (lr_board){9, 6, 25, LR_BOARD_CHESSBOARD};
    cc.subpix_window = 11;
    snprintf(path, sizeof path, "%s/camera.json", dir);
    if (lr_camcal_save(path, &cc, &e))
        fail_msg("%s", e.msg);
    lr_rig_pose p;
    memset(&p, 0, sizeof p);
    p.camera = *pose;
    p.rms = 0.1;
    p.points = 8;
    snprintf(p.source, sizeof p.source, "points");
    snprintf(path, sizeof path, "%s/pose.json", dir);
    if (lr_rig_pose_save(path, &p, &e))
        fail_msg("%s", e.msg);
}

static void test_cli(void **state)
{
    (void)state;
    lr_intrinsics k;
    lr_pose pose;
    candle_camera(&k, &pose);
    char *dir = sim_tempdir("compare");
    char rigdir[512], capture[512], small[512], report[512], heat[512];
    snprintf(rigdir, sizeof rigdir, "%s/rig", dir);
    assert_int_equal(mkdir(rigdir, 0755), 0);
    write_rig(rigdir, &k, &pose);
    snprintf(capture, sizeof capture, "%s/cap.png", dir);
    snprintf(small, sizeof small, "%s/small.png", dir);
    snprintf(report, sizeof report, "%s/report.json", dir);
    snprintf(heat, sizeof heat, "%s/heat.png", dir);
    /* The capture: the same CPU twin render (seed 1, 2 frames, small maps) through the sensor. */
    lr_camview *v;
    lr_err e = {0};
    assert_int_equal(lr_camview_create(&k, &pose, 0, &v, &e), LR_OK);
    lr_image wax = render_candle(NULL, v, NULL);
    lr_sensor s = {.exposure_s = 4, .gain = sensor_gain(), .full_well_e = 20000,
                   .read_noise_e = 5, .seed = 3};
    lr_img cap, tiny;
    assert_int_equal(lr_sensor_capture(&s, &wax, &cap, &e), LR_OK);
    assert_int_equal(lr_img_write(capture, &cap, &e), LR_OK);
    assert_int_equal(lr_img_alloc(&tiny, 40, 30, 3, 1, &e), LR_OK);
    assert_int_equal(lr_img_write(small, &tiny, &e), LR_OK);

    const char *ok[] = {"--scene", LR_SOURCE_CONFIGS "/scenes/candle.json", "--calib", rigdir,
                        "--capture", capture, "--times", "4", "--report", report,
                        "--heatmap", heat, "--cpu", "--frames", "2",
                        "--set", "render.K=4", "--set", "render.N=4", "--set",
                        "render.map_size=64", "--set", "render.N_vpl=16"};
    assert_int_equal(run_compare(ok, 23), 0);
    /* lamprig-capsim (release build) through the same rig: its render reports progress on
     * stderr (the CPU twin's stages, counts rising to total of total), --quiet silences it
     * (issue 33 item 13: an 844 s capture said nothing). */
    for (int quiet = 0; quiet < 2; quiet++) {
        int cst = lr_test_run_cli(dir,
                                  "build/bin/lamprig-capsim --scene %s/scenes/candle.json "
                                  "--calib %s --out %s/sim.png --cpu --frames 2 --set render.K=4 "
                                  "--set render.N=4 --set render.map_size=64 --set "
                                  "render.N_vpl=16 %s",
                                  LR_SOURCE_CONFIGS, rigdir, dir, quiet ? "--quiet" : "");
        char *err = lr_test_slurp(dir, "err");
        if (cst != 0)
            fail_msg("lamprig-capsim: exit %d: %s", cst, err);
        if (quiet) {
            assert_int_equal(strlen(err), 0);
        } else {
            printf("%s", err);
            int n = 0, last = -1, done = 0, total = 0;
            for (const char *p = err; (p = strstr(p, "lamprig-capsim: cpu maps ")); p++, n++) {
                assert_int_equal(sscanf(p, "lamprig-capsim: cpu maps %d/%d", &done, &total), 2);
                assert_true(done > last);
                last = done;
            }
            assert_true(n >= 2); /* the first report and the one closing the stage */
            assert_int_equal(done, total);
            assert_int_equal(total, 1); /* one object, one light */
        }
        free(err);
    }
    char *text;
    size_t len;
    assert_int_equal(lr_file_read(report, LR_FILE_MAX_TEXT, &text, &len, &e), LR_OK);
    assert_non_null(strstr(text, "\"kind\": \"comparison\""));
    assert_non_null(strstr(text, "\"rel_rmse\""));
    assert_non_null(strstr(text, "\"render_s\""));
    free(text);
    /* The heatmap: the image plus a 90 px colour bar and a 28 px title strip; the image's
     * border pixels are never compared (1 px boundary rule), so they are grey (0.5 -> 128). */
    lr_img hm;
    assert_int_equal(lr_img_read(heat, LR_IMG_RGB8, &hm, &e), LR_OK);
    assert_int_equal(hm.w, CW + 90);
    assert_int_equal(hm.h, CH + 28);
    const uint8_t *corner = (const uint8_t *)hm.px + 3 * (28 * hm.w + 0);
    assert_int_equal(corner[0], 128);
    assert_int_equal(corner[1], 128);
    assert_int_equal(corner[2], 128);
    lr_img_free(&hm);

    /* A vignetted capture (cos^4 with the calibrated focal length, ~25 % fall-off in the
     * corners): compared as is, the fall-off is error; with --vignette cos4 it is divided out
     * and the error returns to the sensor noise of the unvignetted capture (within 25 %, as
     * in test_simulated_capture: the darker corners collect fewer electrons). */
    {
        char vcap[600], vrep[600], vrep2[600];
        snprintf(vcap, sizeof vcap, "%s/vcap.png", dir);
        snprintf(vrep, sizeof vrep, "%s/vrep.json", dir);
        snprintf(vrep2, sizeof vrep2, "%s/vrep2.json", dir);
        lr_sensor sv = s;
        sv.vignette = LR_VIGNETTE_COS4;
        sv.focal_px = sqrt(k.fx * k.fy);
        sv.cx = k.cx;
        sv.cy = k.cy;
        lr_img vc;
        assert_int_equal(lr_sensor_capture(&sv, &wax, &vc, &e), LR_OK);
        assert_int_equal(lr_img_write(vcap, &vc, &e), LR_OK);
        lr_img_free(&vc);
        const char *plain[] = {"--scene", LR_SOURCE_CONFIGS "/scenes/candle.json", "--calib",
                               rigdir, "--capture", vcap, "--times", "4", "--report", vrep,
                               "--cpu", "--frames", "2", "--set", "render.K=4", "--set",
                               "render.N=4", "--set", "render.map_size=64", "--set",
                               "render.N_vpl=16", "--vignette", "cos4"};
        assert_int_equal(run_compare(plain, 21), 0); /* without --vignette */
        plain[9] = vrep2;
        assert_int_equal(run_compare(plain, 23), 0); /* with --vignette cos4 */
        double rel[3];
        const char *reps[3] = {report, vrep, vrep2};
        for (int i = 0; i < 3; i++) {
            lr_json *j;
            lr_err je = {0};
            assert_int_equal(lr_file_read(reps[i], LR_FILE_MAX_TEXT, &text, &len, &e), LR_OK);
            assert_int_equal(lr_json_parse(text, len, reps[i], &j, &je), LR_OK);
            lr_jnode all = lr_json_get(j, lr_json_get(j, lr_json_root(j), "regions"), "all");
            assert_int_equal(lr_json_get_number(j, all, "rel_rmse", true, &rel[i], &je), LR_OK);
            lr_json_destroy(j);
            free(text);
        }
        printf("vignetted capture: rel RMSE %.4f as is, %.4f divided out (plain capture %.4f)\n",
               rel[1], rel[2], rel[0]);
        assert_true(rel[1] > 2 * rel[0]);
        assert_true(rel[2] < 1.25 * rel[0]);
    }

    /* A capture of the wrong size: exit 1, message naming both sizes. */
    const char *bad_size[] = {"--scene", LR_SOURCE_CONFIGS "/scenes/candle.json", "--calib",
                              rigdir, "--capture", small, "--report", report, "--cpu"};
    assert_int_equal(run_compare(bad_size, 9), 1);
    /* No calibration folder / no pose: exit 1. */
    const char *no_calib[] = {"--scene", LR_SOURCE_CONFIGS "/scenes/candle.json", "--calib",
                              "/nonexistent/rig", "--capture", capture, "--report", report};
    assert_int_equal(run_compare(no_calib, 8), 1);
    char posefile[600];
    snprintf(posefile, sizeof posefile, "%s/pose.json", rigdir);
    assert_int_equal(unlink(posefile), 0);
    assert_int_equal(run_compare(no_calib + 0, 2), 2); /* missing --calib etc.: usage */
    const char *no_pose[] = {"--scene", LR_SOURCE_CONFIGS "/scenes/candle.json", "--calib",
                             rigdir, "--capture", capture, "--report", report};
    assert_int_equal(run_compare(no_pose, 8), 1);
    /* A stack without --times is a usage error. */
    const char *stack[] = {"--scene", "x.json", "--calib", rigdir, "--capture", capture, capture,
                           "--report", report};
    assert_int_equal(run_compare(stack, 9), 2);

    lr_img_free(&tiny);
    lr_img_free(&cap);
    lr_image_free(&wax);
    lr_camview_destroy(v);
    sim_rmdir(dir);
    free(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ciede2000_sharma),
        cmocka_unit_test(test_lab_transform),
        cmocka_unit_test(test_identical_images),
        cmocka_unit_test(test_simulated_capture),
        cmocka_unit_test(test_gpu_view_matches_cpu),
        cmocka_unit_test(test_cli),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
