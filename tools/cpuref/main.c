/* lamprig-cpuref: the converged CPU reference of a scene's camera view (render/cpu/frame.h),
 * or with --twin the CPU twin of the GPU renderer, written as linear PFM plus a variance PFM.
 *
 *   lamprig-cpuref --scene FILE [--width W] [--height H] [--samples N] --out F.pfm
 *                  [--var F.var.pfm] [--twin [--frames F]] [--vpl N] [--no-vpl]
 *                  [--threads T] [--seed S] [--set key=value ...] [--compare REF.pfm]
 *
 * --compare: also print the errors against a physical reference image of the same size
 * (`lamprig-reference render`, REF.var.pfm beside it) on the bench's masks (compare.c).
 * --samples: reference samples per band per pixel and per VPL (default 1024). The variance
 * image defaults to the --out name with ".var.pfm" for ".pfm". A summary line (time, samples,
 * samples/s, pixels) goes to stdout. The options are the table below (firmware/tool.h: its
 * --help is generated from it, a bad argument is one line naming the flag, exit 2). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/cpu/frame.h"
#include "render/image/image.h"
#include "render/scene/scene.h"
#include "firmware/tool.h"
#include "tools/cpuref/compare.h"

#define PROGRAM "lamprig-cpuref"
#define MAX_SETS 64

static const lr_argspec opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED,
     .help = "the scene file (configs/scenes/)"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "F.pfm", .flags = LR_ARG_REQUIRED,
     .help = "the image, linear PFM"},
    {.name = "--var", .type = LR_ARG_PATH, .metavar = "F.var.pfm",
     .help = "the variance image (default: the --out name with .var.pfm for .pfm)"},
    {.name = "--width", .type = LR_ARG_INT, .metavar = "W", .min = 1, .max = LR_IMAGE_MAX_SIDE,
     .help = "image width in pixels (default 160)"},
    {.name = "--height", .type = LR_ARG_INT, .metavar = "H", .min = 1, .max = LR_IMAGE_MAX_SIDE,
     .help = "image height in pixels (default 120)"},
    {.name = "--samples", .type = LR_ARG_INT, .min = 1, .max = 1 << 24,
     .help = "reference samples per band per pixel and per VPL (default 1024)"},
    {.name = "--twin",
     .help = "the CPU twin of the GPU renderer instead of the converged reference"},
    {.name = "--frames", .type = LR_ARG_INT, .metavar = "F", .min = 1, .max = 1 << 20,
     .help = "frames the twin accumulates (default: the scene's render.frames)"},
    {.name = "--vpl", .type = LR_ARG_INT, .min = 1, .max = 1 << 20,
     .help = "virtual point lights (default: render.N_vpl with --twin, else 1024)"},
    {.name = "--no-vpl", .help = "no virtual point lights (direct light and the maps only)"},
    {.name = "--threads", .type = LR_ARG_INT, .metavar = "T", .min = 1, .max = 64,
     .help = "worker threads (default: every CPU)"},
    {.name = "--seed", .type = LR_ARG_INT, .metavar = "S", .min = 1, .max = 1 << 30,
     .help = "sample seed (default 1)"},
    {.name = "--set", .type = LR_ARG_STRING, .metavar = "key=value", .repeat = MAX_SETS,
     .help = "change a scene field before rendering (repeatable)"},
    {.name = "--compare", .type = LR_ARG_PATH, .metavar = "REF.pfm",
     .help = "also print the errors against a physical reference of the same\n"
             "size (`lamprig-reference render`, REF.var.pfm beside it) on the\n"
             "bench's masks"},
    {0},
};

static const lr_command tool = {
    .name = PROGRAM,
    .about = "The converged CPU reference of a scene's camera view (render/cpu/frame.h), or with\n"
             "--twin the CPU twin of the GPU renderer, written as linear PFM plus a variance PFM.",
    .opts = opts,
    .notes = "A summary line (time, samples, samples/s, pixels) goes to stdout. Exit status 0, 1\n"
             "(failure, message on stderr), 2 (bad arguments).",
};

int main(int argc, char **argv)
{
    lr_cpu_render_desc d = {.mode = LR_CPU_REFERENCE, .width = 160, .height = 120};
    int seed = 1;
    lr_args args;
    int status = lr_tool_args(&tool, argc, argv, &args);
    if (status >= 0)
        return status;
    lr_err e = {0};
    static const char *const ints[] = {"--width", "--height", "--samples", "--frames",
                                       "--vpl",   "--threads", "--seed"};
    int *dest[] = {&d.width, &d.height, &d.samples, &d.frames, &d.vpl_count, &d.threads, &seed};
    for (size_t k = 0; k < sizeof ints / sizeof ints[0]; k++)
        if (lr_args_int(&args, ints[k], dest[k], &e))
            return lr_tool_usage(PROGRAM, "%s", e.msg);
    if (lr_args_has(&args, "--twin"))
        d.mode = LR_CPU_PASS;
    d.no_vpl = lr_args_has(&args, "--no-vpl");
    const char *scene_path = lr_args_get(&args, "--scene"), *out = lr_args_get(&args, "--out");
    const char *var_path = lr_args_get(&args, "--var"), *compare = lr_args_get(&args, "--compare");
    const char *sets[MAX_SETS];
    int nsets = lr_args_values(&args, "--set", sets, MAX_SETS);
    d.seed = (unsigned)seed;
    lr_scene *s;
    if (lr_scene_load(scene_path, &(const lr_warn_sink){lr_warn_stderr, "lamprig-cpuref"}, &s, &e)) {
        fprintf(stderr, "lamprig-cpuref: %s\n", e.msg);
        return 1;
    }
    for (int i = 0; i < nsets; i++)
        if (lr_scene_set_assignment(s, sets[i], NULL, &e)) {
            fprintf(stderr, "lamprig-cpuref: --set %s: %s\n", sets[i], e.msg);
            lr_scene_destroy(s);
            return 1;
        }
    d.scene = s;
    char vbuf[4096];
    if (!var_path) {
        size_t n = strlen(out);
        if (n >= 4 && !strcmp(out + n - 4, ".pfm"))
            snprintf(vbuf, sizeof vbuf, "%.*s.var.pfm", (int)(n - 4), out);
        else
            snprintf(vbuf, sizeof vbuf, "%s.var.pfm", out);
        var_path = vbuf;
    }
    lr_image rgb, var;
    lr_cpu_render_stats st;
    int rc = lr_cpu_render(&d, &rgb, &var, &st, &e);
    if (!rc && !(rc = lr_image_write_pfm(out, &rgb, &e)))
        rc = lr_image_write_pfm(var_path, &var, &e);
    if (rc)
        fprintf(stderr, "lamprig-cpuref: %s\n", e.msg);
    else
        printf("lamprig-cpuref: %s %dx%d %s: %.2f s, %.3g samples, %.3g samples/s, %ld object "
               "pixels (%ld by fallback), %d VPLs -> %s, %s\n",
               lr_scene_name(s), d.width, d.height, d.mode == LR_CPU_PASS ? "twin" : "reference",
               st.seconds, st.samples, st.samples_per_s, st.object_pixels, st.fallback_pixels,
               st.vpls, out, var_path);
    if (!rc && compare && (rc = lr_cpuref_compare(s, &rgb, compare, stdout, &e)))
        fprintf(stderr, "lamprig-cpuref: --compare: %s\n", e.msg);
    lr_image_free(&rgb);
    lr_image_free(&var);
    lr_scene_destroy(s);
    return rc ? 1 : 0;
}
