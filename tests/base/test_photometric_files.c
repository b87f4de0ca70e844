/* render/photometry: the IES LM-63 and EULUMDAT parsers (ies.c, ldt.c), symmetry folding,
 * the flux integral against the example files' stated lumens, refusals with file:line, and
 * the two libFuzzer harnesses (tests/fuzz/) on the committed corpus and mutations of it. */
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

#include "render/photometry/luminaire.h"
#include "tests/support/fs.h"
#include "tests/support/near.h"

#define LLVMFuzzerTestOneInput fuzz_ies
#include "tests/fuzz/fuzz_ies.c"
#undef LLVMFuzzerTestOneInput
#define LLVMFuzzerTestOneInput fuzz_ldt
#include "tests/fuzz/fuzz_ldt.c"
#undef LLVMFuzzerTestOneInput

#define EXAMPLES LR_SOURCE_CONFIGS "/photometry"
#define CORPUS LR_SOURCE_CONFIGS "/../tests/fuzz/corpus"

static void load_ok(const char *path, lr_luminaire *l)
{
    lr_err e = {0};
    if (lr_luminaire_load(path, l, &e))
        fail_msg("%s", e.msg);
}

/* The examples are analytic distributions (tools/make_photometry_examples.py) whose exact flux
 * is the header's lumens. The integral runs on the bilinear interpolant of the samples, whose
 * error against the curve is at most h^2/8 max|f''| (linear interpolation), integrated over
 * the sphere:
 *   bulb  I0 (1 + cos g)/2 at h = 5 deg: |f''| <= I0/2, 9.5e-4 I0 x 4 pi / (2 pi I0) = 1.9e-3;
 *   spot  I0 cos^4 g at 2.5 deg: |f''| = |12 c^2 s^2 - 4 c^4| I0 <= 4 I0: 9.5e-4 I0 x 1.3
 *         x 2 pi (int sin over 0..90 = 1) / (2 pi I0 / 5) = 6.2e-3 (the C factor's linear
 *         interpolation integrates exactly: the trapezoid rule is exact for cos 2C on a full
 *         period);
 *   strip I0 cos g at 5 deg: |f''| <= I0: 9.5e-4 relative bound, 1.9e-3 with the C factor.
 * Plus the midpoint integrator (~1e-5) and the 4-decimal values (< 1e-6). All under the 1 %
 * the issue asks; each asserted at its own bound. */
static void test_examples_flux(void **state)
{
    (void)state;
    static const struct { const char *file; double lumens, bound; const char *format; } ex[] = {
        {"led_bulb_2700k.ies", 806.0, 2e-3, "LM-63-2002"},
        {"led_spot_3000k.ies", 500.0, 6.5e-3, "LM-63-1995"},
        {"led_strip_4000k.ldt", 900.0, 2e-3, "EULUMDAT"},
    };
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", EXAMPLES, ex[i].file);
        lr_luminaire l;
        load_ok(path, &l);
        assert_string_equal(l.format, ex[i].format);
        assert_near_rel(l.lumens, ex[i].lumens, 1e-9);
        double flux = lr_luminaire_flux(&l);
        assert_near_rel(flux, l.lumens, ex[i].bound);
        assert_near_rel(flux, l.lumens, 0.01);
        lr_luminaire_free(&l);
    }
}

/* Lookups at stored angles return the stored values (to the files' 4 decimals, 5e-5 cd), and
 * the symmetry folds every C plane onto the kept ones. */
