#include "firmware/cli.h"

#include <stdarg.h>
#include <stdlib.h>
#include <stdbool.h>
#include <string.h>
#include <time.h>

#include "firmware/version.h"
#include "render/base/atomic_file.h"
#include "render/base/paths.h"
#include "render/base/cache_dir.h"
#include "render/base/dir_check.h"
#include "render/gl/shader_cache.h"
#include "render/transrad/transrad.h"
#include "hal/log.h"

/* ---- messages ------------------------------------------------------------------------- */

/* "calib projector patterns" -> "calib": the prefix every message of the command carries. */
static int top_len(const char *path) { return (int)strcspn(path, " "); }

static void vmessage(const char *path, const char *fmt, va_list ap, int pointer)
{
    char msg[LR_ERR_MSG_MAX];
    vsnprintf(msg, sizeof msg, fmt, ap);
    /* One line, whatever the user typed. */
    for (char *c = msg; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    if (!path)
        fprintf(stderr, "lamprig: %s%s\n", msg, pointer ? " (see `lamprig help`)" : "");
    else if (pointer)
        fprintf(stderr, "lamprig %.*s: %s (see `lamprig help %s`)\n", top_len(path), path, msg,
                path);
    else
        fprintf(stderr, "lamprig %.*s: %s\n", top_len(path), path, msg);
}

int lr_cli_usage(const char *path, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vmessage(path, fmt, ap, 1);
    va_end(ap);
    return LR_EXIT_USAGE;
}

int lr_cli_fail(const char *path, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vmessage(path, fmt, ap, 0);
    va_end(ap);
    return LR_EXIT_FAIL;
}

static void cli_warn(void *path, const char *msg)
{
    const char *p = path;
    char line[LR_ERR_MSG_MAX];
    snprintf(line, sizeof line, "%s", msg);
    for (char *c = line; *c; c++) /* one line, as every message of the CLI */
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    if (p)
        fprintf(stderr, "lamprig %.*s: warning: %s\n", top_len(p), p, line);
    else
        fprintf(stderr, "lamprig: warning: %s\n", line);
}

lr_warn_sink lr_cli_warn_sink(const char *path)
{
    return (lr_warn_sink){cli_warn, (void *)path};
}

/* A top-level command is named by the prefix already: "--scene FILE is required"; a
 * subcommand says which one needs it: "dirpole needs --xo x,y,z". */
static int missing(const char *path, const lr_argspec *s)
{
    const char *sub = path + top_len(path);
    const char *mv = lr_args_metavar(s);
    if (*sub)
        return lr_cli_usage(path, "%s needs %s%s%s", sub + 1, s->name, *mv ? " " : "", mv);
    return lr_cli_usage(path, "%s%s%s is required", s->name, *mv ? " " : "", mv);
}

int lr_cli_need(const lr_cli *c, const char *flag)
{
    if (lr_args_has(&c->args, flag))
        return LR_EXIT_OK;
    const lr_argspec *s = lr_args_spec(&c->args, flag);
    if (!s)
        return lr_cli_usage(c->path, "internal: no option %s", flag);
    return missing(c->path, s);
}

int lr_cli_check(const lr_cli *c, int rc, const lr_err *e)
{
    return rc ? lr_cli_usage(c->path, "%s", e->msg) : LR_EXIT_OK;
}

/* ---- before the work -------------------------------------------------------------------- */

/* A full or read-only cache disk must cost the shader cache, not the rig: Mesa's cache dies
 * with SIGBUS on a full disk (render/gl/shader_cache.h). Disabled for this process before any
 * GL context exists (Mesa reads the variable at eglInitialize; no other thread runs yet), with
 * one warning naming the folder. */
static void guard_shader_cache(void)
{
    lr_err e = {0};
    if (lr_gl_shader_cache_check(&e) == LR_OK)
        return;
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
    lr_log_write(NULL, LR_LOG_WARN, "%s; running without it (shaders compiled at every start)",
                 e.msg);
}

/* Free space our cache folder should have: the sim rig's precomputations take 12 MB. */
#define CACHE_MIN_FREE (16u << 20)

/* The precomputation caches ($XDG_CACHE_HOME/lamprig, render/transrad/cache.c): a folder that
 * cannot take writes costs every start a rebuild of seconds, said here once rather than never
 * (each store fails quietly: best effort). Otherwise stale temps of a killed writer are swept
 * and the folder is held to its cap (render/base/cache_dir.h). */
static void tidy_caches(void)
{
    char dir[1024];
    if (!lr_tr_cache_default_dir(dir, sizeof dir))
        return;
    lr_err e = {0};
    if (lr_dir_check_writable(dir, CACHE_MIN_FREE, &e)) {
        lr_log_write(NULL, LR_LOG_WARN, "cache folder: %s; precomputations (translucent "
                     "radiosity, receiver light) are rebuilt at every start", e.msg);
        return;
    }
    uint64_t cap;
    if (lr_cache_max_bytes(&cap, &e))
        lr_log_write(NULL, LR_LOG_WARN, "%s; using %llu MiB", e.msg,
                     (unsigned long long)(cap >> 20));
    lr_cache_tidy t;
    if (lr_cache_dir_tidy(dir, cap, time(NULL), &t, &e))
        lr_log_write(NULL, LR_LOG_WARN, "cache folder: %s", e.msg);
    else if (t.temps_removed || t.files_removed)
        lr_log_write(NULL, LR_LOG_INFO, "cache folder %s: removed %d stale temporary files and "
                     "%d cache files (%llu -> %llu MiB, cap %llu MiB)", dir, t.temps_removed,
                     t.files_removed, (unsigned long long)(t.bytes_before >> 20),
                     (unsigned long long)(t.bytes_after >> 20), (unsigned long long)(cap >> 20));
}

/* ---- dispatch ------------------------------------------------------------------------- */

static int is_help(const char *a) { return !strcmp(a, "--help") || !strcmp(a, "-h"); }

static const lr_command *find_sub(const lr_command *group, const char *name)
{
    for (const lr_command *const *s = group->subs; *s; s++)
        if (!strcmp((*s)->name, name))
            return *s;
    return NULL;
}

/* "a, b or c" (joined with `last` before the final name). */
static void sub_names(const lr_command *group, const char *last, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = '\0';
    for (const lr_command *const *s = group->subs; *s && n < cap; s++) {
        const char *sep = s == group->subs ? "" : s[1] ? ", " : last;
        n += (size_t)snprintf(buf + n, cap - n, "%s%s", sep, (*s)->name);
    }
}

/* Whether an LR_ARG_ALONE option (one that answers by itself) was given. */
static bool alone_given(const lr_cli *c)
{
    for (int k = 0; k < c->args.nspecs; k++)
        if ((c->cmd->opts[k].flags & LR_ARG_ALONE) && c->args.value[k])
            return true;
    return false;
}

int lr_cli_command(const lr_command *cmd, const char *parent, int argc, char **argv)
{
    char path[256];
    if (parent)
        snprintf(path, sizeof path, "%s %s", parent, cmd->name);
    else
        snprintf(path, sizeof path, "%s", cmd->name);
    if (cmd->subs) {
        char names[512];
        if (argc < 2) {
            sub_names(cmd, " or ", names, sizeof names);
            return lr_cli_usage(path, "missing subcommand: %s", names);
        }
        if (is_help(argv[1])) {
            lr_help_print(stdout, cmd, path);
            return LR_EXIT_OK;
        }
        const lr_command *sub = find_sub(cmd, argv[1]);
        if (!sub) {
            sub_names(cmd, ", ", names, sizeof names);
            return lr_cli_usage(path, "unknown subcommand '%s' (%s)", argv[1], names);
        }
        return lr_cli_command(sub, path, argc - 1, argv + 1);
    }
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--help") || (i == 1 && is_help(argv[i]))) {
            lr_help_print(stdout, cmd, path);
            return LR_EXIT_OK;
        }
    lr_cli *c = calloc(1, sizeof *c);
    if (!c)
        return lr_cli_fail(path, "out of memory");
    c->cmd = cmd;
    c->path = path;
    lr_err e = {0};
    int st = LR_EXIT_OK;
    const lr_argspec *need;
    if (lr_args_parse(argc - 1, argv + 1, cmd->opts, cmd->max_operands, &c->args, &e))
        st = lr_cli_usage(path, "%s", e.msg);
    else if (!alone_given(c) && (need = lr_args_missing(&c->args)))
        st = missing(path, need);
    /* Files the command will write are checked before it does any work: a directory or a
     * folder that does not exist is a bad argument now, not an I/O failure after it. */
    for (int k = 0; !st && k < c->args.nspecs; k++)
        if ((cmd->opts[k].flags & LR_ARG_OUTPUT) && c->args.value[k] &&
            lr_atomic_file_check(c->args.value[k], &e))
            st = lr_cli_usage(path, "%s %s", cmd->opts[k].name, e.msg);
    if (!st) {
        guard_shader_cache();
        tidy_caches();
        st = cmd->run(c);
    }
    fflush(stdout);
    free(c);
    return st;
}

