/* Scenes: the shipped scene files, whether lights are surrounded, camera matrices, errors
 * naming file, line and field, and run-time parameters with their dirty flags. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/base/mat4.h"
#include "render/mesh/shapes.h"
#include "render/mesh/triangle.h"
#include "render/scene/scene.h"
#include "render/schedule.h"
#include "tests/support/doc_block.h"
#include "tests/support/near.h"

typedef struct warnings {
    int n;
    char msg[8][LR_ERR_MSG_MAX];
} warnings;

static void collect(void *user, const char *msg)
{
    warnings *w = user;
    if (w->n < 8)
        snprintf(w->msg[w->n], sizeof w->msg[0], "%s", msg);
    w->n++;
}

static void expect_msg(const lr_err *e, const char *needle)
{
    if (!strstr(e->msg, needle))
        fail_msg("message '%s' lacks '%s'", e->msg, needle);
}

/* expected: NULL, or the one warning the scene must give (a substring of it). */
static lr_scene *load_warns(const char *path, const char *expected)
{
    lr_scene *s = NULL;
    lr_err e = {0};
    warnings w = {0};
    lr_warn_sink sink = {collect, &w};
    if (lr_scene_load(path, &sink, &s, &e))
        fail_msg("%s", e.msg);
    /* The shipped scenes build without a single repair. */
    if (expected) {
        assert_int_equal(w.n, 1);
        if (!strstr(w.msg[0], expected))
            fail_msg("%s: warning '%s' lacks '%s'", path, w.msg[0], expected);
    } else if (w.n) {
        fail_msg("%s: unexpected warning: %s", path, w.msg[0]);
    }
    /* The sink must outlive the scene: later changes may warn. A changed mesh of the shipped
     * scenes does not, so a dangling pointer would only matter then; keep none. */
    lr_scene_destroy(s);
    assert_int_equal(lr_scene_load(path, NULL, &s, &e), LR_OK);
    return s;
}

static lr_scene *load(const char *path) { return load_warns(path, NULL); }

static char tmpdir[64];

