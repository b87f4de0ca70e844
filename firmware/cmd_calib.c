/* `lamprig calib ...`: argument parsing and reporting around calib/. Every result is computed
 * in full before its file is written, and written atomically after validation, so a failed
 * run leaves the previous calibration untouched (exit status 1, one-line reason on stderr). */
#include "firmware/cmd_calib.h"

#include <glob.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/albedo.h"
#include "calib/ar_frame.h"
#include "calib/camcal.h"
#include "calib/camresp.h"
#include "calib/capture.h"
#include "calib/calfile.h"
#include "calib/colormatrix.h"
#include "calib/graycode.h"
#include "calib/pose.h"
#include "calib/procam.h"
#include "calib/projresp.h"
#include "calib/rig.h"
#include "firmware/args.h"
#include "firmware/cli.h"

const char lr_cmd_calib_usage[] =
    "usage: lamprig calib SUBCOMMAND [OPTIONS]\n"
    "\n"
    "  camera --images GLOB --board COLSxROWS --square MM --out FILE.json\n"
    "         [--pattern chessboard|circles|acircles] [--fix-aspect] [--drop-outliers]\n"
    "         [--subpix-window N|auto] [--outlier-factor F] [--min-views N]\n"
    "      camera intrinsics from photos of a board; outlier views are named\n"
    "  projector patterns --proj WxH --out DIR\n"
    "      write the Gray-code sequence (white, black, pattern_NN.png) for the projector\n"
    "  projector capture --device /dev/videoN --proj WxH --out DIR\n"
    "         --display file:PATH|prompt:PATTERN_DIR [--camera-size WxH] [--settle-ms N]\n"
    "      show the sequence and capture it live (one pose: run once per board pose)\n"
    "  projector decode --captures DIR [--proj WxH] [--contrast N] [--shadow N] [--map OUT.png]\n"
    "      decode one capture folder per camera pixel and report what decoded\n"
    "  projector calibrate --captures DIR --board COLSxROWS --square MM --out FILE.json\n"
    "         [--proj WxH] [--camera CAMERA.json] [--pattern P] [--fix-aspect]\n"
    "         [--contrast N] [--shadow N] [--window N] [--subpix-window N|auto]\n"
    "      projector intrinsics and projector-camera extrinsics from pose folders in DIR\n"
    "  camera-response --images GLOB --times T1,T2,... --out FILE.json [--hdr OUT.hdr]\n"
    "         [--samples N] [--lambda L]\n"
    "      camera response (Debevec) from an exposure stack (times in s, 1/30 allowed,\n"
    "      in the order GLOB sorts), optionally the merged HDR image\n"
    "  projector-response patterns --proj WxH --out DIR [--steps N]\n"
    "  projector-response capture --device /dev/videoN --proj WxH --out DIR\n"
    "         --display file:PATH|prompt:PATTERN_DIR [--camera-size WxH] [--settle-ms N]\n"
    "      show the 17 default flat levels per channel and capture them live\n"
    "  projector-response fit --captures DIR --out FILE.json [--camera-response FILE.json]\n"
    "      per-channel projector response (black subtracted) from flat-level captures\n"
    "  color --pairs PAIRS.json --out FILE.json\n"
    "  color --checker PHOTO --out FILE.json [--camera-response FILE.json]\n"
    "      3x3 colour matrix, camera linear RGB -> linear sRGB\n"
    "  pose --image PHOTO --board COLSxROWS --square MM --origin X,Y,Z --x-axis X,Y,Z\n"
    "       --y-axis X,Y,Z --camera CAMERA.json --out pose.json [--projector PROJECTOR.json]\n"
    "       [--pattern P]\n"
    "  pose --points POINTS.json --camera CAMERA.json --out pose.json [--projector P.json]\n"
    "      the camera's (and projector's) pose in scene coordinates (mm) from a photo of a\n"
    "      board lying at a known place (its first point at --origin, its +x and +y axes\n"
    "      along --x-axis / --y-axis), or from pixels of known scene points: POINTS.json is\n"
    "      {\"version\":1, \"kind\":\"pose_points\", \"points\":[{\"scene\":[x,y,z],\n"
    "      \"pixel\":[u,v]}, ...]}\n"
    "  albedo --captures DIR --out FILE.json [--calib DIR] [--proj WxH] [--contrast N]\n"
    "         [--shadow N] [--fill N]\n"
    "      the mockup's response to each projector pixel (white - black, linearised with the\n"
    "      calibration folder's camera response) from a Gray-code capture of the white\n"
    "      mockup, for spatial AR; writes FILE.json and FILE.pfm beside it\n"
    "  ar-frame --scene FILE --calib DIR --out LEVELS.png [--target OUT.pfm] [--gain G]\n"
    "         [--samples N] [--render-width N] [--seed N]\n"
    "      one spatial-AR projector frame: the scene rendered from the projector (pose.json's\n"
    "      projector pose), divided by the mockup's response (DIR/albedo.json, else an ideal\n"
    "      white mockup of the scene's geometry), clipped, through the inverse projector\n"
    "      response; prints how much was clipped\n"
    "  check FILE...\n"
    "      load and validate calibration files of any kind, print a summary; a JSON file\n"
    "      that is not a calibration file (no \"kind\", e.g. a rig config) is named and\n"
    "      skipped; exit status 1 only when a file cannot be read, is not JSON or is a\n"
    "      calibration file that does not load\n"
    "\n"
    "Exit status: 0 success, 1 failure (the output file is left as it was), 2 bad arguments.";

/* ---- arguments ------------------------------------------------------------------------ */

typedef struct opt {
    const char *name;
    const char **value; /* option with an argument */
    bool *flag;         /* option without */
} opt;

static int usage_error(const char *cmd, const char *fmt, const char *arg)
{
    fprintf(stderr, "lamprig calib %s: ", cmd);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (see `lamprig help calib`)\n");
    return LR_EXIT_USAGE;
}

/* Parses argv[first..] against opts; positional arguments are refused unless pos != NULL
 * (then collected there, at most maxpos). */
