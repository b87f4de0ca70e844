/* Material fitting (issue 5 item 5): captures simulated from a render at known sigma through
 * the capture simulator's sensor model (calib/capture_sim.h: exposure, shot and read noise,
 * its default gamma response, 8 bits) and written as a PNG, read back as `lamprig fit` reads
 * them (lr_fit_load_captures) with a calibration folder WITHOUT camera_response.json, then
 * lr_fit_run from a start 4x off must recover the sigma (issue 10 item 4: fit used to read
 * such captures as linear, and fitted sigma_s' 100x too low); and a scene whose camera does
 * not see the object fails clearly. Also the optimiser on its own. */
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
#include <unistd.h>

#include "calib/capture_sim.h"
#include "calib/fit.h"
#include "calib/fit_captures.h"
#include "calib/fit_checks.h"
#include "calib/nelder_mead.h"
#include "calib/rig.h"
#include "render/cpu/frame.h"
#include "tests/support/cli.h"
#include "tests/support/fs.h"
#include "tests/support/near.h"

/* Rosenbrock's valley: the classic hard case for the simplex; minimum 0 at (1, 1). */
static double rosen(const double *x)
{
    return 100 * (x[1] - x[0] * x[0]) * (x[1] - x[0] * x[0]) + (1 - x[0]) * (1 - x[0]);
}

static void test_nelder_mead(void **state)
{
    (void)state;
    lr_nm nm;
    double x0[2] = {-1.2, 1}, step[2] = {0.5, 0.5}, x[2];
    lr_nm_init(&nm, 2, x0, step, 1e-12, 1e-8, 2000, 3);
    while (lr_nm_ask(&nm, x))
        lr_nm_tell(&nm, rosen(x));
    double f = lr_nm_best(&nm, x);
    /* tolerances: the stopping rule's xtol 1e-8 and the valley's conditioning (curvature
     * ratio ~ 2500 at the minimum): 1e-3 in x is loose enough for any correct simplex */
    assert_near(x[0], 1, 1e-3);
    assert_near(x[1], 1, 1e-3);
    assert_true(f < 1e-8);
    assert_true(nm.evals < 2000);
    /* +inf outside a domain is respected: minimum of (x-3)^2 on x <= 2 is at the edge */
    double y0[1] = {0}, st[1] = {1}, y[1];
    lr_nm_init(&nm, 1, y0, st, 1e-10, 1e-6, 500, 2);
    while (lr_nm_ask(&nm, y))
        lr_nm_tell(&nm, y[0] > 2 ? INFINITY : (y[0] - 3) * (y[0] - 3));
    lr_nm_best(&nm, y);
    assert_near(y[0], 2, 1e-5);
}

/* Seed 001's measurement in miniature: a narrow spot (3 deg) on the top of a thick slab,
 * seen from above. The halo's fall-off around the spot measures sigma_tr, its level the
 * albedo, so both coefficients of each band are identifiable; every pixel is the object. */
static const double TRUE_SA[3] = {0.005, 0.01, 0.02};
static const double TRUE_SS[3] = {0.5, 0.8, 1.0};
enum { W = 16, H = 16 };

static const char SLAB[] =
    "{\"name\": \"fit_slab\", \"objects\": [{\"name\": \"slab\", \"material\": {\"name\": "
    "\"start\", \"source\": \"test\", \"sigma_a\": [0.1, 0.1, 0.1], \"sigma_s_prime\": [1, 1, 1], "
    "\"eta\": 1.4}, \"mesh\": {\"type\": \"box\", \"size\": [200, 200, 60]}, "
    "\"transform\": {\"translate\": [0, 0, -30]}}], "
    "\"lights\": [{\"type\": \"spot\", \"position\": [0, 0, 100], \"direction\": [0, 0, -1], "
    "\"inner_deg\": 4, \"outer_deg\": 5, \"intensity\": 1}], "
    "\"camera\": {\"position\": [0, -1, 300], \"target\": [0, 0, 0], \"up\": [0, 1, 0], "
    "\"fov_deg\": 8}}";

