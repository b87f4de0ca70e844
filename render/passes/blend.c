/* The blend pass (render/passes/blend.h). */
#include "render/passes/blend.h"

#include <GLES3/gl31.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl/shader.h"
#include "render/passes/defines.h"
#include "render/passes/passes.h"

struct lr_blend {
    lr_gl *gl;
    /* prog[op][n]: the pass for tone curve op (LR_BLEND_OPS: the linear sum) and n images of
     * non-zero weight (LR_BLEND_OP, LR_BLEND_N), built on first use: a candle's frame reads
     * one image and runs no per-pixel loop or branch. */
    lr_program *prog[LR_BLEND_OPS + 1][LR_BLEND_MAX_IMAGES + 1];
    lr_program *blit; /* lr_blend_present's copy to the default framebuffer, built on use */
    const char *shader_dir;
    const char *const *defines;
    lr_tex *ldr, *hdr;
    lr_fb *fb_ldr, *fb_hdr;
    lr_blend_input in; /* of the last run */
    bool have_input, hdr_valid;
    /* The output is SRGB8_ALPHA8 (the store encodes, LR_BLEND_SRGB_STORE 1), or RGBA8 that
     * the shader encodes where EXT_texture_sRGB_decode is missing. */
    bool srgb_store;
};

int lr_blend_create(const lr_blend_desc *d, lr_blend **out, lr_err *e)
{
    *out = NULL;
    if (!d || !d->gl || d->width < 1 || d->height < 1)
        return lr_err_set(e, LR_EINVAL, "blend pass: a GL context and a size are required");
    lr_blend *b = calloc(1, sizeof *b);
    if (!b)
        return lr_err_set(e, LR_ENOMEM, "blend pass: out of memory");
    b->gl = d->gl;
    b->shader_dir = d->shader_dir;
    b->defines = d->defines;
    lr_tex_desc hdr = {.format = LR_TEX_RGBA32F, .width = d->width, .height = d->height,
                       .label = "HDR output"};
    /* The hardware sRGB encode on the store replaces the shader's (three square roots per
     * channel on llvmpipe, where this pass is the whole of a dimmer frame). Its readers see
     * the stored bytes either way (render/gl/tex.h). */
    b->srgb_store = lr_gl_caps_get(d->gl)->srgb_decode;
    lr_tex_desc ldr = {.format = b->srgb_store ? LR_TEX_SRGB8_ALPHA8 : LR_TEX_RGBA8,
                       .width = d->width, .height = d->height, .linear = true,
                       .label = "tone-mapped output"};
    int rc;
    if ((rc = lr_tex_create(d->gl, &hdr, &b->hdr, e)) ||
        (rc = lr_tex_create(d->gl, &ldr, &b->ldr, e)) ||
        (rc = lr_fb_create(d->gl, &(lr_fb_desc){.color = {{b->hdr, 0}}, .label = "HDR output"},
                           &b->fb_hdr, e)) ||
        (rc = lr_fb_create(d->gl,
                           &(lr_fb_desc){.color = {{b->ldr, 0}}, .label = "tone-mapped output"},
                           &b->fb_ldr, e))) {
        lr_blend_destroy(b);
        return rc;
    }
    *out = b;
    return LR_OK;
}

void lr_blend_destroy(lr_blend *b)
{
    if (!b)
        return;
    lr_fb_destroy(b->fb_ldr);
    lr_fb_destroy(b->fb_hdr);
    lr_tex_destroy(b->ldr);
    lr_tex_destroy(b->hdr);
    for (int op = 0; op <= LR_BLEND_OPS; op++)
        for (int n = 0; n <= LR_BLEND_MAX_IMAGES; n++)
            lr_program_destroy(b->prog[op][n]);
    lr_program_destroy(b->blit);
    free(b);
}

static void uniform_i(lr_program *p, const char *name, int v)
{
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniform1i(loc, v);
}

/* The program for tone curve op (LR_BLEND_OPS: the linear sum, LR_BLEND_LINEAR in GLSL) and
 * n images of non-zero weight: the caller's defines (render/passes/defines.h: the curves'
 * names) plus LR_BLEND_OP and LR_BLEND_N. */
static int program(lr_blend *b, int op, int n, lr_program **out, lr_err *e)
{
    if (!b->prog[op][n]) {
        lr_shader_defines own = {0};
        const char *defs[2 * LR_DEFINES_MAX + 1];
        int k = 0;
        for (; b->defines && b->defines[k] && k < LR_DEFINES_MAX; k++)
            defs[k] = b->defines[k];
        if (b->defines && b->defines[k])
            return lr_err_set(e, LR_EINVAL, "blend pass: more than %d shader defines",
                              LR_DEFINES_MAX);
        lr_shader_defines_add(&own, "LR_BLEND_OP", op);
        lr_shader_defines_add(&own, "LR_BLEND_N", n);
        lr_shader_defines_add(&own, "LR_BLEND_SRGB_STORE", b->srgb_store ? 1 : 0);
        for (int i = 0; i < own.n; i++)
            defs[k++] = own.list[i];
        defs[k] = NULL;
        lr_program_desc pd = {.vertex = "blend.vert", .fragment = "blend.frag",
                              .dir = b->shader_dir, .defines = defs};
        int rc = lr_program_create(&pd, &b->prog[op][n], e);
        if (rc)
            return rc;
    }
    *out = b->prog[op][n];
    return LR_OK;
}

