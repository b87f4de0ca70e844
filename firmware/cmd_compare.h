/* lamprig compare — a comparison run: render the calibrated camera's view of a scene and
 * compare it with captures of the mockup (issue 5 item 4; see lr_compare_usage). */
#ifndef LR_CMD_COMPARE_H
#define LR_CMD_COMPARE_H

extern const char lr_compare_summary[];
extern const char lr_compare_usage[];

/* argv[0] is "compare". Returns an LR_EXIT_* status. */
int lr_cmd_compare(int argc, char **argv);

#endif
