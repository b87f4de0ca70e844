/* lamprig-transrad — seed 000's translucent radiosity on a scene, with its figures: patches,
 * precomputation time, direct-light and solve time, the time after a light move (warm start),
 * residuals, and where the light goes (receivers: direct, indirect, and the shares of the
 * indirect from objects and from receivers; the power that leaves the scene).
 *
 *   lamprig-transrad SCENE.json [--set KEY=VALUE]... [--patch MM] [--receiver MM] [--rays N]
 *                    [--transfer-mb MB] [--thin-wall auto|off|on] [--split] [--no-cache]
 *
 * The options, their defaults and ranges are the table below (firmware/tool.h: `--help` is
 * generated from it; a bad argument is one line naming the flag, exit status 2).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/scene/scene.h"
#include "render/transrad/transrad.h"
#include "firmware/tool.h"
#include "tools/transrad/split.h"

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

#define PROGRAM "lamprig-transrad"
#define MAX_SETS 64

static const lr_argspec opts[] = {
    {.name = "--set", .type = LR_ARG_STRING, .metavar = "KEY=VALUE", .repeat = MAX_SETS,
     .help = "change a scene field first (repeatable)"},
    {.name = "--patch", .type = LR_ARG_NUMBER, .metavar = "MM", .flags = LR_ARG_FLOOR,
     .help = "object patch (cluster cell) edge in mm (default 0: 12 mm)"},
    {.name = "--receiver", .type = LR_ARG_NUMBER, .metavar = "MM", .flags = LR_ARG_FLOOR,
     .help = "receiver grid cell in mm (default 0: 30 mm, at most 64 cells\n"
             "a side)"},
    {.name = "--rays", .type = LR_ARG_INT, .flags = LR_ARG_FLOOR,
     .help = "form-factor rays per patch (default 0: 512)"},
    {.name = "--transfer-mb", .type = LR_ARG_INT, .metavar = "MB", .flags = LR_ARG_FLOOR,
     .help = "build the precomputed transfer within MB (default 0: none,\n"
             "the warm-started sweeps)"},
    {.name = "--thin-wall", .type = LR_ARG_CHOICE, .choices = "auto|off|on",
     .help = "S on slab walls (render/transrad/thinwall.c): by its rule\n"
             "(default), never, on every slab patch"},
    {.name = "--split", .help = "per light and object: where S sends the light that entered, by\n"
                                "distance and facing (split.c)"},
    {.name = "--no-cache", .help = "build F and S even when $XDG_CACHE_HOME/lamprig has them (by\n"
                                   "default they are read from and written to the cache)"},
    {0},
};

static const lr_command tool = {
    .name = PROGRAM,
    .about = "Seed 000's translucent radiosity on a scene, with its figures: patches,\n"
             "precomputation time, direct-light and solve time, the time after a light move\n"
             "(warm start), residuals, and where the light goes.",
    .opts = opts,
    .operands = "SCENE.json",
    .max_operands = 1,
    .notes = "Exit status 0, 1 (failure, message on stderr), 2 (bad arguments).",
};

int main(int argc, char **argv)
{
    lr_args args;
    int status = lr_tool_args(&tool, argc, argv, &args);
    if (status >= 0)
        return status;
    if (args.npos != 1)
        return lr_tool_usage(PROGRAM, "SCENE.json is required");
    char cdir[1024];
    lr_tr_settings set = {.cache_dir = lr_tr_cache_default_dir(cdir, sizeof cdir)};
    lr_err e = {0};
    /* The table's order of --thin-wall's choices is the enum's: auto 0, off 1, on 2. */
    _Static_assert(LR_TR_THIN_AUTO == 0 && LR_TR_THIN_OFF == 1 && LR_TR_THIN_ON == 2,
                   "--thin-wall's choices in the enum's order");
    /* The first reader that refuses its value stops the chain; e says which and why. */
    if (lr_args_double(&args, "--patch", &set.patch_mm, &e) ||
        lr_args_double(&args, "--receiver", &set.receiver_mm, &e) ||
        lr_args_int(&args, "--rays", &set.rays_per_patch, &e) ||
        lr_args_int(&args, "--transfer-mb", &set.transfer_mb, &e) ||
        lr_args_choice(&args, "--thin-wall", &set.thin_wall, &e))
        return lr_tool_usage(PROGRAM, "%s", e.msg);
    if (lr_args_has(&args, "--no-cache"))
        set.cache_dir = NULL;
    int split = lr_args_has(&args, "--split");
    lr_scene *s;
    if (lr_scene_load(args.pos[0], &(const lr_warn_sink){lr_warn_stderr, PROGRAM}, &s, &e)) {
        fprintf(stderr, "lamprig-transrad: %s\n", e.msg);
        return 1;
    }
    const char *sets[MAX_SETS];
    int nsets = lr_args_values(&args, "--set", sets, MAX_SETS);
    for (int i = 0; i < nsets; i++)
        if (lr_scene_set_assignment(s, sets[i], NULL, &e)) {
            fprintf(stderr, "lamprig-transrad: %s\n", e.msg);
            lr_scene_destroy(s);
            return 1;
        }
    double t0 = now_s();
    lr_tr *t;
    if (lr_tr_create_scene(s, &set, &t, &e)) {
        fprintf(stderr, "lamprig-transrad: %s\n", e.msg);
        return 1;
    }
    double t1 = now_s();
    int no = lr_scene_object_count(s), nr = lr_scene_receiver_count(s);
    printf("scene %s: %zu patches (", lr_scene_name(s), lr_tr_patch_count(t));
    for (int i = 0; i < no + nr; i++) {
        size_t f, c;
        lr_tr_surface_patches(t, i, &f, &c);
        printf("%s%zu", i ? " " : "", c);
    }
    size_t xb = lr_tr_transfer_bytes(t);
    printf("), precomputation (F, S%s) %.2f s, transfer %s (%.1f MB)\n",
           lr_tr_cache_hit(t) ? " from the cache" : "", t1 - t0, xb ? "built" : "not built",
           xb / 1048576.0);
    /* Where S sends the light that enters each object: its lit face and the far face, against
     * the slab's R and T where the object has a wall thickness. */
    for (int i = 0; i < no; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        double lit[3], opp[3];
        lr_tr_subsurface_split(t, i, lit, opp);
        printf("object %d: S sends out of the lit face %.4f %.4f %.4f, the opposite face "
               "%.4f %.4f %.4f", i, lit[0], lit[1], lit[2], opp[0], opp[1], opp[2]);
        if (o->thickness_mm > 0) {
            double R[3], T[3];
            lr_multipole_total(&o->coeffs, o->thickness_mm, R, T);
            printf("; slab %.3g mm: R %.4f %.4f %.4f, T %.4f %.4f %.4f, thin wall (rule at %g mm "
                   "patches): %s", o->thickness_mm, R[0], R[1], R[2], T[0], T[1], T[2],
                   set.patch_mm > 0 ? set.patch_mm : 12.0,
                   lr_tr_wall_thin(&o->coeffs, o->thickness_mm,
                                   set.patch_mm > 0 ? set.patch_mm : 12.0) ? "yes" : "no");
        }
        printf("\n");
    }
    for (int l = 0; l < lr_scene_light_count(s) && l < LR_TR_MAX_SLOTS; l++) {
        lr_tr_stats st = {0};
        if (lr_tr_solve_light(t, lr_scene_light_at(s, l), l, &st, &e)) {
            fprintf(stderr, "lamprig-transrad: %s\n", e.msg);
            return 1;
        }
        printf("light %d: direct %.1f ms, solve %.1f ms, %d sweeps, residual after 10 %.2e, "
               "final %.2e\n", l, st.ms_direct, st.ms_solve, st.iterations, st.residual10,
               st.residual);
        /* Receivers: reflected power from direct light and from the bounce; the bounce's
         * sources (objects, receivers) from F row by row. */
        double dir[3] = {0}, ind[3] = {0}, from_obj[3] = {0}, from_rcv[3] = {0};
        size_t n = lr_tr_patch_count(t);
        for (int r = 0; r < nr; r++) {
            const lr_receiver *rc = lr_scene_receiver_at(s, r);
            size_t f, c;
            lr_tr_surface_patches(t, no + r, &f, &c);
            for (size_t p = f; p < f + c; p++) {
                double A, H[3], Hi[3];
                lr_tr_patch_geometry(t, p, NULL, NULL, &A);
                lr_tr_irradiance(t, l, p, H);
                lr_tr_indirect(t, l, p, Hi);
                for (size_t q = 0; q < n; q++) {
                    double F = lr_tr_form_factor(t, p, q);
                    if (F == 0)
                        continue;
                    double W[3];
                    lr_tr_radiosity(t, l, q, W);
                    for (int b = 0; b < 3; b++) {
                        double v = rc->albedo[b] * A * F * W[b];
                        if (lr_tr_patch_surface(t, q) < no)
                            from_obj[b] += v;
                        else
                            from_rcv[b] += v;
                    }
                }
                for (int b = 0; b < 3; b++) {
                    dir[b] += rc->albedo[b] * A * (H[b] - Hi[b]);
                    ind[b] += rc->albedo[b] * A * Hi[b];
                }
            }
        }
        double esc[3];
        lr_tr_escaped_power(t, l, esc);
        printf("  receivers reflect (W per W/sr, R G B): direct %.4g %.4g %.4g, bounce %.4g "
               "%.4g %.4g\n", dir[0], dir[1], dir[2], ind[0], ind[1], ind[2]);
        printf("  bounce from objects %.4g %.4g %.4g, from receivers %.4g %.4g %.4g "
               "(receiver interreflection %.1f %% of the receivers' light, G)\n",
               from_obj[0], from_obj[1], from_obj[2], from_rcv[0], from_rcv[1], from_rcv[2],
               100 * from_rcv[1] / (dir[1] + ind[1]));
        printf("  leaves the scene %.4g %.4g %.4g\n", esc[0], esc[1], esc[2]);
        for (int i = 0; split && i < no; i++)
            lr_trtool_print_split(t, i, l, &lr_scene_object_at(s, i)->coeffs);
        /* A light move: 1 mm along x, warm-started. */
        lr_light moved = *lr_scene_light_at(s, l);
        moved.position.x += 1.0;
        lr_tr_stats sm = {0};
        if (lr_tr_solve_light(t, &moved, l, &sm, &e)) {
            fprintf(stderr, "lamprig-transrad: %s\n", e.msg);
            return 1;
        }
        printf("  after a 1 mm light move (%s): direct %.1f ms, solve %.1f ms, %d sweeps, "
               "residual %.2e\n", sm.transfer ? "transfer" : "warm start", sm.ms_direct,
               sm.ms_solve, sm.iterations, sm.residual);
    }
    lr_tr_destroy(t);
    lr_scene_destroy(s);
    return 0;
}
