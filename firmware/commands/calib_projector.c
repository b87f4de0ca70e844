/* `lamprig calib projector patterns|capture|decode|calibrate`: the Gray-code sequence, its
 * decoding and the projector-camera calibration (calib/graycode.h, calib/procam.h). capture
 * is in calib_capture.c, shared with projector-response. */
#include <math.h>
#include <stdio.h>

#include "calib/camcal.h"
#include "calib/graycode.h"
#include "calib/procam.h"
#include "firmware/commands/calib_cli.h"

/* ---- patterns ------------------------------------------------------------------------- */

static int run_patterns(const lr_cli *c)
{
    const char *out = lr_args_get(&c->args, "--out");
    int pw = 0, ph = 0, st;
    lr_err e = {0};
    if ((st = lr_cli_check(c, lr_args_size(&c->args, "--proj", &pw, &ph, &e), &e)))
        return st;
    lr_progress_meter *pm = lr_cli_progress(c);
    st = lr_gc_write_patterns(out, pw, ph, lr_progress_meter_sink(pm), &e);
    lr_progress_meter_destroy(pm);
    if (st)
        return lr_cli_fail(c->path, "%s", e.msg);
    int n = 0;
    lr_gc_frame_count(pw, ph, &n, &e);
    printf("%d frames for a %dx%d projector -> %s/\n", n, pw, ph, out);
    return LR_EXIT_OK;
}

static const lr_argspec patterns_opts[] = {
    LR_CALIB_PROJ_OPT(LR_ARG_REQUIRED, "the projector's resolution"),
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the folder the frames are written to"},
    LR_CLI_QUIET_OPT,
    {0},
};

static const lr_command patterns = {
    .name = "patterns",
    .summary = "write the Gray-code sequence (white, black, pattern_NN.png) for the projector",
    .opts = patterns_opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_patterns,
};

/* ---- decode --------------------------------------------------------------------------- */

static int run_decode(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *dir = lr_args_get(a, "--captures"), *map = lr_args_get(a, "--map");
    int pw = 0, ph = 0, st;
    lr_gc_params params = {0};
    lr_err e = {0};
    if ((st = lr_cli_check(c, lr_args_size(a, "--proj", &pw, &ph, &e) ||
                                  lr_args_int(a, "--contrast", &params.contrast, &e) ||
                                  lr_args_int(a, "--shadow", &params.shadow, &e),
                           &e)))
        return st;
    lr_progress_meter *pm = lr_cli_progress(c);
    lr_gc_map *m;
    st = lr_gc_decode_dir(dir, pw, ph, &params, lr_progress_meter_sink(pm), &m, &e);
    lr_progress_meter_destroy(pm);
    if (st)
        return lr_cli_fail(c->path, "%s", e.msg);
    long total = (long)lr_gc_map_width(m) * lr_gc_map_height(m);
    printf("%s: %dx%d camera pixels:", dir, lr_gc_map_width(m), lr_gc_map_height(m));
    for (int s = LR_GC_VALID; s <= LR_GC_OUT_OF_RANGE; s++) {
        long n = lr_gc_map_count(m, s);
        printf(" %s %ld (%.1f %%)%s", lr_gc_status_name(s), n, 100.0 * n / total,
               s < LR_GC_OUT_OF_RANGE ? "," : "\n");
    }
    if (map) {
        if (lr_gc_map_save(m, map, &e)) {
            lr_gc_map_destroy(m);
            return lr_cli_fail(c->path, "%s", e.msg);
        }
        printf("map (R = projector x, G = y, B = status) -> %s\n", map);
    }
    lr_gc_map_destroy(m);
    return LR_EXIT_OK;
}

static const lr_argspec decode_opts[] = {
    {.name = "--captures", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "one capture folder (white.png, black.png, pattern_NN.png)"},
    LR_CALIB_PROJ_OPT(0, "the projector's resolution (default: the folder's sequence.json)"),
    LR_CALIB_DECODE_OPTS,
    {.name = "--map", .type = LR_ARG_PATH, .metavar = "OUT.png",
     .help = "the decoded map (R = projector x, G = y, B = status)"},
    LR_CLI_QUIET_OPT,
    {0},
};

