/* `lamprig optics`: run through lr_cli_main with argv arrays, stdout/stderr captured, JSON read
 * back with lr_json and compared with the library; bad arguments; the PNG plot. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <cairo.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "firmware/cli.h"
#include "firmware/profile_plot.h"
#include "render/base/json.h"
#include "render/material/material.h"
#include "render/optics/optics.h"

/* ---- running the CLI ------------------------------------------------------------------------ */

typedef struct run_result {
    int status;
    char *out; /* captured stdout, NUL-terminated */
    char *err; /* captured stderr */
} run_result;

static char *slurp_fd(FILE *f)
{
    fflush(f);
    long n = ftell(f);
    rewind(f);
    char *buf = calloc(1, (size_t)n + 1);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
    return buf;
}

/* argv is NULL-terminated and starts after "lamprig". */
static run_result run(const char *const *args)
{
    char *argv[64];
    int argc = 0;
    argv[argc++] = (char *)"lamprig";
    for (const char *const *a = args; *a; a++)
        argv[argc++] = (char *)*a;
    argv[argc] = NULL;

    fflush(stdout);
    fflush(stderr);
    FILE *fo = tmpfile(), *fe = tmpfile();
    assert_non_null(fo);
    assert_non_null(fe);
    int so = dup(STDOUT_FILENO), se = dup(STDERR_FILENO);
    dup2(fileno(fo), STDOUT_FILENO);
    dup2(fileno(fe), STDERR_FILENO);
    run_result r;
    r.status = lr_cli_main(argc, argv);
    fflush(stdout);
    fflush(stderr);
    dup2(so, STDOUT_FILENO);
    dup2(se, STDERR_FILENO);
    close(so);
    close(se);
    /* The command wrote through the descriptors; read the files from their start. */
    fseek(fo, 0, SEEK_END);
    fseek(fe, 0, SEEK_END);
    r.out = slurp_fd(fo);
    r.err = slurp_fd(fe);
    fclose(fo);
    fclose(fe);
    return r;
}

static void run_free(run_result *r)
{
    free(r->out);
    free(r->err);
}

static lr_json *parse_out(const run_result *r)
{
    if (r->status != 0)
        fail_msg("status %d, stderr: %s", r->status, r->err);
    lr_json *j = NULL;
    lr_err e = {0};
    if (lr_json_parse(r->out, strlen(r->out), "<stdout>", &j, &e) != LR_OK)
        fail_msg("stdout is not JSON: %s\n%s", e.msg, r->out);
    return j;
}

static void get3(const lr_json *j, lr_jnode obj, const char *key, double out[3])
{
    lr_err e = {0};
    if (lr_json_get_numbers(j, obj, key, true, out, 3, &e) != LR_OK)
        fail_msg("%s", e.msg);
}

/* %.17g round-trips every double and glibc's strtod rounds correctly, so what the CLI prints
 * reads back to the very double the library computed: comparisons below are exact. */
static void assert_same3(const double got[3], const double want[3])
{
    for (int b = 0; b < 3; b++)
        if (got[b] != want[b])
            fail_msg("band %d: printed %.17g, library %.17g", b, got[b], want[b]);
}

static lr_coeffs coeffs_of(const char *name)
{
    lr_material m;
    lr_coeffs c;
    lr_err e = {0};
    if (lr_material_find(name, &m, &e) != LR_OK || lr_coeffs_derive(&m.medium, &c, &e) != LR_OK)
        fail_msg("%s: %s", name, e.msg);
    return c;
}

/* ---- values --------------------------------------------------------------------------------- */

