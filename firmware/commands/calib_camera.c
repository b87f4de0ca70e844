/* `lamprig calib camera`: camera intrinsics from photos of a board (calib/camcal.h). */
#include <stdio.h>

#include "calib/camcal.h"
#include "firmware/commands/calib_cli.h"

static int run(const lr_cli *c);

static const lr_argspec opts[] = {
    {.name = "--images", .type = LR_ARG_STRING, .metavar = "GLOB", .flags = LR_ARG_REQUIRED,
     .help = "the photos of the board (quote the pattern)"},
    LR_CALIB_BOARD_OPTS(LR_ARG_REQUIRED),
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "FILE.json", .flags = LR_ARG_REQUIRED,
     .help = "the camera calibration written"},
    {.name = "--fix-aspect", .help = "fit one focal length (fx = fy)"},
    {.name = "--drop-outliers", .help = "refit without the outlier views"},
    LR_CALIB_SUBPIX_OPT,
    {.name = "--outlier-factor", .type = LR_ARG_NUMBER, .metavar = "F", .min = 1, .max = 1e3,
     .help = "a view is an outlier above F times the median error (default 3)"},
    {.name = "--min-views", .type = LR_ARG_INT, .min = 1, .max = 10000,
     .help = "fewest views the fit accepts (default 3)"},
    LR_CLI_QUIET_OPT,
    {0},
};

const lr_command lr_calib_camera = {
    .name = "camera",
    .summary = "camera intrinsics from photos of a board; outlier views are named",
    .opts = opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run,
};

static int run(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *images = lr_args_get(a, "--images"), *out = lr_args_get(a, "--out");
    lr_camcal_desc d = {.fix_aspect = lr_args_has(a, "--fix-aspect"),
                        .drop_outliers = lr_args_has(a, "--drop-outliers")};
    lr_err e = {0};
    int rc;
    if ((rc = lr_calib_board(c, &d.board)) || (rc = lr_calib_subpix(c, &d.subpix_window)) ||
        (rc = lr_cli_check(c, lr_args_double(a, "--outlier-factor", &d.outlier_factor, &e) ||
                                  lr_args_int(a, "--min-views", &d.min_views, &e),
                           &e)))
        return rc;
    glob_t g;
    if ((rc = lr_calib_glob(c, images, &g)))
        return rc;
    lr_progress_meter *pm = lr_cli_progress(c);
    d.images = (const char *const *)g.gl_pathv;
    d.nimages = (int)g.gl_pathc;
    d.progress = lr_progress_meter_sink(pm);
    lr_camcal cal;
    rc = lr_camcal_run(&d, &cal, &e);
    lr_progress_meter_destroy(pm);
    globfree(&g);
    /* One line per image left out, also when too few remain: they say why. */
    for (int i = 0; i < cal.nrejected; i++)
        fprintf(stderr, "skipped %s: %s\n", cal.rejected[i].image, cal.rejected[i].reason);
    if (rc) {
        lr_camcal_free(&cal);
        return lr_cli_fail(c->path, "%s", e.msg);
    }
    double med = lr_camcal_median_error(&cal);
    for (int i = 0; i < cal.nviews; i++)
        if (cal.views[i].outlier)
            fprintf(stderr, "outlier view %s: error %.3f px, median %.3f px%s\n",
                    cal.views[i].image, cal.views[i].error, med,
                    cal.views[i].used ? " (kept; --drop-outliers refits without it)" : " (dropped)");
    if (lr_camcal_save(out, &cal, &e)) {
        lr_camcal_free(&cal);
        return lr_cli_fail(c->path, "%s", e.msg);
    }
    int used = 0;
    for (int i = 0; i < cal.nviews; i++)
        used += cal.views[i].used;
    printf("camera %dx%d: fx %.3f fy %.3f cx %.3f cy %.3f  k1 %.5f k2 %.5f  rms %.4f px, %d "
           "views -> %s\n",
           cal.k.width, cal.k.height, cal.k.fx, cal.k.fy, cal.k.cx, cal.k.cy, cal.k.dist[0],
           cal.k.dist[1], cal.rms, used, out);
    lr_camcal_free(&cal);
    return LR_EXIT_OK;
}