static int draw(lr_blend *b, lr_fb *fb, bool linear, lr_err *e)
{
    const lr_blend_input *in = &b->in;
    /* Exposure multiplies the weights here rather than every pixel (lr_tonemap_apply's rule:
     * exposure 0 means 1); the linear sum for readback takes the weights alone. */
    double x = linear ? 1.0 : in->exposure != 0.0f ? (double)in->exposure : 1.0;
    /* Only the images whose weight is not zero are read (a light switched off costs nothing). */
    float w[3 * LR_BLEND_MAX_IMAGES] = {0};
    int layer[LR_BLEND_MAX_IMAGES] = {0}, n = 0;
    for (int l = 0; l < in->n; l++) {
        if (in->w[l][0] == 0.0 && in->w[l][1] == 0.0 && in->w[l][2] == 0.0)
            continue;
        for (int c = 0; c < 3; c++)
            w[3 * n + c] = (float)(in->w[l][c] * x);
        layer[n++] = l;
    }
    int op = linear ? LR_BLEND_OPS
                    : in->tonemap_op >= 0 && in->tonemap_op < LR_BLEND_OPS ? in->tonemap_op : 0;
    lr_program *p = NULL;
    int rc = program(b, op, n, &p, e);
    if (rc)
        return rc;
    lr_fb_bind(fb);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(p));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D_ARRAY, lr_tex_id(in->images));
    uniform_i(p, "u_images", 0);
    GLint loc = lr_program_uniform(p, "u_w");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_w[0]");
    if (loc >= 0)
        glUniform3fv(loc, LR_BLEND_MAX_IMAGES, w);
    if ((loc = lr_program_uniform(p, "u_layer")) >= 0 ||
        (loc = lr_program_uniform(p, "u_layer[0]")) >= 0)
        glUniform1iv(loc, LR_BLEND_MAX_IMAGES, layer);
    if ((rc = lr_program_check(p, e)))
        return rc;
    lr_gl_draw_fullscreen(b->gl);
    return lr_gl_check(linear ? "blend pass (HDR sum)" : "blend pass", e);
}

int lr_blend_run(lr_blend *b, const lr_blend_input *in, lr_err *e)
{
    if (!in || !in->images || in->n < 1 || in->n > LR_BLEND_MAX_IMAGES)
        return lr_err_set(e, LR_EINVAL, "blend pass: %d images; takes 1..%d",
                          in && in->images ? in->n : 0, LR_BLEND_MAX_IMAGES);
    b->in = *in;
    b->have_input = true;
    b->hdr_valid = false;
    return draw(b, b->fb_ldr, false, e);
}

int lr_blend_hdr(lr_blend *b, lr_fb **out, lr_err *e)
{
    *out = NULL;
    if (!b->have_input)
        return lr_err_set(e, LR_EINVAL, "blend pass: no frame rendered yet");
    if (!b->hdr_valid) {
        int rc = draw(b, b->fb_hdr, true, e);
        if (rc)
            return rc;
        b->hdr_valid = true;
    }
    *out = b->fb_hdr;
    return LR_OK;
}

lr_tex *lr_blend_ldr(const lr_blend *b) { return b->ldr; }
lr_fb *lr_blend_ldr_fb(const lr_blend *b) { return b->fb_ldr; }

int lr_blend_read_hdr(lr_blend *b, float *rgb, lr_err *e)
{
    lr_fb *hdr;
    int rc = lr_blend_hdr(b, &hdr, e);
    if (rc)
        return rc;
    int w, h;
    lr_fb_size(hdr, &w, &h);
    size_t n = (size_t)w * (size_t)h;
    float *rgba = malloc(n * 4 * sizeof *rgba);
    if (!rgba)
        return lr_err_set(e, LR_ENOMEM, "blend: HDR readback: out of memory");
    rc = lr_fb_read(hdr, 0, 0, 0, w, h, rgba, e);
    if (!rc)
        for (size_t i = 0; i < n; i++)
            memcpy(rgb + 3 * i, rgba + 4 * i, 3 * sizeof *rgb);
    free(rgba);
    return rc;
}

int lr_blend_read_rgba8(lr_blend *b, unsigned char *out, lr_err *e)
{
    int w, h;
    lr_fb_size(b->fb_ldr, &w, &h);
    size_t n = (size_t)w * (size_t)h;
    float *rgba = malloc(n * 4 * sizeof *rgba);
    if (!rgba)
        return lr_err_set(e, LR_ENOMEM, "blend: readback: out of memory");
    int rc = lr_fb_read(b->fb_ldr, 0, 0, 0, w, h, rgba, e);
    if (!rc)
        for (int y = 0; y < h; y++) {
            const float *src = rgba + (size_t)(h - 1 - y) * w * 4;
            unsigned char *dst = out + (size_t)y * w * 4;
            for (int i = 0; i < w * 4; i++) {
                float v = src[i] * 255.0f + 0.5f;
                dst[i] = (unsigned char)(v < 0.0f ? 0.0f : v > 255.0f ? 255.0f : v);
            }
        }
    free(rgba);
    return rc;
}

int lr_blend_present(lr_blend *b, lr_err *e)
{
    int w, h;
    lr_gl_size(b->gl, &w, &h);
    if (w > 0 && h > 0) {
        if (!b->blit) {
            lr_program_desc pd = {.vertex = "fullscreen.vert", .fragment = "blit.frag",
                                  .dir = b->shader_dir, .defines = b->defines};
            int rc = lr_program_create(&pd, &b->blit, e);
            if (rc)
                return rc;
        }
        lr_gl_bind_default(b->gl);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        glUseProgram(lr_program_id(b->blit));
        lr_passes_bind_tex(b->blit, "u_src", 0, b->ldr);
        int rc = lr_program_check(b->blit, e);
        if (rc)
            return rc;
        lr_gl_draw_fullscreen(b->gl);
    }
    return lr_gl_present(b->gl, e);
}
