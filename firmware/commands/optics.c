/* lamprig optics — a designer's view of a material: the standard dipole profile (and its
 * plot), total diffuse reflectance, and directional dipole values, as JSON on stdout.
 * Bad arguments: one line on stderr, exit status 2. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/commands/commands.h"
#include "firmware/profile_plot.h"
#include "render/material/material.h"
#include "render/optics/optics.h"

/* Profile points when the plot chooses the radii. */
#define PLOT_POINTS 200
/* Most radii accepted in --r. */
#define MAX_RADII 4096

/* Options every material-taking subcommand accepts, followed by its own. */
#define MATERIAL_OPTS                                                                           \
    {.name = "--material", .type = LR_ARG_STRING, .metavar = "NAME", .group = "MATERIAL",       \
     .help = "a preset, configs/materials/NAME.json; or the four below"},                      \
    {.name = "--sigma-a", .type = LR_ARG_TRIPLE, .metavar = "R,G,B", .group = "MATERIAL",      \
     .help = "absorption, mm^-1, >= 0"},                                                       \
    {.name = "--sigma-s-prime", .type = LR_ARG_TRIPLE, .metavar = "R,G,B",                     \
     .group = "MATERIAL", .help = "reduced scattering, mm^-1, >= 0"},                          \
    {.name = "--eta", .type = LR_ARG_NUMBER, .metavar = "E", .group = "MATERIAL",              \
     .help = "relative index of refraction inside/outside"},                                   \
    {.name = "--g", .type = LR_ARG_NUMBER, .metavar = "G", .group = "MATERIAL",                \
     .help = "Henyey-Greenstein mean cosine, default 0"}

#define VECTOR(flag, what)                                                                      \
    {.name = flag, .type = LR_ARG_TRIPLE, .metavar = "x,y,z", .flags = LR_ARG_REQUIRED,        \
     .help = what}

static int run_profile(const lr_cli *c);
static int run_total(const lr_cli *c);
static int run_dirpole(const lr_cli *c);
static int run_materials(const lr_cli *c);

static const lr_argspec profile_opts[] = {
    MATERIAL_OPTS,
    {.name = "--r", .type = LR_ARG_NUMBERS, .metavar = "r1,r2,...",
     .help = "radii, mm (>= 0; default with --plot: 200 log-spaced)"},
    {.name = "--plot", .type = LR_ARG_PATH, .metavar = "FILE.png",
     .help = "draw R_d(r) log-log into FILE.png (written atomically)"},
    {0},
};
static const lr_argspec total_opts[] = {MATERIAL_OPTS, {0}};
static const lr_argspec dirpole_opts[] = {
    MATERIAL_OPTS,
    VECTOR("--xi", "where light enters, mm"),
    VECTOR("--ni", "the outward normal at x_i"),
    VECTOR("--wi", "from x_i toward the light (w_i . n_i >= 0)"),
    VECTOR("--xo", "where light leaves, mm"),
    VECTOR("--no", "the outward normal at x_o"),
    {0},
};
static const lr_argspec no_opts[] = {{0}};

#define MATERIAL_NOTE                                                                           \
    "MATERIAL is either --material NAME (a preset, configs/materials/NAME.json) or --sigma-a,\n" \
    "--sigma-s-prime and --eta (with --g, default 0)."
#define EXIT_NOTE                                                                               \
    "Exit status: 0 done; 1 a preset file is broken or the plot could not be written;\n"        \
    "2 bad arguments (one line on stderr)."

