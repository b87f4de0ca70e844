/* lamprig — EGL display and GLES 3.1 context creation shared by both back ends. */
#include "render/gl/gl_priv.h"

#include <string.h>

bool lr_gl__has_ext(const char *list, const char *name)
{
    /* Whole-word match: "EGL_KHR_platform_gbm" must not match "EGL_KHR_platform_gbm_x". */
    size_t n = strlen(name);
    for (const char *p = list; p && (p = strstr(p, name)) != NULL; p += n) {
        bool start = p == list || p[-1] == ' ';
        bool end = p[n] == ' ' || p[n] == '\0';
        if (start && end)
            return true;
    }
    return false;
}

const char *lr_gl__egl_error_str(EGLint err)
{
    switch (err) {
#define C(x) case x: return #x
    C(EGL_SUCCESS);
    C(EGL_NOT_INITIALIZED);
    C(EGL_BAD_ACCESS);
    C(EGL_BAD_ALLOC);
    C(EGL_BAD_ATTRIBUTE);
    C(EGL_BAD_CONFIG);
    C(EGL_BAD_CONTEXT);
    C(EGL_BAD_CURRENT_SURFACE);
    C(EGL_BAD_DISPLAY);
    C(EGL_BAD_MATCH);
    C(EGL_BAD_NATIVE_PIXMAP);
    C(EGL_BAD_NATIVE_WINDOW);
    C(EGL_BAD_PARAMETER);
    C(EGL_BAD_SURFACE);
    C(EGL_CONTEXT_LOST);
#undef C
    default: return "unknown EGL error";
    }
}

int lr_gl__egl_display(lr_gl *gl, EGLenum platform, void *native, const char *platform_ext,
                       lr_err *e)
{
    /* Client extensions are queried on EGL_NO_DISPLAY (EGL_EXT_client_extensions). */
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client || !lr_gl__has_ext(client, "EGL_EXT_platform_base"))
        return lr_err_set(e, LR_EUNSUPPORTED, "EGL: missing client extension EGL_EXT_platform_base");
    if (!lr_gl__has_ext(client, platform_ext))
        return lr_err_set(e, LR_EUNSUPPORTED, "EGL: missing client extension %s", platform_ext);

    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    if (!get_display)
        return lr_err_set(e, LR_EUNSUPPORTED, "EGL: eglGetPlatformDisplayEXT not found");
    EGLDisplay dpy = get_display(platform, native, NULL);
    if (dpy == EGL_NO_DISPLAY)
        return lr_err_set(e, LR_ENODEV, "EGL: eglGetPlatformDisplayEXT (%s): %s", platform_ext,
                          lr_gl__egl_error_str(eglGetError()));
    EGLint major, minor;
    if (!eglInitialize(dpy, &major, &minor))
        return lr_err_set(e, LR_ENODEV, "EGL: eglInitialize (%s): %s", platform_ext,
                          lr_gl__egl_error_str(eglGetError()));
    gl->dpy = dpy;
    if (!eglBindAPI(EGL_OPENGL_ES_API))
        return lr_err_set(e, LR_EGL, "EGL: eglBindAPI(EGL_OPENGL_ES_API): %s",
                          lr_gl__egl_error_str(eglGetError()));
    return LR_OK;
}

int lr_gl__egl_context(lr_gl *gl, lr_err *e)
{
    /* Ask for exactly what the SBC has. A driver may hand back a later compatible version
     * (llvmpipe gives 3.2); lr_gl_create checks the version it got is at least 3.1. */
    static const EGLint attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 3,
        EGL_CONTEXT_MINOR_VERSION, 1,
        EGL_NONE,
    };
    gl->ctx = eglCreateContext(gl->dpy, gl->config, EGL_NO_CONTEXT, attribs);
    if (gl->ctx == EGL_NO_CONTEXT)
        return lr_err_set(e, LR_EUNSUPPORTED, "EGL: eglCreateContext (OpenGL ES 3.1): %s",
                          lr_gl__egl_error_str(eglGetError()));
    return LR_OK;
}

int lr_gl__headless_context(lr_gl *gl, lr_err *e)
{
    const char *exts = eglQueryString(gl->dpy, EGL_EXTENSIONS);
    /* Making a context current without a surface is the whole point of a headless back end. */
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
