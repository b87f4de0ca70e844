/* Image files: PFM bit-exact round trips and byte layout, PNG tone mapping and 8-bit sRGB
 * round trips, rejection of truncated and corrupt files with the file named, atomic writes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/image/image.h"
#include "tests/support/fs.h"

static int setup(void **state)
{
    *state = lr_test_tmpdir();
    return 0;
}

static int teardown(void **state)
{
    lr_test_rmtree(*state);
    return 0;
}

/* A 5x3 image (odd, non-square: row and column mix-ups show) with distinct values. */
static lr_image ramp(void)
{
    lr_image img;
    assert_int_equal(lr_image_alloc(&img, 5, 3, NULL), LR_OK);
    for (int i = 0; i < 5 * 3 * 3; i++)
        img.rgb[i] = (float)i * 0.37f - 3.0f;
    return img;
}

static int dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *de; (de = readdir(d)) != NULL;)
        n += de->d_name[0] != '.';
    closedir(d);
    return n;
}

/* ---- PFM -------------------------------------------------------------------------------- */

static void pfm_round_trip_is_bit_exact(void **state)
{
    char *path = lr_test_path(*state, "a.pfm");
    lr_image img = ramp();
    /* Values the HDR scan must see as they are: NaN, infinities, -0, a denormal, FLT_MAX. */
    img.rgb[0] = NAN;
    img.rgb[1] = INFINITY;
    img.rgb[2] = -INFINITY;
    img.rgb[3] = -0.0f;
    img.rgb[4] = 1e-40f;
    img.rgb[5] = 3.4028235e38f;
    lr_err e = {0};
    if (lr_image_write_pfm(path, &img, &e))
        fail_msg("%s", e.msg);
    lr_image back = {0};
    if (lr_image_read_pfm(path, &back, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(back.width, 5);
    assert_int_equal(back.height, 3);
    assert_memory_equal(back.rgb, img.rgb, 5 * 3 * 3 * sizeof(float));
    lr_image_free(&back);
    lr_image_free(&img);
    free(path);
}

static void pfm_layout_is_little_endian_bottom_up(void **state)
{
    char *path = lr_test_path(*state, "layout.pfm");
    lr_image img = ramp();
    assert_int_equal(lr_image_write_pfm(path, &img, NULL), LR_OK);
    size_t n;
    unsigned char *d = lr_test_read(path, &n);
    const char header[] = "PF\n5 3\n-1.0\n";
    size_t h = sizeof header - 1;
    assert_int_equal(n, h + 5 * 3 * 3 * 4);
    assert_memory_equal(d, header, h);
    /* The first stored pixel is the bottom-left one: row 2 of the top-down image. */
    float first = img.rgb[2 * 5 * 3];
    uint32_t u;
    memcpy(&u, &first, 4);
    const unsigned char le[4] = {(unsigned char)u, (unsigned char)(u >> 8), (unsigned char)(u >> 16),
                                 (unsigned char)(u >> 24)};
    assert_memory_equal(d + h, le, 4);
    /* The last stored float is the top-right pixel's blue. */
    memcpy(&u, &img.rgb[4 * 3 + 2], 4);
    const unsigned char le2[4] = {(unsigned char)u, (unsigned char)(u >> 8), (unsigned char)(u >> 16),
                                  (unsigned char)(u >> 24)};
    assert_memory_equal(d + n - 4, le2, 4);
    free(d);
    lr_image_free(&img);
    free(path);
}

static void pfm_reads_big_endian_and_grey(void **state)
{
    /* 2x1 big-endian colour (positive scale), and 1x2 little-endian greyscale "Pf". */
    unsigned char be[] = "PF\n2 1\n1.0\n"
                         "\x3f\x80\x00\x00" "\x40\x00\x00\x00" "\x40\x40\x00\x00"
                         "\xbf\x00\x00\x00" "\x00\x00\x00\x00" "\x42\xc8\x00\x00";
    char *p = lr_test_write(*state, "be.pfm", be, sizeof be - 1);
    lr_image img = {0};
    lr_err e = {0};
    if (lr_image_read_pfm(p, &img, &e))
        fail_msg("%s", e.msg);
    const float want[6] = {1.0f, 2.0f, 3.0f, -0.5f, 0.0f, 100.0f};
    assert_memory_equal(img.rgb, want, sizeof want);
    lr_image_free(&img);
    free(p);

    unsigned char grey[] = "Pf\n1 2\n-1\n"
                           "\x00\x00\x80\x3f" /* bottom row: 1.0 */
                           "\x00\x00\x00\x40";/* top row: 2.0 */
    p = lr_test_write(*state, "grey.pfm", grey, sizeof grey - 1);
    if (lr_image_read_pfm(p, &img, &e))
        fail_msg("%s", e.msg);
    const float want_g[6] = {2, 2, 2, 1, 1, 1};
    assert_memory_equal(img.rgb, want_g, sizeof want_g);
    lr_image_free(&img);
    free(p);
}

static void expect_pfm_error(const char *dir, const char *name, const void *data, size_t len,
                             int code, const char *what)
{
    char *p = lr_test_write(dir, name, data, len);
    lr_image img = {(int)0xbad, (int)0xbad, (float *)1};
    lr_err e = {0};
    assert_int_equal(lr_image_read_pfm(p, &img, &e), code);
    assert_null(img.rgb);
    char want[512];
    snprintf(want, sizeof want, "%s: %s", p, what);
    assert_string_equal(e.msg, want);
    free(p);
}

static void pfm_bad_files_are_rejected_by_name(void **state)
{
    const char *dir = *state;
    char *good = lr_test_path(dir, "good.pfm");
    lr_image img = ramp();
    assert_int_equal(lr_image_write_pfm(good, &img, NULL), LR_OK);
    size_t n;
    unsigned char *d = lr_test_read(good, &n);

    expect_pfm_error(dir, "trunc.pfm", d, n - 7, LR_EPARSE, "truncated: 173 of 180 pixel bytes");
    expect_pfm_error(dir, "hdr.pfm", d, 8, LR_EPARSE, "truncated PFM header");
    unsigned char *longer = malloc(n + 3);
    memcpy(longer, d, n);
    memcpy(longer + n, "xyz", 3);
    expect_pfm_error(dir, "long.pfm", longer, n + 3, LR_EPARSE,
                     "3 unexpected bytes after the pixel data");
    expect_pfm_error(dir, "ppm.pfm", "P6\n5 3\n255\n", (size_t)-1, LR_EPARSE,
                     "not a PFM file (no PF/Pf signature)");
    expect_pfm_error(dir, "empty.pfm", "", 0, LR_EPARSE, "not a PFM file (no PF/Pf signature)");
    expect_pfm_error(dir, "size.pfm", "PF\n0 3\n-1.0\n", (size_t)-1, LR_EPARSE,
                     "bad PFM size \"0 3\" (1..16384)");
    expect_pfm_error(dir, "huge.pfm", "PF\n99999999 3\n-1.0\n", (size_t)-1, LR_EPARSE,
                     "bad PFM size \"99999999 3\" (1..16384)");
    expect_pfm_error(dir, "scale.pfm", "PF\n1 1\nabc\n", (size_t)-1, LR_EPARSE,
                     "bad PFM scale \"abc\"");
    expect_pfm_error(dir, "zero.pfm", "PF\n1 1\n0.0\n", (size_t)-1, LR_EPARSE, "bad PFM scale \"0.0\"");

    lr_image back = {0};
    lr_err e = {0};
    assert_int_equal(lr_image_read_pfm("/nonexistent/x.pfm", &back, &e), LR_EIO);
    assert_string_equal(e.msg, "/nonexistent/x.pfm: cannot open: No such file or directory");
    free(longer);
    free(d);
    free(good);
    lr_image_free(&img);
}

/* ---- tone mapping and sRGB ---------------------------------------------------------------- */

static void tonemap_and_srgb_values(void **state)
{
    assert_true(lr_tonemap_apply(NULL, 0.25f) == 0.25f);
    assert_true(lr_tonemap_apply(NULL, 7.0f) == 1.0f);
    assert_true(lr_tonemap_apply(NULL, -1.0f) == 0.0f);
    assert_true(lr_tonemap_apply(NULL, NAN) == 0.0f);
    assert_true(lr_tonemap_apply(NULL, INFINITY) == 1.0f);
    const lr_tonemap exp2 = {.exposure = 2.0f};
    assert_true(lr_tonemap_apply(&exp2, 0.25f) == 0.5f);
    const lr_tonemap rh = {.op = LR_TONEMAP_REINHARD};
    assert_true(lr_tonemap_apply(&rh, 1.0f) == 0.5f);
    assert_true(lr_tonemap_apply(&rh, 3.0f) == 0.75f);
    assert_true(lr_tonemap_apply(&rh, INFINITY) == 1.0f);
    const lr_tonemap aces = {.op = LR_TONEMAP_ACES};
    assert_true(lr_tonemap_apply(&aces, 0.0f) == 0.0f);
    /* x = 1: (2.51 + 0.03) / (2.43 + 0.59 + 0.14) = 2.54 / 3.16 */
    assert_float_equal(lr_tonemap_apply(&aces, 1.0f), 2.54f / 3.16f, 1e-6f);
    assert_true(lr_tonemap_apply(&aces, 1e6f) == 1.0f); /* the fit exceeds 1 (1.033); clipped */

    /* IEC 61966-2-1 reference points. */
    assert_float_equal(lr_srgb_encode(0.0031308f), 0.0404500f, 1e-6f); /* both branches meet */
    assert_float_equal(lr_srgb_encode(0.18f), 0.4613561f, 1e-6f);
    assert_float_equal(lr_srgb_decode(0.5f), 0.2140411f, 1e-6f);
    assert_true(lr_srgb_encode(1.0f) == 1.0f && lr_srgb_decode(1.0f) == 1.0f);
    for (int i = 0; i <= 255; i++) {
        float s = (float)i / 255.0f;
        assert_float_equal(lr_srgb_encode(lr_srgb_decode(s)), s, 2e-6f);
    }
}

/* The blend pass's fast sRGB encode (lr_srgb_encode_fast, Taylor's three-square-root fit)
 * against IEC 61966-2-1 over [0, 1], on a uniform grid of 2^22 steps and a logarithmic one
 * from 2^-30: within 0.25 of an 8-bit step (the fit's own error peaks at 0.247 steps, at the
 * branch point), so its 8-bit code is the exact one or one step off; the ends are exact. */
static void fast_srgb_encode_within_a_quarter_step(void **state)
{
    (void)state;
    double worst = 0.0;
    long off = 0, n = 0;
    for (int k = 0; k <= (1 << 22); k++) {
        for (int m = 0; m < 2; m++) {
            float l = m ? (float)k / (float)(1 << 22) : exp2f(-30.0f + 30.0f * (float)k / (1 << 22));
            float a = lr_srgb_encode_fast(l), b = lr_srgb_encode(l);
            worst = fmax(worst, fabs((double)a - b));
            off += rintf(a * 255.0f) != rintf(b * 255.0f);
            n++;
        }
    }
    print_message("fast sRGB encode: worst %.4f of a step, %ld of %ld codes one step off\n",
                  worst * 255.0, off, n);
    assert_true(worst <= 0.25 / 255.0);
    assert_true(lr_srgb_encode_fast(0.0f) == 0.0f && lr_srgb_encode_fast(-1.0f) == 0.0f);
    assert_true(lr_srgb_encode_fast(NAN) == 0.0f);
    assert_true(lr_srgb_encode_fast(1.0f) <= 1.0f && lr_srgb_encode_fast(5.0f) <= 1.0f);
    assert_true(rintf(lr_srgb_encode_fast(1.0f) * 255.0f) == 255.0f);
}

/* ---- PNG ---------------------------------------------------------------------------------- */

static void png_round_trip_is_exact_at_8_bits(void **state)
{
    char *path = lr_test_path(*state, "a.png");
    lr_image img;
    assert_int_equal(lr_image_alloc(&img, 16, 17, NULL), LR_OK);
    for (int i = 0; i < 16 * 17 * 3; i++)
        img.rgb[i] = (float)((i * 37) % 1000) / 999.0f; /* [0, 1], clipped by nothing */
    img.rgb[0] = 2.5f;  /* clipped to white */
    img.rgb[1] = -1.0f; /* black */
    img.rgb[2] = NAN;   /* black */
    lr_err e = {0};
    if (lr_image_write_png(path, &img, NULL, &e))
        fail_msg("%s", e.msg);
    lr_image back = {0};
    if (lr_image_read_png(path, &back, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(back.width, 16);
    assert_int_equal(back.height, 17);
    /* PNG holds q = round(255 * srgb(tonemap(v))); reading decodes q / 255 back to linear. So
     * re-encoding what was read gives q exactly (to float rounding, far below 1/255). */
    for (int i = 0; i < 16 * 17 * 3; i++) {
        float q = rintf(lr_srgb_encode(lr_tonemap_apply(NULL, img.rgb[i])) * 255.0f);
        float got = lr_srgb_encode(back.rgb[i]) * 255.0f;
        if (fabsf(got - q) > 1e-3f)
            fail_msg("sample %d: wrote %g (q=%g), read %g (q=%g)", i, img.rgb[i], q, back.rgb[i], got);
    }
    assert_true(back.rgb[0] == 1.0f && back.rgb[1] == 0.0f && back.rgb[2] == 0.0f);
    /* Orientation: top-left stays top-left. */
    lr_image_free(&back);

    /* Exposure and operator are applied: Reinhard at exposure 2 maps 0.5 to 0.5. */
    for (int i = 0; i < 16 * 17 * 3; i++)
        img.rgb[i] = 0.5f;
    if (lr_image_write_png(path, &img, &(lr_tonemap){.op = LR_TONEMAP_REINHARD, .exposure = 2.0f}, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_image_read_png(path, &back, &e), LR_OK);
    assert_float_equal(lr_srgb_encode(back.rgb[7]) * 255.0f, rintf(lr_srgb_encode(0.5f) * 255.0f), 1e-3f);
    lr_image_free(&back);
    lr_image_free(&img);
    free(path);
}

static void png_rows_are_top_down(void **state)
{
    char *path = lr_test_path(*state, "rows.png");
    lr_image img;
    assert_int_equal(lr_image_alloc(&img, 2, 3, NULL), LR_OK);
    img.rgb[0] = 1.0f;                   /* top-left red */
    img.rgb[(2 * 2 + 1) * 3 + 2] = 1.0f; /* bottom-right blue */
    assert_int_equal(lr_image_write_png(path, &img, NULL, NULL), LR_OK);
    lr_image back = {0};
    assert_int_equal(lr_image_read_png(path, &back, NULL), LR_OK);
    assert_memory_equal(back.rgb, img.rgb, 2 * 3 * 3 * sizeof(float));
    lr_image_free(&back);
    lr_image_free(&img);
    free(path);
}

static void png_bad_files_are_rejected_by_name(void **state)
{
    const char *dir = *state;
    char *good = lr_test_path(dir, "good.png");
    lr_image img = ramp();
    assert_int_equal(lr_image_write_png(good, &img, NULL, NULL), LR_OK);
    size_t n;
    unsigned char *d = lr_test_read(good, &n);
    lr_image back = {0};
    lr_err e = {0};
    char prefix[512];

    /* Cut inside the image data: the header reads fine, decoding fails. */
    char *trunc = lr_test_write(dir, "trunc.png", d, n - 20);
    assert_int_equal(lr_image_read_png(trunc, &back, &e), LR_EPARSE);
    assert_null(back.rgb);
    print_message("%s\n", e.msg);
    snprintf(prefix, sizeof prefix, "%s: corrupt or truncated PNG: ", trunc);
    assert_int_equal(strncmp(e.msg, prefix, strlen(prefix)), 0);

    /* A flipped byte in the image data: CRC mismatch. */
    d[n - 20] ^= 0x55;
    char *crc = lr_test_write(dir, "crc.png", d, n);
    assert_int_equal(lr_image_read_png(crc, &back, &e), LR_EPARSE);
    print_message("%s\n", e.msg);
    snprintf(prefix, sizeof prefix, "%s: ", crc);
    assert_int_equal(strncmp(e.msg, prefix, strlen(prefix)), 0);

    char *text = lr_test_write(dir, "text.png", "hello, not a png\n", (size_t)-1);
    assert_int_equal(lr_image_read_png(text, &back, &e), LR_EPARSE);
    snprintf(prefix, sizeof prefix, "%s: not a readable PNG: ", text);
    assert_int_equal(strncmp(e.msg, prefix, strlen(prefix)), 0);

    char *hdr = lr_test_write(dir, "hdr.png", d, 12); /* signature and half an IHDR */
    assert_int_equal(lr_image_read_png(hdr, &back, &e), LR_EPARSE);
    snprintf(prefix, sizeof prefix, "%s: not a readable PNG: ", hdr);
    assert_int_equal(strncmp(e.msg, prefix, strlen(prefix)), 0);

    assert_int_equal(lr_image_read_png("/nonexistent/y.png", &back, &e), LR_EIO);
    assert_string_equal(e.msg, "/nonexistent/y.png: cannot open: No such file or directory");
    free(trunc);
    free(crc);
    free(text);
    free(hdr);
    free(d);
    free(good);
    lr_image_free(&img);
}

/* ---- atomic writes ------------------------------------------------------------------------ */

static void writes_replace_atomically_and_leave_no_temp(void **state)
{
    const char *dir = *state;
    char *path = lr_test_write(dir, "out.pfm", "old contents", (size_t)-1);
    lr_image img = ramp();
    assert_int_equal(lr_image_write_pfm(path, &img, NULL), LR_OK);
    char *png = lr_test_path(dir, "out.png");
    assert_int_equal(lr_image_write_png(png, &img, NULL, NULL), LR_OK);
    free(png);
    assert_int_equal(dir_entries(dir), 2); /* out.pfm, out.png: no temporaries left behind */
    lr_image back = {0};
    assert_int_equal(lr_image_read_pfm(path, &back, NULL), LR_OK);
    assert_memory_equal(back.rgb, img.rgb, 5 * 3 * 3 * sizeof(float));
    lr_image_free(&back);

    /* A directory that does not exist: error naming the destination, nothing created. */
    char *bad = lr_test_path(dir, "missing/sub/x.png");
    lr_err e = {0};
    assert_int_equal(lr_image_write_png(bad, &img, NULL, &e), LR_EIO);
    char want[512];
    snprintf(want, sizeof want, "%s: cannot create a temporary file beside it: No such file or directory", bad);
    assert_string_equal(e.msg, want);
    assert_int_equal(dir_entries(dir), 2);

    /* Empty images are refused before anything is written. */
    lr_image empty = {0};
    assert_int_equal(lr_image_write_pfm(path, &empty, &e), LR_EINVAL);
    assert_int_equal(lr_image_read_pfm(path, &back, NULL), LR_OK); /* old file intact */
    lr_image_free(&back);
    free(bad);
    free(path);
    lr_image_free(&img);
}

static void gl_readback_is_flipped(void **state)
{
    /* 2x2 RGBA in GL order: row 0 (bottom) = 1, 2; row 1 (top) = 3, 4 (in red). */
    const float rgba[16] = {1, 0, 0, 9, 2, 0, 0, 9, 3, 0, 0, 9, 4, 0, 0, 9};
    lr_image img = {0};
    assert_int_equal(lr_image_from_gl_rgba(&img, rgba, 2, 2, NULL), LR_OK);
    const float want[12] = {3, 0, 0, 4, 0, 0, 1, 0, 0, 2, 0, 0};
    assert_memory_equal(img.rgb, want, sizeof want);
    lr_image_free(&img);
    lr_image_free(&img); /* idempotent */
    lr_err e = {0};
    assert_int_equal(lr_image_alloc(&img, 0, 5, &e), LR_EINVAL);
    assert_string_equal(e.msg, "image size 0x5 outside 1..16384");
}

int main(void)
{
#define T(name) cmocka_unit_test_setup_teardown(name, setup, teardown)
    const struct CMUnitTest tests[] = {
        T(pfm_round_trip_is_bit_exact),
        T(pfm_layout_is_little_endian_bottom_up),
        T(pfm_reads_big_endian_and_grey),
        T(pfm_bad_files_are_rejected_by_name),
        T(tonemap_and_srgb_values),
        T(fast_srgb_encode_within_a_quarter_step),
        T(png_round_trip_is_exact_at_8_bits),
        T(png_rows_are_top_down),
        T(png_bad_files_are_rejected_by_name),
        T(writes_replace_atomically_and_leave_no_temp),
        T(gl_readback_is_flipped),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='cube*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
