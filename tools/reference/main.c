/* lamprig-reference: the physical reference renderer (render/reference) on the command line.
 *
 *   lamprig-reference render --scene FILE [--out F.pfm] [--variance F.pfm] [--cache]
 *                            [--cache-dir DIR] [--width N] [--height N] [--spp N]
 *                            [--pass N] [--threads N] [--seed N] [--quiet]
 *   lamprig-reference validate [--photons N] [--threads N] [--seed N]
 *
 * Exit status 0 on success, 1 on a runtime failure, 2 on bad arguments (one line on stderr).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "firmware/args.h"
#include "render/base/json.h"
#include "render/base/progress.h"
#include "render/reference/reference.h"
#include "render/scene/scene.h"

static const char usage[] =
    "usage: lamprig-reference render --scene FILE [options]\n"
    "       lamprig-reference validate [--photons N] [--threads N] [--seed N]\n"
    "\n"
    "render: a volumetric Monte Carlo reference image of a scene file (README, \"Physical\n"
    "reference\"): linear radiance as PFM, and the variance of each pixel's mean.\n"
    "  --scene FILE       reference scene (configs/reference/) or project scene\n"
    "                     (configs/scenes/: objects with meshes, receivers)\n"
    "  --out FILE         mean image, PFM (default build/reference.pfm)\n"
    "  --variance FILE    per-pixel variance of the mean, PFM (default: OUT with .var.pfm)\n"
    "  --cache            reuse or fill build/reference-cache/<key>.pfm (+ .var.pfm, .json)\n"
    "  --cache-dir DIR    the same with another directory\n"
    "  --width N, --height N, --spp N, --seed N   override the scene file's render block\n"
    "  --pass N           samples per pixel per progressive pass (default 4)\n"
    "  --threads N        worker threads (default: all CPUs; the image does not depend on it)\n"
    "  --quiet            no progress lines on stderr (a line rewritten in place on a\n"
    "                     terminal, one a second otherwise; --progress: the default)\n"
    "\n"
    "validate: the published slab benchmarks and the sphere energy balance, by counting\n"
    "photons on the renderer's transport code (default 4000000 photons each).\n";

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* An integer flag in [lo, hi]; returns 0 or prints the error and returns 2. */
static int int_flag(const lr_args *a, const char *flag, long lo, long hi, long *out)
{
    const char *v = lr_args_get(a, flag);
    if (!v)
        return 0;
    double x;
    lr_err e = {0};
    if (lr_args_number(flag, v, &x, &e) || x != (double)(long)x || x < (double)lo ||
        x > (double)hi) {
        fprintf(stderr, "lamprig-reference: %s: expected an integer in %ld..%ld, got '%s'\n",
                flag, lo, hi, v);
        return 2;
    }
    *out = (long)x;
    return 0;
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
    static const lr_argspec specs[] = {
        {.name = "--scene", .type = LR_ARG_STRING},
        {.name = "--out", .type = LR_ARG_STRING},
        {.name = "--variance", .type = LR_ARG_STRING},
        {.name = "--cache"},
        {.name = "--cache-dir", .type = LR_ARG_STRING},
        {.name = "--width", .type = LR_ARG_STRING},
        {.name = "--height", .type = LR_ARG_STRING},
        {.name = "--spp", .type = LR_ARG_STRING},
        {.name = "--pass", .type = LR_ARG_STRING},
        {.name = "--threads", .type = LR_ARG_STRING},
        {.name = "--seed", .type = LR_ARG_STRING},
        {.name = "--progress"},
        {.name = "--quiet"},
        {0},
    };
    lr_args a;
    lr_err e = {0};
    if (lr_args_parse(argc, argv, specs, 0, &a, &e)) {
        fprintf(stderr, "lamprig-reference render: %s\n", e.msg);
        return 2;
    }
    const char *scene = lr_args_get(&a, "--scene");
    if (!scene) {
        fprintf(stderr, "lamprig-reference render: --scene FILE is required\n");
        return 2;
    }
    long w = -1, h = -1, spp = -1, pass = -1, threads = 0, seed = -1;
    if (int_flag(&a, "--width", 1, 16384, &w) || int_flag(&a, "--height", 1, 16384, &h) ||
        int_flag(&a, "--spp", 1, 1L << 30, &spp) || int_flag(&a, "--pass", 1, 1L << 30, &pass) ||
        int_flag(&a, "--threads", 1, 1024, &threads) ||
        int_flag(&a, "--seed", 0, 1L << 53, &seed))
        return 2;
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
    int status = 0;
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
    static const lr_argspec specs[] = {{.name = "--photons", .type = LR_ARG_STRING},
                                       {.name = "--threads", .type = LR_ARG_STRING},
                                       {.name = "--seed", .type = LR_ARG_STRING},
                                       {0}};
    lr_args a;
    lr_err e = {0};
    if (lr_args_parse(argc, argv, specs, 0, &a, &e)) {
        fprintf(stderr, "lamprig-reference validate: %s\n", e.msg);
        return 2;
    }
    long photons = 4000000, threads = 0, seed = 1;
    if (int_flag(&a, "--photons", 2, 1L << 40, &photons) ||
        int_flag(&a, "--threads", 1, 1024, &threads) || int_flag(&a, "--seed", 0, 1L << 53, &seed))
        return 2;
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
    printf("\n%ld photons per problem, %.1f s on %d threads (%.3g photons/s); specular part "
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
        return argc < 2 ? 2 : 0;
    }
    if (!strcmp(argv[1], "render"))
        return cmd_render(argc - 2, argv + 2);
    if (!strcmp(argv[1], "validate"))
        return cmd_validate(argc - 2, argv + 2);
    fprintf(stderr, "lamprig-reference: unknown command '%s' (render, validate, help)\n",
            argv[1]);
    return 2;
}
