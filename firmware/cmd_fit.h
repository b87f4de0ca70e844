/* lamprig fit — material parameters from captures (issue 5 item 5; calib/fit.h). */
#ifndef LR_CMD_FIT_H
#define LR_CMD_FIT_H

extern const char lr_fit_summary[];
extern const char lr_fit_usage[];

/* argv[0] is "fit". Returns an LR_EXIT_* status. */
int lr_cmd_fit(int argc, char **argv);

#endif
