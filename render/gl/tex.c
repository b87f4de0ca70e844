/* lamprig — textures, framebuffers and float readback. */
#include "render/gl/tex.h"

#include "render/gl/gl_priv.h"

#include <stdio.h>
#include <stdlib.h>

struct lr_tex {
    lr_gl *gl;    /* whose memory count holds `bytes` (lr_gl_memory) */
    size_t bytes; /* storage: width x height x layers x the format's texel size */
    GLuint id;
    GLenum target;
    lr_tex_format format;
    int width, height, layers;
    char label[48];
};

struct lr_fb {
    lr_gl *gl;
    size_t rb_bytes; /* the depth renderbuffer of our own (4 bytes a pixel) */
    GLuint id, depth_rb;
    int width, height;
    int ncolor;
    lr_tex_format color_format[LR_FB_MAX_COLOR];
    char label[48];
};

/* EXT_texture_sRGB_decode (GLES2/gl2ext.h names them; the values are the registry's). */
#define LR_GL_TEXTURE_SRGB_DECODE_EXT 0x8A48
#define LR_GL_SKIP_DECODE_EXT 0x8A4A

static const struct format_info {
    GLenum internal, format, type; /* internal format; upload format/type */
    int channels;
    int texel_bytes; /* storage per texel (what lr_gl_memory counts) */
    bool is_float, is_depth, is_32f;
    unsigned need;                 /* enum lr_gl_need to render into it */
    const char *name;
} formats[] = {
    [LR_TEX_RGBA32F] = {GL_RGBA32F, GL_RGBA, GL_FLOAT, 4, 16, true, false, true, LR_GL_NEED_FLOAT_RT,
                        "RGBA32F"},
    [LR_TEX_RGBA16F] = {GL_RGBA16F, GL_RGBA, GL_FLOAT, 4, 8, true, false, false,
                        LR_GL_NEED_HALF_FLOAT_RT, "RGBA16F"},
    [LR_TEX_R32F] = {GL_R32F, GL_RED, GL_FLOAT, 1, 4, true, false, true, LR_GL_NEED_FLOAT_RT, "R32F"},
    [LR_TEX_RGBA8] = {GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, 4, 4, false, false, false, 0, "RGBA8"},
    [LR_TEX_DEPTH32F] = {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, 1, 4, false, true, true, 0,
                         "DEPTH32F"},
    [LR_TEX_DEPTH24] = {GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, 1, 4, false, true,
                        false, 0, "DEPTH24"},
    [LR_TEX_SRGB8_ALPHA8] = {GL_SRGB8_ALPHA8, GL_RGBA, GL_UNSIGNED_BYTE, 4, 4, false, false, false,
                             LR_GL_NEED_SRGB_DECODE, "SRGB8_ALPHA8"},
};

