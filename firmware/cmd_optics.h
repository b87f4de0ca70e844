/* lamprig optics — a designer's view of a material (see lr_optics_usage). */
#ifndef LR_CMD_OPTICS_H
#define LR_CMD_OPTICS_H

extern const char lr_optics_summary[];
extern const char lr_optics_usage[];

/* argv[0] is "optics", argv[1] the subcommand. Returns an LR_EXIT_* status. */
int lr_cmd_optics(int argc, char **argv);

#endif
