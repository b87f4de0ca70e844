#include "tests/support/calib_sim.h"

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "calib/graycode.h"

int sim_scene_alloc(sim_scene *s, int cam_w, int cam_h, int ss)
{
    memset(s, 0, sizeof *s);
    s->cam_w = cam_w;
    s->cam_h = cam_h;
    s->ss = ss;
    s->samples = calloc((size_t)cam_w * (size_t)cam_h * (size_t)(ss * ss), sizeof *s->samples);
    return s->samples ? 0 : -1;
}

void sim_scene_free(sim_scene *s)
{
    free(s->samples);
    s->samples = NULL;
}

sim_sample *sim_at(sim_scene *s, int x, int y, int k)
{
    return &s->samples[((size_t)y * (size_t)s->cam_w + (size_t)x) * (size_t)(s->ss * s->ss) +
                       (size_t)k];
}

double sim_gauss(unsigned long long *state)
{
    /* xorshift64* then Box-Muller. */
    double u[2];
    for (int i = 0; i < 2; i++) {
        unsigned long long x = *state;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        *state = x;
        u[i] = ((x * 2685821657736338717ULL) >> 11) * (1.0 / 9007199254740992.0);
    }
    if (u[0] < 1e-300)
        u[0] = 1e-300;
    return sqrt(-2 * log(u[0])) * cos(2 * M_PI * u[1]);
}

static void blur(double *v, int w, int h, double sigma)
{
    int r = (int)ceil(3 * sigma);
    double *k = malloc(sizeof *k * (size_t)(2 * r + 1));
    double *tmp = malloc(sizeof *tmp * (size_t)w * (size_t)h);
    double sum = 0;
    for (int i = -r; i <= r; i++)
        sum += k[i + r] = exp(-0.5 * i * i / (sigma * sigma));
    for (int i = 0; i <= 2 * r; i++)
        k[i] /= sum;
    for (int pass = 0; pass < 2; pass++) {
        for (int y = 0; y < h; y++)
            for (int x = 0; x < w; x++) {
                double acc = 0;
                for (int i = -r; i <= r; i++) {
                    int xx = pass == 0 ? x + i : x, yy = pass == 0 ? y : y + i;
                    xx = xx < 0 ? 0 : xx >= w ? w - 1 : xx;
                    yy = yy < 0 ? 0 : yy >= h ? h - 1 : yy;
                    acc += k[i + r] * v[(size_t)yy * (size_t)w + (size_t)xx];
                }
                tmp[(size_t)y * (size_t)w + (size_t)x] = acc;
            }
        memcpy(v, tmp, sizeof *v * (size_t)w * (size_t)h);
    }
    free(k);
    free(tmp);
}

/* Projector pixel index lighting each sample for a pw x ph frame, -1 when unlit. */
static int32_t *index_samples(const sim_scene *s, int pw, int ph)
{
    size_t n = (size_t)s->cam_w * (size_t)s->cam_h * (size_t)(s->ss * s->ss);
    int32_t *idx = malloc(sizeof *idx * n);
    if (!idx)
        return NULL;
    for (size_t i = 0; i < n; i++) {
        const sim_sample *p = &s->samples[i];
        idx[i] = -1;
        if (isnan(p->px))
            continue;
        double x = floor(p->px + 0.5), y = floor(p->py + 0.5);
        if (x >= 0 && y >= 0 && x < pw && y < ph)
            idx[i] = (int32_t)(y * pw + x);
    }
    return idx;
}