int lr_tex_create(lr_gl *gl, const lr_tex_desc *d, lr_tex **out, lr_err *e)
{
    *out = NULL;
    const char *label = d->label ? d->label : "texture";
    const lr_gl_caps *caps = lr_gl_caps_get(gl);
    if ((unsigned)d->format >= sizeof formats / sizeof formats[0] || (unsigned)d->type > LR_TEX_2D_ARRAY)
        return lr_err_set(e, LR_EINVAL, "%s: unknown format %d or type %d", label, (int)d->format,
                          (int)d->type);
    const struct format_info *f = &formats[d->format];
    int w = d->width, h = d->height ? d->height : (d->type == LR_TEX_CUBE ? d->width : 0);
    int layers = d->type == LR_TEX_CUBE ? 6 : d->type == LR_TEX_2D_ARRAY && d->layers ? d->layers : 1;
    int max = d->type == LR_TEX_CUBE ? caps->max_cube_map_size : caps->max_texture_size;
    if (w <= 0 || h <= 0 || w > max || h > max || d->layers < 0 ||
        (d->type == LR_TEX_2D_ARRAY && layers > caps->max_array_layers))
        return lr_err_set(e, LR_EINVAL, "%s: size %dx%dx%d outside 1..%d (layers 1..%d)", label, w,
                          h, layers, max, caps->max_array_layers);
    if (d->type == LR_TEX_CUBE && w != h)
        return lr_err_set(e, LR_EINVAL, "%s: cube map faces must be square, not %dx%d", label, w, h);
    if (d->linear && f->is_depth)
        return lr_err_set(e, LR_EUNSUPPORTED, "%s: %s textures cannot be filtered linearly in GLES",
                          label, f->name);
    if (d->linear && f->is_32f) {
        int rc = lr_gl_caps_require(caps, LR_GL_NEED_FLOAT_LINEAR, e);
        if (rc)
            return lr_err_prefix(e, "%s (%s, linear)", label, f->name);
    }
    /* An sRGB texture is sampled as stored (below): without the extension it would decode. */
    if (d->format == LR_TEX_SRGB8_ALPHA8 && lr_gl_caps_require(caps, f->need, e))
        return lr_err_prefix(e, "%s (%s)", label, f->name);

    lr_tex *t = calloc(1, sizeof *t);
    if (!t)
        return lr_err_set(e, LR_ENOMEM, "%s", label);
    static const GLenum targets[] = {GL_TEXTURE_2D, GL_TEXTURE_CUBE_MAP, GL_TEXTURE_2D_ARRAY};
    t->target = targets[d->type];
    t->format = d->format;
    t->width = w;
    t->height = h;
    t->layers = layers;
    snprintf(t->label, sizeof t->label, "%s", label);
    glGenTextures(1, &t->id);
    glBindTexture(t->target, t->id);
    if (d->type == LR_TEX_2D_ARRAY)
        glTexStorage3D(t->target, 1, f->internal, w, h, layers);
    else
        glTexStorage2D(t->target, 1, f->internal, w, h);
    GLint filter = d->linear ? GL_LINEAR : GL_NEAREST;
    GLint wrap = d->repeat ? GL_REPEAT : GL_CLAMP_TO_EDGE;
    glTexParameteri(t->target, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(t->target, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(t->target, GL_TEXTURE_WRAP_S, wrap);
    glTexParameteri(t->target, GL_TEXTURE_WRAP_T, wrap);
    glTexParameteri(t->target, GL_TEXTURE_WRAP_R, wrap);
    /* Readers of the sRGB output (the present blit, previews) want the encoded bytes, as they
     * got them from the RGBA8 target that the shader encoded: no decode on sampling. Rendering
     * into it still encodes (EXT_sRGB_write_control's default; GLES 3.0 always). */
    if (d->format == LR_TEX_SRGB8_ALPHA8)
        glTexParameteri(t->target, LR_GL_TEXTURE_SRGB_DECODE_EXT, LR_GL_SKIP_DECODE_EXT);
    glBindTexture(t->target, 0);
    int rc = lr_gl_check(label, e);
    if (rc) {
        lr_tex_destroy(t);
        return rc;
    }
    t->gl = gl;
    t->bytes = (size_t)w * (size_t)h * (size_t)layers * (size_t)f->texel_bytes;
    lr_gl__mem_add(gl, (long long)t->bytes);
    *out = t;
    return LR_OK;
}

void lr_tex_destroy(lr_tex *t)
{
    if (!t)
        return;
    glDeleteTextures(1, &t->id);
    if (t->gl)
        lr_gl__mem_add(t->gl, -(long long)t->bytes);
    free(t);
}

GLuint lr_tex_id(const lr_tex *t) { return t->id; }
GLenum lr_tex_target(const lr_tex *t) { return t->target; }
lr_tex_format lr_tex_format_of(const lr_tex *t) { return t->format; }
int lr_tex_channels(const lr_tex *t) { return formats[t->format].channels; }

void lr_tex_size(const lr_tex *t, int *width, int *height, int *layers)
{
    if (width)
        *width = t->width;
    if (height)
        *height = t->height;
    if (layers)
        *layers = t->layers;
}

static int check_layer(const lr_tex *t, int layer, lr_err *e)
{
    if (layer < 0 || layer >= t->layers)
        return lr_err_set(e, LR_EINVAL, "%s: layer %d outside 0..%d", t->label, layer, t->layers - 1);
    return LR_OK;
}

int lr_tex_upload(lr_tex *t, int layer, const float *data, lr_err *e)
{
    const struct format_info *f = &formats[t->format];
    if (!f->is_float)
        return lr_err_set(e, LR_EINVAL, "%s: float upload into %s", t->label, f->name);
    int rc = check_layer(t, layer, e);
    if (rc)
        return rc;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glBindTexture(t->target, t->id);
    if (t->target == GL_TEXTURE_2D_ARRAY)
        glTexSubImage3D(t->target, 0, 0, 0, layer, t->width, t->height, 1, f->format, f->type, data);
    else if (t->target == GL_TEXTURE_CUBE_MAP)
        glTexSubImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)layer, 0, 0, 0, t->width, t->height,
                        f->format, f->type, data);
    else
        glTexSubImage2D(t->target, 0, 0, 0, t->width, t->height, f->format, f->type, data);
    glBindTexture(t->target, 0);
    return lr_gl_check(t->label, e);
}

