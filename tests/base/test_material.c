/* Materials: the shipped presets (values, provenance, derived quantities) and every loading
 * error naming the file, the line and the field. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "tests/support/fs.h"

#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/base/json.h"
#include "render/material/material.h"
#include "render/optics/optics.h"

/* ---- helpers ---------------------------------------------------------------------------- */

static char tmpdir[64];

static void write_file(const char *dir, const char *name, const char *text)
{
    free(lr_test_write(dir, name, text, (size_t)-1));
}

static void remove_tree(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        if (!strcmp(de->d_name, ".") || !strcmp(de->d_name, ".."))
            continue;
        char path[PATH_MAX];
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        if (de->d_type == DT_DIR)
            remove_tree(path);
        else
            unlink(path);
    }
    closedir(d);
    rmdir(dir);
}

static int setup_tmp(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/lamprig-material-XXXXXX");
    assert_non_null(mkdtemp(tmpdir));
    return 0;
}

static int teardown_tmp(void **state)
{
    (void)state;
    remove_tree(tmpdir);
    /* Back to the shipped presets for the next test. */
    setenv("LAMPRIG_CONFIGS", LR_SOURCE_CONFIGS, 1);
    return 0;
}

/* Loads DIR/name and expects failure with exactly "DIR/name" + tail. */
static void expect_load_error(const char *name, int code, const char *tail)
{
    char path[256], want[1024];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    snprintf(want, sizeof want, "%s%s", path, tail);
    lr_material m;
    lr_err e = {0};
    int rc = lr_material_load(path, &m, &e);
    if (rc != code || strcmp(e.msg, want) != 0)
        fail_msg("load %s: rc %d (want %d)\n got  '%s'\n want '%s'", name, rc, code, e.msg, want);
}

/* ---- shipped presets ---------------------------------------------------------------------- */

/* Jensen et al. 2001, Fig. 5, transcribed here independently of configs/materials (from the
 * paper's table as reproduced in pbrt-v3's SubsurfaceParameterTable, mm^-1). The comparison is
 * exact: both sides are the same decimal literals parsed by a correctly rounding strtod. */
static const struct {
    const char *name;
    double sigma_s_prime[3], sigma_a[3], eta;
} jensen[] = {
    {"apple", {2.29, 2.39, 1.97}, {0.0030, 0.0034, 0.046}, 1.3},
    {"chicken1", {0.15, 0.21, 0.38}, {0.015, 0.077, 0.19}, 1.3},
    {"chicken2", {0.19, 0.25, 0.32}, {0.018, 0.088, 0.20}, 1.3},
    {"cream", {7.38, 5.47, 3.15}, {0.0002, 0.0028, 0.0163}, 1.3},
    {"ketchup", {0.18, 0.07, 0.03}, {0.061, 0.97, 1.45}, 1.3},
    {"marble", {2.19, 2.62, 3.00}, {0.0021, 0.0041, 0.0071}, 1.5},
    {"potato", {0.68, 0.70, 0.55}, {0.0024, 0.0090, 0.12}, 1.3},
    {"skimmilk", {0.70, 1.22, 1.90}, {0.0014, 0.0025, 0.0142}, 1.3},
    {"skin1", {0.74, 0.88, 1.01}, {0.032, 0.17, 0.48}, 1.3},
    {"skin2", {1.09, 1.59, 1.79}, {0.013, 0.070, 0.145}, 1.3},
    {"spectralon", {11.6, 20.4, 14.9}, {0.00, 0.00, 0.00}, 1.3},
    {"wholemilk", {2.55, 3.21, 3.77}, {0.0011, 0.0024, 0.014}, 1.3},
};
#define N_JENSEN ((int)(sizeof jensen / sizeof jensen[0]))

static void test_jensen_values_exact(void **state)
{
    (void)state;
    for (int i = 0; i < N_JENSEN; i++) {
        lr_material m;
        lr_err e = {0};
        if (lr_material_find(jensen[i].name, &m, &e) != LR_OK)
            fail_msg("%s: %s", jensen[i].name, e.msg);
        assert_string_equal(m.name, jensen[i].name);
        for (int b = 0; b < 3; b++) {
            if (m.medium.sigma_a[b] != jensen[i].sigma_a[b] ||
                m.medium.sigma_s_prime[b] != jensen[i].sigma_s_prime[b])
                fail_msg("%s band %d: sigma_a %.17g sigma_s' %.17g", jensen[i].name, b,
                         m.medium.sigma_a[b], m.medium.sigma_s_prime[b]);
        }
        assert_true(m.medium.eta == jensen[i].eta);
        assert_true(m.medium.g == 0.0);
        /* Each file says where its numbers come from. */
        assert_non_null(strstr(m.source, "Jensen"));
        assert_non_null(strstr(m.source, "2001"));
    }
}

