/* lamprig — the CLI layer of the one program, build/bin/lamprig: the command table, the
 * dispatch from it (subcommands, `--help`, required options), the one usage error and the
 * --help text generated from each command's option table (firmware/help.c). The commands
 * themselves live in firmware/commands/, one file each; the option tables are lr_argspec
 * (firmware/args.h).
 */
#ifndef LR_CLI_H
#define LR_CLI_H

#include <stdio.h>

#include "firmware/args.h"
#include "render/base/progress.h"
#include "render/base/warn.h"

/* Exit statuses shared by every subcommand. */
enum { LR_EXIT_OK = 0, LR_EXIT_FAIL = 1, LR_EXIT_USAGE = 2 };

struct lr_command;

/* What a command's run function receives: the parsed arguments, already checked for syntax
 * and required options, and its path for messages. */
typedef struct lr_cli {
    const struct lr_command *cmd;
    const char *path; /* "render", "calib projector patterns" */
    lr_args args;
} lr_cli;

/* A command: a leaf with an option table and a run function, or a group of subcommands
 * (`lamprig calib projector patterns`). Every text is shown by the generated --help. */
typedef struct lr_command {
    const char *name;
    const char *summary;    /* one line in the parent's list ('\n' continues it) */
    const char *about;      /* prose after the usage line; NULL: the summary */
    const lr_argspec *opts; /* leaf: its options, terminated by {0} */
    const char *operands;   /* leaf: the positional arguments in the synopsis ("FILE..."), or NULL */
    int max_operands;
    const char *notes;      /* prose after the options (exit status, examples), or NULL */
    int (*run)(const lr_cli *c);
    const struct lr_command *const *subs; /* group: its subcommands, NULL-terminated */
} lr_command;

/* The program's commands in the order `lamprig help` lists them, NULL-terminated
 * (firmware/commands/table.c). */
extern const lr_command *const lr_commands[];

/* The program: global options, `help`, `version`, then the command. */
int lr_cli_main(int argc, char **argv);

/* Runs one command of the table with argv[0] its name: a group picks its subcommand, a leaf
 * parses its options (`--help` anywhere prints the generated help) and runs. parent is the
 * path above it ("calib"), or NULL for a top-level command. Returns an LR_EXIT_* status. */
int lr_cli_command(const lr_command *cmd, const char *parent, int argc, char **argv);

/* The one usage error: prints `lamprig CMD: MESSAGE (see `lamprig help PATH`)` on one line
 * (CMD the top-level command of path, control characters shown as '?'; path NULL: the
 * program itself) and returns LR_EXIT_USAGE. */
int lr_cli_usage(const char *path, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* A failure after the arguments were accepted: `lamprig CMD: MESSAGE`, LR_EXIT_FAIL. */
int lr_cli_fail(const char *path, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The sink a command passes to lr_scene_load (and the other loaders that warn): each
 * warning as one line `lamprig CMD: warning: MESSAGE` on stderr (CMD the top-level command of
 * path, which must outlive the sink: the lr_cli's path does). */
lr_warn_sink lr_cli_warn_sink(const char *path);
/* Usage error for an option the command needs but did not get (the message of a missing
 * LR_ARG_REQUIRED option): LR_EXIT_OK when flag was given. */
int lr_cli_need(const lr_cli *c, const char *flag);
/* lr_cli_usage with e's message when rc is set; LR_EXIT_OK otherwise (typed getters:
 * `if ((st = lr_cli_check(c, lr_args_int(&c->args, "--n", &n, &e), &e))) return st;`). */
int lr_cli_check(const lr_cli *c, int rc, const lr_err *e);

/* The option every command that can run long takes: its progress lines off. */
#define LR_CLI_QUIET_OPT                                                                        \
    {.name = "--quiet", .help = "no progress lines on stderr (results and errors stay)"}
/* The command's progress printer (render/base/progress.h): lines on stderr prefixed
 * `lamprig PATH`, rewritten in place on a terminal, silent with --quiet (when the command's
 * table has LR_CLI_QUIET_OPT). NULL when out of memory: the work then runs unreported. Free
 * with lr_progress_meter_destroy. */
lr_progress_meter *lr_cli_progress(const lr_cli *c);

/* The generated help of cmd at path ("calib projector") into f (firmware/help.c). */
void lr_help_print(FILE *f, const lr_command *cmd, const char *path);
/* The same for a program of its own (a tool, firmware/tool.h): cmd->name is the program
 * ("lamprig-cpuref"), the usage line `usage: lamprig-cpuref OPTIONS...`. */
void lr_help_print_tool(FILE *f, const lr_command *cmd);

#endif
