/* lamprig-reference: the physical reference renderer (render/reference) on the command line.
 *
 *   lamprig-reference render --scene FILE [OPTIONS]
 *   lamprig-reference validate [--photons N] [--threads N] [--seed N]
 *
 * Each command's options are a table (firmware/tool.h): `COMMAND --help` is generated from it,
 * and a bad argument is one line naming the flag with exit status 2.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "firmware/tool.h"
#include "render/base/json.h"
#include "render/base/progress.h"
#include "render/reference/reference.h"
#include "render/scene/scene.h"

#define PROGRAM "lamprig-reference"

static const lr_argspec render_opts[] = {
    {.name = "--scene", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED,
     .help = "reference scene (configs/reference/) or project scene\n"
             "(configs/scenes/: objects with meshes, receivers)"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "F.pfm",
     .help = "mean image, PFM (default build/reference.pfm)"},
    {.name = "--variance", .type = LR_ARG_PATH, .metavar = "F.pfm",
     .help = "per-pixel variance of the mean, PFM (default: OUT with .var.pfm)"},
    {.name = "--cache", .help = "reuse or fill build/reference-cache/<key>.pfm (+ .var.pfm, .json)"},
    {.name = "--cache-dir", .type = LR_ARG_PATH, .metavar = "DIR",
     .help = "the same with another directory"},
    {.name = "--width", .type = LR_ARG_INT, .metavar = "N", .min = 1, .max = 16384,
     .help = "image width (default: the scene file's render block)"},
    {.name = "--height", .type = LR_ARG_INT, .metavar = "N", .min = 1, .max = 16384,
     .help = "image height (default: the scene file's render block)"},
    {.name = "--spp", .type = LR_ARG_INT, .metavar = "N", .min = 1, .max = 1 << 30,
     .help = "samples per pixel (default: the scene file's render block)"},
    {.name = "--pass", .type = LR_ARG_INT, .metavar = "N", .min = 1, .max = 1 << 30,
     .help = "samples per pixel per progressive pass (default 4)"},
    {.name = "--threads", .type = LR_ARG_INT, .metavar = "N", .min = 1, .max = 1024,
     .help = "worker threads (default: all CPUs; the image does not depend on it)"},
    {.name = "--seed", .type = LR_ARG_INT, .metavar = "N", .flags = LR_ARG_FLOOR,
     .max = 9007199254740992.0, .help = "sample seed, 0..2^53 (default: the scene file's)"},
    {.name = "--progress", .help = "progress lines on stderr (the default)"},
    {.name = "--quiet", .help = "no progress lines on stderr (a line rewritten in place on a\n"
                                "terminal, one a second otherwise)"},
    {0},
};

static const lr_command render_cmd = {
    .name = PROGRAM " render",
    .about = "A volumetric Monte Carlo reference image of a scene file (README, \"Physical\n"
             "reference\"): linear radiance as PFM, and the variance of each pixel's mean.",
    .opts = render_opts,
    .notes = "A summary line (time, samples, cache key) goes to stdout. Exit status 0, 1\n"
             "(failure, message on stderr), 2 (bad arguments).",
};

static const lr_argspec validate_opts[] = {
    {.name = "--photons", .type = LR_ARG_INT, .metavar = "N", .min = 2, .max = 1099511627776.0,
     .help = "photons per problem (default 4000000)"},
    {.name = "--threads", .type = LR_ARG_INT, .metavar = "N", .min = 1, .max = 1024,
     .help = "worker threads (default: all CPUs)"},
    {.name = "--seed", .type = LR_ARG_INT, .metavar = "N", .flags = LR_ARG_FLOOR,
     .max = 9007199254740992.0, .help = "photon seed, 0..2^53 (default 1)"},
    {0},
};

static const lr_command validate_cmd = {
    .name = PROGRAM " validate",
    .about = "The published slab benchmarks and the sphere energy balance, by counting photons\n"
             "on the renderer's transport code.",
    .opts = validate_opts,
    .notes = "A markdown table goes to stdout. Exit status 0, 1 (failure), 2 (bad arguments).",
};

static const char usage[] =
    "Usage: " PROGRAM " COMMAND [OPTIONS]\n"
    "\n"
    "The physical reference renderer (render/reference) on the command line.\n"
    "\n"
    "Commands:\n"
    "  render      a reference image of a scene file, PFM with its variance\n"
    "  validate    the published slab benchmarks and the sphere energy balance\n"
    "\n"
    "`" PROGRAM " COMMAND --help` gives a command's options.\n";

/* The value of a whole-number option given, or dflt. */
static int int64_opt(const lr_command *cmd, const lr_args *a, const char *flag, long long dflt,
                     long long *out)
{
    lr_err e = {0};
    *out = dflt;
    if (lr_args_has(a, flag) && lr_args_int64(a, flag, out, &e))
        return lr_tool_usage(cmd->name, "%s", e.msg);
    return 0;
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The passes' progress through the one printer (render/base/progress.h). */
static void show_progress(const lr_ref_render *r, void *user)
{
    lr_progress_report(user, "spp", lr_ref_render_spp_done(r), lr_ref_render_spp_total(r));
}

/* A project scene (render/scene) has receivers or objects with a "mesh"; a reference scene
 * file (render/reference) has neither. */
static bool is_project_scene(const char *path)
{
    lr_json *j;
    if (lr_json_load(path, &j, NULL))
        return false; /* the reference loader will report it */
    lr_jnode root = lr_json_root(j), objs = lr_json_get(j, root, "objects");
    bool project = lr_json_get(j, root, "receivers") != LR_JNONE ||
                   (lr_json_count(j, objs) > 0 &&
                    lr_json_get(j, lr_json_at(j, objs, 0), "mesh") != LR_JNONE);
    lr_json_destroy(j);
    return project;
}

static int cmd_render(int argc, char **argv)
{
    lr_args a;
    int status = lr_tool_args(&render_cmd, argc, argv, &a);
    if (status >= 0)
        return status;
    const char *scene = lr_args_get(&a, "--scene");
    long long w, h, spp, pass, threads, seed;
    if ((status = int64_opt(&render_cmd, &a, "--width", -1, &w)) ||
        (status = int64_opt(&render_cmd, &a, "--height", -1, &h)) ||
        (status = int64_opt(&render_cmd, &a, "--spp", -1, &spp)) ||
        (status = int64_opt(&render_cmd, &a, "--pass", -1, &pass)) ||
        (status = int64_opt(&render_cmd, &a, "--threads", 0, &threads)) ||
        (status = int64_opt(&render_cmd, &a, "--seed", -1, &seed)))
        return status;
    lr_err e = {0};
    lr_ref_camera cam = {0};
    lr_ref_render_desc d = {0};
    lr_ref_scene *s = NULL;
    lr_scene *project = NULL;
    if (is_project_scene(scene) ? lr_scene_load(scene, &(const lr_warn_sink){lr_warn_stderr, "lamprig-reference"}, &project, &e) ||
                                      lr_ref_scene_from_scene(project, &s, &cam, &e)
                                : lr_ref_scene_load(scene, &s, &cam, &d, &e)) {
        fprintf(stderr, "lamprig-reference: %s\n", e.msg);
        lr_scene_destroy(project);
        return 1;
    }
    if (w > 0)
        d.width = (int)w;
    if (h > 0)
        d.height = (int)h;
    if (spp > 0)
        d.spp = (int)spp;
    if (pass > 0)
        d.spp_per_pass = (int)pass;
    if (seed >= 0)
        d.seed = (uint64_t)seed;
    d.threads = (int)threads;

    const char *out = lr_args_get(&a, "--out");
    if (!out)
        out = "build/reference.pfm";
    char varbuf[4096];
    const char *var = lr_args_get(&a, "--variance");
    if (!var) {
        size_t n = strlen(out);
        if (n > 4 && !strcmp(out + n - 4, ".pfm"))
            n -= 4;
        snprintf(varbuf, sizeof varbuf, "%.*s.var.pfm", (int)n, out);
        var = varbuf;
    }
    double t0 = now();
    lr_progress_meter *pm = NULL;
    if (lr_progress_meter_create(
            &(lr_progress_meter_desc){.prefix = "lamprig-reference",
                                      .style = lr_args_has(&a, "--quiet") ? LR_PROGRESS_QUIET
                                                                          : LR_PROGRESS_AUTO},
            &pm, &e)) {
        fprintf(stderr, "lamprig-reference: %s\n", e.msg);
        lr_ref_scene_destroy(s);
        lr_scene_destroy(project);
        return 1;
    }
    void *pr = (void *)lr_progress_meter_sink(pm);
    lr_ref_image mean = {0}, vimg = {0};
    lr_ref_stats stats = {0};
    status = 0;
    bool hit = false;
    const char *cache_dir = lr_args_get(&a, "--cache-dir");
    if (cache_dir || lr_args_has(&a, "--cache")) {
        if (lr_ref_render_cached(s, &cam, &d, cache_dir, show_progress, pr,
                                 &(const lr_warn_sink){lr_warn_stderr, "lamprig-reference"},
                                 &mean, &vimg, &hit, &e))
            status = 1;
    } else {
        lr_ref_render *r = NULL;
        if (lr_ref_render_create(s, &cam, &d, &r, &e) ||
            lr_ref_render_run(r, show_progress, pr, &e) || lr_ref_render_mean(r, &mean, &e) ||
            lr_ref_render_variance(r, &vimg, &e))
            status = 1;
        if (r)
            stats = *lr_ref_render_stats(r);
        lr_ref_render_destroy(r);
    }
    lr_progress_meter_destroy(pm);
    if (!status && (lr_image_write_pfm(out, &mean, &e) || lr_image_write_pfm(var, &vimg, &e)))
        status = 1;
    if (status) {
        fprintf(stderr, "lamprig-reference: %s\n", e.msg);
    } else {
        double el = now() - t0;
        char key[17];
        lr_ref_cache_key(s, &cam, &d, key);
        printf("reference %s: %dx%d, key %s%s\n", scene, mean.width, mean.height, key,
               hit ? " (from the cache)" : "");
        if (stats.paths)
            printf("  %llu paths in %.2f s: %.3g paths/s on %d threads; NEE %llu (%llu "
                   "refracted, %llu unsolved), truncated %llu, non-finite %llu\n",
                   (unsigned long long)stats.paths, el, (double)stats.paths / el,
                   threads > 0 ? (int)threads : lr_ref_cpu_count(),
                   (unsigned long long)stats.nee, (unsigned long long)stats.nee_refracted,
                   (unsigned long long)stats.nee_unsolved, (unsigned long long)stats.truncated,
                   (unsigned long long)stats.nonfinite);
        printf("  wrote %s and %s\n", out, var);
    }
    lr_ref_image_free(&mean);
    lr_ref_image_free(&vimg);
    lr_ref_scene_destroy(s);
    lr_scene_destroy(project); /* after s: s borrows its meshes */
    return status;
}

static void row(const char *name, lr_ref_estimate x, double published)
{
    if (x.se > 0.0)
        printf("| %s | %.5f ± %.5f | %.5f | %+.1f |\n", name, x.value, x.se, published,
               (x.value - published) / x.se);
    else /* every photon carried the same tally: no sampling error to compare with */
        printf("| %s | %.5f (no variance) | %.5f | %s |\n", name, x.value, published,
               x.value == published ? "exact" : "differs");
}

static int cmd_validate(int argc, char **argv)
{
    lr_args a;
    int status = lr_tool_args(&validate_cmd, argc, argv, &a);
    if (status >= 0)
        return status;
    long long photons, threads, seed;
    if ((status = int64_opt(&validate_cmd, &a, "--photons", 4000000, &photons)) ||
        (status = int64_opt(&validate_cmd, &a, "--threads", 0, &threads)) ||
        (status = int64_opt(&validate_cmd, &a, "--seed", 1, &seed)))
        return status;
    lr_err e = {0};
    double t0 = now();
    lr_ref_slab_problem gio = {.albedo = 0.9, .g = 0.0, .eta = 1.5, .optical_depth = INFINITY,
                               .photons = (uint64_t)photons, .seed = (uint64_t)seed,
                               .threads = (int)threads};
    lr_ref_slab_problem vdh = {.albedo = 0.9, .g = 0.75, .eta = 1.0, .optical_depth = 2.0,
                               .photons = (uint64_t)photons, .seed = (uint64_t)seed + 1,
                               .threads = (int)threads};
    lr_ref_slab_result rg, rv;
    lr_ref_sphere_problem sp = {.medium = {.sigma_s = {1, 1, 1}, .eta = 1.5}, .radius = 1.0,
                                .photons = (uint64_t)photons, .seed = (uint64_t)seed + 2,
                                .threads = (int)threads};
    lr_ref_escape_result esc;
    if (lr_ref_slab_rt(&gio, &rg, &e) || lr_ref_slab_rt(&vdh, &rv, &e) ||
        lr_ref_sphere_escape(&sp, &esc, &e)) {
        fprintf(stderr, "lamprig-reference: %s\n", e.msg);
        return 1;
    }
    double el = now() - t0;
    printf("| quantity | this tracer (± 1 standard error) | published | deviation / SE |\n");
    printf("|---|---|---|---|\n");
    row("semi-infinite, a = 0.9, g = 0, n = 1.5: total reflectance (Giovanelli 1955)",
        rg.r_total, 0.2600);
    row("slab tau = 2, a = 0.9, g = 0.75, n = 1: reflectance (van de Hulst 1980)", rv.r_total,
        0.09739);
    row("slab tau = 2, a = 0.9, g = 0.75, n = 1: total transmittance (van de Hulst 1980)",
        rv.t_total, 0.66096);
    row("sphere, sigma_a = 0, n = 1.5, point light inside: escaping power / 4 pi I", esc.escaped,
        1.0);
    printf("\n%lld photons per problem, %.1f s on %d threads (%.3g photons/s); specular part "
           "of the first: %.5f (Fresnel at normal incidence 0.04); unscattered part of the "
           "transmittance: %.5f (exp(-2) = 0.13534)\n",
           photons, el, threads > 0 ? (int)threads : lr_ref_cpu_count(),
           3.0 * (double)photons / el, rg.r_specular.value, rv.t_unscattered.value);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "help") || !strcmp(argv[1], "--help") ||
        !strcmp(argv[1], "-h")) {
        fputs(usage, argc < 2 ? stderr : stdout);
        return argc < 2 ? LR_EXIT_USAGE : LR_EXIT_OK;
    }
    /* argv[1] stands in for the program name: lr_tool_args reads from argv[1] on. */
    if (!strcmp(argv[1], "render"))
        return cmd_render(argc - 1, argv + 1);
    if (!strcmp(argv[1], "validate"))
        return cmd_validate(argc - 1, argv + 1);
    return lr_tool_usage(PROGRAM, "unknown command '%s' (render, validate)", argv[1]);
}
