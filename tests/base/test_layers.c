/* The tree's include graph against docs/layers.txt: no include goes up a layer, no folder is
 * left out of the layers, no cycle between folders; and no model-id comparison outside
 * render/models/ (render/models/model.h). Each checker is first shown to catch each kind of
 * problem on a small tree made here, so a pass on the real tree means something. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/support/fs.h"
#include "tests/support/include_graph.h"
#include "tests/support/model_ids.h"

#define ROOT LR_SOURCE_CONFIGS "/.."
#define REPORT_MAX 65536

static char report[REPORT_MAX];

/* A tree of four folders in two layers, low (a, c, d) and high (b). */
static char *small_tree(const char *layers)
{
    char *dir = lr_test_tmpdir();
    free(lr_test_write(dir, "layers.txt", layers, (size_t)-1));
    free(lr_test_write(dir, "a/x.h", "#include <stdio.h>\n#include \"a/own.h\"\n", (size_t)-1));
    free(lr_test_write(dir, "a/own.h", "/* nothing */\n", (size_t)-1));
    free(lr_test_write(dir, "b/y.c", "#include \"a/x.h\"\n#include \"y.h\"\n", (size_t)-1));
    free(lr_test_write(dir, "b/y.h", "\n", (size_t)-1));
    free(lr_test_write(dir, "c/p.h", "\n", (size_t)-1));
    free(lr_test_write(dir, "d/q.h", "#include \"c/p.h\"\n", (size_t)-1));
    return dir;
}

static int check(const char *dir)
{
    char *layers = lr_test_path(dir, "layers.txt");
    int n = lr_test_check_layers(dir, layers, report, sizeof report);
    free(layers);
    return n;
}

static void test_clean_tree_passes(void **state)
{
    (void)state;
    char *dir = small_tree("# comment\nlow a c d\nhigh b\n");
    /* b includes a (down), b includes its own y.h by a relative name, d includes c (same
     * layer, no cycle), a includes a system header: nothing to report. */
    assert_int_equal(check(dir), 0);
    assert_string_equal(report, "");
    lr_test_rmtree(dir);
}

static void test_upward_include_is_named(void **state)
{
    (void)state;
    char *dir = small_tree("low a c d\nhigh b\n");
    free(lr_test_write(dir, "c/up.c", "\n\n#include \"b/y.h\"\n", (size_t)-1));
    assert_int_equal(check(dir), 1);
    assert_non_null(strstr(report, "c/up.c:3: includes b/y.h: layer \"low\" includes \"high\""));
    /* The same include from a, which b includes, is one more and closes a cycle: three. */
    free(lr_test_write(dir, "a/up.c", "#include \"b/y.h\"\n", (size_t)-1));
    assert_int_equal(check(dir), 3);
    assert_non_null(strstr(report, "cycle among 2 folders"));
    lr_test_rmtree(dir);
}

static void test_cycle_in_one_layer_is_named(void **state)
{
    (void)state;
    char *dir = small_tree("low a c d\nhigh b\n");
    free(lr_test_write(dir, "c/back.c", "#include \"d/q.h\"\n", (size_t)-1));
    assert_int_equal(check(dir), 1);
    assert_non_null(strstr(report, "cycle among 2 folders"));
    assert_non_null(strstr(report, "c/back.c:1 includes d/q.h"));
    assert_non_null(strstr(report, "d/q.h:1 includes c/p.h"));
    lr_test_rmtree(dir);
}

static void test_unplaced_folder_is_named(void **state)
{
    (void)state;
    char *dir = small_tree("low a c\nhigh b\n");
    assert_int_equal(check(dir), 1);
    assert_non_null(strstr(report, "d: holds sources but is in no layer"));
    lr_test_rmtree(dir);
}

