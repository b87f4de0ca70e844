/* Gray-code round trip: OpenCV's patterns for a 1280x720 projector (11 column bits, 10 row
 * bits: the uneven case), rendered through a known camera->projector homography into
 * simulated captures (tests/support/calib_sim.c), written as PNGs, decoded from the folder.
 * The truth for camera pixel p is the projector pixel round(H p). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "calib/capture.h"
#include "calib/cv_shim.h"
#include "calib/graycode.h"
#include "tests/support/calib_sim.h"
#include "tests/support/near.h"

#define PW 1280
#define PH 720
#define CW 320
#define CH 240

/* Camera corners -> projector points: a tilted view of a patch of the projector at about
 * 0.6 projector pixels per camera pixel (the camera resolves every projector pixel, as a
 * real rig must for full-resolution decoding). */
static void homography(double H[9])
{
    double cam[8] = {0, 0, CW - 1, 0, CW - 1, CH - 1, 0, CH - 1};
    double proj[8] = {400, 200, 600, 190, 610, 330, 395, 340};
    lr_err e = {0};
    assert_int_equal(lr_cv_find_homography(4, cam, proj, 0, H, NULL, &e), LR_OK);
}

static void apply(const double H[9], double x, double y, double *px, double *py)
{
    double w = H[6] * x + H[7] * y + H[8];
    *px = (H[0] * x + H[1] * y + H[2]) / w;
    *py = (H[3] * x + H[4] * y + H[5]) / w;
}

static bool in_shadow(int x, int y) { return x >= 40 && x < 100 && y >= 150 && y < 200; }
static bool defocused(int x, int y) { return x >= 200 && x < 260 && y >= 30 && y < 70; }

/* ss x ss samples spread over the pixel footprint (ss = 1: the centre). In the defocused
 * patch the samples spread over +-3 camera pixels instead (a lens out of focus there). */
static void build_scene(sim_scene *s, const double H[9], int ss)
{
    assert_int_equal(sim_scene_alloc(s, CW, CH, ss), 0);
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++)
            for (int k = 0; k < ss * ss; k++) {
                double spread = defocused(x, y) && ss > 1 ? 6.0 : 1.0;
                double ox = ss > 1 ? ((k % ss) + 0.5) / ss - 0.5 : 0;
                double oy = ss > 1 ? ((k / ss) + 0.5) / ss - 0.5 : 0;
                sim_sample *p = sim_at(s, x, y, k);
                double px, py;
                apply(H, x + spread * ox, y + spread * oy, &px, &py);
                p->px = in_shadow(x, y) ? NAN : (float)px;
                p->py = in_shadow(x, y) ? NAN : (float)py;
                p->albedo = 0.8f;
            }
    s->ambient = 0.05;
    s->gain = 1.0;
    s->black = 0.02;
    s->seed = 7;
}

