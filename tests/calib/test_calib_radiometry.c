/* Radiometric round trips: a known camera response recovered from a synthetic exposure
 * stack (Debevec), HDR merge, a known projector response (per-channel gamma with a black
 * level) recovered from simulated flat captures through a known camera curve, and colour
 * matrices from patch pairs and from a ColorChecker found by OpenCV's mcc. */
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

#include "calib/camresp.h"
#include "calib/colormatrix.h"
#include "calib/isotonic.h"
#include "calib/projresp.h"
#include "firmware/cli.h"
#include "tests/support/calib_sim.h"
#include "tests/support/near.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The camera under test encodes linear exposure X (clipped at 1) with the sRGB curve. */
static double srgb_encode(double x)
{
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1 / 2.4) - 0.055;
}

static uint8_t camera_dn(double x, double noise_dn, unsigned long long *state)
{
    double dn = 255.0 * srgb_encode(x) + (noise_dn > 0 ? noise_dn * sim_gauss(state) : 0);
    return (uint8_t)(dn < 0 ? 0 : dn > 255 ? 255 : lround(dn));
}

#define SW 96
#define SH 72
#define NEXP 6

/* A scene of radiances log-uniform over [1e-3, 1] (independent per channel), photographed
 * at exposures 1/32 .. 32 s x 1/8: every value 0..255 is produced somewhere. */
static void exposure_stack(lr_img *imgs, double *times, double *radiance)
{
    unsigned long long st = 12345;
    for (int i = 0; i < SW * SH * 3; i++) {
        double u = 0.5 + 0.5 * sim_gauss(&st) / 3.0;
        u = u < 0 ? 0 : u > 1 ? 1 : u;
        radiance[i] = pow(10.0, -3.0 + 3.0 * u);
    }
    lr_err e = {0};
    for (int k = 0; k < NEXP; k++) {
        times[k] = pow(4.0, k) / 256.0; /* 1/256 .. 4 */
        assert_int_equal(lr_img_alloc(&imgs[k], SW, SH, 3, 1, &e), LR_OK);
        uint8_t *p = imgs[k].px;
        for (int i = 0; i < SW * SH * 3; i++)
            p[i] = camera_dn(radiance[i] * times[k] * 8.0, 0.7, &st);
    }
}

