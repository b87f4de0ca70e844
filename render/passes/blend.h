/* lamprig — the blend pass (issue 11): the output is the weighted sum of the per-light
 * unit-intensity linear images, sum_l w_l image_l with w_l = intensity x colour x flicker per
 * band, then exposure (folded into the weights), tone curve and sRGB: the output target is
 * SRGB8_ALPHA8, whose store encodes (render/gl/tex.h; where EXT_texture_sRGB_decode is missing,
 * RGBA8 and lr_srgb_encode_fast in the shader, within a quarter of an 8-bit step of the
 * exact encode). Images of weight 0 are not read. Light transport is linear in each light's
 * intensity (render/passes/PIPELINE.md "Linearity"), so a dimmer, colour, flicker or exposure
 * change is this one fullscreen pass and nothing else.
 *
 * Self-contained in the shape issue 15 asks of passes: it owns its program and its targets
 * (the tone-mapped output and the linear HDR sum) and takes its inputs explicitly
 * (lr_blend_input); nothing here reads the renderer. The linear sum is only needed for
 * readback (lr_renderer_read_hdr, tests), so the displayed frame writes the tone-mapped target
 * alone and the HDR sum is drawn on demand from the same images and weights.
 */
#ifndef LR_BLEND_H
#define LR_BLEND_H

#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/gl/tex.h"

#define LR_BLEND_MAX_IMAGES 4
#define LR_BLEND_OPS 3 /* lr_tonemap_op values: clamp, Reinhard, ACES */

typedef struct lr_blend lr_blend;

typedef struct lr_blend_desc {
    lr_gl *gl;
    int width, height;
    const char *shader_dir;      /* where blend.vert and blend.frag are */
    const char *const *defines;  /* the renderer's shader defines (LR_MAX_LIGHTS, ...) */
} lr_blend_desc;

typedef struct lr_blend_input {
    const lr_tex *images;  /* 2D array, layer l = light l's unit-intensity linear radiance;
                            * alpha of layer 0 is copied to the HDR sum (coverage) */
    int n;                 /* layers to sum, 1..LR_BLEND_MAX_IMAGES */
    double w[LR_BLEND_MAX_IMAGES][3]; /* weight per image and band */
    float exposure;
    int tonemap_op;        /* lr_tonemap_op */
} lr_blend_input;

int lr_blend_create(const lr_blend_desc *d, lr_blend **out, lr_err *e);
void lr_blend_destroy(lr_blend *b);

/* Draws the tone-mapped output from in (copied: a later lr_blend_hdr uses the same). */
int lr_blend_run(lr_blend *b, const lr_blend_input *in, lr_err *e);
/* The linear sum of the last lr_blend_run's input, RGBA32F, drawn if not yet drawn for it. */
int lr_blend_hdr(lr_blend *b, lr_fb **out, lr_err *e);

/* The last output read back: linear RGB (w*h*3 floats, rows bottom to top, PFM order) and
 * tone-mapped sRGB (w*h*4 bytes, rows top to bottom, PNG order). */
int lr_blend_read_hdr(lr_blend *b, float *rgb, lr_err *e);
int lr_blend_read_rgba8(lr_blend *b, unsigned char *rgba, lr_err *e);

/* Draws the tone-mapped output to the context's default framebuffer (the projector; nothing
 * to draw on surfaceless) and presents it (lr_gl_present). */
int lr_blend_present(lr_blend *b, lr_err *e);

lr_tex *lr_blend_ldr(const lr_blend *b);
lr_fb *lr_blend_ldr_fb(const lr_blend *b);

#endif
