/* JSON layer: values, line numbers and the file/line/field in every error message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/base/json.h"

static lr_json *parse_ok(const char *text)
{
    lr_json *j = NULL;
    lr_err e = {0};
    int rc = lr_json_parse(text, strlen(text), "t.json", &j, &e);
    if (rc)
        fail_msg("unexpected parse failure: %s", e.msg);
    return j;
}

static void expect_parse_error(const char *text, const char *needle)
{
    lr_json *j = NULL;
    lr_err e = {0};
    assert_int_equal(lr_json_parse(text, strlen(text), "bad.json", &j, &e), LR_EPARSE);
    assert_null(j);
    if (!strstr(e.msg, needle))
        fail_msg("message '%s' lacks '%s'", e.msg, needle);
}

static void test_values_and_lines(void **state)
{
    (void)state;
    lr_json *j = parse_ok("{\n  \"name\": \"wax \\u00e9\\n\",\n  \"eta\": 1.45,\n"
                          "  \"rgb\": [0.5, -2e-3, 10],\n  \"on\": true,\n  \"n\": 42\n}\n");
    lr_jnode root = lr_json_root(j);
    assert_int_equal(lr_json_type(j, root), LR_JSON_OBJECT);
    assert_int_equal(lr_json_count(j, root), 5);
    char name[32];
    lr_err e = {0};
    assert_int_equal(lr_json_get_string(j, root, "name", true, name, sizeof name, &e), LR_OK);
    assert_string_equal(name, "wax \xc3\xa9\n"); /* \u00e9 is 2 bytes of UTF-8 */
    double eta = 0, rgb[3] = {0};
    assert_int_equal(lr_json_get_number(j, root, "eta", true, &eta, &e), LR_OK);
    assert_true(eta == 1.45);
    assert_int_equal(lr_json_get_numbers(j, root, "rgb", true, rgb, 3, &e), LR_OK);
    assert_true(rgb[0] == 0.5 && rgb[1] == -2e-3 && rgb[2] == 10.0);
    bool on = false;
    long n = 0;
    assert_int_equal(lr_json_get_bool(j, root, "on", true, &on, &e), LR_OK);
    assert_true(on);
    assert_int_equal(lr_json_get_int(j, root, "n", true, &n, &e), LR_OK);
    assert_int_equal(n, 42);
    /* Lines are 1-based and point at the value. */
    assert_int_equal(lr_json_line(j, lr_json_get(j, root, "eta")), 3);
    assert_int_equal(lr_json_line(j, lr_json_get(j, root, "n")), 6);
    /* Optional absent member leaves the default. */
    double g = 0.25;
    assert_int_equal(lr_json_get_number(j, root, "g", false, &g, &e), LR_OK);
    assert_true(g == 0.25);
    lr_json_destroy(j);
}

static void test_nested_skips_subtrees(void **state)
{
    (void)state;
    /* Lookup after a deeply nested member must skip the whole subtree. */
    lr_json *j = parse_ok("{\"a\": {\"b\": [1, [2, {\"c\": 3}], {}]}, \"z\": [7, 8]}");
    lr_jnode z = lr_json_get(j, lr_json_root(j), "z");
    assert_int_equal(lr_json_count(j, z), 2);
    double v = 0;
    assert_int_equal(lr_json_number(j, lr_json_at(j, z, 1), "z[1]", &v, NULL), LR_OK);
    assert_true(v == 8.0);
    lr_jnode b = lr_json_get(j, lr_json_get(j, lr_json_root(j), "a"), "b");
    assert_int_equal(lr_json_type(j, lr_json_at(j, b, 2)), LR_JSON_OBJECT);
    assert_int_equal(lr_json_at(j, b, 3), LR_JNONE);
    lr_json_destroy(j);
}

static void test_field_errors_name_line_and_field(void **state)
{
    (void)state;
    lr_json *j = parse_ok("{\n\"eta\": \"high\",\n\"rgb\": [1, 2],\n\"x\": 1.5\n}");
    lr_jnode root = lr_json_root(j);
    lr_err e = {0};
    double v, rgb[3];
    long n;
    assert_int_equal(lr_json_get_number(j, root, "eta", true, &v, &e), LR_EPARSE);
    assert_string_equal(e.msg, "t.json:2: field 'eta': expected a number, got a string");
    assert_int_equal(lr_json_get_numbers(j, root, "rgb", true, rgb, 3, &e), LR_EPARSE);
    assert_string_equal(e.msg, "t.json:3: field 'rgb': expected 3 numbers, got 2");
    assert_int_equal(lr_json_get_int(j, root, "x", true, &n, &e), LR_EPARSE);
    assert_non_null(strstr(e.msg, "t.json:4: field 'x': expected an integer"));
    assert_int_equal(lr_json_get_number(j, root, "sigma_a", true, &v, &e), LR_EPARSE);
    assert_string_equal(e.msg, "t.json:1: field 'sigma_a': missing (required)");
    lr_json_destroy(j);
}