static void test_camera_response(void **state)
{
    (void)state;
    lr_img imgs[NEXP];
    double times[NEXP];
    double *radiance = malloc(sizeof *radiance * SW * SH * 3);
    exposure_stack(imgs, times, radiance);
    lr_camresp r;
    lr_err e = {0};
    lr_camresp_desc d = {imgs, times, NEXP, 0, 0};
    int rc = lr_camresp_fit(&d, &r, &e);
    if (rc)
        fail_msg("fit: %s", e.msg);
    /* Truth: exposure producing value z, relative to the one producing 128. Debevec's curve
     * is smoothed (lambda 10) and sampled at 70 locations, quantisation is +-0.5 DN and noise
     * 0.7 DN. At z = 32 one DN is 4.3 % of exposure (sRGB slope), at 220 1.1 %; the fit
     * averages several samples per value. Measured worst over 32..224: ~3 %. Tolerance 6 %
     * there; below 32 the curve rests on few, steep values, 15 % down to z = 12. */
    double worst = 0;
    for (int c = 0; c < 3; c++)
        for (int z = 12; z <= 235; z++) {
            double truth = lr_srgb_to_linear(z / 255.0) / lr_srgb_to_linear(128 / 255.0);
            double rel = r.curve[c][z] / truth - 1;
            if (z >= 32 && z <= 224)
                worst = fmax(worst, fabs(rel));
            if (fabs(rel) > (z >= 32 && z <= 224 ? 0.06 : 0.15))
                fail_msg("channel %d value %d: response %.5f, truth %.5f (%.1f %%)", c, z,
                         r.curve[c][z], truth, 100 * rel);
        }
    print_message("camera response: worst relative error over 32..224 = %.2f %%\n", 100 * worst);
    /* Monotone by construction, normalised at 128. */
    for (int c = 0; c < 3; c++) {
        assert_near(r.curve[c][128], 1.0, 1e-12);
        for (int z = 1; z < 256; z++)
            assert_true(r.curve[c][z] >= r.curve[c][z - 1]);
    }

    /* HDR merge: radiance up to one global scale (the median ratio). Each sample's error is
     * the response's bias (< 3 %, above) plus noise: 0.7 DN is 1-3 % of exposure between 40
     * and 190 DN, averaged over the 2-3 exposures that carry weight, so ~2 % RMS. For
     * samples some exposure sees well (64..192 DN): RMS under 3 %, worst of 20000 under 10 %
     * (about 4-5 sigma). Samples seen only between 20 and 235 DN lean on the noisy dark end
     * of the curve: worst under 15 %. */
    lr_img hdr;
    rc = lr_camresp_merge(&r, imgs, times, NEXP, &hdr, &e);
    if (rc)
        fail_msg("merge: %s", e.msg);
    assert_int_equal(hdr.depth, 4);
    assert_int_equal(hdr.channels, 3);
    const float *h = hdr.px;
    int nr = SW * SH * 3;
    double *ratio = malloc(sizeof *ratio * (size_t)nr);
    for (int i = 0; i < nr; i++)
        ratio[i] = h[i] / radiance[i];
    qsort(ratio, (size_t)nr, sizeof *ratio, cmp_double);
    double scale = ratio[nr / 2];
    long well = 0, fair = 0;
    double worst_well = 0, worst_fair = 0, ss_well = 0;
    for (int i = 0; i < nr; i++) {
        bool is_well = false, is_fair = false;
        for (int k = 0; k < NEXP; k++) {
            uint8_t z = ((uint8_t *)imgs[k].px)[i];
            is_well |= z >= 64 && z <= 192;
            is_fair |= z >= 20 && z <= 235;
        }
        double err = fabs(h[i] / (scale * radiance[i]) - 1);
        if (is_well) {
            well++;
            ss_well += err * err;
            worst_well = fmax(worst_well, err);
        } else if (is_fair) {
            fair++;
            worst_fair = fmax(worst_fair, err);
        }
    }
    double rms_well = sqrt(ss_well / (double)well);
    print_message("HDR merge: RMS %.2f %%, worst %.2f %% over %ld well-exposed samples; worst "
                  "%.2f %% over %ld fairly exposed\n",
                  100 * rms_well, 100 * worst_well, well, 100 * worst_fair, fair);
    assert_true(well > nr * 8 / 10);
    assert_true(rms_well < 0.03);
    assert_true(worst_well < 0.10);
    assert_true(worst_fair < 0.15);

    /* File round trip; a decreasing curve is refused on load. */
    char path[] = "/tmp/lr_camresp_XXXXXX.json";
    int fd = mkstemps(path, 5);
    assert_true(fd >= 0);
    close(fd);
    assert_int_equal(lr_camresp_save(path, &r, &e), LR_OK);
    lr_camresp back;
    assert_int_equal(lr_camresp_load(path, &back, &e), LR_OK);
    assert_true(memcmp(back.curve, r.curve, sizeof r.curve) == 0);
    assert_int_equal(back.images, NEXP);
    unlink(path);

    /* Too few exposures, equal times: refused with the reason. */
    d.n = 1;
    assert_int_equal(lr_camresp_fit(&d, &r, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "at least 2"));
    double same[2] = {0.5, 0.5};
    d.n = 2;
    d.times = same;
    assert_int_equal(lr_camresp_fit(&d, &r, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "same time"));

    lr_img_free(&hdr);
    for (int k = 0; k < NEXP; k++)
        lr_img_free(&imgs[k]);
    free(ratio);
    free(radiance);
}

/* ---- projector response ---------------------------------------------------------------- */

static const double GAMMA[3] = {2.2, 2.0, 2.4};
#define FW 64
#define FH 48

