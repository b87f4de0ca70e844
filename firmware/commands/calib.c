/* `lamprig calib ...`: the group of calibration subcommands, one file each
 * (firmware/commands/calib_*.c; shared pieces in calib_cli.c). */
#include <stddef.h>

#include "firmware/commands/calib_cli.h"
#include "firmware/commands/commands.h"

const lr_command lr_calib_command = {
    .name = "calib",
    .summary = "calibrate camera, projector and radiometry; check calibration files",
    .about = "Calibration files are written atomically after validation: a failed run leaves the\n"
             "previous file as it was.",
    .notes = LR_CALIB_EXIT_NOTE,
    .subs = (const lr_command *const[]){&lr_calib_camera, &lr_calib_projector,
                                        &lr_calib_camera_response, &lr_calib_projector_response,
                                        &lr_calib_color, &lr_calib_pose, &lr_calib_albedo,
                                        &lr_calib_ar_frame, &lr_calib_check, NULL},
};
