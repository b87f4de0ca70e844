/* lamprig — GL context internals shared by gl.c, egl.c and the back ends (not public). */
#ifndef LR_GL_PRIV_H
#define LR_GL_PRIV_H

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl31.h>

#include "render/gl/gl.h"

/* What differs between surfaceless and KMS, kmscube-style: a small table of functions. The
 * common code owns the EGL context and surface; a back end owns its native objects (DRM fd,
 * GBM device and surface, scanout buffers) and tears them down in `fini`, which runs after
 * the EGL objects that reference them are gone. */
typedef struct lr_gl_ops {
    const char *name;
    int (*present)(lr_gl *gl, lr_err *e);
    int (*dispatch)(lr_gl *gl, lr_err *e);
    int (*event_fd)(const lr_gl *gl);
    bool (*flip_pending)(const lr_gl *gl);
    void (*fini)(lr_gl *gl);
} lr_gl_ops;

struct lr_gl {
    lr_gl_backend backend;
    const lr_gl_ops *ops;
    void *be; /* back end state */
    EGLDisplay dpy;
    EGLConfig config;   /* EGL_NO_CONFIG_KHR on surfaceless when the driver allows it */
    EGLContext ctx;
    EGLSurface surface; /* EGL_NO_SURFACE on surfaceless */
    int width, height;  /* default framebuffer; 0 on surfaceless */
    GLuint empty_vao;   /* for lr_gl_draw_fullscreen */
    lr_gl_caps caps;
    /* lr_gl_create_shared: a second context on the parent's display; destroying it leaves
     * the display and the back end to the parent. */
    bool shared;
    /* Storage of the textures and renderbuffers made through tex.h on this context
     * (lr_gl_memory), now and at its most. */
    size_t mem_bytes, mem_peak;
};

/* tex.c: a texture's or renderbuffer's storage made (delta > 0) or freed. */
void lr_gl__mem_add(lr_gl *gl, long long delta);

/* Back-end constructors: fill gl->ops, gl->be, gl->dpy/config/surface/size and create the
 * context with lr_gl__egl_context. On failure they leave what they made for lr_gl_destroy. */
int lr_gl__surfaceless_init(lr_gl *gl, const lr_gl_desc *desc, lr_err *e);
int lr_gl__kms_init(lr_gl *gl, const lr_gl_desc *desc, lr_err *e);
int lr_gl__device_init(lr_gl *gl, const lr_gl_desc *desc, lr_err *e);

/* egl.c */
/* Checks the client extensions for EGL_EXT_platform_base and `platform_ext`, gets the platform
 * display for `native`, initialises it and binds GLES; sets gl->dpy. */
int lr_gl__egl_display(lr_gl *gl, EGLenum platform, void *native, const char *platform_ext,
                       lr_err *e);
/* Headless back ends: checks EGL_KHR_surfaceless_context, picks a GLES 3 config when the
 * driver lacks EGL_KHR_no_config_context, and creates the context. */
int lr_gl__headless_context(lr_gl *gl, lr_err *e);
/* Creates a GLES 3.1 context on gl->dpy with gl->config into gl->ctx. */
int lr_gl__egl_context(lr_gl *gl, lr_err *e);
/* True when the space-separated extension list `list` holds exactly `name`. */
bool lr_gl__has_ext(const char *list, const char *name);
const char *lr_gl__egl_error_str(EGLint err);

#endif
