/* `lamprig calib camera-response` and `lamprig calib projector-response patterns|capture|fit`:
 * the radiometric responses (calib/camresp.h, calib/projresp.h). projector-response capture
 * is in calib_capture.c. */
#include <stdio.h>
#include <stdlib.h>

#include "calib/camresp.h"
#include "calib/projresp.h"
#include "firmware/commands/calib_cli.h"

/* ---- camera-response ------------------------------------------------------------------ */

static int run_camera_response(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *images = lr_args_get(a, "--images"), *times = lr_args_get(a, "--times");
    const char *out = lr_args_get(a, "--out"), *hdr = lr_args_get(a, "--hdr");
    double t[LR_CAMRESP_MAX_STACK];
    int nt = lr_args_times(times, t, LR_CAMRESP_MAX_STACK);
    if (nt < 2)
        return lr_cli_usage(c->path,
                            "--times '%s': expected 2 or more exposure times, e.g. 1/30,1/8,0.5",
                            times);
    lr_camresp_desc d = {0};
    lr_err e = {0};
    int rc;
    if ((rc = lr_cli_check(c, lr_args_int(a, "--samples", &d.samples, &e) ||
                                  lr_args_double(a, "--lambda", &d.lambda, &e),
                           &e)))
        return rc;
    glob_t g;
    if ((rc = lr_calib_glob(c, images, &g)))
        return rc;
    if ((int)g.gl_pathc != nt) {
        rc = lr_cli_usage(c->path, "%zu images match '%s' but %d times are given", g.gl_pathc,
                          images, nt);
        globfree(&g);
        return rc;
    }
    lr_img imgs[LR_CAMRESP_MAX_STACK];
    int loaded = 0;
    for (; loaded < nt; loaded++)
        if (lr_img_read(g.gl_pathv[loaded], LR_IMG_RGB8, &imgs[loaded], &e)) {
            rc = lr_cli_fail(c->path, "%s", e.msg);
            break;
        }
    lr_camresp r;
    lr_img merged = {0};
    if (!rc) {
        d.images = imgs;
        d.times = t;
        d.n = nt;
        if (lr_camresp_fit(&d, &r, &e) ||
            (hdr && (lr_camresp_merge(&r, imgs, t, nt, &merged, &e) ||
                     lr_img_write(hdr, &merged, &e))) ||
            lr_camresp_save(out, &r, &e))
            rc = lr_cli_fail(c->path, "%s", e.msg);
    }
    for (int i = 0; i < loaded; i++)
        lr_img_free(&imgs[i]);
    lr_img_free(&merged);
    globfree(&g);
    if (!rc)
        printf("camera response from %d exposures: value 64 -> %.4f, 192 -> %.4f (green, "
               "relative to 128) -> %s%s%s\n",
               nt, r.curve[1][64], r.curve[1][192], out, hdr ? ", HDR -> " : "", hdr ? hdr : "");
    return rc;
}

static const lr_argspec camera_response_opts[] = {
    {.name = "--images", .type = LR_ARG_STRING, .metavar = "GLOB", .flags = LR_ARG_REQUIRED,
     .help = "the exposure stack (quote the pattern)"},
    {.name = "--times", .type = LR_ARG_STRING, .metavar = "T1,T2,...", .flags = LR_ARG_REQUIRED,
     .help = "exposure times in s (1/30 allowed), in the order GLOB sorts"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "FILE.json", .flags = LR_ARG_REQUIRED,
     .help = "the camera response written"},
    {.name = "--hdr", .type = LR_ARG_PATH, .metavar = "OUT.hdr",
     .help = "the merged HDR image too"},
    {.name = "--samples", .type = LR_ARG_INT, .min = 10, .max = 100000,
     .help = "pixel locations sampled (default 70)"},
    {.name = "--lambda", .type = LR_ARG_NUMBER, .metavar = "L", .min = 1e-6, .max = 1e6,
     .help = "smoothness (default 10)"},
    {0},
};

const lr_command lr_calib_camera_response = {
    .name = "camera-response",
    .summary = "camera response (Debevec) from an exposure stack (times in s, 1/30 allowed,\n"
               "in the order GLOB sorts), optionally the merged HDR image",
    .opts = camera_response_opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_camera_response,
};

/* ---- projector-response --------------------------------------------------------------- */

static int run_patterns(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *out = lr_args_get(a, "--out");
    int pw = 0, ph = 0, n = 0, rc;
    lr_err e = {0};
    if ((rc = lr_cli_check(c, lr_args_size(a, "--proj", &pw, &ph, &e) ||
                                  lr_args_int(a, "--steps", &n, &e),
                           &e)))
        return rc;
    if (lr_projresp_write_patterns(out, pw, ph, n, &e))
        return lr_cli_fail(c->path, "%s", e.msg);
    printf("flat frames (r_/g_/b_LLL.png) -> %s/\n", out);
    return LR_EXIT_OK;
}

static const lr_argspec patterns_opts[] = {
    LR_CALIB_PROJ_OPT(LR_ARG_REQUIRED, "the projector's resolution"),
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the folder the frames are written to"},
    {.name = "--steps", .type = LR_ARG_INT, .min = 3, .max = 256,
     .help = "flat levels per channel (default 17: 0, 16, ..., 240, 255)"},
    {0},
};

static const lr_command patterns = {
    .name = "patterns",
    .summary = "write the flat frames (r_/g_/b_LLL.png) per channel",
    .opts = patterns_opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_patterns,
};

static int run_fit(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *dir = lr_args_get(a, "--captures"), *out = lr_args_get(a, "--out");
    const char *camresp = lr_args_get(a, "--camera-response");
    lr_err e = {0};
    lr_camresp cam;
    if (camresp && lr_camresp_load(camresp, &cam, &e))
        return lr_cli_fail(c->path, "%s", e.msg);
    lr_projresp *r = malloc(sizeof *r);
    if (!r)
        return lr_cli_fail(c->path, "out of memory");
    int rc = LR_EXIT_OK;
    if (lr_projresp_measure(dir, camresp ? &cam : NULL, r, &e) || lr_projresp_save(out, r, &e))
        rc = lr_cli_fail(c->path, "%s", e.msg);
    else
        printf("projector response from %d levels: gamma r %.3f g %.3f b %.3f, black %.4f "
               "%.4f %.4f of white -> %s\n",
               r->nlevels, r->gamma[0], r->gamma[1], r->gamma[2], r->black[0], r->black[1],
               r->black[2], out);
    free(r);
    return rc;
}

static const lr_argspec fit_opts[] = {
    {.name = "--captures", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the flat-level captures"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "FILE.json", .flags = LR_ARG_REQUIRED,
     .help = "the projector response written"},
    {.name = "--camera-response", .type = LR_ARG_PATH, .metavar = "FILE.json",
     .help = "linearise the captures with it (default: the camera is linear)"},
    {0},
};

static const lr_command fit = {
    .name = "fit",
    .summary = "per-channel projector response (black subtracted) from flat-level captures",
    .opts = fit_opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_fit,
};

const lr_command lr_calib_projector_response = {
    .name = "projector-response",
    .summary = "the projector's per-channel response",
    .notes = LR_CALIB_EXIT_NOTE,
    .subs = (const lr_command *const[]){&patterns, &lr_calib_projresp_capture, &fit, NULL},
};
