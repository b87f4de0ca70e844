/* lamprig — headless back end: EGL_PLATFORM_SURFACELESS_MESA, no window and no pbuffer.
 *
 * Nothing is ever shown, so every pass renders into framebuffer objects; framebuffer 0 does
 * not exist (lr_gl_size reports 0 x 0). */
#include "render/gl/gl_priv.h"

static int surfaceless_present(lr_gl *gl, lr_err *e)
{
    /* Nothing to scan out; flushing keeps the frame's work from piling up in the driver. */
    glFlush();
    return LR_OK;
}

static const lr_gl_ops surfaceless_ops = {
    .name = "surfaceless",
    .present = surfaceless_present,
};

int lr_gl__surfaceless_init(lr_gl *gl, const lr_gl_desc *desc, lr_err *e)
{
    gl->ops = &surfaceless_ops;
    int rc = lr_gl__egl_display(gl, EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY,
                                "EGL_MESA_platform_surfaceless", e);
    if (rc)
        return rc;
    const char *exts = eglQueryString(gl->dpy, EGL_EXTENSIONS);
    /* Making a context current without a surface is the whole point of this back end. */
    if (!lr_gl__has_ext(exts, "EGL_KHR_surfaceless_context"))
        return lr_err_set(e, LR_EUNSUPPORTED, "EGL: missing EGL_KHR_surfaceless_context");
    if (!lr_gl__has_ext(exts, "EGL_KHR_no_config_context")) {
        /* No surfaces will ever be made, so any GLES 3 config will do. */
        static const EGLint attribs[] = {
            EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT,
            EGL_SURFACE_TYPE, 0,
            EGL_NONE,
        };
        EGLint n = 0;
        if (!eglChooseConfig(gl->dpy, attribs, &gl->config, 1, &n) || n < 1)
            return lr_err_set(e, LR_EUNSUPPORTED, "EGL: no config with EGL_OPENGL_ES3_BIT: %s",
                              lr_gl__egl_error_str(eglGetError()));
    }
    return lr_gl__egl_context(gl, e);
}
