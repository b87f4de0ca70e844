/* `lamprig calib color`: the 3x3 colour matrix, camera linear RGB -> linear sRGB, from pairs
 * or a photo of a colour checker (calib/colormatrix.h). */
#include <stdio.h>
#include <stdlib.h>

#include "calib/camresp.h"
#include "calib/colormatrix.h"
#include "firmware/commands/calib_cli.h"

static int run(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *pairs = lr_args_get(a, "--pairs"), *checker = lr_args_get(a, "--checker");
    const char *camresp = lr_args_get(a, "--camera-response"), *out = lr_args_get(a, "--out");
    if (!pairs == !checker)
        return lr_cli_usage(c->path, "give exactly one of --pairs FILE or --checker PHOTO");
    lr_err e = {0};
    lr_colormatrix m;
    int rc;
    if (pairs) {
        double *cam, *ref;
        int n;
        if (lr_colorpairs_load(pairs, &cam, &ref, &n, &e))
            return lr_cli_fail(c->path, "%s", e.msg);
        rc = lr_colormatrix_fit(cam, ref, n, &m, &e);
        free(cam);
        free(ref);
        if (rc)
            return lr_cli_fail(c->path, "%s", e.msg);
    } else {
        lr_camresp cam;
        if (camresp && lr_camresp_load(camresp, &cam, &e))
            return lr_cli_fail(c->path, "%s", e.msg);
        lr_img photo;
        if (lr_img_read(checker, LR_IMG_RGB8, &photo, &e))
            return lr_cli_fail(c->path, "%s", e.msg);
        double measured[72], ref[72];
        rc = lr_colorchecker_measure(&photo, camresp ? &cam : NULL, measured, &e);
        lr_img_free(&photo);
        if (rc) {
            lr_err_prefix(&e, "%s", checker);
            return lr_cli_fail(c->path, "%s", e.msg);
        }
        lr_colorchecker_linear(ref);
        if (lr_colormatrix_fit(measured, ref, 24, &m, &e))
            return lr_cli_fail(c->path, "%s", e.msg);
        snprintf(m.source, sizeof m.source, "colorchecker");
    }
    if (lr_colormatrix_save(out, &m, &e))
        return lr_cli_fail(c->path, "%s", e.msg);
    printf("colour matrix from %d patches (%s): rms %.4f, worst %.4f -> %s\n", m.patches, m.source,
           m.rms, m.max_err, out);
    for (int r = 0; r < 3; r++)
        printf("  [%9.5f %9.5f %9.5f]\n", m.m[3 * r], m.m[3 * r + 1], m.m[3 * r + 2]);
    return LR_EXIT_OK;
}

static const lr_argspec opts[] = {
    {.name = "--pairs", .type = LR_ARG_PATH, .metavar = "PAIRS.json",
     .help = "measured and reference colours (or --checker)"},
    {.name = "--checker", .type = LR_ARG_PATH, .metavar = "PHOTO",
     .help = "a photo of a 24-patch colour checker (or --pairs)"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "FILE.json", .flags = LR_ARG_REQUIRED,
     .help = "the colour matrix written"},
    {.name = "--camera-response", .type = LR_ARG_PATH, .metavar = "FILE.json",
     .help = "--checker: linearise the photo with it"},
    {0},
};

const lr_command lr_calib_color = {
    .name = "color",
    .summary = "3x3 colour matrix, camera linear RGB -> linear sRGB (--pairs or --checker)",
    .opts = opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run,
};
