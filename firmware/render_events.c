/* Event scripts of `lamprig render --events` (see render_events.h). */
#include "firmware/render_events.h"

#include <ctype.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/file.h"

static const char *skip_ws(const char *s, const char *end)
{
    while (s < end && (*s == ' ' || *s == '\t' || *s == '\r'))
        s++;
    return s;
}

int lr_render_events_parse(const char *text, const char *path, lr_render_events *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    snprintf(out->path, sizeof out->path, "%s", path);
    int cap = 0, line = 0, last = -1;
    const char *p = text;
    while (*p) {
        line++;
        const char *end = strchr(p, '\n');
        if (!end)
            end = p + strlen(p);
        const char *s = skip_ws(p, end);
        const char *next = *end ? end + 1 : end;
        if (s == end || *s == '#') {
            p = next;
            continue;
        }
        /* FRAME */
        char *num_end;
        errno = 0;
        long frame = strtol(s, &num_end, 10);
        if (num_end == s || num_end > end || errno || frame < 0 || frame > 100000000 ||
            (num_end < end && *num_end != ' ' && *num_end != '\t')) {
            lr_render_events_free(out);
            return lr_err_set(e, LR_EPARSE, "%s:%d: expected 'FRAME PARAMETER VALUE' with FRAME "
                              "a frame number >= 0", path, line);
        }
        if (frame < last) {
            lr_render_events_free(out);
            return lr_err_set(e, LR_EPARSE, "%s:%d: frame %ld comes before frame %d of an earlier "
                              "line (events must be in frame order)", path, line, frame, last);
        }
        const char *k = skip_ws(num_end, end), *ke = k;
        while (ke < end && *ke != ' ' && *ke != '\t')
            ke++;
        const char *v = skip_ws(ke, end), *ve = end;
        while (ve > v && isspace((unsigned char)ve[-1]))
            ve--;
        if (ke == k || ve == v) {
            lr_render_events_free(out);
            return lr_err_set(e, LR_EPARSE, "%s:%d: expected 'FRAME PARAMETER VALUE'%s", path, line,
                              ke == k ? ": no parameter" : ": no value");
        }
        lr_render_event ev = {.frame = (int)frame, .line = line};
        if ((size_t)(ke - k) >= sizeof ev.key || (size_t)(ve - v) >= sizeof ev.value) {
            lr_render_events_free(out);
            return lr_err_set(e, LR_EPARSE, "%s:%d: parameter or value too long", path, line);
        }
        memcpy(ev.key, k, (size_t)(ke - k));
        memcpy(ev.value, v, (size_t)(ve - v));
        if (out->count == cap) {
            cap = cap ? 2 * cap : 16;
            lr_render_event *n = realloc(out->ev, (size_t)cap * sizeof *n);
            if (!n) {
                lr_render_events_free(out);
                return lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
            }
            out->ev = n;
        }
        out->ev[out->count++] = ev;
        last = (int)frame;
        p = next;
    }
    return LR_OK;
}

int lr_render_events_load(const char *path, lr_render_events *out, lr_err *e)
{
    char *text = NULL;
    size_t len = 0;
    int rc = lr_file_read(path, LR_FILE_MAX_TEXT, &text, &len, e);
    if (rc)
        return rc;
    if (memchr(text, 0, len)) {
        free(text);
        return lr_err_set(e, LR_EPARSE, "%s: contains a NUL byte", path);
    }
    rc = lr_render_events_parse(text, path, out, e);
    free(text);
    return rc;
}

void lr_render_events_free(lr_render_events *ev)
{
    free(ev->ev);
    ev->ev = NULL;
    ev->count = 0;
}
