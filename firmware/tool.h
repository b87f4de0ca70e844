/* lamprig — the argv of the tools (build/bin/lamprig-NAME, tools/NAME/main.c) through the same
 * option tables as the program's commands (firmware/args.h, firmware/cli.h): a tool describes
 * itself as one leaf lr_command whose name is the program ("lamprig-cpuref"), gets its --help
 * generated from the table, and reports every bad argument as one line naming the flag with
 * exit status 2 (LR_EXIT_USAGE), as `lamprig COMMAND` does.
 */
#ifndef LR_TOOL_H
#define LR_TOOL_H

#include "firmware/cli.h"

/* Parses argv[1..argc) (argv[0] the program) against cmd->opts with at most
 * cmd->max_operands positional arguments. `--help` anywhere (or `-h` first) prints the
 * generated help on stdout: LR_EXIT_OK. A syntax error (unknown flag, missing value, a flag
 * given twice, too many operands) or a missing LR_ARG_REQUIRED option (unless an
 * LR_ARG_ALONE one was given) prints one usage line: LR_EXIT_USAGE. Otherwise -1: the tool
 * goes on with *out. */
int lr_tool_args(const lr_command *cmd, int argc, char **argv, lr_args *out);

/* The usage error: `PROGRAM: MESSAGE (see `PROGRAM --help`)` on one line on stderr (control
 * characters shown as '?'); returns LR_EXIT_USAGE. For the typed getters' errors:
 * `if (lr_args_int(&a, "--n", &n, &e) || ...) return lr_tool_usage(P, "%s", e.msg);`. */
int lr_tool_usage(const char *program, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

#endif