static lr_scene *load_slab(const char *camera_target)
{
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_parse(SLAB, sizeof SLAB - 1, "fit_slab.json", NULL, &s, &e))
        fail_msg("scene: %s", e.msg);
    if (camera_target)
        assert_int_equal(lr_scene_set(s, "camera.position", camera_target, NULL, &e), 0);
    return s;
}

static void set_sigma(lr_scene *s, const double sa[3], const double ss[3])
{
    char v[128];
    snprintf(v, sizeof v, "%.17g,%.17g,%.17g", sa[0], sa[1], sa[2]);
    assert_int_equal(lr_scene_set(s, "objects[0].material.sigma_a", v, NULL, NULL), 0);
    snprintf(v, sizeof v, "%.17g,%.17g,%.17g", ss[0], ss[1], ss[2]);
    assert_int_equal(lr_scene_set(s, "objects[0].material.sigma_s_prime", v, NULL, NULL), 0);
}

/* The simulated capture, linearised back to radiance: the truth rendered with another seed
 * and 4x the fit's samples (so the model's and the truth's Monte Carlo noise differ, as a
 * real capture's would), captured at an exposure putting the brightest pixel at 60 % of
 * saturation with the simulator's default response (lamprig-capsim's without
 * camera_response.json), saved as an 8-bit PNG and read back as lamprig fit does with a
 * calibration folder that has no response file: the rig's one rule must read it back. */
static void simulate(lr_image *target, double *noise_rel)
{
    lr_scene *s = load_slab(NULL);
    set_sigma(s, TRUE_SA, TRUE_SS);
    lr_image L;
    lr_err e = {0};
    lr_cpu_render_desc rd = {.scene = s, .width = W, .height = H, .mode = LR_CPU_REFERENCE,
                             .samples = 512, .vpl_count = 16, .no_vpl = true, .seed = 99,
                             .threads = 2};
    if (lr_cpu_render(&rd, &L, NULL, NULL, &e))
        fail_msg("render: %s", e.msg);
    double lmax = 0;
    for (int i = 0; i < W * H * 3; i++)
        lmax = fmax(lmax, L.rgb[i]);
    assert_true(lmax > 0);
    lr_sensor sen = {.exposure_s = 1, .full_well_e = 20000, .read_noise_e = 5, .seed = 1234};
    sen.gain = 0.6 * lr_sensor_saturation(&sen, 0) / lmax;
    lr_img cap;
    if (lr_sensor_capture(&sen, &L, &cap, &e))
        fail_msg("capture: %s", e.msg);
    assert_int_equal(cap.depth, 1);
    char *dir = lr_test_tmpdir(); /* the capture and an (empty) calibration folder */
    char *png = lr_test_path(dir, "capture.png");
    if (lr_img_write(png, &cap, &e))
        fail_msg("%s", e.msg);
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    if (lr_rig_calib_load(dir, cal, &e))
        fail_msg("%s", e.msg);
    assert_false(cal->has_camresp);
    const char *paths[1] = {png};
    if (lr_fit_load_captures(paths, NULL, 1, cal, W, H, sen.gain, target, &e))
        fail_msg("captures: %s", e.msg);
    *noise_rel = lr_fit_rel_rmse(target, &L, NULL, NULL);
    lr_rig_calib_free(cal);
    free(cal);
    free(png);
    lr_test_rmtree(dir);
    lr_img_free(&cap);
    lr_image_free(&L);
    lr_scene_destroy(s);
}

