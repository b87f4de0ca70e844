/* `lamprig calib projector capture` and `lamprig calib projector-response capture`: show a
 * sequence on the projector and capture each frame live (calib/capture.h); the two differ only
 * in the sequence (Gray code, or flat levels per channel). */
#include <stdio.h>
#include <string.h>

#include "calib/capture.h"
#include "calib/graycode.h"
#include "calib/projresp.h"
#include "firmware/commands/calib_cli.h"

typedef struct display {
    lr_gc_show_fn show;
    void *ctx;
} display;

static int parse_display(const lr_cli *c, display *d)
{
    const char *s = lr_args_get(&c->args, "--display");
    if (strncmp(s, "file:", 5) == 0 && s[5]) {
        *d = (display){lr_capture_show_file, (void *)(s + 5)};
        return LR_EXIT_OK;
    }
    if (strncmp(s, "prompt:", 7) == 0 && s[7]) {
        *d = (display){lr_capture_show_prompt, (void *)(s + 7)};
        return LR_EXIT_OK;
    }
    return lr_cli_usage(c->path, "--display '%s': expected file:PATH or prompt:PATTERN_DIR", s);
}

static int capture(const lr_cli *c, bool graycode)
{
    const lr_args *a = &c->args;
    const char *out = lr_args_get(a, "--out");
    int pw = 0, ph = 0, rc;
    lr_err e = {0};
    if ((rc = lr_cli_check(c, lr_args_size(a, "--proj", &pw, &ph, &e), &e)))
        return rc;
    display disp = {0};
    if ((rc = parse_display(c, &disp)))
        return rc;
    lr_capture_desc d = {.device = lr_args_get(a, "--device"), .show = disp.show,
                         .show_ctx = disp.ctx};
    if ((rc = lr_cli_check(c, lr_args_size(a, "--camera-size", &d.width, &d.height, &e) ||
                                  lr_args_int(a, "--settle-ms", &d.settle_ms, &e),
                           &e)))
        return rc;
    lr_progress_meter *pm = lr_cli_progress(c);
    d.progress = lr_progress_meter_sink(pm);
    rc = lr_capture_run(&d, graycode ? lr_gc_run_sequence : lr_projresp_run_sequence, pw, ph, out,
                        &e);
    lr_progress_meter_destroy(pm);
    if (rc)
        return lr_cli_fail(c->path, "%s", e.msg);
    printf("captured -> %s/\n", out);
    return LR_EXIT_OK;
}

static int run_graycode(const lr_cli *c) { return capture(c, true); }
static int run_levels(const lr_cli *c) { return capture(c, false); }

static const lr_argspec opts[] = {
    {.name = "--device", .type = LR_ARG_PATH, .metavar = "/dev/videoN", .flags = LR_ARG_REQUIRED,
     .help = "the camera (V4L2)"},
    LR_CALIB_PROJ_OPT(LR_ARG_REQUIRED, "the projector's resolution"),
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "DIR", .flags = LR_ARG_REQUIRED,
     .help = "the capture folder written"},
    {.name = "--display", .type = LR_ARG_STRING, .metavar = "file:PATH|prompt:PATTERN_DIR",
     .flags = LR_ARG_REQUIRED,
     .help = "how a frame is shown (the firmware's projector output is not\n"
             "wired in yet): written to PATH, which an external viewer shows,\n"
             "or you show PATTERN_DIR's frame and press Enter"},
    {.name = "--camera-size", .type = LR_ARG_SIZE,
     .help = "the camera mode (default: the driver's)"},
    {.name = "--settle-ms", .type = LR_ARG_INT, .min = 1, .max = 60000,
     .help = "wait after each frame is shown (default 150)"},
    LR_CLI_QUIET_OPT,
    {0},
};

const lr_command lr_calib_projector_capture = {
    .name = "capture",
    .summary = "show the sequence and capture it live (one pose: run once per board pose)",
    .opts = opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_graycode,
};

const lr_command lr_calib_projresp_capture = {
    .name = "capture",
    .summary = "show the 17 default flat levels per channel and capture them live",
    .opts = opts,
    .notes = LR_CALIB_EXIT_NOTE,
    .run = run_levels,
};
