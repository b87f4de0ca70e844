#include "calib/camresp.h"

#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "calib/calfile.h"
#include "calib/cv_shim.h"
#include "calib/isotonic.h"

static int check_stack(const lr_img *images, const double *times, int n, lr_err *e)
{
    if (n < 2)
        return lr_err_set(e, LR_EINVAL, "an exposure stack needs at least 2 images, got %d", n);
    for (int i = 0; i < n; i++) {
        if (images[i].channels != 3 || images[i].depth != 1)
            return lr_err_set(e, LR_EINVAL, "exposure %d: need an 8-bit RGB image", i);
        if (images[i].w != images[0].w || images[i].h != images[0].h)
            return lr_err_set(e, LR_EINVAL, "exposure %d: %dx%d, the first is %dx%d", i,
                              images[i].w, images[i].h, images[0].w, images[0].h);
        if (!(times[i] > 0 && isfinite(times[i])))
            return lr_err_set(e, LR_EINVAL, "exposure %d: time %g s must be > 0", i, times[i]);
        for (int j = 0; j < i; j++)
            if (times[j] == times[i])
                return lr_err_set(e, LR_EINVAL, "exposures %d and %d have the same time %g s", j,
                                  i, times[i]);
    }
    return LR_OK;
}

int lr_camresp_fit(const lr_camresp_desc *d, lr_camresp *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    int rc = check_stack(d->images, d->times, d->n, e);
    if (rc)
        return rc;
    int samples = d->samples > 0 ? d->samples : 70;
    double lambda = d->lambda > 0 ? d->lambda : 10.0;
    double resp[3 * 256];
    if ((rc = lr_cv_debevec_response(d->images, d->times, d->n, samples, lambda, resp, e)))
        return rc;
    for (int c = 0; c < 3; c++) {
        double *curve = out->curve[c];
        for (int z = 0; z < 256; z++) {
            curve[z] = resp[c * 256 + z];
            if (!(curve[z] > 0 && isfinite(curve[z])))
                return lr_err_set(e, LR_EINVAL,
                                  "Debevec response channel %d value %d is %g (too few "
                                  "well-exposed samples? use more exposures or a busier scene)",
                                  c, z, curve[z]);
        }
        /* Monotone in log exposure (where Debevec fits), then renormalised at 128. */
        double lg[256];
        for (int z = 0; z < 256; z++)
            lg[z] = log(curve[z]);
        if ((rc = lr_isotonic(lg, NULL, 256, e)))
            return rc;
        double ref = lg[128];
        for (int z = 0; z < 256; z++)
            curve[z] = exp(lg[z] - ref);
    }
    out->images = d->n;
    out->samples = samples;
    out->lambda = lambda;
    return LR_OK;
}

double lr_camresp_gamma_at(double gamma, int z)
{
    /* z = 0 maps to a tiny positive value: the file format requires > 0, and a zero pixel
     * only bounds the exposure from above anyway. */
    return pow((z > 0 ? z : 0.25) / 255.0, gamma) / pow(128.0 / 255.0, gamma);
}

void lr_camresp_gamma(lr_camresp *r, double gamma)
{
    memset(r, 0, sizeof *r);
    for (int c = 0; c < 3; c++)
        for (int z = 0; z < 256; z++)
            r->curve[c][z] = lr_camresp_gamma_at(gamma, z);
}

double lr_camresp_linear(const lr_camresp *r, int c, double z)
{
    if (!(z > 0))
        return r->curve[c][0];
    if (z >= 255)
        return r->curve[c][255];
    int i = (int)z;
    double f = z - i;
    return r->curve[c][i] * (1 - f) + r->curve[c][i + 1] * f;
}

