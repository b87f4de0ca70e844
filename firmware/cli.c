#include "firmware/cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/version.h"
#include "render/base/paths.h"

static void print_help(FILE *f)
{
    fprintf(f, "usage: lamprig [--configs DIR] [--shaders DIR] COMMAND [ARGS...]\n\ncommands:\n");
    for (const lr_command *c = lr_commands; c->name; c++)
        fprintf(f, "  %-10s %s\n", c->name, c->summary);
    char shaders[1024];
    if (lr_shaders_dir(shaders, sizeof shaders) != 0)
        snprintf(shaders, sizeof shaders, "(path too long)");
    fprintf(f, "\n`lamprig help COMMAND` shows a command's arguments; `lamprig --version` "
               "(or `lamprig version`) prints the version.\n"
               "\nData (presets, scenes, example rigs; GLSL shaders), found in this order:\n"
               "--configs/--shaders, $LAMPRIG_CONFIGS/$LAMPRIG_SHADERS, ./configs, the installed\n"
               "PREFIX/share/lamprig beside the binary, the source tree it was built in.\n"
               "  configs  %s\n  shaders  %s\n", lr_configs_dir(), shaders);
}

static const lr_command *find(const char *name)
{
    for (const lr_command *c = lr_commands; c->name; c++)
        if (strcmp(c->name, name) == 0)
            return c;
    return NULL;
}

/* The global data options come before the command; they set the environment the library
 * reads (render/base/paths.h), so child processes see the same data. */
static int data_options(int *argc, char ***argv)
{
    while (*argc >= 2 && (!strcmp((*argv)[1], "--configs") || !strcmp((*argv)[1], "--shaders"))) {
        const char *opt = (*argv)[1];
        if (*argc < 3 || !(*argv)[2][0]) {
            fprintf(stderr, "lamprig: %s needs a directory (see `lamprig help`)\n", opt);
            return -1;
        }
        setenv(!strcmp(opt, "--configs") ? "LAMPRIG_CONFIGS" : "LAMPRIG_SHADERS", (*argv)[2], 1);
        (*argv)[2] = (*argv)[0];
        *argv += 2;
        *argc -= 2;
    }
    return 0;
}

int lr_cli_main(int argc, char **argv)
{
    if (data_options(&argc, &argv))
        return LR_EXIT_USAGE;
    if (argc < 2) {
        print_help(stderr);
        return LR_EXIT_USAGE;
    }
    const char *name = argv[1];
    if (!strcmp(name, "--version") || !strcmp(name, "version")) {
        printf("lamprig %s\n", lr_version());
        return LR_EXIT_OK;
    }
    if (!strcmp(name, "help") || !strcmp(name, "--help") || !strcmp(name, "-h")) {
        if (argc >= 3) {
            const lr_command *c = find(argv[2]);
            if (!c) {
                fprintf(stderr, "lamprig: unknown command '%s' (see `lamprig help`)\n", argv[2]);
                return LR_EXIT_USAGE;
            }
            printf("%s\n", c->usage);
            return LR_EXIT_OK;
        }
        print_help(stdout);
        return LR_EXIT_OK;
    }
    const lr_command *c = find(name);
    if (!c) {
        fprintf(stderr, "lamprig: unknown command '%s' (see `lamprig help`)\n", name);
        return LR_EXIT_USAGE;
    }
    return c->main(argc - 1, argv + 1);
}
