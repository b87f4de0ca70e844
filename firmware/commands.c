/* The subcommands of lamprig, in the order `lamprig help` lists them. */
#include "firmware/cli.h"

#include <stddef.h>

#include "firmware/cmd_calib.h"

const lr_command lr_commands[] = {
    {"calib", "calibrate camera, projector and radiometry; check calibration files",
     lr_cmd_calib_usage, lr_cmd_calib},
    {NULL, NULL, NULL, NULL},
};
