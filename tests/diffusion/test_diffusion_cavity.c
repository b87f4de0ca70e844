/* The diffusion_grid model's cavity closure (render/diffusion/dscene.h, render/core/cavity.h
 * lr_cavity_measure_field).
 *
 * The grid's boundary source q is the light's direct irradiance, so light the lit surface
 * sends back into a cavity around the light is lost unless the closure adds it. Asserted:
 *  1. Energy: a closed hollow sphere (outer 10 mm, cavity 6 mm) of non-absorbing material,
 *     eta 1 (no Fresnel: T_hem = 1, R_1 = 0) and 1.5, the light at the centre. Everything that enters
 *     leaves, and only the outer surface lets light out of the rig, so the outer surface emits
 *     the light's 4 pi I. The grid alone lets out a fraction a of it (the rest goes back into
 *     the cavity); with the closure (F = 1: gain = 1 / (1 - b)) the field's outer power is
 *     4 pi I within the grid's own energy error: the discrete solution's int B dA / int q dA
 *     at this spacing (h = 0.5 mm, the auto rule's radius / 20), measured here and allowed
 *     twice, plus the quadrature's 1 %.
 *  2. Where it applies: the candle's flame in its shallow pool gets a gain a little over 1
 *     (F small: the pool sees little of itself); the same flame lifted out of the hull gets
 *     exactly 1.
 *  3. The first bounce's source (render/diffusion/bounce.h), which spreads the closure's light:
 *     inside a spherical cavity of uniform B every chord meets the far wall at the angle it
 *     left, so q_1 = B int_0^1 2 mu F_t(mu)^2 d mu (Malley: cosine-distributed directions);
 *     on the outer surface every ray escapes, q_1 = 0. In the shell, whose direct field is
 *     uniform over the cavity, the spread field is the scalar gain's (1 holds as before). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/optics/optics.h"
#include "render/diffusion/bounce.h"
#include "render/diffusion/dscene.h"
#include "render/mesh/mesh.h"
#include "tests/support/fs.h"
#include "tests/support/near.h"
#include "tests/support/objects.h"
#include "tests/support/render.h"

#define RO 10.0 /* shell: outer radius, mm */
#define RI 6.0  /* cavity radius */

/* The shell as an OBJ file (shared vertices, so the loader sees a closed mesh). */
static void write_shell_obj(const char *path)
{
    lr_mesh *m = lrt_shell_mesh(RO, RI, 3);
    size_t nv = lr_mesh_vertex_count(m), nt = lr_mesh_triangle_count(m);
    const float *p = lr_mesh_positions(m);
    const uint32_t *ix = lr_mesh_indices(m);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    for (size_t v = 0; v < nv; v++)
        fprintf(f, "v %.9g %.9g %.9g\n", p[3 * v], p[3 * v + 1], p[3 * v + 2]);
    for (size_t t = 0; t < nt; t++)
        fprintf(f, "f %u %u %u\n", ix[3 * t] + 1, ix[3 * t + 1] + 1, ix[3 * t + 2] + 1);
    assert_int_equal(fclose(f), 0);
    lr_mesh_destroy(m);
}

static const char shell_scene[] =
    "{\"name\": \"grid_shell\",\n"
    " \"objects\": [{\"name\": \"shell\", \"model\": \"diffusion_grid\",\n"
    "   \"material\": {\"name\": \"white\", \"base\": \"marble\", \"sigma_a\": [0, 0, 0],"
    " \"eta\": %.2f, \"source\": \"test: marble's scattering, no absorption\"},\n"
    "   \"mesh\": {\"type\": \"file\", \"path\": \"shell.obj\"}}],\n"
    " \"lights\": [{\"type\": \"point\", \"position\": [0, 0, 0], \"intensity\": 1}],\n"
    " \"camera\": {\"position\": [0, -100, 0], \"target\": [0, 0, 0], \"up\": [0, 0, 1]}}\n";

/* int B dA over the sphere of radius r (points by the Halton sphere: equal solid angle each). */
static void sphere_power(const lr_dfield_view *v, double r, int n, double P[3])
{
    P[0] = P[1] = P[2] = 0.0;
    double dA = 4.0 * M_PI * r * r / n;
    for (int i = 0; i < n; i++) {
        lr_vec3 u = lr_halton_sphere((unsigned)i + 1), x = lr_v3_scale(u, r);
        double B[3];
        lr_dfield_eval(v->data, v->n, v->origin, v->h, x, B);
        for (int c = 0; c < 3; c++)
            P[c] += B[c] * dA;
    }
}