static int setup(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/lr_scene_XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

/* Parses a scene text named tmpdir/t.json (relative mesh paths resolve in tmpdir). */
static int parse(const char *text, lr_scene **s, lr_err *e)
{
    char name[128];
    snprintf(name, sizeof name, "%s/t.json", tmpdir);
    return lr_scene_parse(text, strlen(text), name, NULL, s, e);
}

static void get(const lr_scene *s, const char *key, const char *want)
{
    char buf[256];
    lr_err e = {0};
    if (lr_scene_get(s, key, buf, sizeof buf, &e))
        fail_msg("get %s: %s", key, e.msg);
    if (strcmp(buf, want) != 0)
        fail_msg("get %s = '%s', expected '%s'", key, buf, want);
}

/* Sets key and asserts exactly the dirty flags `want` come back. */
static void set_ok(lr_scene *s, const char *key, const char *value, unsigned want)
{
    unsigned d = 0;
    lr_err e = {0};
    if (lr_scene_set(s, key, value, &d, &e))
        fail_msg("set %s=%s: %s", key, value, e.msg);
    if (d != want)
        fail_msg("set %s: dirty %#x, expected %#x", key, d, want);
}

/* Asserts a refused change: the message starts with the key and contains needle, the dirty
 * mask is untouched and the value reads back as before. */
static void set_bad(lr_scene *s, const char *key, const char *value, const char *needle)
{
    char before[256] = "", after[256] = "";
    lr_err ge = {0};
    bool readable = lr_scene_get(s, key, before, sizeof before, &ge) == LR_OK;
    unsigned d = 0x100;
    lr_err e = {0};
    int rc = lr_scene_set(s, key, value, &d, &e);
    if (rc == LR_OK)
        fail_msg("set %s=%s accepted", key, value);
    assert_int_equal(d, 0x100);
    if (strncmp(e.msg, key, strlen(key)) != 0)
        fail_msg("message '%s' does not start with the key '%s'", e.msg, key);
    expect_msg(&e, needle);
    if (readable) {
        assert_int_equal(lr_scene_get(s, key, after, sizeof after, &ge), LR_OK);
        assert_string_equal(before, after);
    }
}

/* ---- shipped scenes ----------------------------------------------------------------------- */

static void test_candle_scene(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/candle.json");
    assert_string_equal(lr_scene_name(s), "candle");
    assert_int_equal(lr_scene_object_count(s), 1);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_string_equal(o->name, "pillar");
    assert_int_equal(o->kind, LR_MESH_CANDLE);
    assert_true(o->closed);
    /* A wax preset, scaled from a measured one (candle_wax = marble at half density). */
    lr_material wax, marble;
    lr_err e = {0};
    assert_int_equal(lr_material_find("candle_wax", &wax, &e), LR_OK);
    assert_int_equal(lr_material_find("marble", &marble, &e), LR_OK);
    assert_string_equal(o->material.name, "candle_wax");
    for (int b = 0; b < 3; b++) {
        assert_true(o->material.medium.sigma_a[b] == wax.medium.sigma_a[b]);
        assert_true(o->material.medium.sigma_s_prime[b] == 0.5 * marble.medium.sigma_s_prime[b]);
        assert_true(o->coeffs.sigma_tr[b] > 0 && isfinite(o->coeffs.sigma_tr[b]));
    }
    /* A 70 mm pillar, 120 mm tall, standing on the table. */
    lr_vec3 lo, hi;
    lr_mesh_bounds(o->mesh, &lo, &hi);
    assert_true(fabs(hi.x - lo.x - 70) < 1e-4 && fabs(hi.z - 120) < 1e-4 && fabs(lo.z) < 1e-9);
    /* The flame: a point light in the melt pool, below the rim, above the pool's surface. */
    assert_int_equal(lr_scene_light_count(s), 1);
    const lr_light *l = lr_scene_light_at(s, 0);
    assert_int_equal(l->type, LR_LIGHT_POINT);
    assert_true(l->position.z < 120 && l->position.z > 112);
    assert_true(l->flicker.amplitude > 0);
    int obj = -2;
    assert_int_equal(lr_scene_light_enclosure(s, 0, &obj), LR_ENCLOSURE_HULL);
    assert_int_equal(obj, 0);
    /* Wax surrounds it: every horizontal ray from the flame hits the wax, as does the ray
     * down; only upward rays escape through the pool's opening. */
    for (int k = 0; k < 16; k++) {
        double a = 2 * M_PI * k / 16;
        assert_true(lr_bvh_occluded(o->bvh, l->position, lr_v3(cos(a), sin(a), 0), 0, 1e4));
    }
    assert_true(lr_bvh_occluded(o->bvh, l->position, lr_v3(0, 0, -1), 0, 1e4));
    assert_false(lr_bvh_occluded(o->bvh, l->position, lr_v3(0, 0, 1), 0, 1e4));
    /* Table and wall. */
    assert_int_equal(lr_scene_receiver_count(s), 2);
    int t = lr_scene_find_receiver(s, "table"), w = lr_scene_find_receiver(s, "wall");
    assert_true(t >= 0 && w >= 0);
    const lr_receiver *table = lr_scene_receiver_at(s, t), *wall = lr_scene_receiver_at(s, w);
    assert_true(table->normal.z == 1.0 && wall->normal.y == -1.0);
    assert_true(table->albedo[0] > 0 && table->albedo[0] <= 1);
    assert_true(fabs(lr_mesh_area(wall->mesh) - 1200.0 * 800.0) < 1e-6);
    /* The wall stands behind the candle as the camera sees it. */
    assert_true(wall->center.y > hi.y && lr_scene_camera(s)->position.y < lo.y);
    const lr_render_settings *r = lr_scene_render(s);
    assert_true(r->K == 16 && r->N == 16 && r->N_vpl == 64 && r->frames == 64);
    /* The shipped budget, one the proxy's table meets (render/plan/README.md). */
    assert_true(lr_scene_quality(s)->max_error == 0.15 && lr_scene_quality(s)->frame_ms == 600);
    lr_scene_destroy(s);
}

/* jar_candle.json, issue 12's scene not tuned on: a candle burnt down into a deep pool, the
 * flame 30 mm below the rim. The escape cone follows from the paraboloid pool (depth 35 at
 * the axis, radius 36; the flame 5 mm above its bottom at z = 65): a ray at elevation t
 * (slope) meets z = 65 + 35 r^2 / 36^2 where 35 r^2 / 1296 - t r - 5 = 0, inside the rim
 * (r < 36) for t < 30 / 36 (40 degrees), so rays at 35 degrees hit the wax (r = 31.8 mm) and
 * at 50 degrees leave through the opening (r = 48 > 36): 4 mm of margin over the facets. */
static void test_jar_candle_scene(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/jar_candle.json");
    assert_string_equal(lr_scene_name(s), "jar_candle");
    assert_int_equal(lr_scene_object_count(s), 1);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_int_equal(o->kind, LR_MESH_CANDLE);
    assert_true(o->closed);
    assert_string_equal(o->material.name, "candle_wax");
    /* The shipped model is the default; the wall thickness is there for the multipole rows. */
    assert_int_equal(o->sss_model, LR_SSS_DIRECTIONAL_DIPOLE);
    assert_true(o->thickness_mm == 16.0);
    lr_vec3 lo, hi;
    lr_mesh_bounds(o->mesh, &lo, &hi);
    assert_true(fabs(hi.x - lo.x - 80) < 1e-4 && fabs(hi.z - 100) < 1e-4 && fabs(lo.z) < 1e-9);
    assert_int_equal(lr_scene_light_count(s), 1);
    const lr_light *l = lr_scene_light_at(s, 0);
    assert_int_equal(l->type, LR_LIGHT_POINT);
    assert_true(l->position.z == 70.0);
    int obj = -2;
    assert_int_equal(lr_scene_light_enclosure(s, 0, &obj), LR_ENCLOSURE_HULL);
    assert_int_equal(obj, 0);
    /* The pool's bottom (the axis vertex at 100 - 35) is 5 mm under the flame. */
    lr_hit h;
    assert_true(lr_bvh_intersect(o->bvh, l->position, lr_v3(0, 0, -1), 0, 1e4, &h));
    assert_true(fabs(h.t - 5.0) < 1e-4);
    for (int k = 0; k < 16; k++) {
        double a = 2 * M_PI * k / 16;
        for (int j = 0; j < 2; j++) {
            double el = (j ? 35.0 : 0.0) * M_PI / 180;
            lr_vec3 d = lr_v3(cos(a) * cos(el), sin(a) * cos(el), sin(el));
            assert_true(lr_bvh_occluded(o->bvh, l->position, d, 0, 1e4));
        }
        double el = 50.0 * M_PI / 180;
        assert_false(lr_bvh_occluded(o->bvh, l->position,
                                     lr_v3(cos(a) * cos(el), sin(a) * cos(el), sin(el)), 0, 1e4));
    }
    assert_true(lr_scene_find_receiver(s, "table") >= 0 && lr_scene_find_receiver(s, "wall") >= 0);
    lr_scene_destroy(s);
}

static void test_lampshade_scene(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/lampshade.json");
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_int_equal(o->kind, LR_MESH_SHADE);
    assert_string_equal(o->material.name, "porcelain");
    /* Shade ~150-250 mm across, open top and bottom: a ray up the axis leaves untouched. */
    lr_vec3 lo, hi;
    lr_mesh_bounds(o->mesh, &lo, &hi);
    assert_true(hi.x - lo.x > 150 && hi.x - lo.x < 250);
    const lr_light *bulb = lr_scene_light_at(s, 0);
    assert_false(lr_bvh_occluded(o->bvh, bulb->position, lr_v3(0, 0, 1), 0, 1e4));
    assert_false(lr_bvh_occluded(o->bvh, bulb->position, lr_v3(0, 0, -1), 0, 1e4));
    /* Sideways through the middle of a facet (half a segment round, 3 mm off a ring): the
     * inner and outer facets are the vertex radii's offset delta apart radially, which is
     * delta cos(pi/96) at the facet's middle; 1e-4 mm covers float positions ~200 mm. */
    lr_hit h1, h2;
    double a = M_PI / 96;
    lr_vec3 from = lr_v3_add(bulb->position, lr_v3(0, 0, 3)), dir = lr_v3(cos(a), sin(a), 0);
    assert_true(lr_bvh_intersect(o->bvh, from, dir, 0, 1e4, &h1));
    assert_true(lr_bvh_intersect(o->bvh, from, dir, h1.t + 1e-6, 1e4, &h2));
    lr_shade_desc sd = {.radius_bottom = 110, .radius_top = 70, .height = 170, .thickness = 1.5,
                        .segments = 96};
    assert_true(fabs((h2.t - h1.t) - lr_shade_radial_offset(&sd) * cos(a)) < 1e-4);
    /* The bulb is inside the shade's bounding volume (its convex hull), not in the porcelain. */
    int obj;
    assert_int_equal(lr_scene_light_enclosure(s, 0, &obj), LR_ENCLOSURE_HULL);
    assert_int_equal(obj, 0);
    assert_true(lr_scene_find_receiver(s, "table") >= 0 && lr_scene_find_receiver(s, "wall") >= 0);
    lr_scene_destroy(s);
}

static void test_sphere_and_votive_scenes(void **state)
{
    (void)state;
    /* The light sits inside solid material: the loader says so (issue 3: never a silent 0). */
    lr_scene *s = load_warns("configs/scenes/sphere.json",
                             "sphere.json:16: lights[0] 'core' at (0, 0, 0) is inside the "
                             "material of objects[0] 'ball' (white_no_absorption): it "
                             "lights nothing the renderer draws");
    assert_false(lr_scene_object_at(s, 0)->sd_raw); /* energy-normalised S_d by default */
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    /* Non-absorbing: sigma_a = 0, so sigma_tr = 0 (albedo 1). */
    for (int b = 0; b < 3; b++)
        assert_true(o->material.medium.sigma_a[b] == 0.0 && o->coeffs.sigma_tr[b] == 0.0);
    assert_int_equal(lr_scene_light_enclosure(s, 0, NULL), LR_ENCLOSURE_SOLID);
    /* Defaults where the file is silent. */
    const lr_render_settings *r = lr_scene_render(s);
    assert_true(r->K == 16 && r->N == 16 && r->N_vpl == 64 && r->map_size == 256 &&
                r->gbuffer_size == 256 && r->vpl_map_size == 64 && r->frames == 64);
    /* exposure_ev 19.908 (configs/scenes/README.md: the multiplier 1e3 it had): the check
     * derives the multiplier, 9.8352e8 / 2^EV. */
    assert_true(r->exposure_ev == 19.908);
    assert_near(r->exposure, 9.8352e8 / pow(2.0, 19.908), 1e-12 * r->exposure);
    assert_near(r->exposure, 1e3, 3e-4 * 1e3);
    assert_int_equal(lr_scene_receiver_count(s), 0);
    lr_scene_destroy(s);

    /* A designer's mesh file, path relative to the scene; a scaled preset inline. */
    s = load("configs/scenes/votive.json");
    o = lr_scene_object_at(s, 0);
    assert_int_equal(o->kind, LR_MESH_FILE);
    assert_true(o->closed);
    lr_material wax;
    lr_err e = {0};
    assert_int_equal(lr_material_find("candle_wax", &wax, &e), LR_OK);
    for (int b = 0; b < 3; b++)
        assert_true(fabs(o->material.medium.sigma_s_prime[b] - 1.5 * wax.medium.sigma_s_prime[b]) <
                    1e-15);
    assert_int_equal(lr_scene_light_enclosure(s, 0, NULL), LR_ENCLOSURE_HULL);
    get(s, "objects[votive].material.scale", "1.5");
    get(s, "objects[votive].mesh.path", "../meshes/votive.obj");
    lr_scene_destroy(s);
}

/* The refined copy lies on the described surface: every vertex of it on a triangle of the
 * built mesh (float positions: 1e-4 mm at these 100 mm sizes), its normal within the crease
 * angle (60 degrees) of that triangle's face, and the same area. */
static void expect_refined_copy(const lr_scene_object *o)
{
    const lr_mesh *m = o->mesh, *b = o->built_mesh;
    assert_true(lr_mesh_longest_edge(m) <= 12.0 + 1e-9);
    assert_near_rel(lr_mesh_area(m), lr_mesh_area(b), 1e-6);
    const float *N = lr_mesh_normals(m);
    for (size_t v = 0; v < lr_mesh_vertex_count(m); v++) {
        lr_vec3 x = lr_mesh_vertex(m, v), n = lr_v3(N[3 * v], N[3 * v + 1], N[3 * v + 2]);
        double best = INFINITY, cos_best = -2;
        for (size_t t = 0; t < lr_mesh_triangle_count(b); t++) {
            lr_vec3 p[3];
            double w[3];
            lr_mesh_triangle(b, t, p);
            double d = lr_v3_len(lr_v3_sub(lr_closest_on_triangle(x, p[0], p[1], p[2], w), x));
            double c = lr_v3_dot(n, lr_mesh_triangle_normal(b, t));
            if (d < best - 1e-6 || (d < best + 1e-6 && c > cos_best)) {
                best = fmin(best, d);
                cos_best = c;
            }
        }
        assert_true(best < 1e-4);
        assert_near(lr_v3_len(n), 1.0, 1e-6);
        assert_true(cos_best > 0.5 - 1e-6);
    }
}

/* The renderer draws each object's mesh refined to edges of at most 12 mm (per-vertex values:
 * translucent radiosity's B, the receivers' light on objects); the physical reference traces
 * built_mesh, the surface as described. */
static void test_refined_mesh(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/votive.json");
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_true(o->mesh != o->built_mesh);
    assert_near(lr_mesh_longest_edge(o->built_mesh), hypot(65.0, 2 * 40.0 * sin(M_PI / 32)), 1e-3);
    assert_true(lr_mesh_triangle_count(o->mesh) > 10 * lr_mesh_triangle_count(o->built_mesh));
    expect_refined_copy(o);
    /* A rebuilt object (a transform change) is refined again. */
    lr_err e = {0};
    assert_int_equal(lr_scene_set(s, "objects[0].transform.scale", "1.5,1.5,1.5", NULL, &e),
                     LR_OK);
    o = lr_scene_object_at(s, 0);
    assert_near(lr_mesh_longest_edge(o->built_mesh), 1.5 * hypot(65.0, 2 * 40.0 * sin(M_PI / 32)), 2e-3);
    expect_refined_copy(o);
    lr_scene_destroy(s);
    /* A mesh fine enough already is drawn as built. */
    s = load_warns("configs/scenes/sphere.json", "inside the material");
    o = lr_scene_object_at(s, 0);
    assert_true(lr_mesh_longest_edge(o->built_mesh) <= 12.0);
    assert_ptr_equal(o->mesh, o->built_mesh);
    lr_scene_destroy(s);
}

static void test_camera_matrices(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/candle.json");
    const lr_camera *c = lr_scene_camera(s);
    double v[16], p[16], vp[16];
    lr_camera_view(c, v);
    lr_camera_projection(c, 4.0 / 3.0, p);
    /* The target lies on the view axis at its distance: exact up to rounding (1e-9 mm). */
    lr_vec3 t = lr_mat4_point(v, c->target);
    double dist = lr_v3_len(lr_v3_sub(c->target, c->position));
    assert_true(fabs(t.x) < 1e-9 && fabs(t.y) < 1e-9 && fabs(t.z + dist) < 1e-9);
    /* Up stays up: a point above the target projects above the centre. */
    lr_mat4_mul(p, v, vp);
    lr_vec3 ndc = lr_mat4_project(vp, c->target);
    assert_true(fabs(ndc.x) < 1e-12 && fabs(ndc.y) < 1e-12 && ndc.z > -1 && ndc.z < 1);
    assert_true(lr_mat4_project(vp, lr_v3_add(c->target, lr_v3(0, 0, 10))).y > 0);
    /* The vertical field of view: a point at the top edge of the frustum maps to y = 1. */
    double half = c->fov_deg / 2 * M_PI / 180;
    lr_vec3 view_top = lr_v3(0, dist * tan(half), -dist);
    double inv[16];
    assert_int_equal(lr_mat4_inverse(v, inv), 0);
    assert_true(fabs(lr_mat4_project(vp, lr_mat4_point(inv, view_top)).y - 1) < 1e-9);
    /* The float versions are the double ones rounded. */
    float vf[16], pf[16];
    lr_camera_view_f(c, vf);
    lr_camera_projection_f(c, 4.0 / 3.0, pf);
    for (int i = 0; i < 16; i++)
        assert_true(vf[i] == (float)v[i] && pf[i] == (float)p[i]);
    /* Orthographic: the view height maps to [-1, 1]. */
    unsigned d = 0;
    lr_err e = {0};
    assert_int_equal(lr_scene_set(s, "camera.type", "orthographic", &d, &e), LR_OK);
    assert_int_equal(lr_scene_set(s, "camera.height_mm", "400", &d, &e), LR_OK);
    lr_camera_projection(lr_scene_camera(s), 1.0, p);
    lr_mat4_mul(p, v, vp);
    lr_vec3 top = lr_mat4_point(inv, lr_v3(0, 200, -dist));
    assert_true(fabs(lr_mat4_project(vp, top).y - 1) < 1e-9);
    lr_scene_destroy(s);
}

static void test_light_shape_and_flicker(void **state)
{
    (void)state;
    lr_light spot = {.type = LR_LIGHT_SPOT, .direction = lr_v3(0, 0, -1), .inner_deg = 20,
                     .outer_deg = 30, .intensity = 2, .color = {1, 0.5, 0.25}};
    double rgb[3];
    lr_light_rgb(&spot, rgb);
    assert_true(rgb[0] == 2 && rgb[1] == 1 && rgb[2] == 0.5);
    assert_true(lr_light_shape(&spot, lr_v3(0, 0, -1)) == 1.0);
    double a = 25 * M_PI / 180; /* halfway in angle: strictly between */
    double mid = lr_light_shape(&spot, lr_v3(sin(a), 0, -cos(a)));
    assert_true(mid > 0.0 && mid < 1.0);
    a = 31 * M_PI / 180;
    assert_true(lr_light_shape(&spot, lr_v3(sin(a), 0, -cos(a))) == 0.0);

    lr_scene *s = load("configs/scenes/candle.json");
    const lr_light *l = lr_scene_light_at(s, 0);
    double s1, s2;
    lr_vec3 o1, o2;
    lr_light_flicker_at(l, 1.234, &s1, &o1);
    lr_light_flicker_at(l, 1.234, &s2, &o2);
    assert_true(s1 == s2 && o1.x == o2.x && o1.y == o2.y && o1.z == o2.z); /* deterministic */
    /* Mean 1: the average of each sine over T = 100 s at >= 7 Hz is at most 1/(pi f T) <
     * 5e-4 of its weight, sampling at 100 Hz aliases none of 7, 11.3, 19 Hz onto 0 Hz. So
     * |mean - 1| < amplitude * 1e-3; the swing stays within the amplitude and the sway within
     * jitter_mm. */
    double sum = 0, lo = INFINITY, hi = -INFINITY, sway = 0;
    for (int i = 0; i < 10000; i++) {
        double f;
        lr_vec3 off;
        lr_light_flicker_at(l, i * 0.01, &f, &off);
        sum += f;
        lo = fmin(lo, f);
        hi = fmax(hi, f);
        sway = fmax(sway, lr_v3_len(off));
    }
    assert_true(fabs(sum / 10000 - 1) < l->flicker.amplitude * 1e-3);
    assert_true(lo >= 1 - l->flicker.amplitude && hi <= 1 + l->flicker.amplitude);
    assert_true(hi - lo > l->flicker.amplitude); /* it does flicker */
    assert_true(sway > 0 && sway <= sqrt(2.0 + 1.0 / 9.0) * l->flicker.jitter_mm);
    lr_scene_destroy(s);
}

/* ---- errors in files ---------------------------------------------------------------------- */

/* A valid scene with a placeholder for one line of the object and one of the light. */
static void scene_text(char *buf, size_t cap, const char *object_extra, const char *light_extra,
                       const char *mesh)
{
    snprintf(buf, cap,
             "{\n"                                                       /* 1 */
             "  \"objects\": [\n"                                        /* 2 */
             "    {\"name\": \"c\",\n"                                   /* 3 */
             "     \"material\": \"candle_wax\",\n"                      /* 4 */
             "     \"mesh\": %s%s\n"                                     /* 5 */
             "    }\n"                                                   /* 6 */
             "  ],\n"                                                    /* 7 */
             "  \"lights\": [\n"                                         /* 8 */
             "    {\"type\": \"point\", \"position\": [0, 0, 115],\n"    /* 9 */
             "     \"intensity\": 0.01%s}\n"                             /* 10 */
             "  ],\n"                                                    /* 11 */
             "  \"camera\": {\"position\": [0, -400, 200],\n"            /* 12 */
             "             \"target\": [0, 0, 60]}\n"                    /* 13 */
             "}\n",
             mesh ? mesh : "{\"type\": \"candle\"}", object_extra, light_extra);
}

static void expect_scene_error(const char *text, int code, const char *needle)
{
    lr_scene *s = NULL;
    lr_err e = {0};
    int rc = parse(text, &s, &e);
    if (rc == LR_OK)
        fail_msg("accepted:\n%s", text);
    assert_null(s);
    assert_int_equal(rc, code);
    expect_msg(&e, needle);
}

static void test_file_errors_name_file_line_field(void **state)
{
    (void)state;
    char t[2048];
    lr_scene *s;
    lr_err e = {0};
    scene_text(t, sizeof t, "", "", NULL);
    assert_int_equal(parse(t, &s, &e), LR_OK);
    lr_scene_destroy(s);

    /* Unknown field (a typo), on its line. */
    scene_text(t, sizeof t, ",\n     \"colour\": [1, 1, 1]", "", NULL);
    expect_scene_error(t, LR_EPARSE, "t.json:6: field 'colour': unknown field in objects[0]");
    /* Wrong type. */
    scene_text(t, sizeof t, "", ", \"color\": \"warm\"", NULL);
    expect_scene_error(t, LR_EPARSE, "t.json:10: field 'lights[0].color': expected an array, "
                                     "got a string");
    /* A duplicate field (the second would silently win in a lax reader). */
    scene_text(t, sizeof t, "", ",\n     \"intensity\": -1", NULL);
    expect_scene_error(t, LR_EPARSE, "t.json:11: field 'lights[0].intensity': duplicate key "
                                     "(first on line 10)");
    /* A value out of range, at its own line. */
    snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"candle_wax\", \"mesh\": {\"type\": "
             "\"sphere\"}}],\n \"lights\": [{\"type\": \"point\", \"position\": [0,0,0],\n"
             " \"intensity\": -1}],\n \"camera\": {\"position\": [0,-1,0], \"target\": [0,0,0]}}");
    expect_scene_error(t, LR_EINVAL, "t.json:3: field 'lights[0].intensity': must be >= 0 "
                                     "(W/sr), got -1");
    /* Missing material; unknown preset; an inline material's own error. */
    snprintf(t, sizeof t, "{\"objects\": [\n {\"mesh\": {\"type\": \"sphere\"}}],\n"
             " \"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": 1}],\n"
             " \"camera\": {\"position\": [0,-1,0], \"target\": [0,0,0]}}");
    expect_scene_error(t, LR_EPARSE, "t.json:2: field 'objects[0].material': missing (required");
    scene_text(t, sizeof t, "", "", NULL);
    char *m = strstr(t, "candle_wax");
    memcpy(m, "candlewax_", 10);
    expect_scene_error(t, LR_EIO, "t.json:4: field 'objects[0].material': no usable preset "
                                  "'candlewax_'");
    /* Mesh parameters: the generator's check, at the parameter's line. */
    scene_text(t, sizeof t, "", "",
               "{\"type\": \"candle\",\n       \"height\": 100, \"pool_depth\": 120}");
    expect_scene_error(t, LR_EINVAL, "t.json:6: field 'objects[0].mesh.pool_depth': must be > 0 "
                                     "and < height (100 mm), got 120");
    scene_text(t, sizeof t, "", "", "{\"type\": \"cylinder\"}");
    expect_scene_error(t, LR_EINVAL, "t.json:5: field 'objects[0].mesh.type': unknown type "
                                     "'cylinder' (one of: candle, shade, sphere, box, file)");
    /* A mesh file that is not there: the path in the scene, then the reason. */
    scene_text(t, sizeof t, "", "", "{\"type\": \"file\",\n  \"path\": \"nope.ply\"}");
    expect_scene_error(t, LR_EIO, "t.json:6: field 'objects[0].mesh.path': ");
    expect_scene_error(t, LR_EIO, "nope.ply: cannot open");
    /* A broken mesh file: its own file and line come through. */
    char mp[128];
    snprintf(mp, sizeof mp, "%s/bad.obj", tmpdir);
    FILE *f = fopen(mp, "w");
    fputs("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", f);
    fclose(f);
    scene_text(t, sizeof t, "", "", "{\"type\": \"file\", \"path\": \"bad.obj\"}");
    expect_scene_error(t, LR_EINVAL, "bad.obj:4: vertex index 4 out of range (3 vertices)");
    /* Cross-field checks: a spot's inner cone wider than its outer one. */
    snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"candle_wax\", \"mesh\": {\"type\": "
             "\"sphere\"}}],\n \"lights\": [{\"type\": \"spot\", \"position\": [0,0,200], "
             "\"direction\": [0,0,-1],\n \"inner_deg\": 40, \"outer_deg\": 30, \"intensity\": 1}],\n"
             " \"camera\": {\"position\": [0,-1,0], \"target\": [0,0,0]}}");
    expect_scene_error(t, LR_EINVAL, "t.json:3: field 'lights[0].inner_deg': must be in (0, "
                                     "outer_deg = 30] degrees, got 40");
    /* A camera looking nowhere; an albedo above 1; duplicate names; nothing lit. */
    snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"candle_wax\", \"mesh\": {\"type\": "
             "\"sphere\"}}],\n \"lights\": [{\"type\": \"point\", \"position\": [0,0,0], "
             "\"intensity\": 1}],\n \"camera\": {\"position\": [0,0,9],\n \"target\": [0,0,9]}}");
    expect_scene_error(t, LR_EINVAL, "t.json:4: field 'camera.target': must differ from position");
    snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"candle_wax\", \"mesh\": {\"type\": "
             "\"sphere\"}}],\n \"lights\": [{\"type\": \"point\", \"position\": [0,0,0], "
             "\"intensity\": 1}],\n \"camera\": {\"position\": [0,-1,0], \"target\": [0,0,0]},\n"
             " \"receivers\": [{\"type\": \"plane\", \"center\": [0,0,0], \"normal\": [0,0,1], "
             "\"size\": [1, 1],\n \"albedo\": [1.2, 0.5, 0.5]}]}");
    expect_scene_error(t, LR_EINVAL, "t.json:5: field 'receivers[0].albedo': each band must be "
                                     "in [0, 1]");
    snprintf(t, sizeof t, "{\"objects\": [{\"name\": \"a\", \"material\": \"marble\", \"mesh\": "
             "{\"type\": \"sphere\"}},\n {\"name\": \"a\", \"material\": \"marble\", \"mesh\": "
             "{\"type\": \"box\"}}],\n \"lights\": [{\"type\": \"point\", \"position\": [0,0,0], "
             "\"intensity\": 1}],\n \"camera\": {\"position\": [0,-1,0], \"target\": [0,0,0]}}");
    expect_scene_error(t, LR_EINVAL, "t.json:2: field 'objects[1].name': 'a' is already the name "
                                     "of objects[0]");
    snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": "
             "\"sphere\"}}],\n \"lights\": [],\n \"camera\": {\"position\": [0,-1,0], "
             "\"target\": [0,0,0]}}");
    expect_scene_error(t, LR_EPARSE, "t.json:2: field 'lights': must not be empty");
    /* Not JSON at all. */
    expect_scene_error("{\"objects\": [", LR_EPARSE, "t.json:1: field 'objects': unexpected end of file");
    /* A file that is not there. */
    assert_int_equal(lr_scene_load("configs/scenes/no_such.json", NULL, &s, &e), LR_EIO);
    expect_msg(&e, "configs/scenes/no_such.json: cannot open");
}