/* ---- framebuffers ------------------------------------------------------------------------ */

static void attach(GLenum point, const lr_fb_attachment *a)
{
    const lr_tex *t = a->tex;
    if (t->target == GL_TEXTURE_2D_ARRAY)
        glFramebufferTextureLayer(GL_FRAMEBUFFER, point, t->id, 0, a->layer);
    else if (t->target == GL_TEXTURE_CUBE_MAP)
        glFramebufferTexture2D(GL_FRAMEBUFFER, point, GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)a->layer,
                               t->id, 0);
    else
        glFramebufferTexture2D(GL_FRAMEBUFFER, point, GL_TEXTURE_2D, t->id, 0);
}

static const char *fb_status_str(GLenum s)
{
    switch (s) {
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_DIMENSIONS: return "GL_FRAMEBUFFER_INCOMPLETE_DIMENSIONS";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "GL_FRAMEBUFFER_UNSUPPORTED";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    default: return "unknown framebuffer status";
    }
}

/* Checks one attachment before GL sees it, so errors name the field. */
static int check_attachment(const lr_gl *gl, const char *label, const char *field,
                            const lr_fb_attachment *a, bool depth, int *w, int *h, lr_err *e)
{
    const struct format_info *f = &formats[a->tex->format];
    if (f->is_depth != depth)
        return lr_err_set(e, LR_EINVAL, "%s: %s: %s is not a %s format", label, field, f->name,
                          depth ? "depth" : "colour");
    int rc = check_layer(a->tex, a->layer, e);
    if (rc)
        return lr_err_prefix(e, "%s: %s", label, field);
    if (f->need && lr_gl_caps_require(lr_gl_caps_get(gl), f->need, e))
        return lr_err_prefix(e, "%s: %s (%s)", label, field, f->name);
    if (*w == 0) {
        *w = a->tex->width;
        *h = a->tex->height;
    } else if (*w != a->tex->width || *h != a->tex->height) {
        return lr_err_set(e, LR_EINVAL, "%s: %s is %dx%d, the others %dx%d", label, field,
                          a->tex->width, a->tex->height, *w, *h);
    }
    return LR_OK;
}