static void test_pattern_covers_folders_below(void **state)
{
    (void)state;
    char *dir = small_tree("low a c d\nhigh b\ntop t/*\n");
    free(lr_test_write(dir, "t/one/m.c", "#include \"b/y.h\"\n", (size_t)-1));
    free(lr_test_write(dir, "t/two/n.c", "#include \"t/one/m.c\"\n", (size_t)-1));
    assert_int_equal(check(dir), 0);
    lr_test_rmtree(dir);
}

static void test_missing_layers_file_is_an_error(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char *layers = lr_test_path(dir, "layers.txt");
    assert_int_equal(lr_test_check_layers(dir, layers, report, sizeof report), -1);
    assert_non_null(strstr(report, "cannot be read"));
    free(layers);
    lr_test_rmtree(dir);
}

static void test_tree_follows_its_layers(void **state)
{
    (void)state;
    int n = lr_test_check_layers(ROOT, ROOT "/docs/layers.txt", report, sizeof report);
    if (n != 0)
        fprintf(stderr, "docs/layers.txt: %d problem(s):\n%s", n, report);
    assert_int_equal(n, 0);
}

static void test_model_id_comparisons_are_named(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    free(lr_test_write(dir, "render/a/x.c",
                       "int f(int m) { return m == LR_SSS_MULTIPOLE; }\n"
                       "int g(int m)\n{\n    return m !=\n        LR_SSS_SH_TRANSLUCENCY;\n}\n",
                       (size_t)-1));
    free(lr_test_write(dir, "render/shaders/y.frag",
                       "\nswitch (m) { case LR_SSS_DIFFUSION_GRID: break; }\n"
                       "bool h = LR_SSS_STANDARD_DIPOLE == m;\n", (size_t)-1));
    /* Not comparisons: an id given as a value, a name in a comment or a define. */
    free(lr_test_write(dir, "render/b/z.c",
                       "int k = LR_SSS_MULTIPOLE; /* LR_SSS_MULTIPOLE */\n"
                       "#define LR_SSS_X 1\nint n = LR_SSS_MODEL_COUNT;\n", (size_t)-1));
    /* Inside render/models/ and tests/ they are allowed. */
    free(lr_test_write(dir, "render/models/registry.c", "x == LR_SSS_MULTIPOLE\n", (size_t)-1));
    free(lr_test_write(dir, "tests/t/test_q.c", "x == LR_SSS_MULTIPOLE\n", (size_t)-1));
    assert_int_equal(lr_test_check_model_ids(dir, report, sizeof report), 4);
    assert_non_null(strstr(report, "render/a/x.c:1: compares a model id: == LR_SSS_MULTIPOLE"));
    assert_non_null(strstr(report, "render/a/x.c:4: compares a model id: !="));
    assert_non_null(strstr(report, "render/shaders/y.frag:2: compares a model id: case "
                                   "LR_SSS_DIFFUSION_GRID"));
    assert_non_null(strstr(report, "render/shaders/y.frag:3: compares a model id: "
                                   "LR_SSS_STANDARD_DIPOLE =="));
    assert_null(strstr(report, "z.c"));
    assert_null(strstr(report, "registry.c"));
    lr_test_rmtree(dir);
}

static void test_no_model_id_comparison_outside_the_models(void **state)
{
    (void)state;
    int n = lr_test_check_model_ids(ROOT, report, sizeof report);
    if (n != 0)
        fprintf(stderr, "%d model-id comparison(s) outside render/models/:\n%s", n, report);
    assert_int_equal(n, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clean_tree_passes),
        cmocka_unit_test(test_upward_include_is_named),
        cmocka_unit_test(test_cycle_in_one_layer_is_named),
        cmocka_unit_test(test_unplaced_folder_is_named),
        cmocka_unit_test(test_pattern_covers_folders_below),
        cmocka_unit_test(test_missing_layers_file_is_an_error),
        cmocka_unit_test(test_tree_follows_its_layers),
        cmocka_unit_test(test_model_id_comparisons_are_named),
        cmocka_unit_test(test_no_model_id_comparison_outside_the_models),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