/* ---- parameters -------------------------------------------------------------------------------- */

static void test_set_dirty_flags(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/candle.json");
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    const lr_light *l = lr_scene_light_at(s, 0);

    /* Dimmer: composition only, and the value is what was set. */
    set_ok(s, "light.intensity", "0.0025", LR_DIRTY_INTENSITY);
    assert_true(l->intensity == 0.0025);
    get(s, "lights[0].intensity", "0.0025");
    assert_int_equal(lr_dirty_passes(LR_DIRTY_INTENSITY), LR_PASS_BLEND);
    set_ok(s, "lights[flame].color", "1,0.5,0.25", LR_DIRTY_INTENSITY);
    assert_true(l->color[1] == 0.5);
    set_ok(s, "lights[0].flicker.amplitude", "0.2", LR_DIRTY_INTENSITY);

    /* The flame moves: everything. Flicker, sway included, is applied at composition on the
     * renderer's clock (the transport stays at the mean position): composition only. */
    set_ok(s, "lights[0].position", "[0, 0, 116]", LR_DIRTY_LIGHT_GEOMETRY);
    assert_true(l->position.z == 116);
    set_ok(s, "lights[0].flicker.jitter_mm", "0.5", LR_DIRTY_INTENSITY);
    set_ok(s, "lights[0].flicker.frequency_hz", "9", LR_DIRTY_INTENSITY);
    set_ok(s, "lights[0].flicker.seed", "4", LR_DIRTY_INTENSITY);
    assert_int_equal(lr_dirty_passes(LR_DIRTY_LIGHT_GEOMETRY),
                     LR_PASS_GBUFFER | LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE |
                         LR_PASS_SURFACE | LR_PASS_COMPOSE | LR_PASS_BLEND | LR_PASS_LPV);

    /* Materials: maps, VPLs and composition, not the light's G-buffer. */
    lr_material marble;
    lr_err e = {0};
    assert_int_equal(lr_material_find("marble", &marble, &e), LR_OK);
    set_ok(s, "objects[0].material", "marble", LR_DIRTY_MATERIAL);
    assert_string_equal(o->material.name, "marble");
    set_ok(s, "objects[pillar].material.scale", "2", LR_DIRTY_MATERIAL);
    for (int b = 0; b < 3; b++) /* x2 is exact in binary */
        assert_true(o->material.medium.sigma_s_prime[b] == 2 * marble.medium.sigma_s_prime[b]);
    get(s, "objects[0].material.scale", "2");
    get(s, "objects[0].material", "marble");
    set_ok(s, "objects[0].material.scale", "0.5,1,2", LR_DIRTY_MATERIAL);
    assert_true(o->material.medium.sigma_a[0] == 0.5 * marble.medium.sigma_a[0] &&
                o->material.medium.sigma_a[2] == 2 * marble.medium.sigma_a[2]);
    set_ok(s, "objects[0].material.eta", "1.3", LR_DIRTY_MATERIAL);
    assert_true(o->material.medium.eta == 1.3 && o->coeffs.eta == 1.3);
    set_ok(s, "objects[0].material.sigma_a", "0.01,0.02,0.03", LR_DIRTY_MATERIAL);
    assert_true(o->material.medium.sigma_a[1] == 0.02); /* an override is not scaled */
    get(s, "objects[0].material.sigma_a", "0.01,0.02,0.03");
    /* A new preset replaces the whole material, scale included. */
    set_ok(s, "objects[0].material", "candle_wax", LR_DIRTY_MATERIAL);
    get(s, "objects[0].material.scale", "1");
    assert_int_equal(lr_dirty_passes(LR_DIRTY_MATERIAL),
                     LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE | LR_PASS_SURFACE |
                         LR_PASS_COMPOSE | LR_PASS_BLEND | LR_PASS_LPV);

    /* View and receivers: composition only. */
    set_ok(s, "camera.position", "0,-500,250", LR_DIRTY_CAMERA);
    set_ok(s, "camera.fov_deg", "30", LR_DIRTY_CAMERA);
    assert_int_equal(lr_dirty_passes(LR_DIRTY_CAMERA), LR_PASS_COMPOSE | LR_PASS_BLEND);
    set_ok(s, "receivers[wall].albedo", "0.5,0.5,0.5", LR_DIRTY_RECEIVERS);
    set_ok(s, "receivers[table].center", "0,-75,-1", LR_DIRTY_RECEIVERS);
    assert_true(lr_mesh_vertex(lr_scene_receiver_at(s, 0)->mesh, 0).z == -1.0);
    assert_int_equal(lr_dirty_passes(LR_DIRTY_RECEIVERS),
                     LR_PASS_IRRADIANCE | LR_PASS_COMPOSE | LR_PASS_BLEND | LR_PASS_LPV);
    set_ok(s, "render.exposure", "1e6", LR_DIRTY_DISPLAY);
    assert_int_equal(lr_dirty_passes(LR_DIRTY_DISPLAY), LR_PASS_BLEND);
    set_ok(s, "render.K", "32", LR_DIRTY_SETTINGS);
    assert_int_equal(lr_scene_render(s)->K, 32);
    /* The renderer's limit (LR_SCENE_MAX_K, the radiosity pass's arrays) is the field's: 33
     * is refused here, not by the renderer after loading. */
    set_bad(s, "render.K", "33", "must be between 1 and 32, got 33");
    set_ok(s, "render.K", "0", LR_DIRTY_SETTINGS); /* 0: the default, as in the file */
    assert_int_equal(lr_scene_render(s)->K, 16);
    set_ok(s, "quality.max_error", "0.02", LR_DIRTY_SETTINGS);

    /* Geometry: everything, and the mesh and its BVH are rebuilt. Deeper pool: a ray down the
     * axis meets the wax at 120 - 12 (float positions: 1e-5 mm). */
    set_ok(s, "objects[0].mesh.pool_depth", "12", LR_DIRTY_GEOMETRY);
    lr_hit h;
    assert_true(lr_bvh_intersect(o->bvh, lr_v3(0, 0, 200), lr_v3(0, 0, -1), 0, 1e4, &h));
    assert_true(fabs(200 - h.t - 108) < 1e-5);
    get(s, "objects[0].mesh.pool_depth", "12");
    set_ok(s, "objects[0].transform.translate", "100,0,0", LR_DIRTY_GEOMETRY);
    assert_true(fabs(o->center.x - 100) < 1e-4);
    assert_int_equal(lr_dirty_passes(LR_DIRTY_GEOMETRY),
                     LR_PASS_GBUFFER | LR_PASS_RADIOSITY | LR_PASS_VPL | LR_PASS_IRRADIANCE |
                         LR_PASS_SURFACE | LR_PASS_COMPOSE | LR_PASS_BLEND | LR_PASS_LPV);
    /* The flame stayed at the origin: now outside the moved candle's hull. */
    assert_int_equal(lr_scene_light_enclosure(s, 0, NULL), LR_ENCLOSURE_NONE);
    set_ok(s, "light.position", "100,0,60", LR_DIRTY_LIGHT_GEOMETRY); /* in the wax */
    assert_int_equal(lr_scene_light_enclosure(s, 0, NULL), LR_ENCLOSURE_SOLID);
    set_ok(s, "objects[0].mesh.pool_depth", "0", LR_DIRTY_GEOMETRY); /* flat top */
    get(s, "objects[0].mesh.pool_depth", "0");

    /* Flags accumulate in the caller's mask; an empty mask needs no pass. */
    unsigned d = 0;
    assert_int_equal(lr_scene_set(s, "light.intensity", "0.005", &d, &e), LR_OK);
    assert_int_equal(lr_scene_set(s, "camera.far", "5000", &d, &e), LR_OK);
    assert_int_equal(d, LR_DIRTY_INTENSITY | LR_DIRTY_CAMERA);
    assert_int_equal(lr_dirty_passes(d), LR_PASS_COMPOSE | LR_PASS_BLEND);
    assert_int_equal(lr_dirty_passes(0), 0);
    assert_string_equal(lr_dirty_name(LR_DIRTY_MATERIAL), "material");
    /* --set KEY=VALUE: split at the first '='. */
    d = 0;
    assert_int_equal(lr_scene_set_assignment(s, "render.exposure=2e6", &d, &e), LR_OK);
    assert_true(lr_scene_render(s)->exposure == 2e6 && d == LR_DIRTY_DISPLAY);
    assert_int_equal(lr_scene_set_assignment(s, "render.exposure", &d, &e), LR_EINVAL);
    expect_msg(&e, "'render.exposure': expected KEY=VALUE");
    lr_scene_destroy(s);
}

