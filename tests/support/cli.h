/* lamprig tests — running the built command line (build/bin/lamprig, built by `make test`) as
 * a child, the way a user does, for the CLI tests (test_cli_checks, test_plan,
 * test_render_cli). */
#ifndef LR_TEST_CLI_H
#define LR_TEST_CLI_H

/* Runs the shell command printf(fmt, ...) with stdin from /dev/null, stdout into DIR/out and
 * stderr into DIR/err; returns its exit status, -1 when it did not exit (a signal). Commands
 * longer than 2047 characters are cut. */
int lr_test_run_cli(const char *dir, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* DIR/NAME read whole (NUL-terminated); fails the running cmocka test when unreadable. The
 * caller frees. */
char *lr_test_slurp(const char *dir, const char *name);

#endif
