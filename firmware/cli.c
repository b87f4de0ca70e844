#include "firmware/cli.h"

#include <stdio.h>
#include <string.h>

#include "firmware/version.h"

static void print_help(FILE *f)
{
    fprintf(f, "usage: lamprig COMMAND [ARGS...]\n\ncommands:\n");
    for (const lr_command *c = lr_commands; c->name; c++)
        fprintf(f, "  %-10s %s\n", c->name, c->summary);
    fprintf(f, "\n`lamprig help COMMAND` shows a command's arguments; `lamprig --version` "
               "(or `lamprig version`) prints the version.\n");
}

static const lr_command *find(const char *name)
{
    for (const lr_command *c = lr_commands; c->name; c++)
        if (strcmp(c->name, name) == 0)
            return c;
    return NULL;
}

int lr_cli_main(int argc, char **argv)
{
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
