/* lamprig render --events: a script of scene changes, one per line,
 *
 *     FRAME PARAMETER VALUE      e.g.  4 light.intensity 0.5
 *
 * applied before frame FRAME (0-based) through lr_scene_set; PARAMETER is a scene-file name
 * (render/scene/scene.h), VALUE the rest of the line. Blank lines and lines starting with '#'
 * are ignored. Events must be in non-decreasing frame order. Errors name FILE:LINE. */
#ifndef LR_RENDER_EVENTS_H
#define LR_RENDER_EVENTS_H

#include "render/base/err.h"

typedef struct lr_render_event {
    int frame;
    int line;
    char key[128];
    char value[256];
} lr_render_event;

typedef struct lr_render_events {
    char path[256];
    int count;
    lr_render_event *ev; /* owned */
} lr_render_events;

/* Parses text (named `path` in messages). LR_EPARSE with "PATH:LINE: ..." on bad lines. */
int lr_render_events_parse(const char *text, const char *path, lr_render_events *out, lr_err *e);
/* Reads and parses a file. */
int lr_render_events_load(const char *path, lr_render_events *out, lr_err *e);
void lr_render_events_free(lr_render_events *ev);

#endif