static void test_set_rejects_bad_values(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/candle.json");
    set_bad(s, "light.intensity", "-1", "must be >= 0 (W/sr), got -1");
    set_bad(s, "light.intensity", "abc", "expected a number, got 'abc'");
    set_bad(s, "light.intensity", "nan", "expected a number");
    set_bad(s, "light.intensity", "0x10", "expected a number");
    set_bad(s, "light.intensity", "1 2", "expected a number");
    set_bad(s, "lights[0].position", "1,2", "expected x,y,z (three numbers), got '1,2'");
    set_bad(s, "lights[0].position", "1,2,1e999", "expected x,y,z");
    set_bad(s, "lights[0].radiance", "1", "a point light's strength is its 'intensity'");
    set_bad(s, "lights[0].outer_deg", "10", "a point light has no parameter 'outer_deg'");
    set_bad(s, "lights[3].intensity", "1", "index 3 out of range (the scene has 1 lights)");
    set_bad(s, "lights[candle].intensity", "1", "no lights named 'candle'");
    set_bad(s, "lights[0].flicker.amplitude", "1.5", "must be in [0, 1], got 1.5");
    set_bad(s, "objects[0].material", "no_such", "objects[0].material: no usable preset 'no_such'");
    set_bad(s, "objects[0].material", "../configs/x", "is not a name");
    set_bad(s, "objects[0].material.scale", "0", "must be > 0, got 0");
    set_bad(s, "objects[0].material.scale", "1,2", "expected a number or x,y,z");
    set_bad(s, "objects[0].material.eta", "9", "eta");
    set_bad(s, "objects[0].material.g", "1", "g");
    set_bad(s, "objects[0].material.colour", "1", "a material has no parameter 'colour'");
    set_bad(s, "objects[0].mesh.pool_depth", "130",
            "objects[0].mesh.pool_depth: must be > 0 and < height (120 mm), got 130");
    /* The scene file set pool_radius to 31: a 20 mm radius would leave it outside. */
    set_bad(s, "objects[0].mesh.radius", "20",
            "then pool_radius must be > 0 and <= radius (20 mm), got 31");
    set_bad(s, "objects[0].mesh.type", "sphere", "cannot change");
    set_bad(s, "objects[0].mesh.thickness", "2", "a candle mesh has no parameter 'thickness'");
    set_bad(s, "objects[0].transform.scale", "0", "must be > 0 (no mirroring)");
    set_bad(s, "camera.target", "0,-450,230", "must differ from position");
    set_bad(s, "camera.up", "0,0,0", "must be a non-zero vector");
    set_bad(s, "camera.fov_deg", "180", "must be in (0, 180) degrees");
    set_bad(s, "render.K", "1000", "must be between 1 and 32, got 1000");
    set_bad(s, "render.K", "2.5", "expected an integer");
    set_bad(s, "render.exposure", "-1", "must be > 0");
    set_bad(s, "receivers[wall].albedo", "1.2,0.5,0.5", "each band must be in [0, 1]");
    set_bad(s, "receivers[wall].size", "0,100", "must be > 0 mm");
    set_bad(s, "nonsense.x", "1", "unknown parameter");
    set_bad(s, "objects.material", "marble", "expected objects[INDEX or NAME].PARAMETER");
    set_bad(s, "camera[0].fov_deg", "30", "'camera' takes no index");
    /* After all that, the scene is as loaded. */
    get(s, "light.intensity", "0.005");
    get(s, "objects[0].mesh.pool_depth", "8");
    get(s, "objects[0].material", "candle_wax");
    lr_scene_destroy(s);
}

