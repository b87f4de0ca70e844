#include "firmware/tool.h"

#include <stdarg.h>
#include <stdbool.h>
#include <string.h>

int lr_tool_usage(const char *program, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* One line, whatever the user typed (a value with a newline in it). */
    for (char *c = msg; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    fprintf(stderr, "%s: %s (see `%s --help`)\n", program, msg, program);
    return LR_EXIT_USAGE;
}

int lr_tool_args(const lr_command *cmd, int argc, char **argv, lr_args *out)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || (i == 1 && !strcmp(argv[i], "-h"))) {
            lr_help_print_tool(stdout, cmd);
            return LR_EXIT_OK;
        }
    lr_err e = {0};
    if (lr_args_parse(argc - 1, argv + 1, cmd->opts, cmd->max_operands, out, &e))
        return lr_tool_usage(cmd->name, "%s", e.msg);
    for (int k = 0; k < out->nspecs; k++)
        if ((cmd->opts[k].flags & LR_ARG_ALONE) && out->value[k])
            return -1;
    const lr_argspec *s = lr_args_missing(out);
    if (s) {
        const char *mv = lr_args_metavar(s);
        return lr_tool_usage(cmd->name, "%s%s%s is required", s->name, *mv ? " " : "", mv);
    }
    return -1;
}
