/* lamprig-cpuref --compare REF.pfm: the rendered image against a physical reference
 * (`lamprig-reference render`, with REF.var.pfm beside it) on the bench's masks
 * (render/eval): relative RMSE on object and receiver pixels, the receivers' power ratio with
 * the reference's standard error, and the median |ln ratio| on object pixels. */
#include <stdio.h>
#include <string.h>

#include "render/eval/eval.h"
#include "render/image/image.h"
#include "tools/cpuref/compare.h"

int lr_cpuref_compare(const lr_scene *s, const lr_image *img, const char *ref_path, FILE *out,
                      lr_err *e)
{
    char vpath[4096];
    size_t n = strlen(ref_path);
    if (n >= 4 && !strcmp(ref_path + n - 4, ".pfm"))
        snprintf(vpath, sizeof vpath, "%.*s.var.pfm", (int)(n - 4), ref_path);
    else
        snprintf(vpath, sizeof vpath, "%s.var.pfm", ref_path);
    lr_image ref = {0}, var = {0};
    lr_eval_masks m = {0};
    int rc = lr_image_read_pfm(ref_path, &ref, e);
    if (!rc)
        rc = lr_image_read_pfm(vpath, &var, e);
    if (!rc && (ref.width != img->width || ref.height != img->height || var.width != ref.width ||
                var.height != ref.height))
        rc = lr_err_set(e, LR_EINVAL, "%s: %dx%d, the image is %dx%d", ref_path, ref.width,
                        ref.height, img->width, img->height);
    if (!rc)
        rc = lr_eval_masks_create(s, img->width, img->height, &m, e);
    if (!rc) {
        size_t px = (size_t)img->width * img->height;
        lr_eval_ratio pr = lr_eval_power_ratio(img->rgb, ref.rgb, var.rgb, m.receivers, px, -1);
        fprintf(out, "compare %s: rel_rmse objects %.4f (reference SE %.4f), receivers %.4f "
                     "(reference SE %.4f); receiver power %.4f +- %.4f; median |ln| objects "
                     "%.4f; %ld object, %ld receiver pixels\n",
                ref_path, lr_eval_rel_rmse(img->rgb, ref.rgb, m.object, px),
                lr_eval_rel_stderr(var.rgb, ref.rgb, m.object, px),
                lr_eval_rel_rmse(img->rgb, ref.rgb, m.receivers, px),
                lr_eval_rel_stderr(var.rgb, ref.rgb, m.receivers, px), pr.ratio, pr.se,
                lr_eval_median_abs_log(img->rgb, ref.rgb, m.object, px), m.object_px,
                m.receiver_px);
    }
    lr_eval_masks_free(&m);
    lr_image_free(&ref);
    lr_image_free(&var);
    return rc;
}