static void test_fit_recovers_sigma(void **state)
{
    (void)state;
    lr_image target;
    double noise_rel;
    simulate(&target, &noise_rel);
    lr_scene *s = load_slab(NULL);
    lr_fit_desc d = {.scene = s, .object = 0, .target = &target, .mode = LR_FIT_SIGMA,
                     .samples = 128, .no_vpl = true, .seed = 1, .threads = 2,
                     .restarts = 1, .max_evals = 160};
    /* a deliberately wrong start: absorption 4x too high, scattering 4x too low */
    for (int b = 0; b < 3; b++) {
        d.sigma_a_start[b] = 4 * TRUE_SA[b];
        d.sigma_s_start[b] = TRUE_SS[b] / 4;
    }
    lr_fit_result r;
    lr_err e = {0};
    if (lr_fit_run(&d, &r, &e))
        fail_msg("fit: %s", e.msg);
    for (int b = 0; b < 3; b++)
        print_message("band %d: sigma_a %.4f (true %.4f, +-%.3f log) sigma_s' %.4f (true %.4f, "
                      "+-%.3f log) rel rmse %.4f (loss %.4f), %d iterations, %d evals\n",
                      b, r.sigma_a[b], TRUE_SA[b], r.stderr_log[b][0], r.sigma_s_prime[b],
                      TRUE_SS[b], r.stderr_log[b][1], r.rel_rmse[b], r.loss[b], r.iterations[b],
                      r.evals[b]);
    print_message("%ld pixels, start rel rmse %.3f -> %.4f (capture noise %.4f), %d renders, "
                  "%.1f s\n",
                  r.mask_pixels, r.start_rel_rmse, r.rel_rmse_all, noise_rel, r.renders,
                  r.seconds);
    /* The model at the truth, with the fit's seed and samples: its error is the noise floor
     * (the CPU reference's Monte Carlo noise per pixel at 128 samples, ~18 %, dominates the
     * capture's ~1 %). */
    /* the scene is left at the result */
    assert_near_rel(lr_scene_object_at(s, 0)->material.medium.sigma_a[1], r.sigma_a[1], 1e-12);
    set_sigma(s, TRUE_SA, TRUE_SS);
    lr_image at_truth;
    lr_cpu_render_desc rd = {.scene = s, .width = W, .height = H, .mode = LR_CPU_REFERENCE,
                             .samples = 128, .no_vpl = true, .seed = 1, .threads = 2};
    assert_int_equal(lr_cpu_render(&rd, &at_truth, NULL, NULL, NULL), 0);
    double floor_rel = lr_fit_rel_rmse(&at_truth, &target, NULL, NULL);
    print_message("noise floor (model at the truth) %.4f\n", floor_rel);
    /* A good capture passes every check of calib/fit_checks.h. */
    char why[1024];
    unsigned weak = lr_fit_check_result(LR_FIT_SIGMA, &r, why, sizeof why);
    print_message("checks: %u %s; model noise %.4f, cond %.3g %.3g %.3g\n", weak, why,
                  r.noise_rel, r.cond[0], r.cond[1], r.cond[2]);
    assert_int_equal(weak, 0);
    assert_int_equal(r.object_pixels, W * H);
    assert_int_equal(r.mask_pixels, W * H);
    lr_image_free(&at_truth);
    /* converged: from a start whose error is over three times the floor down to within 30 %
     * of the floor (the fit's objective is two other draws of the model's noise, seeds 1 and
     * 7920 at half the samples, so the full-sample render at its optimum sits above the
     * floor by about the draw-to-draw spread of the error, 10-20 % here) */
    assert_true(r.start_rel_rmse > 3 * floor_rel);
    assert_true(r.rel_rmse_all < 1.3 * floor_rel);
    /* Recovered within a factor 2 (0.7 in log) per coefficient. Derivation: the loss is flat
     * to within its own noise. Per-pixel model noise f = 18 % over the ~40 pixels of the halo,
     * where sigma_tr shows, gives an L^2 noise of f^2 sqrt(2 / 40) = 0.007, L ~ 0.085; the
     * image's relative sensitivity to log sigma along the constant-albedo ridge is ~0.25, so
     * one fit resolves about 0.085 / 0.25 = 0.34 in log (one sigma); the bound is two. This is
     * the CPU reference's noise at a test-sized budget (128 samples, 16 x 16), not the
     * optimiser: more samples shrink it as 1 / sqrt(samples) (calib/README.md, "Material
     * fitting"). The
     * reported Gauss-Newton standard errors ignore that the noise field changes with sigma
     * and come out 3-10x smaller; they are checked to be finite and positive only. */
    for (int b = 0; b < 3; b++) {
        assert_near(log(r.sigma_a[b] / TRUE_SA[b]), 0, 0.7);
        assert_near(log(r.sigma_s_prime[b] / TRUE_SS[b]), 0, 0.7);
        assert_true(r.stderr_log[b][0] > 0 && isfinite(r.stderr_log[b][0]));
        assert_true(r.stderr_log[b][1] > 0 && isfinite(r.stderr_log[b][1]));
        assert_true(r.iterations[b] > 5 && r.evals[b] <= 161);
    }
    lr_image_free(&target);
    lr_scene_destroy(s);
}

