/* Camera intrinsics from real photographs nobody here took: OpenCV's sample chessboard
 * photos (Debian opencv-doc, left01..left14.jpg, 640x480, 9x6 inner corners, 25 mm squares
 * according to OpenCV's own result file) checked against OpenCV's result for the same photos,
 * left_intrinsics.yml (flags: 2 = CALIB_FIX_ASPECT_RATIO, aspect 1). Plus the outlier rule,
 * rejected images, and the projection/GL conventions of calib/intrinsics.c. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <glob.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "calib/camcal.h"
#include "calib/cv_shim.h"
#include "calib/intrinsics.h"
#include "tests/support/fs.h"
#include "tests/support/near.h"

#define DATA "/usr/share/doc/opencv-doc/examples/data"

/* OpenCV's result, read from the YAML with a scanner rather than typed in, so the test
 * follows the file Debian ships. */
typedef struct ref_result {
    double K[9], dist[5], avg_err;
    double view_err[13];
    int nframes;
} ref_result;

static const char *after(const char *text, const char *key)
{
    const char *p = strstr(text, key);
    return p ? p + strlen(key) : NULL;
}

static int read_data(const char *p, double *out, int n)
{
    p = p ? strstr(p, "data: [") : NULL;
    if (!p)
        return -1;
    p += strlen("data: [");
    for (int i = 0; i < n; i++) {
        char *end;
        out[i] = strtod(p, &end);
        if (end == p)
            return -1;
        p = end;
        while (*p == ',' || *p == ' ' || *p == '\n')
            p++;
    }
    return 0;
}

static void load_reference(ref_result *r)
{
    FILE *f = fopen(DATA "/left_intrinsics.yml", "r");
    if (!f)
        fail_msg(DATA "/left_intrinsics.yml missing: install Debian's opencv-doc (make deps)");
    static char text[16384];
    size_t n = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[n] = '\0';
    const char *p = after(text, "nframes:");
    assert_non_null(p);
    r->nframes = atoi(p);
    assert_int_equal(r->nframes, 13);
    assert_int_equal(read_data(after(text, "camera_matrix:"), r->K, 9), 0);
    assert_int_equal(read_data(after(text, "distortion_coefficients:"), r->dist, 5), 0);
    assert_int_equal(read_data(after(text, "per_view_reprojection_errors:"), r->view_err, 13), 0);
    p = after(text, "avg_reprojection_error:");
    assert_non_null(p);
    r->avg_err = strtod(p, NULL);
    /* The file's flags: 2 = fixed aspect ratio 1, which is what --fix-aspect does. */
    p = after(text, "flags:");
    assert_non_null(p);
    assert_int_equal(atoi(p), 2);
}

static int sample_images(glob_t *g)
{
    int rc = glob(DATA "/left[0-9]*.jpg", 0, NULL, g);
    if (rc != 0 || g->gl_pathc != 13)
        fail_msg("expected 13 photos " DATA "/left[0-9]*.jpg from opencv-doc, found %zu",
                 rc == 0 ? g->gl_pathc : 0);
    return 0;
}

