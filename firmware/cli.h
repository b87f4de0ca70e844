/* lamprig — subcommand table of the one program, build/bin/lamprig. */
#ifndef LR_CLI_H
#define LR_CLI_H

/* Exit statuses shared by every subcommand. */
enum { LR_EXIT_OK = 0, LR_EXIT_FAIL = 1, LR_EXIT_USAGE = 2 };

typedef struct lr_command {
    const char *name;
    const char *summary; /* one line for `lamprig help` */
    const char *usage;   /* full usage for `lamprig help NAME` */
    /* argv[0] is the subcommand name. */
    int (*main)(int argc, char **argv);
} lr_command;

/* The table, terminated by an entry with name == NULL (firmware/commands.c). */
extern const lr_command lr_commands[];

int lr_cli_main(int argc, char **argv);

#endif
