#include "calib/colormatrix.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/calfile.h"
#include "calib/cv_shim.h"

/* X-Rite ColorChecker Classic as 8-bit sRGB (D65), the values X-Rite publishes (tabulated
 * in Wikipedia's ColorChecker article), in reading order: dark skin, light skin, blue sky,
 * foliage, blue flower, bluish green / orange ... yellow / blue ... cyan / white ... black. */
static const unsigned char checker_srgb8[72] = {
    115, 82,  68,  194, 150, 130, 98,  122, 157, 87,  108, 67,  133, 128, 177, 103, 189, 170,
    214, 126, 44,  80,  91,  166, 193, 90,  99,  94,  60,  108, 157, 188, 64,  224, 163, 46,
    56,  61,  150, 70,  148, 73,  175, 54,  60,  231, 199, 31,  187, 86,  149, 8,   133, 161,
    243, 243, 242, 200, 200, 200, 160, 160, 160, 122, 122, 121, 85,  85,  85,  52,  52,  52};

const unsigned char *lr_colorchecker_srgb8(void) { return checker_srgb8; }

double lr_srgb_to_linear(double v)
{
    /* IEC 61966-2-1. */
    return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4);
}

void lr_colorchecker_linear(double out[72])
{
    for (int i = 0; i < 72; i++)
        out[i] = lr_srgb_to_linear(checker_srgb8[i] / 255.0);
}

/* Solves the 3x3 system A x = b (Gaussian elimination, partial pivoting). Returns the
 * smallest pivot relative to the largest |A| entry, 0 for a singular A. */
static double solve3(double A[9], double b[3], double x[3])
{
    double scale = 0;
    for (int i = 0; i < 9; i++)
        scale = fmax(scale, fabs(A[i]));
    if (!(scale > 0))
        return 0;
    double minpiv = INFINITY;
    int perm[3] = {0, 1, 2};
    for (int col = 0; col < 3; col++) {
        int best = col;
        for (int r = col + 1; r < 3; r++)
            if (fabs(A[3 * perm[r] + col]) > fabs(A[3 * perm[best] + col]))
                best = r;
        int t = perm[col];
        perm[col] = perm[best];
        perm[best] = t;
        double piv = A[3 * perm[col] + col];
        minpiv = fmin(minpiv, fabs(piv) / scale);
        if (!(fabs(piv) > 0))
            return 0;
        for (int r = col + 1; r < 3; r++) {
            double f = A[3 * perm[r] + col] / piv;
            for (int k = col; k < 3; k++)
                A[3 * perm[r] + k] -= f * A[3 * perm[col] + k];
            b[perm[r]] -= f * b[perm[col]];
        }
    }
    for (int col = 2; col >= 0; col--) {
        double s = b[perm[col]];
        for (int k = col + 1; k < 3; k++)
            s -= A[3 * perm[col] + k] * x[k];
        x[col] = s / A[3 * perm[col] + col];
    }
    return minpiv;
}

int lr_colormatrix_fit(const double *cam, const double *ref, int n, lr_colormatrix *out,
                       lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (n < 3)
        return lr_err_set(e, LR_EINVAL, "colour matrix: %d patches (need at least 3)", n);
    for (int i = 0; i < 3 * n; i++)
        if (!isfinite(cam[i]) || !isfinite(ref[i]))
            return lr_err_set(e, LR_EINVAL, "colour matrix: patch %d has a non-finite value",
                              i / 3);
    /* Normal equations (C^T C) m_row = C^T r_col for each output channel. */
    double ctc[9] = {0}, ctr[9] = {0};
    for (int i = 0; i < n; i++)
        for (int a = 0; a < 3; a++) {
            for (int b = 0; b < 3; b++)
                ctc[3 * a + b] += cam[3 * i + a] * cam[3 * i + b];
            for (int o = 0; o < 3; o++)
                ctr[3 * a + o] += cam[3 * i + a] * ref[3 * i + o];
        }
    for (int o = 0; o < 3; o++) {
        double A[9], b[3] = {ctr[o], ctr[3 + o], ctr[6 + o]}, x[3];
        memcpy(A, ctc, sizeof A);
        /* C^T C has the squared condition number of C: 1e-10 relative pivots mean the
         * patches span less than three colour directions to ~1e-5, i.e. not at all. */
        if (solve3(A, b, x) < 1e-10)
            return lr_err_set(e, LR_EINVAL,
                              "colour matrix: the %d patches do not span three colour directions "
                              "(all grey or collinear colours)",
                              n);
        for (int k = 0; k < 3; k++)
            out->m[3 * o + k] = x[k];
    }
    double ss = 0;
    for (int i = 0; i < n; i++) {
        double p[3], d2 = 0;
        lr_colormatrix_apply(out, cam + 3 * i, p);
        for (int k = 0; k < 3; k++)
            d2 += (p[k] - ref[3 * i + k]) * (p[k] - ref[3 * i + k]);
        ss += d2;
        out->max_err = fmax(out->max_err, sqrt(d2));
    }
    out->rms = sqrt(ss / n);
    out->patches = n;
    snprintf(out->source, sizeof out->source, "pairs");
    return LR_OK;
}

