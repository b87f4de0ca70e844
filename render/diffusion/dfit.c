/* lamprig — `lamprig fit --diffusion`: captures file to volume file (dfit.h). */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/atomic_file.h"
#include "render/base/file.h"
#include "render/diffusion/dfit.h"
#include "render/diffusion/dgrid.h"
#include "render/diffusion/inverse.h"

#define LR_DFIT_MAX_PATTERNS 64
#define LR_DFIT_MAX_CELLS 64

typedef struct obs {
    double x, y, z, B[3];
    int pattern;
} obs;

typedef struct caps {
    double S[3], eta, h;
    int n_pat;
    double rect[LR_DFIT_MAX_PATTERNS][4], E[LR_DFIT_MAX_PATTERNS][3];
    obs *o;
    size_t n_obs, cap_obs;
} caps;

static int nums(const char *s, double *v, int n)
{
    for (int k = 0; k < n; k++) {
        char *end;
        v[k] = strtod(s, &end);
        if (end == s || !isfinite(v[k]))
            return -1;
        s = end;
    }
    while (isspace((unsigned char)*s))
        s++;
    return *s ? -1 : 0;
}

static int parse(const char *path, caps *c, lr_err *e)
{
    char *text;
    size_t len;
    int rc = lr_file_read(path, LR_FILE_MAX_TEXT, &text, &len, e);
    if (rc)
        return rc;
    memset(c, 0, sizeof *c);
    int ln = 0;
    bool header = false;
    for (char *line = text, *next; line && *line; line = next) {
        next = strchr(line, '\n');
        if (next)
            *next++ = 0;
        ln++;
        char *s = line;
        while (isspace((unsigned char)*s))
            s++;
        size_t l = strlen(s);
        while (l && isspace((unsigned char)s[l - 1]))
            s[--l] = 0;
        if (!*s || *s == '#')
            continue;
        double v[7];
#define BAD(...)                                                                             \
    do {                                                                                     \
        char m_[200];                                                                        \
        snprintf(m_, sizeof m_, __VA_ARGS__);                                                \
        rc = lr_err_set(e, LR_EPARSE, "%s:%d: %s", path, ln, m_);                            \
        goto done;                                                                           \
    } while (0)
        if (!header) {
            if (strcmp(s, "lamprig-diffusion-captures 1") != 0)
                BAD("expected the header 'lamprig-diffusion-captures 1'");
            header = true;
        } else if (strncmp(s, "block ", 6) == 0) {
            if (nums(s + 6, c->S, 3) || !(c->S[0] > 0 && c->S[1] > 0 && c->S[2] > 0))
                BAD("field 'block': three sizes > 0 (mm) expected");
        } else if (strncmp(s, "eta ", 4) == 0) {
            if (nums(s + 4, &c->eta, 1) || c->eta < 0.5 || c->eta > 2.5)
                BAD("field 'eta': a number in [0.5, 2.5] expected");
        } else if (strncmp(s, "h ", 2) == 0) {
            if (nums(s + 2, &c->h, 1) || !(c->h > 0))
                BAD("field 'h': a spacing > 0 (mm) expected");
        } else if (strncmp(s, "pattern ", 8) == 0) {
            if (c->n_pat == LR_DFIT_MAX_PATTERNS)
                BAD("at most %d patterns", LR_DFIT_MAX_PATTERNS);
            if (nums(s + 8, v, 7) || v[4] < 0 || v[5] < 0 || v[6] < 0 || !(v[2] > v[0]) ||
                !(v[3] > v[1]))
                BAD("field 'pattern': X0 Y0 X1 Y1 (X1 > X0, Y1 > Y0) and R G B >= 0 expected");
            memcpy(c->rect[c->n_pat], v, 4 * sizeof *v);
            memcpy(c->E[c->n_pat], v + 4, 3 * sizeof *v);
            c->n_pat++;
        } else if (strncmp(s, "B ", 2) == 0) {
            if (!c->n_pat)
                BAD("a 'B' line before the first 'pattern'");
            if (nums(s + 2, v, 6) || v[3] < 0 || v[4] < 0 || v[5] < 0)
                BAD("field 'B': X Y Z and R G B >= 0 expected");
            if (c->n_obs == c->cap_obs) {
                size_t cap = c->cap_obs ? 2 * c->cap_obs : 256;
                obs *o = realloc(c->o, cap * sizeof *o);
                if (!o) {
                    rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
                    goto done;
                }
                c->o = o;
                c->cap_obs = cap;
            }
            c->o[c->n_obs++] = (obs){v[0], v[1], v[2], {v[3], v[4], v[5]}, c->n_pat - 1};
        } else {
            BAD("unknown line '%.40s' (block, eta, h, pattern or B expected)", s);
        }
#undef BAD
    }
    if (!header || !(c->S[0] > 0) || !(c->eta > 0) || !(c->h > 0) || !c->n_pat || !c->n_obs)
        rc = lr_err_set(e, LR_EPARSE, "%s: needs the header, block, eta, h, a pattern and B lines",
                        path);
    else
        for (int a = 0; a < 3 && !rc; a++)
            if (c->S[a] / c->h > LR_DFIT_MAX_CELLS)
                rc = lr_err_set(e, LR_EINVAL, "%s: block side %g mm over h %g: at most %d cells",
                                path, c->S[a], c->h, LR_DFIT_MAX_CELLS);
done:
    free(text);
    return rc;
}

