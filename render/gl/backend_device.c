/* lamprig — headless back end on an EGL device (EGL_EXT_platform_device): no window and no
 * pbuffer, like surfaceless, for EGL vendors without EGL_MESA_platform_surfaceless. NVIDIA's
 * proprietary EGL is the case that matters: a GPU server or a Jetson-class board renders
 * headless only through its device platform.
 *
 * Which device: LAMPRIG_EGL_DEVICE=N picks the Nth of eglQueryDevicesEXT's list; otherwise the
 * first device that is not a software rasteriser (EGL_MESA_device_software), else the first. */
#include "render/gl/gl_priv.h"

#include <stdlib.h>
#include <string.h>

#define MAX_DEVICES 16

static int device_present(lr_gl *gl, lr_err *e)
{
    (void)gl;
    (void)e;
    /* Nothing to scan out; flushing keeps the frame's work from piling up in the driver. */
    glFlush();
    return LR_OK;
}

static const lr_gl_ops device_ops = {
    .name = "device",
    .present = device_present,
};

static int pick_device(EGLDeviceEXT *devices, int n, int *pick, lr_err *e)
{
    const char *env = getenv("LAMPRIG_EGL_DEVICE");
    if (env && *env) {
        char *end = NULL;
        long i = strtol(env, &end, 10);
        if (*end != '\0' || i < 0 || i >= n)
            return lr_err_set(e, LR_EINVAL,
                              "EGL: LAMPRIG_EGL_DEVICE='%s': expected 0..%d (%d device%s)", env,
                              n - 1, n, n == 1 ? "" : "s");
        *pick = (int)i;
        return LR_OK;
    }
    PFNEGLQUERYDEVICESTRINGEXTPROC device_string =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    for (int i = 0; device_string && i < n; i++) {
        const char *exts = device_string(devices[i], EGL_EXTENSIONS);
        if (!lr_gl__has_ext(exts, "EGL_MESA_device_software")) {
            *pick = i;
            return LR_OK;
        }
    }
    *pick = 0;
    return LR_OK;
}

int lr_gl__device_init(lr_gl *gl, const lr_gl_desc *desc, lr_err *e)
{
    (void)desc;
    gl->ops = &device_ops;
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    /* EGL_EXT_device_base is enumeration + query in one name (NVIDIA lists only it). */
    if (!client || (!lr_gl__has_ext(client, "EGL_EXT_device_enumeration") &&
                    !lr_gl__has_ext(client, "EGL_EXT_device_base")))
        return lr_err_set(e, LR_EUNSUPPORTED,
                          "EGL: missing client extension EGL_EXT_device_enumeration");
    PFNEGLQUERYDEVICESEXTPROC query_devices =
        (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    if (!query_devices)
        return lr_err_set(e, LR_EUNSUPPORTED, "EGL: eglQueryDevicesEXT not found");
    EGLDeviceEXT devices[MAX_DEVICES];
    EGLint n = 0;
    if (!query_devices(MAX_DEVICES, devices, &n) || n < 1)
        return lr_err_set(e, LR_ENODEV, "EGL: no EGL device (eglQueryDevicesEXT: %s)",
                          lr_gl__egl_error_str(eglGetError()));
    int pick = 0;
    int rc = pick_device(devices, n, &pick, e);
    if (rc)
        return rc;
    rc = lr_gl__egl_display(gl, EGL_PLATFORM_DEVICE_EXT, devices[pick],
                                "EGL_EXT_platform_device", e);
    if (rc)
        return rc;
    return lr_gl__headless_context(gl, e);
}
