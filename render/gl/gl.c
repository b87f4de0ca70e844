/* lamprig — GL context: back-end dispatch, version check, capabilities. */
#include "render/gl/gl_priv.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Indexed by lr_gl_backend. */
static int (*const backend_init[])(lr_gl *, const lr_gl_desc *, lr_err *) = {
    [LR_GL_SURFACELESS] = lr_gl__surfaceless_init,
    [LR_GL_KMS] = lr_gl__kms_init,
    [LR_GL_DEVICE] = lr_gl__device_init,
};

static void copy_gl_string(char *dst, size_t cap, GLenum name)
{
    const char *s = (const char *)glGetString(name);
    snprintf(dst, cap, "%s", s ? s : "");
}

static int query_caps(lr_gl *gl, lr_err *e)
{
    lr_gl_caps *c = &gl->caps;
    copy_gl_string(c->renderer, sizeof c->renderer, GL_RENDERER);
    copy_gl_string(c->vendor, sizeof c->vendor, GL_VENDOR);

    GLint n = 0;
    glGetIntegerv(GL_NUM_EXTENSIONS, &n);
    const char **exts = calloc(n > 0 ? (size_t)n : 1, sizeof *exts);
    if (!exts)
        return lr_err_set(e, LR_ENOMEM, "GL: extension list");
    for (GLint i = 0; i < n; i++)
        exts[i] = (const char *)glGetStringi(GL_EXTENSIONS, (GLuint)i);
    int rc = lr_gl_caps_parse((const char *)glGetString(GL_VERSION), exts, n, c, e);
    free(exts);
    if (rc)
        return rc;
    if (c->major < 3 || (c->major == 3 && c->minor < 1))
        return lr_err_set(e, LR_EUNSUPPORTED, "GL: OpenGL ES 3.1 required, %s gives \"%s\"",
                          c->renderer, c->version);

    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &c->max_texture_size);
    glGetIntegerv(GL_MAX_CUBE_MAP_TEXTURE_SIZE, &c->max_cube_map_size);
    glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &c->max_array_layers);
    glGetIntegerv(GL_MAX_COLOR_ATTACHMENTS, &c->max_color_attachments);
    glGetIntegerv(GL_MAX_DRAW_BUFFERS, &c->max_draw_buffers);
    return lr_gl_check("GL: capability query", e);
}

int lr_gl_create(const lr_gl_desc *desc, lr_gl **out, lr_err *e)
{
    static const lr_gl_desc defaults = {0};
    if (!desc)
        desc = &defaults;
    *out = NULL;
    if ((unsigned)desc->backend >= sizeof backend_init / sizeof backend_init[0])
        return lr_err_set(e, LR_EINVAL, "GL: unknown back end %d", (int)desc->backend);
    if (desc->width < 0 || desc->height < 0 || desc->refresh_hz < 0)
        return lr_err_set(e, LR_EINVAL, "GL: negative mode size or refresh rate");

    lr_gl *gl = calloc(1, sizeof *gl);
    if (!gl)
        return lr_err_set(e, LR_ENOMEM, "GL: context");
    gl->backend = desc->backend;
    gl->dpy = EGL_NO_DISPLAY;
    gl->config = EGL_NO_CONFIG_KHR;
    gl->ctx = EGL_NO_CONTEXT;
    gl->surface = EGL_NO_SURFACE;

    int rc = backend_init[desc->backend](gl, desc, e);
    if (rc == LR_OK && !eglMakeCurrent(gl->dpy, gl->surface, gl->surface, gl->ctx))
        rc = lr_err_set(e, LR_EGL, "EGL: eglMakeCurrent: %s", lr_gl__egl_error_str(eglGetError()));
    if (rc == LR_OK)
        rc = query_caps(gl, e);
    if (rc == LR_OK) {
        glGenVertexArrays(1, &gl->empty_vao);
        rc = lr_gl_check("GL: vertex array", e);
    }
    if (rc) {
        lr_gl_destroy(gl);
        return rc;
    }
    *out = gl;
    return LR_OK;
}