static void test_total(void **state)
{
    (void)state;
    static const char *const names[] = {"marble", "ketchup", "spectralon", "candle_wax"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        const char *args[] = {"optics", "total", "--material", names[i], NULL};
        run_result r = run(args);
        lr_json *j = parse_out(&r);
        lr_coeffs c = coeffs_of(names[i]);
        double total[3], got[3];
        lr_dipole_rd_total(&c, total);
        get3(j, lr_json_root(j), "Rd_total", got);
        assert_same3(got, total);
        get3(j, lr_json_root(j), "sigma_tr", got);
        assert_same3(got, c.sigma_tr);
        get3(j, lr_json_root(j), "albedo", got);
        assert_same3(got, c.albedo_prime);
        /* Marble: albedo' > 0.99 in every band (2.19 / 2.1921 ... 3.00 / 3.0071). */
        if (!strcmp(names[i], "marble"))
            for (int b = 0; b < 3; b++)
                assert_true(got[b] > 0.99);
        assert_string_equal(r.err, "");
        lr_json_destroy(j);
        run_free(&r);
    }
}

static void test_profile(void **state)
{
    (void)state;
    const char *args[] = {"optics", "profile", "--material", "skin1", "--r", "0,0.25,1,2.5,10",
                          NULL};
    run_result r = run(args);
    lr_json *j = parse_out(&r);
    lr_coeffs c = coeffs_of("skin1");
    const double radii[5] = {0, 0.25, 1, 2.5, 10};
    lr_jnode rs = lr_json_get(j, lr_json_root(j), "r");
    lr_jnode rd = lr_json_get(j, lr_json_root(j), "Rd");
    assert_int_equal(lr_json_count(j, rs), 5);
    assert_int_equal(lr_json_count(j, rd), 5);
    lr_err e = {0};
    for (int i = 0; i < 5; i++) {
        double rv, got[3], want[3];
        assert_int_equal(lr_json_number(j, lr_json_at(j, rs, i), "r", &rv, &e), LR_OK);
        assert_true(rv == radii[i]);
        assert_int_equal(lr_json_numbers(j, lr_json_at(j, rd, i), "Rd", got, 3, &e), LR_OK);
        lr_dipole_rd(&c, radii[i], want);
        assert_same3(got, want);
    }
    lr_json_destroy(j);
    run_free(&r);

    /* The same medium given as coefficients prints the same numbers as the preset. */
    const char *preset[] = {"optics", "profile", "--material", "marble", "--r", "0.5,1,2", NULL};
    const char *coeffs[] = {"optics",          "profile",      "--sigma-a", "0.0021,0.0041,0.0071",
                            "--sigma-s-prime", "2.19,2.62,3.00", "--eta",   "1.5",
                            "--r=0.5,1,2",     NULL};
    run_result a = run(preset), b = run(coeffs);
    assert_int_equal(a.status, 0);
    assert_int_equal(b.status, 0);
    assert_string_equal(a.out, b.out);
    run_free(&a);
    run_free(&b);
}

