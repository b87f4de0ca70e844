/* lamprig — section timing: EXT_disjoint_timer_query, or glFinish + CLOCK_MONOTONIC. */
#include "render/gl/timer.h"

#include <EGL/egl.h>
#include <GLES3/gl31.h>
/* after gl31.h: the extension header needs its platform macros */
#include <GLES2/gl2ext.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

typedef struct section {
    char name[32];
    GLuint query;    /* GPU mode */
    double t0;       /* CPU mode: start, seconds */
    double ms;
} section;

struct lr_timer {
    bool gpu;
    bool open;
    int count, max;
    section *s;
    /* EXT_disjoint_timer_query entry points (not in the core GLES 3.1 library). */
    PFNGLGENQUERIESEXTPROC gen;
    PFNGLDELETEQUERIESEXTPROC del;
    PFNGLBEGINQUERYEXTPROC begin;
    PFNGLENDQUERYEXTPROC end;
    PFNGLGETQUERYOBJECTUI64VEXTPROC get_u64;
};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

int lr_timer_create(lr_gl *gl, const lr_timer_desc *d, lr_timer **out, lr_err *e)
{
    static const lr_timer_desc defaults = {0};
    if (!d)
        d = &defaults;
    *out = NULL;
    if (d->max_sections < 0)
        return lr_err_set(e, LR_EINVAL, "timer: max_sections %d < 0", d->max_sections);
    lr_timer *t = calloc(1, sizeof *t);
    if (!t)
        return lr_err_set(e, LR_ENOMEM, "timer");
    t->max = d->max_sections ? d->max_sections : 16;
    t->s = calloc((size_t)t->max, sizeof *t->s);
    if (!t->s) {
        free(t);
        return lr_err_set(e, LR_ENOMEM, "timer");
    }
    if (!d->cpu && lr_gl_caps_get(gl)->timer_query) {
        t->gen = (PFNGLGENQUERIESEXTPROC)eglGetProcAddress("glGenQueriesEXT");
        t->del = (PFNGLDELETEQUERIESEXTPROC)eglGetProcAddress("glDeleteQueriesEXT");
        t->begin = (PFNGLBEGINQUERYEXTPROC)eglGetProcAddress("glBeginQueryEXT");
        t->end = (PFNGLENDQUERYEXTPROC)eglGetProcAddress("glEndQueryEXT");
        t->get_u64 = (PFNGLGETQUERYOBJECTUI64VEXTPROC)eglGetProcAddress("glGetQueryObjectui64vEXT");
        t->gpu = t->gen && t->del && t->begin && t->end && t->get_u64;
    }
    if (t->gpu) {
        for (int i = 0; i < t->max; i++)
            t->gen(1, &t->s[i].query);
        /* Clear a stale disjoint flag so the first frame is judged on its own. */
        GLint disjoint;
        glGetIntegerv(GL_GPU_DISJOINT_EXT, &disjoint);
    }
    int rc = lr_gl_check("timer", e);
    if (rc) {
        lr_timer_destroy(t);
        return rc;
    }
    *out = t;
    return LR_OK;
}

void lr_timer_destroy(lr_timer *t)
{
    if (!t)
        return;
    if (t->gpu)
        for (int i = 0; i < t->max; i++)
            t->del(1, &t->s[i].query);
    free(t->s);
    free(t);
}

bool lr_timer_is_gpu(const lr_timer *t) { return t->gpu; }

int lr_timer_begin(lr_timer *t, const char *name, lr_err *e)
{
    if (t->open)
        return lr_err_set(e, LR_EINVAL, "timer: \"%s\" begun while \"%s\" is open", name,
                          t->s[t->count].name);
    if (t->count == t->max)
        return lr_err_set(e, LR_EINVAL, "timer: more than %d sections in a frame", t->max);
    section *s = &t->s[t->count];
    snprintf(s->name, sizeof s->name, "%s", name);
    s->ms = NAN;
    if (t->gpu) {
        t->begin(GL_TIME_ELAPSED_EXT, s->query);
    } else {
        glFinish(); /* so the section does not also pay for earlier work */
        s->t0 = now_s();
    }
    t->open = true;
    return LR_OK;
}

int lr_timer_end(lr_timer *t, lr_err *e)
{
    if (!t->open)
        return lr_err_set(e, LR_EINVAL, "timer: end without begin");
    section *s = &t->s[t->count];
    if (t->gpu) {
        t->end(GL_TIME_ELAPSED_EXT);
    } else {
        glFinish();
        s->ms = (now_s() - s->t0) * 1e3;
    }
    t->open = false;
    t->count++;
    return LR_OK;
}

int lr_timer_collect(lr_timer *t, lr_err *e)
{
    if (t->open)
        return lr_err_set(e, LR_EINVAL, "timer: collect while \"%s\" is open", t->s[t->count].name);
    if (!t->gpu)
        return LR_OK;
    for (int i = 0; i < t->count; i++) {
        GLuint64 ns = 0;
        t->get_u64(t->s[i].query, GL_QUERY_RESULT_EXT, &ns); /* waits for the GPU */
        t->s[i].ms = (double)ns * 1e-6;
    }
    /* Read after the results: a disjoint event during any of them invalidates the frame. */
    GLint disjoint = 0;
    glGetIntegerv(GL_GPU_DISJOINT_EXT, &disjoint);
    if (disjoint) {
        for (int i = 0; i < t->count; i++)
            t->s[i].ms = NAN;
        return lr_err_set(e, LR_EIO, "timer: GPU disjoint event, this frame's times are invalid");
    }
    return lr_gl_check("timer", e);
}

void lr_timer_reset(lr_timer *t)
{
    t->count = 0;
    t->open = false;
}

int lr_timer_count(const lr_timer *t) { return t->count; }
const char *lr_timer_name(const lr_timer *t, int i) { return t->s[i].name; }
double lr_timer_ms(const lr_timer *t, int i) { return t->s[i].ms; }