static void test_fit_no_object(void **state)
{
    (void)state;
    /* the camera looks along the slab's top, 300 mm above it: no object pixel */
    lr_scene *s = load_slab(NULL);
    assert_int_equal(lr_scene_set(s, "camera.target", "1000,0,300", NULL, NULL), 0);
    lr_image target;
    assert_int_equal(lr_image_alloc(&target, W, H, NULL), 0);
    for (int i = 0; i < W * H * 3; i++)
        target.rgb[i] = 1;
    lr_fit_desc d = {.scene = s, .target = &target, .samples = 8, .no_vpl = true};
    lr_fit_result r;
    lr_err e = {0};
    assert_int_equal(lr_fit_run(&d, &r, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "object 'slab' covers 0 pixels"));
    assert_non_null(strstr(e.msg, "no visible object"));
    /* and an object index that does not exist */
    d.object = 3;
    assert_int_equal(lr_fit_run(&d, &r, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "object 3"));
    lr_image_free(&target);
    lr_scene_destroy(s);
}

/* Captures to the fit's target: an 8-bit photo of a ramp at twice the fit's size, through a
 * gamma-2.2 camera response, box-filtered 2:1 and scaled; an exposure stack merged; bad
 * inputs named. */
static void test_fit_captures(void **state)
{
    (void)state;
    char dir[] = "/tmp/lr_fitcap_XXXXXX";
    assert_non_null(mkdtemp(dir));
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    cal->has_camresp = true;
    lr_camresp_gamma(&cal->camresp, 2.2);
    lr_img img;
    char p1[4096], p2[4096];
    const double times[2] = {1, 0.25};
    const char *paths[2] = {p1, p2};
    for (int k = 0; k < 2; k++) {
        assert_int_equal(lr_img_alloc(&img, 16, 8, 3, 1, NULL), 0);
        uint8_t *px = img.px;
        for (int y = 0; y < 8; y++)
            for (int x = 0; x < 16; x++)
                for (int c = 0; c < 3; c++)
                    px[3 * (y * 16 + x) + c] = (uint8_t)(40 + 10 * x + (k ? 0 : 5 * c));
        snprintf(k ? p2 : p1, 4096, "%s/shot%d.png", dir, k);
        assert_int_equal(lr_img_write(k ? p2 : p1, &img, NULL), 0);
        lr_img_free(&img);
    }
    lr_image t;
    lr_err e = {0};
    /* Clipped pixels: one saturated channel at (3, 5), all black at (12, 1), in the first
     * shot only (saved as shot2.png beside it). */
    assert_int_equal(lr_img_read(p1, LR_IMG_RGB8, &img, NULL), 0);
    ((uint8_t *)img.px)[3 * (5 * 16 + 3) + 1] = 252;
    memset((uint8_t *)img.px + 3 * (1 * 16 + 12), 0, 3);
    char p3[4096];
    snprintf(p3, sizeof p3, "%s/shot2.png", dir);
    assert_int_equal(lr_img_write(p3, &img, NULL), 0);
    lr_img_free(&img);
    const char *clip_paths[2] = {p3, p2};
    if (lr_fit_load_captures(clip_paths, NULL, 1, cal, 8, 4, 2.0, &t, &e))
        fail_msg("captures: %s", e.msg);
    /* exactly the fit pixels whose 2 x 2 footprint holds them are NaN (left out by the fit) */
    for (int y = 0; y < 4; y++)
        for (int x = 0; x < 8; x++) {
            bool out = (x == 1 && y == 2) || (x == 6 && y == 0);
            assert_true(isfinite(t.rgb[3 * (8 * y + x)]) == !out);
        }
    lr_image_free(&t);
    /* in a stack, a value clipped in one shot only is merged from the other */
    if (lr_fit_load_captures(clip_paths, times, 2, cal, 8, 4, 1.0, &t, &e))
        fail_msg("stack: %s", e.msg);
    for (int i = 0; i < 8 * 4 * 3; i++)
        assert_true(isfinite(t.rgb[i]));
    lr_image_free(&t);
    if (lr_fit_load_captures(paths, NULL, 1, cal, 8, 4, 2.0, &t, &e))
        fail_msg("captures: %s", e.msg);
    /* pixel (x, y) of the target averages source columns 2x and 2x+1 (rows alike):
     * (curve(z0) + curve(z1)) / 2 / scale, exact up to float storage */
    for (int x = 0; x < 8; x++)
        for (int c = 0; c < 3; c++) {
            double z0 = 40 + 20 * x + 5 * c, z1 = z0 + 10;
            double want = 0.5 * (cal->camresp.curve[c][(int)z0] + cal->camresp.curve[c][(int)z1]) / 2.0;
            assert_near_rel(t.rgb[3 * (2 * 8 + x) + c], want, 1e-5);
        }
    lr_image_free(&t);
    /* a stack: merged (Debevec's weighted mean of curve(z) / t) before the filter */
    if (lr_fit_load_captures(paths, times, 2, cal, 8, 4, 1.0, &t, &e))
        fail_msg("stack: %s", e.msg);
    assert_true(t.rgb[0] > 0 && isfinite(t.rgb[0]));
    lr_image_free(&t);
    assert_int_equal(lr_fit_load_captures(paths, NULL, 2, cal, 8, 4, 1.0, &t, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "exposure times"));
    assert_int_equal(lr_fit_load_captures(paths, NULL, 1, cal, 8, 8, 1.0, &t, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "aspect"));
    free(cal);
    unlink(p1);
    unlink(p2);
    unlink(p3);
    rmdir(dir);
}