static const double MIX[9] = {0.80, 0.15, 0.02, 0.12, 0.75, 0.10, 0.03, 0.12, 0.70};

typedef struct flat_ctx {
    const char *dir;
    unsigned long long state;
} flat_ctx;

/* The simulated rig for flats: projector channel c at level v gives light
 * black + (1 - black) v^gamma_c (black = 2 %), plus 1 % ambient; the camera sees it with a
 * 3x3 crosstalk between projector primaries and its channels, over an albedo that falls off
 * towards the edges (vignetting), and outside a central window nothing is lit. sRGB-encoded,
 * 0.8 DN noise. */
static int show_flat(void *ctx, int index, const lr_img *frame, const char *name, lr_err *e)
{
    (void)index;
    flat_ctx *f = ctx;
    const uint8_t *in = frame->px;
    double level[3];
    for (int c = 0; c < 3; c++)
        level[c] = in[c] / 255.0; /* flat frame: the first pixel says it all */
    double P[3];
    for (int c = 0; c < 3; c++)
        P[c] = 0.02 + 0.98 * pow(level[c], GAMMA[c]);
    lr_img cam;
    int rc = lr_img_alloc(&cam, FW, FH, 3, 1, e);
    if (rc)
        return rc;
    uint8_t *o = cam.px;
    for (int y = 0; y < FH; y++)
        for (int x = 0; x < FW; x++) {
            bool lit = x >= 8 && x < FW - 8 && y >= 6 && y < FH - 6;
            double r2 = ((x - FW / 2.0) * (x - FW / 2.0) + (y - FH / 2.0) * (y - FH / 2.0)) /
                        (FW * FW / 4.0);
            double albedo = 0.55 * (1 - 0.3 * r2);
            for (int j = 0; j < 3; j++) {
                double light = 0.01;
                if (lit)
                    for (int c = 0; c < 3; c++)
                        light += MIX[3 * j + c] * P[c];
                o[3 * (y * FW + x) + j] = camera_dn(albedo * light, 0.8, &f->state);
            }
        }
    char path[512];
    snprintf(path, sizeof path, "%s/%s", f->dir, name);
    rc = lr_img_write_frame(path, &cam, e);
    lr_img_free(&cam);
    return rc;
}

