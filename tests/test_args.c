/* firmware/args: option tables and comma-separated number lists, shared by the subcommands. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "firmware/args.h"

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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_forms),
        cmocka_unit_test(test_parse_errors),
        cmocka_unit_test(test_numbers),
    };
    return cmocka_run_group_tests_name("args", tests, NULL, NULL);
}
