/* lamprig fit — arguments, captures, the fit (calib/fit.h), a GPU confirmation render, the
 * material preset written atomically after the material loader accepted it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/fit.h"
#include "calib/fit_captures.h"
#include "calib/fit_checks.h"
#include "calib/rig.h"
#include "firmware/commands/commands.h"
#include "render/base/atomic_file.h"
#include "render/base/json.h"
#include "render/diffusion/dfit.h"
#include "render/gl/gl.h"
#include "render/material/material.h"
#include "render/renderer.h"

static int run_fit(const lr_cli *c);

/* The data do not determine the material (calib/fit_checks.h): nothing written. */
enum { FIT_EXIT_WEAK = 3 };

static const lr_argspec opts[] = {
    {.name = "--diffusion", .type = LR_ARG_PATH, .metavar = "CAPTURES", .flags = LR_ARG_ALONE,
     .help = "inverse diffusion (seed 001): a block sample's captures under projector patterns\n"
             "(format in render/diffusion/dfit.h) to a per-voxel volume file, --out F.vol;\n"
             "--max-evals sets the conjugate-gradient iterations (default 150)"},
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED,
     .help = "the scene; its camera must be the rig's camera"},
    {.name = "--captures", .type = LR_ARG_STRING, .metavar = "IMG[,IMG...]",
     .flags = LR_ARG_REQUIRED,
     .help = "8-bit photos of the lit object (one, or an exposure stack)"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "MATERIAL.json", .flags = LR_ARG_REQUIRED,
     .help = "the material preset written (configs/materials format)"},
    {.name = "--calib", .type = LR_ARG_PATH, .metavar = "DIR",
     .help = "the calibration folder: camera response and colour matrix"},
    {.name = "--gamma", .type = LR_ARG_NUMBER, .metavar = "G", .min = 0.1, .max = 10,
     .help = "the camera's response when DIR has no camera_response.json (or\n"
             "there is no --calib): value v is exposure (v/128)^G; default 2.2\n"
             "(an sRGB camera), the rule lamprig compare and lamprig-capsim\n"
             "use; refused beside camera_response.json"},
    {.name = "--times", .type = LR_ARG_NUMBERS, .metavar = "T1,T2,...",
     .help = "their exposure times, s (default 1)"},
    {.name = "--object", .type = LR_ARG_STRING, .metavar = "NAME",
     .help = "the object fitted (default the first)"},
    {.name = "--scale-preset", .type = LR_ARG_STRING, .metavar = "NAME",
     .help = "fit two scales (sigma_a, sigma_s') on the preset NAME instead of\n"
             "sigma per band"},
    {.name = "--start-sigma-a", .type = LR_ARG_TRIPLE, .metavar = "R,G,B",
     .flags = LR_ARG_ABOVE_MIN, .help = "start of the search, mm^-1 (with --start-sigma-s)"},
    {.name = "--start-sigma-s", .type = LR_ARG_TRIPLE, .metavar = "R,G,B",
     .flags = LR_ARG_ABOVE_MIN, .help = "start of the search, mm^-1 (with --start-sigma-a)"},
    {.name = "--size", .type = LR_ARG_SIZE, .min = 2, .max = 4096,
     .help = "model resolution (default 64x48; the captures' aspect)"},
    {.name = "--samples", .type = LR_ARG_INT, .min = 2, .max = 1 << 20,
     .help = "reference samples per band per pixel (default 128)"},
    {.name = "--capture-scale", .type = LR_ARG_NUMBER, .metavar = "S", .flags = LR_ARG_ABOVE_MIN,
     .help = "camera exposure units per W/(mm^2 sr) (default render.exposure)"},
    {.name = "--huber", .type = LR_ARG_NUMBER, .metavar = "H", .flags = LR_ARG_ABOVE_MIN,
     .help = "Huber threshold, fraction of the mean capture (default 0.1)"},
    {.name = "--max-evals", .type = LR_ARG_INT, .min = 3, .max = 100000,
     .help = "model evaluations per band (default 200)"},
    {.name = "--seed", .type = LR_ARG_INT, .min = 1, .max = 1 << 30,
     .help = "the reference renderer's random seed (default 1)"},
    {.name = "--threads", .type = LR_ARG_INT, .min = 1, .max = 1024,
     .help = "worker threads (default: all CPUs)"},
    {.name = "--name", .type = LR_ARG_STRING, .metavar = "NAME",
     .help = "the preset's name (default: the --out file's base name)"},
    {.name = "--no-gpu-check", .help = "skip the confirmation render on the GPU"},
    {.name = "--accept-weak",
     .help = "write the material even when the data do not determine it (too few\n"
             "unclipped pixels, most of the object clipped, a flat residual, a\n"
             "parameter at its bound, a residual over twice the noise): warned,\n"
             "not refused"},
    LR_CLI_QUIET_OPT,
    {0},
};