static void test_every_preset_loads(void **state)
{
    (void)state;
    static const char *const expected[] = {
        "apple",      "candle_wax", "chicken1",  "chicken2", "cream",    "fabric_shade",
        "ketchup",    "marble",     "paper_shade", "porcelain", "potato", "skimmilk",
        "skin1",      "skin2",      "spectralon", "wholemilk"};
    char **names = NULL;
    int n = 0;
    lr_err e = {0};
    assert_int_equal(lr_material_names(&names, &n, &e), LR_OK);
    /* Exactly the shipped set, sorted (configs/materials/README.md is not a preset). */
    assert_int_equal(n, (int)(sizeof expected / sizeof expected[0]));
    for (int i = 0; i < n; i++) {
        assert_string_equal(names[i], expected[i]);
        lr_material m;
        if (lr_material_find(names[i], &m, &e) != LR_OK)
            fail_msg("%s: %s", names[i], e.msg);
        assert_true(strlen(m.source) > 40); /* a citation or a derivation, not a placeholder */
        lr_coeffs c;
        assert_int_equal(lr_coeffs_derive(&m.medium, &c, &e), LR_OK);
        double total[3];
        lr_dipole_rd_total(&c, total);
        for (int b = 0; b < 3; b++)
            assert_true(total[b] >= 0.0 && total[b] <= 1.0);
    }
    lr_material_names_free(names, n);
}

static void test_derived_quantities_sane(void **state)
{
    (void)state;
    lr_material m;
    lr_coeffs c;
    lr_err e = {0};
    double total[3];
    /* Marble scatters almost without loss: albedo' = 2.19 / 2.1921 = 0.99904 in red, the
     * lowest band (blue) 3.00 / 3.0071 = 0.99764. */
    assert_int_equal(lr_material_find("marble", &m, &e), LR_OK);
    assert_int_equal(lr_coeffs_derive(&m.medium, &c, &e), LR_OK);
    for (int b = 0; b < 3; b++)
        assert_true(c.albedo_prime[b] > 0.99);
    /* Ketchup is red: red light survives, blue is absorbed (sigma_a 1.45 vs sigma_s' 0.03). */
    assert_int_equal(lr_material_find("ketchup", &m, &e), LR_OK);
    assert_int_equal(lr_coeffs_derive(&m.medium, &c, &e), LR_OK);
    lr_dipole_rd_total(&c, total);
    assert_true(total[0] > 10 * total[1] && total[1] > total[2]);
    /* Spectralon does not absorb: albedo' exactly 1 and sigma_tr exactly 0 (no light lost). */
    assert_int_equal(lr_material_find("spectralon", &m, &e), LR_OK);
    assert_int_equal(lr_coeffs_derive(&m.medium, &c, &e), LR_OK);
    for (int b = 0; b < 3; b++) {
        assert_true(c.albedo_prime[b] == 1.0);
        assert_true(c.sigma_tr[b] == 0.0);
    }
    /* The chicken1 source claims red Rd_total 0.31 (dipole, eta 1.3) with sigma_a 0.015;
     * the closed form gives 0.3137. Tolerance 0.005: the claim is quoted to two digits. */
    assert_int_equal(lr_material_find("chicken1", &m, &e), LR_OK);
    assert_int_equal(lr_coeffs_derive(&m.medium, &c, &e), LR_OK);
    lr_dipole_rd_total(&c, total);
    assert_true(fabs(total[0] - 0.31) < 0.005);
    /* ... and 0.65 with Mitsuba's 0.0015. */
    m.medium.sigma_a[0] = 0.0015;
    assert_int_equal(lr_coeffs_derive(&m.medium, &c, &e), LR_OK);
    lr_dipole_rd_total(&c, total);
    assert_true(fabs(total[0] - 0.65) < 0.005);
}