static void test_projector_response(void **state)
{
    (void)state;
    char *dir = sim_tempdir("projresp");
    assert_non_null(dir);
    flat_ctx f = {dir, 99};
    lr_err e = {0};
    /* 17 levels: 0, 16, ..., 240, 255. */
    assert_int_equal(lr_projresp_run_sequence(8, 8, show_flat, &f, &e), LR_OK);
    lr_camresp srgb;
    lr_camresp_gamma(&srgb, 1.0); /* placeholder, replaced by the exact sRGB curve below */
    for (int c = 0; c < 3; c++)
        for (int z = 0; z < 256; z++)
            srgb.curve[c][z] = lr_srgb_to_linear((z > 0 ? z : 0.25) / 255.0);
    lr_projresp r;
    int rc = lr_projresp_measure(dir, &srgb, &r, &e);
    if (rc)
        fail_msg("measure: %s", e.msg);
    assert_int_equal(r.nlevels, 17);
    /* Truth after black subtraction and normalisation: y = v^gamma exactly (the 2 % black,
     * 1 % ambient, crosstalk and vignetting all cancel). Errors: 0.8 DN noise averaged over
     * 1536 lit pixels x 3 channels is ~0.01 DN; 8-bit quantisation with that noise as dither
     * is unbiased; the nonlinear decode of noisy values biases each level by ~1e-4
     * relative. Between measured levels the power-law interpolation is exact for a pure
     * gamma. So: LUT within 0.002 of v^gamma everywhere, the fitted exponent within 0.02. */
    double worst = 0;
    for (int c = 0; c < 3; c++) {
        for (int i = 0; i < 256; i++) {
            double truth = pow(i / 255.0, GAMMA[c]);
            worst = fmax(worst, fabs(r.lut[c][i] - truth));
            if (fabs(r.lut[c][i] - truth) > 0.002)
                fail_msg("channel %d level %d: LUT %.5f, truth %.5f", c, i, r.lut[c][i], truth);
        }
        assert_near(r.gamma[c], GAMMA[c], 0.02);
        /* black = L(0) / L(1) summed over camera channels: at level 0 every primary leaks its
         * 2 % black, at full level one primary is on and the other two still leak. */
        double total = 0, col = 0;
        for (int j = 0; j < 9; j++)
            total += MIX[j];
        for (int j = 0; j < 3; j++)
            col += MIX[3 * j + c];
        double black = (0.03 + 0.02 * total) / (0.03 + col + 0.02 * (total - col));
        assert_near(r.black[c], black, 0.002);
        /* Inversion: eval(inverse(y)) = y, and inverse(eval(v)) = v on the table's nodes. */
        for (int k = 1; k < 100; k++) {
            double y = k / 100.0;
            assert_near(lr_projresp_eval(&r, c, lr_projresp_inverse(&r, c, y)), y, 1e-12);
        }
        for (int i = 1; i < 256; i++)
            assert_near(lr_projresp_inverse(&r, c, r.lut[c][i]), i / 255.0, 1e-12);
        assert_near(lr_projresp_inverse(&r, c, 0.0), 0.0, 0);
        assert_near(lr_projresp_inverse(&r, c, 1.0), 1.0, 0);
    }
    print_message("projector response: worst LUT error %.5f, gamma %.4f %.4f %.4f\n", worst,
                  r.gamma[0], r.gamma[1], r.gamma[2]);

    char path[512];
    snprintf(path, sizeof path, "%s/projector_response.json", dir);
    assert_int_equal(lr_projresp_save(path, &r, &e), LR_OK);
    lr_projresp back;
    assert_int_equal(lr_projresp_load(path, &back, &e), LR_OK);
    assert_true(memcmp(back.lut, r.lut, sizeof r.lut) == 0);
    assert_int_equal(back.nlevels, 17);

    /* A missing full-level capture is named. */
    snprintf(path, sizeof path, "%s/g_255.png", dir);
    unlink(path);
    assert_int_equal(lr_projresp_measure(dir, &srgb, &r, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "g_255.png"));
    sim_rmdir(dir);
    free(dir);
}

static void test_projector_response_noisy_monotone(void **state)
{
    (void)state;
    /* A flickering level (measured brighter than the next) is pooled by the isotonic fit:
     * the table stays monotone and passes through the pooled mean. */
    double lv[5] = {0, 0.25, 0.5, 0.75, 1}, light[15];
    double y[5] = {0, 0.30, 0.25, 0.6, 1};
    for (int k = 0; k < 5; k++)
        for (int c = 0; c < 3; c++)
            light[3 * k + c] = 0.1 + 2.0 * y[k];
    lr_projresp r;
    lr_err e = {0};
    assert_int_equal(lr_projresp_fit(lv, light, 5, &r, &e), LR_OK);
    for (int i = 1; i < 256; i++)
        assert_true(r.lut[0][i] >= r.lut[0][i - 1]);
    assert_near(r.lut[0][64], 0.275, 0.005); /* (0.30 + 0.25) / 2 at v = 0.25 (level 63.75) */
    assert_near(r.measured[0][1], 0.30, 1e-12);
    /* Black not darker than white: refused, naming the channel. */
    light[3 * 4 + 1] = light[1];
    assert_int_equal(lr_projresp_fit(lv, light, 5, &r, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "channel g"));

    double v[6] = {3, 1, 2, 2, 0, 5};
    assert_int_equal(lr_isotonic(v, NULL, 6, &e), LR_OK);
    /* 3,1,2,2,0 pool to 1.6; 5 stays */
    for (int i = 0; i < 5; i++)
        assert_near(v[i], 1.6, 1e-12);
    assert_near(v[5], 5, 0);
}

