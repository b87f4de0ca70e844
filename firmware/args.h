/* lamprig — command-line arguments shared by the subcommands: `--flag VALUE` options (also
 * `--flag=VALUE`) checked against a table, and comma-separated number lists ("1,2.5,3e-2").
 * Every error is one line naming the flag, for the caller to print and exit with status 2.
 */
#ifndef LR_ARGS_H
#define LR_ARGS_H

#include "render/base/err.h"

#define LR_ARGS_MAX 32

typedef struct lr_argspec {
    const char *name; /* "--sigma-a" */
    int takes_value;  /* 1: needs a value; 0: a switch */
} lr_argspec;

typedef struct lr_args {
    const lr_argspec *specs; /* the table given to lr_args_parse (NULL-name terminated) */
    int nspecs;
    const char *value[LR_ARGS_MAX]; /* value of specs[i]; "" for a switch; NULL when absent */
    int npos;
    const char *pos[LR_ARGS_MAX];   /* positional arguments, in order */
} lr_args;

/* Parses argv[0..argc) (no program or subcommand name in it) against specs, terminated by an
 * entry with name == NULL (at most LR_ARGS_MAX entries). Unknown flags, a missing value, a value
 * given to a switch, a flag given twice, and more than max_positional positional arguments are
 * errors (LR_EINVAL). A value may start with '-' ("--r -1" reaches the number check, which then
 * names the flag). */
int lr_args_parse(int argc, char **argv, const lr_argspec *specs, int max_positional,
                  lr_args *out, lr_err *e);

/* The value of flag `name` (which must be in the table), or NULL when it was not given. */
const char *lr_args_get(const lr_args *a, const char *name);
/* Whether flag `name` was given. */
int lr_args_has(const lr_args *a, const char *name);

/* One finite decimal number ("1", "-2.5e-3"); NaN, Inf, hex and trailing text are errors. */
int lr_args_number(const char *flag, const char *text, double *out, lr_err *e);
/* A comma-separated list of min..max finite decimal numbers; *count receives how many. */
int lr_args_numbers(const char *flag, const char *text, double *out, int min, int max,
                    int *count, lr_err *e);
/* Exactly three numbers (an RGB triple, a position, a direction). */
int lr_args_triple(const char *flag, const char *text, double out[3], lr_err *e);
/* Exposure times "1/30,0.5,2" (fractions allowed, each > 0 and finite) into t[cap]: the
 * count, or -1 when malformed or more than cap. */
int lr_args_times(const char *s, double *t, int cap);

#endif