const lr_command lr_fit_command = {
    .name = "fit",
    .summary = "fit a material (sigma_a, sigma_s' per band, or two scales on a preset) to "
               "captures of the lit object",
    .about =
        "Fits the object's material so that the CPU reference render of the scene's camera view\n"
        "matches the captures (linearised with the calibration folder's camera response and colour\n"
        "matrix; several exposures are merged to HDR with --times). The scene's camera must be the\n"
        "rig's camera. Nelder-Mead in log sigma per band (or on two scales of the preset NAME with\n"
        "--scale-preset), Huber loss over the object's pixels; the result is confirmed with one GPU\n"
        "render. Prints parameters, residual (relative RMSE), iterations and time; writes the\n"
        "material preset (configs/materials format) atomically.",
    .opts = opts,
    .notes = "Progress (evaluations, uncertainty, GPU check frames) goes to stderr; --quiet turns it\n"
             "off. Exit status: 0 success, 1 failure (the output is left as it was), 2 bad\n"
             "arguments, 3 a weak fit refused: the captures do not determine the material (the\n"
             "check and its figures are named, with the exposure-stack command that recovers\n"
             "clipped pixels; nothing written; --accept-weak writes it anyway).",
    .run = run_fit,
};

/* JSON string body with quotes and backslashes escaped (names and paths only). */
static void json_escape(const char *s, char *buf, size_t cap)
{
    size_t k = 0;
    for (; *s && k + 3 < cap; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            buf[k++] = '\\';
        buf[k++] = c < 0x20 ? '?' : (char)c;
    }
    buf[k] = 0;
}

/* The preset, validated by the material loader before it replaces anything. */
static int write_material(const char *path, const char *name, const char *source,
                          const lr_medium *m, lr_err *e)
{
    char ename[256], esrc[1024], text[4096];
    json_escape(name, ename, sizeof ename);
    json_escape(source, esrc, sizeof esrc);
    int n = snprintf(text, sizeof text,
                     "{\n  \"name\": \"%s\",\n  \"source\": \"%s\",\n"
                     "  \"sigma_a\": [%.6g, %.6g, %.6g],\n"
                     "  \"sigma_s_prime\": [%.6g, %.6g, %.6g],\n"
                     "  \"eta\": %.6g,\n  \"g\": %.6g\n}\n",
                     ename, esrc, m->sigma_a[0], m->sigma_a[1], m->sigma_a[2],
                     m->sigma_s_prime[0], m->sigma_s_prime[1], m->sigma_s_prime[2], m->eta, m->g);
    if (n < 0 || (size_t)n >= sizeof text)
        return lr_err_set(e, LR_EINVAL, "%s: material text too long", path);
    lr_json *j;
    int rc = lr_json_parse(text, (size_t)n, path, &j, e);
    if (rc)
        return rc;
    lr_material check;
    rc = lr_material_from_json(j, lr_json_root(j), "material", &check, e);
    lr_json_destroy(j);
    if (rc)
        return lr_err_prefix(e, "%s: the fitted material does not validate", path);
    return lr_atomic_write(path, text, (size_t)n, e);
}

