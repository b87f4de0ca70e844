/* firmware/args: option tables and comma-separated number lists, shared by the subcommands;
 * the typed getters and their messages, repeats and lists, required options, the program's
 * head options; firmware/cli: the dispatch's exit statuses and the generated help. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/args.h"
#include "firmware/cli.h"
#include "firmware/commands/calib_cli.h"
#include "tests/support/fs.h"

static const lr_argspec specs[] = {{.name = "--r", .type = LR_ARG_NUMBERS},
                                   {.name = "--plot", .type = LR_ARG_PATH},
                                   {.name = "--verbose"},
                                   {0}};

static void test_parse_forms(void **state)
{
    (void)state;
    char *argv[] = {"--r", "-1,2", "pos", "--plot=out.png", "--verbose"};
    lr_args a;
    lr_err e = {0};
    assert_int_equal(lr_args_parse(5, argv, specs, 1, &a, &e), LR_OK);
    /* A value may start with '-': it is the number check's job to judge it. */
    assert_string_equal(lr_args_get(&a, "--r"), "-1,2");
    assert_string_equal(lr_args_get(&a, "--plot"), "out.png");
    assert_true(lr_args_has(&a, "--verbose"));
    assert_string_equal(lr_args_get(&a, "--verbose"), "");
    assert_int_equal(a.npos, 1);
    assert_string_equal(a.pos[0], "pos");
    char *none[] = {NULL};
    assert_int_equal(lr_args_parse(0, none, specs, 0, &a, &e), LR_OK);
    assert_false(lr_args_has(&a, "--r"));
    assert_null(lr_args_get(&a, "--plot"));
}