/* The scene's grid objects solved, with their closure. */
static lr_dscene *solved(const lr_scene *s)
{
    lr_dscene *d;
    lr_err e = {0};
    assert_int_equal(lr_dscene_create(&d, &e), LR_OK);
    if (lr_dscene_update(d, s, &e))
        fail_msg("%s", e.msg);
    return d;
}

/* The shell scene at eta, loaded from files in dir (the caller removes dir). */
static lr_scene *shell_scene_at(const char *dir, double eta)
{
    char *obj = lr_test_path(dir, "shell.obj");
    write_shell_obj(obj);
    char text[sizeof shell_scene + 16];
    snprintf(text, sizeof text, shell_scene, eta);
    char *path = lr_test_write(dir, "shell.json", text, (size_t)-1);
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    free(path);
    free(obj);
    return s;
}

static void check_closed_shell(double eta)
{
    char *dir = lr_test_tmpdir();
    lr_scene *s = shell_scene_at(dir, eta);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_true(o->closed);
    assert_near(lr_dscene_spacing(o), 0.5, 0.01);
    lr_dscene *d = solved(s);
    double gain[3];
    assert_true(lr_dscene_cavity_gain(d, 0, 0, gain));
    lr_dfield_view v;
    assert_true(lr_dscene_field(d, 0, 0, &v));
    /* The icosphere's faces lie up to 0.2 % inside the sphere (level 3: r cos of half an edge's
     * angle); the field is smooth across that, so points on the sphere read it well. A closed
     * shell around the light at its centre: int q dA = 4 pi I F_t(1) exactly (every ray
     * meets the wall at normal incidence). The field is the pipeline's B, whose exitance is
     * T_hem B. */
    double T = lr_hemi_transmittance(eta), Q = 4.0 * M_PI * lr_fresnel_transmittance(1.0, eta);
    double out[3], in[3];
    sphere_power(&v, RO, 8192, out);
    sphere_power(&v, RI, 8192, in);
    for (int c = 0; c < 3; c++) {
        out[c] *= T;
        in[c] *= T;
    }
    for (int c = 0; c < 3; c++) {
        /* The grid's own energy error: int B over both surfaces of the closed field (B =
         * gain * B_direct) over int q, non-absorbing, so 1 for the exact solution. */
        double direct_out = out[c] / gain[c], direct_in = in[c] / gain[c];
        double energy = (direct_out + direct_in) / Q;
        double a = direct_out / Q, b = direct_in / Q;
        double emitted = out[c] / (4.0 * M_PI);
        print_message("eta %.1f band %d: a %.3f b %.3f (energy %.4f); gain %.3f (1 / (1 - b) = %.3f); "
                      "outer power %.4f x 4 pi I (direct only %.4f)\n",
                      eta, c, a, b, energy, gain[c], 1.0 / (1.0 - b), emitted,
                      direct_out / (4.0 * M_PI));
        /* With eta 1 (F = 1, R_1 = 0, T = 1) the closure's series sums to 1 / (1 - b). Its b is
         * measured on other points (on the mesh's faces, 8192 stratified by area), so the two
         * b agree within 0.01; the gain itself, 1 / (1 - b) with b near 0.8, magnifies that. */
        if (eta == 1.0)
            assert_near(1.0 - 1.0 / gain[c], b, 0.01);
        /* The rendered exitance (T_hem B) accounts for what entered within the grid's
         * discretisation error (0.4-0.5 % here; 1.1 % on the solver's sphere test at this h):
         * with the solver's exitance passed on as B it was T_hem of it, 0.91 at eta 1.5. */
        assert_near(energy, 1.0, 0.015);
        assert_true(direct_out / (4.0 * M_PI) < 0.8); /* without the closure: far off */
        assert_near(emitted, 1.0, 2.0 * fabs(energy - 1.0) + 0.01);
    }
    lr_dscene_destroy(d);
    lr_scene_destroy(s);
    lr_test_rmtree(dir);
}

/* eta 1: no Fresnel; eta 1.5: the entry's reflection, the light the wall sends back arriving
 * diffusely, and the pipeline's B convention (exitance / T_hem) all enter the balance. */