static void test_examples_lookup(void **state)
{
    (void)state;
    lr_luminaire l;
    load_ok(EXAMPLES "/led_bulb_2700k.ies", &l);
    double i0 = 806.0 / (2.0 * M_PI);
    assert_int_equal(l.sym, LR_LUM_SYM_ROTATIONAL);
    assert_near(lr_luminaire_cd(&l, 0.0, 0.0), i0, 5e-5);
    assert_near(lr_luminaire_cd(&l, 137.0, 90.0), 0.5 * i0, 5e-5);
    assert_near(lr_luminaire_cd(&l, 0.0, 180.0), 0.0, 5e-5);
    lr_luminaire_free(&l);

    load_ok(EXAMPLES "/led_spot_3000k.ies", &l);
    i0 = 500.0 * 5.0 / (2.0 * M_PI);
    assert_int_equal(l.sym, LR_LUM_SYM_QUADRANT);
    assert_int_equal(l.n_tilt, 3);
    assert_near(l.tilt_factor[2], 0.9, 0.0);
    double c45 = pow(cos(M_PI / 4), 4);
    /* C0 and C180 are the wide planes (1.3), C90 and C270 the narrow (0.7). */
    assert_near(lr_luminaire_cd(&l, 0.0, 45.0), 1.3 * i0 * c45, 5e-5);
    assert_near(lr_luminaire_cd(&l, 180.0, 45.0), 1.3 * i0 * c45, 5e-5);
    assert_near(lr_luminaire_cd(&l, 90.0, 45.0), 0.7 * i0 * c45, 5e-5);
    assert_near(lr_luminaire_cd(&l, 270.0, 45.0), 0.7 * i0 * c45, 5e-5);
    assert_near(lr_luminaire_cd(&l, -90.0, 45.0), 0.7 * i0 * c45, 5e-5);
    /* C 195 folds to 165, i.e. onto the kept 15. */
    assert_near(lr_luminaire_cd(&l, 195.0, 45.0), lr_luminaire_cd(&l, 15.0, 45.0), 1e-12);
    /* Beyond the file's vertical range (0..90): dark. */
    assert_near(lr_luminaire_cd(&l, 0.0, 120.0), 0.0, 0.0);
    lr_luminaire_free(&l);

    load_ok(EXAMPLES "/led_strip_4000k.ldt", &l);
    i0 = 900.0 / (0.8 * M_PI);
    assert_int_equal(l.sym, LR_LUM_SYM_QUADRANT);
    assert_int_equal(l.n_h, 7);
    assert_near(lr_luminaire_cd(&l, 0.0, 0.0), i0, 5e-4);      /* cd/klm x 1 klm */
    assert_near(lr_luminaire_cd(&l, 270.0, 60.0), 0.6 * i0 * 0.5, 5e-4);
    lr_luminaire_free(&l);
}

static void corpus_ok(const char *file, lr_luminaire *l)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", CORPUS, file);
    load_ok(path, l);
}

