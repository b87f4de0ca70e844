/* lamprig optics — a designer's view of a material: the standard dipole profile (and its
 * plot), total diffuse reflectance, and directional dipole values, as JSON on stdout.
 * Bad arguments: one line on stderr, exit status 2. */
#include "firmware/cmd_optics.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/args.h"
#include "firmware/cli.h"
#include "firmware/profile_plot.h"
#include "render/material/material.h"
#include "render/optics/optics.h"

const char lr_optics_summary[] = "optics of a material: dipole profile, plot, totals, directional dipole";

const char lr_optics_usage[] =
    "usage: lamprig optics SUBCOMMAND [ARGS]\n"
    "\n"
    "A designer's view of a material, as JSON on stdout (numbers printed with 17 significant\n"
    "digits: they read back to the same double). Units: mm, mm^-1.\n"
    "\n"
    "Subcommands:\n"
    "  profile MATERIAL --r r1,r2,...  [--plot FILE.png]\n"
    "      standard dipole R_d(r) of Jensen et al. 2001, mm^-2, per band:\n"
    "      {\"r\":[...],\"Rd\":[[R,G,B],...]}\n"
    "      --plot draws R_d(r) log-log into FILE.png (written atomically). Without --r the\n"
    "      plot uses 200 radii log-spaced from 1/20 of the shortest mean free path to where\n"
    "      the slowest band has decayed by e^-10 (at most 1000 mean free paths).\n"
    "  total MATERIAL\n"
    "      {\"Rd_total\":[R,G,B],\"sigma_tr\":[R,G,B],\"albedo\":[R,G,B]}: closed-form total\n"
    "      diffuse reflectance, effective transport coefficient (mm^-1), reduced albedo\n"
    "      sigma_s'/(sigma_a + sigma_s').\n"
    "  dirpole MATERIAL --xi x,y,z --ni x,y,z --wi x,y,z --xo x,y,z --no x,y,z\n"
    "      directional dipole S_d of Frisvad et al. 2014, mm^-2 sr^-1:\n"
    "      {\"sd\":[R,G,B],\"sd_fresnel\":[R,G,B]}. x_i, n_i: where light enters and the\n"
    "      outward normal there; w_i points from x_i toward the light (w_i . n_i >= 0);\n"
    "      x_o, n_o: where it leaves. sd excludes the boundary Fresnel transmission,\n"
    "      sd_fresnel = sd * F_t(w_i). Directions are normalised; zero length is an error.\n"
    "  materials\n"
    "      the preset names MATERIAL can use, a JSON array.\n"
    "\n"
    "MATERIAL is either\n"
    "  --material NAME                a preset, configs/materials/NAME.json\n"
    "or\n"
    "  --sigma-a R,G,B                absorption, mm^-1, >= 0\n"
    "  --sigma-s-prime R,G,B          reduced scattering, mm^-1, >= 0\n"
    "  --eta E                        relative index of refraction inside/outside\n"
    "  [--g G]                        Henyey-Greenstein mean cosine, default 0\n"
    "\n"
    "Exit status: 0 done; 1 a preset file is broken or the plot could not be written;\n"
    "2 bad arguments (one line on stderr).\n"
    "\n"
    "Examples:\n"
    "  lamprig optics total --material marble\n"
    "  lamprig optics profile --material candle_wax --r 0.5,1,2,4,8 --plot wax.png\n"
    "  lamprig optics profile --sigma-a 0.002,0.004,0.007 --sigma-s-prime 2.2,2.6,3 --eta 1.5 \\\n"
    "      --plot custom.png\n"
    "  lamprig optics dirpole --material marble --xi 0,0,0 --ni 0,0,1 --wi 0,0,1 \\\n"
    "      --xo 1,0,0 --no 0,0,1";

/* Options every material-taking subcommand accepts, followed by its own. */
#define MATERIAL_SPECS                                                                          \
    {"--material", 1}, {"--sigma-a", 1}, {"--sigma-s-prime", 1}, {"--eta", 1}, {"--g", 1}

/* Profile points when the plot chooses the radii. */
#define PLOT_POINTS 200
/* Most radii accepted in --r. */
#define MAX_RADII 4096

