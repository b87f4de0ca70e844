/* Translucent radiosity under area lights (render/transrad/direct_area.c; issue 14 parts 2-3):
 *  - an unoccluded small patch's E against render/area's closed forms (Lambert's polygon
 *    formula for a quad, pi L a^2 / (a^2 + h^2) on a disk's axis), tilted and off-axis too,
 *    within 1 %: the patch is 2 x 2 mm, so its mean differs from the value at its centre by
 *    the curvature of E over 1 mm at >= 40 mm (< 0.1 %), and the reference is the closed form
 *    averaged over 16 x 16 points of the patch;
 *  - shadows: an opaque sheet just below the emitter whose edge lies in the plane x = 0 hides
 *    exactly the emitter's x < 0 half from every point with x = 0 (the lines from such a point
 *    through the edge stay in that plane), so a patch centred on x = 0 gets half the light
 *    within 2 % (its 2 mm width moves the shadow line by 1 mm x 1/100 on the emitter); a sheet
 *    over the whole emitter leaves nothing;
 *  - energy: a quad (one-sided) and a disk (two-sided) of unit radiance inside sphere_shell
 *    (no absorption) emit pi A and 2 pi A, and all of it must leave the shell: within the
 *    issue's 10 % (the point light's 4 pi test holds to 2 %);
 *  - bad input: a degenerate emitter, area_samples out of range. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/area/emitter.h"
#include "render/area/frames.h"
#include "render/base/paths.h"
#include "render/mesh/shapes.h"
#include "render/transrad/transrad.h"
#include "tests/support/near.h"
#include "tests/support/objects.h"

static lr_mesh *quad_mesh(lr_vec3 c, lr_vec3 n, lr_vec3 u, double su, double sv)
{
    lr_quad_desc q = {.center = c, .normal = n, .u_dir = u, .size_u = su, .size_v = sv};
    lr_mesh *m;
    lr_err e = {0};
    if (lr_mesh_quad(&q, &m, &e))
        fail_msg("%s", e.msg);
    return m;
}

/* A square plane patch (one cell) of side a at c, normal n. */
typedef struct patch {
    lr_mesh *m;
    lr_bvh *b;
    lr_tr_surface_desc d;
    lr_vec3 c, n, u, v;
    double a;
} patch;

static patch patch_make(lr_vec3 c, lr_vec3 n, double a)
{
    patch p = {.c = c, .n = lr_v3_normalize(n), .a = a};
    lr_vec3 ref = fabs(p.n.z) < 0.9 ? lr_v3(0, 0, 1) : lr_v3(1, 0, 0);
    p.u = lr_v3_normalize(lr_v3_cross(ref, p.n));
    p.v = lr_v3_cross(p.n, p.u);
    p.m = quad_mesh(c, p.n, p.u, a, a);
    p.b = lrt_bvh(p.m);
    p.d = (lr_tr_surface_desc){.kind = LR_TR_PLANE, .mesh = p.m, .bvh = p.b, .center = c,
                               .normal = p.n, .u_dir = p.u, .size_u = a, .size_v = a,
                               .cells_u = 1, .cells_v = 1, .albedo = {0, 0, 0}};
    return p;
}

static void patch_free(patch *p)
{
    lr_bvh_destroy(p->b);
    lr_mesh_destroy(p->m);
}

/* The closed form averaged over 16 x 16 points of the patch. */
static double patch_closed_form(const patch *p, const lr_area_emitter *em)
{
    double sum = 0;
    for (int i = 0; i < 16; i++)
        for (int j = 0; j < 16; j++) {
            double s = ((i + 0.5) / 16 - 0.5) * p->a, t = ((j + 0.5) / 16 - 0.5) * p->a;
            lr_vec3 x = lr_v3_add(p->c, lr_v3_add(lr_v3_scale(p->u, s), lr_v3_scale(p->v, t)));
            sum += lr_area_irradiance(em, 1.0, x, p->n);
        }
    return sum / 256;
}