static void test_opencv_sample_photos(void **state)
{
    (void)state;
    ref_result ref;
    load_reference(&ref);
    glob_t g;
    sample_images(&g);
    lr_camcal_desc d = {
        .images = (const char *const *)g.gl_pathv,
        .nimages = (int)g.gl_pathc,
        .board = {9, 6, 25.0, LR_BOARD_CHESSBOARD},
        .fix_aspect = true,
    };
    lr_camcal c;
    lr_err e = {0};
    int rc = lr_camcal_run(&d, &c, &e);
    if (rc)
        fail_msg("calibration failed: %s", e.msg);
    print_message("ours:   fx %.4f fy %.4f cx %.4f cy %.4f rms %.4f\n", c.k.fx, c.k.fy, c.k.cx,
                  c.k.cy, c.rms);
    print_message("OpenCV: fx %.4f fy %.4f cx %.4f cy %.4f avg %.4f\n", ref.K[0], ref.K[4],
                  ref.K[2], ref.K[5], ref.avg_err);
    assert_int_equal(c.nviews, 13);
    assert_int_equal(c.nrejected, 0);
    /* The brief's tolerances: 2 px on the focal length, 1.5 px on the principal point. Both
     * fits run the same algorithm on the same photos; what differs is corner refinement
     * details and OpenCV version, which move the result by well under a pixel. */
    assert_near(c.k.fx, ref.K[0], 2.0);
    assert_near(c.k.fy, ref.K[4], 2.0);
    assert_near(c.k.cx, ref.K[2], 1.5);
    assert_near(c.k.cy, ref.K[5], 1.5);
    /* --fix-aspect: fx / fy stays exactly 1. */
    assert_near(c.k.fx / c.k.fy, 1.0, 1e-12);
    assert_true(c.rms < 0.5);
    /* k1 is the dominant distortion term of this lens; same sign and close. */
    assert_near(c.k.dist[0], ref.dist[0], 0.02);

    /* Outlier rule (error > 3 x median and > 0.5 px): OpenCV's own per-view errors single out
     * one photo, left02 (1.18 px against a median of 0.19 px); ours must name it and only it. */
    int outliers = 0;
    for (int i = 0; i < c.nviews; i++) {
        if (c.views[i].outlier) {
            outliers++;
            assert_non_null(strstr(c.views[i].image, "left02.jpg"));
        }
        assert_true(c.views[i].used);
    }
    assert_int_equal(outliers, 1);
    double med = lr_camcal_median_error(&c);
    assert_true(med > 0.05 && med < 0.4);

    /* Save, reload: bit-identical numbers (shortest round-trip formatting). */
    char path[] = "/tmp/lr_camcal_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    rc = lr_camcal_save(path, &c, &e);
    if (rc)
        fail_msg("save: %s", e.msg);
    lr_camcal back;
    rc = lr_camcal_load(path, &back, &e);
    if (rc)
        fail_msg("load: %s", e.msg);
    assert_true(back.k.fx == c.k.fx && back.k.cy == c.k.cy && back.rms == c.rms);
    assert_true(back.k.dist[4] == c.k.dist[4]);
    assert_int_equal(back.nviews, 13);
    assert_true(back.views[1].error == c.views[1].error);
    assert_int_equal(back.k.width, 640);
    assert_int_equal(back.k.height, 480);
    lr_camcal_free(&back);
    unlink(path);

    /* Refit without the outlier: the RMS drops and one view is left out. */
    d.drop_outliers = true;
    lr_camcal c2;
    rc = lr_camcal_run(&d, &c2, &e);
    if (rc)
        fail_msg("refit failed: %s", e.msg);
    assert_true(c2.rms < c.rms);
    int unused = 0;
    for (int i = 0; i < c2.nviews; i++)
        unused += !c2.views[i].used;
    assert_int_equal(unused, 1);
    print_message("without left02: fx %.4f cx %.4f cy %.4f rms %.4f\n", c2.k.fx, c2.k.cx,
                  c2.k.cy, c2.rms);
    lr_camcal_free(&c2);

    /* The adaptive window (0.4 x corner spacing, at most 11) explains the outlier: left02's
     * squares are 21.7 px apart, where an 11 px half-window over-reaches. With it every view
     * fits to about 0.2 px, nothing is flagged, the RMS halves, and the focal length moves by
     * less than the spread between plausible refinement settings (measured 533.3 px; 2.7 px
     * below OpenCV's 11-px result, which left02's corners pull up). 4 px bounds that shift. */
    d.drop_outliers = false;
    d.subpix_window = LR_SUBPIX_AUTO;
    rc = lr_camcal_run(&d, &c2, &e);
    if (rc)
        fail_msg("auto-window calibration failed: %s", e.msg);
    print_message("auto window: fx %.4f cx %.4f cy %.4f rms %.4f\n", c2.k.fx, c2.k.cx,
                  c2.k.cy, c2.rms);
    assert_true(c2.rms < 0.25);
    assert_true(c2.rms < 0.6 * c.rms);
    for (int i = 0; i < c2.nviews; i++) {
        assert_false(c2.views[i].outlier);
        assert_true(c2.views[i].error < 0.3);
    }
    assert_near(c2.k.fx, ref.K[0], 4.0);
    assert_near(c2.k.cx, ref.K[2], 2.0);
    assert_near(c2.k.cy, ref.K[5], 2.0);
    lr_camcal_free(&c2);
    lr_camcal_free(&c);
    globfree(&g);
}

