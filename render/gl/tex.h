/* lamprig — textures and framebuffers for the passes: float formats, cube maps and arrays,
 * float readback.
 *
 * Rows are in GL order everywhere here: row 0 is the bottom of the image. Cube faces are
 * numbered as GL_TEXTURE_CUBE_MAP_POSITIVE_X + face: 0..5 = +X, -X, +Y, -Y, +Z, -Z.
 * All calls need the lr_gl's context current.
 */
#ifndef LR_TEX_H
#define LR_TEX_H

#include <GLES3/gl31.h>
#include <stdbool.h>

#include "render/base/err.h"
#include "render/gl/gl.h"

typedef enum lr_tex_type {
    LR_TEX_2D = 0, /* default */
    LR_TEX_CUBE,
    LR_TEX_2D_ARRAY,
} lr_tex_type;

typedef enum lr_tex_format {
    LR_TEX_RGBA32F = 0, /* default: radiometry */
    LR_TEX_RGBA16F,
    LR_TEX_R32F,
    LR_TEX_RGBA8,       /* tone-mapped output */
    LR_TEX_DEPTH32F,
    LR_TEX_DEPTH24,
    LR_TEX_SRGB8_ALPHA8, /* tone-mapped output, sRGB-encoded by the store (GLES 3.0 core);
                          * sampled and read back as the stored bytes (SKIP_DECODE), like
                          * RGBA8 holding the encoded values */
} lr_tex_format;

typedef struct lr_tex lr_tex;

typedef struct lr_tex_desc {
    lr_tex_type type;
    lr_tex_format format;
    int width, height;  /* cube: square; height 0 means = width */
    int layers;         /* 2D array only; 0 means 1 */
    bool linear;        /* LINEAR filtering; default NEAREST (maps are read texel by texel).
                         * 32-bit float needs OES_texture_float_linear; depth cannot. */
    bool repeat;        /* REPEAT wrapping; default CLAMP_TO_EDGE */
    const char *label;  /* names the texture in messages; default "texture" */
} lr_tex_desc;

/* Allocates immutable storage (one mip level). Errors: LR_EINVAL (size 0, beyond the driver's
 * limit, non-square cube), LR_EUNSUPPORTED (linear filtering of a format that cannot). */
int lr_tex_create(lr_gl *gl, const lr_tex_desc *desc, lr_tex **out, lr_err *e);
void lr_tex_destroy(lr_tex *t);

GLuint lr_tex_id(const lr_tex *t);
/* GL_TEXTURE_2D, GL_TEXTURE_CUBE_MAP or GL_TEXTURE_2D_ARRAY. */
GLenum lr_tex_target(const lr_tex *t);
lr_tex_format lr_tex_format_of(const lr_tex *t);
/* layers: 6 for a cube, the array size, 1 for 2D. Any pointer may be NULL. */
void lr_tex_size(const lr_tex *t, int *width, int *height, int *layers);
/* Floats per texel in upload/readback data: 1 for R32F, 4 otherwise. */
int lr_tex_channels(const lr_tex *t);

/* Uploads width x height texels of float data (lr_tex_channels per texel, rows bottom-up) into
 * `layer` (cube face or array layer; 0 for 2D). Float formats only. */
int lr_tex_upload(lr_tex *t, int layer, const float *data, lr_err *e);

/* ---- framebuffers ---------------------------------------------------------------------- */

#define LR_FB_MAX_COLOR 4

typedef struct lr_fb_attachment {
    lr_tex *tex;
    int layer; /* cube face or array layer; 0 for 2D */
} lr_fb_attachment;

typedef struct lr_fb lr_fb;

typedef struct lr_fb_desc {
    /* Colour attachments 0, 1, ... up to the first NULL tex; fragment output i writes color[i]. */
    lr_fb_attachment color[LR_FB_MAX_COLOR];
    lr_fb_attachment depth;   /* a depth texture, or tex NULL */
    bool depth_buffer;        /* with depth.tex NULL: a 24-bit depth renderbuffer of our own */
    const char *label;        /* names the framebuffer in messages; default "framebuffer" */
} lr_fb_desc;

/* Every attachment must have the same size. Float colour attachments are checked against the
 * capabilities first, so a missing EXT_color_buffer_float is reported by name rather than as
 * GL_FRAMEBUFFER_UNSUPPORTED. The framebuffer does not own the textures. */
int lr_fb_create(lr_gl *gl, const lr_fb_desc *desc, lr_fb **out, lr_err *e);
void lr_fb_destroy(lr_fb *fb);

GLuint lr_fb_id(const lr_fb *fb);
void lr_fb_size(const lr_fb *fb, int *width, int *height);
/* Binds for drawing and reading and sets the viewport to the whole attachment size. */
void lr_fb_bind(const lr_fb *fb);

/* Reads a w x h rectangle at (x, y) of colour attachment `index` as RGBA floats (4 per texel,
 * rows bottom-up; RGBA8 attachments come back divided by 255, R32F as (r, 0, 0, 1)). Leaves
 * the framebuffer bound. */
int lr_fb_read(lr_fb *fb, int index, int x, int y, int w, int h, float *rgba, lr_err *e);

#endif
