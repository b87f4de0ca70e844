/* lamprig — command-line arguments, the parsing half of the CLI layer (firmware/cli.h is the
 * other half: the command table, usage errors and the generated --help). One table of options
 * per command says, per option, its name, the type and range of its value, its place in the
 * --help text and whether it is required; lr_args_parse checks the syntax (`--flag VALUE`,
 * `--flag=VALUE`, switches, repeats) and the typed getters convert and range-check the values
 * when the command reads them. Every error is one line naming the flag, for the caller to
 * print and exit with status 2 (lr_cli_usage).
 */
#ifndef LR_ARGS_H
#define LR_ARGS_H

#include "render/base/err.h"

#define LR_ARGS_MAX 32
/* Positional arguments (`calib check FILE...` over a folder's files). */
#define LR_ARGS_POS 1024
/* Values of repeatable options (--set k=v ..., --capture A B ...), all options together. */
#define LR_ARGS_MULTI 128

typedef enum lr_argtype {
    LR_ARG_SWITCH = 0,  /* no value */
    LR_ARG_STRING = 1,  /* any non-empty text: a name, a glob, key=value */
    LR_ARG_PATH,        /* a file or folder name; LR_ARG_OUTPUT: checked writable at start */
    LR_ARG_INT,         /* a whole number in [min, max] (lr_args_int) */
    LR_ARG_NUMBER,      /* a finite decimal number in the range (lr_args_double) */
    LR_ARG_NUMBERS,     /* comma-separated numbers, each in the range (lr_args_list) */
    LR_ARG_TRIPLE,      /* exactly three comma-separated numbers (lr_args_list) */
    LR_ARG_SIZE,        /* WIDTHxHEIGHT, each a whole number in [min, max] (lr_args_size) */
    LR_ARG_CHOICE,      /* one of `choices` (lr_args_choice) */
} lr_argtype;

enum {
    LR_ARG_REQUIRED = 1u << 0,  /* the command refuses to run without it */
    LR_ARG_ABOVE_MIN = 1u << 1, /* the range excludes min: "> 0" */
    LR_ARG_LIST = 1u << 2,      /* takes the following arguments up to the next --option */
    LR_ARG_OUTPUT = 1u << 3,    /* LR_ARG_PATH written by the command: checked before it runs */
    LR_ARG_ALONE = 1u << 4,     /* answers by itself (`--help-scene`): no option is required with it */
    LR_ARG_FLOOR = 1u << 5,     /* min is a bound even when it and max are 0: ">= 0" */
};

typedef struct lr_argspec {
    const char *name;    /* "--sigma-a" */
    int type;            /* lr_argtype; 0 (a switch) takes no value, any other type one */
    const char *metavar; /* the value's name in --help ("R,G,B"); NULL: from the type */
    const char *help;    /* the line after the option in --help; '\n' continues it */
    unsigned flags;      /* LR_ARG_* above */
    /* Value range: both 0 means any value (unless LR_ARG_ABOVE_MIN: then > 0, or
     * LR_ARG_FLOOR: then >= 0); max <= min means no upper bound. */
    double min, max;
    int repeat;          /* most values when it may repeat (or LR_ARG_LIST); 0: given once */
    const char *choices; /* LR_ARG_CHOICE: "chessboard|circles|acircles" */
    const char *group;   /* options shown as one word in synopses ("MATERIAL"), or NULL */
} lr_argspec;

typedef struct lr_args {
    const lr_argspec *specs; /* the table given to lr_args_parse (NULL-name terminated) */
    int nspecs;
    const char *value[LR_ARGS_MAX]; /* value of specs[i]; "" for a switch; NULL when absent */
    int count[LR_ARGS_MAX];         /* how many values specs[i] got */
    int npos;
    const char *pos[LR_ARGS_POS];   /* positional arguments, in order */
    int nmulti;                     /* values of repeatable options, in order */
    struct {
        int spec;
        const char *value;
    } multi[LR_ARGS_MULTI];
} lr_args;

/* Parses argv[0..argc) (no program or subcommand name in it) against specs, terminated by an
 * entry with name == NULL (at most LR_ARGS_MAX entries). Unknown flags, a missing value, a value
 * given to a switch, a flag given twice (or more than its repeat), and more than max_positional
 * positional arguments are errors (LR_EINVAL). A value may start with '-' ("--r -1" reaches the
 * number check, which then names the flag). Values are not checked against their type here:
 * the getters below do that when the command reads them. */
int lr_args_parse(int argc, char **argv, const lr_argspec *specs, int max_positional,
                  lr_args *out, lr_err *e);
/* The same, stopping at the first argument that is not one of the table's options: *used
 * receives how many of argv were (the program's options before its command name). */
int lr_args_parse_head(int argc, char **argv, const lr_argspec *specs, lr_args *out, int *used,
                       lr_err *e);

/* The first LR_ARG_REQUIRED option that was not given, or NULL. */
const lr_argspec *lr_args_missing(const lr_args *a);
/* The table entry of flag `name`, or NULL. */
const lr_argspec *lr_args_spec(const lr_args *a, const char *name);

/* The value of flag `name` (which must be in the table), or NULL when it was not given. */
const char *lr_args_get(const lr_args *a, const char *name);
/* Whether flag `name` was given. */
int lr_args_has(const lr_args *a, const char *name);
/* Every value of a repeatable or list option, in order, into out[cap]: the count. */
int lr_args_values(const lr_args *a, const char *name, const char **out, int cap);

/* Typed getters: when the flag was not given they return LR_OK and leave *out as it is (the
 * caller's default); a value that is malformed or outside the table's range is LR_EINVAL with
 * one line naming the flag and the value. */
int lr_args_int(const lr_args *a, const char *name, int *out, lr_err *e);
/* The same for whole numbers beyond int (seeds up to 2^53, the largest exact in a double). */
int lr_args_int64(const lr_args *a, const char *name, long long *out, lr_err *e);
int lr_args_double(const lr_args *a, const char *name, double *out, lr_err *e);
/* LR_ARG_TRIPLE (3 numbers) or LR_ARG_NUMBERS (1..cap numbers) into out; *count how many. */
int lr_args_list(const lr_args *a, const char *name, double *out, int cap, int *count,
                 lr_err *e);
int lr_args_size(const lr_args *a, const char *name, int *w, int *h, lr_err *e);
/* The index of the value in the option's choices. */
int lr_args_choice(const lr_args *a, const char *name, int *index, lr_err *e);

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

/* The value's name in --help: the table's metavar, else one from the type ("N", "WxH"). */
const char *lr_args_metavar(const lr_argspec *s);

#endif
