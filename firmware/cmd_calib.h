/* lamprig calib — the `calib` subcommand (camera, projector, radiometry, file checks). */
#ifndef LR_CMD_CALIB_H
#define LR_CMD_CALIB_H

extern const char lr_cmd_calib_usage[];
int lr_cmd_calib(int argc, char **argv);

#endif
