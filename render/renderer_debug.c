/* Readback of the passes' intermediate results (render/renderer_debug.h). */
#include "render/renderer_debug.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/base/median.h"
#include "render/bounce/rbounce.h"
#include "render/optics/optics.h"
#include "render/renderer_parts.h"

static lr_renderer_parts parts(const lr_renderer *r)
{
    lr_renderer_parts p;
    lr_renderer_parts_get(r, &p);
    return p;
}

void lr_renderer_debug_map_info(const lr_renderer *r, lr_debug_map_info *out)
{
    lr_renderer_parts p = parts(r);
    const lr_radiosity *rad = p.radiosity;
    memset(out, 0, sizeof *out);
    out->K = rad->K;
    out->size = rad->size;
    out->frames = rad->F;
    out->N = p.rs->N;
    out->center = rad->center;
    out->radius = rad->radius;
    out->r_max = rad->r_max;
    out->seed = p.seed;
}

void lr_renderer_debug_cavity_gain(const lr_renderer *r, int object, double out[3])
{
    lr_renderer_debug_light_cavity_gain(r, 0, object, out);
}

void lr_renderer_debug_light_cavity_gain(const lr_renderer *r, int l, int object, double out[3])
{
    bool ok = l >= 0 && l < LR_MAX_LIGHTS && object >= 0 && object < LR_MAX_OBJECTS;
    for (int c = 0; c < 3; c++)
        out[c] = ok ? parts(r).objs->cavity_gain[3 * (l * LR_MAX_OBJECTS + object) + c] : 1.0;
}

lr_vec3 lr_renderer_debug_map_dir(const lr_renderer *r, int k)
{
    const lr_radiosity *rad = parts(r).radiosity;
    return k >= 0 && k < rad->K ? rad->d[k] : lr_v3(0, 0, 0);
}

void lr_renderer_debug_map_matrix(const lr_renderer *r, int k, double out[16])
{
    const lr_radiosity *rad = parts(r).radiosity;
    memcpy(out, rad->P[k >= 0 && k < rad->K ? k : 0], 16 * sizeof *out);
}

/* Reads colour attachment `att` of framebuffer fb into 4-float texels. */
static float *read_fb(lr_fb *fb, int att, int w, int h, lr_err *e)
{
    float *buf = malloc((size_t)w * h * 4 * sizeof *buf);
    if (!buf) {
        lr_err_set(e, LR_ENOMEM, "debug readback: out of memory");
        return NULL;
    }
    if (lr_fb_read(fb, att, 0, 0, w, h, buf, e)) {
        free(buf);
        return NULL;
    }
    return buf;
}

static void copy3(float *dst, const float *src, size_t n)
{
    if (dst)
        for (size_t i = 0; i < n; i++)
            memcpy(dst + 3 * i, src + 4 * i, 3 * sizeof *dst);
}

int lr_renderer_debug_read_map(lr_renderer *r, int k, float *B, float *pos, float *nrm, int *object,
                               lr_err *e)
{
    return lr_renderer_debug_read_light_map(r, 0, k, B, pos, nrm, object, e);
}

int lr_renderer_debug_read_light_map(lr_renderer *r, int l, int k, float *B, float *pos,
                                     float *nrm, int *object, lr_err *e)
{
    const lr_radiosity *rad = parts(r).radiosity;
    if (k < 0 || k >= rad->K)
        return lr_err_set(e, LR_EINVAL, "debug: map %d of %d", k, rad->K);
    if (l < 0 || l >= rad->n_lights)
        return lr_err_set(e, LR_EINVAL, "debug: light %d of %d", l, rad->n_lights);
    int n = rad->size;
    size_t cnt = (size_t)n * n;
    lr_fb *fb = rad->fb[l * rad->K + k];
    float *b = read_fb(fb, 0, n, n, e);
    float *p = b ? read_fb(fb, 1, n, n, e) : NULL;
    float *q = p ? read_fb(fb, 2, n, n, e) : NULL;
    if (!q) {
        free(b);
        free(p);
        return e ? e->code : LR_EIO;
    }
    copy3(B, b, cnt);
    if (B)
        for (size_t i = 0; i < 3 * cnt; i++)
            B[i] /= rad->scale[l];
    copy3(pos, p, cnt);
    copy3(nrm, q, cnt);
    if (object)
        for (size_t i = 0; i < cnt; i++)
            object[i] = p[4 * i + 3] > 0.5f ? (int)(q[4 * i + 3] + 0.5f) : -1;
    free(b);
    free(p);
    free(q);
    return LR_OK;
}

int lr_renderer_debug_vpl_count(const lr_renderer *r)
{
    const lr_vpl *v = parts(r).vpl;
    return v->fb ? v->n : 0;
}

lr_vec3 lr_renderer_debug_vpl_center(const lr_renderer *r)
{
    return parts(r).vpl->center;
}