static void test_rejected_images(void **state)
{
    (void)state;
    /* Three good photos; a blank 640x480 frame (no board); a photo of another size (OpenCV's
     * fruits); a missing file. */
    char blank[] = "/tmp/lr_blank_XXXXXX.png";
    int fd = mkstemps(blank, 4);
    assert_true(fd >= 0);
    close(fd);
    lr_img img;
    lr_err e = {0};
    assert_int_equal(lr_img_alloc(&img, 640, 480, 1, 1, &e), LR_OK);
    memset(img.px, 128, 640 * 480);
    assert_int_equal(lr_img_write(blank, &img, &e), LR_OK);
    lr_img_free(&img);
    const char *imgs[] = {DATA "/left01.jpg", blank, DATA "/left03.jpg", DATA "/fruits.jpg",
                          "/nonexistent/x.png", DATA "/left04.jpg"};
    lr_camcal_desc d = {.images = imgs, .nimages = 6, .board = {9, 6, 25.0, LR_BOARD_CHESSBOARD}};
    lr_camcal c;
    int rc = lr_camcal_run(&d, &c, &e);
    if (rc)
        fail_msg("calibration failed: %s", e.msg);
    assert_int_equal(c.nviews, 3);
    assert_int_equal(c.nrejected, 3);
    assert_string_equal(c.rejected[0].image, blank);
    assert_non_null(strstr(c.rejected[0].reason, "9x6 chessboard not found"));
    assert_non_null(strstr(c.rejected[1].image, "fruits.jpg"));
    assert_non_null(strstr(c.rejected[1].reason, "differs from the first good view's 640x480"));
    assert_non_null(strstr(c.rejected[2].reason, "no such image"));
    lr_camcal_free(&c);

    /* Too few remain: an error naming the count and the first failure. */
    const char *few[] = {DATA "/left01.jpg", blank, DATA "/left03.jpg"};
    d.images = few;
    d.nimages = 3;
    rc = lr_camcal_run(&d, &c, &e);
    assert_int_equal(rc, LR_EINVAL);
    assert_non_null(strstr(e.msg, "2 of 3 images usable"));
    assert_non_null(strstr(e.msg, blank));
    assert_int_equal(c.nrejected, 1); /* kept for the caller to list */
    lr_camcal_free(&c);
    unlink(blank);

    /* A square chessboard is refused before any work (orientation ambiguity). */
    d.board = (lr_board){6, 6, 25.0, LR_BOARD_CHESSBOARD};
    assert_int_equal(lr_camcal_run(&d, &c, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "square one is ambiguous"));
}

static void test_projection_matches_opencv(void **state)
{
    (void)state;
    /* Our distortion model is OpenCV's: same pixels as cv::projectPoints to 1e-9 px for a
     * lens with strong distortion (the coefficients of left_intrinsics.yml) across the field. */
    lr_intrinsics k = {640, 480, 535.9, 535.9, 342.3, 235.6,
                       {-0.2664, -0.0386, 0.00178, -0.00028, 0.2384}};
    double K[9];
    lr_intrinsics_matrix(&k, K);
    double X[3 * 25], uv[2 * 25];
    for (int i = 0; i < 25; i++) {
        X[3 * i] = -0.5 + 0.25 * (i % 5);
        X[3 * i + 1] = -0.4 + 0.2 * (i / 5);
        X[3 * i + 2] = 1.0 + 0.1 * i;
    }
    double r0[3] = {0, 0, 0}, t0[3] = {0, 0, 0};
    lr_err e = {0};
    assert_int_equal(lr_cv_project_points(25, X, r0, t0, K, k.dist, uv, &e), LR_OK);
    for (int i = 0; i < 25; i++) {
        double ours[2];
        lr_intrinsics_project(&k, X + 3 * i, ours);
        assert_near(ours[0], uv[2 * i], 1e-9);
        assert_near(ours[1], uv[2 * i + 1], 1e-9);
        /* Undistortion inverts it: back to X/Z, Y/Z within 1e-9 (the iteration stops at a
         * 1e-6 px residual; 1e-9 in normalised units is 5e-7 px). */
        double xy[2];
        assert_int_equal(lr_intrinsics_undistort(&k, ours, xy, &e), LR_OK);
        assert_near(xy[0], X[3 * i] / X[3 * i + 2], 1e-9);
        assert_near(xy[1], X[3 * i + 1] / X[3 * i + 2], 1e-9);
    }
}