static void test_set_shade_and_file_mesh(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/lampshade.json");
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_true(o->closed);
    /* A thicker wall: the shell's volume grows in proportion (Pappus, see test_mesh). */
    double v1 = lr_mesh_volume(o->mesh);
    set_ok(s, "objects[shade].mesh.thickness", "2", LR_DIRTY_GEOMETRY);
    double ratio = lr_mesh_volume(o->mesh) / v1;
    assert_true(ratio > 1.3 && ratio < 1.34); /* 2/1.5 less the thinner inner radius */
    /* Without rims it is open; zero thickness is a single surface. The bulb stays inside the
     * bounding volume either way. */
    set_ok(s, "objects[shade].mesh.rims", "false", LR_DIRTY_GEOMETRY);
    assert_false(o->closed);
    get(s, "objects[shade].mesh.rims", "false");
    set_ok(s, "objects[shade].mesh.thickness", "0", LR_DIRTY_GEOMETRY);
    lr_mesh_report rep;
    lr_mesh_analyze(o->mesh, &rep);
    assert_int_equal(rep.boundary_loops, 2);
    assert_int_equal(lr_scene_light_enclosure(s, 0, NULL), LR_ENCLOSURE_HULL);
    get(s, "objects[0].mesh.thickness", "0");
    get(s, "objects[0].mesh.radius_top", "70");
    lr_scene_destroy(s);

    s = load("configs/scenes/votive.json");
    set_bad(s, "objects[0].mesh.path", "missing.obj", "missing.obj: cannot open");
    set_ok(s, "objects[0].mesh.scale", "1.5", LR_DIRTY_GEOMETRY);
    lr_vec3 lo, hi;
    lr_mesh_bounds(lr_scene_object_at(s, 0)->mesh, &lo, &hi);
    assert_true(fabs(hi.z - 1.5 * 65) < 1e-4);
    lr_scene_destroy(s);
}

