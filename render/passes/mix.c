/* The mix pass (render/passes/mix.h). */
#include "render/passes/mix.h"

#include <GLES3/gl31.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/gl/shader.h"

struct lr_mix {
    lr_gl *gl;
    lr_program *prog;
    GLuint fb;
};

int lr_mix_create(lr_gl *gl, const char *shader_dir, lr_mix **out, lr_err *e)
{
    *out = NULL;
    lr_mix *m = calloc(1, sizeof *m);
    if (!m)
        return lr_err_set(e, LR_ENOMEM, "mix pass: out of memory");
    m->gl = gl;
    lr_program_desc pd = {.vertex = "fullscreen.vert", .fragment = "mix.frag", .dir = shader_dir};
    int rc = lr_program_create(&pd, &m->prog, e);
    if (rc) {
        free(m);
        return rc;
    }
    glGenFramebuffers(1, &m->fb);
    *out = m;
    return LR_OK;
}

void lr_mix_destroy(lr_mix *m)
{
    if (!m)
        return;
    lr_program_destroy(m->prog);
    glDeleteFramebuffers(1, &m->fb);
    free(m);
}

int lr_mix_run(lr_mix *m, const lr_mix_input *in, lr_tex *target, lr_err *e)
{
    int w, h, nl;
    lr_tex_size(target, &w, &h, &nl);
    if (!in || in->n < 1 || in->n > LR_MIX_MAX_SETS || in->layers < 1 || in->layers > nl ||
        in->layers > LR_SCENE_MAX_LIGHTS)
        return lr_err_set(e, LR_EINVAL, "mix pass: %d sets of %d layers into %d", in ? in->n : 0,
                          in ? in->layers : 0, nl);
    GLuint p = lr_program_id(m->prog);
    glUseProgram(p);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    for (int k = 0; k < LR_MIX_MAX_SETS; k++) {
        glActiveTexture(GL_TEXTURE0 + (GLenum)k);
        glBindTexture(GL_TEXTURE_2D_ARRAY, lr_tex_id(in->sets[k < in->n ? k : 0]));
        char name[24];
        snprintf(name, sizeof name, "u_set%d", k);
        GLint loc = lr_program_uniform(m->prog, name);
        if (loc >= 0)
            glUniform1i(loc, k);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, m->fb);
    GLenum att = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &att);
    glViewport(0, 0, w, h);
    GLint la = lr_program_uniform(m->prog, "u_a");
    if (la < 0)
        la = lr_program_uniform(m->prog, "u_a[0]");
    GLint ll = lr_program_uniform(m->prog, "u_layer");
    for (int l = 0; l < in->layers; l++) {
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, lr_tex_id(target), 0, l);
        float a[3 * LR_MIX_MAX_SETS] = {0}, lnd[3] = {0};
        for (int k = 0; k < in->n; k++)
            for (int b = 0; b < 3; b++) {
                a[3 * k + b] = (float)in->a[k][b];
                if (in->a[k][b] != 0.0)
                    lnd[b] += (float)(in->a[k][b] * log(in->d[k][l]));
            }
        if (la >= 0)
            glUniform3fv(la, LR_MIX_MAX_SETS, a);
        GLint ld = lr_program_uniform(m->prog, "u_lnd");
        if (ld >= 0)
            glUniform3fv(ld, 1, lnd);
        if (ll >= 0)
            glUniform1i(ll, l);
        int rc = lr_program_check(m->prog, e);
        if (rc)
            return rc;
        lr_gl_draw_fullscreen(m->gl);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glActiveTexture(GL_TEXTURE0);
    return lr_gl_check("mix pass", e);
}