static int parse(const char *cmd, int argc, char **argv, int first, const opt *opts,
                 const char **pos, int maxpos, int *npos)
{
    if (npos)
        *npos = 0;
    for (int i = first; i < argc; i++) {
        const char *a = argv[i];
        if (strncmp(a, "--", 2) != 0) {
            if (!pos || *npos >= maxpos)
                return usage_error(cmd, "unexpected argument '%s'", a);
            pos[(*npos)++] = a;
            continue;
        }
        const opt *o = NULL;
        for (const opt *p = opts; p->name; p++)
            if (strcmp(p->name, a + 2) == 0)
                o = p;
        if (!o)
            return usage_error(cmd, "unknown option '%s'", a);
        if (o->flag) {
            *o->flag = true;
        } else {
            if (i + 1 >= argc)
                return usage_error(cmd, "option '%s' needs a value", a);
            *o->value = argv[++i];
        }
    }
    return LR_EXIT_OK;
}

static int need(const char *cmd, const char *value, const char *name)
{
    return value ? LR_EXIT_OK : usage_error(cmd, "missing --%s", name);
}

static bool parse_wxh(const char *s, int *w, int *h)
{
    int a, b, n = 0;
    if (!s || sscanf(s, "%dx%d%n", &a, &b, &n) != 2 || s[n] != '\0' || a <= 0 || b <= 0)
        return false;
    *w = a;
    *h = b;
    return true;
}

static bool parse_int(const char *s, int lo, int hi, int *out)
{
    char *end;
    long v = s ? strtol(s, &end, 10) : 0;
    if (!s || *s == '\0' || *end != '\0' || v < lo || v > hi)
        return false;
    *out = (int)v;
    return true;
}

static bool parse_double(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v = s ? strtod(s, &end) : 0;
    if (!s || *s == '\0' || *end != '\0' || !(v >= lo && v <= hi))
        return false;
    *out = v;
    return true;
}

static int parse_board(const char *cmd, const char *size, const char *square, const char *pattern,
                       lr_board *b)
{
    lr_err e = {0};
    if (lr_board_parse_size(size, &b->cols, &b->rows, &e))
        return usage_error(cmd, "%s", e.msg);
    if (!parse_double(square, 1e-3, 1e4, &b->square_mm))
        return usage_error(cmd, "--square '%s': expected millimetres > 0", square);
    b->pattern = LR_BOARD_CHESSBOARD;
    if (pattern && lr_board_parse_pattern(pattern, &b->pattern, &e))
        return usage_error(cmd, "%s", e.msg);
    if (lr_board_check(b, &e))
        return usage_error(cmd, "%s", e.msg);
    return LR_EXIT_OK;
}

static int parse_subpix(const char *cmd, const char *s, int *out)
{
    *out = 0;
    if (!s)
        return LR_EXIT_OK;
    if (strcmp(s, "auto") == 0) {
        *out = LR_SUBPIX_AUTO;
        return LR_EXIT_OK;
    }
    if (!parse_int(s, 1, 100, out))
        return usage_error(cmd, "--subpix-window '%s': expected 1..100 or auto", s);
    return LR_EXIT_OK;
}

static int fail(const char *cmd, const lr_err *e)
{
    fprintf(stderr, "lamprig calib %s: %s\n", cmd, e->msg);
    return LR_EXIT_FAIL;
}

/* Sorted glob matches; an error when nothing matches. */
static int expand(const char *cmd, const char *pattern, glob_t *g)
{
    int rc = glob(pattern, 0, NULL, g);
    if (rc != 0 || g->gl_pathc == 0) {
        if (rc == 0)
            globfree(g);
        fprintf(stderr, "lamprig calib %s: no files match '%s'\n", cmd, pattern);
        return LR_EXIT_FAIL;
    }
    return LR_EXIT_OK;
}

/* ---- progress ------------------------------------------------------------------------- */

typedef struct progress_state {
    char stage[256];
    int last_decile;
} progress_state;

/* One line per stage and per tenth of it: readable in a log, alive on a terminal. */
static void print_progress(void *ctx, const char *stage, int done, int total)
{
    progress_state *p = ctx;
    int decile = total > 0 ? (int)((long)done * 10 / total) : 10;
    if (strncmp(p->stage, stage, sizeof p->stage - 1) != 0) {
        snprintf(p->stage, sizeof p->stage, "%s", stage);
        p->last_decile = -1;
    }
    if (decile == p->last_decile)
        return;
    p->last_decile = decile;
    fprintf(stderr, "  %s: %d/%d\n", stage, done, total);
}

/* ---- camera --------------------------------------------------------------------------- */

static int cmd_camera(int argc, char **argv)
{
    const char *images = NULL, *size = NULL, *square = NULL, *pattern = NULL, *out = NULL;
    const char *subpix = NULL, *factor = NULL, *min_views = NULL;
    bool fix_aspect = false, drop = false;
    const opt opts[] = {{"images", &images, NULL},      {"board", &size, NULL},
                        {"square", &square, NULL},      {"pattern", &pattern, NULL},
                        {"out", &out, NULL},            {"fix-aspect", NULL, &fix_aspect},
                        {"drop-outliers", NULL, &drop}, {"subpix-window", &subpix, NULL},
                        {"outlier-factor", &factor, NULL}, {"min-views", &min_views, NULL},
                        {NULL, NULL, NULL}};
    const char *cmd = "camera";
    int rc = parse(cmd, argc, argv, 2, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, images, "images")) || (rc = need(cmd, size, "board")) ||
        (rc = need(cmd, square, "square")) || (rc = need(cmd, out, "out")))
        return rc;
    lr_camcal_desc d = {.fix_aspect = fix_aspect, .drop_outliers = drop};
    if ((rc = parse_board(cmd, size, square, pattern, &d.board)) ||
        (rc = parse_subpix(cmd, subpix, &d.subpix_window)))
        return rc;
    if (factor && !parse_double(factor, 1.0, 1e3, &d.outlier_factor))
        return usage_error(cmd, "--outlier-factor '%s': expected a number >= 1", factor);
    if (min_views && !parse_int(min_views, 1, 10000, &d.min_views))
        return usage_error(cmd, "--min-views '%s': expected a count >= 1", min_views);
    glob_t g;
    if ((rc = expand(cmd, images, &g)))
        return rc;
    progress_state ps = {{0}, -1};
    lr_progress progress = {print_progress, &ps};
    d.images = (const char *const *)g.gl_pathv;
    d.nimages = (int)g.gl_pathc;
    d.progress = &progress;
    lr_camcal c;
    lr_err e = {0};
    rc = lr_camcal_run(&d, &c, &e);
    globfree(&g);
    /* One line per image left out, also when too few remain: they say why. */
    for (int i = 0; i < c.nrejected; i++)
        fprintf(stderr, "skipped %s: %s\n", c.rejected[i].image, c.rejected[i].reason);
    if (rc) {
        lr_camcal_free(&c);
        return fail(cmd, &e);
    }
    double med = lr_camcal_median_error(&c);
    for (int i = 0; i < c.nviews; i++)
        if (c.views[i].outlier)
            fprintf(stderr, "outlier view %s: error %.3f px, median %.3f px%s\n",
                    c.views[i].image, c.views[i].error, med,
                    c.views[i].used ? " (kept; --drop-outliers refits without it)" : " (dropped)");
    rc = lr_camcal_save(out, &c, &e);
    if (rc) {
        lr_camcal_free(&c);
        return fail(cmd, &e);
    }
    int used = 0;
    for (int i = 0; i < c.nviews; i++)
        used += c.views[i].used;
    printf("camera %dx%d: fx %.3f fy %.3f cx %.3f cy %.3f  k1 %.5f k2 %.5f  rms %.4f px, %d "
           "views -> %s\n",
           c.k.width, c.k.height, c.k.fx, c.k.fy, c.k.cx, c.k.cy, c.k.dist[0], c.k.dist[1], c.rms,
           used, out);
    lr_camcal_free(&c);
    return LR_EXIT_OK;
}

