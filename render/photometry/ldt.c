/* EULUMDAT (.ldt) photometric files: one item per line, in this order (the format's line
 * numbers):
 *   1 company; 2 Ityp (0-3); 3 Isym (0 none, 1 about the vertical axis, 2 C0-C180 plane,
 *   3 C90-C270 plane, 4 both); 4 Mc, C planes in 0..360; 5 Dc; 6 Ng, intensities per plane;
 *   7 Dg; 8-12 report number, luminaire name and number, file name, date / user;
 *   13-21 luminaire and luminous-area dimensions (mm); 22 downward flux fraction (%);
 *   23 light output ratio LORL (%); 24 conversion factor for the intensities; 25 tilt during
 *   measurement; 26 n, sets of lamps; then n lines each of 26a number of lamps, 26b type,
 *   26c total flux (lm), 26d colour, 26e colour rendering, 26f wattage; 27 ten direct
 *   ratios; 28 the Mc C angles; 29 the Ng gamma angles; 30 the intensities in cd per 1000 lm
 *   of lamp flux, plane by plane, for the planes Isym keeps (all Mc; one; C0..C180;
 *   C90..C270; C0..C90).
 * Intensities become candela with set 1's flux x the conversion factor / 1000; the luminaire's
 * flux is that flux x LORL. */
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/photometry/luminaire.h"

/* The next line as text (trimmed); "NAME:LINE: ... missing" at the end. */
static int text_line(lr_lum_text *t, const char *what, char *buf, size_t cap, lr_err *e)
{
    if (t->p >= t->end)
        return lr_err_set(e, LR_EPARSE, "%s:%d: expected %s, got the end of the file", t->name,
                          t->line, what);
    const char *nl = memchr(t->p, '\n', (size_t)(t->end - t->p));
    size_t n = nl ? (size_t)(nl - t->p) : (size_t)(t->end - t->p);
    const char *s = t->p;
    t->p += n + (nl ? 1 : 0);
    while (n && (s[n - 1] == '\r' || s[n - 1] == ' ' || s[n - 1] == '\t'))
        n--;
    while (n && (*s == ' ' || *s == '\t'))
        s++, n--;
    if (n >= cap)
        n = cap - 1;
    memcpy(buf, s, n);
    buf[n] = '\0';
    t->line++;
    return LR_OK;
}

/* A line holding one number. */
static int num_line(lr_lum_text *t, const char *what, double *v, lr_err *e)
{
    char buf[96];
    int line = t->line, rc = text_line(t, what, buf, sizeof buf, e);
    if (rc)
        return rc;
    lr_lum_text one = {buf, buf + strlen(buf), t->name, line};
    if ((rc = lr_lum_number(&one, what, v, e)))
        return rc;
    double extra;
    lr_err ignore = {0};
    if (lr_lum_number(&one, what, &extra, &ignore) == LR_OK)
        return lr_err_set(e, LR_EPARSE, "%s:%d: expected only %s on the line, got '%.40s'",
                          t->name, line, what, buf);
    return LR_OK;
}

static int int_line(lr_lum_text *t, const char *what, int lo, int hi, int *out, lr_err *e)
{
    double v;
    int line = t->line, rc = num_line(t, what, &v, e);
    if (rc)
        return rc;
    if (!(v == floor(v) && v >= lo && v <= hi))
        return lr_err_set(e, LR_EPARSE, "%s:%d: %s must be a whole number in [%d, %d], got %g",
                          t->name, line, what, lo, hi, v);
    *out = (int)v;
    return LR_OK;
}