static const lr_command decode = {
    .name = "decode",
    .summary = "decode one capture folder per camera pixel and report what decoded",
    .opts = decode_opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_decode,
};

/* ---- calibrate ------------------------------------------------------------------------ */

static int run_calibrate(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *camera = lr_args_get(a, "--camera"), *out = lr_args_get(a, "--out");
    lr_procam_desc d = {.captures = lr_args_get(a, "--captures"),
                        .proj_fix_aspect = lr_args_has(a, "--fix-aspect")};
    lr_err e = {0};
    int rc;
    if ((rc = lr_calib_board(c, &d.board)) || (rc = lr_calib_subpix(c, &d.subpix_window)) ||
        (rc = lr_cli_check(c, lr_args_size(a, "--proj", &d.proj_w, &d.proj_h, &e) ||
                                  lr_args_int(a, "--contrast", &d.decode.contrast, &e) ||
                                  lr_args_int(a, "--shadow", &d.decode.shadow, &e) ||
                                  lr_args_int(a, "--window", &d.local.half_window, &e),
                           &e)))
        return rc;
    lr_camcal cam;
    if (camera) {
        if (lr_camcal_load(camera, &cam, &e))
            return lr_cli_fail(c->path, "%s", e.msg);
        d.camera = &cam.k;
        d.camera_rms = cam.rms;
    }
    lr_progress_meter *pm = lr_cli_progress(c);
    d.progress = lr_progress_meter_sink(pm);
    lr_procam p;
    rc = lr_procam_run(&d, &p, &e);
    lr_progress_meter_destroy(pm);
    if (camera)
        lr_camcal_free(&cam);
    if (rc)
        return lr_cli_fail(c->path, "%s", e.msg);
    for (int i = 0; i < p.nrejected; i++)
        fprintf(stderr, "skipped pose %s: %s\n", p.rejected[i].name, p.rejected[i].reason);
    if (lr_procam_save(out, &p, &e)) {
        lr_procam_free(&p);
        return lr_cli_fail(c->path, "%s", e.msg);
    }
    printf("projector %dx%d: fx %.3f fy %.3f cx %.3f cy %.3f  rms %.4f px\n", p.proj.width,
           p.proj.height, p.proj.fx, p.proj.fy, p.proj.cx, p.proj.cy, p.proj_rms);
    printf("projector from camera: T (%.2f, %.2f, %.2f) mm, baseline %.2f mm, stereo rms %.4f "
           "px, %d poses -> %s\n",
           p.T[0], p.T[1], p.T[2], sqrt(p.T[0] * p.T[0] + p.T[1] * p.T[1] + p.T[2] * p.T[2]),
           p.rms, p.nposes, out);
    lr_procam_free(&p);
    return LR_EXIT_OK;
}

static const lr_argspec calibrate_opts[] = {
    {.name = "--captures", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the session: one capture folder per board pose"},
    LR_CALIB_BOARD_OPTS(LR_ARG_REQUIRED),
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "FILE.json", .flags = LR_ARG_REQUIRED,
     .help = "the projector calibration written"},
    LR_CALIB_PROJ_OPT(0, "the projector's resolution (default: the sequence.json files)"),
    {.name = "--camera", .type = LR_ARG_PATH, .metavar = "CAMERA.json",
     .help = "the camera's intrinsics, kept fixed (default: fitted too)"},
    {.name = "--fix-aspect", .help = "fit one projector focal length (fx = fy)"},
    LR_CALIB_DECODE_OPTS,
    {.name = "--window", .type = LR_ARG_INT, .min = 2, .max = 500,
     .help = "half-size of the local homography window, px (default 23)"},
    LR_CALIB_SUBPIX_OPT,
    LR_CLI_QUIET_OPT,
    {0},
};

static const lr_command calibrate = {
    .name = "calibrate",
    .summary = "projector intrinsics and projector-camera extrinsics from pose folders in DIR",
    .opts = calibrate_opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_calibrate,
};

const lr_command lr_calib_projector = {
    .name = "projector",
    .summary = "the projector's Gray-code calibration",
    .notes = LR_CALIB_EXIT_NOTE,
    .subs = (const lr_command *const[]){&patterns, &lr_calib_projector_capture, &decode,
                                        &calibrate, NULL},
};
