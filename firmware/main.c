/* lamprig — firmware for a lamp-design rig. One program, several subcommands (firmware/cli.c). */
#include "firmware/cli.h"

int main(int argc, char **argv)
{
    return lr_cli_main(argc, argv);
}