/* Up to 62 regions: nodes whose log coefficients all lie within tau of a region's first
 * member join it; tau doubles until the count fits. */
static const char region_chars[] = "0123456789abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ";

static int cluster(const double (*v)[6], size_t n, int *label, double (*centre)[6])
{
    for (double tau = 0.02;; tau *= 2.0) {
        int k = 0;
        double (*first)[6] = centre;
        bool ok = true;
        for (size_t p = 0; p < n && ok; p++) {
            int hit = -1;
            for (int r = 0; r < k && hit < 0; r++) {
                bool near = true;
                for (int j = 0; j < 6; j++)
                    near &= fabs(v[p][j] - first[r][j]) <= tau;
                if (near)
                    hit = r;
            }
            if (hit < 0) {
                if (k == 62) {
                    ok = false;
                    break;
                }
                memcpy(first[k], v[p], sizeof first[k]);
                hit = k++;
            }
            label[p] = hit;
        }
        if (ok) {
            /* region values: the mean of the members' log coefficients */
            double sum[62][6] = {{0}};
            int cnt[62] = {0};
            for (size_t p = 0; p < n; p++) {
                cnt[label[p]]++;
                for (int j = 0; j < 6; j++)
                    sum[label[p]][j] += v[p][j];
            }
            for (int r = 0; r < k; r++)
                for (int j = 0; j < 6; j++)
                    centre[r][j] = sum[r][j] / cnt[r];
            return k;
        }
    }
}