/* ---- colour matrix -------------------------------------------------------------------- */

static void test_color_matrix_pairs(void **state)
{
    (void)state;
    static const double M[9] = {1.62, -0.41, -0.21, -0.28, 1.49, -0.21, 0.04, -0.52, 1.48};
    double cam[24 * 3], ref[24 * 3], clean[24 * 3];
    unsigned long long st = 4242;
    for (int i = 0; i < 24; i++) {
        for (int k = 0; k < 3; k++)
            cam[3 * i + k] = 0.03 + 0.87 * (0.5 + sim_gauss(&st) / 6.0);
        for (int r = 0; r < 3; r++) {
            clean[3 * i + r] = M[3 * r] * cam[3 * i] + M[3 * r + 1] * cam[3 * i + 1] +
                               M[3 * r + 2] * cam[3 * i + 2];
            ref[3 * i + r] = clean[3 * i + r] + 0.002 * sim_gauss(&st);
        }
    }
    lr_colormatrix m;
    lr_err e = {0};
    /* Exact pairs: the matrix to rounding. */
    assert_int_equal(lr_colormatrix_fit(cam, clean, 24, &m, &e), LR_OK);
    for (int i = 0; i < 9; i++)
        assert_near(m.m[i], M[i], 1e-12);
    assert_true(m.rms < 1e-12);
    /* 0.002 noise on 24 patches whose colours spread ~0.15 per channel: each entry's
     * standard error is ~0.002 / (0.15 sqrt(24)) = 0.003, larger for correlated channels.
     * 0.02 is several of those; the residual RMS is the noise, sqrt(3) x 0.002 = 0.0035. */
    assert_int_equal(lr_colormatrix_fit(cam, ref, 24, &m, &e), LR_OK);
    for (int i = 0; i < 9; i++)
        assert_near(m.m[i], M[i], 0.02);
    assert_near(m.rms, 0.0035, 0.0015);
    assert_int_equal(m.patches, 24);

    /* All-grey patches cannot fix a colour matrix. */
    double grey[18];
    for (int i = 0; i < 6; i++)
        grey[3 * i] = grey[3 * i + 1] = grey[3 * i + 2] = 0.1 + 0.1 * i;
    assert_int_equal(lr_colormatrix_fit(grey, grey, 6, &m, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "three colour directions"));

    /* The pairs file format. */
    char *dir = sim_tempdir("color");
    char path[512];
    snprintf(path, sizeof path, "%s/pairs.json", dir);
    FILE *f = fopen(path, "w");
    fprintf(f, "{\"version\": 1, \"kind\": \"color_pairs\", \"pairs\": [\n");
    for (int i = 0; i < 24; i++)
        fprintf(f, "  {\"camera\": [%.17g, %.17g, %.17g], \"reference\": [%.17g, %.17g, %.17g]}%s\n",
                cam[3 * i], cam[3 * i + 1], cam[3 * i + 2], clean[3 * i], clean[3 * i + 1],
                clean[3 * i + 2], i < 23 ? "," : "");
    fprintf(f, "]}\n");
    fclose(f);
    double *c2, *r2;
    int n;
    assert_int_equal(lr_colorpairs_load(path, &c2, &r2, &n, &e), LR_OK);
    assert_int_equal(n, 24);
    assert_int_equal(lr_colormatrix_fit(c2, r2, n, &m, &e), LR_OK);
    assert_near(m.m[4], M[4], 1e-12);
    free(c2);
    free(r2);
    snprintf(path, sizeof path, "%s/color.json", dir);
    assert_int_equal(lr_colormatrix_save(path, &m, &e), LR_OK);
    lr_colormatrix back;
    assert_int_equal(lr_colormatrix_load(path, &back, &e), LR_OK);
    assert_true(memcmp(back.m, m.m, sizeof m.m) == 0);
    assert_string_equal(back.source, "pairs");
    sim_rmdir(dir);
    free(dir);
}