/* E of the patch (surface 0) under light l with the other surfaces given. */
static double solve_E(const lr_tr_surface_desc *d, int n, const lr_light *l)
{
    lr_tr_settings set = {.rays_per_patch = 64, .seed = 3};
    lr_tr *t;
    lr_err e = {0};
    if (lr_tr_create(d, n, &set, &t, &e))
        fail_msg("%s", e.msg);
    if (lr_tr_solve_light(t, l, 0, NULL, &e))
        fail_msg("%s", e.msg);
    double H[3];
    lr_tr_irradiance(t, 0, 0, H);
    assert_near(H[0], H[2], 1e-12 * (1 + H[1])); /* E is the same in every band */
    lr_tr_destroy(t);
    return H[1];
}

static lr_light quad_light(lr_vec3 c, lr_vec3 hu, lr_vec3 hv, bool two_sided)
{
    return (lr_light){.type = LR_LIGHT_QUAD, .name = "quad", .position = c, .edge_u = hu,
                      .edge_v = hv, .two_sided = two_sided, .intensity = 1,
                      .color = {1, 1, 1}};
}

static lr_light disk_light(lr_vec3 c, lr_vec3 n, double r, bool two_sided)
{
    return (lr_light){.type = LR_LIGHT_DISK, .name = "disk", .position = c, .direction = n,
                      .radius = r, .two_sided = two_sided, .intensity = 1,
                      .color = {1, 1, 1}};
}

static void test_unoccluded_closed_forms(void **state)
{
    (void)state;
    lr_err e = {0};
    /* A 40 x 60 mm quad at z = 100 facing down, an 8 x 60 mm strip at x = -15 facing +x, a disk of
     * radius 25 facing down. */
    lr_light lights[3] = {
        quad_light(lr_v3(0, 0, 100), lr_v3(20, 0, 0), lr_v3(0, -30, 0), false),
        quad_light(lr_v3(-15, 0, 60), lr_v3(0, 4, 0), lr_v3(0, 0, 30), false),
        disk_light(lr_v3(0, 0, 100), lr_v3(0, 0, -1), 25, false),
    };
    struct { lr_vec3 c, n; } where[] = {
        {{0, 0, 0}, {0, 0, 1}},        /* below the centre (on the disk's axis) */
        {{35, 20, 10}, {0, 0, 1}},     /* off axis */
        {{-30, 10, 20}, {0.5, 0, 1}},  /* tilted toward it */
        {{60, -5, 40}, {-1, 0.2, 0.3}},/* facing sideways: the horizon cuts the emitter */
    };
    for (int l = 0; l < 3; l++) {
        lr_area_emitter em;
        if (lr_area_from_light(&lights[l], &em, &e))
            fail_msg("%s", e.msg);
        for (size_t w = 0; w < sizeof where / sizeof where[0]; w++) {
            patch p = patch_make(where[w].c, where[w].n, 2);
            double E = solve_E(&p.d, 1, &lights[l]), ref = patch_closed_form(&p, &em);
            print_message("%s at (%g %g %g): E %.6e closed form %.6e (%+.4f %%)\n",
                          lights[l].name, where[w].c.x, where[w].c.y, where[w].c.z, E, ref,
                          ref > 0 ? 100 * (E / ref - 1) : 0.0);
            if (ref > 0)
                assert_near_rel(E, ref, 0.01);
            else
                assert_near(E, 0.0, 1e-15);
            patch_free(&p);
        }
    }
    /* The disk on its axis: pi L a^2 / (a^2 + h^2). */
    patch p = patch_make(lr_v3(0, 0, 0), lr_v3(0, 0, 1), 2);
    double E = solve_E(&p.d, 1, &lights[2]);
    assert_near_rel(E, M_PI * 625 / (625 + 1e4), 0.01);
    patch_free(&p);
}

