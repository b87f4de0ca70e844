/* IES LM-63 photometric files (-2002, -1995, -1991 and the 1986 form without a first line):
 * keyword lines, TILT=NONE or TILT=INCLUDE (TILT=<file> is refused: the data would be in
 * another file), then the numbers:
 *   lamps, lumens per lamp (-1: absolute photometry), candela multiplier, vertical angles,
 *   horizontal angles, photometric type (1 = C; B and A are refused), units, width, length,
 *   height; ballast factor, the 1995 ballast-lamp factor / 2002 "future use", input watts;
 *   the vertical angles, the horizontal angles, then per horizontal angle its candela values.
 * Numbers may share or split lines (the standard lets a writer wrap at 132 characters).
 * The horizontal range gives the symmetry: one angle 0 rotational, 0..90 quadrant, 0..180
 * bilateral, 90..270 bilateral about C90-C270, 0..360 none (LM-63-2002 section 5.11). */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/photometry/luminaire.h"

/* The line of text at t->p (without its end), advancing past it. */
static size_t next_line(lr_lum_text *t, const char **start)
{
    *start = t->p;
    const char *nl = memchr(t->p, '\n', (size_t)(t->end - t->p));
    size_t n = nl ? (size_t)(nl - t->p) : (size_t)(t->end - t->p);
    t->p += n;
    if (nl) {
        t->p++;
        t->line++;
    }
    while (n && (*start)[n - 1] == '\r')
        n--;
    return n;
}

static int fail(const lr_lum_text *t, int line, const char *msg, lr_err *e)
{
    return lr_err_set(e, LR_EPARSE, "%s:%d: %s", t->name, line, msg);
}

/* A count that must be a whole number in [lo, hi]. */
static int count(lr_lum_text *t, const char *what, int lo, int hi, int *out, lr_err *e)
{
    double v;
    int rc = lr_lum_number(t, what, &v, e);
    if (rc)
        return rc;
    if (!(v == floor(v) && v >= lo && v <= hi))
        return lr_err_set(e, LR_EPARSE, "%s:%d: %s must be a whole number in [%d, %d], got %g",
                          t->name, t->line, what, lo, hi, v);
    *out = (int)v;
    return LR_OK;
}

static int numbers(lr_lum_text *t, const char *what, double *a, int n, lr_err *e)
{
    for (int i = 0; i < n; i++) {
        int rc = lr_lum_number(t, what, &a[i], e);
        if (rc)
            return rc;
    }
    return LR_OK;
}

