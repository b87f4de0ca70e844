/* Intensity lookup, flux and the number reader shared by the parsers (luminaire.h). */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "render/photometry/luminaire.h"

void lr_luminaire_free(lr_luminaire *l)
{
    if (!l)
        return;
    free(l->v_deg);
    free(l->h_deg);
    free(l->cd);
    free(l->tilt_deg);
    free(l->tilt_factor);
    memset(l, 0, sizeof *l);
}

int lr_lum_alloc(lr_luminaire *l, lr_err *e)
{
    l->v_deg = calloc((size_t)l->n_v, sizeof *l->v_deg);
    l->h_deg = calloc((size_t)l->n_h, sizeof *l->h_deg);
    l->cd = calloc((size_t)l->n_v * (size_t)l->n_h, sizeof *l->cd);
    if (!l->v_deg || !l->h_deg || !l->cd)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    return LR_OK;
}

int lr_lum_skip(lr_lum_text *t)
{
    while (t->p < t->end && (isspace((unsigned char)*t->p) || *t->p == ',')) {
        if (*t->p == '\n')
            t->line++;
        t->p++;
    }
    return t->line;
}

int lr_lum_number(lr_lum_text *t, const char *what, double *v, lr_err *e)
{
    lr_lum_skip(t);
    if (t->p >= t->end)
        return lr_err_set(e, LR_EPARSE, "%s:%d: expected %s, got the end of the file", t->name,
                          t->line, what);
    char tok[64];
    size_t n = 0;
    while (t->p + n < t->end && !isspace((unsigned char)t->p[n]) && t->p[n] != ',' &&
           n < sizeof tok - 1) {
        tok[n] = t->p[n];
        n++;
    }
    tok[n] = '\0';
    char *endp;
    errno = 0;
    double x = strtod(tok, &endp);
    if (endp == tok || *endp != '\0' || !isfinite(x) || errno == ERANGE)
        return lr_err_set(e, LR_EPARSE, "%s:%d: expected %s, got '%.24s'", t->name, t->line,
                          what, tok);
    t->p += n;
    *v = x;
    return LR_OK;
}

int lr_lum_angles(const lr_lum_text *t, int line, const char *what, const double *a, int n,
                  double lo, double hi, lr_err *e)
{
    for (int i = 0; i < n; i++) {
        if (!(a[i] >= lo && a[i] <= hi))
            return lr_err_set(e, LR_EPARSE, "%s:%d: %s angle %d is %g, outside [%g, %g]",
                              t->name, line, what, i + 1, a[i], lo, hi);
        if (i && !(a[i] > a[i - 1]))
            return lr_err_set(e, LR_EPARSE, "%s:%d: %s angles must increase: %g after %g",
                              t->name, line, what, a[i], a[i - 1]);
    }
    return LR_OK;
}

/* The stored plane angle that C plane h (degrees, any) shows, by the symmetry. */
static double fold(const lr_luminaire *l, double h)
{
    h = fmod(h, 360.0);
    if (h < 0.0)
        h += 360.0;
    switch (l->sym) {
    case LR_LUM_SYM_ROTATIONAL: return l->h_deg[0];
    case LR_LUM_SYM_QUADRANT:
        if (h > 180.0)
            h = 360.0 - h;
        return h > 90.0 ? 180.0 - h : h;
    case LR_LUM_SYM_BILATERAL: return h > 180.0 ? 360.0 - h : h;
    case LR_LUM_SYM_BILATERAL90:
        if (h < 90.0)
            return 180.0 - h;
        return h > 270.0 ? 540.0 - h : h;
    case LR_LUM_SYM_NONE: return h;
    }
    return h;
}

/* Index i and weight t of x between a[i] and a[i + 1] (clamped to the ends); *out: outside. */
static int bracket(const double *a, int n, double x, double *t, bool *out)
{
    *out = x < a[0] || x > a[n - 1];
    if (n == 1 || x <= a[0]) {
        *t = 0.0;
        return 0;
    }
    if (x >= a[n - 1]) {
        *t = 1.0;
        return n - 2;
    }
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        int m = (lo + hi) / 2;
        if (a[m] <= x)
            lo = m;
        else
            hi = m;
    }
    *t = (x - a[lo]) / (a[lo + 1] - a[lo]);
    return lo;
}

double lr_luminaire_cd(const lr_luminaire *l, double h_deg, double v_deg)
{
    if (!(v_deg >= l->v_deg[0] && v_deg <= l->v_deg[l->n_v - 1]))
        return 0.0;
    double tv, th;
    bool out;
    int iv = bracket(l->v_deg, l->n_v, v_deg, &tv, &out);
    int jv = l->n_v > 1 ? iv + 1 : iv;
    double h = fold(l, h_deg);
    int ih = 0, jh = 0;
    th = 0.0;
    if (l->n_h > 1) {
        if (l->sym == LR_LUM_SYM_NONE && h > l->h_deg[l->n_h - 1]) {
            /* Between the last plane and 360 (= the first): wrap. */
            ih = l->n_h - 1;
            jh = 0;
            th = (h - l->h_deg[ih]) / (360.0 + l->h_deg[0] - l->h_deg[ih]);
        } else {
            ih = bracket(l->h_deg, l->n_h, h, &th, &out);
            jh = ih + 1;
        }
    }
    const double *a = l->cd + (size_t)ih * l->n_v, *b = l->cd + (size_t)jh * l->n_v;
    double va = a[iv] + (a[jv] - a[iv]) * tv, vb = b[iv] + (b[jv] - b[iv]) * tv;
    return va + (vb - va) * th;
}

double lr_luminaire_flux(const lr_luminaire *l)
{
    /* Midpoint rule over gamma (0.25 deg) and C (1 deg); dOmega = sin(gamma) dgamma dC. */
    const int nv = 720, nh = l->sym == LR_LUM_SYM_ROTATIONAL ? 1 : 360;
    double dv = M_PI / nv, dh = 2.0 * M_PI / nh, sum = 0.0;
    for (int j = 0; j < nh; j++) {
        double h = (j + 0.5) * 360.0 / nh;
        for (int i = 0; i < nv; i++) {
            double g = (i + 0.5) * dv;
            sum += lr_luminaire_cd(l, h, g * (180.0 / M_PI)) * sin(g);
        }
    }
    return sum * dv * dh;
}

double lr_luminaire_max_cd(const lr_luminaire *l)
{
    double m = 0.0;
    for (size_t i = 0; i < (size_t)l->n_v * (size_t)l->n_h; i++)
        if (l->cd[i] > m)
            m = l->cd[i];
    return m;
}