static void test_gl_matrices(void **state)
{
    (void)state;
    /* A projector with strong lens shift (principal point at the bottom edge): a world point
     * taken through GL view + projection + viewport lands on the pixel the pinhole model
     * gives, with NDC +y at image row 0. float matrices: 1e-3 px is float rounding at 1 m. */
    lr_intrinsics k = {1280, 720, 1500.0, 1490.0, 650.0, 715.0, {0}};
    double R[9] = {0.9950041652780258, 0, 0.09983341664682815, 0, 1, 0,
                   -0.09983341664682815, 0, 0.9950041652780258}; /* 0.1 rad about y */
    double T[3] = {-120.0, 30.0, 50.0};
    float V[16], P[16];
    lr_extrinsics_gl_view(R, T, V);
    lr_intrinsics_gl_projection(&k, 100.0, 5000.0, P);
    double pts[4][3] = {{0, 0, 800}, {150, -80, 1200}, {-200, 100, 900}, {30, 40, 3000}};
    for (int i = 0; i < 4; i++) {
        const double *Xw = pts[i];
        double Xd[3];
        for (int r = 0; r < 3; r++)
            Xd[r] = R[3 * r] * Xw[0] + R[3 * r + 1] * Xw[1] + R[3 * r + 2] * Xw[2] + T[r];
        double uv[2];
        lr_intrinsics_project(&k, Xd, uv);
        double eye[4], clip[4];
        for (int r = 0; r < 4; r++)
            eye[r] = V[r] * Xw[0] + V[4 + r] * Xw[1] + V[8 + r] * Xw[2] + V[12 + r];
        for (int r = 0; r < 4; r++)
            clip[r] = P[r] * eye[0] + P[4 + r] * eye[1] + P[8 + r] * eye[2] + P[12 + r] * eye[3];
        double nx = clip[0] / clip[3], ny = clip[1] / clip[3], nz = clip[2] / clip[3];
        double u = (nx + 1) * 0.5 * k.width - 0.5;
        double v = (1 - ny) * 0.5 * k.height - 0.5;
        assert_near(u, uv[0], 1e-3);
        assert_near(v, uv[1], 1e-3);
        assert_true(nz > -1 && nz < 1);
    }
}

/* ---- circle grids: synthetic views of a known camera ---------------------------------- */

static void rotation(const double r[3], double R[9])
{
    double th = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    double k[3] = {r[0] / th, r[1] / th, r[2] / th};
    double c = cos(th), s = sin(th), v = 1 - c;
    double m[9] = {c + k[0] * k[0] * v,        k[0] * k[1] * v - k[2] * s, k[0] * k[2] * v + k[1] * s,
                   k[1] * k[0] * v + k[2] * s, c + k[1] * k[1] * v,        k[1] * k[2] * v - k[0] * s,
                   k[2] * k[0] * v - k[1] * s, k[2] * k[1] * v + k[0] * s, c + k[2] * k[2] * v};
    memcpy(R, m, sizeof m);
}

/* Renders a white board with black dots (radius 0.3 x spacing) at the board's points, seen
 * by camera k from pose (R, T), 3x3 supersampled; writes a PNG. */
static void render_grid(const lr_intrinsics *k, const lr_board *b, const double R[9],
                        const double T[3], const double *rays, const char *path)
{
    double *pts = malloc(sizeof *pts * 3 * (size_t)lr_board_points(b));
    lr_board_object_points(b, pts);
    lr_img img;
    lr_err e = {0};
    assert_int_equal(lr_img_alloc(&img, k->width, k->height, 1, 1, &e), LR_OK);
    uint8_t *o = img.px;
    double n[3] = {R[2], R[5], R[8]}, nd = n[0] * T[0] + n[1] * T[1] + n[2] * T[2];
    double rad = 0.3 * b->square_mm;
    for (int y = 0; y < k->height; y++)
        for (int x = 0; x < k->width; x++) {
            double acc = 0;
            for (int sy = 0; sy < 3; sy++)
                for (int sx = 0; sx < 3; sx++) {
                    const double *xy = rays + 2 * (((size_t)y * (size_t)k->width + (size_t)x) * 9 +
                                                   (size_t)(sy * 3 + sx));
                    double t = nd / (n[0] * xy[0] + n[1] * xy[1] + n[2]);
                    double X[3] = {t * xy[0] - T[0], t * xy[1] - T[1], t - T[2]};
                    double u = R[0] * X[0] + R[3] * X[1] + R[6] * X[2];
                    double v = R[1] * X[0] + R[4] * X[1] + R[7] * X[2];
                    double albedo = 0.9;
                    /* Only the grid points of the two nearest rows can be within a radius. */
                    int r0 = (int)floor(v / b->square_mm);
                    for (int r = r0; r <= r0 + 1; r++) {
                        if (r < 0 || r >= b->rows)
                            continue;
                        double cu = u / b->square_mm;
                        if (b->pattern == LR_BOARD_ACIRCLES)
                            cu = (cu - r % 2) / 2;
                        int c = (int)lround(cu);
                        if (c < 0 || c >= b->cols)
                            continue;
                        const double *q = pts + 3 * (r * b->cols + c);
                        double du = u - q[0], dv = v - q[1];
                        if (du * du + dv * dv < rad * rad)
                            albedo = 0.1;
                    }
                    acc += albedo;
                }
            o[y * k->width + x] = (uint8_t)lround(255 * acc / 9);
        }
    assert_int_equal(lr_img_write(path, &img, &e), LR_OK);
    lr_img_free(&img);
    free(pts);
}

