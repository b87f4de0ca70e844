/* JSON layer: values, line numbers and the file/line/field in every error message. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/base/json.h"
#include "render/base/paths.h"

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
}

static void test_malformed(void **state)
{
    (void)state;
    expect_parse_error("{\"a\": 1,\n\"b\": [1, 2\n",
                       "bad.json:3: field 'b': unexpected end of file ('[' from line 2 is not "
                       "closed)");
    expect_parse_error("", "bad.json:1: empty document");
    expect_parse_error(" \n\t\r ", "bad.json:2: empty document");
    expect_parse_error("{\"a\": 1,\n\n \"b\": }", "bad.json:3: field 'b': expected a value, got '}'");
    expect_parse_error("{\"a\":", "bad.json:1: field 'a': unexpected end of file");
    /* Too long for the buffer is an error when read, not a silent truncation. */
    lr_json *j = parse_ok("[\"0123456789abcdef\"]");
    char buf[16];
    lr_err e = {0};
    assert_int_equal(lr_json_string(j, lr_json_at(j, 0, 0), "s", buf, sizeof buf, &e), LR_EPARSE);
    assert_non_null(strstr(e.msg, "longer than 15 bytes"));
    lr_json_destroy(j);
}

/* ---- strict RFC 8259: what the reader refuses, each naming file:line and the field ---------- */

static void test_rejects_invalid_literals(void **state)
{
    (void)state;
    /* A bare word used to be typed by its first letter: tuesday read as true, nope as null. */
    expect_parse_error("{\"a\": tuesday}", "bad.json:1: field 'a': invalid literal 'tuesday'");
    expect_parse_error("nope", "bad.json:1: invalid literal 'nope'");
    expect_parse_error("{\"x\": {\"on\":\n fals}}", "bad.json:2: field 'x.on': invalid literal 'fals'");
    expect_parse_error("[true, truex]", "bad.json:1: field '[1]': invalid literal 'truex'");
    expect_parse_error("[nul]", "invalid literal 'nul'");
    expect_parse_error("[True]", "invalid literal 'True'");
    expect_parse_error("[null1]", "invalid literal 'null1'");
    /* JSON has no NaN or Infinity. */
    expect_parse_error("{\"v\": NaN}", "bad.json:1: field 'v': invalid literal 'NaN' (JSON has no "
                                       "NaN or Infinity)");
    expect_parse_error("{\"v\": Infinity}", "field 'v': invalid literal 'Infinity' (JSON has no");
    expect_parse_error("{\"v\": -Infinity}", "field 'v': malformed number '-Infinity' (JSON has no");
    expect_parse_error("{\"v\": -nan}", "field 'v': malformed number '-nan' (JSON has no");
    /* Single quotes, comments and bare keys are JavaScript, not JSON. */
    expect_parse_error("['a']", "bad.json:1: field '[0]': unexpected character '''");
    expect_parse_error("{a: 1}", "bad.json:1: expected a key in double quotes, got 'a'");
    expect_parse_error("[1] // c", "bad.json:1: text after the top-level value");
    expect_parse_error("{\"a\": 1 /* c */}",
                       "bad.json:1: field 'a': expected ',' or '}' after a member, got '/'");
}

static void test_rejects_trailing_commas(void **state)
{
    (void)state;
    expect_parse_error("[1, 2,]", "bad.json:1: trailing comma before ']'");
    expect_parse_error("{\"a\": 1,\n}", "bad.json:2: trailing comma before '}'");
    expect_parse_error("{\"l\": [\n 1,\n 2,\n ],\n \"b\": 2}",
                       "bad.json:4: field 'l': trailing comma before ']'");
    expect_parse_error("{\"o\": {\"a\": 1,}}", "bad.json:1: field 'o': trailing comma before '}'");
    expect_parse_error("[,]", "bad.json:1: field '[0]': expected a value, got ','");
    expect_parse_error("[1,,2]", "bad.json:1: field '[1]': expected a value, got ','");
    expect_parse_error("{,}", "bad.json:1: expected a key in double quotes, got ','");
    /* Missing separators. */
    expect_parse_error("[1 2]", "bad.json:1: field '[0]': expected ',' or ']' after an element, "
                                "got '2'");
    expect_parse_error("{\"a\": 1\n \"b\": 2}",
                       "bad.json:2: field 'a': expected ',' or '}' after a member, got '\"'");
    expect_parse_error("{\"a\" 1}", "bad.json:1: field 'a': expected ':' after the key, got '1'");
    expect_parse_error("[1}", "bad.json:1: field '[0]': expected ',' or ']' after an element, "
                              "got '}'");
}