static void test_dirpole_marble(void **state)
{
    (void)state;
    /* The reference: marble, planar, normal incidence, r = 1 mm, from an independent
     * implementation of Frisvad et al. 2014. Printed there to 7 digits: 1e-4 relative. */
    const char *args[] = {"optics", "dirpole", "--material", "marble", "--xi", "0,0,0", "--ni",
                          "0,0,1",  "--wi",    "0,0,1",      "--xo",   "1,0,0", "--no", "0,0,1",
                          NULL};
    run_result r = run(args);
    lr_json *j = parse_out(&r);
    double sd[3], sdf[3];
    get3(j, lr_json_root(j), "sd", sd);
    get3(j, lr_json_root(j), "sd_fresnel", sdf);
    const double want[3] = {1.481979e-2, 1.576677e-2, 1.620976e-2};
    for (int b = 0; b < 3; b++)
        if (fabs(sd[b] / want[b] - 1) > 1e-4)
            fail_msg("band %d: sd %.7e, want %.7e", b, sd[b], want[b]);
    /* At normal incidence F_t = 1 - ((eta - 1) / (eta + 1))^2 = 0.96 for eta 1.5; both the
     * printed values carry 17 digits, so the ratio holds to a few ulps (1e-12 relative). */
    double ft = 1 - pow((1.5 - 1) / (1.5 + 1), 2);
    for (int b = 0; b < 3; b++)
        assert_true(fabs(sdf[b] / (sd[b] * ft) - 1) < 1e-12);
    lr_json_destroy(j);

    /* Unnormalised directions are normalised: the same output, byte for byte. */
    const char *scaled[] = {"optics", "dirpole", "--material", "marble", "--xi", "0,0,0", "--ni",
                            "0,0,5",  "--wi",    "0,0,0.25",   "--xo",   "1,0,0", "--no", "0,0,2",
                            NULL};
    run_result s = run(scaled);
    assert_int_equal(s.status, 0);
    assert_string_equal(s.out, r.out);
    run_free(&s);
    run_free(&r);

    /* Oblique light on a tilted surface against the library directly. */
    const char *oblique[] = {"optics", "dirpole",  "--material", "skin2", "--xi", "0.1,0.2,0",
                             "--ni",   "0,0,1",    "--wi",       "1,0,1", "--xo", "-0.5,0.3,0.05",
                             "--no",   "0,0.6,0.8", NULL};
    r = run(oblique);
    j = parse_out(&r);
    lr_coeffs c = coeffs_of("skin2");
    double want_sd[3], want_sdf[3];
    lr_vec3 wi = lr_v3(1 / sqrt(2.0), 0, 1 / sqrt(2.0));
    lr_dirpole_sd(&c, lr_v3(0.1, 0.2, 0), lr_v3(0, 0, 1), wi, lr_v3(-0.5, 0.3, 0.05),
                  lr_v3(0, 0.6, 0.8), want_sd);
    lr_dirpole_sd_fresnel(&c, lr_v3(0.1, 0.2, 0), lr_v3(0, 0, 1), wi, lr_v3(-0.5, 0.3, 0.05),
                          lr_v3(0, 0.6, 0.8), want_sdf);
    get3(j, lr_json_root(j), "sd", sd);
    get3(j, lr_json_root(j), "sd_fresnel", sdf);
    /* 1/sqrt(2) computed here and by normalising (1,0,1) there may differ in the last bit. */
    for (int b = 0; b < 3; b++) {
        assert_true(fabs(sd[b] - want_sd[b]) <= 1e-12 * fabs(want_sd[b]));
        assert_true(fabs(sdf[b] - want_sdf[b]) <= 1e-12 * fabs(want_sdf[b]));
        assert_true(sdf[b] < sd[b]); /* F_t < 1 at 45 degrees */
    }
    lr_json_destroy(j);
    run_free(&r);
}

static void test_materials_list(void **state)
{
    (void)state;
    const char *args[] = {"optics", "materials", NULL};
    run_result r = run(args);
    lr_json *j = parse_out(&r);
    char **names = NULL;
    int n = 0;
    lr_err e = {0};
    assert_int_equal(lr_material_names(&names, &n, &e), LR_OK);
    assert_int_equal(lr_json_type(j, lr_json_root(j)), LR_JSON_ARRAY);
    assert_int_equal(lr_json_count(j, lr_json_root(j)), n);
    for (int i = 0; i < n; i++)
        assert_true(lr_json_str_eq(j, lr_json_at(j, lr_json_root(j), i), names[i]));
    assert_true(n >= 16);
    lr_material_names_free(names, n);
    lr_json_destroy(j);
    run_free(&r);
}

static void test_help(void **state)
{
    (void)state;
    const char *args[] = {"help", "optics", NULL};
    run_result r = run(args);
    assert_int_equal(r.status, 0);
    assert_non_null(strstr(r.out, "usage: lamprig optics"));
    assert_non_null(strstr(r.out, "--sigma-s-prime"));
    assert_non_null(strstr(r.out, "dirpole MATERIAL --xi"));
    run_free(&r);
    const char *list[] = {"help", NULL};
    r = run(list);
    assert_int_equal(r.status, 0);
    assert_non_null(strstr(r.out, "  optics "));
    run_free(&r);
}