/* ---- projector ------------------------------------------------------------------------ */

typedef struct display {
    lr_gc_show_fn show;
    void *ctx;
} display;

static int parse_display(const char *cmd, const char *s, display *d)
{
    if (!s)
        return usage_error(cmd, "%s",
                           "missing --display: the firmware's projector output is not wired "
                           "in yet; use file:PATH (an external viewer shows PATH) or "
                           "prompt:PATTERN_DIR (you show each pattern, then press Enter)");
    if (strncmp(s, "file:", 5) == 0 && s[5]) {
        *d = (display){lr_capture_show_file, (void *)(s + 5)};
        return LR_EXIT_OK;
    }
    if (strncmp(s, "prompt:", 7) == 0 && s[7]) {
        *d = (display){lr_capture_show_prompt, (void *)(s + 7)};
        return LR_EXIT_OK;
    }
    return usage_error(cmd, "--display '%s': expected file:PATH or prompt:PATTERN_DIR", s);
}

static int cmd_projector_patterns(int argc, char **argv)
{
    const char *proj = NULL, *out = NULL, *cmd = "projector patterns";
    const opt opts[] = {{"proj", &proj, NULL}, {"out", &out, NULL}, {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 3, opts, NULL, 0, NULL);
    int pw, ph;
    if (rc || (rc = need(cmd, proj, "proj")) || (rc = need(cmd, out, "out")))
        return rc;
    if (!parse_wxh(proj, &pw, &ph))
        return usage_error(cmd, "--proj '%s': expected WIDTHxHEIGHT", proj);
    progress_state ps = {{0}, -1};
    lr_progress progress = {print_progress, &ps};
    lr_err e = {0};
    if (lr_gc_write_patterns(out, pw, ph, &progress, &e))
        return fail(cmd, &e);
    int n = 0;
    lr_gc_frame_count(pw, ph, &n, &e);
    printf("%d frames for a %dx%d projector -> %s/\n", n, pw, ph, out);
    return LR_EXIT_OK;
}

static int capture_common(const char *cmd, int argc, char **argv, bool graycode)
{
    const char *device = NULL, *proj = NULL, *out = NULL, *disp = NULL, *csize = NULL;
    const char *settle = NULL;
    const opt opts[] = {{"device", &device, NULL},     {"proj", &proj, NULL},
                        {"out", &out, NULL},           {"display", &disp, NULL},
                        {"camera-size", &csize, NULL}, {"settle-ms", &settle, NULL},
                        {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 3, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, device, "device")) || (rc = need(cmd, proj, "proj")) ||
        (rc = need(cmd, out, "out")))
        return rc;
    int pw, ph;
    if (!parse_wxh(proj, &pw, &ph))
        return usage_error(cmd, "--proj '%s': expected WIDTHxHEIGHT", proj);
    display disp_cb;
    if ((rc = parse_display(cmd, disp, &disp_cb)))
        return rc;
    lr_capture_desc d = {.device = device, .show = disp_cb.show, .show_ctx = disp_cb.ctx};
    if (csize && !parse_wxh(csize, &d.width, &d.height))
        return usage_error(cmd, "--camera-size '%s': expected WIDTHxHEIGHT", csize);
    if (settle && !parse_int(settle, 1, 60000, &d.settle_ms))
        return usage_error(cmd, "--settle-ms '%s': expected 1..60000", settle);
    progress_state ps = {{0}, -1};
    lr_progress progress = {print_progress, &ps};
    d.progress = &progress;
    lr_err e = {0};
    rc = lr_capture_run(&d, graycode ? lr_gc_run_sequence : lr_projresp_run_sequence, pw, ph, out,
                        &e);
    if (rc)
        return fail(cmd, &e);
    printf("captured -> %s/\n", out);
    return LR_EXIT_OK;
}

static int cmd_projector_decode(int argc, char **argv)
{
    const char *dir = NULL, *proj = NULL, *contrast = NULL, *shadow = NULL, *map = NULL;
    const char *cmd = "projector decode";
    const opt opts[] = {{"captures", &dir, NULL}, {"proj", &proj, NULL},
                        {"contrast", &contrast, NULL}, {"shadow", &shadow, NULL},
                        {"map", &map, NULL},      {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 3, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, dir, "captures")))
        return rc;
    int pw = 0, ph = 0;
    lr_gc_params params = {0};
    if (proj && !parse_wxh(proj, &pw, &ph))
        return usage_error(cmd, "--proj '%s': expected WIDTHxHEIGHT", proj);
    if (contrast && !parse_int(contrast, 1, 255, &params.contrast))
        return usage_error(cmd, "--contrast '%s': expected 1..255", contrast);
    if (shadow && !parse_int(shadow, 1, 255, &params.shadow))
        return usage_error(cmd, "--shadow '%s': expected 1..255", shadow);
    progress_state ps = {{0}, -1};
    lr_progress progress = {print_progress, &ps};
    lr_gc_map *m;
    lr_err e = {0};
    if (lr_gc_decode_dir(dir, pw, ph, &params, &progress, &m, &e))
        return fail(cmd, &e);
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
            return fail(cmd, &e);
        }
        printf("map (R = projector x, G = y, B = status) -> %s\n", map);
    }
    lr_gc_map_destroy(m);
    return LR_EXIT_OK;
}

