/* lamprig tests — headless GL context, with the driver pinned for leak reports. */
#include "tests/support/gl.h"

#include <EGL/egl.h>
#include <dlfcn.h>
#include <link.h>
#include <stdio.h>

static int pin(struct dl_phdr_info *info, size_t size, void *data)
{
    /* RTLD_NOLOAD only looks the library up; with RTLD_NODELETE it becomes permanent.
     * The handle is deliberately never closed. */
    if (info->dlpi_name && info->dlpi_name[0])
        dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    return 0;
}

void lr_test_pin_libraries(void)
{
    dl_iterate_phdr(pin, NULL);
}

/* Every test binary opens EGL through this eglInitialize (the executable's definition wins
 * over libEGL's, for our library's calls too): the real one, then the pin. Mesa loads its
 * driver (swrast_dri.so, libLLVM) inside eglInitialize and unloads it at eglTerminate, so a
 * one-time allocation the driver never frees was reported from a stale address, "<unknown
 * module>" or whatever library later got mapped there (issue 10: test_gl_context, which
 * creates and destroys contexts without lr_test_gl_create, failed at random libraries), and
 * the suppressions could not match it. Pinned here, every binary that opens EGL keeps the
 * driver's name on such stacks, whichever function created the context. */
EGLBoolean eglInitialize(EGLDisplay dpy, EGLint *major, EGLint *minor)
{
    typedef EGLBoolean (*init_fn)(EGLDisplay, EGLint *, EGLint *);
    init_fn real = (init_fn)dlsym(RTLD_NEXT, "eglInitialize"); /* libEGL's */
    if (!real)
        return EGL_FALSE;
    EGLBoolean ok = real(dpy, major, minor);
    if (ok)
        lr_test_pin_libraries();
    return ok;
}

int lr_test_gl_create(lr_gl **out)
{
    lr_err e = {0};
    int rc = lr_gl_create(NULL, out, &e);
    if (rc) {
        fprintf(stderr, "lr_gl_create: %s\n", e.msg);
        return rc;
    }
    lr_test_pin_libraries();
    return LR_OK;
}