int lr_dfit_run(const lr_dfit_desc *d, lr_dfit_result *res, lr_err *e)
{
    memset(res, 0, sizeof *res);
    caps c = {0};
    int rc = parse(d->captures, &c, e);
    if (rc) {
        free(c.o);
        return rc;
    }
    lr_dbox box = {lr_v3(0, 0, 0), lr_v3(c.S[0], c.S[1], c.S[2])};
    lr_dshape shape = lr_dshape_box(&box);
    lr_dgrid *g = NULL;
    lr_dsystem *sys = NULL;
    double *q = NULL, *y = NULL, *theta = NULL, (*vals)[6] = NULL;
    unsigned char *seen = NULL;
    lr_dinv_pattern *pat = NULL;
    int *label = NULL, *one = NULL;
    char *text = NULL;
    if ((rc = lr_dgrid_create(&shape, c.h, &g, e)) || (rc = lr_dsystem_create(g, c.eta, &sys, e)))
        goto done;
    size_t ng = lr_dgrid_ghost_count(g), np = lr_dgrid_inside_count(g);
    int M = c.n_pat;
    q = calloc((size_t)M * 3 * ng, sizeof *q);
    y = calloc((size_t)M * 3 * ng, sizeof *y);
    seen = calloc((size_t)M * ng, 1);
    pat = calloc((size_t)M, sizeof *pat);
    theta = malloc(2 * np * sizeof *theta);
    vals = malloc(np * sizeof *vals);
    label = malloc(np * sizeof *label);
    one = calloc(np, sizeof *one);
    if (!q || !y || !seen || !pat || !theta || !vals || !label || !one) {
        rc = lr_err_set(e, LR_ENOMEM, "fit --diffusion: out of memory");
        goto done;
    }
    /* Patterns on the ghosts of the top face; observations to their nearest ghost. */
    for (size_t k = 0; k < ng; k++) {
        lr_vec3 b, n;
        size_t u;
        lr_dgrid_ghost_at(g, k, &b, &n, &u);
        for (int m = 0; m < M; m++) {
            bool lit = n.z > 0.9 && fabs(b.z - c.S[2]) <= 1e-9 * (1.0 + c.S[2]) &&
                       b.x >= c.rect[m][0] && b.x <= c.rect[m][2] && b.y >= c.rect[m][1] &&
                       b.y <= c.rect[m][3];
            for (int ch = 0; ch < 3; ch++)
                q[((size_t)m * 3 + ch) * ng + k] = lit ? c.E[m][ch] : 0.0;
        }
    }
    for (size_t i = 0; i < c.n_obs; i++) {
        lr_vec3 p = lr_v3(c.o[i].x, c.o[i].y, c.o[i].z);
        size_t best = 0;
        double bd = INFINITY;
        int m = c.o[i].pattern;
        for (size_t k = 0; k < ng; k++) {
            lr_vec3 b, n;
            size_t u;
            lr_dgrid_ghost_at(g, k, &b, &n, &u);
            double dd = lr_v3_len(lr_v3_sub(b, p));
            /* Ghosts sharing a surface point (a face's depths 0 and h, box edges): the last one
             * this pattern leaves unlit, as a measurement of multiple scattering is (seed 001
             * Sec. 4.1). */
            bool unlit = q[((size_t)m * 3) * ng + k] == 0.0 && q[((size_t)m * 3 + 1) * ng + k] == 0.0 &&
                         q[((size_t)m * 3 + 2) * ng + k] == 0.0;
            if (dd < bd - 1e-9 * c.h || (dd <= bd + 1e-9 * c.h && unlit))
                bd = fmin(bd, dd), best = k;
        }
        if (!(bd <= c.h)) {
            rc = lr_err_set(e, LR_EINVAL,
                            "%s: B at (%g, %g, %g): no boundary point of the sample within h = %g mm",
                            d->captures, p.x, p.y, p.z, c.h);
            goto done;
        }
        seen[(size_t)m * ng + best] = 1;
        for (int ch = 0; ch < 3; ch++)
            y[((size_t)m * 3 + ch) * ng + best] = c.o[i].B[ch];
        res->observations++;
    }
    res->patterns = M;
    res->unknowns_per_band = (int)(2 * np);
    for (int ch = 0; ch < 3; ch++) {
        for (int m = 0; m < M; m++)
            pat[m] = (lr_dinv_pattern){q + ((size_t)m * 3 + ch) * ng, y + ((size_t)m * 3 + ch) * ng,
                                       seen + (size_t)m * ng};
        /* Homogeneous first (seed 001 Sec. 4.2), from plain wax-like values. */
        lr_dinv_desc hd = {.sys = sys, .patterns = pat, .n_patterns = M, .group = one,
                           .n_groups = 1, .tol = 1e-9};
        lr_dinv *v;
        double th[2] = {log(0.3), log(0.01)};
        lr_dinv_report rep;
        if ((rc = lr_dinv_create(&hd, &v, e)))
            goto done;
        rc = lr_dinv_fit(v, th, 60, 1e-14, &rep, e);
        lr_dinv_destroy(v);
        if (rc)
            goto done;
        res->homogeneous_D[ch] = exp(th[0]);
        res->homogeneous_mu[ch] = exp(th[1]);
        res->misfit_homogeneous[ch] = rep.f;
        lr_dinv_desc dd = {.sys = sys, .patterns = pat, .n_patterns = M,
                           .lambda = d->lambda > 0 ? d->lambda : 1e-6, .tol = 1e-9};
        if ((rc = lr_dinv_create(&dd, &v, e)))
            goto done;
        for (size_t p = 0; p < np; p++) {
            theta[p] = th[0];
            theta[np + p] = th[1];
        }
        rc = lr_dinv_fit(v, theta, d->max_iter > 0 ? d->max_iter : 150, 1e-14, &rep, e);
        lr_dinv_destroy(v);
        if (rc)
            goto done;
        res->misfit[ch] = rep.f;
        for (size_t p = 0; p < np; p++) {
            /* D = 1 / (3 (sigma_a + sigma_s')), mu = sigma_a (seed 001 Sec. 3) */
            double Dp = exp(theta[p]), mu = exp(theta[np + p]);
            vals[p][ch] = log(mu);
            vals[p][3 + ch] = log(fmax(1.0 / (3.0 * Dp) - mu, 1e-6));
        }
    }
    double centre[62][6];
    int nr = cluster((const double(*)[6])vals, np, label, centre);
    res->regions = nr;
    /* The volume: cells = inside nodes (a box's inside nodes are a full sub-block). */
    int lo[3] = {1 << 30, 1 << 30, 1 << 30}, hi[3] = {-1, -1, -1}, n[3];
    lr_dgrid_dims(g, n);
    lr_vec3 o = lr_dgrid_origin(g);
    double h = lr_dgrid_h(g);
    for (size_t p = 0; p < np; p++) {
        lr_vec3 x = lr_dgrid_param_pos(g, p);
        int ijk[3] = {(int)lround((x.x - o.x) / h), (int)lround((x.y - o.y) / h),
                      (int)lround((x.z - o.z) / h)};
        for (int a = 0; a < 3; a++) {
            lo[a] = ijk[a] < lo[a] ? ijk[a] : lo[a];
            hi[a] = ijk[a] > hi[a] ? ijk[a] : hi[a];
        }
    }
    int dims[3] = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
    size_t cap = 4096 + (size_t)nr * 160 + (size_t)(dims[0] + 1) * dims[1] * dims[2] + dims[2];
    text = malloc(cap);
    if (!text) {
        rc = lr_err_set(e, LR_ENOMEM, "fit --diffusion: out of memory");
        goto done;
    }
    size_t w = (size_t)snprintf(
        text, cap,
        "# lamprig fit --diffusion %s: %d patterns, %d observations, %zu nodes, %d regions\n"
        "lamprig-volume 1\nbox %.6g %.6g %.6g %.6g %.6g %.6g\ndims %d %d %d\n",
        d->captures, M, res->observations, np, nr, o.x + h * (lo[0] - 0.5), o.y + h * (lo[1] - 0.5),
        o.z + h * (lo[2] - 0.5), o.x + h * (hi[0] + 0.5), o.y + h * (hi[1] + 0.5),
        o.z + h * (hi[2] + 0.5), dims[0], dims[1], dims[2]);
    for (int r = 0; r < nr && w < cap; r++)
        w += (size_t)snprintf(text + w, cap - w,
                              "region %c sigma_a %.6g %.6g %.6g sigma_s_prime %.6g %.6g %.6g\n",
                              region_chars[r], exp(centre[r][0]), exp(centre[r][1]),
                              exp(centre[r][2]), exp(centre[r][3]), exp(centre[r][4]),
                              exp(centre[r][5]));
    w += (size_t)snprintf(text + w, cap - w, "data\n");
    for (int k = lo[2]; k <= hi[2]; k++) {
        for (int j = lo[1]; j <= hi[1]; j++) {
            for (int i = lo[0]; i <= hi[0]; i++) {
                size_t node = ((size_t)k * n[1] + (size_t)j) * n[0] + (size_t)i;
                long p = lr_dgrid_kind(g, node) == LR_DNODE_IN ? lr_dgrid_param(g, node) : 0;
                text[w++] = region_chars[label[p]];
            }
            text[w++] = '\n';
        }
        text[w++] = '\n';
    }
    /* The loader must accept what we write before it replaces anything. */
    lr_dvolume *check;
    text[w] = 0;
    if ((rc = lr_dvolume_parse(text, d->out, &check, e)))
        goto done;
    lr_dvolume_destroy(check);
    rc = lr_atomic_write(d->out, text, w, e);
done:
    free(text);
    free(c.o), free(q), free(y), free(seen), free(pat), free(theta), free(vals), free(label),
        free(one);
    lr_dsystem_destroy(sys);
    lr_dgrid_destroy(g);
    return rc;
}