static void test_candle_wax_is_scaled_marble(void **state)
{
    (void)state;
    lr_material wax, marble;
    lr_err e = {0};
    assert_int_equal(lr_material_find("candle_wax", &wax, &e), LR_OK);
    assert_int_equal(lr_material_find("marble", &marble, &e), LR_OK);
    /* scale 0.5 is exact in binary: the product is exact. */
    for (int b = 0; b < 3; b++) {
        assert_true(wax.medium.sigma_a[b] == 0.5 * marble.medium.sigma_a[b]);
        assert_true(wax.medium.sigma_s_prime[b] == 0.5 * marble.medium.sigma_s_prime[b]);
    }
    assert_true(wax.medium.eta == 1.44); /* the override, not marble's 1.5 */
    /* What its source claims: diffusion lengths 17, 11, 8 mm and a 1 cm wall passing
     * exp(-10 sigma_tr) = 0.56, 0.41, 0.28 (quoted to 2 digits: tolerances half a unit of the
     * last quoted digit). */
    lr_coeffs c;
    assert_int_equal(lr_coeffs_derive(&wax.medium, &c, &e), LR_OK);
    const double len[3] = {17, 11, 8}, pass[3] = {0.56, 0.41, 0.28};
    for (int b = 0; b < 3; b++) {
        assert_true(fabs(1.0 / c.sigma_tr[b] - len[b]) < 0.5);
        assert_true(fabs(exp(-10.0 * c.sigma_tr[b]) - pass[b]) < 0.005);
    }
}

/* Kubelka-Munk slab (Kubelka 1948) without interface reflection: reflectance over black R0 and
 * diffuse transmittance T of thickness d, from K = 2 sigma_a, S = 3/4 sigma_s' - 1/4 sigma_a
 * (the mapping the shade presets' sources state). */
static void km_slab(double sigma_a, double sigma_s_prime, double d, double *R0, double *T)
{
    double K = 2 * sigma_a, S = 0.75 * sigma_s_prime - 0.25 * sigma_a;
    double a = (S + K) / S, b = sqrt(a * a - 1), x = b * S * d;
    double den = a * sinh(x) + b * cosh(x);
    *R0 = sinh(x) / den;
    *T = b / den;
}

static void test_shades_reproduce_their_stated_sheets(void **state)
{
    (void)state;
    /* The targets quoted in each preset's source. The coefficients were rounded to 3
     * significant digits after inverting KM; that moves R0 and T by < 0.001, so 0.002 is the
     * tolerance. */
    static const struct {
        const char *name;
        double d, R0[3], T[3];
    } sheets[] = {
        {"paper_shade", 0.1, {0.79, 0.79, 0.76}, {0.18, 0.18, 0.16}},
        {"fabric_shade", 0.3, {0.62, 0.60, 0.55}, {0.33, 0.31, 0.27}},
        {"porcelain", 1.0, {0.70, 0.69, 0.66}, {0.14, 0.12, 0.09}},
    };
    for (size_t i = 0; i < sizeof sheets / sizeof sheets[0]; i++) {
        lr_material m;
        lr_err e = {0};
        assert_int_equal(lr_material_find(sheets[i].name, &m, &e), LR_OK);
        char d[16];
        snprintf(d, sizeof d, "%g mm", sheets[i].d);
        assert_non_null(strstr(m.source, d)); /* the stated thickness is the one tested */
        for (int b = 0; b < 3; b++) {
            double R0, T;
            km_slab(m.medium.sigma_a[b], m.medium.sigma_s_prime[b], sheets[i].d, &R0, &T);
            if (fabs(R0 - sheets[i].R0[b]) > 0.002 || fabs(T - sheets[i].T[b]) > 0.002)
                fail_msg("%s band %d: R0 %.4f T %.4f", sheets[i].name, b, R0, T);
        }
    }
}

/* ---- loading errors ------------------------------------------------------------------------ */

static const char good_head[] = "{\n  \"name\": \"x\",\n  \"source\": \"test\",\n";