/* ---- the program ---------------------------------------------------------------------- */

static void print_help(FILE *f)
{
    fprintf(f, "usage: lamprig [--configs DIR] [--shaders DIR] COMMAND [ARGS...]\n\ncommands:\n");
    for (const lr_command *const *c = lr_commands; *c; c++)
        fprintf(f, "  %-10s %s\n", (*c)->name, (*c)->summary);
    char shaders[1024];
    if (lr_shaders_dir(shaders, sizeof shaders) != 0)
        snprintf(shaders, sizeof shaders, "(path too long)");
    fprintf(f, "\n`lamprig help COMMAND` (or `lamprig COMMAND --help`) shows a command's "
               "arguments;\n`lamprig --version` (or `lamprig version`) prints the version.\n"
               "\nData (presets, scenes, example rigs; GLSL shaders), found in this order:\n"
               "--configs/--shaders, $LAMPRIG_CONFIGS/$LAMPRIG_SHADERS, ./configs, the installed\n"
               "PREFIX/share/lamprig beside the binary, the source tree it was built in.\n"
               "  configs  %s\n  shaders  %s\n", lr_configs_dir(), shaders);
}

static const lr_command *find(const char *name)
{
    for (const lr_command *const *c = lr_commands; *c; c++)
        if (strcmp((*c)->name, name) == 0)
            return *c;
    return NULL;
}