static void test_sharp_roundtrip(void **state)
{
    (void)state;
    double H[9];
    homography(H);
    sim_scene s;
    build_scene(&s, H, 1);
    s.noise_dn = 2.0;
    char *dir = sim_tempdir("gc_sharp");
    assert_non_null(dir);
    assert_int_equal(sim_write_graycode(&s, PW, PH, dir), 0);

    lr_gc_map *m;
    lr_err e = {0};
    /* Projector size from the folder's sequence.json. */
    int rc = lr_gc_decode_dir(dir, 0, 0, NULL, NULL, &m, &e);
    if (rc)
        fail_msg("decode: %s", e.msg);
    assert_int_equal(lr_gc_map_width(m), CW);
    assert_int_equal(lr_gc_map_height(m), CH);
    /* Un-blurred pixels see exactly one projector pixel, and the pattern/inverse contrast
     * (0.8 x 0.98 x 255 = 200 DN) dwarfs the noise (2 DN, so a flip needs a 50-sigma
     * excursion): every lit pixel decodes exactly, every shadowed one is flagged. */
    long shadow = 0, exact = 0, lit = 0;
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            int px = -1, py = -1;
            int st = lr_gc_map_get(m, x, y, &px, &py);
            if (in_shadow(x, y)) {
                assert_int_equal(st, LR_GC_SHADOW);
                shadow++;
                continue;
            }
            lit++;
            double tx, ty;
            apply(H, x, y, &tx, &ty);
            if (st != LR_GC_VALID)
                fail_msg("pixel (%d,%d): status %s", x, y, lr_gc_status_name(st));
            if (px != (int)floor(tx + 0.5) || py != (int)floor(ty + 0.5))
                fail_msg("pixel (%d,%d): decoded (%d,%d), truth (%.3f,%.3f)", x, y, px, py, tx,
                         ty);
            exact++;
        }
    assert_int_equal(shadow, 60 * 50);
    assert_int_equal(exact, lit);
    assert_int_equal(lr_gc_map_count(m, LR_GC_SHADOW), 60 * 50);
    assert_int_equal(lr_gc_map_count(m, LR_GC_VALID), CW * CH - 60 * 50);

    /* Save / load the map as a 16-bit PNG: identical. */
    char path[512];
    snprintf(path, sizeof path, "%s/map.png", dir);
    assert_int_equal(lr_gc_map_save(m, path, &e), LR_OK);
    lr_gc_map *back;
    rc = lr_gc_map_load(path, PW, PH, &back, &e);
    if (rc)
        fail_msg("map load: %s", e.msg);
    for (int y = 0; y < CH; y += 3)
        for (int x = 0; x < CW; x += 3) {
            int a = -1, b = -1, c = -1, d = -1;
            assert_int_equal(lr_gc_map_get(m, x, y, &a, &b), lr_gc_map_get(back, x, y, &c, &d));
            assert_int_equal(a, c);
            assert_int_equal(b, d);
        }
    lr_gc_map_destroy(back);
    /* A map for a smaller projector than its contents is refused, naming the pixel. */
    assert_int_equal(lr_gc_map_load(path, 320, 200, &back, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "not a valid entry"));

    /* Local homographies: board-corner-like points at non-integer positions map to H p
     * within 0.05 px. Each decoded pixel carries a uniform +-0.5 px quantisation error
     * (sigma 0.29 px); a 47x47 window holds ~2200 of them, so the fitted centre is good to
     * ~0.29 / sqrt(2200) x a few = 0.01-0.02 px. 0.05 px is 3-5 times that. */
    double cam[10] = {60.3, 40.7, 160.25, 120.5, 250.8, 200.1, 300.0, 20.0, 33.3, 222.2};
    double proj[10];
    bool ok[5];
    int mapped;
    assert_int_equal(lr_gc_local_homography(m, cam, 5, NULL, proj, ok, &mapped, &e), LR_OK);
    assert_int_equal(mapped, 5);
    for (int i = 0; i < 5; i++) {
        double tx, ty;
        apply(H, cam[2 * i], cam[2 * i + 1], &tx, &ty);
        assert_true(ok[i]);
        assert_near(proj[2 * i], tx, 0.05);
        assert_near(proj[2 * i + 1], ty, 0.05);
    }
    /* A point inside the shadow has too few valid pixels in a small window: not mapped. */
    double dark[2] = {70, 175};
    lr_gc_local_params lp = {.half_window = 8};
    assert_int_equal(lr_gc_local_homography(m, dark, 1, &lp, proj, ok, &mapped, &e), LR_OK);
    assert_int_equal(mapped, 0);
    assert_false(ok[0]);
    assert_true(isnan(proj[0]));

    lr_gc_map_destroy(m);
    sim_scene_free(&s);
    sim_rmdir(dir);
    free(dir);
}

static void test_blurred_roundtrip(void **state)
{
    (void)state;
    double H[9];
    homography(H);
    sim_scene s;
    build_scene(&s, H, 4);
    s.noise_dn = 2.0;
    s.blur_sigma = 0.6;
    char *dir = sim_tempdir("gc_blur");
    assert_non_null(dir);
    assert_int_equal(sim_write_graycode(&s, PW, PH, dir), 0);
    lr_gc_map *m;
    lr_err e = {0};
    /* Contrast threshold 20 DN: a tenth of the full pattern contrast. */
    lr_gc_params params = {.contrast = 20};
    int rc = lr_gc_decode_dir(dir, PW, PH, &params, NULL, &m, &e);
    if (rc)
        fail_msg("decode: %s", e.msg);
    long valid = 0, exact = 0, off_by_one = 0, worse = 0, defocus_low = 0, defocus_n = 0;
    for (int y = 0; y < CH; y++)
        for (int x = 0; x < CW; x++) {
            int px, py;
            int st = lr_gc_map_get(m, x, y, &px, &py);
            if (in_shadow(x, y)) {
                /* Blur leaks a little light only into the shadow's outermost pixel ring. */
                if (x > 41 && x < 98 && y > 151 && y < 198)
                    assert_int_equal(st, LR_GC_SHADOW);
                continue;
            }
            if (defocused(x, y)) {
                defocus_n++;
                defocus_low += st == LR_GC_LOW_CONTRAST;
                continue;
            }
            if (st != LR_GC_VALID)
                continue;
            valid++;
            double tx, ty;
            apply(H, x, y, &tx, &ty);
            int dx = abs(px - (int)floor(tx + 0.5)), dy = abs(py - (int)floor(ty + 0.5));
            if (dx == 0 && dy == 0)
                exact++;
            else if (dx <= 1 && dy <= 1)
                off_by_one++;
            else
                worse++;
        }
    print_message("blurred: %ld valid, %ld exact, %ld off by one, %ld worse; defocused %ld/%ld "
                  "low contrast\n",
                  valid, exact, off_by_one, worse, defocus_low, defocus_n);
    /* A pixel straddling a stripe edge sees both neighbours; Gray code changes one bit
     * between neighbouring codes, so an ambiguous bit costs at most one projector pixel
     * (never a far-off code): nothing off by more than one. Most straddling pixels fail the
     * 20 DN contrast test instead: the finest stripes are 2 projector px = 3.3 camera px
     * wide, an edge smeared over ~1.5 camera px (footprint + blur) leaves |pattern - inverse|
     * under 20 DN for ~0.3 px on each side of each column and row edge, about a quarter of
     * the pixels (measured 26%). So: at least 65% valid, and of those 99% exact (measured
     * 99.9%). */
    assert_int_equal(worse, 0);
    long lit = CW * CH - 60 * 50 - 60 * 40;
    assert_true(valid > lit * 65 / 100);
    assert_true(exact > valid * 99 / 100);
    /* Defocus over +-3 camera px (+-2 projector px) washes out the finest stripes: those
     * pixels fail the contrast test instead of decoding to a wrong value. */
    assert_true(defocus_low > defocus_n * 9 / 10);
    lr_gc_map_destroy(m);
    sim_scene_free(&s);
    sim_rmdir(dir);
    free(dir);
}

