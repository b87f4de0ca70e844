/* lamprig — LPV propagation on GLES 3.1 compute shaders (gpu.h). */
#include "render/lpv/gpu.h"

#include <GLES3/gl31.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/gl/shader.h"

struct lr_lpv_gpu {
    int n, cur;
    GLuint grid[2], absorbed, block, fb;
    lr_program *prog;
};

static GLuint tex3d(GLenum fmt, int w, int h, int d)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_3D, t);
    glTexStorage3D(GL_TEXTURE_3D, 1, fmt, w, h, d);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return t;
}

int lr_lpv_gpu_create(lr_gl *gl, int n, const char *shader_dir, lr_lpv_gpu **out, lr_err *e)
{
    (void)gl;
    *out = NULL;
    if (n < LR_LPV_MIN_N || n > LR_LPV_MAX_N)
        return lr_err_set(e, LR_EINVAL, "lpv gpu: n = %d cells per axis, must be %d to %d", n,
                          LR_LPV_MIN_N, LR_LPV_MAX_N);
    lr_lpv_gpu *g = calloc(1, sizeof *g);
    if (!g)
        return lr_err_set(e, LR_ENOMEM, "lpv gpu: out of memory");
    g->n = n;
    char dir[512];
    if (!shader_dir) {
        if (lr_shaders_dir(dir, sizeof dir) != 0) {
            free(g);
            return lr_err_set(e, LR_EIO, "lpv gpu: shader folder not found");
        }
        shader_dir = dir;
    }
    lr_program_desc pd = {.compute = "lpv_propagate.comp", .dir = shader_dir};
    int rc = lr_program_create(&pd, &g->prog, e);
    if (rc) {
        free(g);
        return rc;
    }
    for (int i = 0; i < 2; i++)
        g->grid[i] = tex3d(GL_RGBA32F, 3 * n, n, n);
    g->absorbed = tex3d(GL_R32F, 18 * (n + 1), n + 1, n + 1);
    g->block = tex3d(GL_RGBA32F, n + 1, n + 1, n + 1);
    glGenFramebuffers(1, &g->fb);
    *out = g;
    return lr_gl_check("lpv gpu: textures", e);
}

void lr_lpv_gpu_destroy(lr_lpv_gpu *g)
{
    if (!g)
        return;
    glDeleteTextures(2, g->grid);
    glDeleteTextures(1, &g->absorbed);
    glDeleteTextures(1, &g->block);
    glDeleteFramebuffers(1, &g->fb);
    lr_program_destroy(g->prog);
    free(g);
}

static void upload(GLuint t, GLenum fmt, int w, int h, int d, const float *data)
{
    glBindTexture(GL_TEXTURE_3D, t);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, w, h, d, fmt, GL_FLOAT, data);
}

int lr_lpv_gpu_upload(lr_lpv_gpu *g, const lr_lpv *v, lr_err *e)
{
    int n = g->n, n1 = n + 1;
    if (lr_lpv_n(v) != n)
        return lr_err_set(e, LR_EINVAL, "lpv gpu: volume has n = %d, textures %d", lr_lpv_n(v),
                          n);
    size_t cells = (size_t)n * n * n, ifaces = (size_t)n1 * n1 * n1;
    float *buf = malloc(sizeof(float) * (ifaces * 18 > cells * 12 ? ifaces * 18 : cells * 12));
    if (!buf)
        return lr_err_set(e, LR_ENOMEM, "lpv gpu: upload buffer");
    const double *gr = lr_lpv_grid(v);
    for (size_t i = 0; i < cells * 12; i++)
        buf[i] = (float)gr[i];
    upload(g->grid[0], GL_RGBA, 3 * n, n, n, buf);
    g->cur = 0;
    const double *ab = lr_lpv_absorbed(v);
    for (size_t i = 0; i < ifaces * 18; i++)
        buf[i] = (float)ab[i];
    upload(g->absorbed, GL_RED, 18 * n1, n1, n1, buf);
    upload(g->block, GL_RGBA, n1, n1, n1, lr_lpv_blocking(v));
    free(buf);
    const lr_lpv_stencil *st = lr_lpv_stencil_of(v);
    float vv[30][4], lobe[30][4];
    for (int m = 0; m < 6; m++)
        for (int f = 0; f < 5; f++)
            for (int i = 0; i < 4; i++) {
                vv[m * 5 + f][i] = (float)st->v[m][f][i];
                lobe[m * 5 + f][i] = (float)st->lobe[m][f][i];
            }
    glUseProgram(lr_program_id(g->prog));
    glUniform4fv(lr_program_uniform(g->prog, "u_v"), 30, &vv[0][0]);
    glUniform4fv(lr_program_uniform(g->prog, "u_lobe"), 30, &lobe[0][0]);
    glUniform1i(lr_program_uniform(g->prog, "u_n"), n);
    glUniform1i(lr_program_uniform(g->prog, "u_src"), 0);
    glUniform1i(lr_program_uniform(g->prog, "u_block"), 1);
    int rc = lr_program_check(g->prog, e);
    return rc ? rc : lr_gl_check("lpv gpu: upload", e);
}

