/* Physical reference on triangle meshes (render/mesh): the shell-around-a-light balance of
 * test_reference_sphere on faceted spheres, so that ray casts through the BVH, flat facet
 * normals and Newton-solved connections across facet edges are held to the same photon
 * counts; mesh content in the cache key; open meshes refused as medium boundaries.
 * Tolerances as in test_reference_sphere: 4 combined standard errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/shapes.h"
#include "render/reference/ref_priv.h"
#include "tests/support/mc.h"

static lr_ref_shape *mesh_sphere(double r, int subdivisions)
{
    lr_sphere_desc d = {.radius = r, .subdivisions = subdivisions};
    lr_mesh *m;
    assert_int_equal(lr_mesh_sphere(&d, &m, NULL), LR_OK);
    lr_ref_shape *sh;
    assert_int_equal(lr_ref_mesh_create(m, true, &sh, NULL), LR_OK);
    assert_true(sh->ops->closed);
    return sh;
}

/* A shell of scattering medium between an outer sphere (faceted or analytic) and a faceted
 * cavity of radius 0.6 (320 facets) around a point light in the air cavity. */
static lr_ref_scene *shell(const lr_ref_medium_desc *md, lr_vec3 light, bool mesh_outside)
{
    lr_ref_scene *s;
    assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
    int m;
    assert_int_equal(lr_ref_scene_add_medium(s, md, &m, NULL), LR_OK);
    lr_ref_shape *outer;
    if (mesh_outside)
        outer = mesh_sphere(1.0, 3);
    else
        assert_int_equal(lr_ref_sphere_create(lr_v3(0, 0, 0), 1.0, &outer, NULL), LR_OK);
    lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = outer, .inside = m};
    assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
    od = (lr_ref_object_desc){.kind = LR_REF_BOUNDARY, .shape = mesh_sphere(0.6, 2), .inside = 0,
                              .outside = m};
    assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
    lr_ref_light_desc ld = {.kind = LR_REF_LIGHT_POINT, .position = light, .emission = {1, 1, 1}};
    assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
    assert_int_equal(lr_ref_scene_finish(s, NULL), LR_OK);
    return s;
}

/* Without absorption every photon leaves the faceted shell (conservation: no leak through
 * the BVH's seams); with and without absorption the camera paths' power equals their share
 * of the photons within 4 combined SE. Here a large share of refracted connections (about
 * 16 %) has no solution at all: a point light inside a convex faceted cavity, refracted into
 * the denser wall, lights it in fans that leave dark wedges behind every edge (the facet
 * normals diverge), and the solver correctly finds nothing there. That those are gaps and
 * not missed light is what the balance checks: a lost solution would make the camera paths
 * come up short. (Longer runs than this test's do measure a small shortfall on faceted
 * cavities, -0.13 % +- 0.05 % for 320 and for 1280 facets, none on the analytic sphere:
 * connections that land within rounding of a gap's border. render/reference/README.md lists it.)
 * The first run has a faceted outer sphere too (1280 facets) and checks exact
 * conservation; the balance runs use an analytic outside, so that the (ASan-slowed) BVH work
 * goes to the refracted connections. 64 000 photons, 40 000 camera paths: SE about 0.3 % and
 * 0.6 %. */
static void test_mesh_shell(void **state)
{
    (void)state;
    lr_vec3 light = lr_v3(0.1, -0.2, 0.15);
    lr_ref_medium_desc md = {.sigma_s = {4, 4, 4}, .g = 0.5, .eta = 1.4};
    lr_ref_scene *s = shell(&md, light, true);
    lr_ref_escape_result r;
    assert_int_equal(lr_ref_escape(s, 0, 64000, 61, 0, &r, NULL), LR_OK);
    assert_true(r.escaped.value == 1.0); /* every photon escaped */
    assert_int_equal(r.stats.medium_mismatch, 0);
    assert_int_equal(r.stats.truncated, 0);
    lr_ref_scene_destroy(s);
    for (int absorbing = 0; absorbing < 2; absorbing++) {
        double sa = absorbing ? 0.3 : 0.0;
        md.sigma_a[0] = md.sigma_a[1] = md.sigma_a[2] = sa;
        s = shell(&md, light, false);
        assert_int_equal(lr_ref_escape(s, 0, 64000, 62 + (uint64_t)absorbing, 0, &r, NULL),
                         LR_OK);
        /* The camera paths' share: scattered, and not by way of a reflection first. */
        lr_ref_estimate ph = {r.escaped_scattered.value - r.escaped_light_traced.value,
                              r.escaped_scattered.se + r.escaped_light_traced.se};
        lr_ref_stats cs;
        lr_ref_estimate cam = lrt_camera_outflow(s, 1.0, 40000, 63 + (uint64_t)absorbing, &cs);
        printf("  unsolved %.2f %% of %llu refracted connections\n",
               100.0 * (double)cs.nee_unsolved / (double)cs.nee_refracted,
               (unsigned long long)cs.nee_refracted);
        lrt_assert_agree(absorbing ? "mesh shell, absorbing: camera vs photons"
                                   : "mesh shell: camera vs photons", cam, ph);
        assert_true(cam.se < 0.008 && ph.se < 0.004);
        assert_int_equal(cs.medium_mismatch, 0);
        lr_ref_scene_destroy(s);
    }
}

/* Mesh content is part of the scene hash (so of cache keys): another tessellation, another
 * key; the same mesh built twice, the same key. An open mesh cannot bound a medium. */
static void test_mesh_hash_and_open(void **state)
{
    (void)state;
    uint64_t h[3];
    for (int k = 0; k < 3; k++) {
        lr_ref_scene *s;
        assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
        lr_ref_object_desc od = {.kind = LR_REF_RECEIVER, .shape = mesh_sphere(1.0, k ? 3 : 2),
                                 .albedo = {0.5, 0.5, 0.5}};
        assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
        h[k] = lr_ref_scene_hash(s);
        lr_ref_scene_destroy(s);
    }
    assert_true(h[1] == h[2] && h[0] != h[1]);

    lr_quad_desc qd = {.size_u = 10, .size_v = 10};
    lr_mesh *m;
    assert_int_equal(lr_mesh_quad(&qd, &m, NULL), LR_OK);
    lr_ref_shape *sh;
    assert_int_equal(lr_ref_mesh_create(m, true, &sh, NULL), LR_OK);
    assert_false(sh->ops->closed);
    lr_ref_scene *s;
    assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
    lr_ref_medium_desc md = {.sigma_s = {1, 1, 1}};
    int id;
    assert_int_equal(lr_ref_scene_add_medium(s, &md, &id, NULL), LR_OK);
    lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = sh, .inside = id};
    lr_err e = {0};
    assert_int_equal(lr_ref_scene_add_object(s, &od, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "open mesh"));
    lr_ref_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mesh_shell),
        cmocka_unit_test(test_mesh_hash_and_open),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