/* `lamprig help [COMMAND [SUBCOMMAND...]]`. */
static int help(int argc, char **argv)
{
    if (argc < 1) {
        print_help(stdout);
        return LR_EXIT_OK;
    }
    const lr_command *c = find(argv[0]);
    if (!c)
        return lr_cli_usage(NULL, "unknown command '%s'", argv[0]);
    char path[256];
    snprintf(path, sizeof path, "%s", c->name);
    for (int i = 1; i < argc; i++) {
        const lr_command *sub = c->subs ? find_sub(c, argv[i]) : NULL;
        if (!sub)
            return lr_cli_usage(path, "no subcommand '%s'", argv[i]);
        c = sub;
        size_t n = strlen(path);
        snprintf(path + n, sizeof path - n, " %s", c->name);
    }
    lr_help_print(stdout, c, path);
    return LR_EXIT_OK;
}

/* The global data options come before the command; they set the environment the library
 * reads (render/base/paths.h), so child processes see the same data. */
static const lr_argspec global_opts[] = {
    {.name = "--configs", .type = LR_ARG_PATH, .metavar = "DIR"},
    {.name = "--shaders", .type = LR_ARG_PATH, .metavar = "DIR"},
    {0},
};

int lr_cli_main(int argc, char **argv)
{
    lr_args *g = calloc(1, sizeof *g);
    if (!g)
        return LR_EXIT_FAIL;
    lr_err e = {0};
    int used = 0;
    if (lr_args_parse_head(argc - 1, argv + 1, global_opts, g, &used, &e)) {
        free(g);
        return lr_cli_usage(NULL, "%s", e.msg);
    }
    if (lr_args_has(g, "--configs"))
        setenv("LAMPRIG_CONFIGS", lr_args_get(g, "--configs"), 1);
    if (lr_args_has(g, "--shaders"))
        setenv("LAMPRIG_SHADERS", lr_args_get(g, "--shaders"), 1);
    free(g);
    argc -= used;
    argv += used;
    if (argc < 2) {
        print_help(stderr);
        return LR_EXIT_USAGE;
    }
    const char *name = argv[1];
    if (!strcmp(name, "--version") || !strcmp(name, "version")) {
        printf("lamprig %s\n", lr_version());
        return LR_EXIT_OK;
    }
    if (!strcmp(name, "help") || is_help(name))
        return help(argc - 2, argv + 2);
    const lr_command *c = find(name);
    if (!c)
        return lr_cli_usage(NULL, "unknown command '%s'", name);
    return lr_cli_command(c, NULL, argc - 1, argv + 1);
}

lr_progress_meter *lr_cli_progress(const lr_cli *c)
{
    char prefix[300];
    snprintf(prefix, sizeof prefix, "lamprig %s", c->path);
    bool quiet = lr_args_spec(&c->args, "--quiet") && lr_args_has(&c->args, "--quiet");
    lr_progress_meter *m = NULL;
    lr_progress_meter_create(&(lr_progress_meter_desc){.prefix = prefix,
                                                        .style = quiet ? LR_PROGRESS_QUIET
                                                                       : LR_PROGRESS_AUTO},
                             &m, NULL);
    return m;
}
