/* lamprig — the GL context: OpenGL ES 3.1 through EGL, over one of two back ends.
 *
 *   LR_GL_SURFACELESS  headless (EGL_PLATFORM_SURFACELESS_MESA): no window, no pbuffer; every
 *                      pass renders into its own framebuffer objects. Tests, `lamprig render`.
 *   LR_GL_DEVICE       headless on an EGL device (EGL_EXT_platform_device): the first GPU, or
 *                      LAMPRIG_EGL_DEVICE=N. LR_GL_SURFACELESS falls back to it when the EGL
 *                      vendor lacks the Mesa platform (NVIDIA's EGL on a GPU server).
 *   LR_GL_KMS          the projector: DRM/KMS + GBM + an EGL window surface, scanned out by
 *                      page flips on vblank (kmscube's legacy path).
 *
 * The passes only ever see GLES 3.1 (no geometry shaders, no desktop GL): the context is asked
 * for 3.1 and rejected when the driver reports less. lr_gl_create makes the context current on
 * the calling thread; all GL work must happen on that thread (a worker thread gets its own
 * context, lr_gl_create_shared).
 *
 * Frame loop with the projector (the DRM fd joins the firmware's poll set, as in kmscube):
 *
 *     draw into framebuffer 0 (lr_gl_bind_default)
 *     lr_gl_present(gl, &e);                 // swap + queue a flip for the next vblank
 *     poll({lr_gl_event_fd(gl), POLLIN} + the controls' fds ...);
 *     if (fd readable) lr_gl_dispatch(gl, &e); // reads the flip event, frees the old buffer
 *
 * lr_gl_present waits for an outstanding flip itself, so a caller that does not poll still
 * gets one frame per vblank. On the surfaceless back end there is nothing to flip:
 * lr_gl_event_fd returns -1 and lr_gl_present only flushes.
 *
 * One lr_gl per EGL display at a time: Mesa hands out one EGLDisplay per platform and native
 * display, and lr_gl_destroy terminates it (EGL_KHR_display_reference is not available on
 * Debian 12's Mesa 22.3, so displays cannot be reference-counted).
 */
#ifndef LR_GL_H
#define LR_GL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"

typedef struct lr_gl lr_gl;

typedef enum lr_gl_backend {
    LR_GL_SURFACELESS = 0, /* default */
    LR_GL_KMS,
    LR_GL_DEVICE,
} lr_gl_backend;

typedef struct lr_gl_desc {
    lr_gl_backend backend;
    /* KMS only; zero/NULL picks as described. */
    const char *drm_device; /* e.g. "/dev/dri/card1"; NULL: the first primary node from
                             * drmGetDevices2 that has KMS resources and a connected output */
    const char *connector;  /* e.g. "HDMI-A-1"; NULL: the first connected connector */
    int width, height;      /* mode size; 0: the connector's preferred mode (else its largest) */
    int refresh_hz;         /* with width/height: prefer this vertical refresh; 0: any */
} lr_gl_desc;

/* What the passes may rely on; filled once at creation. The booleans that gate render targets
 * mean "usable", i.e. the extension is advertised *or* the feature is core in the version. */
typedef struct lr_gl_caps {
    int major, minor;           /* GL_MAJOR_VERSION / GL_MINOR_VERSION, e.g. 3, 2 */
    char version[128];          /* GL_VERSION, e.g. "OpenGL ES 3.2 Mesa 22.3.6" */
    char renderer[128];         /* GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)" */
    char vendor[64];            /* GL_VENDOR */
    /* R16F..RGBA32F colour-renderable: EXT_color_buffer_float, core in GLES 3.2. */
    bool color_buffer_float;
    /* R16F/RG16F/RGBA16F colour-renderable: EXT_color_buffer_half_float, or the above. */
    bool color_buffer_half_float;
    /* LINEAR/mipmap filtering of 32-bit float textures: OES_texture_float_linear.
     * (16-bit float textures filter linearly in core GLES 3.0.) */
    bool texture_float_linear;
    /* Blending into 32-bit float targets (progressive accumulation by blending): EXT_float_blend. */
    bool float_blend;
    /* GPU timestamps: EXT_disjoint_timer_query. */
    bool timer_query;
    /* Sampling an sRGB texture without decoding it (EXT_texture_sRGB_decode): the output
     * target is SRGB8_ALPHA8 (the store encodes) and its readers see the stored bytes. */
    bool srgb_decode;
    int max_texture_size;
    int max_cube_map_size;
    int max_array_layers;
    int max_color_attachments;
    int max_draw_buffers;
} lr_gl_caps;