/* ---- the CLI (release build/bin/lamprig): progress and weak fits (issue 33) ------------- */

/* dir/slab.json (the slab scene), dir/good.png (brightest pixel at 60 % of saturation) and
 * dir/clipped.png (at 100x saturation: the spot and most of its halo clipped), both at *gain. */
static void write_cli_case(const char *dir, double *gain)
{
    char path[1024];
    lr_err e = {0};
    snprintf(path, sizeof path, "%s/slab.json", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(SLAB, f);
    fclose(f);
    lr_scene *s = load_slab(NULL);
    set_sigma(s, TRUE_SA, TRUE_SS);
    lr_image L;
    lr_cpu_render_desc rd = {.scene = s, .width = W, .height = H, .mode = LR_CPU_REFERENCE,
                             .samples = 256, .no_vpl = true, .seed = 99, .threads = 2};
    if (lr_cpu_render(&rd, &L, NULL, NULL, &e))
        fail_msg("render: %s", e.msg);
    double lmax = 0;
    for (int i = 0; i < W * H * 3; i++)
        lmax = fmax(lmax, L.rgb[i]);
    lr_sensor sen = {.exposure_s = 1, .full_well_e = 20000, .read_noise_e = 5, .seed = 1234};
    *gain = 0.6 * lr_sensor_saturation(&sen, 0) / lmax;
    for (int k = 0; k < 2; k++) {
        sen.gain = *gain * (k ? 100 / 0.6 : 1);
        lr_img cap;
        if (lr_sensor_capture(&sen, &L, &cap, &e))
            fail_msg("capture: %s", e.msg);
        snprintf(path, sizeof path, "%s/%s.png", dir, k ? "clipped" : "good");
        assert_int_equal(lr_img_write(path, &cap, &e), LR_OK);
        lr_img_free(&cap);
    }
    lr_image_free(&L);
    lr_scene_destroy(s);
}

/* The "evaluations" progress lines of stderr: at least two (the first report is shown at
 * once, and a stage shown is closed at total of total), counts strictly increasing from 0
 * to a last line at N/N, N > 0. Returns how many. */
static int check_progress(const char *err)
{
    int n = 0, last = -1, done = 0, total = 0;
    for (const char *p = err; (p = strstr(p, "lamprig fit: evaluations ")); p++) {
        assert_int_equal(sscanf(p, "lamprig fit: evaluations %d/%d", &done, &total), 2);
        assert_true(done > last);
        if (n == 0)
            assert_int_equal(done, 0);
        last = done;
        n++;
    }
    assert_true(n >= 2);
    assert_int_equal(done, total);
    assert_true(done > 0 && done <= 22); /* --max-evals 20, + 2 for the step under way */
    return n;
}

/* Long commands report progress on stderr, rate-limited, and --quiet silences it
 * (issue 33 item 13). A cheap fit: 16 x 16, 16 samples, at most 20 evaluations. */
static void test_fit_cli_progress(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    double gain;
    write_cli_case(dir, &gain);
    const char *fmt = "build/bin/lamprig fit --scene %s/slab.json --captures %s/good.png "
                      "--capture-scale %.17g --size 16x16 --samples 16 --max-evals 20 "
                      "--threads 2 --no-gpu-check --out %s/m.json %s";
    int st = lr_test_run_cli(dir, fmt, dir, dir, gain, dir, "");
    char *err = lr_test_slurp(dir, "err"), *out = lr_test_slurp(dir, "out");
    print_message("%s%s", out, err);
    assert_int_equal(st, 0);
    int lines = check_progress(err);
    /* rate-limited: at most one line a second plus the closing one, never one per step */
    assert_true(lines < 20);
    free(err);
    free(out);
    st = lr_test_run_cli(dir, fmt, dir, dir, gain, dir, "--quiet");
    err = lr_test_slurp(dir, "err");
    assert_int_equal(st, 0);
    assert_null(strstr(err, "lamprig fit: evaluations"));
    assert_null(strstr(err, "uncertainty"));
    free(err);
    lr_test_rmtree(dir);
}

/* A capture that clips most of the object is refused, before the fit, with the check, its
 * figures and the exposure-stack command (exit 3, nothing written); --accept-weak writes it
 * with a warning (issue 33 item 14: such a fit used to return sigma_s' 6x off, silently). */
static void test_fit_cli_weak(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    double gain;
    write_cli_case(dir, &gain);
    const char *fmt = "build/bin/lamprig fit --scene %s/slab.json --captures %s/clipped.png "
                      "--capture-scale %.17g --size 16x16 --samples 8 --max-evals 6 "
                      "--threads 2 --no-gpu-check --quiet --out %s/m.json %s";
    int st = lr_test_run_cli(dir, fmt, dir, dir, gain, dir, "");
    char *err = lr_test_slurp(dir, "err"), *out = lr_test_slurp(dir, "out");
    print_message("%s%s", out, err);
    assert_int_equal(st, 3);
    assert_non_null(strstr(err, "weak fit refused, nothing written (exit 3)"));
    /* the clipped count the command printed is the one the check names */
    long clipped = 0, inside = 0;
    for (const char *p = out; (p = strstr(p, "lamprig fit: ")); p++)
        if (sscanf(p, "lamprig fit: %ld of the object's %ld pixels left out", &clipped,
                   &inside) == 2)
            break;
    assert_int_equal(inside, W * H);
    assert_true(2 * clipped > inside);
    char want[160];
    snprintf(want, sizeof want, "clipped: %ld of the object's %ld pixels are clipped", clipped,
             inside);
    assert_non_null(strstr(err, want));
    assert_non_null(strstr(err, "--times 1,0.25,0.0625"));
    assert_non_null(strstr(err, "clipped_4.png"));
    char mpath[1024];
    snprintf(mpath, sizeof mpath, "%s/m.json", dir);
    assert_int_equal(access(mpath, F_OK), -1);
    free(err);
    free(out);
    st = lr_test_run_cli(dir, fmt, dir, dir, gain, dir, "--accept-weak");
    err = lr_test_slurp(dir, "err");
    assert_int_equal(st, 0);
    assert_non_null(strstr(err, "warning: weak fit written (--accept-weak)"));
    assert_int_equal(access(mpath, F_OK), 0);
    free(err);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nelder_mead),
        cmocka_unit_test(test_fit_recovers_sigma),
        cmocka_unit_test(test_fit_no_object),
        cmocka_unit_test(test_fit_captures),
        cmocka_unit_test(test_fit_cli_progress),
        cmocka_unit_test(test_fit_cli_weak),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