/* Per object "normalize" (PIPELINE.md "Energy"): false selects [14]'s raw S_d; a bad value is
 * an error naming the field; lr_scene_set/get round-trip it and mark the material dirty. */
static void test_object_normalize_field(void **state)
{
    (void)state;
    const char *fmt = "{\"objects\": [{\"name\": \"b\", \"material\": \"marble\", "
                      "\"normalize\": %s, \"mesh\": {\"type\": \"sphere\", \"radius\": 10}}],"
                      " \"lights\": [{\"type\": \"point\", \"position\": [0, 0, 50],"
                      " \"intensity\": 1}],"
                      " \"camera\": {\"position\": [0, -100, 0], \"target\": [0, 0, 0]}}";
    char text[512];
    lr_scene *s = NULL;
    lr_err e = {0};
    snprintf(text, sizeof text, fmt, "false");
    if (parse(text, &s, &e))
        fail_msg("%s", e.msg);
    assert_true(lr_scene_object_at(s, 0)->sd_raw);
    assert_true(lr_scene_object_sd_norm(lr_scene_object_at(s, 0), 1) == 1.0);
    get(s, "objects[b].normalize", "false");
    unsigned dirty = 0;
    assert_int_equal(lr_scene_set(s, "objects[b].normalize", "true", &dirty, &e), LR_OK);
    assert_true(dirty & LR_DIRTY_MATERIAL);
    assert_false(lr_scene_object_at(s, 0)->sd_raw);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    assert_true(lr_scene_object_sd_norm(o, 1) == o->coeffs.sd_norm[1]);
    assert_true(o->coeffs.sd_norm[1] > 0.75 && o->coeffs.sd_norm[1] < 0.85); /* marble 0.81 */
    get(s, "objects[b].normalize", "true");
    /* The standard dipole's R_d is an exitance: its maps hold R_d / T_hem (composition lets
     * out T_hem of B), 1 / 0.908 at marble's eta 1.5 (render/scene/scene.h). */
    assert_int_equal(lr_scene_set(s, "objects[b].model", "standard_dipole", &dirty, &e), LR_OK);
    o = lr_scene_object_at(s, 0);
    assert_true(lr_scene_object_sd_norm(o, 1) == 1.0 / lr_hemi_transmittance(o->coeffs.eta));
    assert_true(o->coeffs.t_hem > 0.90 && o->coeffs.t_hem < 0.92);
    assert_int_equal(lr_scene_set(s, "objects[b].model", "directional_dipole", &dirty, &e),
                     LR_OK);
    o = lr_scene_object_at(s, 0);
    assert_true(lr_scene_object_sd_norm(o, 1) == o->coeffs.sd_norm[1]);
    assert_int_not_equal(lr_scene_set(s, "objects[b].normalize", "yes", &dirty, &e), LR_OK);
    expect_msg(&e, "expected true or false");
    lr_scene_destroy(s);
    snprintf(text, sizeof text, fmt, "3");
    assert_int_not_equal(parse(text, &s, &e), LR_OK);
    expect_msg(&e, "objects[0].normalize");
    expect_msg(&e, ":1");
}

