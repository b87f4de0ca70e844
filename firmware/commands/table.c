/* The subcommands of lamprig, in the order `lamprig help` lists them. */
#include <stddef.h>

#include "firmware/commands/commands.h"

const lr_command *const lr_commands[] = {
    &lr_optics_command, &lr_calib_command, &lr_compare_command, &lr_fit_command,
    &lr_render_command, &lr_run_command,   &lr_mqtt_send_command, &lr_plan_command, NULL,
};

int lr_cmd_calib(int argc, char **argv)
{
    return lr_cli_command(&lr_calib_command, NULL, argc, argv);
}

int lr_cmd_compare(int argc, char **argv)
{
    return lr_cli_command(&lr_compare_command, NULL, argc, argv);
}
