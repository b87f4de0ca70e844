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
 * samples/s, pixels) goes to stdout. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/cpu/frame.h"
#include "render/image/image.h"
#include "render/scene/scene.h"
#include "tools/cpuref/compare.h"

static void usage(FILE *f)
{
    fprintf(f, "usage: lamprig-cpuref --scene FILE --out F.pfm [--width W] [--height H] "
               "[--samples N] [--var F.var.pfm] [--twin] [--frames F] [--vpl N] [--no-vpl] "
               "[--threads T] [--seed S] [--set key=value ...] [--compare REF.pfm]\n");
}

static int int_arg(const char *opt, const char *v, int lo, int hi, int *out)
{
    char *end;
    long x = strtol(v, &end, 10);
    if (!*v || *end || x < lo || x > hi) {
        fprintf(stderr, "lamprig-cpuref: %s %s: expected an integer in [%d, %d]\n", opt, v, lo, hi);
        return -1;
    }
    *out = (int)x;
    return 0;
}

int main(int argc, char **argv)
{
    const char *scene_path = NULL, *out = NULL, *var_path = NULL, *compare = NULL;
    lr_cpu_render_desc d = {.mode = LR_CPU_REFERENCE, .width = 160, .height = 120};
    const char *sets[64];
    int nsets = 0, seed = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = i + 1 < argc ? argv[i + 1] : NULL;
        int bad = 0;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            usage(stdout);
            return 0;
        } else if (!strcmp(a, "--twin")) {
            d.mode = LR_CPU_PASS;
            continue;
        } else if (!strcmp(a, "--no-vpl")) {
            d.no_vpl = true;
            continue;
        }
        if (!v) {
            fprintf(stderr, "lamprig-cpuref: %s: missing value\n", a);
            usage(stderr);
            return 2;
        }
        i++;
        if (!strcmp(a, "--scene"))
            scene_path = v;
        else if (!strcmp(a, "--out"))
            out = v;
        else if (!strcmp(a, "--compare"))
            compare = v;
        else if (!strcmp(a, "--var"))
            var_path = v;
        else if (!strcmp(a, "--width"))
            bad = int_arg(a, v, 1, LR_IMAGE_MAX_SIDE, &d.width);
        else if (!strcmp(a, "--height"))
            bad = int_arg(a, v, 1, LR_IMAGE_MAX_SIDE, &d.height);
        else if (!strcmp(a, "--samples"))
            bad = int_arg(a, v, 1, 1 << 24, &d.samples);
        else if (!strcmp(a, "--frames"))
            bad = int_arg(a, v, 1, 1 << 20, &d.frames);
        else if (!strcmp(a, "--vpl"))
            bad = int_arg(a, v, 1, 1 << 20, &d.vpl_count);
        else if (!strcmp(a, "--threads"))
            bad = int_arg(a, v, 1, 64, &d.threads);
        else if (!strcmp(a, "--seed"))
            bad = int_arg(a, v, 1, 1 << 30, &seed);
        else if (!strcmp(a, "--set") && nsets < 64)
            sets[nsets++] = v;
        else {
            fprintf(stderr, "lamprig-cpuref: unknown option '%s'\n", a);
            usage(stderr);
            return 2;
        }
        if (bad)
            return 2;
    }
    if (!scene_path || !out) {
        fprintf(stderr, "lamprig-cpuref: --scene and --out are required\n");
        usage(stderr);
        return 2;
    }
    d.seed = (unsigned)seed;
    lr_err e = {0};
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