static void test_closed_shell_emits_light_power(void **state)
{
    (void)state;
    check_closed_shell(1.0);
    check_closed_shell(1.5);
}

static void test_closure_only_where_it_applies(void **state)
{
    (void)state;
    static const char *const sets[] = {"objects[0].model=diffusion_grid",
                                       "objects[0].dgrid_h_mm=6", NULL};
    lr_scene *s = lr_test_scene("candle", sets, NULL);
    lr_dscene *d = solved(s);
    lr_err e = {0};
    double g[3];
    assert_true(lr_dscene_cavity_gain(d, 0, 0, g));
    print_message("candle, flame in the pool: gain %.4f %.4f %.4f\n", g[0], g[1], g[2]);
    for (int c = 0; c < 3; c++) {
        assert_true(g[c] > 1.005); /* some light comes back to the pool */
        assert_true(g[c] < 1.2);   /* a shallow pool: F small */
    }
    /* The flame lifted out of the hull: no closure. */
    unsigned dirty = 0;
    assert_int_equal(lr_scene_set(s, "lights[0].position", "0,0,400", &dirty, &e), LR_OK);
    assert_int_equal(lr_dscene_update(d, s, &e), LR_OK);
    assert_true(lr_dscene_cavity_gain(d, 0, 0, g));
    for (int c = 0; c < 3; c++)
        assert_true(g[c] == 1.0);
    assert_false(lr_dscene_cavity_gain(d, 1, 0, g)); /* no such object */
    lr_dscene_destroy(d);
    lr_scene_destroy(s);
}

/* int_0^1 2 mu F_t(mu)^2 d mu by the midpoint rule (F_t is smooth in mu). */
static double cosine_mean_ft2(double eta)
{
    const int n = 20000;
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        double mu = (i + 0.5) / n, t = lr_fresnel_transmittance(mu, eta);
        sum += 2.0 * mu * t * t / n;
    }
    return sum;
}

static void test_bounce_source_in_a_sphere(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    lr_scene *s = shell_scene_at(dir, 1.5);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    /* A field of B = (1, 2, 3) everywhere: two nodes per axis around the shell, all valid. */
    float data[8 * 4];
    for (int k = 0; k < 8; k++) {
        data[4 * k] = 1.0f, data[4 * k + 1] = 2.0f, data[4 * k + 2] = 3.0f;
        data[4 * k + 3] = 1.0f;
    }
    lr_dbounce bk = {.obj = o,
                     .field = {.data = data, .n = {2, 2, 2}, .origin = lr_v3(-12, -12, -12),
                               .h = 24.0},
                     .rays = 256};
    double want = cosine_mean_ft2(1.5);
    double worst = 0.0;
    const lr_mesh *m = lr_bvh_mesh(o->bvh);
    int ncav = 0, nout = 0;
    /* Every 7th face's centroid, on the surface, with its normal (the cavity's faces the
     * centre: the loader turns a nested closed piece to face its cavity). */
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t += 7) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 g = lr_v3_scale(lr_v3_add(p[0], lr_v3_add(p[1], p[2])), 1.0 / 3.0);
        lr_vec3 n = lr_mesh_triangle_normal(m, t);
        double v[3];
        lr_dbounce_q(&bk, g, n, v);
        if (lr_v3_len(g) < 0.5 * (RI + RO)) {
            assert_true(lr_v3_dot(n, g) < 0.0);
            ncav++;
            for (int c = 0; c < 3; c++)
                worst = fmax(worst, fabs(v[c] / ((c + 1) * want) - 1.0));
        } else {
            nout++;
            for (int c = 0; c < 3; c++)
                assert_true(v[c] == 0.0); /* the outer surface sees nothing of the object */
        }
    }
    assert_true(ncav > 20 && nout > 20);
    print_message("bounce source in the cavity: int 2 mu F_t^2 = %.4f, worst of %d points "
                  "%.2e relative (%d outer points: 0)\n", want, ncav, worst, nout);
    /* 256 stratified cosine-distributed rays on a smooth integrand (F_t^2 changes only near
     * grazing), and the icosphere's facets (0.4 % of the radius) bend the chords a little:
     * within 1 %. */
    assert_true(worst < 0.01);
    lr_scene_destroy(s);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_closed_shell_emits_light_power),
        cmocka_unit_test(test_closure_only_where_it_applies),
        cmocka_unit_test(test_bounce_source_in_a_sphere),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