static int parse(lr_lum_text *t, lr_luminaire *l, lr_err *e)
{
    char buf[96];
    int rc, ityp, isym, mc, ng, nsets;
    double v;
    snprintf(l->format, sizeof l->format, "EULUMDAT");
    if ((rc = text_line(t, "the company line", buf, sizeof buf, e)) ||
        (rc = int_line(t, "Ityp (type indicator)", 0, 3, &ityp, e)) ||
        (rc = int_line(t, "Isym (symmetry indicator)", 0, 4, &isym, e)))
        return rc;
    int mc_line = t->line;
    if ((rc = int_line(t, "Mc (number of C planes)", 1, 721, &mc, e)) ||
        (rc = num_line(t, "Dc (C plane step)", &v, e)) ||
        (rc = int_line(t, "Ng (intensities per C plane)", 2, LR_LUM_MAX_ANGLES, &ng, e)) ||
        (rc = num_line(t, "Dg (gamma step)", &v, e)))
        return rc;
    /* The planes the symmetry keeps: their count and first index among the Mc. */
    int keep = mc, first = 0;
    enum lr_lum_symmetry sym = LR_LUM_SYM_NONE;
    if (isym == 1) {
        keep = 1;
        sym = LR_LUM_SYM_ROTATIONAL;
    } else if (isym == 2 || isym == 3) {
        if (mc % 2)
            return lr_err_set(e, LR_EPARSE, "%s:%d: Isym %d needs an even Mc, got %d", t->name,
                              mc_line, isym, mc);
        if (isym == 3 && mc % 4)
            return lr_err_set(e, LR_EPARSE, "%s:%d: Isym 3 needs Mc a multiple of 4, got %d",
                              t->name, mc_line, mc);
        keep = mc / 2 + 1;
        first = isym == 3 ? mc / 4 : 0;
        sym = isym == 2 ? LR_LUM_SYM_BILATERAL : LR_LUM_SYM_BILATERAL90;
    } else if (isym == 4) {
        if (mc % 4)
            return lr_err_set(e, LR_EPARSE, "%s:%d: Isym 4 needs Mc a multiple of 4, got %d",
                              t->name, mc_line, mc);
        keep = mc / 4 + 1;
        sym = LR_LUM_SYM_QUADRANT;
    }
    if ((size_t)keep * (size_t)ng > LR_LUM_MAX_VALUES)
        return lr_err_set(e, LR_EPARSE, "%s:%d: too many intensities (at most 400000)", t->name,
                          mc_line);
    static const char *const texts[] = {"the measurement report number", "the luminaire name",
                                        "the luminaire number", "the file name",
                                        "the date / user"};
    for (int i = 0; i < 5; i++)
        if ((rc = text_line(t, texts[i], buf, sizeof buf, e)))
            return rc;
    for (int i = 0; i < 9; i++)
        if ((rc = num_line(t, "a luminaire dimension (mm)", &v, e)))
            return rc;
    double dff, lorl, conv, tilt;
    int lorl_line;
    if ((rc = num_line(t, "DFF (downward flux fraction, %)", &dff, e)))
        return rc;
    lorl_line = t->line;
    if ((rc = num_line(t, "LORL (light output ratio, %)", &lorl, e)))
        return rc;
    if (!(lorl > 0.0 && lorl <= 100.0))
        return lr_err_set(e, LR_EPARSE, "%s:%d: LORL must be in (0, 100] %%, got %g", t->name,
                          lorl_line, lorl);
    int conv_line = t->line;
    if ((rc = num_line(t, "the intensities' conversion factor", &conv, e)))
        return rc;
    if (!(conv > 0.0))
        return lr_err_set(e, LR_EPARSE, "%s:%d: the conversion factor must be > 0, got %g",
                          t->name, conv_line, conv);
    if ((rc = num_line(t, "the tilt during measurement", &tilt, e)) ||
        (rc = int_line(t, "n (sets of lamps)", 1, 20, &nsets, e)))
        return rc;
    int lamps = 0;
    double flux = 0.0;
    for (int k = 0; k < 6; k++)
        for (int i = 0; i < nsets; i++) {
            int line = t->line;
            if (k == 0) {
                int nl;
                if ((rc = int_line(t, "the number of lamps", -1000, 1000, &nl, e)))
                    return rc;
                if (nl <= 0)
                    return lr_err_set(e, LR_EPARSE, "%s:%d: the number of lamps must be >= 1 "
                                      "(a negative count, absolute photometry, is not read), "
                                      "got %d", t->name, line, nl);
                if (i == 0)
                    lamps = nl;
            } else if (k == 2 || k == 5) {
                if ((rc = num_line(t, k == 2 ? "the lamps' total flux (lm)" : "the wattage",
                                   &v, e)))
                    return rc;
                if (k == 2 && !(v > 0.0))
                    return lr_err_set(e, LR_EPARSE, "%s:%d: the lamps' flux must be > 0 lm, "
                                      "got %g", t->name, line, v);
                if (k == 2 && i == 0)
                    flux = v;
            } else if ((rc = text_line(t, "a lamp description", buf, sizeof buf, e))) {
                return rc;
            }
        }
    (void)lamps;
    for (int i = 0; i < 10; i++)
        if ((rc = num_line(t, "a direct ratio", &v, e)))
            return rc;
    l->n_v = ng;
    l->n_h = keep;
    l->sym = sym;
    if ((rc = lr_lum_alloc(l, e)))
        return rc;
    int c_line = t->line;
    for (int i = 0; i < mc; i++) {
        if ((rc = num_line(t, "a C angle", &v, e)))
            return rc;
        if (i >= first && i < first + keep)
            l->h_deg[i - first] = v;
        if (isym == 0 && i == 0 && v != 0.0)
            return lr_err_set(e, LR_EPARSE, "%s:%d: the first C angle must be 0, got %g",
                              t->name, c_line, v);
    }
    if ((rc = lr_lum_angles(t, c_line, "C", l->h_deg, keep, 0.0, isym == 0 ? 359.999 : 360.0,
                            e)))
        return rc;
    static const double want[5][2] = {{0, 0}, {0, 0}, {0, 180}, {90, 270}, {0, 90}};
    if (isym >= 2 && !(l->h_deg[0] == want[isym][0] && l->h_deg[keep - 1] == want[isym][1]))
        return lr_err_set(e, LR_EPARSE, "%s:%d: Isym %d keeps the planes C%g..C%g, but those C "
                          "angles are %g..%g", t->name, c_line, isym, want[isym][0],
                          want[isym][1], l->h_deg[0], l->h_deg[keep - 1]);
    if (isym == 1)
        l->h_deg[0] = 0.0;
    int g_line = t->line;
    for (int i = 0; i < ng; i++)
        if ((rc = num_line(t, "a gamma angle", &l->v_deg[i], e)))
            return rc;
    if ((rc = lr_lum_angles(t, g_line, "gamma", l->v_deg, ng, 0.0, 180.0, e)))
        return rc;
    double scale = flux * conv / 1000.0;
    for (int j = 0; j < keep; j++)
        for (int i = 0; i < ng; i++) {
            int line = t->line;
            if ((rc = num_line(t, "an intensity (cd/klm)", &v, e)))
                return rc;
            if (!(v >= 0.0))
                return lr_err_set(e, LR_EPARSE, "%s:%d: intensity %g at C%g, gamma %g is "
                                  "negative", t->name, line, v, l->h_deg[j], l->v_deg[i]);
            l->cd[(size_t)j * ng + i] = v * scale;
        }
    /* Blank lines may close the file; anything else means the counts were wrong. */
    while (t->p < t->end) {
        int line = t->line;
        if ((rc = text_line(t, "", buf, sizeof buf, e)))
            return rc;
        if (buf[0] && !(buf[0] == '\x1a' && !buf[1]))
            return lr_err_set(e, LR_EPARSE, "%s:%d: text after the last intensity (counts "
                              "wrong?): '%.40s'", t->name, line, buf);
    }
    l->lumens = flux * lorl / 100.0;
    return LR_OK;
}

int lr_ldt_parse(const char *text, size_t len, const char *name, lr_luminaire *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    lr_lum_text t = {text, text + len, name, 1};
    int rc = parse(&t, out, e);
    if (rc)
        lr_luminaire_free(out);
    return rc;
}