void lr_colormatrix_apply(const lr_colormatrix *m, const double in[3], double out[3])
{
    for (int r = 0; r < 3; r++)
        out[r] = m->m[3 * r] * in[0] + m->m[3 * r + 1] * in[1] + m->m[3 * r + 2] * in[2];
}

int lr_colorchecker_measure(const lr_img *photo, const lr_camresp *cam, double out[72],
                            lr_err *e)
{
    double enc[72];
    int rc = lr_cv_detect_colorchecker(photo, enc, e);
    if (rc)
        return rc;
    for (int i = 0; i < 72; i++)
        out[i] = cam ? lr_camresp_linear(cam, i % 3, enc[i] * 255.0) : lr_srgb_to_linear(enc[i]);
    return LR_OK;
}

int lr_colorpairs_load(const char *path, double **cam, double **ref, int *n, lr_err *e)
{
    *cam = *ref = NULL;
    *n = 0;
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, "color_pairs", &j, &root, e);
    if (rc)
        return rc;
    lr_jnode pairs;
    int count;
    double *c = NULL, *r = NULL;
    if ((rc = lr_calfile_array(j, root, NULL, "pairs", &pairs, &count, e)))
        goto out;
    c = malloc(sizeof *c * 3 * (size_t)(count ? count : 1));
    r = malloc(sizeof *r * 3 * (size_t)(count ? count : 1));
    if (!c || !r) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto out;
    }
    for (int i = 0; i < count; i++) {
        char where[32];
        snprintf(where, sizeof where, "pairs[%d]", i);
        lr_jnode p = lr_json_at(j, pairs, i);
        if ((rc = lr_calfile_numbers(j, p, where, "camera", 3, -1e6, 1e6, c + 3 * i, e)) ||
            (rc = lr_calfile_numbers(j, p, where, "reference", 3, -1e6, 1e6, r + 3 * i, e)))
            goto out;
    }
    *cam = c;
    *ref = r;
    *n = count;
    c = r = NULL;
out:
    free(c);
    free(r);
    lr_json_destroy(j);
    return rc;
}

/* ---- file ----------------------------------------------------------------------------- */

static void fill(lr_jw *w, const void *obj)
{
    const lr_colormatrix *m = obj;
    lr_jw_matrix(w, "matrix", m->m, 3, 3);
    lr_jw_number(w, "rms", m->rms);
    lr_jw_number(w, "max_error", m->max_err);
    lr_jw_int(w, "patches", m->patches);
    lr_jw_string(w, "source", m->source);
}

static int from_json(const lr_json *j, lr_jnode root, lr_colormatrix *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    static const char *const keys[] = {"version", "kind", "matrix", "rms", "max_error",
                                       "patches", "source", NULL};
    int rc = lr_json_check_keys(j, root, "colour matrix", keys, e);
    if (rc)
        return rc;
    long patches;
    if ((rc = lr_calfile_matrix(j, root, NULL, "matrix", 3, 3, -100, 100, out->m, e)) ||
        (rc = lr_calfile_number(j, root, NULL, "rms", 0, 1e6, &out->rms, e)) ||
        (rc = lr_calfile_number(j, root, NULL, "max_error", 0, 1e6, &out->max_err, e)) ||
        (rc = lr_calfile_int(j, root, NULL, "patches", 3, 100000, &patches, e)) ||
        (rc = lr_json_get_string(j, root, "source", true, out->source, sizeof out->source, e)))
        return rc;
    out->patches = (int)patches;
    const double *m = out->m;
    double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                 m[2] * (m[3] * m[7] - m[4] * m[6]);
    if (!(fabs(det) > 1e-9))
        return lr_json_fail(j, lr_json_get(j, root, "matrix"), "matrix", e, LR_EINVAL,
                            "singular (determinant %g): it would lose colours", det);
    return LR_OK;
}

static int check(const lr_json *j, lr_jnode root, lr_err *e)
{
    lr_colormatrix tmp;
    return from_json(j, root, &tmp, e);
}

int lr_colormatrix_save(const char *path, const lr_colormatrix *m, lr_err *e)
{
    return lr_calfile_save(path, LR_COLORMATRIX_KIND, fill, m, check, e);
}

int lr_colormatrix_load(const char *path, lr_colormatrix *out, lr_err *e)
{
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_COLORMATRIX_KIND, &j, &root, e);
    if (rc)
        return rc;
    rc = from_json(j, root, out, e);
    lr_json_destroy(j);
    return rc;
}