static void test_rejects_malformed_numbers(void **state)
{
    (void)state;
    expect_parse_error("{\"n\": 01}", "bad.json:1: field 'n': leading zero in number '01'");
    expect_parse_error("[-012]", "field '[0]': leading zero in number '-012'");
    expect_parse_error("[00]", "leading zero in number '00'");
    const char *bad[] = {"[0x10]", "[1.]", "[.5]", "[+1]", "[1e]",  "[1e+]",
                         "[-]",    "[1.5.3]", "[1.e5]", "[--1]", "[1e5e5]", "[\xd9\xa1]"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        lr_json *j = NULL;
        lr_err e = {0};
        if (lr_json_parse(bad[i], strlen(bad[i]), "n.json", &j, &e) != LR_EPARSE)
            fail_msg("%s: accepted", bad[i]);
        assert_null(j);
        if (!strstr(e.msg, "n.json:1: field '[0]': "))
            fail_msg("%s: message '%s' lacks file:line:field", bad[i], e.msg);
    }
    expect_parse_error("[0x10]", "field '[0]': malformed number '0x10'");
    expect_parse_error("[1.]", "field '[0]': malformed number '1.'");
    expect_parse_error("[.5]", "field '[0]': unexpected character '.'");
    expect_parse_error("[+1]", "field '[0]': unexpected character '+'");
}

static void test_rejects_out_of_range_numbers(void **state)
{
    (void)state;
    /* 1e-400 used to read as 0 (underflow, silently). */
    expect_parse_error("{\"sigma\":\n 1e-400}", "bad.json:2: field 'sigma': number '1e-400' "
                                                 "underflows a double");
    expect_parse_error("[2.4e-324]", "field '[0]': number '2.4e-324' underflows a double");
    expect_parse_error("[-1e-400]", "underflows a double");
    expect_parse_error("{\"v\": 1e999}", "bad.json:1: field 'v': number '1e999' overflows a double");
    expect_parse_error("[-1.8e308]", "overflows a double");
    /* 311 digits: larger than DBL_MAX (about 1.8e308). */
    char big[400] = "[1";
    memset(big + 2, '0', 310);
    strcpy(big + 312, "]");
    expect_parse_error(big, "overflows a double");
}

static void expect_int_error(const char *text, const char *needle)
{
    lr_json *j = parse_ok(text);
    lr_err e = {0};
    long n = 12345;
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "n", true, &n, &e), LR_EPARSE);
    assert_int_equal(n, 12345); /* untouched */
    if (!strstr(e.msg, needle))
        fail_msg("%s: message '%s' lacks '%s'", text, e.msg, needle);
    lr_json_destroy(j);
}

static long int_of(const char *text)
{
    lr_json *j = parse_ok(text);
    lr_err e = {0};
    long n = 0;
    if (lr_json_get_int(j, lr_json_root(j), "n", true, &n, &e) != LR_OK)
        fail_msg("%s: %s", text, e.msg);
    lr_json_destroy(j);
    return n;
}

static void test_int_range(void **state)
{
    (void)state;
    /* 2^63 used to pass the range check ((double)LONG_MAX is 2^63) and be cast: UB. */
    expect_int_error("{\"n\":\n 9223372036854775808}",
                     "t.json:2: field 'n': integer 9223372036854775808 out of range");
    expect_int_error("{\"n\": -9223372036854775809}", "field 'n': integer -9223372036854775809 out");
    expect_int_error("{\"n\": 100000000000000000000}", "out of range");
    expect_int_error("{\"n\": 1e19}", "field 'n': expected an integer");
    /* 2^53 + 1 written with a fraction reads as 2^53: not exact, refused. */
    expect_int_error("{\"n\": 9007199254740993.0}", "field 'n': expected an integer");
    expect_int_error("{\"n\": 1.5}", "field 'n': expected an integer, got 1.5");
    expect_int_error("{\"n\": \"3\"}", "field 'n': expected a number, got a string");
    assert_true(int_of("{\"n\": 9223372036854775807}") == LONG_MAX);
    assert_true(int_of("{\"n\": -9223372036854775808}") == LONG_MIN);
    assert_true(int_of("{\"n\": -0}") == 0);
    assert_true(int_of("{\"n\": 1e2}") == 100);
    assert_true(int_of("{\"n\": 2.50e1}") == 25);
    assert_true(int_of("{\"n\": 9007199254740991.0}") == 9007199254740991L);
    /* Plain digits beyond 2^53 are exact (read as an integer, not through a double). */
    assert_true(int_of("{\"n\": 9007199254740993}") == 9007199254740993L);
}