/* One GPU render of the fitted scene at the fit's size, converged; its relative RMSE against
 * the captures over the object's pixels. */
static int gpu_check(lr_scene *scene, int object, const lr_image *target,
                     const lr_progress *progress, double *rel, double *ms, lr_err *e)
{
    lr_gl *gl = NULL;
    lr_renderer *r = NULL;
    lr_image img = {0};
    float *rgb = NULL;
    unsigned char *mask = NULL;
    int w = target->width, h = target->height, rc;
    if ((rc = lr_gl_create(NULL, &gl, e)) ||
        (rc = lr_renderer_create(&(lr_renderer_desc){.gl = gl, .scene = scene, .width = w,
                                                     .height = h},
                                 &r, e)))
        goto done;
    *ms = 0;
    int frames = lr_scene_render(scene)->frames;
    lr_progress_report(progress, "GPU check frame", 0, frames);
    for (int i = 0; i < 100000 && lr_renderer_needs_frame(r); i++) {
        lr_frame_stats st;
        if ((rc = lr_renderer_frame(r, &st, e)))
            goto done;
        *ms += st.total_ms;
        lr_progress_report(progress, "GPU check frame", i + 1, frames);
    }
    rgb = malloc(sizeof(float) * 3 * (size_t)w * h);
    mask = malloc((size_t)w * h);
    if (!rgb || !mask) {
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
        goto done;
    }
    if ((rc = lr_renderer_read_hdr(r, rgb, e)) || (rc = lr_image_alloc(&img, w, h, e)))
        goto done;
    for (int y = 0; y < h; y++) /* GL rows bottom to top */
        memcpy(img.rgb + (size_t)y * w * 3, rgb + (size_t)(h - 1 - y) * w * 3,
               sizeof(float) * 3 * (size_t)w);
    lr_fit_object_mask(scene, object, w, h, mask);
    *rel = lr_fit_rel_rmse(&img, target, mask, NULL);
done:
    lr_image_free(&img);
    free(rgb);
    free(mask);
    lr_renderer_destroy(r);
    lr_gl_destroy(gl);
    return rc;
}

/* lamprig fit --diffusion CAPTURES --out F.vol (render/diffusion/dfit.h). */
static int run_fit_diffusion(const lr_cli *c)
{
    const lr_args *a = &c->args;
    lr_err e = {0};
    const char *out = lr_args_get(a, "--out");
    if (!out)
        return lr_cli_usage(c->path, "--diffusion needs --out F.vol");
    lr_dfit_desc d = {.captures = lr_args_get(a, "--diffusion"), .out = out};
    int st = lr_cli_check(c, lr_args_int(a, "--max-evals", &d.max_iter, &e), &e);
    if (st)
        return st;
    lr_dfit_result r;
    if (lr_dfit_run(&d, &r, &e))
        return e.code == LR_EPARSE || e.code == LR_EINVAL ? lr_cli_usage(c->path, "%s", e.msg)
                                                          : lr_cli_fail(c->path, "%s", e.msg);
    printf("fit --diffusion: %d patterns, %d observations, %d unknowns per band\n", r.patterns,
           r.observations, r.unknowns_per_band);
    for (int ch = 0; ch < 3; ch++)
        printf("  band %d: homogeneous D %.4g mm mu %.4g /mm (misfit %.3e); per voxel misfit %.3e\n",
               ch, r.homogeneous_D[ch], r.homogeneous_mu[ch], r.misfit_homogeneous[ch],
               r.misfit[ch]);
    printf("wrote %s (%d regions)\n", out, r.regions);
    return LR_EXIT_OK;
}

/* What the refusal names: the command run, to say the one that would work. */
typedef struct weak_ctx {
    const lr_cli *c;
    const char *scene, *calib, *captures;
    int ncaptures;
    double time; /* the (first) capture's exposure time, s */
    const char *out;
    int w, h;
    long clipped;
} weak_ctx;

/* The refusal: the checks that failed with their figures, then what to do -- an exposure
 * stack when pixels are clipped (lr_fit_load_captures merges it, so the clipped ones come
 * back), a larger --size when the object is small in the view. FIT_EXIT_WEAK. */