/* objects[i].model (the diffusion-model switch) and the cap on lights. */
static void test_model_switch_and_light_cap(void **state)
{
    (void)state;
    char t[2048];
    lr_scene *s;
    lr_err e = {0};
    scene_text(t, sizeof t, "", "", NULL);
    assert_int_equal(parse(t, &s, &e), LR_OK);
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_DIRECTIONAL_DIPOLE);
    get(s, "objects[0].model", "directional_dipole");
    set_ok(s, "objects[c].model", "standard_dipole", LR_DIRTY_MATERIAL);
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_STANDARD_DIPOLE);
    get(s, "objects[0].model", "standard_dipole");
    set_bad(s, "objects[0].model", "jensen",
            "expected directional_dipole, standard_dipole, multipole, "); /* ... every model */
    /* seed 001's grid model and its spacing (issue 14) */
    set_ok(s, "objects[0].model", "diffusion_grid", LR_DIRTY_MATERIAL);
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_DIFFUSION_GRID);
    set_ok(s, "objects[0].dgrid_h_mm", "2.5", LR_DIRTY_MATERIAL);
    assert_true(lr_scene_object_at(s, 0)->dgrid_h_mm == 2.5);
    set_bad(s, "objects[0].dgrid_h_mm", "0.01", "dgrid_h_mm");
    /* Seed 002's model needs nothing else (issue 14). */
    set_ok(s, "objects[0].model", "sh_translucency", LR_DIRTY_MATERIAL);
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_SH_TRANSLUCENCY);
    set_ok(s, "objects[0].model", "standard_dipole", LR_DIRTY_MATERIAL);
    /* The multipole needs the wall's thickness first (issue 12). */
    set_bad(s, "objects[0].model", "multipole", "needs the object's thickness_mm set first");
    set_bad(s, "objects[0].thickness_mm", "-2", "objects[0].thickness_mm");
    /* 0 is "not given", which only the multipole refuses. */
    set_ok(s, "objects[0].thickness_mm", "0", LR_DIRTY_MATERIAL);
    set_ok(s, "objects[0].thickness_mm", "1.5", LR_DIRTY_MATERIAL);
    get(s, "objects[0].thickness_mm", "1.5");
    set_ok(s, "objects[0].model", "multipole", LR_DIRTY_MATERIAL);
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_MULTIPOLE);
    assert_true(lr_scene_object_at(s, 0)->thickness_mm == 1.5);
    set_bad(s, "objects[0].thickness_mm", "0", "the multipole needs a thickness > 0 mm");
    assert_true(lr_scene_object_at(s, 0)->thickness_mm == 1.5);
    /* The multipole's R and T are exitances too: 1 / T_hem. */
    assert_true(lr_scene_object_sd_norm(lr_scene_object_at(s, 0), 0) ==
                1.0 / lr_scene_object_at(s, 0)->coeffs.t_hem);
    lr_scene_destroy(s);
    scene_text(t, sizeof t, ",\n     \"model\": \"multipole\", \"thickness_mm\": 7", "", NULL);
    assert_int_equal(parse(t, &s, &e), LR_OK);
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_MULTIPOLE);
    assert_true(lr_scene_object_at(s, 0)->thickness_mm == 7.0);
    lr_scene_destroy(s);
    scene_text(t, sizeof t, ",\n     \"model\": \"multipole\"", "", NULL);
    expect_scene_error(t, LR_EPARSE, "field 'objects[0].thickness_mm': missing (required with "
                                     "model multipole)");
    scene_text(t, sizeof t, ",\n     \"model\": \"multipole\", \"thickness_mm\": -1", "", NULL);
    expect_scene_error(t, LR_EINVAL, "t.json:6: field 'objects[0].thickness_mm'");

    scene_text(t, sizeof t, ",\n     \"model\": \"standard_dipole\"", "", NULL);
    assert_int_equal(parse(t, &s, &e), LR_OK);
    assert_int_equal(lr_scene_object_at(s, 0)->sss_model, LR_SSS_STANDARD_DIPOLE);
    lr_scene_destroy(s);
    scene_text(t, sizeof t, ",\n     \"model\": \"dipole\"", "", NULL);
    expect_scene_error(t, LR_EINVAL, "t.json:6: field 'objects[0].model': 'dipole': expected "
                                     "directional_dipole, standard_dipole, multipole, ");
    scene_text(t, sizeof t, ",\n     \"model\": 1", "", NULL);
    expect_scene_error(t, LR_EPARSE, "t.json:6: field 'objects[0].model'");

    /* LR_SCENE_MAX_LIGHTS lights load; one more is refused at the lights array. */
    for (int n = LR_SCENE_MAX_LIGHTS; n <= LR_SCENE_MAX_LIGHTS + 1; n++) {
        int len = snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"candle_wax\", "
                           "\"mesh\": {\"type\": \"sphere\"}}],\n \"lights\": [");
        for (int i = 0; i < n; i++)
            len += snprintf(t + len, sizeof t - (size_t)len, "%s{\"type\": \"point\", "
                            "\"position\": [0,0,%d], \"intensity\": 1}", i ? ", " : "",
                            100 + i);
        snprintf(t + len, sizeof t - (size_t)len, "],\n \"camera\": {\"position\": [0,-1,0], "
                 "\"target\": [0,0,0]}}");
        if (n == LR_SCENE_MAX_LIGHTS) {
            assert_int_equal(parse(t, &s, &e), LR_OK);
            assert_int_equal(lr_scene_light_count(s), n);
            lr_scene_destroy(s);
        } else {
            expect_scene_error(t, LR_EINVAL, "t.json:2: field 'lights': 5 lights; at most 4");
        }
    }
}

/* configs/scenes/README.md quotes the field reference written from the tables that load, set
 * and check scenes (render/scene/field_tables.c): a field, range or default changed in one
 * place shows up in the other, or this fails. */
/* Area lights (issue 14, seed 004): the shipped LED shade's quads, a disk from text, changes by
 * name with their dirty bits, and the refusals (parallel edges, no radius, a point light's
 * strength name). */