static void circles_case(const lr_board *b)
{
    /* A camera with mild barrel distortion; six board poses about half a metre away. */
    const lr_intrinsics truth = {640, 480, 600.0, 600.0, 322.0, 236.0, {-0.1, 0.05, 0, 0, 0}};
    static const double rv[6][3] = {{0.1, 0.05, 0.02}, {0.45, -0.1, 0.1}, {-0.4, 0.3, -0.05},
                                    {0.15, 0.5, 0.2},  {-0.3, -0.4, 0.1}, {0.35, 0.35, -0.3}};
    static const double tv[6][3] = {{-90, -60, 520}, {-110, -40, 540}, {-70, -80, 500},
                                    {-100, -50, 480}, {-80, -70, 560}, {-95, -55, 510}};
    /* Undistorted rays of the 3x3 samples of every pixel, shared by all views. */
    size_t nrays = (size_t)truth.width * (size_t)truth.height * 9;
    double *rays = malloc(sizeof *rays * 2 * nrays);
    assert_non_null(rays);
    lr_err e = {0};
    for (int y = 0; y < truth.height; y++)
        for (int x = 0; x < truth.width; x++)
            for (int k = 0; k < 9; k++) {
                double uv[2] = {x + (k % 3 - 1) / 3.0, y + (k / 3 - 1) / 3.0};
                size_t i = ((size_t)y * (size_t)truth.width + (size_t)x) * 9 + (size_t)k;
                assert_int_equal(lr_intrinsics_undistort(&truth, uv, rays + 2 * i, &e), LR_OK);
            }
    char dir[] = "/tmp/lr_circles_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char paths[6][64];
    const char *imgs[6];
    for (int i = 0; i < 6; i++) {
        double R[9];
        rotation(rv[i], R);
        snprintf(paths[i], sizeof paths[i], "%s/view%d.png", dir, i);
        render_grid(&truth, b, R, tv[i], rays, paths[i]);
        imgs[i] = paths[i];
    }
    free(rays);
    lr_camcal_desc d = {.images = imgs, .nimages = 6, .board = *b};
    lr_camcal c;
    int rc = lr_camcal_run(&d, &c, &e);
    if (rc)
        fail_msg("%s: %s", lr_board_pattern_name(b->pattern), e.msg);
    print_message("%s: fx %.3f fy %.3f cx %.3f cy %.3f k1 %.4f rms %.4f\n",
                  lr_board_pattern_name(b->pattern), c.k.fx, c.k.fy, c.k.cx, c.k.cy, c.k.dist[0],
                  c.rms);
    assert_int_equal(c.nviews, 6);
    /* Blob centroids of 3x3-supersampled dots are good to a few hundredths of a pixel (a
     * perspective-distorted circle's centroid is off its centre by less than that at these
     * sizes); six views pin f to about 0.1 %: 1.5 px on f, 2 px on the principal point,
     * 0.02 on k1, RMS under 0.1 px. */
    assert_near(c.k.fx, truth.fx, 1.5);
    assert_near(c.k.fy, truth.fy, 1.5);
    assert_near(c.k.cx, truth.cx, 2.0);
    assert_near(c.k.cy, truth.cy, 2.0);
    assert_near(c.k.dist[0], truth.dist[0], 0.02);
    assert_true(c.rms < 0.1);
    lr_camcal_free(&c);
    for (int i = 0; i < 6; i++)
        unlink(paths[i]);
    rmdir(dir);
}