int lr_camresp_merge(const lr_camresp *r, const lr_img *images, const double *times, int n,
                     lr_img *out, lr_err *e)
{
    int rc = check_stack(images, times, n, e);
    if (rc)
        return rc;
    if ((rc = lr_img_alloc(out, images[0].w, images[0].h, 3, 4, e)))
        return rc;
    double lg[3][256], lt[LR_CAMRESP_MAX_STACK];
    if (n > LR_CAMRESP_MAX_STACK) {
        lr_img_free(out);
        return lr_err_set(e, LR_EINVAL, "exposure stack of %d images (at most %d)", n,
                          LR_CAMRESP_MAX_STACK);
    }
    for (int c = 0; c < 3; c++)
        for (int z = 0; z < 256; z++)
            lg[c][z] = log(r->curve[c][z]);
    int shortest = 0, longest = 0;
    for (int k = 0; k < n; k++) {
        lt[k] = log(times[k]);
        if (times[k] < times[shortest])
            shortest = k;
        if (times[k] > times[longest])
            longest = k;
    }
    float *o = out->px;
    size_t np = (size_t)images[0].w * (size_t)images[0].h * 3;
    for (size_t i = 0; i < np; i++) {
        int c = (int)(i % 3);
        double sw = 0, acc = 0;
        bool clipped = false;
        for (int k = 0; k < n; k++) {
            int z = ((const uint8_t *)images[k].px)[i];
            double w = z <= 127 ? z : 255 - z;
            clipped |= z == 255;
            sw += w;
            acc += w * (lg[c][z] - lt[k]);
        }
        if (sw > 0)
            o[i] = (float)exp(acc / sw);
        else if (clipped)
            o[i] = (float)(r->curve[c][255] / times[shortest]);
        else
            o[i] = (float)(r->curve[c][0] / times[longest]);
    }
    return LR_OK;
}

/* ---- file ----------------------------------------------------------------------------- */

static void fill(lr_jw *w, const void *obj)
{
    const lr_camresp *r = obj;
    lr_jw_array(w, "curve");
    for (int c = 0; c < 3; c++)
        lr_jw_numbers(w, NULL, r->curve[c], 256);
    lr_jw_array_end(w);
    lr_jw_int(w, "images", r->images);
    lr_jw_int(w, "samples", r->samples);
    lr_jw_number(w, "lambda", r->lambda);
}

static int from_json(const lr_json *j, lr_jnode root, lr_camresp *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    static const char *const keys[] = {"version", "kind", "curve", "images", "samples", "lambda",
                                       NULL};
    int rc = lr_json_check_keys(j, root, "camera response", keys, e);
    if (rc)
        return rc;
    double m[3 * 256];
    if ((rc = lr_calfile_matrix(j, root, NULL, "curve", 3, 256, 1e-30, 1e30, m, e)))
        return rc;
    for (int c = 0; c < 3; c++)
        for (int z = 0; z < 256; z++) {
            out->curve[c][z] = m[c * 256 + z];
            if (z > 0 && m[c * 256 + z] < m[c * 256 + z - 1])
                return lr_json_fail(j, lr_json_get(j, root, "curve"), "curve", e, LR_EINVAL,
                                    "channel %d decreases at value %d (%g after %g): a response "
                                    "must be non-decreasing",
                                    c, z, m[c * 256 + z], m[c * 256 + z - 1]);
        }
    long images = 0, samples = 0;
    if (lr_json_get(j, root, "images") != LR_JNONE &&
        ((rc = lr_calfile_int(j, root, NULL, "images", 0, 100000, &images, e)) ||
         (rc = lr_calfile_int(j, root, NULL, "samples", 0, 100000000, &samples, e)) ||
         (rc = lr_calfile_number(j, root, NULL, "lambda", 0, 1e9, &out->lambda, e))))
        return rc;
    out->images = (int)images;
    out->samples = (int)samples;
    return LR_OK;
}

static int check(const lr_json *j, lr_jnode root, lr_err *e)
{
    lr_camresp tmp;
    return from_json(j, root, &tmp, e);
}

int lr_camresp_save(const char *path, const lr_camresp *r, lr_err *e)
{
    return lr_calfile_save(path, LR_CAMRESP_KIND, fill, r, check, e);
}

int lr_camresp_load(const char *path, lr_camresp *out, lr_err *e)
{
    lr_json *j;
    lr_jnode root;
    int rc = lr_calfile_load(path, LR_CAMRESP_KIND, &j, &root, e);
    if (rc)
        return rc;
    rc = from_json(j, root, out, e);
    lr_json_destroy(j);
    return rc;
}