void lr_gl_destroy(lr_gl *gl)
{
    if (!gl)
        return;
    if (gl->dpy != EGL_NO_DISPLAY) {
        if (gl->empty_vao && eglGetCurrentContext() == gl->ctx)
            glDeleteVertexArrays(1, &gl->empty_vao);
        eglMakeCurrent(gl->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (gl->ctx != EGL_NO_CONTEXT)
            eglDestroyContext(gl->dpy, gl->ctx);
        if (gl->surface != EGL_NO_SURFACE)
            eglDestroySurface(gl->dpy, gl->surface);
        /* Before the back end frees the native display (GBM device) it was made from; a
         * shared context leaves both to its parent. */
        if (!gl->shared)
            eglTerminate(gl->dpy);
    }
    if (!gl->shared && gl->ops && gl->ops->fini)
        gl->ops->fini(gl);
    free(gl);
}

const lr_gl_caps *lr_gl_caps_get(const lr_gl *gl) { return &gl->caps; }

void lr_gl__mem_add(lr_gl *gl, long long delta)
{
    if (delta < 0 && (size_t)-delta > gl->mem_bytes)
        gl->mem_bytes = 0; /* not reached: every free follows its own make */
    else
        gl->mem_bytes = (size_t)((long long)gl->mem_bytes + delta);
    if (gl->mem_bytes > gl->mem_peak)
        gl->mem_peak = gl->mem_bytes;
}

void lr_gl_memory(const lr_gl *gl, size_t *bytes, size_t *peak)
{
    if (bytes)
        *bytes = gl->mem_bytes;
    if (peak)
        *peak = gl->mem_peak;
}
lr_gl_backend lr_gl_backend_of(const lr_gl *gl) { return gl->backend; }
const char *lr_gl_backend_name(const lr_gl *gl) { return gl->ops->name; }

void lr_gl_size(const lr_gl *gl, int *width, int *height)
{
    if (width)
        *width = gl->width;
    if (height)
        *height = gl->height;
}

int lr_gl_make_current(lr_gl *gl, lr_err *e)
{
    if (!eglMakeCurrent(gl->dpy, gl->surface, gl->surface, gl->ctx))
        return lr_err_set(e, LR_EGL, "EGL: eglMakeCurrent: %s", lr_gl__egl_error_str(eglGetError()));
    return LR_OK;
}

void lr_gl_bind_default(lr_gl *gl)
{
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, gl->width, gl->height);
}

int lr_gl_present(lr_gl *gl, lr_err *e) { return gl->ops->present(gl, e); }

int lr_gl_event_fd(const lr_gl *gl) { return gl->ops->event_fd ? gl->ops->event_fd(gl) : -1; }

int lr_gl_dispatch(lr_gl *gl, lr_err *e) { return gl->ops->dispatch ? gl->ops->dispatch(gl, e) : LR_OK; }

bool lr_gl_flip_pending(const lr_gl *gl)
{
    return gl->ops->flip_pending ? gl->ops->flip_pending(gl) : false;
}

void lr_gl_draw_fullscreen(lr_gl *gl)
{
    glBindVertexArray(gl->empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
}

const char *lr_gl_error_str(unsigned err)
{
    switch (err) {
    case GL_NO_ERROR: return "GL_NO_ERROR";
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "unknown GL error";
    }
}

int lr_gl_check(const char *what, lr_err *e)
{
    GLenum first = glGetError();
    if (first == GL_NO_ERROR)
        return LR_OK;
    /* Drain the rest so the next check reports only what happens after this one. Bounded: a
     * lost context may return errors forever. */
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; i++)
        ;
    return lr_err_set(e, LR_EGL, "%s: %s", what, lr_gl_error_str(first));
}