static void test_rejects_bad_strings(void **state)
{
    (void)state;
    expect_parse_error("{\"s\": \"\\q\"}", "bad.json:1: field 's': invalid escape '\\q' in string");
    expect_parse_error("[\"\\x41\"]", "invalid escape '\\x' in string");
    expect_parse_error("[\"\\u12\"]", "field '[0]': invalid escape '\\u12\"]' in string");
    expect_parse_error("[\"\\u12g4\"]", "invalid escape '\\u12g4' in string");
    /* Surrogates: a pair is one code point; alone, either half is not text. */
    expect_parse_error("{\"s\": \"\\ud800\"}", "field 's': unpaired surrogate '\\ud800' in string");
    expect_parse_error("[\"\\udc00\"]", "unpaired surrogate '\\udc00' in string");
    expect_parse_error("[\"\\ud800\\u0041\"]", "unpaired surrogate '\\ud800' in string");
    expect_parse_error("[\"\\ud800\\ud800\"]", "unpaired surrogate '\\ud800' in string");
    expect_parse_error("[\"\\uDBFF\"]", "unpaired surrogate '\\uDBFF' in string");
    expect_parse_error("[\"a\\u0000b\"]", "'\\u0000' in string (not supported");
    /* Raw control characters (a tab, a line break) must be escaped. */
    expect_parse_error("{\"s\": \"a\tb\"}", "field 's': control character 0x09 in string");
    expect_parse_error("{\"s\": \"ab\n}", "field 's': line break in string (missing closing quote?)");
    expect_parse_error("{\"s\": \"ab", "field 's': unexpected end of file in a string");
    /* Invalid UTF-8: a stray byte, an overlong '/', an encoded surrogate, a truncated 'é', a
     * code point past U+10FFFF, a truncated '€'. */
    expect_parse_error("[\"\xff\"]", "field '[0]': invalid UTF-8 in string");
    expect_parse_error("[\"\xc0\xaf\"]", "invalid UTF-8 in string");
    expect_parse_error("[\"\xed\xa0\x80\"]", "invalid UTF-8 in string");
    expect_parse_error("[\"\xc3\"]", "invalid UTF-8 in string");
    expect_parse_error("[\"\xf4\x90\x80\x80\"]", "invalid UTF-8 in string");
    expect_parse_error("[\"\xe2\x82\"]", "invalid UTF-8 in string");
    /* Outside strings, only JSON's four whitespace bytes. */
    expect_parse_error("[1,\f2]", "field '[1]': unexpected character 0x0c");
    expect_parse_error("[1,\xc2\xa0 2]", "unexpected character 0xc2");
}

static void test_rejects_duplicate_keys(void **state)
{
    (void)state;
    /* Duplicates are refused everywhere (RFC 8259 leaves their meaning open; a lax reader
     * silently keeps one of them). Keys compare after unescaping. */
    expect_parse_error("{\"a\": 1,\n \"a\": 2}", "bad.json:2: field 'a': duplicate key (first on "
                                                "line 1)");
    expect_parse_error("{\"o\": [{\"x\": 1,\n\n \"\\u0078\": 2}]}",
                       "bad.json:3: field 'o[0].x': duplicate key (first on line 1)");
    /* Among many keys (sorted, not compared pairwise). */
    size_t cap = 20000 * 16;
    char *text = malloc(cap);
    size_t o = 0;
    o += (size_t)snprintf(text + o, cap - o, "{");
    for (int i = 0; i < 20000; i++)
        o += (size_t)snprintf(text + o, cap - o, "%s\"k%d\": %d", i ? ",\n" : "", i, i);
    o += (size_t)snprintf(text + o, cap - o, "}");
    lr_json *j = parse_ok(text);
    assert_int_equal(lr_json_count(j, lr_json_root(j)), 20000);
    long v = 0;
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "k19999", true, &v, NULL), LR_OK);
    assert_int_equal(v, 19999);
    lr_json_destroy(j);
    snprintf(text + o - 1, cap - (o - 1), ",\n\"k123\": 0}");
    expect_parse_error(text, "bad.json:20001: field 'k123': duplicate key (first on line 124)");
    free(text);
}