/* A ColorChecker drawn as a photo would show it: 4 x 6 patches of the reference colours on
 * a black card, on a grey table, slightly rotated. */
static void draw_checker(lr_img *img)
{
    lr_err e = {0};
    assert_int_equal(lr_img_alloc(img, 800, 600, 3, 1, &e), LR_OK);
    uint8_t *p = img->px;
    const unsigned char *ref = lr_colorchecker_srgb8();
    const double ang = 0.05, ca = cos(ang), sa = sin(ang);
    const double cx = 400, cy = 300, patch = 80, gap = 18;
    const double cw = 6 * patch + 7 * gap, ch = 4 * patch + 5 * gap;
    for (int y = 0; y < 600; y++)
        for (int x = 0; x < 800; x++) {
            /* chart coordinates, origin at the card's top-left */
            double dx = x - cx, dy = y - cy;
            double u = ca * dx + sa * dy + cw / 2, v = -sa * dx + ca * dy + ch / 2;
            uint8_t rgb[3] = {150, 150, 145};
            if (u >= 0 && u < cw && v >= 0 && v < ch) {
                rgb[0] = rgb[1] = rgb[2] = 20;
                double pu = u - gap, pv = v - gap;
                int col = (int)floor(pu / (patch + gap)), row = (int)floor(pv / (patch + gap));
                double iu = pu - col * (patch + gap), iv = pv - row * (patch + gap);
                if (col >= 0 && col < 6 && row >= 0 && row < 4 && iu < patch && iv < patch)
                    memcpy(rgb, ref + 3 * (row * 6 + col), 3);
            }
            memcpy(p + 3 * (y * 800 + x), rgb, 3);
        }
}

static void test_colorchecker(void **state)
{
    (void)state;
    lr_img photo;
    draw_checker(&photo);
    double lin[72];
    lr_err e = {0};
    int rc = lr_colorchecker_measure(&photo, NULL, lin, &e);
    if (rc)
        fail_msg("mcc: %s", e.msg);
    /* mcc averages the patch interiors: on a noise-free drawing the means are the drawn
     * values up to edge pixels it includes (1-2 DN). 3 DN in 8-bit sRGB. */
    const unsigned char *ref = lr_colorchecker_srgb8();
    for (int i = 0; i < 72; i++) {
        double enc = srgb_encode(lin[i]) * 255;
        if (fabs(enc - ref[i]) > 3)
            fail_msg("patch %d channel %d: %.1f, drawn %d", i / 3, i % 3, enc, ref[i]);
    }
    /* The photo is already reference sRGB: the fitted matrix is the identity. */
    double truth[72];
    lr_colorchecker_linear(truth);
    lr_colormatrix m;
    assert_int_equal(lr_colormatrix_fit(lin, truth, 24, &m, &e), LR_OK);
    for (int i = 0; i < 9; i++)
        assert_near(m.m[i], i % 4 == 0 ? 1.0 : 0.0, 0.03);
    /* The same through the CLI, from a JPEG as a camera would deliver it (JPEG shifts patch
     * means by a DN or two: 0.05 on the matrix). */
    char *dir = sim_tempdir("checker");
    char jpg[512], out[512];
    snprintf(jpg, sizeof jpg, "%s/chart.jpg", dir);
    snprintf(out, sizeof out, "%s/color.json", dir);
    assert_int_equal(lr_img_write(jpg, &photo, &e), LR_OK);
    char *argv[] = {"lamprig", "calib", "color", "--checker", jpg, "--out", out, NULL};
    assert_int_equal(lr_cli_main(7, argv), LR_EXIT_OK);
    lr_colormatrix back;
    assert_int_equal(lr_colormatrix_load(out, &back, &e), LR_OK);
    assert_string_equal(back.source, "colorchecker");
    assert_int_equal(back.patches, 24);
    for (int i = 0; i < 9; i++)
        assert_near(back.m[i], i % 4 == 0 ? 1.0 : 0.0, 0.05);
    sim_rmdir(dir);
    free(dir);
    lr_img_free(&photo);

    /* A photo without a chart: a clear error. */
    assert_int_equal(lr_img_alloc(&photo, 320, 240, 3, 1, &e), LR_OK);
    memset(photo.px, 90, 320 * 240 * 3);
    assert_int_equal(lr_colorchecker_measure(&photo, NULL, lin, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "no ColorChecker"));
    lr_img_free(&photo);
}