static int cmd_projector_calibrate(int argc, char **argv)
{
    const char *dir = NULL, *proj = NULL, *size = NULL, *square = NULL, *pattern = NULL;
    const char *camera = NULL, *contrast = NULL, *shadow = NULL, *window = NULL, *out = NULL;
    const char *subpix = NULL;
    bool fix_aspect = false;
    const char *cmd = "projector calibrate";
    const opt opts[] = {{"captures", &dir, NULL},   {"proj", &proj, NULL},
                        {"board", &size, NULL},     {"square", &square, NULL},
                        {"pattern", &pattern, NULL}, {"camera", &camera, NULL},
                        {"contrast", &contrast, NULL}, {"shadow", &shadow, NULL},
                        {"window", &window, NULL},  {"out", &out, NULL},
                        {"subpix-window", &subpix, NULL}, {"fix-aspect", NULL, &fix_aspect},
                        {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 3, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, dir, "captures")) || (rc = need(cmd, size, "board")) ||
        (rc = need(cmd, square, "square")) || (rc = need(cmd, out, "out")))
        return rc;
    lr_procam_desc d = {.captures = dir, .proj_fix_aspect = fix_aspect};
    if ((rc = parse_board(cmd, size, square, pattern, &d.board)) ||
        (rc = parse_subpix(cmd, subpix, &d.subpix_window)))
        return rc;
    if (proj && !parse_wxh(proj, &d.proj_w, &d.proj_h))
        return usage_error(cmd, "--proj '%s': expected WIDTHxHEIGHT", proj);
    if (contrast && !parse_int(contrast, 1, 255, &d.decode.contrast))
        return usage_error(cmd, "--contrast '%s': expected 1..255", contrast);
    if (shadow && !parse_int(shadow, 1, 255, &d.decode.shadow))
        return usage_error(cmd, "--shadow '%s': expected 1..255", shadow);
    if (window && !parse_int(window, 2, 500, &d.local.half_window))
        return usage_error(cmd, "--window '%s': expected a half-size of 2..500 px", window);
    lr_err e = {0};
    lr_camcal cam;
    if (camera) {
        if (lr_camcal_load(camera, &cam, &e))
            return fail(cmd, &e);
        d.camera = &cam.k;
        d.camera_rms = cam.rms;
    }
    progress_state ps = {{0}, -1};
    lr_progress progress = {print_progress, &ps};
    d.progress = &progress;
    lr_procam p;
    rc = lr_procam_run(&d, &p, &e);
    if (camera)
        lr_camcal_free(&cam);
    if (rc)
        return fail(cmd, &e);
    for (int i = 0; i < p.nrejected; i++)
        fprintf(stderr, "skipped pose %s: %s\n", p.rejected[i].name, p.rejected[i].reason);
    if (lr_procam_save(out, &p, &e)) {
        lr_procam_free(&p);
        return fail(cmd, &e);
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

static int cmd_projector(int argc, char **argv)
{
    const char *sub = argc > 2 ? argv[2] : "";
    if (!strcmp(sub, "patterns"))
        return cmd_projector_patterns(argc, argv);
    if (!strcmp(sub, "capture"))
        return capture_common("projector capture", argc, argv, true);
    if (!strcmp(sub, "decode"))
        return cmd_projector_decode(argc, argv);
    if (!strcmp(sub, "calibrate"))
        return cmd_projector_calibrate(argc, argv);
    return usage_error("projector", "expected patterns, capture, decode or calibrate, got '%s'",
                       sub);
}

/* ---- radiometry ----------------------------------------------------------------------- */

static int cmd_camera_response(int argc, char **argv)
{
    const char *images = NULL, *times = NULL, *out = NULL, *hdr = NULL, *samples = NULL;
    const char *lambda = NULL, *cmd = "camera-response";
    const opt opts[] = {{"images", &images, NULL}, {"times", &times, NULL},
                        {"out", &out, NULL},       {"hdr", &hdr, NULL},
                        {"samples", &samples, NULL}, {"lambda", &lambda, NULL},
                        {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 2, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, images, "images")) || (rc = need(cmd, times, "times")) ||
        (rc = need(cmd, out, "out")))
        return rc;
    double t[LR_CAMRESP_MAX_STACK];
    int nt = lr_args_times(times, t, LR_CAMRESP_MAX_STACK);
    if (nt < 2)
        return usage_error(cmd, "--times '%s': expected 2 or more exposure times, e.g. "
                                "1/30,1/8,0.5", times);
    lr_camresp_desc d = {0};
    if (samples && !parse_int(samples, 10, 100000, &d.samples))
        return usage_error(cmd, "--samples '%s': expected 10..100000", samples);
    if (lambda && !parse_double(lambda, 1e-6, 1e6, &d.lambda))
        return usage_error(cmd, "--lambda '%s': expected a positive number", lambda);
    glob_t g;
    if ((rc = expand(cmd, images, &g)))
        return rc;
    lr_err e = {0};
    if ((int)g.gl_pathc != nt) {
        fprintf(stderr, "lamprig calib %s: %zu images match '%s' but %d times are given\n", cmd,
                g.gl_pathc, images, nt);
        globfree(&g);
        return LR_EXIT_USAGE;
    }
    lr_img imgs[LR_CAMRESP_MAX_STACK];
    int loaded = 0;
    rc = LR_EXIT_OK;
    for (; loaded < nt; loaded++)
        if (lr_img_read(g.gl_pathv[loaded], LR_IMG_RGB8, &imgs[loaded], &e)) {
            rc = fail(cmd, &e);
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
            rc = fail(cmd, &e);
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

static int cmd_projector_response(int argc, char **argv)
{
    const char *sub = argc > 2 ? argv[2] : "";
    if (!strcmp(sub, "capture"))
        return capture_common("projector-response capture", argc, argv, false);
    if (!strcmp(sub, "patterns")) {
        const char *proj = NULL, *out = NULL, *steps = NULL, *cmd = "projector-response patterns";
        const opt opts[] = {{"proj", &proj, NULL}, {"out", &out, NULL}, {"steps", &steps, NULL},
                            {NULL, NULL, NULL}};
        int rc = parse(cmd, argc, argv, 3, opts, NULL, 0, NULL);
        int pw, ph, n = 0;
        if (rc || (rc = need(cmd, proj, "proj")) || (rc = need(cmd, out, "out")))
            return rc;
        if (!parse_wxh(proj, &pw, &ph))
            return usage_error(cmd, "--proj '%s': expected WIDTHxHEIGHT", proj);
        if (steps && !parse_int(steps, 3, 256, &n))
            return usage_error(cmd, "--steps '%s': expected 3..256", steps);
        lr_err e = {0};
        if (lr_projresp_write_patterns(out, pw, ph, n, &e))
            return fail(cmd, &e);
        printf("flat frames (r_/g_/b_LLL.png) -> %s/\n", out);
        return LR_EXIT_OK;
    }
    if (!strcmp(sub, "fit")) {
        const char *dir = NULL, *out = NULL, *camresp = NULL, *cmd = "projector-response fit";
        const opt opts[] = {{"captures", &dir, NULL}, {"out", &out, NULL},
                            {"camera-response", &camresp, NULL}, {NULL, NULL, NULL}};
        int rc = parse(cmd, argc, argv, 3, opts, NULL, 0, NULL);
        if (rc || (rc = need(cmd, dir, "captures")) || (rc = need(cmd, out, "out")))
            return rc;
        lr_err e = {0};
        lr_camresp cam;
        if (camresp && lr_camresp_load(camresp, &cam, &e))
            return fail(cmd, &e);
        lr_projresp *r = malloc(sizeof *r);
        if (!r) {
            lr_err_set(&e, LR_ENOMEM, "out of memory");
            return fail(cmd, &e);
        }
        rc = LR_EXIT_OK;
        if (lr_projresp_measure(dir, camresp ? &cam : NULL, r, &e) ||
            lr_projresp_save(out, r, &e))
            rc = fail(cmd, &e);
        else
            printf("projector response from %d levels: gamma r %.3f g %.3f b %.3f, black %.4f "
                   "%.4f %.4f of white -> %s\n",
                   r->nlevels, r->gamma[0], r->gamma[1], r->gamma[2], r->black[0], r->black[1],
                   r->black[2], out);
        free(r);
        return rc;
    }
    return usage_error("projector-response", "expected patterns, capture or fit, got '%s'", sub);
}

static int cmd_color(int argc, char **argv)
{
    const char *pairs = NULL, *checker = NULL, *camresp = NULL, *out = NULL, *cmd = "color";
    const opt opts[] = {{"pairs", &pairs, NULL}, {"checker", &checker, NULL},
                        {"camera-response", &camresp, NULL}, {"out", &out, NULL},
                        {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 2, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, out, "out")))
        return rc;
    if (!pairs == !checker)
        return usage_error(cmd, "%s", "give exactly one of --pairs FILE or --checker PHOTO");
    lr_err e = {0};
    lr_colormatrix m;
    if (pairs) {
        double *c, *r;
        int n;
        if (lr_colorpairs_load(pairs, &c, &r, &n, &e))
            return fail(cmd, &e);
        rc = lr_colormatrix_fit(c, r, n, &m, &e);
        free(c);
        free(r);
        if (rc)
            return fail(cmd, &e);
    } else {
        lr_camresp cam;
        if (camresp && lr_camresp_load(camresp, &cam, &e))
            return fail(cmd, &e);
        lr_img photo;
        if (lr_img_read(checker, LR_IMG_RGB8, &photo, &e))
            return fail(cmd, &e);
        double measured[72], ref[72];
        rc = lr_colorchecker_measure(&photo, camresp ? &cam : NULL, measured, &e);
        lr_img_free(&photo);
        if (rc) {
            lr_err_prefix(&e, "%s", checker);
            return fail(cmd, &e);
        }
        lr_colorchecker_linear(ref);
        if (lr_colormatrix_fit(measured, ref, 24, &m, &e))
            return fail(cmd, &e);
        snprintf(m.source, sizeof m.source, "colorchecker");
    }
    if (lr_colormatrix_save(out, &m, &e))
        return fail(cmd, &e);
    printf("colour matrix from %d patches (%s): rms %.4f, worst %.4f -> %s\n", m.patches, m.source,
           m.rms, m.max_err, out);
    for (int r = 0; r < 3; r++)
        printf("  [%9.5f %9.5f %9.5f]\n", m.m[3 * r], m.m[3 * r + 1], m.m[3 * r + 2]);
    return LR_EXIT_OK;
}

/* ---- pose ----------------------------------------------------------------------------- */

static bool parse_vec3(const char *s, double v[3])
{
    int n = 0;
    if (!s || sscanf(s, "%lf,%lf,%lf%n", &v[0], &v[1], &v[2], &n) != 3 || s[n] != '\0')
        return false;
    return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
}

/* {"version":1, "kind":"pose_points", "points":[{"scene":[3], "pixel":[2]}, ...]} */
static int load_pose_points(const char *path, double **xyz, double **uv, int *n, lr_err *e)
{
    lr_json *j;
    lr_jnode root, arr;
    int count = 0;
    int rc = lr_calfile_load(path, "pose_points", &j, &root, e);
    if (rc)
        return rc;
    if ((rc = lr_calfile_array(j, root, NULL, "points", &arr, &count, e))) {
        lr_json_destroy(j);
        return rc;
    }
    *xyz = malloc((size_t)(count ? count : 1) * 3 * sizeof **xyz);
    *uv = malloc((size_t)(count ? count : 1) * 2 * sizeof **uv);
    if (!*xyz || !*uv)
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
    for (int i = 0; i < count && !rc; i++) {
        lr_jnode p = lr_json_at(j, arr, i);
        char prefix[32];
        snprintf(prefix, sizeof prefix, "points[%d]", i);
        if ((rc = lr_calfile_numbers(j, p, prefix, "scene", 3, -1e5, 1e5, *xyz + 3 * i, e)))
            break;
        rc = lr_calfile_numbers(j, p, prefix, "pixel", 2, -1e5, 1e5, *uv + 2 * i, e);
    }
    lr_json_destroy(j);
    if (rc) {
        free(*xyz);
        free(*uv);
        *xyz = *uv = NULL;
        return rc;
    }
    *n = count;
    return LR_OK;
}

static int cmd_pose(int argc, char **argv)
{
    const char *image = NULL, *size = NULL, *square = NULL, *pattern = NULL, *origin = NULL;
    const char *xaxis = NULL, *yaxis = NULL, *camera = NULL, *projector = NULL, *out = NULL;
    const char *points = NULL, *cmd = "pose";
    const opt opts[] = {{"image", &image, NULL},       {"board", &size, NULL},
                        {"square", &square, NULL},     {"pattern", &pattern, NULL},
                        {"origin", &origin, NULL},     {"x-axis", &xaxis, NULL},
                        {"y-axis", &yaxis, NULL},      {"camera", &camera, NULL},
                        {"projector", &projector, NULL}, {"out", &out, NULL},
                        {"points", &points, NULL},     {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 2, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, camera, "camera")) || (rc = need(cmd, out, "out")))
        return rc;
    if (!image == !points)
        return usage_error(cmd, "%s", "give exactly one of --image PHOTO or --points FILE");
    lr_board b = {0};
    lr_board_placement pl;
    if (image) {
        if ((rc = need(cmd, size, "board")) || (rc = need(cmd, square, "square")) ||
            (rc = need(cmd, origin, "origin")) || (rc = need(cmd, xaxis, "x-axis")) ||
            (rc = need(cmd, yaxis, "y-axis")) ||
            (rc = parse_board(cmd, size, square, pattern, &b)))
            return rc;
        if (!parse_vec3(origin, pl.origin))
            return usage_error(cmd, "--origin '%s': expected x,y,z (mm)", origin);
        if (!parse_vec3(xaxis, pl.x_axis))
            return usage_error(cmd, "--x-axis '%s': expected x,y,z", xaxis);
        if (!parse_vec3(yaxis, pl.y_axis))
            return usage_error(cmd, "--y-axis '%s': expected x,y,z", yaxis);
    }
    lr_err e = {0};
    lr_camcal cc;
    if (lr_camcal_load(camera, &cc, &e))
        return fail(cmd, &e);
    lr_intrinsics k = cc.k;
    lr_camcal_free(&cc);
    lr_procam pc;
    if (projector && lr_procam_load(projector, &pc, &e))
        return fail(cmd, &e);
    lr_rig_pose p;
    if (image) {
        lr_img gray;
        if (lr_img_read(image, LR_IMG_GRAY8, &gray, &e)) {
            rc = LR_EXIT_FAIL;
        } else {
            rc = lr_rig_pose_from_board(&gray, &b, &pl, &k, projector ? &pc : NULL, &p, &e);
            if (rc)
                lr_err_prefix(&e, "%s", image);
            lr_img_free(&gray);
        }
    } else {
        double *xyz, *uv;
        int n;
        rc = load_pose_points(points, &xyz, &uv, &n, &e);
        if (!rc) {
            rc = lr_rig_pose_from_points(n, xyz, uv, &k, projector ? &pc : NULL, &p, &e);
            free(xyz);
            free(uv);
        }
    }
    if (projector)
        lr_procam_free(&pc);
    if (rc || lr_rig_pose_save(out, &p, &e))
        return fail(cmd, &e);
    lr_vec3 c = lr_pose_center(&p.camera);
    printf("camera at (%.2f, %.2f, %.2f) mm in the scene, %d points, rms %.4f px -> %s\n", c.x,
           c.y, c.z, p.points, p.rms, out);
    if (p.has_projector) {
        lr_vec3 q = lr_pose_center(&p.projector);
        printf("projector at (%.2f, %.2f, %.2f) mm\n", q.x, q.y, q.z);
    }
    return LR_EXIT_OK;
}