static int weak_refuse(const weak_ctx *k, const char *why)
{
    fprintf(stderr, "lamprig fit: weak fit refused, nothing written (exit 3): the captures do "
                    "not determine the material. %s\n", why);
    char cal[1024] = "";
    if (k->calib)
        snprintf(cal, sizeof cal, " --calib %s", k->calib);
    if (k->clipped > 0) {
        /* the first capture's name without its extension, for the shots added */
        char base[1024];
        snprintf(base, sizeof base, "%.*s", (int)strcspn(k->captures, ","), k->captures);
        char *dot = strrchr(base, '.');
        if (dot && !strchr(dot, '/'))
            *dot = 0;
        double t = k->time;
        fprintf(stderr,
                "  An exposure stack brings the clipped pixels back: add shots at 1/4 and 1/16 "
                "of the exposure time (%g s; shorter still while the shortest clips) and fit "
                "them together:\n",
                t);
        if (k->ncaptures == 1 && k->calib)
            fprintf(stderr,
                    "    lamprig-capsim --scene %s --calib %s --exposure %g --out %s_4.png "
                    "(simulated; on the rig, the same view at %g s)\n"
                    "    lamprig-capsim --scene %s --calib %s --exposure %g --out %s_16.png\n",
                    k->scene, k->calib, t / 4, base, t / 4, k->scene, k->calib, t / 16, base);
        if (k->ncaptures == 1)
            fprintf(stderr,
                    "    lamprig fit --scene %s%s --captures %s,%s_4.png,%s_16.png --times "
                    "%g,%g,%g --out %s --size %dx%d\n",
                    k->scene, cal, k->captures, base, base, t, t / 4, t / 16, k->out, k->w,
                    k->h);
        else /* a stack that still clips: shorter shots on top of it */
            fprintf(stderr,
                    "    lamprig fit --scene %s%s --captures %s,%s_4.png,%s_16.png --times "
                    "<yours>,%g,%g --out %s --size %dx%d\n",
                    k->scene, cal, k->captures, base, base, t / 4, t / 16, k->out, k->w, k->h);
    } else {
        fprintf(stderr, "  The object is small in the view: a larger --size (now %dx%d) gives "
                        "it more pixels.\n",
                k->w, k->h);
    }
    fprintf(stderr, "  --accept-weak writes the material anyway.\n");
    return FIT_EXIT_WEAK;
}

