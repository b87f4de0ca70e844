/* lamprig's commands, one file each in firmware/commands/ (calib's subcommands in calib_*.c),
 * listed by firmware/commands/table.c in the order `lamprig help` shows them. Each is an
 * lr_command (firmware/cli.h): option table, help texts and run function. */
#ifndef LR_COMMANDS_H
#define LR_COMMANDS_H

#include "firmware/cli.h"

extern const lr_command lr_optics_command;
extern const lr_command lr_calib_command;
extern const lr_command lr_compare_command;
extern const lr_command lr_fit_command;
extern const lr_command lr_render_command;
extern const lr_command lr_run_command;
extern const lr_command lr_mqtt_send_command;
extern const lr_command lr_plan_command;

/* `lamprig calib ...` and `lamprig compare ...` with argv[0] "calib" / "compare": the same
 * dispatch as lr_cli_main (tests call them). Return an LR_EXIT_* status. */
int lr_cmd_calib(int argc, char **argv);
int lr_cmd_compare(int argc, char **argv);

#endif