/* ---- bad arguments -------------------------------------------------------------------------- */

static void test_bad_arguments(void **state)
{
    (void)state;
#define M "--material", "marble"
#define XYZ "--xi", "0,0,0", "--ni", "0,0,1", "--wi", "0,0,1", "--xo", "1,0,0", "--no", "0,0,1"
    static const struct {
        const char *args[24];
        const char *needle; /* in the one-line message */
    } cases[] = {
        {{"optics", NULL}, "missing subcommand"},
        {{"optics", "spin", NULL}, "unknown subcommand 'spin'"},
        {{"optics", "total", M, "--frobnicate", NULL}, "unknown option '--frobnicate'"},
        {{"optics", "total", M, "extra", NULL}, "unexpected argument 'extra'"},
        {{"optics", "profile", M, "--r", NULL}, "--r needs a value"},
        {{"optics", "profile", M, "--r=", NULL}, "--r needs a value"},
        {{"optics", "profile", M, "--r", "1", "--r", "2", NULL}, "--r given twice"},
        {{"optics", "profile", M, NULL}, "profile needs --r"},
        {{"optics", "profile", M, "--r", "1,,2", NULL}, "--r: item 2 of '1,,2' is empty"},
        {{"optics", "profile", M, "--r", "1,x", NULL}, "--r: 'x' is not a finite decimal number"},
        {{"optics", "profile", M, "--r", "-1", NULL}, "--r: radius 1 is -1"},
        {{"optics", "profile", M, "--r", "1e999", NULL}, "--r: '1e999' is out of range"},
        {{"optics", "total", "--sigma-a", "1,2", "--sigma-s-prime", "1,1,1", "--eta", "1.3", NULL},
         "--sigma-a: expected 3 comma-separated numbers, got 2"},
        {{"optics", "total", "--sigma-a", "1,2,3,4", "--sigma-s-prime", "1,1,1", "--eta", "1.3",
          NULL},
         "got 4"},
        {{"optics", "total", "--sigma-a", "0,0,0", "--sigma-s-prime", "1,1,1", "--eta", "abc",
          NULL},
         "--eta: 'abc' is not a finite decimal number"},
        {{"optics", "total", "--sigma-a", "0,0,0", "--sigma-s-prime", "1,1,1", "--eta", "nan",
          NULL},
         "--eta: 'nan' is not a finite decimal number"},
        {{"optics", "total", "--sigma-a", "inf,0,0", "--sigma-s-prime", "1,1,1", "--eta", "1.3",
          NULL},
         "--sigma-a: 'inf' is not a finite decimal number"},
        {{"optics", "total", "--sigma-a", "0,-0.1,0", "--sigma-s-prime", "1,1,1", "--eta", "1.3",
          NULL},
         "--sigma-a: component 2 is negative"},
        {{"optics", "total", "--sigma-a", "0,0,0", "--sigma-s-prime", "1,1,-1", "--eta", "1.3",
          NULL},
         "--sigma-s-prime: component 3 is negative"},
        {{"optics", "total", "--sigma-a", "0,0,0", "--sigma-s-prime", "1,1,1", NULL},
         "give --material NAME, or --sigma-a, --sigma-s-prime and --eta"},
        {{"optics", "total", "--sigma-a", "0,0,0", "--sigma-s-prime", "1,1,1", "--eta", "0", NULL},
         "eta = 0"},
        {{"optics", "total", "--sigma-a", "0,0,0", "--sigma-s-prime", "1,1,1", "--eta", "1.3",
          "--g", "1", NULL},
         "g = 1"},
        {{"optics", "total", "--sigma-a", "0,0,0", "--sigma-s-prime", "0,1,1", "--eta", "1.3",
          NULL},
         "sigma_t_prime[0]"},
        {{"optics", "total", "--eta", "1,2", M, NULL}, "--material cannot be combined"},
        {{"optics", "total", M, "--sigma-a", "0,0,0", NULL}, "--material cannot be combined"},
        {{"optics", "total", "--material", "nosuch", NULL}, "no preset 'nosuch'"},
        {{"optics", "total", "--material", "../configs/materials/marble", NULL},
         "is not a preset name"},
        {{"optics", "dirpole", M, "--xi", "0,0,0", "--ni", "0,0,1", "--wi", "0,0,1", "--no",
          "0,0,1", NULL},
         "dirpole needs --xo x,y,z"},
        {{"optics", "dirpole", M, "--xi", "0,0,0", "--ni", "0,0,0", "--wi", "0,0,1", "--xo",
          "1,0,0", "--no", "0,0,1", NULL},
         "--ni: a direction must have non-zero, finite length"},
        {{"optics", "dirpole", M, "--xi", "0,0,0", "--ni", "0,0,1", "--wi", "0,0,-1", "--xo",
          "1,0,0", "--no", "0,0,1", NULL},
         "--wi points below the surface"},
        {{"optics", "dirpole", M, "--xi", "0,0", "--ni", "0,0,1", "--wi", "0,0,1", "--xo",
          "1,0,0", "--no", "0,0,1", NULL},
         "--xi: expected 3 comma-separated numbers, got 2"},
        {{"optics", "dirpole", M, XYZ, "--r", "1", NULL}, "unknown option '--r'"},
        {{"optics", "materials", "--material", "marble", NULL}, "unknown option '--material'"},
        {{"optics", "total", "--material", "bad\nname", NULL}, "'bad?name' is not a preset name"},
    };
#undef M
#undef XYZ
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        run_result r = run(cases[i].args);
        if (r.status != LR_EXIT_USAGE)
            fail_msg("case %zu (%s): status %d, stderr '%s'", i, cases[i].needle, r.status, r.err);
        /* One line, prefixed, nothing on stdout. */
        size_t len = strlen(r.err);
        if (len == 0 || r.err[len - 1] != '\n' || strchr(r.err, '\n') != r.err + len - 1)
            fail_msg("case %zu: not one line: '%s'", i, r.err);
        assert_int_equal(strncmp(r.err, "lamprig optics: ", 16), 0);
        if (!strstr(r.err, cases[i].needle))
            fail_msg("case %zu: '%s' lacks '%s'", i, r.err, cases[i].needle);
        assert_string_equal(r.out, "");
        run_free(&r);
    }
}