/* ---- check ---------------------------------------------------------------------------- */

enum { CHECK_VALID, CHECK_INVALID, CHECK_SKIPPED };

/* Whether path is a calibration file at all: a JSON object with a top-level "kind" (every
 * calibration file has one; rig configs, scenes and materials have none). 1 yes, 0 no, -1 it
 * cannot be read or is not JSON (message in e). */
static int has_kind(const char *path, lr_err *e)
{
    lr_json *j;
    if (lr_json_load(path, &j, e))
        return -1;
    lr_jnode root = lr_json_root(j);
    int yes = lr_json_type(j, root) == LR_JSON_OBJECT && lr_json_get(j, root, "kind") != LR_JNONE;
    lr_json_destroy(j);
    return yes;
}

static bool known_kind(const char *kind)
{
    static const char *const kinds[] = {LR_CAMCAL_KIND,      LR_PROCAM_KIND,  LR_CAMRESP_KIND,
                                        LR_PROJRESP_KIND,    LR_COLORMATRIX_KIND, LR_POSE_KIND,
                                        LR_ALBEDO_KIND,      LR_GC_SEQUENCE_KIND};
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++)
        if (!strcmp(kind, kinds[k]))
            return true;
    return false;
}

/* Checks one file: CHECK_VALID (summary on stdout), CHECK_INVALID (the error on stderr) or
 * CHECK_SKIPPED (valid JSON but not a calibration file: one line on stdout). */