static const lr_command profile_cmd = {
    .name = "profile",
    .summary = "standard dipole R_d(r) of Jensen et al. 2001, mm^-2, per band:\n"
               "{\"r\":[...],\"Rd\":[[R,G,B],...]}\n"
               "--plot draws R_d(r) log-log into FILE.png (written atomically). Without --r the\n"
               "plot uses 200 radii log-spaced from 1/20 of the shortest mean free path to where\n"
               "the slowest band has decayed by e^-10 (at most 1000 mean free paths).",
    .opts = profile_opts,
    .notes = MATERIAL_NOTE "\n\n" EXIT_NOTE "\n\nExample:\n"
             "  lamprig optics profile --material candle_wax --r 0.5,1,2,4,8 --plot wax.png",
    .run = run_profile,
};
static const lr_command total_cmd = {
    .name = "total",
    .summary = "{\"Rd_total\":[R,G,B],\"sigma_tr\":[R,G,B],\"albedo\":[R,G,B]}: closed-form total\n"
               "diffuse reflectance, effective transport coefficient (mm^-1), reduced albedo\n"
               "sigma_s'/(sigma_a + sigma_s').",
    .opts = total_opts,
    .notes = MATERIAL_NOTE "\n\n" EXIT_NOTE "\n\nExample:\n  lamprig optics total --material marble",
    .run = run_total,
};
static const lr_command dirpole_cmd = {
    .name = "dirpole",
    .summary = "directional dipole S_d of Frisvad et al. 2014, mm^-2 sr^-1:\n"
               "{\"sd\":[R,G,B],\"sd_fresnel\":[R,G,B]}. x_i, n_i: where light enters and the\n"
               "outward normal there; w_i points from x_i toward the light (w_i . n_i >= 0);\n"
               "x_o, n_o: where it leaves. sd excludes the boundary Fresnel transmission,\n"
               "sd_fresnel = sd * F_t(w_i). Directions are normalised; zero length is an error.",
    .opts = dirpole_opts,
    .notes = MATERIAL_NOTE "\n\n" EXIT_NOTE "\n\nExample:\n"
             "  lamprig optics dirpole --material marble --xi 0,0,0 --ni 0,0,1 --wi 0,0,1 \\\n"
             "      --xo 1,0,0 --no 0,0,1",
    .run = run_dirpole,
};
static const lr_command materials_cmd = {
    .name = "materials",
    .summary = "the preset names MATERIAL can use, a JSON array.",
    .opts = no_opts,
    .notes = EXIT_NOTE,
    .run = run_materials,
};

const lr_command lr_optics_command = {
    .name = "optics",
    .summary = "optics of a material: dipole profile, plot, totals, directional dipole",
    .about = "A designer's view of a material, as JSON on stdout (numbers printed with 17 significant\n"
             "digits: they read back to the same double). Units: mm, mm^-1.",
    .notes =
        "MATERIAL is either\n"
        "  --material NAME                a preset, configs/materials/NAME.json\n"
        "or\n"
        "  --sigma-a R,G,B                absorption, mm^-1, >= 0\n"
        "  --sigma-s-prime R,G,B          reduced scattering, mm^-1, >= 0\n"
        "  --eta E                        relative index of refraction inside/outside\n"
        "  [--g G]                        Henyey-Greenstein mean cosine, default 0\n"
        "\n" EXIT_NOTE "\n"
        "\n"
        "Examples:\n"
        "  lamprig optics total --material marble\n"
        "  lamprig optics profile --material candle_wax --r 0.5,1,2,4,8 --plot wax.png\n"
        "  lamprig optics profile --sigma-a 0.002,0.004,0.007 --sigma-s-prime 2.2,2.6,3 --eta 1.5 \\\n"
        "      --plot custom.png\n"
        "  lamprig optics dirpole --material marble --xi 0,0,0 --ni 0,0,1 --wi 0,0,1 \\\n"
        "      --xo 1,0,0 --no 0,0,1",
    .subs = (const lr_command *const[]){&profile_cmd, &total_cmd, &dirpole_cmd, &materials_cmd, NULL},
};

/* Resolves the material options into a medium and a title. Returns LR_EXIT_OK or the exit
 * status to return (the message is already printed). */
static int get_material(const lr_cli *c, lr_medium *m, char *title, size_t cap)
{
    const lr_args *a = &c->args;
    const char *name = lr_args_get(a, "--material");
    const char *sa = lr_args_get(a, "--sigma-a"), *ss = lr_args_get(a, "--sigma-s-prime");
    const char *eta = lr_args_get(a, "--eta"), *g = lr_args_get(a, "--g");
    lr_err e = {0};
    if (name) {
        if (sa || ss || eta || g)
            return lr_cli_usage(c->path, "--material cannot be combined with --sigma-a, "
                                         "--sigma-s-prime, --eta or --g");
        if (!lr_material_name_ok(name))
            return lr_cli_usage(c->path, "--material: '%s' is not a preset name", name);
        char **names = NULL;
        int count = 0, known = 0;
        if (lr_material_names(&names, &count, &e) != LR_OK)
            return lr_cli_fail(c->path, "%s", e.msg);
        for (int i = 0; i < count && !known; i++)
            known = strcmp(names[i], name) == 0;
        lr_material_names_free(names, count);
        if (!known)
            return lr_cli_usage(c->path,
                                "--material: no preset '%s' (`lamprig optics materials` lists them)",
                                name);
        lr_material mat;
        if (lr_material_find(name, &mat, &e) != LR_OK)
            return lr_cli_fail(c->path, "%s", e.msg);
        *m = mat.medium;
        snprintf(title, cap, "%s", mat.name);
        return LR_EXIT_OK;
    }
    if (!sa || !ss || !eta)
        return lr_cli_usage(c->path, "give --material NAME, or --sigma-a, --sigma-s-prime and --eta");
    memset(m, 0, sizeof *m);
    int n = 0;
    if (lr_args_list(a, "--sigma-a", m->sigma_a, 3, &n, &e) ||
        lr_args_list(a, "--sigma-s-prime", m->sigma_s_prime, 3, &n, &e) ||
        lr_args_double(a, "--eta", &m->eta, &e) || lr_args_double(a, "--g", &m->g, &e))
        return lr_cli_usage(c->path, "%s", e.msg);
    for (int i = 0; i < 3; i++)
        if (m->sigma_a[i] < 0 || m->sigma_s_prime[i] < 0)
            return lr_cli_usage(c->path, "%s: component %d is negative (coefficients are >= 0)",
                                m->sigma_a[i] < 0 ? "--sigma-a" : "--sigma-s-prime", i + 1);
    if (lr_medium_validate(m, &e) != LR_OK)
        return lr_cli_usage(c->path, "%s", e.msg);
    snprintf(title, cap, "sigma_a %.3g,%.3g,%.3g  sigma_s' %.3g,%.3g,%.3g  eta %.3g", m->sigma_a[0],
             m->sigma_a[1], m->sigma_a[2], m->sigma_s_prime[0], m->sigma_s_prime[1],
             m->sigma_s_prime[2], m->eta);
    return LR_EXIT_OK;
}