static void test_area_lights(void **state)
{
    (void)state;
    lr_scene *s = load("configs/scenes/led_shade.json");
    assert_int_equal(lr_scene_light_count(s), 4);
    const lr_light *l = lr_scene_light_at(s, 0);
    assert_int_equal(l->type, LR_LIGHT_QUAD);
    assert_true(lr_light_is_area(l));
    assert_false(l->two_sided);
    /* 8 x 60 mm facing +x: edge_u x edge_v = (0,4,0) x (0,0,30). */
    assert_near(lr_light_area(l), 480.0, 1e-9);
    lr_vec3 n = lr_light_area_normal(l);
    assert_near(n.x, 1.0, 1e-12);
    assert_near(lr_light_shape(l, lr_v3(1, 0, 0)), 480.0, 1e-9);
    assert_near(lr_light_shape(l, lr_v3(-1, 0, 0)), 0.0, 0.0);
    assert_near(l->intensity, 5e-4, 1e-18);
    get(s, "lights[led_px].edge_u", "0,4,0");
    get(s, "lights[0].two_sided", "false");
    set_ok(s, "lights[0].radiance", "1e-3", LR_DIRTY_INTENSITY);
    set_ok(s, "lights[0].edge_v", "0,0,20", LR_DIRTY_LIGHT_GEOMETRY);
    set_ok(s, "lights[0].two_sided", "true", LR_DIRTY_LIGHT_GEOMETRY);
    assert_near(lr_light_shape(lr_scene_light_at(s, 0), lr_v3(-1, 0, 0)), 320.0, 1e-9);
    set_bad(s, "lights[0].edge_v", "0,8,0", "must not be parallel to edge_u");
    set_bad(s, "lights[0].intensity", "1", "a quad light's strength is its 'radiance'");
    set_bad(s, "lights[0].radius", "3", "a quad light has no parameter 'radius'");
    set_bad(s, "lights[0].radiance", "-1", "must be >= 0 (W/(mm^2 sr))");
    lr_scene_destroy(s);

    char t[1024];
    snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": "
             "\"sphere\"}}],\n \"lights\": [{\"type\": \"disk\", \"position\": [0,0,100],\n"
             " \"normal\": [0,0,-2], \"radius\": 10, \"radiance\": 0.5, \"two_sided\": true}],\n"
             " \"camera\": {\"position\": [0,-300,0], \"target\": [0,0,0]}}");
    lr_err e = {0};
    assert_int_equal(parse(t, &s, &e), LR_OK);
    l = lr_scene_light_at(s, 0);
    assert_int_equal(l->type, LR_LIGHT_DISK);
    assert_near(l->direction.z, -1.0, 1e-15); /* normalised */
    assert_near(lr_light_area(l), 100.0 * M_PI, 1e-9);
    assert_true(l->two_sided);
    set_bad(s, "lights[0].radius", "0", "must be > 0");
    set_ok(s, "lights[0].normal", "0,1,0", LR_DIRTY_LIGHT_GEOMETRY);
    lr_scene_destroy(s);
    /* Required fields and the edges' relation, at the file's line. */
    char *r = strstr(t, "\"radius\": 10, ");
    memset(r, ' ', strlen("\"radius\": 10, "));
    expect_scene_error(t, LR_EPARSE, "t.json:2: field 'lights[0].radius': missing (required");
    snprintf(t, sizeof t, "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": "
             "\"sphere\"}}],\n \"lights\": [{\"type\": \"quad\", \"position\": [0,0,100],\n"
             " \"edge_u\": [1,0,0], \"edge_v\": [-2,0,0], \"radiance\": 1}],\n"
             " \"camera\": {\"position\": [0,-300,0], \"target\": [0,0,0]}}");
    expect_scene_error(t, LR_EINVAL, "field 'lights[0].edge_v': must not be parallel");
}

static void test_readme_field_reference(void **state)
{
    (void)state;
    lr_test_doc_block("configs/scenes/README.md", "scene-fields", lr_scene_fields_markdown);
}

/* Issue 33: lights that light nothing the renderer draws. A box of wax (closed) holds light 0
 * inside its material; light 1 has zero power; light 2, outside, lights the box. The loader
 * warns for 0 and 1, naming each; the scene is dark only while light 2 is off too, and a
 * change (lr_scene_set) is seen at once. */
static void test_dark_lights(void **state)
{
    (void)state;
    const char *text =
        "{\"objects\": [{\"name\": \"block\", \"material\": \"candle_wax\",\n"
        "  \"mesh\": {\"type\": \"box\", \"size\": [40, 40, 40]}}],\n"
        " \"lights\": [\n"
        "  {\"type\": \"point\", \"name\": \"in\", \"position\": [1, 2, 3], \"intensity\": 1},\n"
        "  {\"type\": \"point\", \"name\": \"off\", \"position\": [0, 0, 100], "
        "\"intensity\": 0},\n"
        "  {\"type\": \"spot\", \"name\": \"side\", \"position\": [0, -200, 0], "
        "\"direction\": [0, 1, 0], \"intensity\": 1, \"color\": [0, 0, 0]}],\n"
        " \"camera\": {\"position\": [0, -300, 0], \"target\": [0, 0, 0], \"up\": [0, 0, 1]}}\n";
    char name[128];
    snprintf(name, sizeof name, "%s/dark.json", tmpdir);
    warnings w = {0};
    lr_warn_sink sink = {collect, &w};
    lr_scene *s = NULL;
    lr_err e = {0};
    if (lr_scene_parse(text, strlen(text), name, &sink, &s, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(w.n, 3);
    assert_non_null(strstr(w.msg[0], "dark.json:4: lights[0] 'in' at (1, 2, 3) is inside the "
                                     "material of objects[0] 'block' (candle_wax): it lights "
                                     "nothing the renderer draws"));
    assert_non_null(strstr(w.msg[1], "dark.json:5: lights[1] 'off' has zero power (intensity 0, "
                                     "color 1, 1, 1): it lights nothing"));
    assert_non_null(strstr(w.msg[2], "lights[2] 'side' has zero power (intensity 1, color 0, 0, 0)"));
    char why[LR_ERR_MSG_MAX];
    assert_true(lr_scene_dark(s, why, sizeof why));
    assert_non_null(strstr(why, "lights[0] 'in' at (1, 2, 3) is inside the material"));
    assert_non_null(strstr(why, "; lights[1] 'off' has zero power"));
    assert_non_null(strstr(why, "; lights[2] 'side' has zero power"));
    /* The spot gets a colour: it lights the box from outside. */
    if (lr_scene_set(s, "lights[2].color", "1,1,1", NULL, &e))
        fail_msg("%s", e.msg);
    assert_false(lr_scene_light_dark(s, 2, why, sizeof why));
    assert_string_equal(why, "");
    assert_false(lr_scene_dark(s, why, sizeof why));
    /* Moved into the box, it lights nothing again (the loader's warnings are not re-run: the
     * check is the callers', after their changes). */
    if (lr_scene_set(s, "lights[2].position", "0,0,-10", NULL, &e))
        fail_msg("%s", e.msg);
    assert_true(lr_scene_light_dark(s, 2, why, sizeof why));
    assert_non_null(strstr(why, "lights[2] 'side' at (0, 0, -10) is inside the material"));
    assert_true(lr_scene_dark(s, NULL, 0));
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_dark_lights),
        cmocka_unit_test(test_candle_scene),
        cmocka_unit_test(test_jar_candle_scene),
        cmocka_unit_test(test_lampshade_scene),
        cmocka_unit_test(test_sphere_and_votive_scenes),
        cmocka_unit_test(test_object_normalize_field),
        cmocka_unit_test(test_camera_matrices),
        cmocka_unit_test(test_light_shape_and_flicker),
        cmocka_unit_test(test_area_lights),
        cmocka_unit_test(test_file_errors_name_file_line_field),
        cmocka_unit_test(test_set_dirty_flags),
        cmocka_unit_test(test_set_rejects_bad_values),
        cmocka_unit_test(test_set_shade_and_file_mesh),
        cmocka_unit_test(test_model_switch_and_light_cap),
        cmocka_unit_test(test_refined_mesh),
        cmocka_unit_test(test_readme_field_reference),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