static int check_one(const char *path)
{
    char kind[64];
    lr_err e = {0};
    int k = has_kind(path, &e);
    if (k < 0) {
        fprintf(stderr, "%s\n", e.msg);
        return CHECK_INVALID;
    }
    if (k == 0) {
        printf("%s: not a calibration file (no \"kind\"), skipped\n", path);
        return CHECK_SKIPPED;
    }
    if (lr_calfile_peek_kind(path, kind, sizeof kind, &e)) {
        fprintf(stderr, "%s\n", e.msg);
        return CHECK_INVALID;
    }
    if (!known_kind(kind)) {
        printf("%s: not a calibration file (kind '%s'), skipped\n", path, kind);
        return CHECK_SKIPPED;
    }
    int rc = LR_OK;
    if (!strcmp(kind, LR_CAMCAL_KIND)) {
        lr_camcal c;
        if (!(rc = lr_camcal_load(path, &c, &e))) {
            printf("%s: camera %dx%d, fx %.3f fy %.3f cx %.3f cy %.3f, rms %.4f px, %d views\n",
                   path, c.k.width, c.k.height, c.k.fx, c.k.fy, c.k.cx, c.k.cy, c.rms, c.nviews);
            lr_camcal_free(&c);
        }
    } else if (!strcmp(kind, LR_PROCAM_KIND)) {
        lr_procam p;
        if (!(rc = lr_procam_load(path, &p, &e))) {
            printf("%s: projector %dx%d fx %.3f fy %.3f cx %.3f cy %.3f; camera %dx%d; "
                   "T (%.2f, %.2f, %.2f) mm; stereo rms %.4f px\n",
                   path, p.proj.width, p.proj.height, p.proj.fx, p.proj.fy, p.proj.cx, p.proj.cy,
                   p.cam.width, p.cam.height, p.T[0], p.T[1], p.T[2], p.rms);
            lr_procam_free(&p);
        }
    } else if (!strcmp(kind, LR_CAMRESP_KIND)) {
        lr_camresp r;
        if (!(rc = lr_camresp_load(path, &r, &e)))
            printf("%s: camera response, %d exposures\n", path, r.images);
    } else if (!strcmp(kind, LR_PROJRESP_KIND)) {
        lr_projresp *r = malloc(sizeof *r);
        if (!r)
            rc = lr_err_set(&e, LR_ENOMEM, "out of memory");
        else if (!(rc = lr_projresp_load(path, r, &e)))
            printf("%s: projector response, %d levels, gamma %.3f %.3f %.3f\n", path, r->nlevels,
                   r->gamma[0], r->gamma[1], r->gamma[2]);
        free(r);
    } else if (!strcmp(kind, LR_COLORMATRIX_KIND)) {
        lr_colormatrix m;
        if (!(rc = lr_colormatrix_load(path, &m, &e)))
            printf("%s: colour matrix from %d patches, rms %.4f\n", path, m.patches, m.rms);
    } else if (!strcmp(kind, LR_POSE_KIND)) {
        lr_rig_pose p;
        if (!(rc = lr_rig_pose_load(path, &p, &e))) {
            lr_vec3 c = lr_pose_center(&p.camera);
            printf("%s: pose from %s, camera at (%.2f, %.2f, %.2f) mm, rms %.4f px%s\n", path,
                   p.source, c.x, c.y, c.z, p.rms, p.has_projector ? ", with projector" : "");
        }
    } else if (!strcmp(kind, LR_ALBEDO_KIND)) {
        lr_albedo a;
        if (!(rc = lr_albedo_load(path, &a, &e))) {
            printf("%s: mockup response %dx%d, %ld pixels measured, %ld filled\n", path,
                   a.response.width, a.response.height, a.measured_pixels, a.filled_pixels);
            lr_albedo_free(&a);
        }
    } else if (!strcmp(kind, LR_GC_SEQUENCE_KIND)) {
        char dir[4096];
        snprintf(dir, sizeof dir, "%s", path);
        char *slash = strrchr(dir, '/');
        if (slash)
            *slash = '\0';
        else
            snprintf(dir, sizeof dir, ".");
        int pw, ph;
        if (!(rc = lr_gc_read_sequence(dir, &pw, &ph, &e)))
            printf("%s: Gray-code sequence for a %dx%d projector\n", path, pw, ph);
    }
    if (rc) {
        fprintf(stderr, "%s\n", e.msg);
        return CHECK_INVALID;
    }
    return CHECK_VALID;
}