static void test_errors_name_file_line_field(void **state)
{
    (void)state;
    char text[1024];
    /* Wrong type. */
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0.1, 0.2, 0.3],\n  \"sigma_s_prime\": [1, 1, 1],\n"
             "  \"eta\": \"1.3\"\n}\n",
             good_head);
    write_file(tmpdir, "type.json", text);
    expect_load_error("type.json", LR_EPARSE, ":6: field 'eta': expected a number, got a string");
    /* Missing field: the object's line. */
    write_file(tmpdir, "missing.json",
               "{\n  \"name\": \"x\",\n  \"source\": \"test\",\n  \"sigma_s_prime\": [1, 1, 1],\n"
               "  \"eta\": 1.3\n}\n");
    expect_load_error("missing.json", LR_EPARSE,
                      ":1: field 'sigma_a': missing (required unless 'base' is given)");
    /* Negative coefficient: the element's line and index. */
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0.1,\n    -0.2, 0.3],\n  \"sigma_s_prime\": [1, 1, 1],\n"
             "  \"eta\": 1.3\n}\n",
             good_head);
    write_file(tmpdir, "negative.json", text);
    expect_load_error("negative.json", LR_EINVAL,
                      ":5: field 'sigma_a[1]': must be >= 0 (mm^-1), got -0.2");
    /* Wrong count. */
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0.1, 0.2, 0.3],\n  \"sigma_s_prime\": [1, 1],\n  \"eta\": 1.3\n}\n",
             good_head);
    write_file(tmpdir, "count.json", text);
    expect_load_error("count.json", LR_EPARSE, ":5: field 'sigma_s_prime': expected 3 numbers, got 2");
    /* Unknown field (a typo). */
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0.1, 0.2, 0.3],\n  \"sigma_s_prime\": [1, 1, 1],\n  \"eta\": 1.3,\n"
             "  \"colour\": [1, 1, 1]\n}\n",
             good_head);
    write_file(tmpdir, "unknown.json", text);
    expect_load_error("unknown.json", LR_EPARSE, ":7: field 'colour': unknown field in material");
    /* Duplicate field. */
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0.1, 0.2, 0.3],\n  \"sigma_s_prime\": [1, 1, 1],\n  \"eta\": 1.3,\n"
             "  \"eta\": 1.4\n}\n",
             good_head);
    write_file(tmpdir, "dup.json", text);
    expect_load_error("dup.json", LR_EPARSE, ":7: field 'eta': duplicate key (first on line 6)");
    /* Malformed JSON: file and line (there is no field to name). */
    write_file(tmpdir, "malformed.json", "{\n  \"name\": \"x\",\n  \"eta\": ,\n}\n");
    lr_material m;
    lr_err e = {0};
    char path[256], want[512];
    snprintf(path, sizeof path, "%s/malformed.json", tmpdir);
    assert_int_equal(lr_material_load(path, &m, &e), LR_EPARSE);
    snprintf(want, sizeof want, "%s:3: ", path);
    if (strncmp(e.msg, want, strlen(want)) != 0)
        fail_msg("got '%s', want prefix '%s'", e.msg, want);
    /* Missing and empty source: provenance is required. */
    write_file(tmpdir, "nosource.json",
               "{\n  \"name\": \"x\",\n  \"sigma_a\": [0, 0, 0],\n  \"sigma_s_prime\": [1, 1, 1],\n"
               "  \"eta\": 1.3\n}\n");
    expect_load_error("nosource.json", LR_EPARSE,
                      ":1: field 'source': missing (required: cite where the numbers come from)");
    write_file(tmpdir, "emptysource.json",
               "{\n  \"name\": \"x\",\n  \"source\": \"\",\n  \"sigma_a\": [0, 0, 0],\n"
               "  \"sigma_s_prime\": [1, 1, 1],\n  \"eta\": 1.3\n}\n");
    expect_load_error("emptysource.json", LR_EINVAL,
                      ":3: field 'source': must not be empty (cite where the numbers come from)");
    /* Out of range: g, eta (the optics' range, reported at the eta line), sigma_t' == 0. */
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0.1, 0.2, 0.3],\n  \"sigma_s_prime\": [1, 1, 1],\n  \"eta\": 1.3,\n"
             "  \"g\": 1\n}\n",
             good_head);
    write_file(tmpdir, "g.json", text);
    expect_load_error("g.json", LR_EINVAL, ":7: field 'g': must be in (-1, 1), got 1");
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0.1, 0.2, 0.3],\n  \"sigma_s_prime\": [1, 1, 1],\n  \"eta\": 3\n}\n",
             good_head);
    write_file(tmpdir, "eta.json", text);
    snprintf(path, sizeof path, "%s/eta.json", tmpdir);
    assert_int_equal(lr_material_load(path, &m, &e), LR_EINVAL);
    snprintf(want, sizeof want, "%s:6: field 'eta': ", path);
    if (strncmp(e.msg, want, strlen(want)) != 0 || !strstr(e.msg, "eta = 3"))
        fail_msg("got '%s', want prefix '%s'", e.msg, want);
    snprintf(text, sizeof text,
             "%s  \"sigma_a\": [0, 0, 0],\n  \"sigma_s_prime\": [1, 0, 1],\n  \"eta\": 1.3\n}\n",
             good_head);
    write_file(tmpdir, "zero.json", text);
    snprintf(path, sizeof path, "%s/zero.json", tmpdir);
    assert_int_equal(lr_material_load(path, &m, &e), LR_EINVAL);
    snprintf(want, sizeof want, "%s:5: field 'sigma_s_prime': ", path);
    if (strncmp(e.msg, want, strlen(want)) != 0 || !strstr(e.msg, "sigma_t_prime[1]"))
        fail_msg("got '%s', want prefix '%s' and band 1", e.msg, want);
    /* Not a file at all. */
    snprintf(path, sizeof path, "%s/absent.json", tmpdir);
    assert_int_equal(lr_material_load(path, &m, &e), LR_EIO);
    assert_non_null(strstr(e.msg, "absent.json: cannot open"));
}