int lr_renderer_debug_read_vpls(lr_renderer *r, lr_debug_vpl *out, lr_err *e)
{
    int n = lr_renderer_debug_vpl_count(r);
    if (!n)
        return LR_OK;
    lr_fb *fb = parts(r).vpl->fb;
    float *p = read_fb(fb, 0, n, 1, e);
    float *q = p ? read_fb(fb, 1, n, 1, e) : NULL;
    float *b = q ? read_fb(fb, 2, n, 1, e) : NULL;
    if (!b) {
        free(p);
        free(q);
        return e ? e->code : LR_EIO;
    }
    for (int v = 0; v < n; v++) {
        lr_debug_vpl *o = &out[v];
        memset(o, 0, sizeof *o);
        o->u = lr_halton_sphere((unsigned)v + 1);
        o->valid = p[4 * v + 3] > 0.0f;
        o->pos = lr_v3(p[4 * v], p[4 * v + 1], p[4 * v + 2]);
        o->area = p[4 * v + 3];
        o->nrm = lr_v3(q[4 * v], q[4 * v + 1], q[4 * v + 2]);
        o->object = o->valid ? (int)(q[4 * v + 3] + 0.5f) : -1;
        for (int c = 0; c < 3; c++)
            o->B[c] = b[4 * v + c];
        o->weight = b[4 * v + 3];
    }
    free(p);
    free(q);
    free(b);
    return LR_OK;
}

void lr_renderer_debug_gbuffer_info(const lr_renderer *r, lr_debug_gbuffer_info *out)
{
    lr_renderer_debug_light_gbuffer_info(r, 0, out);
}

void lr_renderer_debug_light_gbuffer_info(const lr_renderer *r, int l, lr_debug_gbuffer_info *out)
{
    memset(out, 0, sizeof *out);
    const lr_gbuffer *gb = parts(r).gbuffer;
    if (l < 0 || l >= gb->n_lights)
        return;
    const lr_light_gbuffer *g = &gb->light[l];
    out->cube = g->mode == LR_GB_CUBE;
    out->orthographic = g->mode == LR_GB_ORTHO;
    out->size = g->size;
    if (out->cube)
        memcpy(out->vp, g->face_vp, sizeof out->vp);
    else
        memcpy(out->vp[0], g->vp_d, sizeof out->vp[0]);
    out->light_pos = g->pos;
    out->light_dir = g->dir;
}

int lr_renderer_debug_read_gbuffer(lr_renderer *r, int face, float *pos, float *nrm, int *object,
                                   lr_err *e)
{
    const lr_light_gbuffer *g = &parts(r).gbuffer->light[0];
    bool cube = g->mode == LR_GB_CUBE;
    if (face < 0 || face >= (cube ? 6 : 1))
        return lr_err_set(e, LR_EINVAL, "debug: G-buffer face %d", face);
    lr_fb *fb = cube ? g->fb[face] : g->fb_2d;
    int n = g->size;
    size_t cnt = (size_t)n * n;
    float *p = read_fb(fb, 0, n, n, e);
    float *q = p ? read_fb(fb, 1, n, n, e) : NULL;
    if (!q) {
        free(p);
        return e ? e->code : LR_EIO;
    }
    copy3(pos, p, cnt);
    copy3(nrm, q, cnt);
    if (object)
        for (size_t i = 0; i < cnt; i++)
            object[i] = p[4 * i + 3] > 0.5f ? (int)(p[4 * i + 3] + 0.5f) - 1 : -1;
    free(p);
    free(q);
    return LR_OK;
}

int lr_renderer_debug_uncovered(lr_renderer *r, int *count, lr_err *e)
{
    lr_renderer_parts pt = parts(r);
    lr_fb *hdr;
    int rc = pt.blend ? lr_blend_hdr(pt.blend, &hdr, e)
                      : lr_err_set(e, LR_EINVAL, "renderer: no image (no resources)");
    if (rc)
        return rc;
    float *p = read_fb(hdr, 0, pt.width, pt.height, e);
    if (!p)
        return e ? e->code : LR_EIO;
    int n = 0;
    for (size_t i = 0; i < (size_t)pt.width * pt.height; i++)
        n += p[4 * i + 3] < 0.5f;
    free(p);
    *count = n;
    return LR_OK;
}

bool lr_renderer_debug_compose_gathered(const lr_renderer *r)
{
    return parts(r).compose->gathered;
}

long lr_renderer_debug_slices(const lr_renderer *r) { return lr_slicer_count(parts(r).slicer); }

void lr_renderer_debug_on_slice(lr_renderer *r, lr_slice_fn fn, void *ctx)
{
    lr_slicer_set_hook(parts(r).slicer, fn, ctx);
}

void lr_renderer_debug_surface_info(const lr_renderer *r, lr_debug_surface_info *out)
{
    const lr_surface *sc = parts(r).surface;
    memset(out, 0, sizeof *out);
    if (!sc->built)
        return;
    out->entries = sc->entries;
    out->n_objects = sc->n_objects;
    for (int i = 0; i < sc->n_objects && i < LR_MAX_OBJECTS; i++) {
        out->nv[i] = sc->nv[i];
        out->h[i] = sc->h[i];
    }
}