static int parse(lr_lum_text *t, lr_luminaire *l, lr_err *e)
{
    const char *s;
    size_t n = next_line(t, &s);
    /* Skip a UTF-8 byte order mark. */
    if (n >= 3 && memcmp(s, "\xEF\xBB\xBF", 3) == 0) {
        s += 3;
        n -= 3;
    }
    static const struct { const char *head, *format; } heads[] = {
        {"IESNA:LM-63-2002", "LM-63-2002"}, {"IESNA:LM-63-1995", "LM-63-1995"},
        {"IESNA91", "LM-63-1991"}};
    snprintf(l->format, sizeof l->format, "LM-63-1986");
    bool first_is_head = false;
    for (size_t i = 0; i < sizeof heads / sizeof heads[0]; i++)
        if (n >= strlen(heads[i].head) && memcmp(s, heads[i].head, strlen(heads[i].head)) == 0) {
            snprintf(l->format, sizeof l->format, "%s", heads[i].format);
            first_is_head = true;
        }
    if (n >= 5 && memcmp(s, "IESNA", 5) == 0 && !first_is_head)
        return fail(t, t->line - 1, "unknown IESNA header (expected IESNA:LM-63-2002, "
                    "IESNA:LM-63-1995 or IESNA91)", e);
    /* Keyword lines ([TEST] ...) until TILT=; the 1986 form has free text lines instead. */
    int line = first_is_head ? t->line : t->line - 1;
    if (!first_is_head)
        t->p = s, t->line = line;
    for (;;) {
        if (t->p >= t->end)
            return fail(t, t->line, "no TILT= line", e);
        line = t->line;
        n = next_line(t, &s);
        if (n >= 5 && memcmp(s, "TILT=", 5) == 0) {
            const char *v = s + 5;
            size_t vn = n - 5;
            while (vn && (v[vn - 1] == ' ' || v[vn - 1] == '\t'))
                vn--;
            if (vn == 4 && memcmp(v, "NONE", 4) == 0)
                break;
            if (vn == 7 && memcmp(v, "INCLUDE", 7) == 0) {
                int rc, geom, nt;
                double g;
                if ((rc = lr_lum_number(t, "the lamp-to-luminaire geometry", &g, e)))
                    return rc;
                geom = (int)g;
                if (!(g == geom && geom >= 1 && geom <= 3))
                    return fail(t, t->line, "lamp-to-luminaire geometry must be 1, 2 or 3", e);
                if ((rc = count(t, "the number of tilt angles", 1, LR_LUM_MAX_ANGLES, &nt, e)))
                    return rc;
                l->n_tilt = nt;
                l->tilt_deg = calloc((size_t)nt, sizeof *l->tilt_deg);
                l->tilt_factor = calloc((size_t)nt, sizeof *l->tilt_factor);
                if (!l->tilt_deg || !l->tilt_factor)
                    return lr_err_set(e, LR_ENOMEM, "out of memory");
                int at = lr_lum_skip(t);
                if ((rc = numbers(t, "a tilt angle", l->tilt_deg, nt, e)))
                    return rc;
                if ((rc = lr_lum_angles(t, at, "tilt", l->tilt_deg, nt, 0.0, 180.0, e)))
                    return rc;
                if ((rc = numbers(t, "a tilt multiplying factor", l->tilt_factor, nt, e)))
                    return rc;
                for (int i = 0; i < nt; i++)
                    if (!(l->tilt_factor[i] >= 0.0))
                        return fail(t, t->line, "a tilt multiplying factor is negative", e);
                break;
            }
            return fail(t, line, "TILT= must be NONE or INCLUDE (tilt data in another file is "
                        "not read)", e);
        }
        if (first_is_head && n && s[0] != '[' && strcmp(l->format, "LM-63-2002") == 0)
            return fail(t, line, "expected a [KEYWORD] line or TILT=", e);
    }
    int rc, lamps, nv, nh, type, units;
    double lm, mult, dim[3], ballast, future, watts;
    if ((rc = count(t, "the number of lamps", 1, 1000, &lamps, e)) ||
        (rc = lr_lum_number(t, "the lumens per lamp", &lm, e)))
        return rc;
    if (!(lm > 0.0 || lm == -1.0))
        return fail(t, t->line, "lumens per lamp must be > 0 or -1 (absolute photometry)", e);
    if ((rc = lr_lum_number(t, "the candela multiplier", &mult, e)))
        return rc;
    if (!(mult > 0.0))
        return fail(t, t->line, "the candela multiplier must be > 0", e);
    if ((rc = count(t, "the number of vertical angles", 1, LR_LUM_MAX_ANGLES, &nv, e)) ||
        (rc = count(t, "the number of horizontal angles", 1, LR_LUM_MAX_ANGLES, &nh, e)))
        return rc;
    if ((size_t)nv * (size_t)nh > LR_LUM_MAX_VALUES)
        return fail(t, t->line, "too many candela values (at most 400000)", e);
    if ((rc = count(t, "the photometric type", 1, 3, &type, e)))
        return rc;
    if (type != 1)
        return fail(t, t->line, "photometric type B or A (2, 3): only type C (1) is read", e);
    if ((rc = count(t, "the units type", 1, 2, &units, e)) ||
        (rc = numbers(t, "a luminous opening dimension", dim, 3, e)) ||
        (rc = lr_lum_number(t, "the ballast factor", &ballast, e)) ||
        (rc = lr_lum_number(t, "the ballast-lamp factor / future use", &future, e)) ||
        (rc = lr_lum_number(t, "the input watts", &watts, e)))
        return rc;
    if (!(ballast > 0.0))
        return fail(t, t->line, "the ballast factor must be > 0", e);
    l->n_v = nv;
    l->n_h = nh;
    if ((rc = lr_lum_alloc(l, e)))
        return rc;
    int at = lr_lum_skip(t);
    if ((rc = numbers(t, "a vertical angle", l->v_deg, nv, e)) ||
        (rc = lr_lum_angles(t, at, "vertical", l->v_deg, nv, 0.0, 180.0, e)))
        return rc;
    /* Type C: 0..90, 0..180 or 90..180 (a luminaire lighting down, all round, or up). */
    if (!(l->v_deg[0] == 0.0 || l->v_deg[0] == 90.0) ||
        !(l->v_deg[nv - 1] == 90.0 || l->v_deg[nv - 1] == 180.0) || nv < 2)
        return fail(t, at, "type C vertical angles must run 0..90, 0..180 or 90..180", e);
    at = lr_lum_skip(t);
    if ((rc = numbers(t, "a horizontal angle", l->h_deg, nh, e)) ||
        (rc = lr_lum_angles(t, at, "horizontal", l->h_deg, nh, 0.0, 360.0, e)))
        return rc;
    double h0 = l->h_deg[0], h1 = l->h_deg[nh - 1];
    if (nh == 1 && h0 == 0.0)
        l->sym = LR_LUM_SYM_ROTATIONAL;
    else if (h0 == 0.0 && h1 == 90.0)
        l->sym = LR_LUM_SYM_QUADRANT;
    else if (h0 == 0.0 && h1 == 180.0)
        l->sym = LR_LUM_SYM_BILATERAL;
    else if (h0 == 90.0 && h1 == 270.0)
        l->sym = LR_LUM_SYM_BILATERAL90;
    else if (h0 == 0.0 && h1 == 360.0)
        l->sym = LR_LUM_SYM_NONE;
    else
        return fail(t, at, "horizontal angles must be 0, 0..90, 0..180, 90..270 or 0..360", e);
    for (int j = 0; j < nh; j++)
        for (int i = 0; i < nv; i++) {
            double v;
            if ((rc = lr_lum_number(t, "a candela value", &v, e)))
                return rc;
            if (!(v >= 0.0))
                return lr_err_set(e, LR_EPARSE, "%s:%d: candela value %g at horizontal %g, "
                                  "vertical %g is negative", t->name, t->line, v, l->h_deg[j],
                                  l->v_deg[i]);
            l->cd[(size_t)j * nv + i] = v * mult * ballast;
        }
    /* A full circle's last plane repeats the first: both are data, and must agree. */
    if (l->sym == LR_LUM_SYM_NONE)
        for (int i = 0; i < nv; i++)
            if (fabs(l->cd[(size_t)(nh - 1) * nv + i] - l->cd[i]) >
                1e-6 * fmax(l->cd[i], 1.0))
                return fail(t, t->line, "the 360-degree plane differs from the 0-degree one", e);
    double extra;
    lr_err ignore = {0};
    if (lr_lum_number(t, "", &extra, &ignore) == LR_OK)
        return fail(t, t->line, "numbers after the last candela value (counts wrong?)", e);
    l->lumens = lm > 0.0 ? lamps * lm : 0.0;
    return LR_OK;
}

int lr_ies_parse(const char *text, size_t len, const char *name, lr_luminaire *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    lr_lum_text t = {text, text + len, name, 1};
    int rc = parse(&t, out, e);
    if (rc)
        lr_luminaire_free(out);
    return rc;
}