int lr_lpv_gpu_propagate(lr_lpv_gpu *g, int steps, lr_err *e)
{
    if (steps < 0 || steps > 4 * g->n)
        return lr_err_set(e, LR_EINVAL, "lpv gpu: steps = %d, must be 0 to %d (4 n)", steps,
                          4 * g->n);
    glUseProgram(lr_program_id(g->prog));
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_3D, g->block);
    glBindImageTexture(1, g->absorbed, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32F);
    GLuint groups = (GLuint)(g->n + 3) / 4;
    for (int s = 0; s < steps; s++) {
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_3D, g->grid[g->cur]);
        glBindImageTexture(0, g->grid[1 - g->cur], 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_RGBA32F);
        glDispatchCompute(groups, groups, groups);
        /* The next step samples what this one wrote, and reloads the absorbed image. */
        glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        g->cur = 1 - g->cur;
    }
    return lr_gl_check("lpv gpu: propagate", e);
}

/* Reads a w x h x d float 3D texture, `comp` channels (1: r32f, 4: rgba32f), slice by slice
 * through a framebuffer (RGBA/FLOAT, the readback GLES guarantees for float buffers). */
static int read3d(lr_lpv_gpu *g, GLuint t, int w, int h, int d, int comp, double *out,
                  lr_err *e)
{
    float *px = malloc(sizeof(float) * 4 * (size_t)w * h);
    if (!px)
        return lr_err_set(e, LR_ENOMEM, "lpv gpu: readback buffer");
    glMemoryBarrier(GL_FRAMEBUFFER_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
    glBindFramebuffer(GL_FRAMEBUFFER, g->fb);
    int rc = LR_OK;
    for (int z = 0; z < d && !rc; z++) {
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, t, 0, z);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
            rc = lr_err_set(e, LR_EUNSUPPORTED, "lpv gpu: a float 3D texture slice is not a "
                                                "complete framebuffer (EXT_color_buffer_float)");
            break;
        }
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, px);
        for (size_t i = 0; i < (size_t)w * h; i++)
            for (int c = 0; c < comp; c++)
                out[((size_t)z * w * h + i) * comp + c] = px[i * 4 + c];
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    free(px);
    return rc ? rc : lr_gl_check("lpv gpu: readback", e);
}

int lr_lpv_gpu_download(lr_lpv_gpu *g, lr_lpv *v, lr_err *e)
{
    int n = g->n, n1 = n + 1;
    if (lr_lpv_n(v) != n)
        return lr_err_set(e, LR_EINVAL, "lpv gpu: volume has n = %d, textures %d", lr_lpv_n(v),
                          n);
    double *grid = malloc(sizeof(double) * (size_t)n * n * n * 12);
    double *ab = malloc(sizeof(double) * (size_t)n1 * n1 * n1 * 18);
    int rc = (!grid || !ab) ? lr_err_set(e, LR_ENOMEM, "lpv gpu: readback") : LR_OK;
    if (!rc)
        rc = read3d(g, g->grid[g->cur], 3 * n, n, n, 4, grid, e);
    if (!rc)
        rc = read3d(g, g->absorbed, 18 * n1, n1, n1, 1, ab, e);
    if (!rc)
        lr_lpv_set_state(v, grid, ab);
    free(grid);
    free(ab);
    return rc;
}

int lr_lpv_gpu_run(void *ctx, lr_lpv *v, int steps, lr_err *e)
{
    lr_lpv_gpu *g = ctx;
    int rc = lr_lpv_gpu_upload(g, v, e);
    if (!rc)
        rc = lr_lpv_gpu_propagate(g, steps, e);
    if (!rc)
        rc = lr_lpv_gpu_download(g, v, e);
    return rc;
}