static void test_base_and_scale(void **state)
{
    (void)state;
    write_file(tmpdir, "milk.json",
               "{\"name\": \"milk\", \"source\": \"test\", \"sigma_a\": [0.25, 0.5, 1],\n"
               " \"sigma_s_prime\": [2, 4, 8], \"eta\": 1.3, \"g\": 0.5}\n");
    /* RGB scale and an override: the override is taken as given, the rest scaled. */
    write_file(tmpdir, "thin.json",
               "{\"name\": \"thin\", \"source\": \"test\", \"base\": \"milk\",\n"
               " \"scale\": [0.5, 2, 4], \"sigma_a\": [0.1, 0.1, 0.1]}\n");
    char path[256];
    snprintf(path, sizeof path, "%s/thin.json", tmpdir);
    lr_material m;
    lr_err e = {0};
    if (lr_material_load(path, &m, &e) != LR_OK)
        fail_msg("%s", e.msg);
    assert_string_equal(m.name, "thin");
    const double ssp[3] = {1, 8, 32};
    for (int b = 0; b < 3; b++) {
        assert_true(m.medium.sigma_a[b] == 0.1);
        assert_true(m.medium.sigma_s_prime[b] == ssp[b]); /* powers of two: exact */
    }
    assert_true(m.medium.eta == 1.3 && m.medium.g == 0.5); /* inherited */
    /* Two levels: a scalar scale on a scaled preset multiplies again. */
    write_file(tmpdir, "thinner.json",
               "{\"name\": \"thinner\", \"source\": \"test\", \"base\": \"thin\", \"scale\": 0.25}\n");
    snprintf(path, sizeof path, "%s/thinner.json", tmpdir);
    assert_int_equal(lr_material_load(path, &m, &e), LR_OK);
    assert_true(m.medium.sigma_a[2] == 0.025 && m.medium.sigma_s_prime[2] == 8);

    /* Errors around base/scale, each at its line and field. */
    write_file(tmpdir, "cyc_a.json",
               "{\"name\": \"cyc_a\", \"source\": \"test\",\n \"base\": \"cyc_b\"}\n");
    write_file(tmpdir, "cyc_b.json",
               "{\"name\": \"cyc_b\", \"source\": \"test\",\n\n \"base\": \"cyc_a\"}\n");
    char tail[600];
    snprintf(tail, sizeof tail,
             ":2: field 'base': in base preset 'cyc_b': %s/cyc_b.json:3: field 'base': base "
             "cycle: cyc_a -> cyc_b -> cyc_a",
             tmpdir);
    expect_load_error("cyc_a.json", LR_EINVAL, tail);
    write_file(tmpdir, "self.json", "{\"name\": \"self\", \"source\": \"t\", \"base\": \"self\"}\n");
    expect_load_error("self.json", LR_EINVAL, ":1: field 'base': base cycle: self -> self");
    write_file(tmpdir, "nobase.json",
               "{\"name\": \"x\", \"source\": \"t\",\n \"base\": \"nosuch\"}\n");
    snprintf(tail, sizeof tail,
             ":2: field 'base': no preset 'nosuch' (%s/nosuch.json not found)", tmpdir);
    expect_load_error("nobase.json", LR_EIO, tail);
    write_file(tmpdir, "escape.json",
               "{\"name\": \"x\", \"source\": \"t\",\n \"base\": \"../milk\"}\n");
    expect_load_error("escape.json", LR_EINVAL,
                      ":2: field 'base': '../milk' is not a preset name (letters, digits, '_', "
                      "'-', '.'; no '/' or leading '.')");
    write_file(tmpdir, "scale_only.json",
               "{\"name\": \"x\", \"source\": \"t\", \"sigma_a\": [0, 0, 0],\n"
               " \"sigma_s_prime\": [1, 1, 1], \"eta\": 1.3,\n \"scale\": 2}\n");
    expect_load_error("scale_only.json", LR_EPARSE,
                      ":3: field 'scale': needs 'base' (scale multiplies the base preset's "
                      "coefficients)");
    write_file(tmpdir, "scale_neg.json",
               "{\"name\": \"x\", \"source\": \"t\", \"base\": \"milk\",\n"
               " \"scale\": [1,\n -1, 1]}\n");
    expect_load_error("scale_neg.json", LR_EINVAL, ":3: field 'scale': must be > 0, got -1");
    write_file(tmpdir, "scale_str.json",
               "{\"name\": \"x\", \"source\": \"t\", \"base\": \"milk\",\n \"scale\": \"2\"}\n");
    expect_load_error("scale_str.json", LR_EPARSE,
                      ":2: field 'scale': expected a number or an array of 3 numbers, got a string");
    /* A broken base names the base's own file and line. */
    write_file(tmpdir, "broken.json",
               "{\"name\": \"broken\", \"source\": \"t\", \"sigma_a\": [0, 0, 0],\n"
               " \"sigma_s_prime\": [1, 1, 1],\n \"eta\": -1}\n");
    write_file(tmpdir, "on_broken.json",
               "{\"name\": \"x\", \"source\": \"t\", \"base\": \"broken\"}\n");
    snprintf(tail, sizeof tail,
             ":1: field 'base': in base preset 'broken': %s/broken.json:3: field 'eta': "
             "relative index of refraction must be > 0, got -1",
             tmpdir);
    expect_load_error("on_broken.json", LR_EINVAL, tail);
}