static int run_fit(const lr_cli *c)
{
    const lr_args *a = &c->args;
    lr_err e = {0};
    if (lr_args_has(a, "--diffusion"))
        return run_fit_diffusion(c);
    const char *scene_path = lr_args_get(a, "--scene"), *caps = lr_args_get(a, "--captures"),
               *out = lr_args_get(a, "--out");
    lr_fit_desc d = {.samples = 128};
    int w = 64, h = 48, seed = 0, n3 = 0;
    double times[16], scale = 0, gamma = 0;
    int ntimes = 0;
    int st = lr_cli_check(
        c, lr_args_size(a, "--size", &w, &h, &e) || lr_args_int(a, "--samples", &d.samples, &e) ||
               lr_args_int(a, "--max-evals", &d.max_evals, &e) ||
               lr_args_int(a, "--threads", &d.threads, &e) ||
               lr_args_list(a, "--times", times, 16, &ntimes, &e) ||
               lr_args_double(a, "--capture-scale", &scale, &e) ||
               lr_args_double(a, "--huber", &d.huber, &e) ||
               lr_args_double(a, "--gamma", &gamma, &e) ||
               lr_args_list(a, "--start-sigma-a", d.sigma_a_start, 3, &n3, &e) ||
               lr_args_list(a, "--start-sigma-s", d.sigma_s_start, 3, &n3, &e) ||
               lr_args_int(a, "--seed", &seed, &e),
        &e);
    if (st)
        return st;
    d.seed = (unsigned)seed;
    if (lr_args_has(a, "--start-sigma-a") != lr_args_has(a, "--start-sigma-s"))
        return lr_cli_usage(c->path, "--start-sigma-a and --start-sigma-s go together");
    /* captures: a comma-separated list */
    char *list = strdup(caps);
    if (!list)
        return lr_cli_fail(c->path, "out of memory");
    const char *paths[16];
    int n = 0;
    for (char *t = strtok(list, ","); t && n < 16; t = strtok(NULL, ","))
        paths[n++] = t;
    if (ntimes && ntimes != n) {
        free(list);
        return lr_cli_usage(c->path, "--times needs one time per capture");
    }
    if (n > 1 && !ntimes) {
        free(list);
        return lr_cli_usage(c->path, "several captures are an exposure stack: give --times");
    }

    int status = LR_EXIT_FAIL;
    lr_scene *scene = NULL;
    lr_progress_meter *pm = lr_cli_progress(c);
    lr_rig_calib *cal = calloc(1, sizeof *cal);
    lr_image target = {0};
    if (!cal) {
        free(list);
        lr_progress_meter_destroy(pm);
        return LR_EXIT_FAIL;
    }
    lr_warn_sink warn = lr_cli_warn_sink(c->path);
    if (lr_scene_load(scene_path, &warn, &scene, &e)) {
        status = e.code == LR_EIO ? lr_cli_fail(c->path, "%s", e.msg)
                                  : lr_cli_usage(c->path, "%s", e.msg);
        goto done;
    }
    const char *oname = lr_args_get(a, "--object");
    d.object = oname ? lr_scene_find_object(scene, oname) : 0;
    if (d.object < 0) {
        status = lr_cli_usage(c->path, "--object %s: no such object in %s", oname, scene_path);
        goto done;
    }
    const char *preset = lr_args_get(a, "--scale-preset");
    if (preset) {
        char key[64];
        snprintf(key, sizeof key, "objects[%d].material", d.object);
        if (lr_scene_set(scene, key, preset, NULL, &e)) {
            status = lr_cli_usage(c->path, "%s", e.msg);
            goto done;
        }
        d.mode = LR_FIT_SCALE;
    }
    const char *cdir = lr_args_get(a, "--calib");
    if (cdir && lr_rig_calib_load(cdir, cal, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    if (gamma > 0 && lr_rig_set_gamma(cal, gamma, &e)) {
        status = lr_cli_usage(c->path, "%s", e.msg);
        goto done;
    }
    /* Said before the work: an assumed response is the first suspect of a bad fit. */
    char resp[256];
    printf("lamprig fit: captures read with %s\n", lr_rig_response_name(cal, resp, sizeof resp));
    if (!scale)
        scale = lr_scene_render(scene)->exposure;
    if (lr_fit_load_captures(paths, ntimes ? times : NULL, n, cal, w, h, scale, &target, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    unsigned char *om = malloc((size_t)w * h);
    if (!om) {
        lr_err_set(&e, LR_ENOMEM, "out of memory");
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    long inside = lr_fit_object_mask(scene, d.object, w, h, om), clipped = 0;
    for (size_t p = 0; p < (size_t)w * h; p++)
        clipped += om[p] && !isfinite(target.rgb[3 * p]);
    free(om);
    if (clipped) /* said: a mostly clipped object is fitted from what is left */
        printf("lamprig fit: %ld of the object's %ld pixels left out: they touch capture "
               "pixels clipped (some channel >= 250, or black) in every capture\n",
               clipped, inside);
    /* Refused before the work when the data cannot carry it (the checks that need no fit). */
    char why[1536];
    bool accept = lr_args_has(a, "--accept-weak");
    unsigned weak = lr_fit_check_data(d.mode, inside, inside - clipped, why, sizeof why);
    weak_ctx wk = {c, scene_path, cdir, caps, n, ntimes ? times[0] : 1.0, out, w, h, clipped};
    if (weak && !accept) {
        status = weak_refuse(&wk, why);
        goto done;
    }
    d.scene = scene;
    d.target = &target;
    d.progress = lr_progress_meter_sink(pm);
    lr_fit_result r;
    int frc = lr_fit_run(&d, &r, &e);
    if (frc) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    const lr_scene_object *o = lr_scene_object_at(scene, d.object);
    printf("lamprig fit: %s object '%s', %d x %d, %ld object pixels, %d samples\n",
           lr_scene_name(scene), o->name, w, h, r.mask_pixels, d.samples);
    static const char *band[3] = {"R", "G", "B"};
    if (d.mode == LR_FIT_SCALE)
        printf("  scales on '%s': sigma_a x %.4g (+-%.2g log), sigma_s' x %.4g (+-%.2g log), "
               "%d iterations, %d evaluations\n",
               preset, r.scale[0], r.stderr_log[0][0], r.scale[1], r.stderr_log[0][1],
               r.iterations[0], r.evals[0]);
    for (int b = 0; b < 3; b++) {
        printf("  %s: sigma_a %.5g mm^-1 (+-%.2g log)  sigma_s' %.5g mm^-1 (+-%.2g log)  "
               "rel RMSE %.4f",
               band[b], r.sigma_a[b], r.stderr_log[d.mode == LR_FIT_SCALE ? 0 : b][0],
               r.sigma_s_prime[b], r.stderr_log[d.mode == LR_FIT_SCALE ? 0 : b][1],
               r.rel_rmse[b]);
        if (d.mode == LR_FIT_SIGMA)
            printf("  %d iterations, %d evaluations", r.iterations[b], r.evals[b]);
        printf("\n");
    }
    printf("  residual: relative RMSE %.4f (start %.4f), %d renders, %.2f s\n", r.rel_rmse_all,
           r.start_rel_rmse, r.renders, r.seconds);
    if (!lr_args_has(a, "--no-gpu-check")) {
        double rel = 0, ms = 0;
        lr_err ge = {0};
        if (gpu_check(scene, d.object, &target, lr_progress_meter_sink(pm), &rel, &ms, &ge))
            printf("  GPU check: not run (%s)\n", ge.msg);
        else
            printf("  GPU check: relative RMSE %.4f against the captures (CPU reference %.4f), "
                   "%.0f ms\n",
                   rel, r.rel_rmse_all, ms);
    }
    weak = lr_fit_check_result(d.mode, &r, why, sizeof why);
    char weak_names[96] = "";
    lr_fit_check_names(weak, weak_names, sizeof weak_names);
    if (weak && !accept) {
        status = weak_refuse(&wk, why);
        goto done;
    }
    if (weak)
        fprintf(stderr, "lamprig fit: warning: weak fit written (--accept-weak): %s\n", why);
    char name[LR_MATERIAL_NAME_MAX];
    const char *nm = lr_args_get(a, "--name");
    if (!nm) {
        const char *base = strrchr(out, '/');
        base = base ? base + 1 : out;
        size_t len = strcspn(base, ".");
        snprintf(name, sizeof name, "%.*s", (int)(len < sizeof name ? len : sizeof name - 1),
                 base);
        nm = name;
    }
    char source[1024];
    snprintf(source, sizeof source,
             "lamprig fit: %s, object '%s', %d capture(s) from %s read with %s, %s, relative "
             "RMSE %.4f over %ld pixels at %d x %d%s%s",
             scene_path, o->name, n, paths[0], resp,
             d.mode == LR_FIT_SCALE ? "two scales on a preset" : "sigma per band",
             r.rel_rmse_all, r.mask_pixels, w, h, weak ? "; WEAK, accepted: " : "",
             weak_names);
    if (write_material(out, nm, source, &o->material.medium, &e)) {
        status = lr_cli_fail(c->path, "%s", e.msg);
        goto done;
    }
    printf("  wrote %s\n", out);
    status = LR_EXIT_OK;
done:
    lr_progress_meter_destroy(pm);
    lr_image_free(&target);
    lr_rig_calib_free(cal);
    free(cal);
    lr_scene_destroy(scene);
    free(list);
    return status;
}