static void test_rejects_trailing_text(void **state)
{
    (void)state;
    expect_parse_error("{\"a\": 1} {\"b\": 2}", "bad.json:1: text after the top-level value");
    expect_parse_error("[1]]", "text after the top-level value");
    expect_parse_error("{}\n}", "bad.json:2: text after the top-level value");
    expect_parse_error("1 2", "text after the top-level value");
    expect_parse_error("truefalse", "invalid literal 'truefalse'");
    /* A NUL byte inside the text (the length says there is more). */
    lr_json *j = NULL;
    lr_err e = {0};
    assert_int_equal(lr_json_parse("[1]\0x", 5, "z.json", &j, &e), LR_EPARSE);
    assert_null(j);
    assert_non_null(strstr(e.msg, "z.json:1: text after the top-level value"));
}

/* ---- accepted edge cases ------------------------------------------------------------------- */

static double num_of(const char *text)
{
    lr_json *j = parse_ok(text);
    double v = -1;
    lr_err e = {0};
    if (lr_json_number(j, lr_json_root(j), "v", &v, &e) != LR_OK)
        fail_msg("%s: %s", text, e.msg);
    lr_json_destroy(j);
    return v;
}

static void test_accepts_edge_cases(void **state)
{
    (void)state;
    assert_true(num_of("1e308") == 1e308);
    assert_true(num_of("-1.7976931348623157e308") == -DBL_MAX);
    assert_true(num_of("2.2250738585072014e-308") == DBL_MIN);
    /* Subnormals are finite doubles and are accepted (decision: only a nonzero number that
     * reads as 0 or as infinity is refused). 5e-324 rounds to the smallest, 2^-1074. */
    assert_true(num_of("5e-324") == nextafter(0.0, 1.0));
    assert_true(num_of("1e-310") > 0 && num_of("1e-310") < DBL_MIN);
    double z = num_of("-0");
    assert_true(z == 0 && signbit(z));
    assert_true(num_of("0e-400") == 0); /* zero is not an underflow */
    assert_true(num_of("0.000e999") == 0);
    assert_true(num_of("-0.0E+0") == 0);
    assert_true(num_of("123.456e-2") == 1.23456);
    assert_true(num_of(" \t\r\n 7 \n") == 7);
    /* Top-level scalars (RFC 8259 allows any value). */
    lr_json *j = parse_ok("true");
    assert_int_equal(lr_json_type(j, lr_json_root(j)), LR_JSON_BOOL);
    lr_json_destroy(j);
    j = parse_ok("null");
    assert_int_equal(lr_json_type(j, lr_json_root(j)), LR_JSON_NULL);
    lr_json_destroy(j);
    j = parse_ok("[false, null, {}, [], \"\"]");
    bool b = true;
    assert_int_equal(lr_json_bool(j, lr_json_at(j, 0, 0), "b", &b, NULL), LR_OK);
    assert_false(b);
    assert_int_equal(lr_json_type(j, lr_json_at(j, 0, 1)), LR_JSON_NULL);
    assert_int_equal(lr_json_count(j, lr_json_at(j, 0, 2)), 0);
    assert_int_equal(lr_json_type(j, lr_json_at(j, 0, 3)), LR_JSON_ARRAY);
    assert_true(lr_json_str_eq(j, lr_json_at(j, 0, 4), ""));
    lr_json_destroy(j);
    /* Escapes: \u00e9 and raw UTF-8 'é' are the same two bytes; a surrogate pair is one code
     * point (U+1F56F, a candle: 4 bytes of UTF-8); every short escape. */
    j = parse_ok("[\"\\u00e9\", \"\xc3\xa9\", \"\\ud83d\\udd6f\", \"\\\"\\\\\\/\\b\\f\\n\\r\\t\","
                 " \"\\u20AC\", \"\xf0\x9f\x95\xaf\"]");
    char s[16];
    assert_int_equal(lr_json_string(j, lr_json_at(j, 0, 0), "s", s, sizeof s, NULL), LR_OK);
    assert_string_equal(s, "\xc3\xa9");
    assert_true(lr_json_str_eq(j, lr_json_at(j, 0, 1), "\xc3\xa9"));
    assert_int_equal(lr_json_string(j, lr_json_at(j, 0, 2), "s", s, sizeof s, NULL), LR_OK);
    assert_string_equal(s, "\xf0\x9f\x95\xaf");
    assert_int_equal(lr_json_string(j, lr_json_at(j, 0, 3), "s", s, sizeof s, NULL), LR_OK);
    assert_string_equal(s, "\"\\/\b\f\n\r\t");
    assert_true(lr_json_str_eq(j, lr_json_at(j, 0, 4), "\xe2\x82\xac"));
    assert_true(lr_json_str_eq(j, lr_json_at(j, 0, 5), "\xf0\x9f\x95\xaf"));
    lr_json_destroy(j);
    /* A UTF-8 byte-order mark is skipped (RFC 8259 section 8.1 allows it). */
    j = parse_ok("\xef\xbb\xbf{\"a\": 1}");
    assert_int_equal(lr_json_count(j, lr_json_root(j)), 1);
    lr_json_destroy(j);
}