/* JSON output. %.17g reads back to the same double; JSON has no NaN/Inf, so a non-finite
 * result is reported as a failure rather than printed. */
static int all_finite(const double *v, int n)
{
    for (int i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return 0;
    return 1;
}

static void print_triple(const double v[3])
{
    printf("[%.17g,%.17g,%.17g]", v[0], v[1], v[2]);
}

static int nonfinite(const lr_cli *c, const char *what)
{
    return lr_cli_fail(c->path, "internal error: %s is not finite", what);
}

/* Radii for the plot when --r is absent: log-spaced over the scales the profile lives on. */
static int default_radii(const lr_coeffs *c, double *r, int n)
{
    double mfp_min = INFINITY, mfp_max = 0, reach = 0;
    for (int b = 0; b < 3; b++) {
        mfp_min = fmin(mfp_min, c->mfp[b]);
        mfp_max = fmax(mfp_max, c->mfp[b]);
        if (c->sigma_tr[b] > 0)
            reach = fmax(reach, 10.0 / c->sigma_tr[b]); /* R_d ~ e^{-sigma_tr r} */
    }
    double lo = mfp_min / 20.0;
    double hi = reach > 0 ? reach : 1000.0 * mfp_max;
    hi = fmin(fmax(hi, 20.0 * mfp_max), 1000.0 * mfp_max);
    for (int i = 0; i < n; i++)
        r[i] = lo * pow(hi / lo, (double)i / (n - 1));
    return n;
}

static int run_profile(const lr_cli *c)
{
    const lr_args *a = &c->args;
    int st;
    lr_medium m;
    char title[160];
    if ((st = get_material(c, &m, title, sizeof title)))
        return st;
    const char *rtext = lr_args_get(a, "--r"), *plot = lr_args_get(a, "--plot");
    if (!rtext && !plot)
        return lr_cli_usage(c->path, "profile needs --r r1,r2,... (or --plot FILE.png)");
    lr_err e = {0};
    lr_coeffs co;
    if (lr_coeffs_derive(&m, &co, &e) != LR_OK)
        return lr_cli_usage(c->path, "%s", e.msg);

    int n = 0;
    double *r = malloc(MAX_RADII * sizeof *r);
    double(*rd)[3] = malloc(MAX_RADII * sizeof *rd);
    if (!r || !rd) {
        free(r);
        free(rd);
        return lr_cli_fail(c->path, "out of memory");
    }
    if (rtext) {
        if (lr_args_list(a, "--r", r, MAX_RADII, &n, &e) != LR_OK) {
            st = lr_cli_usage(c->path, "%s", e.msg);
            goto out;
        }
        for (int i = 0; i < n; i++) {
            if (r[i] < 0) {
                st = lr_cli_usage(c->path, "--r: radius %d is %g; radii are >= 0 (mm)", i + 1,
                                  r[i]);
                goto out;
            }
        }
    } else {
        n = default_radii(&co, r, PLOT_POINTS);
    }
    for (int i = 0; i < n; i++) {
        lr_dipole_rd(&co, r[i], rd[i]);
        if (!all_finite(rd[i], 3)) {
            st = nonfinite(c, "R_d(r)");
            goto out;
        }
    }
    if (plot) {
        if (lr_profile_plot_png(plot, title, "r (mm)", "R_d(r) (1/mm^2)", r,
                                (const double(*)[3])rd, n, &e) != LR_OK) {
            st = e.code == LR_EINVAL ? lr_cli_usage(c->path, "--plot: %s", e.msg)
                                     : lr_cli_fail(c->path, "--plot: %s", e.msg);
            goto out;
        }
    }
    printf("{\"r\":[");
    for (int i = 0; i < n; i++)
        printf("%s%.17g", i ? "," : "", r[i]);
    printf("],\"Rd\":[");
    for (int i = 0; i < n; i++) {
        printf("%s", i ? "," : "");
        print_triple(rd[i]);
    }
    printf("]}\n");
    st = LR_EXIT_OK;
out:
    free(r);
    free(rd);
    return st;
}

static int run_total(const lr_cli *c)
{
    int st;
    lr_medium m;
    char title[160];
    if ((st = get_material(c, &m, title, sizeof title)))
        return st;
    lr_err e = {0};
    lr_coeffs co;
    if (lr_coeffs_derive(&m, &co, &e) != LR_OK)
        return lr_cli_usage(c->path, "%s", e.msg);
    double total[3];
    lr_dipole_rd_total(&co, total);
    if (!all_finite(total, 3) || !all_finite(co.sigma_tr, 3) || !all_finite(co.albedo_prime, 3))
        return nonfinite(c, "a total");
    printf("{\"Rd_total\":");
    print_triple(total);
    printf(",\"sigma_tr\":");
    print_triple(co.sigma_tr);
    printf(",\"albedo\":");
    print_triple(co.albedo_prime);
    printf("}\n");
    return LR_EXIT_OK;
}

/* A position (any finite point) or, with unit != 0, a direction normalised to unit length. */
static int get_vec(const lr_cli *c, const char *flag, int unit, lr_vec3 *out)
{
    double v[3];
    int n = 0;
    lr_err e = {0};
    if (lr_args_list(&c->args, flag, v, 3, &n, &e) != LR_OK)
        return lr_cli_usage(c->path, "%s", e.msg);
    lr_vec3 p = lr_v3(v[0], v[1], v[2]);
    if (unit) {
        double len = lr_v3_len(p);
        if (!(len > 0) || !isfinite(len))
            return lr_cli_usage(c->path, "%s: a direction must have non-zero, finite length",
                                flag);
        p = lr_v3_scale(p, 1.0 / len);
    }
    *out = p;
    return LR_EXIT_OK;
}

static int run_dirpole(const lr_cli *c)
{
    int st;
    lr_medium m;
    char title[160];
    if ((st = get_material(c, &m, title, sizeof title)))
        return st;
    lr_vec3 xi, ni, wi, xo, no;
    if ((st = get_vec(c, "--xi", 0, &xi)) || (st = get_vec(c, "--ni", 1, &ni)) ||
        (st = get_vec(c, "--wi", 1, &wi)) || (st = get_vec(c, "--xo", 0, &xo)) ||
        (st = get_vec(c, "--no", 1, &no)))
        return st;
    /* Light arriving from inside the medium at x_i is not what S_d describes. */
    if (lr_v3_dot(wi, ni) < 0)
        return lr_cli_usage(c->path, "%s",
                            "--wi points below the surface at x_i (w_i . n_i < 0); w_i points "
                            "from x_i toward the light");
    lr_err e = {0};
    lr_coeffs co;
    if (lr_coeffs_derive(&m, &co, &e) != LR_OK)
        return lr_cli_usage(c->path, "%s", e.msg);
    double sd[3], sdf[3];
    lr_dirpole_sd(&co, xi, ni, wi, xo, no, sd);
    lr_dirpole_sd_fresnel(&co, xi, ni, wi, xo, no, sdf);
    if (!all_finite(sd, 3) || !all_finite(sdf, 3))
        return nonfinite(c, "S_d");
    printf("{\"sd\":");
    print_triple(sd);
    printf(",\"sd_fresnel\":");
    print_triple(sdf);
    printf("}\n");
    return LR_EXIT_OK;
}

static int run_materials(const lr_cli *c)
{
    char **names = NULL;
    int count = 0;
    lr_err e = {0};
    if (lr_material_names(&names, &count, &e) != LR_OK)
        return lr_cli_fail(c->path, "%s", e.msg);
    /* Preset names are plain (letters, digits, _-.): nothing to escape in JSON. */
    printf("[");
    for (int i = 0; i < count; i++)
        printf("%s\"%s\"", i ? "," : "", names[i]);
    printf("]\n");
    lr_material_names_free(names, count);
    return LR_EXIT_OK;
}