int lr_fb_create(lr_gl *gl, const lr_fb_desc *d, lr_fb **out, lr_err *e)
{
    *out = NULL;
    const char *label = d->label ? d->label : "framebuffer";
    int w = 0, h = 0, n = 0, rc;
    for (; n < LR_FB_MAX_COLOR && d->color[n].tex; n++) {
        char field[24];
        snprintf(field, sizeof field, "color[%d]", n);
        if ((rc = check_attachment(gl, label, field, &d->color[n], false, &w, &h, e)))
            return rc;
    }
    if (n > lr_gl_caps_get(gl)->max_color_attachments)
        return lr_err_set(e, LR_EUNSUPPORTED, "%s: %d colour attachments, driver allows %d", label,
                          n, lr_gl_caps_get(gl)->max_color_attachments);
    if (d->depth.tex && (rc = check_attachment(gl, label, "depth", &d->depth, true, &w, &h, e)))
        return rc;
    if (w == 0)
        return lr_err_set(e, LR_EINVAL, "%s: no attachments", label);

    lr_fb *fb = calloc(1, sizeof *fb);
    if (!fb)
        return lr_err_set(e, LR_ENOMEM, "%s", label);
    fb->width = w;
    fb->height = h;
    fb->ncolor = n;
    snprintf(fb->label, sizeof fb->label, "%s", label);
    glGenFramebuffers(1, &fb->id);
    glBindFramebuffer(GL_FRAMEBUFFER, fb->id);
    GLenum bufs[LR_FB_MAX_COLOR];
    for (int i = 0; i < n; i++) {
        attach(GL_COLOR_ATTACHMENT0 + (GLenum)i, &d->color[i]);
        fb->color_format[i] = d->color[i].tex->format;
        bufs[i] = GL_COLOR_ATTACHMENT0 + (GLenum)i;
    }
    glDrawBuffers(n, bufs);
    if (d->depth.tex) {
        attach(GL_DEPTH_ATTACHMENT, &d->depth);
    } else if (d->depth_buffer) {
        glGenRenderbuffers(1, &fb->depth_rb);
        glBindRenderbuffer(GL_RENDERBUFFER, fb->depth_rb);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
        glBindRenderbuffer(GL_RENDERBUFFER, 0);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, fb->depth_rb);
        fb->gl = gl;
        fb->rb_bytes = (size_t)w * (size_t)h * 4;
        lr_gl__mem_add(gl, (long long)fb->rb_bytes);
    }
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    rc = lr_gl_check(label, e);
    if (rc == LR_OK && status != GL_FRAMEBUFFER_COMPLETE)
        rc = lr_err_set(e, LR_EGL, "%s: incomplete: %s", label, fb_status_str(status));
    if (rc) {
        lr_fb_destroy(fb);
        return rc;
    }
    *out = fb;
    return LR_OK;
}

void lr_fb_destroy(lr_fb *fb)
{
    if (!fb)
        return;
    glDeleteFramebuffers(1, &fb->id);
    if (fb->depth_rb)
        glDeleteRenderbuffers(1, &fb->depth_rb);
    if (fb->gl)
        lr_gl__mem_add(fb->gl, -(long long)fb->rb_bytes);
    free(fb);
}

GLuint lr_fb_id(const lr_fb *fb) { return fb->id; }

void lr_fb_size(const lr_fb *fb, int *width, int *height)
{
    if (width)
        *width = fb->width;
    if (height)
        *height = fb->height;
}

void lr_fb_bind(const lr_fb *fb)
{
    glBindFramebuffer(GL_FRAMEBUFFER, fb->id);
    glViewport(0, 0, fb->width, fb->height);
}

int lr_fb_read(lr_fb *fb, int index, int x, int y, int w, int h, float *rgba, lr_err *e)
{
    if (index < 0 || index >= fb->ncolor)
        return lr_err_set(e, LR_EINVAL, "%s: no colour attachment %d", fb->label, index);
    if (x < 0 || y < 0 || w <= 0 || h <= 0 || x + w > fb->width || y + h > fb->height)
        return lr_err_set(e, LR_EINVAL, "%s: read %dx%d at (%d,%d) outside %dx%d", fb->label, w, h,
                          x, y, fb->width, fb->height);
    glBindFramebuffer(GL_FRAMEBUFFER, fb->id);
    glReadBuffer(GL_COLOR_ATTACHMENT0 + (GLenum)index);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    if (formats[fb->color_format[index]].is_float) {
        /* RGBA/FLOAT is the combination GLES guarantees for reading float colour buffers
         * (EXT_color_buffer_float; glReadPixels in GLES 3.x), whatever their channel count. */
        glReadPixels(x, y, w, h, GL_RGBA, GL_FLOAT, rgba);
    } else {
        size_t n = (size_t)w * (size_t)h * 4;
        unsigned char *px = malloc(n);
        if (!px)
            return lr_err_set(e, LR_ENOMEM, "%s: readback", fb->label);
        glReadPixels(x, y, w, h, GL_RGBA, GL_UNSIGNED_BYTE, px);
        for (size_t i = 0; i < n; i++)
            rgba[i] = (float)px[i] / 255.0f;
        free(px);
    }
    return lr_gl_check(fb->label, e);
}
