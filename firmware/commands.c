/* The subcommands of lamprig, in the order `lamprig help` lists them. */
#include "firmware/cli.h"

#include <stddef.h>

#include "firmware/cmd_optics.h"

const lr_command lr_commands[] = {
    {"optics", lr_optics_summary, lr_optics_usage, lr_cmd_optics},
    {NULL, NULL, NULL, NULL},
};