/* The other symmetries and headers, on the corpus' small files (values chosen by hand). */
static void test_symmetries(void **state)
{
    (void)state;
    lr_luminaire l;
    corpus_ok("ies/lm63_1986.ies", &l);
    assert_string_equal(l.format, "LM-63-1986");
    assert_near(lr_luminaire_cd(&l, 10.0, 22.5), 90.0, 1e-12);
    lr_luminaire_free(&l);
    /* IESNA91, absolute photometry (-1 lumens: none stated), multiplier 2. */
    corpus_ok("ies/bilateral.ies", &l);
    assert_string_equal(l.format, "LM-63-1991");
    assert_int_equal(l.sym, LR_LUM_SYM_BILATERAL);
    assert_near(l.lumens, 0.0, 0.0);
    assert_near(lr_luminaire_cd(&l, 90.0, 90.0), 12.0, 1e-12);
    assert_near(lr_luminaire_cd(&l, 270.0, 90.0), 12.0, 1e-12);
    assert_near(lr_luminaire_cd(&l, 225.0, 0.0), 2.0 * (12 + 14) / 2, 1e-12);
    lr_luminaire_free(&l);
    corpus_ok("ies/bilateral90.ies", &l);
    assert_int_equal(l.sym, LR_LUM_SYM_BILATERAL90);
    assert_near(lr_luminaire_cd(&l, 0.0, 90.0), lr_luminaire_cd(&l, 180.0, 90.0), 1e-12);
    assert_near(lr_luminaire_cd(&l, 45.0, 180.0), lr_luminaire_cd(&l, 135.0, 180.0), 1e-12);
    assert_near(lr_luminaire_cd(&l, 300.0, 90.0), lr_luminaire_cd(&l, 240.0, 90.0), 1e-12);
    lr_luminaire_free(&l);
    /* No symmetry: between 270 (4) and 360 (= 0: 1). */
    corpus_ok("ies/full.ies", &l);
    assert_int_equal(l.sym, LR_LUM_SYM_NONE);
    assert_near(lr_luminaire_cd(&l, 315.0, 0.0), 2.5, 1e-12);
    lr_luminaire_free(&l);
    corpus_ok("ldt/rotational.ldt", &l);
    assert_int_equal(l.sym, LR_LUM_SYM_ROTATIONAL);
    assert_near(lr_luminaire_cd(&l, 77.0, 45.0), 200.0, 1e-9); /* 200 cd/klm x 1000 lm */
    lr_luminaire_free(&l);
    /* EULUMDAT Isym 0: C 315 between the planes 270 and 0 (both 100 at gamma 0). */
    corpus_ok("ldt/none.ldt", &l);
    assert_int_equal(l.sym, LR_LUM_SYM_NONE);
    assert_near(lr_luminaire_cd(&l, 315.0, 45.0), 50.0, 1e-9);
    lr_luminaire_free(&l);
}

static void expect_refused(int ldt, const char *text, const char *needle)
{
    lr_luminaire l;
    lr_err e = {0};
    int rc = ldt ? lr_ldt_parse(text, strlen(text), "x.ldt", &l, &e)
                 : lr_ies_parse(text, strlen(text), "x.ies", &l, &e);
    if (rc == LR_OK)
        fail_msg("accepted:\n%s", text);
    assert_null(l.cd);
    if (!strstr(e.msg, needle))
        fail_msg("message '%s' lacks '%s'", e.msg, needle);
}

static void test_refusals(void **state)
{
    (void)state;
    char *t;
    size_t n;
    static const struct { const char *file, *msg; } bad[] = {
        {"ies/tilt_file.ies", "x.ies:3: TILT= must be NONE or INCLUDE"},
        {"ies/negative.ies", "x.ies:8: candela value -1 at horizontal 0, vertical 90 is "
                             "negative"},
        {"ies/type_b.ies", "x.ies:4: photometric type B or A (2, 3): only type C (1) is read"},
    };
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", CORPUS, bad[i].file);
        t = (char *)lr_test_read(path, &n);
        assert_non_null(t);
        char *z = realloc(t, n + 1);
        z[n] = '\0';
        expect_refused(0, z, bad[i].msg);
        free(z);
    }
    /* The end of the file is reported on the line after the last newline. */
    expect_refused(0, "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 100 1 2 1 1 2 0 0 0\n1 1 0\n"
                   "0 90\n", "x.ies:7: expected a horizontal angle, got the end of the file");
    expect_refused(0, "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 100 1 2 1 1 2 0 0 0\n1 1 0\n"
                   "90 0\n0\n1 1\n", "x.ies:6: vertical angles must increase: 0 after 90");
    expect_refused(0, "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 100 1 2 2 1 2 0 0 0\n1 1 0\n"
                   "0 90\n0 45\n1 1 1 1\n", "x.ies:7: horizontal angles must be 0, 0..90, "
                   "0..180, 90..270 or 0..360");
    expect_refused(0, "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 100 1 2 1 1 2 0 0 0\n1 1 0\n"
                   "0 90\n0\n1 1 7\n", "x.ies:8: numbers after the last candela value");
    expect_refused(0, "IESNA:LM-63-2002\n[TEST] x\nTILT=NONE\n1 100 1 2 1 1 2 0 0 0\n1 1 0\n"
                   "0 90\n0\n1 one\n", "x.ies:8: expected a candela value, got 'one'");
    expect_refused(0, "IESNA:LM-63-2002\nfree text\nTILT=NONE\n",
                   "x.ies:2: expected a [KEYWORD] line or TILT=");
    /* EULUMDAT: LORL on line 23, trailing text, a missing last line. */
    char path[512];
    snprintf(path, sizeof path, "%s/ldt/rotational.ldt", CORPUS);
    t = (char *)lr_test_read(path, &n);
    char *z = realloc(t, n + 1);
    z[n] = '\0';
    char buf[2048];
    snprintf(buf, sizeof buf, "%s", z);
    char *p = buf;
    for (int i = 0; i < 22; i++)
        p = strchr(p, '\n') + 1;
    memcpy(p, "  0", 3); /* "100" -> "  0" */
    expect_refused(1, buf, "x.ldt:23: LORL must be in (0, 100] %, got 0");
    snprintf(buf, sizeof buf, "%sjunk\n", z);
    expect_refused(1, buf, "text after the last intensity (counts wrong?): 'junk'");
    snprintf(buf, sizeof buf, "%s", z);
    buf[strlen(buf) - 3] = '\0'; /* drop the last intensity (line 49) and its newline */
    expect_refused(1, buf, "x.ldt:49: expected an intensity (cd/klm), got the end of the file");
    free(z);
    lr_luminaire l;
    lr_err e = {0};
    assert_int_equal(lr_luminaire_load("lamp.txt", &l, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "expected .ies or .ldt"));
}