static void test_occluder_halves_and_blocks(void **state)
{
    (void)state;
    /* Quad 40 x 40 mm at z = 100 facing down; the patch at the origin facing up. */
    lr_light L = quad_light(lr_v3(0, 0, 100), lr_v3(20, 0, 0), lr_v3(0, -20, 0), false);
    patch p = patch_make(lr_v3(0, 0, 0), lr_v3(0, 0, 1), 2);
    double E0 = solve_E(&p.d, 1, &L);
    /* A sheet 1 mm below the emitter over x in [-60, 0]. */
    lr_mesh *half = quad_mesh(lr_v3(-30, 0, 99), lr_v3(0, 0, -1), lr_v3(1, 0, 0), 60, 120);
    lr_mesh *full = quad_mesh(lr_v3(0, 0, 99), lr_v3(0, 0, -1), lr_v3(1, 0, 0), 120, 120);
    lr_bvh *bh = lrt_bvh(half), *bf = lrt_bvh(full);
    lr_tr_surface_desc d[2] = {p.d, {.kind = LR_TR_DIFFUSE, .mesh = half, .bvh = bh,
                                     .albedo = {0, 0, 0}, .patch_mm = 1e3}};
    double Eh = solve_E(d, 2, &L);
    d[1].mesh = full;
    d[1].bvh = bf;
    double Ef = solve_E(d, 2, &L);
    print_message("occluders: open %.6e, half hidden %.6e (ratio %.4f), all hidden %.3e\n", E0,
                  Eh, Eh / E0, Ef);
    assert_near_rel(Eh, 0.5 * E0, 0.02);
    assert_true(Ef == 0.0);
    lr_bvh_destroy(bh);
    lr_bvh_destroy(bf);
    lr_mesh_destroy(half);
    lr_mesh_destroy(full);
    patch_free(&p);
}

static void shell_emits(const lr_light *L, double expected)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/sphere_shell.json", lr_configs_dir());
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_load(path, NULL, &s, &e))
        fail_msg("%s", e.msg);
    lr_tr *t;
    lr_tr_settings set = {.rays_per_patch = 256};
    if (lr_tr_create_scene(s, &set, &t, &e))
        fail_msg("%s", e.msg);
    lr_tr_stats st;
    if (lr_tr_solve_light(t, L, 0, &st, &e))
        fail_msg("%s", e.msg);
    double P[3];
    lr_tr_escaped_power(t, 0, P);
    print_message("sphere_shell, %s inside: emitted %.4f %.4f %.4f of %.4f (%+.2f %%), %d "
                  "sweeps\n", L->name, P[0], P[1], P[2], expected, 100 * (P[1] / expected - 1),
                  st.iterations);
    for (int b = 0; b < 3; b++)
        assert_near_rel(P[b], expected, 0.10);
    lr_tr_destroy(t);
    lr_scene_destroy(s);
}

static void test_closed_shell_energy(void **state)
{
    (void)state;
    /* A 10 x 4 mm quad, tilted, and a two-sided disk of radius 6 mm, inside the 38 mm cavity. */
    lr_light q = quad_light(lr_v3(3, -2, 5), lr_v3(5, 0, 1), lr_v3(0, 2, 0), false);
    shell_emits(&q, M_PI * 40);
    lr_light d = disk_light(lr_v3(0, 4, -3), lr_v3(0.3, 1, 0.2), 6, true);
    shell_emits(&d, 2 * M_PI * M_PI * 36);
}

static void test_bad_input(void **state)
{
    (void)state;
    patch p = patch_make(lr_v3(0, 0, 0), lr_v3(0, 0, 1), 2);
    lr_tr *t;
    lr_err e = {0};
    lr_tr_settings set = {.rays_per_patch = 16, .area_samples = 257};
    assert_int_equal(lr_tr_create(&p.d, 1, &set, &t, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "area_samples"));
    set.area_samples = 0;
    if (lr_tr_create(&p.d, 1, &set, &t, &e))
        fail_msg("%s", e.msg);
    /* Parallel edges: no area. */
    lr_light L = quad_light(lr_v3(0, 0, 50), lr_v3(10, 0, 0), lr_v3(20, 0, 0), false);
    assert_int_equal(lr_tr_solve_light(t, &L, 0, NULL, &e), LR_EINVAL);
    L = disk_light(lr_v3(0, 0, 50), lr_v3(0, 0, -1), -3, false);
    assert_int_equal(lr_tr_solve_light(t, &L, 0, NULL, &e), LR_EINVAL);
    lr_tr_destroy(t);
    patch_free(&p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unoccluded_closed_forms),
        cmocka_unit_test(test_occluder_halves_and_blocks),
        cmocka_unit_test(test_closed_shell_energy),
        cmocka_unit_test(test_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