static void test_parse_errors(void **state)
{
    (void)state;
    static const struct {
        int argc;
        char *argv[4];
        const char *msg;
    } cases[] = {
        {1, {"--x"}, "unknown option '--x'"},
        {1, {"--r=1=2x"}, NULL}, /* value "1=2x": accepted here, rejected by the number check */
        {1, {"--rr=1"}, "unknown option '--rr'"},
        {1, {"--r"}, "--r needs a value"},
        {1, {"--r="}, "--r needs a value (got an empty one)"},
        {2, {"--verbose", "--verbose"}, "--verbose given twice"},
        {1, {"--verbose=1"}, "--verbose takes no value"},
        {1, {"stray"}, "unexpected argument 'stray'"},
        {1, {"--"}, "unexpected argument '--'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        lr_args a;
        lr_err e = {0};
        int rc = lr_args_parse(cases[i].argc, (char **)cases[i].argv, specs, 0, &a, &e);
        if (!cases[i].msg) {
            assert_int_equal(rc, LR_OK);
            continue;
        }
        assert_int_equal(rc, LR_EINVAL);
        assert_string_equal(e.msg, cases[i].msg);
    }
}

static void test_numbers(void **state)
{
    (void)state;
    double v[8];
    int n = 0;
    lr_err e = {0};
    /* Decimal literals read back exactly as the compiler reads them (correctly rounded). */
    assert_int_equal(lr_args_numbers("--r", "0,0.1,-2.5e-3,1E2,+3", v, 1, 8, &n, &e), LR_OK);
    assert_int_equal(n, 5);
    assert_true(v[0] == 0 && v[1] == 0.1 && v[2] == -2.5e-3 && v[3] == 100 && v[4] == 3);
    double t[3];
    assert_int_equal(lr_args_triple("--xi", "1,2,3", t, &e), LR_OK);
    assert_true(t[0] == 1 && t[1] == 2 && t[2] == 3);
    double x;
    assert_int_equal(lr_args_number("--eta", "1.5", &x, &e), LR_OK);
    assert_true(x == 1.5);
    /* Underflow to a tiny or zero value is not an error (it is a finite number). */
    assert_int_equal(lr_args_number("--eta", "1e-400", &x, &e), LR_OK);
    assert_true(x >= 0 && x < 1e-300);

    static const struct {
        const char *text;
        const char *msg;
    } bad[] = {
        {"1,2", "--xi: expected 3 comma-separated numbers, got 2"},
        {"1,2,3,4", "--xi: expected 3 comma-separated numbers, got 4"},
        {"1,,3", "--xi: item 2 of '1,,3' is empty"},
        {",1,2", "--xi: item 1 of ',1,2' is empty"},
        {"1,2,", "--xi: item 3 of '1,2,' is empty"},
        {"1,nan,3", "--xi: 'nan' is not a finite decimal number"},
        {"1,2,inf", "--xi: 'inf' is not a finite decimal number"},
        {"0x10,1,1", "--xi: '0x10' is not a finite decimal number"},
        {"1, 2,3", "--xi: ' 2' is not a finite decimal number"},
        {"1,2,3e", "--xi: '3e' is not a number"},
        {"1,2,--3", "--xi: '--3' is not a number"},
        {"1,2,1e400", "--xi: '1e400' is out of range"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        assert_int_equal(lr_args_triple("--xi", bad[i].text, t, &e), LR_EINVAL);
        assert_string_equal(e.msg, bad[i].msg);
    }
    assert_int_equal(lr_args_number("--eta", "1,2", &x, &e), LR_EINVAL);
    assert_string_equal(e.msg, "--eta: expected one number, got the list '1,2'");
    assert_int_equal(lr_args_number("--eta", "", &x, &e), LR_EINVAL);
    assert_string_equal(e.msg, "--eta: empty number");
    assert_int_equal(lr_args_numbers("--r", "1,2,3", v, 1, 2, &n, &e), LR_EINVAL);
    assert_string_equal(e.msg, "--r: expected 1 to 2 comma-separated numbers, got 3");
}

/* ---- typed options ------------------------------------------------------------------------ */

static const lr_argspec typed[] = {
    {.name = "--n", .type = LR_ARG_INT, .min = 1, .max = 255},
    {.name = "--gain", .type = LR_ARG_NUMBER, .flags = LR_ARG_ABOVE_MIN},
    {.name = "--fps", .type = LR_ARG_NUMBER, .flags = LR_ARG_ABOVE_MIN, .max = 1e6},
    {.name = "--gamma", .type = LR_ARG_NUMBER, .min = 0.1, .max = 10},
    {.name = "--size", .type = LR_ARG_SIZE, .min = 2, .max = 4096},
    {.name = "--proj", .type = LR_ARG_SIZE},
    {.name = "--pattern", .type = LR_ARG_CHOICE, .choices = "chessboard|circles|acircles"},
    {.name = "--sigma", .type = LR_ARG_TRIPLE, .flags = LR_ARG_ABOVE_MIN},
    {.name = "--set", .type = LR_ARG_STRING, .repeat = 3},
    {.name = "--capture", .type = LR_ARG_PATH, .flags = LR_ARG_LIST | LR_ARG_REQUIRED,
     .repeat = 4},
    {.name = "--out", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED},
    /* ">= 0" with no upper bound (min and max 0 alone would mean any value). */
    {.name = "--wait", .type = LR_ARG_NUMBER, .flags = LR_ARG_FLOOR},
    {.name = "--rays", .type = LR_ARG_INT, .flags = LR_ARG_FLOOR},
    /* Whole numbers beyond int, read with lr_args_int64 (read_one picks it by name). */
    {.name = "--seed", .type = LR_ARG_INT, .min = 0, .max = 4294967295.0},
    {.name = "--big", .type = LR_ARG_INT},
    {0},
};

static int wide(const char *flag) { return !strcmp(flag, "--seed") || !strcmp(flag, "--big"); }

/* Parses one option (plus the required ones) and reads it with the getter of its type. */
static int read_one(const char *flag, const char *value, lr_err *e)
{
    char *argv[] = {(char *)flag, (char *)value, "--capture", "a", "--out", "o"};
    lr_args *a = calloc(1, sizeof *a);
    assert_non_null(a);
    assert_int_equal(lr_args_parse(6, argv, typed, 0, a, e), LR_OK);
    int i = 0, w = 0, h = 0, n = 0;
    double d = 0, v[3];
    long long ll = 0;
    int rc;
    const lr_argspec *s = lr_args_spec(a, flag);
    switch (s->type) {
    case LR_ARG_INT:
        rc = wide(flag) ? lr_args_int64(a, flag, &ll, e) : lr_args_int(a, flag, &i, e);
        break;
    case LR_ARG_NUMBER:
        rc = lr_args_double(a, flag, &d, e);
        break;
    case LR_ARG_SIZE:
        rc = lr_args_size(a, flag, &w, &h, e);
        break;
    case LR_ARG_CHOICE:
        rc = lr_args_choice(a, flag, &i, e);
        break;
    default:
        rc = lr_args_list(a, flag, v, 3, &n, e);
    }
    free(a);
    return rc;
}

static void test_typed_values(void **state)
{
    (void)state;
    static const struct {
        const char *flag, *value, *msg; /* msg NULL: accepted */
    } cases[] = {
        {"--n", "1", NULL},
        {"--n", "255", NULL},
        {"--n", "0", "--n 0: must be a whole number in 1..255"},
        {"--n", "2.5", "--n 2.5: must be a whole number in 1..255"},
        {"--n", "x", "--n: 'x' is not a finite decimal number"},
        {"--gain", "1e-300", NULL},
        {"--gain", "0", "--gain 0: must be > 0"},
        {"--fps", "1e6", NULL},
        {"--fps", "2e6", "--fps 2e6: must be > 0 and <= 1000000"},
        {"--gamma", "0.05", "--gamma 0.05: must be in 0.1..10"},
        {"--size", "64x48", NULL},
        {"--size", "1x48", "--size 1x48: expected WIDTHxHEIGHT, each a whole number in 2..4096"},
        {"--size", "64x", "--size 64x: expected WIDTHxHEIGHT, each a whole number in 2..4096"},
        {"--size", "64x48x2", "--size 64x48x2: expected WIDTHxHEIGHT, each a whole number in "
                              "2..4096"},
        {"--proj", "0x1", "--proj 0x1: expected WIDTHxHEIGHT, each a whole number >= 1"},
        {"--proj", "+8x8", "--proj +8x8: expected WIDTHxHEIGHT, each a whole number >= 1"},
        {"--pattern", "circles", NULL},
        {"--pattern", "hex", "--pattern 'hex': expected chessboard, circles or acircles"},
        {"--sigma", "1,2,3", NULL},
        {"--sigma", "1,0,3", "--sigma 1,0,3: item 2 must be > 0"},
        {"--sigma", "1,2", "--sigma: expected 3 comma-separated numbers, got 2"},
        {"--wait", "0", NULL},
        {"--wait", "1e9", NULL},
        {"--wait", "-0.5", "--wait -0.5: must be >= 0"},
        {"--rays", "0", NULL},
        {"--rays", "-1", "--rays -1: must be a whole number >= 0"},
        {"--seed", "0", NULL},
        {"--seed", "4294967295", NULL},
        {"--seed", "4294967296", "--seed 4294967296: must be a whole number in 0..4294967295"},
        {"--seed", "-1", "--seed -1: must be a whole number in 0..4294967295"},
        /* 2^53 is the last whole number a double holds with all below it; 1e16 is past it. */
        {"--big", "9007199254740992", NULL},
        {"--big", "1e16", "--big 1e16: out of range"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        lr_err e = {0};
        int rc = read_one(cases[k].flag, cases[k].value, &e);
        if (!cases[k].msg) {
            if (rc)
                fail_msg("%s %s: %s", cases[k].flag, cases[k].value, e.msg);
            continue;
        }
        assert_int_equal(rc, LR_EINVAL);
        assert_string_equal(e.msg, cases[k].msg);
    }
    /* The values themselves: an absent option leaves the caller's default. */
    char *argv[] = {"--size", "640x480", "--pattern", "acircles", "--capture", "a", "--out", "o"};
    lr_args *a = calloc(1, sizeof *a);
    assert_non_null(a);
    lr_err e = {0};
    assert_int_equal(lr_args_parse(8, argv, typed, 0, a, &e), LR_OK);
    int w = 0, h = 0, p = -1, n = 42;
    assert_int_equal(lr_args_size(a, "--size", &w, &h, &e), LR_OK);
    assert_int_equal(lr_args_choice(a, "--pattern", &p, &e), LR_OK);
    assert_int_equal(lr_args_int(a, "--n", &n, &e), LR_OK);
    assert_true(w == 640 && h == 480 && p == 2 && n == 42);
    /* The largest seed comes back whole: above 2^31 lr_args_int would refuse it. */
    char *seed[] = {"--seed", "4294967295", "--capture", "a", "--out", "o"};
    long long s64 = 0;
    assert_int_equal(lr_args_parse(6, seed, typed, 0, a, &e), LR_OK);
    assert_int_equal(lr_args_int(a, "--seed", &n, &e), LR_EINVAL);
    assert_int_equal(lr_args_int64(a, "--seed", &s64, &e), LR_OK);
    assert_true(s64 == 4294967295LL);
    free(a);
}

static void test_repeats_lists_required(void **state)
{
    (void)state;
    lr_args *a = calloc(1, sizeof *a);
    assert_non_null(a);
    lr_err e = {0};
    /* --capture takes every argument up to the next option, and may come again. */
    char *ok[] = {"--set", "a=1", "--capture", "x.png", "y.png", "--set=b=2", "--capture",
                  "z.png", "--out", "o"};
    assert_int_equal(lr_args_parse(10, ok, typed, 0, a, &e), LR_OK);
    const char *v[8];
    assert_int_equal(lr_args_values(a, "--set", v, 8), 2);
    assert_string_equal(v[0], "a=1");
    assert_string_equal(v[1], "b=2");
    assert_int_equal(lr_args_values(a, "--capture", v, 8), 3);
    assert_string_equal(v[2], "z.png");
    assert_int_equal(lr_args_values(a, "--out", v, 8), 1);
    assert_null(lr_args_missing(a));

    static const struct {
        int argc;
        char *argv[8];
        const char *msg;
    } bad[] = {
        {8, {"--set", "1", "--set", "2", "--set", "3", "--set", "4"}, "--set: at most 3"},
        {2, {"--capture", "--out"}, "--capture needs a value"},
        {6, {"--capture", "a", "b", "c", "d", "e"}, "--capture: at most 4"},
        {3, {"--out", "o", "stray"}, "unexpected argument 'stray'"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        assert_int_equal(lr_args_parse(bad[k].argc, (char **)bad[k].argv, typed, 0, a, &e),
                         LR_EINVAL);
        assert_string_equal(e.msg, bad[k].msg);
    }
    /* The first required option not given. */
    char *no_capture[] = {"--out", "o"};
    assert_int_equal(lr_args_parse(2, no_capture, typed, 0, a, &e), LR_OK);
    assert_string_equal(lr_args_missing(a)->name, "--capture");

    /* The program's head options stop at the command, or at an option that is not theirs. */
    static const lr_argspec head[] = {{.name = "--configs", .type = LR_ARG_PATH}, {0}};
    char *h1[] = {"--configs", "/c", "render", "--configs", "x"};
    int used = -1;
    assert_int_equal(lr_args_parse_head(5, h1, head, a, &used, &e), LR_OK);
    assert_int_equal(used, 2);
    assert_string_equal(lr_args_get(a, "--configs"), "/c");
    char *h2[] = {"--version"};
    assert_int_equal(lr_args_parse_head(1, h2, head, a, &used, &e), LR_OK);
    assert_int_equal(used, 0);
    free(a);
}

/* ---- the dispatch and the generated help --------------------------------------------------- */

static int ran;
static int run_leaf(const lr_cli *c)
{
    ran++;
    return lr_args_has(&c->args, "--fail") ? lr_cli_fail(c->path, "failed") : LR_EXIT_OK;
}

static const lr_argspec leaf_opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED, .help = "the scene"},
    {.name = "--set", .type = LR_ARG_STRING, .metavar = "key=value", .repeat = 4,
     .help = "a change\nover two lines"},
    {.name = "--fail", .help = "exit 1"},
    {0},
};
static const lr_command leaf = {.name = "leaf", .summary = "a leaf", .opts = leaf_opts,
                                .notes = "Exit status: 0.", .run = run_leaf};
static const lr_command group = {.name = "grp", .summary = "a group",
                                 .subs = (const lr_command *const[]){&leaf, NULL}};

static void test_dispatch_and_help(void **state)
{
    (void)state;
    ran = 0;
    char *ok[] = {"grp", "leaf", "--scene", "s.json"};
    assert_int_equal(lr_cli_command(&group, NULL, 4, ok), LR_EXIT_OK);
    char *fails[] = {"grp", "leaf", "--scene", "s.json", "--fail"};
    assert_int_equal(lr_cli_command(&group, NULL, 5, fails), LR_EXIT_FAIL);
    assert_int_equal(ran, 2);
    /* Bad arguments never reach the command. */
    char *missing[] = {"grp", "leaf", "--set", "a=1"};
    char *unknown[] = {"grp", "leaf", "--scene", "s", "--x"};
    char *nosub[] = {"grp"};
    char *badsub[] = {"grp", "branch"};
    assert_int_equal(lr_cli_command(&group, NULL, 4, missing), LR_EXIT_USAGE);
    assert_int_equal(lr_cli_command(&group, NULL, 5, unknown), LR_EXIT_USAGE);
    assert_int_equal(lr_cli_command(&group, NULL, 1, nosub), LR_EXIT_USAGE);
    assert_int_equal(lr_cli_command(&group, NULL, 2, badsub), LR_EXIT_USAGE);
    assert_int_equal(ran, 2);

    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    lr_help_print(f, &leaf, "grp leaf");
    fclose(f);
    assert_string_equal(text, "usage: lamprig grp leaf --scene FILE [--set key=value ...] [--fail]\n"
                              "\n"
                              "a leaf\n"
                              "\n"
                              "  --scene FILE     the scene\n"
                              "  --set key=value  a change\n"
                              "                   over two lines\n"
                              "  --fail           exit 1\n"
                              "\n"
                              "Exit status: 0.\n");
    free(text);
    f = open_memstream(&text, &len);
    assert_non_null(f);
    lr_help_print(f, &group, "grp");
    fclose(f);
    assert_string_equal(text, "usage: lamprig grp SUBCOMMAND [OPTIONS]\n"
                              "\n"
                              "a group\n"
                              "\n"
                              "Subcommands (`lamprig help grp SUBCOMMAND` shows one in full):\n"
                              "  leaf --scene FILE [--set key=value ...] [--fail]\n"
                              "      a leaf\n");
    free(text);
}

/* firmware/README.md quotes one generated help: it must be what the program prints. */
static void test_readme_quotes_the_help(void **state)
{
    (void)state;
    size_t n;
    char *readme = (char *)lr_test_read("firmware/README.md", &n);
    assert_non_null(readme);
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    assert_non_null(f);
    lr_help_print(f, &lr_calib_projector_response, "calib projector-response");
    fclose(f);
    if (!strstr(readme, text))
        fail_msg("firmware/README.md lacks the help of `lamprig calib projector-response`:\n%s",
                 text);
    free(text);
    free(readme);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_forms),
        cmocka_unit_test(test_parse_errors),
        cmocka_unit_test(test_numbers),
        cmocka_unit_test(test_typed_values),
        cmocka_unit_test(test_repeats_lists_required),
        cmocka_unit_test(test_dispatch_and_help),
        cmocka_unit_test(test_readme_quotes_the_help),
    };
    return cmocka_run_group_tests_name("args", tests, NULL, NULL);
}