/* Each corpus file as it is, then `variants` deterministic mutations of it: a byte replaced
 * by one of a few that matter to the grammar (digits, sign, separators, a newline), a cut at
 * a random length, or a number's digit duplicated. */
static int run_corpus(const char *dir, int (*fn)(const uint8_t *, size_t), int variants)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *de;
    int runs = 0, files = 0;
    uint64_t s = 0x9E3779B97F4A7C15ull;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.')
            continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        size_t n;
        unsigned char *data = lr_test_read(path, &n);
        assert_non_null(data);
        files++;
        fn(data, n);
        runs++;
        unsigned char *m = malloc(n + 8);
        static const char subst[] = "0123456789-+., \n\r9e";
        for (int v = 0; v < variants; v++) {
            s = s * 6364136223846793005ull + 1442695040888963407ull;
            uint64_t r = s >> 17;
            memcpy(m, data, n);
            size_t len = n;
            switch (r % 3) {
            case 0: m[(r >> 2) % n] = (unsigned char)subst[(r >> 24) % (sizeof subst - 1)]; break;
            case 1: len = (r >> 2) % n; break;
            default: {
                size_t at = (r >> 2) % n;
                memmove(m + at + 1, m + at, n - at);
                len = n + 1;
                break;
            }
            }
            fn(m, len);
            runs++;
        }
        free(m);
        free(data);
    }
    closedir(d);
    assert_true(files >= 3);
    return runs;
}

static int ies_fn(const uint8_t *d, size_t n) { return fuzz_ies(d, n); }
static int ldt_fn(const uint8_t *d, size_t n) { return fuzz_ldt(d, n); }

static void test_fuzz_corpus(void **state)
{
    (void)state;
    /* 1500 variants per seed: ~18000 parses, a few seconds under ASan. */
    int a = run_corpus(CORPUS "/ies", ies_fn, 1500);
    int b = run_corpus(CORPUS "/ldt", ldt_fn, 1500);
    assert_true(a > 9 * 1500 && b > 3 * 1500);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_examples_flux),  cmocka_unit_test(test_examples_lookup),
        cmocka_unit_test(test_symmetries),     cmocka_unit_test(test_refusals),
        cmocka_unit_test(test_fuzz_corpus),
    };
    return cmocka_run_group_tests_name("photometric_files", tests, NULL, NULL);
}