static void test_circle_grids(void **state)
{
    (void)state;
    lr_board sym = {7, 5, 25.0, LR_BOARD_CIRCLES};
    circles_case(&sym);
    /* OpenCV's asymmetric layout: 4 points a row, rows shifted by half a period. */
    lr_board asym = {4, 9, 15.0, LR_BOARD_ACIRCLES};
    circles_case(&asym);
}

/* ---- chessboards of a known camera: order and size of the views do not matter ---------- */

/* A 9x6 chessboard (inner corners; 10x7 squares of square_mm, the first corner at the board
 * origin) on white paper, seen by the distortion-free camera k from pose (R, T), 4x4
 * supersampled; 8-bit grey PNG. */
static void render_chessboard(const lr_intrinsics *k, const lr_board *b, const double R[9],
                              const double T[3], const char *path)
{
    lr_img img;
    lr_err e = {0};
    assert_int_equal(lr_img_alloc(&img, k->width, k->height, 1, 1, &e), LR_OK);
    uint8_t *o = img.px;
    double n[3] = {R[2], R[5], R[8]}, nd = n[0] * T[0] + n[1] * T[1] + n[2] * T[2];
    double sq = b->square_mm;
    for (int y = 0; y < k->height; y++)
        for (int x = 0; x < k->width; x++) {
            double acc = 0;
            for (int s = 0; s < 16; s++) {
                /* the ray through the sample; the board plane n.X = n.T in camera space */
                double xy[2] = {(x + (s % 4 - 1.5) / 4 - k->cx) / k->fx,
                                (y + (s / 4 - 1.5) / 4 - k->cy) / k->fy};
                double t = nd / (n[0] * xy[0] + n[1] * xy[1] + n[2]);
                double X[3] = {t * xy[0] - T[0], t * xy[1] - T[1], t - T[2]};
                double u = (R[0] * X[0] + R[3] * X[1] + R[6] * X[2]) / sq;
                double v = (R[1] * X[0] + R[4] * X[1] + R[7] * X[2]) / sq;
                double albedo = 0.9;
                if (u >= -1 && u < b->cols && v >= -1 && v < b->rows &&
                    ((int)floor(u) + (int)floor(v)) % 2 == 0)
                    albedo = 0.1;
                acc += albedo;
            }
            o[y * k->width + x] = (uint8_t)lround(255 * acc / 16);
        }
    assert_int_equal(lr_img_write(path, &img, &e), LR_OK);
    lr_img_free(&img);
}