static void test_sequence_files(void **state)
{
    (void)state;
    lr_err e = {0};
    int n;
    /* 1280 needs 11 bits, 720 needs 10: (11 + 10) x 2 patterns + white + black. */
    assert_int_equal(lr_gc_frame_count(PW, PH, &n, &e), LR_OK);
    assert_int_equal(n, 44);
    char name[32];
    lr_gc_frame_name(0, name, sizeof name);
    assert_string_equal(name, "white.png");
    lr_gc_frame_name(45, name, sizeof name);
    assert_string_equal(name, "pattern_43.png");

    char *dir = sim_tempdir("gc_pat");
    assert_int_equal(lr_gc_write_patterns(dir, 64, 48, NULL, &e), LR_OK);
    int pw, ph;
    assert_int_equal(lr_gc_read_sequence(dir, &pw, &ph, &e), LR_OK);
    assert_int_equal(pw, 64);
    assert_int_equal(ph, 48);
    /* The written patterns are OpenCV's: pattern_00 is the most significant column bit (the
     * right half lit), pattern_01 its inverse. */
    char path[512];
    snprintf(path, sizeof path, "%s/pattern_00.png", dir);
    lr_img img;
    assert_int_equal(lr_img_read(path, LR_IMG_GRAY8, &img, &e), LR_OK);
    const uint8_t *p = img.px;
    assert_int_equal(p[0], 0);
    assert_int_equal(p[63], 255);
    lr_img_free(&img);
    snprintf(path, sizeof path, "%s/pattern_01.png", dir);
    assert_int_equal(lr_img_read(path, LR_IMG_GRAY8, &img, &e), LR_OK);
    p = img.px;
    assert_int_equal(p[0], 255);
    assert_int_equal(p[63], 0);
    lr_img_free(&img);

    /* Decoding a folder with a capture missing names the file. */
    snprintf(path, sizeof path, "%s/pattern_05.png", dir);
    unlink(path);
    lr_gc_map *m;
    assert_int_not_equal(lr_gc_decode_dir(dir, 0, 0, NULL, NULL, &m, &e), LR_OK);
    assert_non_null(strstr(e.msg, "pattern_05.png"));
    sim_rmdir(dir);
    free(dir);
}

static int never_shown(void *ctx, int index, const lr_img *frame, const char *name, lr_err *e)
{
    (void)index;
    (void)frame;
    (void)name;
    (void)e;
    (*(int *)ctx)++;
    return LR_OK;
}

static void test_live_capture_without_camera(void **state)
{
    (void)state;
    /* No camera on this machine: the capture fails before anything is shown or written,
     * with a message naming the device. */
    char *dir = sim_tempdir("gc_live");
    char out[512];
    snprintf(out, sizeof out, "%s/pose_01", dir);
    int shown = 0;
    lr_capture_desc d = {.device = "/dev/video_lamprig_absent", .show = never_shown,
                         .show_ctx = &shown};
    lr_err e = {0};
    assert_int_equal(lr_capture_run(&d, lr_gc_run_sequence, 1280, 720, out, &e), LR_ENODEV);
    assert_non_null(strstr(e.msg, "/dev/video_lamprig_absent"));
    assert_non_null(strstr(e.msg, "no such camera device"));
    /* A device node that is not a camera (a character device V4L2 cannot open). */
    d.device = "/dev/null";
    assert_int_equal(lr_capture_run(&d, lr_gc_run_sequence, 1280, 720, out, &e), LR_ENODEV);
    assert_non_null(strstr(e.msg, "/dev/null: cannot open as a V4L2 camera"));
    /* A regular file is refused without asking OpenCV. */
    snprintf(out, sizeof out, "%s/not_a_device", dir);
    FILE *f = fopen(out, "w");
    fclose(f);
    d.device = out;
    assert_int_equal(lr_capture_run(&d, lr_gc_run_sequence, 1280, 720, dir, &e), LR_ENODEV);
    assert_non_null(strstr(e.msg, "not a V4L2 character device"));
    assert_int_equal(shown, 0);
    snprintf(out, sizeof out, "%s/pose_01", dir);
    assert_int_not_equal(access(out, F_OK), 0);
    sim_rmdir(dir);
    free(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sequence_files),
        cmocka_unit_test(test_sharp_roundtrip),
        cmocka_unit_test(test_blurred_roundtrip),
        cmocka_unit_test(test_live_capture_without_camera),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