static void test_check_keys(void **state)
{
    (void)state;
    static const char *const allowed[] = {"eta", "g", NULL};
    lr_json *j = parse_ok("{\"eta\": 1.3,\n \"gg\": 0}");
    lr_err e = {0};
    assert_int_equal(lr_json_check_keys(j, lr_json_root(j), "material", allowed, &e), LR_EPARSE);
    assert_string_equal(e.msg, "t.json:2: field 'gg': unknown field in material");
    lr_json_destroy(j);
    j = parse_ok("{\"eta\": 1.3, \"g\": 0,\n\"eta\": 1.5}");
    assert_int_equal(lr_json_check_keys(j, lr_json_root(j), "material", allowed, &e), LR_EPARSE);
    assert_string_equal(e.msg, "t.json:2: field 'eta': duplicate field in material");
    lr_json_destroy(j);
}

static void test_malformed(void **state)
{
    (void)state;
    expect_parse_error("{\"a\": 1,\n\"b\": [1, 2\n", "bad.json:");
    expect_parse_error("", "empty document");
    expect_parse_error("{\"a\": 1} {\"b\": 2}", "text after the top-level value");
    expect_parse_error("{\"a\": 1,\n\n \"b\": }", "bad.json:3");
    /* Numbers JSON forbids are rejected when read, with the field named. */
    const char *bad[] = {"[0x10]", "[1.]", "[.5]", "[01]", "[1e]", "[-]", "[1e999]"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        lr_json *j = NULL;
        lr_err e = {0};
        double v;
        if (lr_json_parse(bad[i], strlen(bad[i]), "n.json", &j, &e) != LR_OK)
            continue; /* jsmn already refused it: fine */
        assert_int_equal(lr_json_number(j, lr_json_at(j, lr_json_root(j), 0), "v", &v, &e),
                         LR_EPARSE);
        assert_non_null(strstr(e.msg, "n.json:1: field 'v'"));
        lr_json_destroy(j);
    }
    /* Bad escapes and an embedded NUL escape. */
    expect_parse_error("[\"\\q\"]", "bad.json:1: invalid JSON"); /* jsmn refuses \q */
    lr_json *j = parse_ok("[\"a\\u0000b\", \"\\ud800\"]");
    char buf[16];
    lr_err e = {0};
    assert_int_equal(lr_json_string(j, lr_json_at(j, 0, 0), "s", buf, sizeof buf, &e), LR_EPARSE);
    assert_int_equal(lr_json_string(j, lr_json_at(j, 0, 1), "s", buf, sizeof buf, &e), LR_EPARSE);
    assert_non_null(strstr(e.msg, "malformed escape"));
    /* Too long for the buffer. */
    lr_json_destroy(j);
    j = parse_ok("[\"0123456789abcdef\"]");
    assert_int_equal(lr_json_string(j, lr_json_at(j, 0, 0), "s", buf, sizeof buf, &e), LR_EPARSE);
    assert_non_null(strstr(e.msg, "longer than 15 bytes"));
    lr_json_destroy(j);
}

static void test_deep_nesting_does_not_recurse(void **state)
{
    (void)state;
    /* 200000 nested arrays: a recursive walker would overflow the stack. */
    size_t depth = 200000;
    char *text = malloc(2 * depth + 1);
    memset(text, '[', depth);
    memset(text + depth, ']', depth);
    text[2 * depth] = '\0';
    lr_json *j = parse_ok(text);
    assert_int_equal(lr_json_count(j, lr_json_root(j)), 1);
    assert_int_equal(lr_json_at(j, lr_json_root(j), 0), 1);
    lr_json_destroy(j);
    free(text);
}

static void test_load_file(void **state)
{
    (void)state;
    char path[] = "/tmp/lamprig-json-XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    const char *text = "{\n \"k\": [1,\n 2, true]\n}\n";
    assert_int_equal(write(fd, text, strlen(text)), (ssize_t)strlen(text));
    close(fd);
    lr_json *j = NULL;
    lr_err e = {0};
    assert_int_equal(lr_json_load(path, &j, &e), LR_OK);
    double v;
    assert_int_equal(lr_json_number(j, lr_json_at(j, lr_json_get(j, 0, "k"), 2), "k[2]", &v, &e),
                     LR_EPARSE);
    char want[128];
    snprintf(want, sizeof want, "%s:3: field 'k[2]': expected a number, got a boolean", path);
    assert_string_equal(e.msg, want);
    lr_json_destroy(j);
    unlink(path);
    assert_int_equal(lr_json_load(path, &j, &e), LR_EIO);
    assert_non_null(strstr(e.msg, "cannot open"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values_and_lines),
        cmocka_unit_test(test_nested_skips_subtrees),
        cmocka_unit_test(test_field_errors_name_line_and_field),
        cmocka_unit_test(test_check_keys),
        cmocka_unit_test(test_malformed),
        cmocka_unit_test(test_deep_nesting_does_not_recurse),
        cmocka_unit_test(test_load_file),
    };
    return cmocka_run_group_tests_name("json", tests, NULL, NULL);
}
