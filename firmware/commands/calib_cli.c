#include "firmware/commands/calib_cli.h"

#include <stdio.h>
#include <string.h>

#include "calib/camcal.h"

int lr_calib_board(const lr_cli *c, lr_board *b)
{
    const lr_args *a = &c->args;
    lr_err e = {0};
    int st, unused = 0;
    if (lr_board_parse_size(lr_args_get(a, "--board"), &b->cols, &b->rows, &e))
        return lr_cli_usage(c->path, "%s", e.msg);
    if ((st = lr_cli_check(c, lr_args_double(a, "--square", &b->square_mm, &e) ||
                                  lr_args_choice(a, "--pattern", &unused, &e),
                           &e)))
        return st;
    b->pattern = LR_BOARD_CHESSBOARD;
    const char *pattern = lr_args_get(a, "--pattern");
    if (pattern && lr_board_parse_pattern(pattern, &b->pattern, &e))
        return lr_cli_usage(c->path, "%s", e.msg);
    if (lr_board_check(b, &e))
        return lr_cli_usage(c->path, "%s", e.msg);
    return LR_EXIT_OK;
}

int lr_calib_subpix(const lr_cli *c, int *out)
{
    const char *s = lr_args_get(&c->args, "--subpix-window");
    *out = 0;
    if (!s)
        return LR_EXIT_OK;
    if (strcmp(s, "auto") == 0) {
        *out = LR_SUBPIX_AUTO;
        return LR_EXIT_OK;
    }
    /* A number: the table's range would say "1..100", and "or auto" belongs in the message. */
    double v;
    lr_err e = {0};
    if (lr_args_number("--subpix-window", s, &v, &e) || v != (int)v || v < 1 || v > 100)
        return lr_cli_usage(c->path, "--subpix-window %s: must be a whole number in 1..100 or auto",
                            s);
    *out = (int)v;
    return LR_EXIT_OK;
}

int lr_calib_glob(const lr_cli *c, const char *pattern, glob_t *g)
{
    int rc = glob(pattern, 0, NULL, g);
    if (rc != 0 || g->gl_pathc == 0) {
        if (rc == 0)
            globfree(g);
        return lr_cli_fail(c->path, "no files match '%s'", pattern);
    }
    return LR_EXIT_OK;
}