/* One line on stderr, whatever the user typed: control characters become '?'. */
static int usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int usage_error(const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    for (char *c = msg; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    fprintf(stderr, "lamprig optics: %s (see `lamprig help optics`)\n", msg);
    return LR_EXIT_USAGE;
}

static int err_usage(const lr_err *e) { return usage_error("%s", e->msg); }

/* Resolves the material options into a medium and a title. Returns LR_EXIT_OK or the exit
 * status to return (the message is already printed). */
static int get_material(const lr_args *a, lr_medium *m, char *title, size_t cap)
{
    const char *name = lr_args_get(a, "--material");
    const char *sa = lr_args_get(a, "--sigma-a"), *ss = lr_args_get(a, "--sigma-s-prime");
    const char *eta = lr_args_get(a, "--eta"), *g = lr_args_get(a, "--g");
    lr_err e = {0};
    if (name) {
        if (sa || ss || eta || g)
            return usage_error("%s", "--material cannot be combined with --sigma-a, "
                                     "--sigma-s-prime, --eta or --g");
        if (!lr_material_name_ok(name))
            return usage_error("--material: '%s' is not a preset name", name);
        char **names = NULL;
        int count = 0, known = 0;
        if (lr_material_names(&names, &count, &e) != LR_OK) {
            fprintf(stderr, "lamprig optics: %s\n", e.msg);
            return LR_EXIT_FAIL;
        }
        for (int i = 0; i < count && !known; i++)
            known = strcmp(names[i], name) == 0;
        lr_material_names_free(names, count);
        if (!known)
            return usage_error("--material: no preset '%s' (`lamprig optics materials` lists "
                               "them)",
                               name);
        lr_material mat;
        if (lr_material_find(name, &mat, &e) != LR_OK) {
            fprintf(stderr, "lamprig optics: %s\n", e.msg);
            return LR_EXIT_FAIL;
        }
        *m = mat.medium;
        snprintf(title, cap, "%s", mat.name);
        return LR_EXIT_OK;
    }
    if (!sa || !ss || !eta)
        return usage_error("%s", "give --material NAME, or --sigma-a, --sigma-s-prime and --eta");
    memset(m, 0, sizeof *m);
    if (lr_args_triple("--sigma-a", sa, m->sigma_a, &e) ||
        lr_args_triple("--sigma-s-prime", ss, m->sigma_s_prime, &e) ||
        lr_args_number("--eta", eta, &m->eta, &e) || (g && lr_args_number("--g", g, &m->g, &e)))
        return err_usage(&e);
    for (int i = 0; i < 3; i++) {
        char msg[160];
        if (m->sigma_a[i] < 0 || m->sigma_s_prime[i] < 0) {
            snprintf(msg, sizeof msg, "%s: component %d is negative (coefficients are >= 0)",
                     m->sigma_a[i] < 0 ? "--sigma-a" : "--sigma-s-prime", i + 1);
            return usage_error("%s", msg);
        }
    }
    if (lr_medium_validate(m, &e) != LR_OK)
        return err_usage(&e);
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

static int nonfinite(const char *what)
{
    fprintf(stderr, "lamprig optics: internal error: %s is not finite\n", what);
    return LR_EXIT_FAIL;
}

static int parse(int argc, char **argv, const lr_argspec *specs, lr_args *a)
{
    lr_err e = {0};
    /* argv[0] "optics", argv[1] the subcommand. */
    if (lr_args_parse(argc - 2, argv + 2, specs, 0, a, &e) != LR_OK)
        return err_usage(&e);
    return LR_EXIT_OK;
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

static int cmd_profile(int argc, char **argv)
{
    static const lr_argspec specs[] = {MATERIAL_SPECS, {"--r", 1}, {"--plot", 1}, {NULL, 0}};
    lr_args a;
    int st = parse(argc, argv, specs, &a);
    if (st)
        return st;
    lr_medium m;
    char title[160];
    if ((st = get_material(&a, &m, title, sizeof title)))
        return st;
    const char *rtext = lr_args_get(&a, "--r"), *plot = lr_args_get(&a, "--plot");
    if (!rtext && !plot)
        return usage_error("%s", "profile needs --r r1,r2,... (or --plot FILE.png)");
    lr_err e = {0};
    lr_coeffs c;
    if (lr_coeffs_derive(&m, &c, &e) != LR_OK)
        return err_usage(&e);

    int n = 0;
    double *r = malloc(MAX_RADII * sizeof *r);
    double(*rd)[3] = malloc(MAX_RADII * sizeof *rd);
    if (!r || !rd) {
        free(r);
        free(rd);
        fprintf(stderr, "lamprig optics: out of memory\n");
        return LR_EXIT_FAIL;
    }
    if (rtext) {
        if (lr_args_numbers("--r", rtext, r, 1, MAX_RADII, &n, &e) != LR_OK) {
            st = err_usage(&e);
            goto out;
        }
        for (int i = 0; i < n; i++) {
            if (r[i] < 0) {
                char msg[96];
                snprintf(msg, sizeof msg, "--r: radius %d is %g; radii are >= 0 (mm)", i + 1,
                         r[i]);
                st = usage_error("%s", msg);
                goto out;
            }
        }
    } else {
        n = default_radii(&c, r, PLOT_POINTS);
    }
    for (int i = 0; i < n; i++) {
        lr_dipole_rd(&c, r[i], rd[i]);
        if (!all_finite(rd[i], 3)) {
            st = nonfinite("R_d(r)");
            goto out;
        }
    }
    if (plot) {
        if (lr_profile_plot_png(plot, title, "r (mm)", "R_d(r) (1/mm^2)", r,
                                (const double(*)[3])rd, n, &e) != LR_OK) {
            fprintf(stderr, "lamprig optics: --plot: %s\n", e.msg);
            st = e.code == LR_EINVAL ? LR_EXIT_USAGE : LR_EXIT_FAIL;
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

static int cmd_total(int argc, char **argv)
{
    static const lr_argspec specs[] = {MATERIAL_SPECS, {NULL, 0}};
    lr_args a;
    int st = parse(argc, argv, specs, &a);
    if (st)
        return st;
    lr_medium m;
    char title[160];
    if ((st = get_material(&a, &m, title, sizeof title)))
        return st;
    lr_err e = {0};
    lr_coeffs c;
    if (lr_coeffs_derive(&m, &c, &e) != LR_OK)
        return err_usage(&e);
    double total[3];
    lr_dipole_rd_total(&c, total);
    if (!all_finite(total, 3) || !all_finite(c.sigma_tr, 3) || !all_finite(c.albedo_prime, 3))
        return nonfinite("a total");
    printf("{\"Rd_total\":");
    print_triple(total);
    printf(",\"sigma_tr\":");
    print_triple(c.sigma_tr);
    printf(",\"albedo\":");
    print_triple(c.albedo_prime);
    printf("}\n");
    return LR_EXIT_OK;
}

/* A position (any finite point) or, with unit != 0, a direction normalised to unit length. */
static int get_vec(const lr_args *a, const char *flag, int unit, lr_vec3 *out)
{
    const char *text = lr_args_get(a, flag);
    if (!text)
        return usage_error("dirpole needs %s x,y,z", flag);
    double v[3];
    lr_err e = {0};
    if (lr_args_triple(flag, text, v, &e) != LR_OK)
        return err_usage(&e);
    lr_vec3 p = lr_v3(v[0], v[1], v[2]);
    if (unit) {
        double len = lr_v3_len(p);
        if (!(len > 0) || !isfinite(len))
            return usage_error("%s: a direction must have non-zero, finite length", flag);
        p = lr_v3_scale(p, 1.0 / len);
    }
    *out = p;
    return LR_EXIT_OK;
}

static int cmd_dirpole(int argc, char **argv)
{
    static const lr_argspec specs[] = {MATERIAL_SPECS, {"--xi", 1}, {"--ni", 1}, {"--wi", 1},
                                       {"--xo", 1},    {"--no", 1}, {NULL, 0}};
    lr_args a;
    int st = parse(argc, argv, specs, &a);
    if (st)
        return st;
    lr_medium m;
    char title[160];
    if ((st = get_material(&a, &m, title, sizeof title)))
        return st;
    lr_vec3 xi, ni, wi, xo, no;
    if ((st = get_vec(&a, "--xi", 0, &xi)) || (st = get_vec(&a, "--ni", 1, &ni)) ||
        (st = get_vec(&a, "--wi", 1, &wi)) || (st = get_vec(&a, "--xo", 0, &xo)) ||
        (st = get_vec(&a, "--no", 1, &no)))
        return st;
    /* Light arriving from inside the medium at x_i is not what S_d describes. */
    if (lr_v3_dot(wi, ni) < 0)
        return usage_error("%s", "--wi points below the surface at x_i (w_i . n_i < 0); "
                                 "w_i points from x_i toward the light");
    lr_err e = {0};
    lr_coeffs c;
    if (lr_coeffs_derive(&m, &c, &e) != LR_OK)
        return err_usage(&e);
    double sd[3], sdf[3];
    lr_dirpole_sd(&c, xi, ni, wi, xo, no, sd);
    lr_dirpole_sd_fresnel(&c, xi, ni, wi, xo, no, sdf);
    if (!all_finite(sd, 3) || !all_finite(sdf, 3))
        return nonfinite("S_d");
    printf("{\"sd\":");
    print_triple(sd);
    printf(",\"sd_fresnel\":");
    print_triple(sdf);
    printf("}\n");
    return LR_EXIT_OK;
}

static int cmd_materials(int argc, char **argv)
{
    static const lr_argspec specs[] = {{NULL, 0}};
    lr_args a;
    int st = parse(argc, argv, specs, &a);
    if (st)
        return st;
    char **names = NULL;
    int count = 0;
    lr_err e = {0};
    if (lr_material_names(&names, &count, &e) != LR_OK) {
        fprintf(stderr, "lamprig optics: %s\n", e.msg);
        return LR_EXIT_FAIL;
    }
    /* Preset names are plain (letters, digits, _-.): nothing to escape in JSON. */
    printf("[");
    for (int i = 0; i < count; i++)
        printf("%s\"%s\"", i ? "," : "", names[i]);
    printf("]\n");
    lr_material_names_free(names, count);
    return LR_EXIT_OK;
}

int lr_cmd_optics(int argc, char **argv)
{
    static const struct {
        const char *name;
        int (*run)(int, char **);
    } subs[] = {{"profile", cmd_profile},
                {"total", cmd_total},
                {"dirpole", cmd_dirpole},
                {"materials", cmd_materials}};
    if (argc < 2)
        return usage_error("%s", "missing subcommand: profile, total, dirpole or materials");
    int st = -1;
    for (size_t i = 0; i < sizeof subs / sizeof subs[0]; i++)
        if (strcmp(argv[1], subs[i].name) == 0)
            st = subs[i].run(argc, argv);
    if (st < 0)
        st = usage_error("unknown subcommand '%s' (profile, total, dirpole, materials)", argv[1]);
    fflush(stdout);
    return st;
}