static int render_indexed(const sim_scene *s, const int32_t *idx, const lr_img *frame,
                          unsigned frame_seed, lr_img *out)
{
    lr_err e = {0};
    if (lr_img_alloc(out, s->cam_w, s->cam_h, 1, 1, &e))
        return -1;
    size_t np = (size_t)s->cam_w * (size_t)s->cam_h;
    double *v = malloc(sizeof *v * np);
    /* Normal deviates from a table drawn once per frame: Box-Muller for every pixel of every
     * frame dominated the tests' run time. 4096 deviates indexed by a 64-bit generator are
     * plenty for noise that only has to be unbiased and of the right spread. */
    enum { NTAB = 4096 };
    double *tab = malloc(sizeof *tab * NTAB);
    if (!v || !tab) {
        free(v);
        free(tab);
        return -1;
    }
    int n = s->ss * s->ss;
    const uint8_t *f = frame->px;
    double lit[256];
    for (int k = 0; k < 256; k++)
        lit[k] = s->ambient + s->gain * (s->black + (1 - s->black) * k / 255.0);
    for (size_t i = 0; i < np; i++) {
        double acc = 0;
        for (int k = 0; k < n; k++) {
            size_t j = i * (size_t)n + (size_t)k;
            acc += s->samples[j].albedo * (idx[j] < 0 ? s->ambient : lit[f[idx[j]]]);
        }
        v[i] = acc / n;
    }
    if (s->blur_sigma > 0)
        blur(v, s->cam_w, s->cam_h, s->blur_sigma);
    unsigned long long state = 0x9E3779B97F4A7C15ULL ^ ((unsigned long long)s->seed << 20) ^
                               (unsigned long long)frame_seed * 0xBF58476D1CE4E5B9ULL;
    if (!state)
        state = 1;
    for (int k = 0; k < NTAB; k++)
        tab[k] = sim_gauss(&state);
    uint8_t *o = out->px;
    for (size_t i = 0; i < np; i++) {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        double g = tab[(state * 2685821657736338717ULL) >> 52];
        double dn = 255.0 * v[i] + s->noise_dn * g;
        o[i] = (uint8_t)(dn < 0 ? 0 : dn > 255 ? 255 : lround(dn));
    }
    free(v);
    free(tab);
    return 0;
}

int sim_render(const sim_scene *s, const lr_img *frame, unsigned frame_seed, lr_img *out)
{
    int32_t *idx = index_samples(s, frame->w, frame->h);
    if (!idx)
        return -1;
    int rc = render_indexed(s, idx, frame, frame_seed, out);
    free(idx);
    return rc;
}

typedef struct write_ctx {
    const sim_scene *s;
    const int32_t *idx;
    const char *dir;
} write_ctx;

static int show(void *ctx, int index, const lr_img *frame, const char *name, lr_err *e)
{
    write_ctx *w = ctx;
    lr_img cam;
    if (render_indexed(w->s, w->idx, frame, (unsigned)index + 1, &cam))
        return lr_err_set(e, LR_ENOMEM, "sim: render failed");
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", w->dir, name);
    int rc = lr_img_write_frame(path, &cam, e);
    lr_img_free(&cam);
    return rc;
}

int sim_write_graycode(const sim_scene *s, int pw, int ph, const char *dir)
{
    mkdir(dir, 0755);
    int32_t *idx = index_samples(s, pw, ph);
    if (!idx)
        return -1;
    write_ctx w = {s, idx, dir};
    lr_err e = {0};
    int rc = lr_gc_run_sequence(pw, ph, show, &w, &e);
    free(idx);
    if (!rc)
        rc = lr_gc_write_sequence(dir, pw, ph, &e);
    if (rc)
        fprintf(stderr, "sim_write_graycode: %s\n", e.msg);
    return rc;
}

char *sim_tempdir(const char *tag)
{
    char *d = malloc(256);
    if (!d)
        return NULL;
    snprintf(d, 256, "/tmp/lr_%s_XXXXXX", tag);
    if (!mkdtemp(d)) {
        free(d);
        return NULL;
    }
    return d;
}

void sim_rmdir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *ent;
    while ((ent = readdir(d))) {
        if (!strcmp(ent->d_name, ".") || !strcmp(ent->d_name, ".."))
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, ent->d_name);
        struct stat st;
        if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode))
            sim_rmdir(path);
        else
            unlink(path);
    }
    closedir(d);
    rmdir(dir);
}
