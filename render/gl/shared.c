/* lamprig — a second GL context sharing the first one's objects (gl.h, lr_gl_create_shared). */
#include "render/gl/gl_priv.h"

#include <stdlib.h>

static int shared_present(lr_gl *gl, lr_err *e)
{
    (void)gl;
    (void)e;
    glFlush();
    return LR_OK;
}

static const lr_gl_ops shared_ops = {
    .name = "shared",
    .present = shared_present,
};

int lr_gl_create_shared(lr_gl *parent, lr_gl **out, lr_err *e)
{
    *out = NULL;
    if (!parent)
        return lr_err_set(e, LR_EINVAL, "GL: shared context without a parent");
    const char *exts = eglQueryString(parent->dpy, EGL_EXTENSIONS);
    /* The worker has no surface of its own: it draws into framebuffer objects only. */
    if (!lr_gl__has_ext(exts, "EGL_KHR_surfaceless_context"))
        return lr_err_set(e, LR_EUNSUPPORTED,
                          "EGL: a worker context needs EGL_KHR_surfaceless_context");
    lr_gl *gl = calloc(1, sizeof *gl);
    if (!gl)
        return lr_err_set(e, LR_ENOMEM, "GL: shared context");
    gl->backend = parent->backend;
    gl->ops = &shared_ops;
    gl->dpy = parent->dpy;
    gl->config = parent->config;
    gl->surface = EGL_NO_SURFACE;
    gl->shared = true;
    gl->caps = parent->caps;
    static const EGLint attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 3,
        EGL_CONTEXT_MINOR_VERSION, 1,
        EGL_NONE,
    };
    gl->ctx = eglCreateContext(gl->dpy, gl->config, parent->ctx, attribs);
    int rc = LR_OK;
    if (gl->ctx == EGL_NO_CONTEXT)
        rc = lr_err_set(e, LR_EGL, "EGL: eglCreateContext (shared, OpenGL ES 3.1): %s",
                        lr_gl__egl_error_str(eglGetError()));
    if (!rc && !eglMakeCurrent(gl->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, gl->ctx))
        rc = lr_err_set(e, LR_EGL, "EGL: eglMakeCurrent (shared): %s",
                        lr_gl__egl_error_str(eglGetError()));
    if (!rc) {
        glGenVertexArrays(1, &gl->empty_vao); /* vertex arrays are not shared */
        rc = lr_gl_check("GL: vertex array (shared context)", e);
    }
    if (rc) {
        lr_gl_destroy(gl);
        return rc;
    }
    *out = gl;
    return LR_OK;
}