static void test_nesting_depth_limit(void **state)
{
    (void)state;
    /* 512 levels are read; deeper is refused while scanning, with a message: 100000 unclosed
     * '[' and 100000 '{"a":' fail cleanly, with no recursion to overflow the stack. */
    size_t depth = 512;
    char *text = malloc(5 * 100000 + 1);
    memset(text, '[', depth);
    memset(text + depth, ']', depth);
    text[2 * depth] = '\0';
    lr_json *j = parse_ok(text);
    assert_int_equal(lr_json_count(j, lr_json_root(j)), 1);
    assert_int_equal(lr_json_at(j, lr_json_root(j), 0), 1);
    lr_json_destroy(j);
    memset(text, '[', depth + 1);
    memset(text + depth + 1, ']', depth + 1);
    text[2 * depth + 2] = '\0';
    expect_parse_error(text, "bad.json:1: nesting deeper than 512 levels");
    memset(text, '[', 100000);
    text[100000] = '\0';
    expect_parse_error(text, "bad.json:1: nesting deeper than 512 levels");
    for (int i = 0; i < 100000; i++)
        memcpy(text + 5 * i, "{\"a\":", 5);
    text[500000] = '\0';
    expect_parse_error(text, "bad.json:1: nesting deeper than 512 levels");
    free(text);
}

/* Every JSON file the project ships parses under the strict reader. */
static void check_dir(const char *dir, int *count)
{
    DIR *d = opendir(dir);
    if (!d)
        fail_msg("%s: cannot open", dir);
    struct dirent *de;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.')
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        struct stat st;
        assert_int_equal(stat(path, &st), 0);
        size_t n = strlen(de->d_name);
        if (S_ISDIR(st.st_mode)) {
            check_dir(path, count);
        } else if (n > 5 && strcmp(de->d_name + n - 5, ".json") == 0) {
            lr_json *j = NULL;
            lr_err e = {0};
            if (lr_json_load(path, &j, &e) != LR_OK)
                fail_msg("%s", e.msg);
            lr_json_destroy(j);
            (*count)++;
        }
    }
    closedir(d);
}

static void test_shipped_files_are_strict(void **state)
{
    (void)state;
    int count = 0;
    char fixtures[1024];
    check_dir(lr_configs_dir(), &count);
    snprintf(fixtures, sizeof fixtures, "%s/../tests/fixtures", lr_configs_dir());
    check_dir(fixtures, &count);
    assert_true(count >= 30); /* materials, scenes, rig, controls, references */
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
        cmocka_unit_test(test_rejects_invalid_literals),
        cmocka_unit_test(test_rejects_trailing_commas),
        cmocka_unit_test(test_rejects_malformed_numbers),
        cmocka_unit_test(test_rejects_out_of_range_numbers),
        cmocka_unit_test(test_int_range),
        cmocka_unit_test(test_rejects_bad_strings),
        cmocka_unit_test(test_rejects_duplicate_keys),
        cmocka_unit_test(test_rejects_trailing_text),
        cmocka_unit_test(test_accepts_edge_cases),
        cmocka_unit_test(test_nesting_depth_limit),
        cmocka_unit_test(test_load_file),
        cmocka_unit_test(test_shipped_files_are_strict),
    };
    return cmocka_run_group_tests_name("json", tests, NULL, NULL);
}