/* ---- plot ----------------------------------------------------------------------------------- */

/* Pixels whose colour is near the curve colour of band b: the dominant channel of that colour
 * well above the others (antialiased edges blend with white and fail this, line cores pass). */
static int count_band_pixels(cairo_surface_t *s, int b)
{
    int w = cairo_image_surface_get_width(s), h = cairo_image_surface_get_height(s);
    int stride = cairo_image_surface_get_stride(s);
    unsigned char *data = cairo_image_surface_get_data(s);
    int n = 0;
    for (int y = 0; y < h; y++) {
        for (int x = 0; x < w; x++) {
            uint32_t px = *(uint32_t *)(data + y * stride + 4 * x);
            double rgb[3] = {((px >> 16) & 0xff) / 255.0, ((px >> 8) & 0xff) / 255.0,
                             (px & 0xff) / 255.0};
            double d = 0;
            for (int k = 0; k < 3; k++)
                d = fmax(d, fabs(rgb[k] - lr_profile_plot_colour[b][k]));
            n += d < 0.12;
        }
    }
    return n;
}

static int count_dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *de;
    while ((de = readdir(d)) != NULL)
        n += strcmp(de->d_name, ".") && strcmp(de->d_name, "..");
    closedir(d);
    return n;
}

static void test_plot_png(void **state)
{
    (void)state;
    char dir[] = "/tmp/lamprig-plot-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/marble.png", dir);
    const char *args[] = {"optics", "profile", "--material", "marble", "--plot", path, NULL};
    run_result r = run(args);
    lr_json *j = parse_out(&r);
    /* Without --r: 200 radii, log-spaced (constant ratio) and increasing. */
    lr_jnode rs = lr_json_get(j, lr_json_root(j), "r");
    assert_int_equal(lr_json_count(j, rs), 200);
    double r0, r1, rlast;
    lr_err e = {0};
    assert_int_equal(lr_json_number(j, lr_json_at(j, rs, 0), "r", &r0, &e), LR_OK);
    assert_int_equal(lr_json_number(j, lr_json_at(j, rs, 1), "r", &r1, &e), LR_OK);
    assert_int_equal(lr_json_number(j, lr_json_at(j, rs, 199), "r", &rlast, &e), LR_OK);
    lr_coeffs c = coeffs_of("marble");
    /* From 1/20 of the shortest mean free path (blue, 1/3.0071 mm) ... */
    assert_true(fabs(r0 - c.mfp[2] / 20) < 1e-15);
    /* ... to where red, the slowest band, has decayed by e^-10 (10 / sigma_tr = 85 mm). */
    assert_true(fabs(rlast / (10 / c.sigma_tr[0]) - 1) < 1e-12);
    assert_true(r1 > r0);
    lr_json_destroy(j);
    run_free(&r);

    cairo_surface_t *s = cairo_image_surface_create_from_png(path);
    assert_int_equal(cairo_surface_status(s), CAIRO_STATUS_SUCCESS);
    assert_int_equal(cairo_image_surface_get_width(s), LR_PROFILE_PLOT_WIDTH);
    assert_int_equal(cairo_image_surface_get_height(s), LR_PROFILE_PLOT_HEIGHT);
    /* Each curve spans the plot (about 670 px wide at 2.5 px line width: thousands of pixels);
     * the legend swatch alone is about 60 px. 500 proves a curve is drawn in each colour. */
    for (int b = 0; b < 3; b++) {
        int n = count_band_pixels(s, b);
        if (n < 500)
            fail_msg("band %d: only %d pixels of its colour", b, n);
    }
    cairo_surface_destroy(s);
    /* Written atomically: only the PNG is left, no temp file beside it. */
    assert_int_equal(count_dir_entries(dir), 1);

    /* An unwritable destination fails with status 1 and leaves nothing. */
    char bad[96];
    snprintf(bad, sizeof bad, "%s/no/such/dir/x.png", dir);
    const char *args2[] = {"optics", "profile", "--material", "marble", "--plot", bad, NULL};
    r = run(args2);
    assert_int_equal(r.status, LR_EXIT_FAIL);
    assert_non_null(strstr(r.err, "--plot"));
    assert_string_equal(r.out, "");
    run_free(&r);

    /* A plot with explicit radii: one r > 0 is not enough for a log axis. */
    const char *args3[] = {"optics", "profile", "--material", "marble", "--r", "0,1", "--plot",
                           path, NULL};
    r = run(args3);
    assert_int_equal(r.status, LR_EXIT_USAGE);
    assert_non_null(strstr(r.err, "at least two distinct r > 0"));
    run_free(&r);

    unlink(path);
    rmdir(dir);
}

int main(void)
{
    setenv("LAMPRIG_CONFIGS", LR_SOURCE_CONFIGS, 1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_total),          cmocka_unit_test(test_profile),
        cmocka_unit_test(test_dirpole_marble), cmocka_unit_test(test_materials_list),
        cmocka_unit_test(test_help),           cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_plot_png),
    };
    int failed = cmocka_run_group_tests_name("cli_optics", tests, NULL, NULL);
    /* cairo keeps its toy-font faces (and through them fontconfig patterns) cached for the
     * life of the process; release them so that LeakSanitizer sees only our own memory. */
    cairo_debug_reset_static_data();
    return failed;
}