static void test_view_order_and_size(void **state)
{
    (void)state;
    /* Six views of a 640x480 pinhole camera; a blank frame of another size that comes first
     * (as a stray photo sorting first in a glob does: the bug made its size the one every
     * other view was refused against); a view WITH the board from another camera (400x300)
     * after the first good view. Wanted: the blank and the other size skipped, one entry each
     * with the reason, all six views used, whatever the order. */
    const lr_intrinsics truth = {640, 480, 620.0, 620.0, 324.0, 236.0, {0}};
    const lr_intrinsics other = {400, 300, 380.0, 380.0, 200.0, 150.0, {0}};
    const lr_board b = {9, 6, 20.0, LR_BOARD_CHESSBOARD};
    static const double rv[6][3] = {{0.1, 0.05, 0.02}, {0.45, -0.1, 0.1}, {-0.4, 0.3, -0.05},
                                    {0.15, 0.5, 0.2},  {-0.3, -0.4, 0.1}, {0.35, 0.35, -0.3}};
    static const double tv[6][3] = {{-80, -50, 430}, {-90, -40, 450}, {-70, -60, 420},
                                    {-85, -45, 400}, {-75, -55, 460}, {-80, -50, 430}};
    char *dir = lr_test_tmpdir();
    char *views[6];
    for (int i = 0; i < 6; i++) {
        char name[32];
        snprintf(name, sizeof name, "left%02d.png", i + 1);
        views[i] = lr_test_path(dir, name);
        double R[9];
        rotation(rv[i], R);
        render_chessboard(&truth, &b, R, tv[i], views[i]);
    }
    char *small = lr_test_path(dir, "left.png"), *big = lr_test_path(dir, "left03b.png");
    lr_img img;
    lr_err e = {0};
    assert_int_equal(lr_img_alloc(&img, 612, 459, 1, 1, &e), LR_OK);
    memset(img.px, 128, 612 * 459);
    assert_int_equal(lr_img_write(small, &img, &e), LR_OK);
    lr_img_free(&img);
    double R[9];
    rotation(rv[0], R);
    render_chessboard(&other, &b, R, (double[3]){-80, -50, 400}, big);

    /* glob order: left.png, left01, left02, left03, left03b, left04..06; then reversed */
    const char *order[8] = {small,    views[0], views[1], views[2],
                            big,      views[3], views[4], views[5]};
    const char *reversed[8];
    for (int i = 0; i < 8; i++)
        reversed[i] = order[7 - i];
    lr_camcal c[2];
    for (int run = 0; run < 2; run++) {
        lr_camcal_desc d = {.images = run ? reversed : order, .nimages = 8, .board = b};
        int rc = lr_camcal_run(&d, &c[run], &e);
        if (rc)
            fail_msg("run %d: %s", run, e.msg);
        print_message("run %d: fx %.3f fy %.3f cx %.3f cy %.3f k1 %.4f rms %.4f\n", run,
                      c[run].k.fx, c[run].k.fy, c[run].k.cx, c[run].k.cy, c[run].k.dist[0],
                      c[run].rms);
        assert_int_equal(c[run].nviews, 6);
        assert_int_equal(c[run].k.width, 640);
        assert_int_equal(c[run].k.height, 480);
        assert_int_equal(c[run].nrejected, 2);
        /* one entry each, naming the file and the reason, in the order given */
        const lr_camcal_reject *blank = &c[run].rejected[run ? 1 : 0];
        const lr_camcal_reject *size = &c[run].rejected[run ? 0 : 1];
        assert_string_equal(blank->image, small);
        /* first: no board; last (after the first good view): its size is checked first */
        if (run)
            assert_non_null(strstr(blank->reason, "size 612x459 differs from the first good "
                                                  "view's 640x480"));
        else
            assert_string_equal(blank->reason, "9x6 chessboard not found");
        assert_string_equal(size->image, big);
        assert_non_null(strstr(size->reason, "size 400x300 differs from the first good view's "
                                             "640x480"));
        assert_non_null(strstr(size->reason, run ? views[5] : views[0]));
        /* Corners of 4x4-supersampled edges are good to a few hundredths of a pixel; six
         * tilted views pin f to ~0.1 % (the circle grids' bounds: 1.5 px on f, 2 px on the
         * principal point) and the distortion the truth does not have to ~0.01. */
        assert_near(c[run].k.fx, truth.fx, 1.5);
        assert_near(c[run].k.fy, truth.fy, 1.5);
        assert_near(c[run].k.cx, truth.cx, 2.0);
        assert_near(c[run].k.cy, truth.cy, 2.0);
        assert_near(c[run].k.dist[0], 0.0, 0.01);
        assert_true(c[run].rms < 0.1);
    }
    /* The same views, so the same fit: the order changes only the arithmetic's order. */
    assert_near(c[1].k.fx, c[0].k.fx, 1e-3);
    assert_near(c[1].k.cx, c[0].k.cx, 1e-3);
    assert_near(c[1].rms, c[0].rms, 1e-6);
    lr_camcal_free(&c[0]);
    lr_camcal_free(&c[1]);

    /* Too few usable: the error counts them, and the skipped images are still listed for
     * the caller to show (one line each), the other-size view among them. */
    const char *few[4] = {small, views[0], big, views[1]};
    lr_camcal_desc d = {.images = few, .nimages = 4, .board = b};
    lr_camcal f;
    assert_int_equal(lr_camcal_run(&d, &f, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "2 of 4 images usable"));
    assert_int_equal(f.nviews, 0);
    assert_int_equal(f.nrejected, 2);
    assert_string_equal(f.rejected[0].image, small);
    assert_string_equal(f.rejected[1].image, big);
    lr_camcal_free(&f);

    for (int i = 0; i < 6; i++)
        free(views[i]);
    free(small);
    free(big);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_opencv_sample_photos),
        cmocka_unit_test(test_rejected_images),
        cmocka_unit_test(test_projection_matches_opencv),
        cmocka_unit_test(test_gl_matrices),
        cmocka_unit_test(test_circle_grids),
        cmocka_unit_test(test_view_order_and_size),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
