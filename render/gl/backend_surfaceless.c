/* lamprig — headless back end: EGL_PLATFORM_SURFACELESS_MESA, no window and no pbuffer.
 *
 * Nothing is ever shown, so every pass renders into framebuffer objects; framebuffer 0 does
 * not exist (lr_gl_size reports 0 x 0). */
#include "render/gl/gl_priv.h"

#include <stdlib.h>
#include <string.h>

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
    /* LAMPRIG_EGL_PLATFORM=device asks for the GPU where glvnd would hand the surfaceless
     * platform to Mesa's software rasteriser (a machine with both vendors installed). */
    const char *force = getenv("LAMPRIG_EGL_PLATFORM");
    if (force && *force && strcmp(force, "device") != 0 && strcmp(force, "surfaceless") != 0)
        return lr_err_set(e, LR_EINVAL,
                          "EGL: LAMPRIG_EGL_PLATFORM='%s': expected surfaceless or device", force);
    if (force && strcmp(force, "device") == 0)
        return lr_gl__device_init(gl, desc, e);
    /* An EGL without the Mesa platform (NVIDIA's, alone) still renders headless through its
     * devices: fall back to them rather than fail. */
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!(force && *force) && client &&
        !lr_gl__has_ext(client, "EGL_MESA_platform_surfaceless") &&
        lr_gl__has_ext(client, "EGL_EXT_platform_device"))
        return lr_gl__device_init(gl, desc, e);
    gl->ops = &surfaceless_ops;
    int rc = lr_gl__egl_display(gl, EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY,
                                "EGL_MESA_platform_surfaceless", e);
    if (rc)
        return rc;
    return lr_gl__headless_context(gl, e);
}
