/* lamprig run — the rig firmware's main program (see lr_run_usage, firmware/rig/rig.h). */
#ifndef LR_CMD_RUN_H
#define LR_CMD_RUN_H

extern const char lr_run_summary[];
extern const char lr_run_usage[];

/* argv[0] is "run". Returns an LR_EXIT_* status. */
int lr_cmd_run(int argc, char **argv);

#endif