static void test_find_and_names(void **state)
{
    (void)state;
    char dir[128];
    snprintf(dir, sizeof dir, "%s/materials", tmpdir);
    assert_int_equal(mkdir(dir, 0755), 0);
    write_file(dir, "b.json", "{\"name\": \"b\", \"source\": \"t\", \"sigma_a\": [0, 0, 0],"
                              " \"sigma_s_prime\": [1, 1, 1], \"eta\": 1.3}\n");
    write_file(dir, "a.json", "{\"name\": \"a\", \"source\": \"t\", \"base\": \"b\"}\n");
    write_file(dir, "wrong.json", "{\"name\": \"right\", \"source\": \"t\", \"base\": \"b\"}\n");
    write_file(dir, "README.md", "not a preset\n");
    write_file(dir, ".hidden.json", "{}\n");
    write_file(dir, "has space.json", "{}\n");
    setenv("LAMPRIG_CONFIGS", tmpdir, 1);

    char **names = NULL;
    int n = 0;
    lr_err e = {0};
    assert_int_equal(lr_material_names(&names, &n, &e), LR_OK);
    assert_int_equal(n, 3);
    assert_string_equal(names[0], "a");
    assert_string_equal(names[1], "b");
    assert_string_equal(names[2], "wrong");
    lr_material_names_free(names, n);

    lr_material m;
    assert_int_equal(lr_material_find("a", &m, &e), LR_OK);
    assert_true(m.medium.sigma_s_prime[0] == 1.0);
    /* The name inside must match the file it was found by. */
    assert_int_equal(lr_material_find("wrong", &m, &e), LR_EINVAL);
    char want[600];
    snprintf(want, sizeof want,
             "%s/wrong.json:1: field 'name': is 'right' but the preset file is named "
             "'wrong.json' (they must agree)",
             dir);
    assert_string_equal(e.msg, want);
    /* Only plain names: no way out of the presets directory. */
    static const char *const bad[] = {"../etc/passwd", "a/b", "..", ".hidden", "", "a b"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(lr_material_find(bad[i], &m, &e), LR_EINVAL);
        assert_non_null(strstr(e.msg, "not a preset name"));
    }
    assert_int_equal(lr_material_find("nosuch", &m, &e), LR_EIO);
    assert_non_null(strstr(e.msg, "nosuch.json: cannot open"));
    /* No presets directory at all. */
    setenv("LAMPRIG_CONFIGS", "/nonexistent-lamprig", 1);
    assert_int_equal(lr_material_names(&names, &n, &e), LR_EIO);
    assert_null(names);
    assert_int_equal(n, 0);
}