/* Linear camera image of an 8-bit capture (the calibration's response and colour matrix). */
static int read_linear(const char *path, const lr_rig_calib *cal, lr_image *out, lr_err *e)
{
    lr_img img;
    int rc = lr_img_read(path, LR_IMG_RGB8, &img, e);
    if (rc)
        return rc;
    if ((rc = lr_image_alloc(out, img.w, img.h, e))) {
        lr_img_free(&img);
        return rc;
    }
    const uint8_t *p = img.px;
    for (size_t k = 0; k < (size_t)img.w * img.h; k++) {
        double v[3];
        lr_rig_camera_to_linear(cal, p + 3 * k, v);
        for (int c = 0; c < 3; c++)
            out->rgb[3 * k + c] = (float)v[c];
    }
    lr_img_free(&img);
    return LR_OK;
}

static int cmd_albedo(int argc, char **argv)
{
    const char *dir = NULL, *out = NULL, *cdir = NULL, *proj = NULL, *contrast = NULL,
               *shadow = NULL, *fill = NULL;
    const char *cmd = "albedo";
    const opt opts[] = {{"captures", &dir, NULL}, {"out", &out, NULL},
                        {"calib", &cdir, NULL},   {"proj", &proj, NULL},
                        {"contrast", &contrast, NULL}, {"shadow", &shadow, NULL},
                        {"fill", &fill, NULL},    {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 2, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, dir, "captures")) || (rc = need(cmd, out, "out")))
        return rc;
    int pw = 0, ph = 0, passes = -1;
    lr_gc_params params = {0};
    if (proj && !parse_wxh(proj, &pw, &ph))
        return usage_error(cmd, "--proj '%s': expected WIDTHxHEIGHT", proj);
    if (contrast && !parse_int(contrast, 1, 255, &params.contrast))
        return usage_error(cmd, "--contrast '%s': expected 1..255", contrast);
    if (shadow && !parse_int(shadow, 1, 255, &params.shadow))
        return usage_error(cmd, "--shadow '%s': expected 1..255", shadow);
    if (fill && !parse_int(fill, 0, 64, &passes))
        return usage_error(cmd, "--fill '%s': expected 0..64 passes", fill);
    lr_err e = {0};
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    if (!cal)
        return LR_EXIT_FAIL;
    if (cdir && lr_rig_calib_load(cdir, cal, &e)) {
        free(cal);
        return fail(cmd, &e);
    }
    progress_state ps = {{0}, -1};
    lr_progress progress = {print_progress, &ps};
    lr_gc_map *m = NULL;
    lr_image white = {0}, black = {0};
    lr_albedo a = {0};
    char path[4096];
    int status = LR_EXIT_OK;
    if (lr_gc_decode_dir(dir, pw, ph, &params, &progress, &m, &e)) {
        status = fail(cmd, &e);
        goto done;
    }
    snprintf(path, sizeof path, "%s/white.png", dir);
    if (read_linear(path, cal, &white, &e)) {
        status = fail(cmd, &e);
        goto done;
    }
    snprintf(path, sizeof path, "%s/black.png", dir);
    if (read_linear(path, cal, &black, &e) ||
        lr_albedo_measure(&white, &black, m, passes, &a, &e) || lr_albedo_save(out, &a, &e)) {
        status = fail(cmd, &e);
        goto done;
    }
    lr_gc_map_projector_size(m, &pw, &ph);
    printf("%s: mockup response for a %dx%d projector: %ld pixels measured (%.1f %%), %ld "
           "filled; scale %.4g (camera linear units of full white at M = 1)\n",
           out, pw, ph, a.measured_pixels, 100.0 * a.measured_pixels / ((long)pw * ph),
           a.filled_pixels, a.scale);
