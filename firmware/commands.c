/* The subcommands of lamprig, in the order `lamprig help` lists them. */
#include "firmware/cli.h"

#include <stddef.h>

#include "firmware/cmd_calib.h"
#include "firmware/cmd_compare.h"
#include "firmware/cmd_optics.h"
#include "firmware/cmd_plan.h"
#include "firmware/cmd_render.h"
#include "firmware/cmd_run.h"

const lr_command lr_commands[] = {
    {"optics", lr_optics_summary, lr_optics_usage, lr_cmd_optics},
    {"calib", "calibrate camera, projector and radiometry; check calibration files",
     lr_cmd_calib_usage, lr_cmd_calib},
    {"compare", lr_compare_summary, lr_compare_usage, lr_cmd_compare},
    {"render", lr_render_summary, lr_render_usage, lr_cmd_render},
    {"run", lr_run_summary, lr_run_usage, lr_cmd_run},
    {"plan", lr_plan_summary, lr_plan_usage, lr_cmd_plan},
    {NULL, NULL, NULL, NULL},
};