static void test_embedded_in_scene(void **state)
{
    (void)state;
    const char *scene = "{\n  \"objects\": [\n    {\"material\": {\n"
                        "      \"name\": \"wax2\", \"source\": \"scene test\",\n"
                        "      \"base\": \"marble\", \"scale\": 2}},\n"
                        "    {\"material\": {\"name\": \"bad\", \"source\": \"t\",\n"
                        "      \"sigma_a\": [0, 0,\n -1], \"sigma_s_prime\": [1, 1, 1], \"eta\": 1}}\n"
                        "  ]\n}\n";
    lr_json *j = NULL;
    lr_err e = {0};
    assert_int_equal(lr_json_parse(scene, strlen(scene), "scene.json", &j, &e), LR_OK);
    lr_jnode objs = lr_json_get(j, lr_json_root(j), "objects");
    lr_material m;
    /* base resolves among the shipped presets (marble x 2; doubling is exact). */
    if (lr_material_from_json(j, lr_json_get(j, lr_json_at(j, objs, 0), "material"),
                              "objects[0].material", &m, &e) != LR_OK)
        fail_msg("%s", e.msg);
    assert_string_equal(m.name, "wax2");
    assert_true(m.medium.sigma_s_prime[0] == 2 * 2.19 && m.medium.sigma_a[2] == 2 * 0.0071);
    assert_true(m.medium.eta == 1.5);
    assert_int_equal(lr_material_from_json(j, lr_json_get(j, lr_json_at(j, objs, 1), "material"),
                                           "objects[1].material", &m, &e),
                     LR_EINVAL);
    assert_string_equal(e.msg, "scene.json:8: field 'objects[1].material.sigma_a[2]': must be "
                               ">= 0 (mm^-1), got -1");
    /* An unknown key names the object. */
    lr_json_destroy(j);
    const char *typo = "{\"m\": {\"name\": \"x\", \"source\": \"t\", \"base\": \"marble\",\n"
                       " \"sclae\": 2}}";
    assert_int_equal(lr_json_parse(typo, strlen(typo), "s2.json", &j, &e), LR_OK);
    assert_int_equal(lr_material_from_json(j, lr_json_get(j, lr_json_root(j), "m"), "m", &m, &e),
                     LR_EPARSE);
    assert_string_equal(e.msg, "s2.json:2: field 'sclae': unknown field in m");
    lr_json_destroy(j);
}

int main(void)
{
    /* The shipped presets, wherever the test is run from. */
    setenv("LAMPRIG_CONFIGS", LR_SOURCE_CONFIGS, 1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_jensen_values_exact),
        cmocka_unit_test(test_every_preset_loads),
        cmocka_unit_test(test_derived_quantities_sane),
        cmocka_unit_test(test_candle_wax_is_scaled_marble),
        cmocka_unit_test(test_shades_reproduce_their_stated_sheets),
        cmocka_unit_test_setup_teardown(test_errors_name_file_line_field, setup_tmp, teardown_tmp),
        cmocka_unit_test_setup_teardown(test_base_and_scale, setup_tmp, teardown_tmp),
        cmocka_unit_test_setup_teardown(test_find_and_names, setup_tmp, teardown_tmp),
        cmocka_unit_test(test_embedded_in_scene),
    };
    return cmocka_run_group_tests_name("material", tests, NULL, NULL);
}