done:
    lr_albedo_free(&a);
    lr_image_free(&white);
    lr_image_free(&black);
    lr_gc_map_destroy(m);
    lr_rig_calib_free(cal);
    free(cal);
    return status;
}

static int cmd_ar_frame(int argc, char **argv)
{
    const char *scene_path = NULL, *cdir = NULL, *out = NULL, *tpath = NULL, *gain = NULL,
               *samples = NULL, *rwidth = NULL, *seed = NULL;
    const char *cmd = "ar-frame";
    const opt opts[] = {{"scene", &scene_path, NULL}, {"calib", &cdir, NULL},
                        {"out", &out, NULL},          {"target", &tpath, NULL},
                        {"gain", &gain, NULL},        {"samples", &samples, NULL},
                        {"render-width", &rwidth, NULL}, {"seed", &seed, NULL},
                        {NULL, NULL, NULL}};
    int rc = parse(cmd, argc, argv, 2, opts, NULL, 0, NULL);
    if (rc || (rc = need(cmd, scene_path, "scene")) || (rc = need(cmd, cdir, "calib")) ||
        (rc = need(cmd, out, "out")))
        return rc;
    lr_ar_frame_desc d = {0};
    int sd = 0;
    if (gain && !parse_double(gain, 1e-30, 1e30, &d.gain))
        return usage_error(cmd, "--gain '%s': expected a number > 0", gain);
    if (samples && !parse_int(samples, 1, 1 << 20, &d.samples))
        return usage_error(cmd, "--samples '%s': expected 1..1048576", samples);
    if (rwidth && !parse_int(rwidth, 2, 16384, &d.render_width))
        return usage_error(cmd, "--render-width '%s': expected 2..16384", rwidth);
    if (seed && !parse_int(seed, 1, 1 << 30, &sd))
        return usage_error(cmd, "--seed '%s': expected a whole number > 0", seed);
    d.seed = (unsigned)sd;
    lr_err e = {0};
    lr_scene *scene = NULL;
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    lr_albedo a = {0};
    lr_image levels = {0}, target = {0};
    lr_img png = {0};
    int status = LR_EXIT_FAIL;
    if (!cal)
        return LR_EXIT_FAIL;
    if (lr_scene_load(scene_path, NULL, &scene, &e) || lr_rig_calib_load(cdir, cal, &e)) {
        fail(cmd, &e);
        goto done;
    }
    char apath[4096];
    snprintf(apath, sizeof apath, "%s/%s", cdir, LR_RIG_ALBEDO);
    FILE *f = fopen(apath, "r");
    if (f) {
        fclose(f);
        if (lr_albedo_load(apath, &a, &e)) {
            fail(cmd, &e);
            goto done;
        }
    }
    d.scene = scene;
    d.calib = cal;
    d.response = f ? &a.response : NULL;
    lr_ar_stats st;
    if (lr_ar_frame(&d, &levels, &target, &st, &e) ||
        (tpath && lr_image_write_pfm(tpath, &target, &e)) ||
        lr_img_alloc(&png, levels.width, levels.height, 3, 1, &e)) {
        fail(cmd, &e);
        goto done;
    }
    uint8_t *px = png.px;
    for (size_t k = 0; k < (size_t)levels.width * levels.height * 3; k++)
        px[k] = (uint8_t)lrint(255 * fmin(1.0, fmax(0.0, levels.rgb[k])));
    if (lr_img_write(out, &png, &e)) {
        fail(cmd, &e);
        goto done;
    }
    char msg[128];
    lr_ar_stats_format(&st, msg, sizeof msg);
    printf("%s: %dx%d projector frame, mockup response from %s; gain %.4g; %s (%ld of %ld lit "
           "pixels)\n",
           out, levels.width, levels.height, f ? apath : "the scene's geometry (ideal white)",
           st.gain, msg, st.clipped_pixels, st.lit_pixels);
    status = LR_EXIT_OK;
done:
    lr_img_free(&png);
    lr_image_free(&levels);
    lr_image_free(&target);
    lr_albedo_free(&a);
    lr_rig_calib_free(cal);
    free(cal);
    lr_scene_destroy(scene);
    return status;
}

static int cmd_check(int argc, char **argv)
{
    if (argc < 3)
        return usage_error("check", "%s", "expected one or more calibration files");
    int count[3] = {0};
    for (int i = 2; i < argc; i++)
        count[check_one(argv[i])]++;
    if (argc > 3)
        printf("%d valid, %d invalid, %d not calibration files\n", count[CHECK_VALID],
               count[CHECK_INVALID], count[CHECK_SKIPPED]);
    /* Files that are not calibration files (a glob over a folder that also holds rig configs)
     * do not fail the check; one that is, or claims to be, and does not load does. */
    return count[CHECK_INVALID] ? LR_EXIT_FAIL : LR_EXIT_OK;
}

int lr_cmd_calib(int argc, char **argv)
{
    const char *sub = argc > 1 ? argv[1] : "";
    if (!strcmp(sub, "camera"))
        return cmd_camera(argc, argv);
    if (!strcmp(sub, "projector"))
        return cmd_projector(argc, argv);
    if (!strcmp(sub, "camera-response"))
        return cmd_camera_response(argc, argv);
    if (!strcmp(sub, "projector-response"))
        return cmd_projector_response(argc, argv);
    if (!strcmp(sub, "color"))
        return cmd_color(argc, argv);
    if (!strcmp(sub, "pose"))
        return cmd_pose(argc, argv);
    if (!strcmp(sub, "albedo"))
        return cmd_albedo(argc, argv);
    if (!strcmp(sub, "ar-frame"))
        return cmd_ar_frame(argc, argv);
    if (!strcmp(sub, "check"))
        return cmd_check(argc, argv);
    fprintf(stderr, "%s\n", lr_cmd_calib_usage);
    return LR_EXIT_USAGE;
}
