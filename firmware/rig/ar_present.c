/* lamprig firmware — spatial AR frames on the projector (see ar_present.h). */
#include "firmware/rig/ar_present.h"

#include <GLES3/gl31.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/gl/shader.h"

struct lr_ar_present {
    lr_gl *gl;
    lr_program *blit;
    GLuint tex;
    int width, height; /* of the uploaded frame; 0 before the first */
};

int lr_ar_present_create(lr_gl *gl, lr_ar_present **out, lr_err *e)
{
    *out = NULL;
    lr_ar_present *p = calloc(1, sizeof *p);
    if (!p)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    p->gl = gl;
    char dir[512];
    if (lr_shaders_dir(dir, sizeof dir) != 0) {
        free(p);
        return lr_err_set(e, LR_EINVAL, "spatial AR output: shader path too long");
    }
    lr_program_desc d = {.vertex = "fullscreen.vert", .fragment = "blit.frag", .dir = dir};
    int rc = lr_program_create(&d, &p->blit, e);
    if (rc) {
        free(p);
        return lr_err_prefix(e, "spatial AR output");
    }
    glGenTextures(1, &p->tex);
    if ((rc = lr_gl_check("spatial AR output: texture", e))) {
        lr_ar_present_destroy(p);
        return rc;
    }
    *out = p;
    return LR_OK;
}

void lr_ar_present_destroy(lr_ar_present *p)
{
    if (!p)
        return;
    if (p->tex)
        glDeleteTextures(1, &p->tex);
    lr_program_destroy(p->blit);
    free(p);
}

void lr_ar_levels_to_rgb8(const lr_image *levels, uint8_t *out)
{
    size_t n = (size_t)levels->width * (size_t)levels->height * 3;
    for (size_t k = 0; k < n; k++)
        out[k] = (uint8_t)lrint(255 * fmin(1.0, fmax(0.0, levels->rgb[k])));
}

int lr_ar_present_upload(lr_ar_present *p, const lr_image *levels, lr_err *e)
{
    int w = levels->width, h = levels->height;
    if (w <= 0 || h <= 0 || !levels->rgb)
        return lr_err_set(e, LR_EINVAL, "spatial AR output: empty frame");
    const lr_gl_caps *caps = lr_gl_caps_get(p->gl);
    if (w > caps->max_texture_size || h > caps->max_texture_size)
        return lr_err_set(e, LR_EINVAL, "spatial AR output: frame %dx%d beyond the driver's "
                          "texture limit %d", w, h, caps->max_texture_size);
    size_t row = (size_t)w * 3;
    uint8_t *top = malloc(row * (size_t)h), *gl_rows = malloc(row * (size_t)h);
    if (!top || !gl_rows) {
        free(top);
        free(gl_rows);
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    }
    lr_ar_levels_to_rgb8(levels, top);
    /* GL rows are bottom-up: row 0 of the texture is the image's last row. */
    for (int y = 0; y < h; y++)
        memcpy(gl_rows + (size_t)y * row, top + (size_t)(h - 1 - y) * row, row);
    glBindTexture(GL_TEXTURE_2D, p->tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, w, h, 0, GL_RGB, GL_UNSIGNED_BYTE, gl_rows);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    free(top);
    free(gl_rows);
    int rc = lr_gl_check("spatial AR output: upload", e);
    if (!rc) {
        p->width = w;
        p->height = h;
    }
    return rc;
}

int lr_ar_present_draw(lr_ar_present *p, int width, int height, lr_err *e)
{
    if (!p->width)
        return lr_err_set(e, LR_EINVAL, "spatial AR output: no frame uploaded");
    GLint filter = width == p->width && height == p->height ? GL_NEAREST : GL_LINEAR;
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(p->blit));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, p->tex);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    GLint loc = lr_program_uniform(p->blit, "u_src");
    if (loc >= 0)
        glUniform1i(loc, 0);
    /* As every render pass does: a uniform blit.frag does not declare is an error. */
    int rc = lr_program_check(p->blit, e);
    if (rc)
        return lr_err_prefix(e, "spatial AR output");
    lr_gl_draw_fullscreen(p->gl);
    return lr_gl_check("spatial AR output: draw", e);
}

int lr_ar_present_show(lr_ar_present *p, const lr_image *levels, lr_err *e)
{
    int rc = lr_ar_present_upload(p, levels, e);
    int w = 0, h = 0;
    lr_gl_size(p->gl, &w, &h);
    if (!rc && w > 0 && h > 0) {
        lr_gl_bind_default(p->gl);
        rc = lr_ar_present_draw(p, w, h, e);
    }
    if (!rc)
        rc = lr_gl_present(p->gl, e);
    return rc;
}