int lr_renderer_debug_read_surface(lr_renderer *r, int l, float *out, lr_err *e)
{
    const lr_surface *sc = parts(r).surface;
    if (!sc->valid || l < 0 || l >= sc->n_lights)
        return lr_err_set(e, LR_EINVAL, "debug surface cache: not drawn, or no light %d", l);
    float *p = read_fb(sc->fb, l, LR_SURFACE_ROW, sc->rows, e);
    if (!p)
        return e ? e->code : LR_EIO;
    memcpy(out, p, (size_t)sc->entries * 4 * sizeof *out);
    free(p);
    return LR_OK;
}

struct lr_debug_floor {
    lr_renderer_parts pt;
    lr_program *p;
    lr_tex *src;
};

void lr_debug_floor_destroy(lr_debug_floor *f)
{
    if (!f)
        return;
    lr_tex_destroy(f->src);
    lr_program_destroy(f->p);
    free(f);
}

int lr_debug_floor_create(lr_renderer *r, lr_debug_floor **out, lr_err *e)
{
    *out = NULL;
    lr_debug_floor *f = calloc(1, sizeof *f);
    if (!f)
        return lr_err_set(e, LR_ENOMEM, "floor pass: out of memory");
    f->pt = parts(r);
    if (!f->pt.blend) {
        free(f);
        return lr_err_set(e, LR_EINVAL, "renderer: no output (resources failed to allocate)");
    }
    lr_program_desc pd = {.vertex = "fullscreen.vert", .fragment = "floor.frag",
                          .dir = f->pt.shader_dir, .defines = f->pt.defines};
    lr_tex_desc td = {.format = LR_TEX_RGBA16F, .width = f->pt.width, .height = f->pt.height,
                      .label = "floor pass source"};
    int rc;
    if ((rc = lr_program_create(&pd, &f->p, e)) || (rc = lr_tex_create(f->pt.gl, &td, &f->src, e))) {
        lr_debug_floor_destroy(f);
        return rc;
    }
    *out = f;
    return LR_OK;
}

static double ms_between(const struct timespec *a, const struct timespec *b)
{
    return (double)(b->tv_sec - a->tv_sec) * 1e3 + (double)(b->tv_nsec - a->tv_nsec) * 1e-6;
}

int lr_debug_floor_run(lr_debug_floor *f, double *wall_ms, double *timer_ms, double *cpu_ms,
                       lr_err *e)
{
    *wall_ms = *timer_ms = *cpu_ms = NAN;
    lr_renderer_parts *pt = &f->pt;
    /* Timed the way a frame is (lr_renderer_frame): the draw inside the renderer's timer
     * section (reset, begin, end, collect), the whole from glFinish to glFinish. */
    struct timespec t0, t1, c0, c1;
    glFinish();
    clock_gettime(CLOCK_MONOTONIC, &t0);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    lr_timer_reset(pt->timer);
    int rc;
    if ((rc = lr_timer_begin(pt->timer, "floor", e)))
        return rc;
    lr_fb_bind(lr_blend_ldr_fb(pt->blend));
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(f->p));
    lr_passes_bind_tex(f->p, "u_src", 0, f->src);
    if ((rc = lr_program_check(f->p, e)))
        return rc;
    lr_gl_draw_fullscreen(pt->gl);
    if ((rc = lr_timer_end(pt->timer, e)))
        return rc;
    int trc = lr_timer_collect(pt->timer, NULL);
    glFinish();
    clock_gettime(CLOCK_MONOTONIC, &t1);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    *timer_ms = trc || lr_timer_count(pt->timer) < 1 ? NAN : lr_timer_ms(pt->timer, 0);
    *wall_ms = ms_between(&t0, &t1);
    *cpu_ms = ms_between(&c0, &c1);
    lr_timer_reset(pt->timer);
    return lr_gl_check("floor pass", e);
}

int lr_renderer_debug_floor_ms(lr_renderer *r, int reps, double *wall_ms, double *timer_ms,
                               lr_err *e)
{
    *wall_ms = *timer_ms = NAN;
    if (reps < 1 || reps > 64)
        return lr_err_set(e, LR_EINVAL, "floor pass: reps = %d: must be 1..64", reps);
    lr_debug_floor *f = NULL;
    int rc = lr_debug_floor_create(r, &f, e);
    double t[64], g[64], c;
    for (int i = 0; i < reps && !rc; i++)
        rc = lr_debug_floor_run(f, &t[i], &g[i], &c, e);
    if (!rc) {
        *wall_ms = lr_median_finite(t, reps);
        *timer_ms = lr_median_finite(g, reps);
    }
    lr_debug_floor_destroy(f);
    return rc;
}

bool lr_renderer_debug_bounce_build(const lr_renderer *r, double *build_s)
{
    *build_s = 0;
    const lr_irradiance *irr = r ? parts(r).irradiance : NULL;
    if (!irr || !irr->rb)
        return false;
    double direct_s, solve_s;
    lr_rbounce_times(irr->rb, build_s, &direct_s, &solve_s);
    return true;
}