static void test_cli_camera_response(void **state)
{
    (void)state;
    /* The CLI path: PNG stack on disk, times as fractions, response file and HDR image. */
    lr_img imgs[NEXP];
    double times[NEXP];
    double *radiance = malloc(sizeof *radiance * SW * SH * 3);
    exposure_stack(imgs, times, radiance);
    char *dir = sim_tempdir("camresp_cli");
    char path[512], glob[512], out[512], hdr[512];
    lr_err e = {0};
    for (int k = 0; k < NEXP; k++) {
        snprintf(path, sizeof path, "%s/exp%d.png", dir, k);
        assert_int_equal(lr_img_write(path, &imgs[k], &e), LR_OK);
        lr_img_free(&imgs[k]);
    }
    snprintf(glob, sizeof glob, "%s/exp*.png", dir);
    snprintf(out, sizeof out, "%s/camera_response.json", dir);
    snprintf(hdr, sizeof hdr, "%s/merged.hdr", dir);
    /* 4^k / 256: 1/256, 1/64, 1/16, 1/4, 1, 4 */
    char *argv[] = {"lamprig", "calib", "camera-response", "--images", glob,
                    "--times", "1/256,1/64,1/16,1/4,1,4", "--out", out, "--hdr", hdr, NULL};
    assert_int_equal(lr_cli_main(11, argv), LR_EXIT_OK);
    lr_camresp r;
    assert_int_equal(lr_camresp_load(out, &r, &e), LR_OK);
    double truth = lr_srgb_to_linear(64 / 255.0) / lr_srgb_to_linear(128 / 255.0);
    assert_near(r.curve[1][64] / truth, 1.0, 0.06); /* as test_camera_response */
    lr_img back;
    assert_int_equal(lr_img_read(hdr, LR_IMG_AS_IS, &back, &e), LR_OK);
    assert_int_equal(back.depth, 4);
    assert_int_equal(back.channels, 3);
    assert_int_equal(back.w, SW);
    /* Radiance .hdr keeps 8-bit mantissas: ratios between pixels to ~1 %, plus the merge's
     * own error (~2 % RMS): a bright and a dark pixel keep their ratio to 10 %. */
    int a = 0, b = 0;
    for (int i = 0; i < SW * SH * 3; i++) {
        if (radiance[i] > radiance[a] && radiance[i] < 0.5)
            a = i;
        if (radiance[i] < radiance[b] && radiance[i] > 0.01)
            b = i;
    }
    double ra = lr_img_get(&back, (a / 3) % SW, (a / 3) / SW, a % 3);
    double rb = lr_img_get(&back, (b / 3) % SW, (b / 3) / SW, b % 3);
    assert_near_rel(ra / rb, radiance[a] / radiance[b], 0.10);
    lr_img_free(&back);
    /* Count mismatch between images and times: a usage error, nothing written. */
    unlink(out);
    char *bad[] = {"lamprig", "calib", "camera-response", "--images", glob,
                   "--times", "1/256,1/64", "--out", out, NULL};
    assert_int_equal(lr_cli_main(9, bad), LR_EXIT_USAGE);
    assert_int_not_equal(access(out, F_OK), 0);
    free(radiance);
    sim_rmdir(dir);
    free(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_camera_response),
        cmocka_unit_test(test_projector_response),
        cmocka_unit_test(test_projector_response_noisy_monotone),
        cmocka_unit_test(test_color_matrix_pairs),
        cmocka_unit_test(test_colorchecker),
        cmocka_unit_test(test_cli_camera_response),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
