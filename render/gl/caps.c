/* lamprig — which float render targets, filters and timers a GLES driver offers.
 *
 * Pure string work, so it is tested against made-up drivers as well as llvmpipe. */
#include "render/gl/gl.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

static bool has(const char *const *exts, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (exts[i] && strcmp(exts[i], name) == 0)
            return true;
    return false;
}

int lr_gl_caps_parse(const char *version, const char *const *exts, int n_exts, lr_gl_caps *c,
                     lr_err *e)
{
    int major = 0, minor = 0;
    /* GLES mandates a GL_VERSION of the form "OpenGL ES N.M vendor-specific". Anything else
     * is desktop GL or a broken driver; neither is what the passes are written for. */
    if (!version || sscanf(version, "OpenGL ES %d.%d", &major, &minor) != 2)
        return lr_err_set(e, LR_EUNSUPPORTED, "GL: not an OpenGL ES context (GL_VERSION \"%s\")",
                          version ? version : "(null)");
    snprintf(c->version, sizeof c->version, "%s", version);
    c->major = major;
    c->minor = minor;
    bool es32 = major > 3 || (major == 3 && minor >= 2);

    /* GLES 3.2 absorbed EXT_color_buffer_float (its 16F/32F formats are colour-renderable in
     * core), so a 3.2 driver need not list the extension. */
    c->color_buffer_float = es32 || has(exts, n_exts, "GL_EXT_color_buffer_float");
    c->color_buffer_half_float =
        c->color_buffer_float || has(exts, n_exts, "GL_EXT_color_buffer_half_float");
    c->texture_float_linear = has(exts, n_exts, "GL_OES_texture_float_linear");
    c->float_blend = has(exts, n_exts, "GL_EXT_float_blend");
    c->timer_query = has(exts, n_exts, "GL_EXT_disjoint_timer_query");
    c->srgb_decode = has(exts, n_exts, "GL_EXT_texture_sRGB_decode");
    return LR_OK;
}

int lr_gl_caps_require(const lr_gl_caps *c, unsigned need, lr_err *e)
{
    static const struct {
        unsigned bit;
        size_t offset; /* of the bool in lr_gl_caps */
        const char *ext, *what;
    } table[] = {
        {LR_GL_NEED_FLOAT_RT, offsetof(lr_gl_caps, color_buffer_float), "GL_EXT_color_buffer_float",
         "32-bit float render targets; core in GLES 3.2"},
        {LR_GL_NEED_HALF_FLOAT_RT, offsetof(lr_gl_caps, color_buffer_half_float),
         "GL_EXT_color_buffer_half_float", "16-bit float render targets"},
        {LR_GL_NEED_FLOAT_LINEAR, offsetof(lr_gl_caps, texture_float_linear),
         "GL_OES_texture_float_linear", "linear filtering of 32-bit float textures"},
        {LR_GL_NEED_FLOAT_BLEND, offsetof(lr_gl_caps, float_blend), "GL_EXT_float_blend",
         "blending into 32-bit float targets"},
        {LR_GL_NEED_TIMER, offsetof(lr_gl_caps, timer_query), "GL_EXT_disjoint_timer_query",
         "GPU timer queries"},
        {LR_GL_NEED_SRGB_DECODE, offsetof(lr_gl_caps, srgb_decode), "GL_EXT_texture_sRGB_decode",
         "sampling an sRGB texture without decoding it"},
    };
    char missing[LR_ERR_MSG_MAX] = "";
    size_t len = 0;
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++) {
        bool ok = *(const bool *)((const char *)c + table[i].offset);
        if (!(need & table[i].bit) || ok)
            continue;
        int k = snprintf(missing + len, sizeof missing - len, "%s%s (%s)", len ? ", " : "",
                         table[i].ext, table[i].what);
        if (k > 0)
            len += (size_t)k < sizeof missing - len ? (size_t)k : sizeof missing - len - 1;
    }
    if (len == 0)
        return LR_OK;
    return lr_err_set(e, LR_EUNSUPPORTED, "GL: missing %s on %s (%s)", missing,
                      c->renderer[0] ? c->renderer : "this driver", c->version);
}