/* Requirements a pass can ask for by name (lr_gl_caps_require). */
enum lr_gl_need {
    LR_GL_NEED_FLOAT_RT = 1u << 0,      /* RGBA32F / R32F render targets */
    LR_GL_NEED_HALF_FLOAT_RT = 1u << 1, /* RGBA16F render targets */
    LR_GL_NEED_FLOAT_LINEAR = 1u << 2,  /* linear filtering of RGBA32F / R32F textures */
    LR_GL_NEED_FLOAT_BLEND = 1u << 3,   /* additive blending into RGBA32F */
    LR_GL_NEED_TIMER = 1u << 4,         /* GPU timer queries */
    LR_GL_NEED_SRGB_DECODE = 1u << 5,   /* sampling SRGB8_ALPHA8 as stored (SKIP_DECODE) */
};

/* Creates the context and makes it current. Errors: LR_ENODEV (no DRM device / display /
 * connected output; the message says which, e.g. "no /dev/dri"), LR_EUNSUPPORTED (EGL platform
 * extension missing, GLES < 3.1), LR_EGL (an EGL call failed; the message names it and the
 * EGL error). */
int lr_gl_create(const lr_gl_desc *desc, lr_gl **out, lr_err *e);
/* A second context that shares textures and buffers (not framebuffers or vertex arrays)
 * with `parent`, on the parent's display and without a surface, made current on the calling
 * thread: a worker thread renders into textures the parent's thread then reads (render/async/).
 * The parent must outlive it; lr_gl_size reports 0 x 0 and lr_gl_present only flushes. The
 * two threads order their work on shared objects with fences (glFenceSync). */
int lr_gl_create_shared(lr_gl *parent, lr_gl **out, lr_err *e);
/* Releases the context, surfaces and DRM state, in that order; NULL is a no-op. */
void lr_gl_destroy(lr_gl *gl);

const lr_gl_caps *lr_gl_caps_get(const lr_gl *gl);
/* The storage (bytes) of the textures and renderbuffers made through render/gl/tex.h on this
 * context, now and at its most: what the renderer's settings cost in GPU memory (a driver
 * adds its own alignment and bookkeeping; shader code and vertex buffers are not counted). */
void lr_gl_memory(const lr_gl *gl, size_t *bytes, size_t *peak);
lr_gl_backend lr_gl_backend_of(const lr_gl *gl);
/* "surfaceless" or "kms". */
const char *lr_gl_backend_name(const lr_gl *gl);

/* Size of the default framebuffer (the projector mode); 0 x 0 on surfaceless. */
void lr_gl_size(const lr_gl *gl, int *width, int *height);

/* Makes the context current on the calling thread (after handing it to another thread). */
int lr_gl_make_current(lr_gl *gl, lr_err *e);

/* Binds framebuffer 0 (the window surface) with a full-size viewport. */
void lr_gl_bind_default(lr_gl *gl);

/* Shows what was drawn into framebuffer 0: KMS swaps, waits for any flip still outstanding,
 * and queues the new buffer for the next vblank; surfaceless flushes. */
int lr_gl_present(lr_gl *gl, lr_err *e);

/* The fd the firmware polls for page-flip completion (POLLIN); -1 when the back end has none. */
int lr_gl_event_fd(const lr_gl *gl);
/* Call when lr_gl_event_fd is readable: consumes the flip event(s). */
int lr_gl_dispatch(lr_gl *gl, lr_err *e);
/* True while a queued flip has not completed. */
bool lr_gl_flip_pending(const lr_gl *gl);

/* Draws one triangle that covers the viewport with the bound program, whose vertex shader
 * should be render/shaders/fullscreen.vert (positions from gl_VertexID, no vertex buffers;
 * one triangle rather than a quad so no fragment is shaded twice along a diagonal). */
void lr_gl_draw_fullscreen(lr_gl *gl);

/* Drains glGetError; when any error was pending, reports the first as LR_EGL with `what` in
 * the message (e.g. "readback: GL_INVALID_OPERATION"). */
int lr_gl_check(const char *what, lr_err *e);
/* "GL_INVALID_ENUM", ... */
const char *lr_gl_error_str(unsigned gl_error);

/* ---- capabilities without a context (caps.c): parse strings a driver reported ---------- */

/* Fills caps from GL_VERSION and a list of extension names; the numeric limits are left
 * untouched. Used by lr_gl_create, and by tests with made-up drivers. */
int lr_gl_caps_parse(const char *version, const char *const *exts, int n_exts, lr_gl_caps *caps,
                     lr_err *e);
/* LR_OK when every bit of `need` (enum lr_gl_need) is met; else LR_EUNSUPPORTED with a message
 * naming each missing extension, e.g. "missing EXT_color_buffer_float (32-bit float render
 * targets) on <renderer>". */
int lr_gl_caps_require(const lr_gl_caps *caps, unsigned need, lr_err *e);

#endif
