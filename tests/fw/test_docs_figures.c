/* README.md's figures block is what `lamprig-bench --figures` generates from the committed
 * bench results (docs/bench/rig.csv, configs/bench/models.csv): no figure in it was typed by
 * hand. The check can fail (a figure changed by hand is caught) and --write restores the
 * block. Runs build/bin/lamprig-bench (built by `make test` before the tests). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "tests/support/fs.h"

#define ROOT LR_SOURCE_CONFIGS "/.."
#define BENCH ROOT "/build/bin/lamprig-bench"

static int run(const char *args)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s --figures %s", BENCH, args);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void test_readme_block_is_generated(void **state)
{
    (void)state;
    assert_int_equal(run("--check"), 0);
}

static void test_a_hand_edit_is_caught_and_write_restores(void **state)
{
    (void)state;
    size_t len;
    char *readme = (char *)lr_test_read(ROOT "/README.md", &len);
    char *b = strstr(readme, "<!-- BEGIN figures -->"), *e = b ? strstr(b, "<!-- END figures -->")
                                                                 : NULL;
    assert_non_null(b);
    assert_non_null(e);
    /* The first digit of a figure inside the block, changed. */
    char *d;
    for (d = strstr(b, "| "); d && d < e && !(d[2] >= '0' && d[2] <= '9'); d = strstr(d + 1, "| "))
        ;
    assert_true(d && d < e);
    char *dir = lr_test_tmpdir();
    char *copy = lr_test_path(dir, "README.md");
    char saved = d[2];
    d[2] = saved == '9' ? '1' : (char)(saved + 1);
    lr_test_put(copy, readme, len);
    char args[2048];
    snprintf(args, sizeof args, "--check '%s' 2>/dev/null", copy);
    assert_int_equal(run(args), 1);
    snprintf(args, sizeof args, "--write '%s' 2>/dev/null", copy);
    assert_int_equal(run(args), 0);
    snprintf(args, sizeof args, "--check '%s'", copy);
    assert_int_equal(run(args), 0);
    d[2] = saved;
    size_t n2;
    char *back = (char *)lr_test_read(copy, &n2);
    assert_int_equal(n2, len);
    assert_memory_equal(back, readme, len);
    free(back);
    free(copy);
    lr_test_rmtree(dir);
    free(readme);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_readme_block_is_generated),
        cmocka_unit_test(test_a_hand_edit_is_caught_and_write_restores),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
