/* The subcommands of lamprig, in the order `lamprig help` lists them. */
#include "firmware/cli.h"

#include <stddef.h>

const lr_command lr_commands[] = {
    {NULL, NULL, NULL, NULL},
};
