/* lamprig render — headless rendering of a scene (see lr_render_usage). */
#ifndef LR_CMD_RENDER_H
#define LR_CMD_RENDER_H

extern const char lr_render_summary[];
extern const char lr_render_usage[];

/* argv[0] is "render". Returns an LR_EXIT_* status. */
int lr_cmd_render(int argc, char **argv);

#endif
