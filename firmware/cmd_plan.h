/* lamprig plan — what the planner would choose for a scene (see lr_plan_usage). */
#ifndef LR_CMD_PLAN_H
#define LR_CMD_PLAN_H

extern const char lr_plan_summary[];
extern const char lr_plan_usage[];

/* argv[0] is "plan". Returns an LR_EXIT_* status. */
int lr_cmd_plan(int argc, char **argv);

#endif
