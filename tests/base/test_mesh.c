/* Meshes: procedural shapes against their analytic area and volume, validation and repair,
 * PLY and OBJ files good and bad, ray casts and closest points of the BVH against brute force,
 * winding numbers and the convex-hull test behind "is this light enclosed". */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "tests/support/fs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render/base/mat4.h"
#include "render/base/paths.h"
#include "render/mesh/bvh.h"
#include "render/mesh/mesh.h"
#include "render/mesh/mesh_io.h"
#include "render/mesh/shapes.h"
#include "render/mesh/triangle.h"
#include "render/mesh/wall.h"

/* ---- helpers ---------------------------------------------------------------------------- */

typedef struct warnings {
    int n;
    char msg[16][LR_ERR_MSG_MAX];
} warnings;

static void collect(void *user, const char *msg)
{
    warnings *w = user;
    if (w->n < 16)
        snprintf(w->msg[w->n], sizeof w->msg[0], "%s", msg);
    w->n++;
}

static bool warned(const warnings *w, const char *needle)
{
    for (int i = 0; i < w->n && i < 16; i++)
        if (strstr(w->msg[i], needle))
            return true;
    return false;
}

static void expect_msg(const lr_err *e, const char *needle)
{
    if (!strstr(e->msg, needle))
        fail_msg("message '%s' lacks '%s'", e->msg, needle);
}

static char tmpdir[64];

static int setup_dir(void **state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/lr_mesh_XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown_dir(void **state)
{
    (void)state;
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

static const char *tmp_path(const char *leaf, char *buf, size_t cap)
{
    snprintf(buf, cap, "%s/%s", tmpdir, leaf);
    return buf;
}

/* dst = src with the first `from` replaced by `to`. */
static void replace_once(char *dst, size_t cap, const char *src, const char *from, const char *to)
{
    const char *p = strstr(src, from);
    assert_non_null(p);
    snprintf(dst, cap, "%.*s%s%s", (int)(p - src), src, to, p + strlen(from));
}


/* Deterministic random numbers for the ray tests (a local 64-bit LCG, Knuth's MMIX constants). */
typedef struct rng {
    uint64_t s;
} rng;

static double uniform(rng *r)
{
    r->s = r->s * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(r->s >> 11) * (1.0 / 9007199254740992.0);
}

static lr_vec3 random_dir(rng *r)
{
    double z = 2.0 * uniform(r) - 1.0, phi = 2.0 * M_PI * uniform(r);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    return lr_v3(s * cos(phi), s * sin(phi), z);
}

/* Float coordinates carry a relative rounding of 2^-24 = 6e-8; areas and volumes computed from
 * them are off by a few times that. 1e-6 relative is the slack every analytic comparison below
 * grants for float storage on top of the derived tessellation error. */
#define FLOAT_SLACK 1e-6

static void assert_between(double x, double lo, double hi, const char *what)
{
    if (!(x >= lo && x <= hi))
        fail_msg("%s = %.12g outside [%.12g, %.12g]", what, x, lo, hi);
}

/* ---- procedural shapes ------------------------------------------------------------------- */

static void test_sphere_watertight_area_volume(void **state)
{
    (void)state;
    const double r = 50.0;
    lr_mesh_report rep;
    lr_sphere_desc d = {.radius = r, .subdivisions = 4, .checks = {.report = &rep}};
    lr_mesh *m;
    lr_err e = {0};
    assert_int_equal(lr_mesh_sphere(&d, &m, &e), LR_OK);
    assert_int_equal(lr_mesh_triangle_count(m), 5120);
    assert_true(rep.closed);
    assert_true(rep.oriented);
    assert_int_equal(rep.boundary_edges, 0);
    assert_int_equal(rep.nonmanifold_edges, 0);
    assert_int_equal(rep.flipped, 0); /* generated outward, not repaired */
    assert_int_equal(rep.components, 1);
    assert_int_equal(rep.degenerate_removed + rep.duplicate_removed, 0);
    /* Euler: a closed genus-0 surface has V - E + F = 2 with E = 3F/2. */
    assert_int_equal((long)lr_mesh_vertex_count(m) - 3 * 5120 / 2 + 5120, 2);

    /* Bound (derived): every face is a chord triangle whose plane lies at r cos(beta) from the
     * centre, beta its angular circumradius. Radial projection maps the face onto the sphere
     * with area ratio d0 r^2 / d^3 for a point at distance d in [r cos beta, r] of a plane at
     * d0 = r cos beta, so sphere area <= face area / cos^2(beta); and a convex body inside the
     * sphere has less area than it. Hence 4 pi r^2 cos^2(beta_max) <= A <= 4 pi r^2. The
     * polyhedron contains the ball of radius r cos(beta_max) (all face planes are that far out)
     * and lies in the ball of radius r, so (4/3) pi r^3 cos^3 <= V <= (4/3) pi r^3. Convexity is
     * checked, not assumed. */
    double cos_beta = 1.0;
    lr_vec3 c = lr_v3(0, 0, 0);
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 n = lr_mesh_triangle_normal(m, t);
        lr_vec3 cen = lr_v3_scale(lr_v3_add(p[0], lr_v3_add(p[1], p[2])), 1.0 / 3.0);
        assert_true(lr_v3_dot(n, lr_v3_sub(cen, c)) > 0.0); /* outward */
        double d0 = lr_v3_dot(n, p[0]) / r;                  /* cos(beta) of this face */
        cos_beta = fmin(cos_beta, d0);
    }
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t += 7) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 n = lr_mesh_triangle_normal(m, t);
        for (size_t v = 0; v < lr_mesh_vertex_count(m); v++)
            assert_true(lr_v3_dot(n, lr_v3_sub(lr_mesh_vertex(m, v), p[0])) <= 1e-9 * r);
    }
    double A = 4.0 * M_PI * r * r, V = 4.0 / 3.0 * M_PI * r * r * r;
    assert_between(lr_mesh_area(m), A * cos_beta * cos_beta * (1 - FLOAT_SLACK),
                   A * (1 + FLOAT_SLACK), "sphere area");
    assert_between(lr_mesh_volume(m), V * pow(cos_beta, 3) * (1 - FLOAT_SLACK),
                   V * (1 + FLOAT_SLACK), "sphere volume");
    /* The bound is not vacuous: at 4 subdivisions the faces span < 3 degrees. */
    assert_true(cos_beta * cos_beta > 0.997);
    /* Bounding sphere: centred, radius r to float precision. */
    lr_vec3 bc;
    double br;
    lr_mesh_bounding_sphere(m, &bc, &br);
    assert_true(lr_v3_len(bc) < 1e-5 && fabs(br - r) < 1e-5);
    lr_mesh_destroy(m);
}

/* Exact area and volume of the candle of lr_candle_desc (see shapes.h). */
static void candle_exact(double R, double H, double d, double a, double *area, double *vol)
{
    double c = d / (a * a);
    double parab = M_PI / (6.0 * c * c) * (pow(1.0 + 4.0 * c * c * a * a, 1.5) - 1.0);
    *area = M_PI * R * R + 2.0 * M_PI * R * H + M_PI * (R * R - a * a) + parab;
    *vol = M_PI * R * R * H - M_PI * d * a * a / 2.0;
}

static void test_candle_watertight_area_volume(void **state)
{
    (void)state;
    const double R = 35, H = 120, d = 8, a = 32;
    const int n = 64, m = 16;
    lr_mesh_report rep;
    lr_candle_desc cd = {.radius = R, .height = H, .pool_depth = d, .pool_radius = a,
                         .segments = n, .pool_rings = m, .checks = {.report = &rep}};
    lr_mesh *mesh;
    lr_err e = {0};
    assert_int_equal(lr_mesh_candle(&cd, &mesh, &e), LR_OK);
    assert_true(rep.closed);
    assert_true(rep.oriented);
    assert_int_equal(rep.flipped, 0);
    assert_int_equal(rep.components, 1);
    assert_int_equal(rep.degenerate_removed + rep.duplicate_removed, 0);

    /* Tessellation error (derived). The mesh is the n-gon revolution of a profile polyline P
     * whose vertices lie on the exact profile. Between two rings each band is a planar
     * trapezoid (two parallel chords), so every horizontal cross-section is a regular n-gon
     * inscribed in the circle P gives: V_mesh = kV V_rev(P) exactly, kV = sin(2x)/(2x),
     * x = pi/n; and each band's area is kA sqrt(dz^2 + dr^2 cos^2 x) / sqrt(dz^2 + dr^2) times
     * its revolved area, kA = sin(x)/x, so A_mesh in [kA cos x, kA] * A_rev(P).
     * P is exact on the straight parts (bottom, wall, rim). In the pool f = H - d + c rho^2,
     * c = d/a^2, is convex and its chords lie above it by at most c h^2/4 (h = a/m): the dish
     * removes less, 0 <= V_rev(P) - V <= pi a^2 c h^2 / 4. Its revolved chords bound a convex
     * set inside the dish's, so A_rev(P) <= A; and with g(u) = sqrt(1+u^2), |g'| <= 1,
     * g'' <= 1, chord slope = f'(midpoint), a second-order expansion of 2 pi int rho g(f')
     * gives A - A_rev(P) <= 2 pi (c h^2 a / 6 + c^2 h^2 a^2 / 4). */
    double x = M_PI / n, kA = sin(x) / x, kV = sin(2 * x) / (2 * x);
    double c = d / (a * a), h = a / m;
    double A, V;
    candle_exact(R, H, d, a, &A, &V);
    double dA = 2 * M_PI * (c * h * h * a / 6 + c * c * h * h * a * a / 4);
    double dV = M_PI * a * a * c * h * h / 4;
    assert_between(lr_mesh_area(mesh), kA * cos(x) * (A - dA) * (1 - FLOAT_SLACK),
                   kA * A * (1 + FLOAT_SLACK), "candle area");
    assert_between(lr_mesh_volume(mesh), kV * V * (1 - FLOAT_SLACK),
                   kV * (V + dV) * (1 + FLOAT_SLACK), "candle volume");
    /* The pool is concave: the centre of its surface is d below the rim. */
    lr_vec3 lo, hi;
    lr_mesh_bounds(mesh, &lo, &hi);
    assert_true(fabs(hi.z - H) < 1e-5 && fabs(lo.z) < 1e-12);
    lr_bvh *b;
    assert_int_equal(lr_bvh_create(mesh, &b, &e), LR_OK);
    lr_hit hit;
    assert_true(lr_bvh_intersect(b, lr_v3(0, 0, H + 10), lr_v3(0, 0, -1), 0, INFINITY, &hit));
    assert_true(fabs(hit.t - (10 + d)) < 1e-5);
    lr_bvh_destroy(b);
    lr_mesh_destroy(mesh);

    /* A flat top is exact up to the angular factor: V = kV pi R^2 H. */
    lr_candle_desc flat = {.radius = R, .height = H, .flat_top = true, .segments = n,
                           .checks = {.report = &rep}};
    assert_int_equal(lr_mesh_candle(&flat, &mesh, &e), LR_OK);
    assert_true(rep.closed && rep.oriented);
    assert_true(fabs(lr_mesh_volume(mesh) / (kV * M_PI * R * R * H) - 1) < FLOAT_SLACK);
    lr_mesh_destroy(mesh);
}

static void test_candle_rejects_bad_parameters(void **state)
{
    (void)state;
    lr_mesh *m;
    lr_err e = {0};
    lr_candle_desc d = {.height = 100, .pool_depth = 120};
    assert_int_equal(lr_mesh_candle(&d, &m, &e), LR_EINVAL);
    assert_null(m);
    expect_msg(&e, "candle: field 'pool_depth': must be > 0 and < height (100 mm), got 120");
    const char *field = NULL;
    lr_candle_desc r, d2 = {.radius = -1};
    assert_int_equal(lr_candle_check(&d2, &r, &field, &e), LR_EINVAL);
    assert_string_equal(field, "radius");
    lr_candle_desc d3 = {.radius = 10, .pool_radius = 11};
    assert_int_equal(lr_candle_check(&d3, &r, &field, &e), LR_EINVAL);
    assert_string_equal(field, "pool_radius");
    lr_candle_desc d4 = {.segments = 2};
    assert_int_equal(lr_candle_check(&d4, &r, &field, &e), LR_EINVAL);
    assert_string_equal(field, "segments");
    /* Defaults: a 70 x 120 mm pillar with an 8 mm pool and a 3 mm rim. */
    lr_candle_desc z = {0};
    assert_int_equal(lr_candle_check(&z, &r, &field, &e), LR_OK);
    assert_true(r.radius == 35 && r.height == 120 && r.pool_depth == 8 && r.pool_radius == 32);
}

static void test_shade_loops_thickness_volume(void **state)
{
    (void)state;
    const double Rb = 100, Rt = 60, H = 150, T = 1.5;
    const int n = 96;
    lr_err e = {0};
    lr_mesh_report rep;
    warnings w = {0};
    lr_shade_desc d = {.radius_bottom = Rb, .radius_top = Rt, .height = H, .thickness = T,
                       .segments = n,
                       .checks = {.report = &rep, .warn = {collect, &w}}};
    lr_mesh *m;
    assert_int_equal(lr_mesh_shade(&d, &m, &e), LR_OK);
    /* With rims the shell is a closed ring (a torus topologically). */
    assert_true(rep.closed && rep.oriented);
    assert_int_equal(rep.flipped, 0);
    assert_int_equal(rep.components, 1);
    /* Volume: every horizontal section is the region between two regular n-gons whose
     * circumradii differ by delta, so V = kV * 2 pi rho_mean delta H exactly (Pappus), with
     * rho_mean = (Rb + Rt)/2 - delta/2. The shell is a difference of two large volumes
     * (~30x its own), so float storage costs ~30 x 6e-8: 1e-5 relative. */
    lr_shade_desc res;
    const char *field;
    assert_int_equal(lr_shade_check(&d, &res, &field, &e), LR_OK);
    double delta = lr_shade_radial_offset(&res);
    double x = M_PI / n, kV = sin(2 * x) / (2 * x);
    double V = kV * 2 * M_PI * ((Rb + Rt) / 2 - delta / 2) * delta * H;
    assert_true(fabs(lr_mesh_volume(m) / V - 1) < 1e-5);

    /* Thickness: from the centroid of every outer facet, straight in along its normal, the
     * first surface is an inner facet exactly T away (facets are parallel by construction).
     * Positions ~100 mm in float are good to 1e-5 mm; 1e-4 mm tolerance. */
    lr_bvh *b;
    assert_int_equal(lr_bvh_create(m, &b, &e), LR_OK);
    int outer = 0;
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 p[3];
        lr_mesh_triangle(m, t, p);
        lr_vec3 nrm = lr_mesh_triangle_normal(m, t);
        lr_vec3 cen = lr_v3_scale(lr_v3_add(p[0], lr_v3_add(p[1], p[2])), 1.0 / 3.0);
        lr_vec3 radial = lr_v3_normalize(lr_v3(cen.x, cen.y, 0));
        if (lr_v3_dot(nrm, radial) < 0.5)
            continue; /* inner wall or rim */
        outer++;
        lr_hit hit;
        assert_true(lr_bvh_intersect(b, cen, lr_v3_scale(nrm, -1), 1e-3, INFINITY, &hit));
        if (fabs(hit.t - T) > 1e-4)
            fail_msg("facet %zu: wall %.9g mm thick, configured %g", t, hit.t, T);
        assert_true(lr_v3_dot(lr_mesh_triangle_normal(m, hit.triangle), radial) < -0.5);
    }
    assert_int_equal(outer, 2 * n * res.rings);
    lr_bvh_destroy(b);
    lr_mesh_destroy(m);

    /* Without rims: inner and outer surfaces open at both ends, two boundary loops per end
     * (the inner and the outer circle), each of n edges; no warning (a shade is meant open). */
    d.no_rims = true;
    w.n = 0;
    assert_int_equal(lr_mesh_shade(&d, &m, &e), LR_OK);
    assert_int_equal(rep.boundary_loops, 4);
    assert_int_equal(rep.boundary_edges, 4 * n);
    assert_int_equal(rep.components, 2);
    assert_false(rep.closed);
    assert_true(rep.oriented);
    assert_int_equal(w.n, 0);
    lr_mesh_destroy(m);

    /* Zero thickness: one surface, one loop per end. */
    lr_shade_desc s = {.single_surface = true, .segments = n, .checks = {.report = &rep}};
    assert_int_equal(lr_mesh_shade(&s, &m, &e), LR_OK);
    assert_int_equal(rep.boundary_loops, 2);
    assert_int_equal(rep.boundary_edges, 2 * n);
    lr_mesh_destroy(m);

    /* Too thick for the top opening. */
    lr_shade_desc thick = {.radius_top = 10, .thickness = 12};
    assert_int_equal(lr_mesh_shade(&thick, &m, &e), LR_EINVAL);
    expect_msg(&e, "shade: field 'thickness'");
}

static void test_box_and_quad(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh_report rep;
    lr_mesh *m;
    lr_box_desc bd = {.center = lr_v3(1, 2, 3), .size = lr_v3(10, 20, 40),
                      .checks = {.report = &rep}};
    assert_int_equal(lr_mesh_box(&bd, &m, &e), LR_OK);
    assert_true(rep.closed && rep.oriented && rep.flipped == 0);
    /* Sizes are exact in float: area and volume exact up to summation rounding. */
    assert_true(fabs(lr_mesh_area(m) - 2 * (200 + 800 + 400)) < 1e-9);
    assert_true(fabs(lr_mesh_volume(m) - 8000) < 1e-9);
    lr_mesh_destroy(m);

    lr_quad_desc qd = {.center = lr_v3(0, 200, 300), .normal = lr_v3(0, -1, 0),
                       .size_u = 800, .size_v = 600, .subdivisions = 4,
                       .checks = {.report = &rep}};
    assert_int_equal(lr_mesh_quad(&qd, &m, &e), LR_OK);
    assert_int_equal(lr_mesh_triangle_count(m), 32);
    assert_true(fabs(lr_mesh_area(m) - 800 * 600) < 1e-6);
    assert_int_equal(rep.boundary_loops, 1);
    assert_int_equal(rep.boundary_edges, 16);
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++)
        assert_true(lr_mesh_triangle_normal(m, t).y < -0.999999);
    lr_mesh_destroy(m);
}

static void test_transform(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh *m, *t;
    lr_sphere_desc sd = {.radius = 10, .subdivisions = 2};
    assert_int_equal(lr_mesh_sphere(&sd, &m, &e), LR_OK);
    double A = lr_mesh_area(m), V = lr_mesh_volume(m);
    double s[16], r[16], tr[16], mat[16];
    lr_mat4_scale(lr_v3(-2, 2, 2), s); /* mirror in x and scale by 2 */
    lr_mat4_rotate_xyz_deg(lr_v3(30, 45, 60), r);
    lr_mat4_translate(lr_v3(100, -50, 20), tr);
    lr_mat4_mul(r, s, mat);
    lr_mat4_mul(tr, mat, mat);
    assert_int_equal(lr_mesh_transform(m, mat, &t, &e), LR_OK);
    /* Area x4, volume x8 and still positive: the mirror reversed the winding. */
    assert_true(fabs(lr_mesh_area(t) / (4 * A) - 1) < FLOAT_SLACK);
    assert_true(fabs(lr_mesh_volume(t) / (8 * V) - 1) < FLOAT_SLACK);
    lr_mesh_report rep;
    lr_mesh_analyze(t, &rep);
    assert_true(rep.closed && rep.oriented);
    /* Normals stay unit and outward. */
    lr_vec3 c = lr_v3(100, -50, 20);
    const float *n = lr_mesh_normals(t);
    for (size_t v = 0; v < lr_mesh_vertex_count(t); v++) {
        lr_vec3 nv = lr_v3(n[3 * v], n[3 * v + 1], n[3 * v + 2]);
        assert_true(fabs(lr_v3_len(nv) - 1) < 1e-6);
        assert_true(lr_v3_dot(nv, lr_v3_normalize(lr_v3_sub(lr_mesh_vertex(t, v), c))) > 0.999);
    }
    lr_mesh_destroy(t);
    double zero[16];
    lr_mat4_scale(lr_v3(1, 0, 1), zero);
    assert_int_equal(lr_mesh_transform(m, zero, &t, &e), LR_EINVAL);
    expect_msg(&e, "singular");
    lr_mesh_destroy(m);
}

/* ---- validation and repair ---------------------------------------------------------------- */

/* A unit cube as 8 shared corners and 12 outward triangles. */
static const double cube_v[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                    {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
static const uint32_t cube_t[12][3] = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7},
                                       {0, 1, 5}, {0, 5, 4}, {1, 2, 6}, {1, 6, 5},
                                       {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};

static void test_create_rejects_nan_and_range(void **state)
{
    (void)state;
    double v[8][3];
    memcpy(v, cube_v, sizeof v);
    v[5][1] = NAN;
    lr_mesh *m;
    lr_err e = {0};
    lr_mesh_desc d = {.name = "cube", .vertex_count = 8, .positions = &v[0][0],
                      .triangle_count = 12, .indices = &cube_t[0][0]};
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_EINVAL);
    assert_null(m);
    expect_msg(&e, "cube: vertex 5: coordinate y is nan");
    v[5][1] = 1e39; /* finite as a double, infinite as a float */
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_EINVAL);
    expect_msg(&e, "overflows float");

    uint32_t t[12][3];
    memcpy(t, cube_t, sizeof t);
    t[7][2] = 8;
    uint32_t origin[12];
    for (int i = 0; i < 12; i++)
        origin[i] = (uint32_t)(20 + i);
    lr_mesh_desc d2 = {.name = "cube.obj", .vertex_count = 8, .positions = &cube_v[0][0],
                       .triangle_count = 12, .indices = &t[0][0], .origin = origin,
                       .origin_is_line = true};
    assert_int_equal(lr_mesh_create(&d2, &m, &e), LR_EINVAL);
    expect_msg(&e, "cube.obj:27: vertex index 8 out of range (8 vertices)");
    d2.origin_is_line = false;
    assert_int_equal(lr_mesh_create(&d2, &m, &e), LR_EINVAL);
    expect_msg(&e, "cube.obj: face 27: vertex index 8");
}

static void test_create_repairs(void **state)
{
    (void)state;
    /* The cube plus: a vertex nobody uses (8), a copy of corner 0 (9) making a triangle with a
     * repeated point, a collinear triangle (0, 1, midpoint 10), and a reversed duplicate. */
    double v[11][3];
    memcpy(v, cube_v, sizeof cube_v);
    double extra[3][3] = {{5, 5, 5}, {0, 0, 0}, {0.5, 0, 0}};
    memcpy(v[8], extra, sizeof extra);
    uint32_t t[15][3];
    memcpy(t, cube_t, sizeof cube_t);
    uint32_t more[3][3] = {{9, 0, 3}, {0, 10, 1}, {1, 2, 0}};
    memcpy(t[12], more, sizeof more);
    warnings w = {0};
    lr_mesh_report rep;
    lr_mesh *m;
    lr_err e = {0};
    lr_mesh_desc d = {.name = "messy", .vertex_count = 11, .positions = &v[0][0],
                      .triangle_count = 15, .indices = &t[0][0],
                      .checks = {.warn = {collect, &w}, .report = &rep}};
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_OK);
    assert_int_equal(rep.degenerate_removed, 2);
    assert_int_equal(rep.duplicate_removed, 1);
    /* 8 unused from the start; 9 and 10 only by removed triangles. */
    assert_int_equal(rep.unreferenced_removed, 3);
    assert_int_equal(lr_mesh_vertex_count(m), 8);
    assert_int_equal(lr_mesh_triangle_count(m), 12);
    assert_true(rep.closed && rep.oriented && rep.normals_computed);
    assert_true(warned(&w, "messy: removed 2 zero-area triangles (first at messy: triangle 12)"));
    assert_true(warned(&w, "messy: removed 1 duplicate face (first at messy: triangle 14)"));
    assert_true(warned(&w, "messy: dropped 3 unreferenced vertices"));
    /* Computed normals: unit, pointing away from the centre (area-weighted corners). */
    const float *n = lr_mesh_normals(m);
    for (size_t i = 0; i < 8; i++) {
        lr_vec3 nv = lr_v3(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
        assert_true(fabs(lr_v3_len(nv) - 1) < 1e-6);
        assert_true(lr_v3_dot(nv, lr_v3_sub(lr_mesh_vertex(m, i), lr_v3(.5, .5, .5))) > 0);
    }
    lr_mesh_destroy(m);

    /* Everything degenerate: nothing left to render. */
    uint32_t flat[1][3] = {{0, 1, 8 + 2}};
    lr_mesh_desc d2 = {.name = "flat", .vertex_count = 11, .positions = &v[0][0],
                       .triangle_count = 1, .indices = &flat[0][0]};
    assert_int_equal(lr_mesh_create(&d2, &m, &e), LR_EINVAL);
    expect_msg(&e, "flat: every triangle has zero area");
}

static void test_winding_repair(void **state)
{
    (void)state;
    uint32_t t[12][3];
    memcpy(t, cube_t, sizeof t);
    /* Turn over the +x face (triangles 6 and 7): its 4 outline edges now run the same way as
     * their neighbours' (the diagonal between the two stays consistent). */
    for (int k = 6; k <= 7; k++) {
        uint32_t s = t[k][1];
        t[k][1] = t[k][2];
        t[k][2] = s;
    }
    warnings w = {0};
    lr_mesh_report rep;
    lr_mesh *m;
    lr_err e = {0};
    lr_mesh_desc d = {.name = "cube", .vertex_count = 8, .positions = &cube_v[0][0],
                      .triangle_count = 12, .indices = &t[0][0],
                      .checks = {.warn = {collect, &w}, .report = &rep}};
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_OK);
    assert_int_equal(rep.inconsistent_edges, 4);
    assert_int_equal(rep.flipped, 2);
    assert_true(rep.oriented);
    assert_true(fabs(lr_mesh_volume(m) - 1.0) < 1e-12);
    assert_true(warned(&w, "cube: inconsistent winding on 4 edges; faces turned to agree"));
    lr_mesh_destroy(m);

    d.checks.flags = LR_MESH_KEEP_WINDING;
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_OK);
    assert_int_equal(rep.inconsistent_edges, 4);
    assert_int_equal(rep.flipped, 0);
    assert_false(rep.oriented);
    lr_mesh_destroy(m);

    /* Inside out: consistent but with negative volume; all 12 faces turned. */
    for (int k = 0; k < 12; k++) {
        t[k][0] = cube_t[k][0];
        t[k][1] = cube_t[k][2];
        t[k][2] = cube_t[k][1];
    }
    d.checks.flags = 0;
    w.n = 0;
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_OK);
    assert_int_equal(rep.inconsistent_edges, 0);
    assert_int_equal(rep.flipped, 12);
    assert_true(fabs(lr_mesh_volume(m) - 1.0) < 1e-12);
    assert_true(warned(&w, "inside out"));
    lr_mesh_destroy(m);
}

/* A hollow cube (a 2-unit cube with a 1-unit cavity, two closed pieces): whatever the input
 * winding of each piece, the outer one ends with positive volume and the nested one with
 * negative volume (its normals point into the cavity, out of the material), so the total is
 * 8 - 1 = 7. Before the nesting rule each piece was turned outward (total 9), and a light in
 * the cavity was taken to sit inside solid material. */
static void test_nested_cavity_orientation(void **state)
{
    (void)state;
    double v[16][3];
    uint32_t t[24][3];
    for (int piece = 0; piece < 2; piece++) {
        double h = piece ? 0.5 : 1.0; /* half size */
        for (int k = 0; k < 8; k++)
            for (int c = 0; c < 3; c++)
                v[8 * piece + k][c] = (cube_v[k][c] - 0.5) * 2.0 * h;
    }
    for (int mode = 0; mode < 4; mode++) {
        bool outer_rev = mode & 1, inner_rev = mode & 2;
        for (int k = 0; k < 12; k++) {
            t[k][0] = cube_t[k][0];
            t[k][1] = outer_rev ? cube_t[k][2] : cube_t[k][1];
            t[k][2] = outer_rev ? cube_t[k][1] : cube_t[k][2];
            t[12 + k][0] = 8 + cube_t[k][0];
            t[12 + k][1] = 8 + (inner_rev ? cube_t[k][2] : cube_t[k][1]);
            t[12 + k][2] = 8 + (inner_rev ? cube_t[k][1] : cube_t[k][2]);
        }
        lr_mesh *m;
        lr_err e = {0};
        lr_mesh_desc d = {.name = "hollow", .vertex_count = 16, .positions = &v[0][0],
                          .triangle_count = 24, .indices = &t[0][0]};
        assert_int_equal(lr_mesh_create(&d, &m, &e), LR_OK);
        assert_true(fabs(lr_mesh_volume(m) - 7.0) < 1e-12);
        /* The cavity's centre is outside the material: winding number 0. */
        assert_true(fabs(lr_mesh_winding_number(m, lr_v3(0, 0, 0))) < 1e-9);
        assert_true(fabs(lr_mesh_winding_number(m, lr_v3(0.75, 0, 0)) - 1.0) < 1e-9);
        lr_mesh_destroy(m);
    }
}

static void test_nonmanifold_and_open(void **state)
{
    (void)state;
    /* Three fins on the edge (0,0,0)-(1,0,0). */
    double v[5][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, -1, 0}};
    uint32_t t[3][3] = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
    warnings w = {0};
    lr_mesh_report rep;
    lr_mesh *m;
    lr_err e = {0};
    lr_mesh_desc d = {.name = "fins", .vertex_count = 5, .positions = &v[0][0],
                      .triangle_count = 3, .indices = &t[0][0],
                      .checks = {.warn = {collect, &w}, .report = &rep}};
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_OK);
    assert_int_equal(rep.nonmanifold_edges, 1);
    assert_false(rep.closed);
    assert_int_equal(rep.boundary_edges, 6);
    assert_true(warned(&w, "fins: 1 non-manifold edge (shared by more than two faces), first at "
                           "(0, 0, 0)"));
    assert_true(warned(&w, "fins: open mesh: 6 boundary edges"));
    lr_mesh_destroy(m);
    /* The same open boundaries with LR_MESH_OPEN_OK: counted, not warned. */
    w.n = 0;
    d.checks.flags = LR_MESH_OPEN_OK;
    assert_int_equal(lr_mesh_create(&d, &m, &e), LR_OK);
    assert_false(warned(&w, "open mesh"));
    assert_int_equal(rep.boundary_edges, 6);
    lr_mesh_destroy(m);
}

/* ---- files -------------------------------------------------------------------------------- */

static const char cube_ply_ascii[] =
    "ply\n"
    "format ascii 1.0\n"
    "comment a 10 mm cube\n"
    "element vertex 8\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "property uchar red\n"
    "element face 6\n"
    "property list uchar int vertex_indices\n"
    "end_header\n"
    "0 0 0 255\n"   /* line 12 */
    "10 0 0 255\n"
    "10 10 0 255\n"
    "0 10 0 255\n"
    "0 0 10 255\n"
    "10 0 10 255\n"
    "10 10 10 255\n"
    "0 10 10 255\n" /* line 19 */
    "4 0 3 2 1\n"   /* line 20 */
    "4 4 5 6 7\n"
    "4 0 1 5 4\n"
    "4 1 2 6 5\n"
    "4 2 3 7 6\n"
    "4 3 0 4 7\n";

static void test_ply_ascii(void **state)
{
    (void)state;
    char path[128];
    tmp_path("cube.ply", path, sizeof path);
    lr_test_put(path, cube_ply_ascii, (size_t)-1);
    lr_mesh_report rep;
    lr_mesh_checks ck = {.report = &rep};
    lr_mesh *m;
    lr_err e = {0};
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_int_equal(lr_mesh_triangle_count(m), 12);
    assert_true(rep.closed && rep.oriented && rep.flipped == 0 && rep.normals_computed);
    assert_true(fabs(lr_mesh_area(m) - 600) < 1e-9);
    assert_true(fabs(lr_mesh_volume(m) - 1000) < 1e-9);
    lr_mesh_destroy(m);

    /* NaN on line 14 (vertex 2). */
    char bad[sizeof cube_ply_ascii + 16];
    snprintf(bad, sizeof bad, "%s", cube_ply_ascii);
    replace_once(bad, sizeof bad, cube_ply_ascii, "10 10 0 255", "nan 10 0 255");
    lr_test_put(path, bad, (size_t)-1);
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EINVAL);
    assert_null(m);
    expect_msg(&e, "cube.ply:14: vertex 2: coordinate x is nan");

    /* Index 8 of 8 vertices on line 23 (face 3). */
    replace_once(bad, sizeof bad, cube_ply_ascii, "4 1 2 6 5", "4 1 2 8 5");
    lr_test_put(path, bad, (size_t)-1);
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EINVAL);
    expect_msg(&e, "cube.ply:23: vertex index 8 out of range (8 vertices)");

    /* Not a number. */
    replace_once(bad, sizeof bad, cube_ply_ascii, "4 2 3 7 6", "4 x 3 7 6");
    lr_test_put(path, bad, (size_t)-1);
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EPARSE);
    expect_msg(&e, "cube.ply:24: face 4: 'x' is not a valid integer");

    /* Header errors name their line. */
    lr_test_put(path, "ply\nformat ascii 1.0\nelement vertex 8\nproperty flot x\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EPARSE);
    expect_msg(&e, "cube.ply:4: malformed property (type 'flot')");
    lr_test_put(path, "ply\nformat binary_big_endian 1.0\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EUNSUPPORTED);
    expect_msg(&e, "cube.ply:2: binary_big_endian");
    lr_test_put(path, "ply\nformat ascii 1.0\nelement vertex 99999999\nend_header\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EPARSE);
    expect_msg(&e, "cube.ply:3: element 'vertex' claims 99999999 items");
}

static void test_ply_binary_roundtrip_and_truncation(void **state)
{
    (void)state;
    char path[128], apath[128];
    tmp_path("candle.ply", path, sizeof path);
    tmp_path("candle_ascii.ply", apath, sizeof apath);
    lr_candle_desc cd = {.segments = 24, .pool_rings = 4};
    lr_mesh *m, *b, *a;
    lr_err e = {0};
    assert_int_equal(lr_mesh_candle(&cd, &m, &e), LR_OK);
    assert_int_equal(lr_mesh_save_ply(m, path, true, &e), LR_OK);
    assert_int_equal(lr_mesh_save_ply(m, apath, false, &e), LR_OK);
    lr_mesh_report rep;
    lr_mesh_checks ck = {.report = &rep};
    assert_int_equal(lr_mesh_load(path, &ck, &b, &e), LR_OK);
    assert_false(rep.normals_computed);
    assert_int_equal(lr_mesh_load(apath, NULL, &a, &e), LR_OK);
    /* Bit-exact: binary floats are copied, ascii ones printed with %.9g (round-trips floats). */
    size_t nv = lr_mesh_vertex_count(m), nt = lr_mesh_triangle_count(m);
    assert_int_equal(lr_mesh_vertex_count(b), nv);
    assert_int_equal(lr_mesh_triangle_count(b), nt);
    assert_memory_equal(lr_mesh_positions(b), lr_mesh_positions(m), 3 * nv * sizeof(float));
    assert_memory_equal(lr_mesh_normals(b), lr_mesh_normals(m), 3 * nv * sizeof(float));
    assert_memory_equal(lr_mesh_indices(b), lr_mesh_indices(m), 3 * nt * sizeof(uint32_t));
    assert_memory_equal(lr_mesh_positions(a), lr_mesh_positions(m), 3 * nv * sizeof(float));
    assert_memory_equal(lr_mesh_indices(a), lr_mesh_indices(m), 3 * nt * sizeof(uint32_t));
    lr_mesh_destroy(a);
    lr_mesh_destroy(b);

    /* Cut the last face short: the error names the element and its index. */
    FILE *f = fopen(path, "rb");
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fclose(f);
    assert_int_equal(truncate(path, len - 5), 0);
    assert_int_equal(lr_mesh_load(path, NULL, &b, &e), LR_EPARSE);
    char want[128];
    snprintf(want, sizeof want, "truncated binary data in face %zu", nt - 1);
    expect_msg(&e, want);
    expect_msg(&e, "candle.ply");
    lr_mesh_destroy(m);
}

static void put32(unsigned char **p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        *(*p)++ = (unsigned char)(v >> (8 * i));
}

static void putf(unsigned char **p, float x)
{
    uint32_t u;
    memcpy(&u, &x, 4);
    put32(p, u);
}

static void test_ply_binary_skips_and_bad_values(void **state)
{
    (void)state;
    /* A binary tetrahedron with properties to skip: a double per vertex, a float list per face,
     * and a whole extra element. */
    const char *hdr = "ply\nformat binary_little_endian 1.0\nelement vertex 4\n"
                      "property float x\nproperty double weight\nproperty float y\n"
                      "property float z\nelement face 4\nproperty list uchar float texcoord\n"
                      "property list uchar uint vertex_indices\nelement edge 1\n"
                      "property int vertex1\nproperty int vertex2\nend_header\n";
    unsigned char buf[512], *p = buf;
    memcpy(p, hdr, strlen(hdr));
    p += strlen(hdr);
    const float V[4][3] = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}};
    for (int i = 0; i < 4; i++) {
        putf(&p, V[i][0]);
        double wgt = 0.5;
        memcpy(p, &wgt, 8); /* the test host is little-endian like every target */
        p += 8;
        putf(&p, V[i][1]);
        putf(&p, V[i][2]);
    }
    const uint32_t F[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
    for (int i = 0; i < 4; i++) {
        *p++ = 2;
        putf(&p, 0.25f);
        putf(&p, 0.75f);
        *p++ = 3;
        for (int k = 0; k < 3; k++)
            put32(&p, F[i][k]);
    }
    put32(&p, 0);
    put32(&p, 1);
    char path[128];
    tmp_path("tet.ply", path, sizeof path);
    lr_test_put(path, buf, (size_t)(p - buf));
    lr_mesh_report rep;
    lr_mesh_checks ck = {.report = &rep};
    lr_mesh *m;
    lr_err e = {0};
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_true(rep.closed && rep.oriented && rep.flipped == 0);
    assert_true(fabs(lr_mesh_volume(m) - 1000.0 / 6.0) < 1e-9);
    lr_mesh_destroy(m);

    /* Vertex 2's y made NaN: named by element index (a binary file has no lines). */
    unsigned char *y2 = buf + strlen(hdr) + 2 * 20 + 12;
    putf(&y2, NAN);
    lr_test_put(path, buf, (size_t)(p - buf));
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EINVAL);
    expect_msg(&e, "tet.ply: vertex 2: coordinate y is nan");
    y2 = buf + strlen(hdr) + 2 * 20 + 12;
    putf(&y2, 10.0f);
    /* Face 3's last index made 7. */
    unsigned char *f3 = buf + strlen(hdr) + 4 * 20 + 3 * 22 + 10 + 8;
    put32(&f3, 7);
    lr_test_put(path, buf, (size_t)(p - buf));
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_EINVAL);
    expect_msg(&e, "tet.ply: face 3: vertex index 7 out of range (4 vertices)");
}

static void test_ply_nonmanifold_warns(void **state)
{
    (void)state;
    char path[128];
    tmp_path("fins.ply", path, sizeof path);
    lr_test_put(path, "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\n"
                     "property float y\nproperty float z\nelement face 3\n"
                     "property list uchar int vertex_indices\nend_header\n"
                     "0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 -1 0\n3 0 1 2\n3 1 0 3\n3 0 1 4\n", (size_t)-1);
    warnings w = {0};
    lr_mesh_report rep;
    lr_mesh_checks ck = {.warn = {collect, &w}, .report = &rep};
    lr_mesh *m;
    lr_err e = {0};
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_int_equal(rep.nonmanifold_edges, 1);
    char want[160];
    snprintf(want, sizeof want, "%s: 1 non-manifold edge", path);
    assert_true(warned(&w, want));
    lr_mesh_destroy(m);
}

static void test_obj_negative_indices_quads_normals(void **state)
{
    (void)state;
    /* A 10 mm cube: quads, every face written with negative indices after its own normal,
     * in the v//vn form; one face in v/vt/vn form, one in plain v. */
    const char *obj =
        "# cube\n"                                       /* 1 */
        "mtllib cube.mtl\no cube\n"                      /* 2-3 */
        "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\n"       /* 4-7 */
        "v 0 0 10\nv 10 0 10\nv 10 10 10\nv 0 10 10\n"   /* 8-11 */
        "vt 0 0\n"                                       /* 12 */
        "vn 0 0 -1\nf -8//-1 -5//-1 -6//-1 -7//-1\n"     /* 13-14 */
        "vn 0 0 1\nf -4//-1 -3//-1 -2//-1 -1//-1\n"      /* 15-16 */
        "vn 0 -1 0\nf 1/1/3 2/1/3 6/1/3 5/1/3\n"         /* 17-18 */
        "vn 1 0 0\nf 2//4 3//4 7//4 6//4\n"              /* 19-20 */
        "vn 0 1 0\nf 3//5 4//5 8//5 7//5\n"              /* 21-22 */
        "vn -1 0 0\ns off\nusemtl wax\nf 4//6 1//6 5//6 8//6\n"; /* 23-26 */
    char path[128];
    tmp_path("cube.obj", path, sizeof path);
    lr_test_put(path, obj, (size_t)-1);
    lr_mesh_report rep;
    warnings w = {0};
    lr_mesh_checks ck = {.report = &rep, .warn = {collect, &w}};
    lr_mesh *m;
    lr_err e = {0};
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_int_equal(lr_mesh_triangle_count(m), 12);
    /* Each corner has its face's normal: 6 faces x 4 corners, split by (v, vn). */
    assert_int_equal(lr_mesh_vertex_count(m), 24);
    assert_false(rep.normals_computed);
    assert_true(rep.closed && rep.oriented && rep.flipped == 0);
    assert_true(fabs(lr_mesh_volume(m) - 1000) < 1e-9);
    assert_int_equal(w.n, 0);
    /* Every vertex normal equals its triangles' geometric normal. */
    const float *n = lr_mesh_normals(m);
    const uint32_t *idx = lr_mesh_indices(m);
    for (size_t t = 0; t < 12; t++) {
        lr_vec3 g = lr_mesh_triangle_normal(m, t);
        for (int k = 0; k < 3; k++) {
            const float *vn = &n[3 * idx[3 * t + k]];
            assert_true(lr_v3_dot(g, lr_v3(vn[0], vn[1], vn[2])) > 0.999999);
        }
    }
    lr_mesh_destroy(m);
}

static void test_obj_errors(void **state)
{
    (void)state;
    char path[128];
    tmp_path("bad.obj", path, sizeof path);
    lr_mesh *m;
    lr_err e = {0};
    lr_test_put(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EINVAL);
    expect_msg(&e, "bad.obj:5: vertex index 9 out of range (3 vertices)");
    lr_test_put(path, "v 0 0 0\nv 1 0 0\nf 1 2 -3\nv 0 1 0\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EINVAL);
    expect_msg(&e, "bad.obj:3: vertex index -3 out of range (2 vertices so far)");
    lr_test_put(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EINVAL);
    expect_msg(&e, "bad.obj:4: vertex index 0");
    lr_test_put(path, "v 0 0 0\nv 1 inf 0\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EINVAL);
    expect_msg(&e, "bad.obj:2: vertex: coordinate y is inf");
    lr_test_put(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EPARSE);
    expect_msg(&e, "bad.obj:4: face with 2 corners");
    lr_test_put(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//0\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EPARSE);
    expect_msg(&e, "bad.obj:5: malformed face corner '3//0'");
    lr_test_put(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2 3\n", (size_t)-1);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EPARSE);
    expect_msg(&e, "bad.obj:4: malformed face corner '1/'");
    /* Unsupported statements: one warning each, the mesh still loads; a forward reference
     * (face before its last vertex) is legal. */
    lr_test_put(path, "v 0 0 0\nv 1 0 0\nl 1 2\nf 1 2 3\ncurv 0 1 1 2\nl 2 1\nv 0 1 0\n", (size_t)-1);
    warnings w = {0};
    lr_mesh_checks ck = {.warn = {collect, &w}, .flags = LR_MESH_OPEN_OK};
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_int_equal(w.n, 2);
    assert_true(warned(&w, "bad.obj:3: 'l' statements are ignored"));
    assert_true(warned(&w, "bad.obj:5: 'curv' statements are ignored"));
    lr_mesh_destroy(m);
    tmp_path("mesh.stl", path, sizeof path);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EUNSUPPORTED);
    tmp_path("missing.obj", path, sizeof path);
    assert_int_equal(lr_mesh_load(path, NULL, &m, &e), LR_EIO);
    expect_msg(&e, "missing.obj: cannot open");
}

/* Files without normals: smooth across gentle edges, split along sharp ones (crease.c). A cube
 * (90-degree edges) gets its faces' normals exactly, one vertex per face corner; the shipped
 * votive (a 32-gon cup: wall facets 11.25 degrees apart, floor, rim and bottom at 90 degrees to
 * the walls) keeps its walls smooth and horizontal and its caps flat. Averaging over every face, as
 * before, gave corner normals up to 84 degrees from their facet (rim 84, floor 69, walls 23). */
static void test_obj_crease_normals(void **state)
{
    (void)state;
    const char *obj = "v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\n"
                      "v 0 0 10\nv 10 0 10\nv 10 10 10\nv 0 10 10\n"
                      "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
    char path[128];
    tmp_path("cube_nonormals.obj", path, sizeof path);
    lr_test_put(path, obj, (size_t)-1);
    lr_mesh_report rep;
    lr_mesh_checks ck = {.report = &rep};
    lr_mesh *m;
    lr_err e = {0};
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_true(rep.closed && rep.oriented && rep.normals_computed);
    assert_int_equal(lr_mesh_vertex_count(m), 24);
    const float *n = lr_mesh_normals(m);
    const uint32_t *idx = lr_mesh_indices(m);
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 g = lr_mesh_triangle_normal(m, t);
        for (int k = 0; k < 3; k++) {
            const float *vn = &n[3 * idx[3 * t + k]];
            assert_true(lr_v3_dot(g, lr_v3(vn[0], vn[1], vn[2])) > 1.0 - 1e-6);
        }
    }
    lr_mesh_destroy(m);

    /* The same cube as PLY without normals: the same split. */
    tmp_path("cube_nonormals.ply", path, sizeof path);
    lr_test_put(path, cube_ply_ascii, (size_t)-1);
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_true(rep.closed && rep.oriented && rep.normals_computed);
    assert_int_equal(lr_mesh_vertex_count(m), 24);
    n = lr_mesh_normals(m);
    idx = lr_mesh_indices(m);
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 g = lr_mesh_triangle_normal(m, t);
        for (int k = 0; k < 3; k++) {
            const float *vn = &n[3 * idx[3 * t + k]];
            assert_true(lr_v3_dot(g, lr_v3(vn[0], vn[1], vn[2])) > 1.0 - 1e-6);
        }
    }
    lr_mesh_destroy(m);

    snprintf(path, sizeof path, "%s/meshes/votive.obj", lr_configs_dir());
    assert_int_equal(lr_mesh_load(path, &ck, &m, &e), LR_OK);
    assert_true(rep.closed && rep.oriented && rep.normals_computed);
    n = lr_mesh_normals(m);
    idx = lr_mesh_indices(m);
    double worst = 1.0;
    for (size_t t = 0; t < lr_mesh_triangle_count(m); t++) {
        lr_vec3 g = lr_mesh_triangle_normal(m, t);
        for (int k = 0; k < 3; k++) {
            uint32_t v = idx[3 * t + k];
            lr_vec3 vn = lr_v3(n[3 * v], n[3 * v + 1], n[3 * v + 2]);
            worst = fmin(worst, lr_v3_dot(g, vn));
            if (fabs(g.z) > 0.5) { /* floor, rim, bottom: flat */
                assert_true(fabs(vn.z - g.z) < 1e-6);
            } else { /* walls: horizontal (only vertical facets averaged) */
                assert_true(fabs(vn.z) < 1e-6);
            }
        }
    }
    /* A wall normal is a weighted mean of two adjacent facets' (the fan triangulation gives
     * the quads on either side one or two triangles at a vertex), so it lies within the
     * 32-gon's 11.25-degree step of either; averaging across the floor or rim tilted it
     * further: up to 22-23 degrees on the walls, 69-84 on the caps. */
    if (!(worst > cos(2.0 * M_PI / 32.0) - 1e-6))
        fail_msg("votive.obj: a corner normal is %.2f degrees from its facet",
                 acos(fmin(1.0, worst)) * 180.0 / M_PI);
    print_message("votive.obj: largest corner normal to facet angle %.2f degrees\n",
                  acos(fmin(1.0, worst)) * 180.0 / M_PI);
    lr_mesh_destroy(m);
}

/* ---- ray casts and closest points ----------------------------------------------------------- */

/* The BVH must give exactly the brute-force answer: the same triangle test on the same data
 * with the same tie rule, so hit/miss, t and triangle agree bit for bit (stronger than the
 * 1e-9 relative asked of it). Rays: random origins around the mesh in random directions, rays
 * from inside, and rays aimed exactly at vertices (hits on shared edges and corners, where a
 * box test that rounds the wrong way would lose the hit). */
static void check_rays(const lr_mesh *m, uint64_t seed, int nrays)
{
    lr_err e = {0};
    lr_bvh *b;
    assert_int_equal(lr_bvh_create(m, &b, &e), LR_OK);
    lr_vec3 c;
    double r;
    lr_mesh_bounding_sphere(m, &c, &r);
    rng g = {seed};
    int hits = 0;
    for (int i = 0; i < nrays; i++) {
        lr_vec3 o, d;
        int kind = i % 3;
        if (kind == 0) { /* from outside, anywhere */
            o = lr_v3_add(c, lr_v3_scale(random_dir(&g), r * (1.0 + 2.0 * uniform(&g))));
            d = random_dir(&g);
        } else if (kind == 1) { /* from inside the bounding sphere */
            o = lr_v3_add(c, lr_v3_scale(random_dir(&g), r * uniform(&g)));
            d = random_dir(&g);
        } else { /* at a vertex */
            o = lr_v3_add(c, lr_v3_scale(random_dir(&g), 2.0 * r));
            size_t v = (size_t)(uniform(&g) * lr_mesh_vertex_count(m));
            d = lr_v3_sub(lr_mesh_vertex(m, v), o);
        }
        double tmax = (i % 7 == 0) ? r : INFINITY;
        lr_hit hb, hr;
        bool fb = lr_bvh_intersect(b, o, d, 0.0, tmax, &hb);
        bool fr = lr_mesh_intersect(m, o, d, 0.0, tmax, &hr);
        if (fb != fr)
            fail_msg("ray %d: bvh %s, brute force %s", i, fb ? "hit" : "miss", fr ? "hit" : "miss");
        assert_int_equal(lr_bvh_occluded(b, o, d, 0.0, tmax), fr);
        if (fr) {
            hits++;
            assert_true(hb.t == hr.t);
            assert_int_equal(hb.triangle, hr.triangle);
            assert_true(hb.u == hr.u && hb.v == hr.v);
        }
    }
    /* The mix is meaningful: a good share of rays hit, a good share miss. */
    assert_true(hits > nrays / 5 && hits < nrays);
    for (int i = 0; i < nrays / 4; i++) {
        lr_vec3 p = lr_v3_add(c, lr_v3_scale(random_dir(&g), 1.5 * r * uniform(&g)));
        lr_closest cb, cr;
        assert_true(lr_bvh_closest(b, p, INFINITY, &cb));
        assert_true(lr_mesh_closest(m, p, INFINITY, &cr));
        assert_true(cb.distance == cr.distance);
        assert_int_equal(cb.triangle, cr.triangle);
        /* The closest point is on the surface: a ray from p to it hits at t = 1. */
        assert_true(cb.distance >= 0);
    }
    lr_bvh_destroy(b);
}

static void test_bvh_matches_brute_force(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh *m;
    lr_candle_desc cd = {.segments = 48, .pool_rings = 8};
    assert_int_equal(lr_mesh_candle(&cd, &m, &e), LR_OK);
    check_rays(m, 1, 1500);
    lr_mesh_destroy(m);
    lr_shade_desc sd = {.segments = 48};
    assert_int_equal(lr_mesh_shade(&sd, &m, &e), LR_OK);
    check_rays(m, 2, 1500);
    lr_mesh_destroy(m);
    lr_box_desc bd = {.size = lr_v3(10, 20, 30)}; /* axis-aligned faces: flat boxes */
    assert_int_equal(lr_mesh_box(&bd, &m, &e), LR_OK);
    check_rays(m, 3, 600);
    lr_mesh_destroy(m);
}

static void test_closest_point_and_hits_exact(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh *m;
    lr_box_desc bd = {.size = lr_v3(10, 10, 10)};
    assert_int_equal(lr_mesh_box(&bd, &m, &e), LR_OK);
    lr_bvh *b;
    assert_int_equal(lr_bvh_create(m, &b, &e), LR_OK);
    lr_closest c;
    /* Beyond a face, an edge and a corner: distances 3, sqrt(2), sqrt(3) exactly. */
    assert_true(lr_bvh_closest(b, lr_v3(0, 0, 8), INFINITY, &c));
    assert_true(fabs(c.distance - 3) < 1e-12 && fabs(c.point.z - 5) < 1e-12);
    assert_true(lr_bvh_closest(b, lr_v3(6, 6, 0), INFINITY, &c));
    assert_true(fabs(c.distance - sqrt(2)) < 1e-12);
    assert_true(lr_bvh_closest(b, lr_v3(6, 6, 6), INFINITY, &c));
    assert_true(fabs(c.distance - sqrt(3)) < 1e-12);
    assert_false(lr_bvh_closest(b, lr_v3(6, 6, 6), 1.0, &c)); /* beyond max_dist */
    /* A shadow ray stopping short of the box is not occluded. */
    assert_false(lr_bvh_occluded(b, lr_v3(0, 0, 20), lr_v3(0, 0, -1), 0, 14.9));
    assert_true(lr_bvh_occluded(b, lr_v3(0, 0, 20), lr_v3(0, 0, -1), 0, 15.1));
    lr_bvh_destroy(b);
    lr_mesh_destroy(m);
}

/* ---- the thinnest wall (wall.h) ------------------------------------------------------------ */

static double wall_of(lr_mesh *m)
{
    lr_bvh *b = NULL;
    lr_err e = {0};
    assert_int_equal(lr_bvh_create(m, &b, &e), LR_OK);
    double t = lr_mesh_wall_thickness(b);
    lr_bvh_destroy(b);
    lr_mesh_destroy(m);
    return t;
}

/* Closed forms: a box's thinnest wall is its smallest side (its two largest faces hold 65 % of
 * the area, so the percentile lands there); a shade's shell is its thickness along every
 * facet normal by construction (lr_shade_desc), the rims (the height across) are 2 % of the
 * area; a sphere's inward normal from a facet centroid is a chord through the centre, 2 R
 * less the sagitta of a facet at each end (rho^2 / 2R each, rho the facet's circumradius,
 * about 0.05 R at 5120 facets: under 0.5 % in all). A jar burnt down to
 * a 4 mm rim: no wall under 4 mm exists, and the thin band by the rim is more than 1 % of the
 * surface, so the answer lies between 4 mm and the wall halfway down the pool (14.5 mm). */
static void test_wall_thickness(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh *m = NULL;
    assert_int_equal(lr_mesh_box(&(lr_box_desc){.size = lr_v3(100, 60, 20)}, &m, &e), LR_OK);
    assert_true(fabs(wall_of(m) - 20.0) < 1e-9);
    double d;
    assert_int_equal(lr_mesh_shade(&(lr_shade_desc){.thickness = 1.5}, &m, &e), LR_OK);
    /* Vertices are floats: 100 mm coordinates round by up to 4e-6 mm. */
    assert_true(fabs(wall_of(m) - 1.5) < 2e-5);
    assert_int_equal(lr_mesh_sphere(&(lr_sphere_desc){.radius = 40}, &m, &e), LR_OK);
    d = wall_of(m);
    assert_true(d > 80.0 * 0.995 && d <= 80.0);
    assert_int_equal(lr_mesh_candle(&(lr_candle_desc){.radius = 40, .height = 100,
                                                      .pool_depth = 35, .pool_radius = 36},
                                    &m, &e),
                     LR_OK);
    d = wall_of(m);
    assert_true(d >= 4.0 - 1e-9 && d < 14.5);
    /* A pillar without a pool: its thinnest wall is its diameter (70 mm; the top's rays run
     * 120 mm down). */
    assert_int_equal(lr_mesh_candle(&(lr_candle_desc){.flat_top = true}, &m, &e), LR_OK);
    d = wall_of(m);
    assert_true(d > 70.0 * 0.99 && d <= 70.0 + 1e-9);
}

/* ---- inside, around ---------------------------------------------------------------------- */

static void test_winding_and_hull(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_mesh *m;
    lr_sphere_desc sd = {.radius = 50, .subdivisions = 3};
    assert_int_equal(lr_mesh_sphere(&sd, &m, &e), LR_OK);
    /* A closed outward mesh: the solid angles sum to exactly 4 pi from inside and 0 from
     * outside; rounding over 1280 atan2 terms stays below 1e-12. */
    assert_true(fabs(lr_mesh_winding_number(m, lr_v3(0, 0, 0)) - 1) < 1e-12);
    assert_true(fabs(lr_mesh_winding_number(m, lr_v3(10, 20, -30)) - 1) < 1e-12);
    assert_true(fabs(lr_mesh_winding_number(m, lr_v3(0, 0, 80))) < 1e-12);
    assert_true(lr_mesh_hull_distance(m, lr_v3(10, 20, -30)) == 0.0);
    /* Outside, along +z: the hull's top vertex is the icosahedron's... the nearest point is
     * on a face near the pole, within the sphere radius; distance in (30, 30 + 50(1-cos b)]. */
    double dz = lr_mesh_hull_distance(m, lr_v3(0, 0, 80));
    assert_true(dz >= 30.0 - 1e-9 && dz < 31.0);
    lr_mesh_destroy(m);

    /* Candle: a flame in the pool, 4 mm below the rim, is outside the wax (winding 0) yet
     * inside the convex hull: surrounded. Above the rim it is outside both. */
    lr_candle_desc cd = {0};
    assert_int_equal(lr_mesh_candle(&cd, &m, &e), LR_OK);
    assert_true(fabs(lr_mesh_winding_number(m, lr_v3(0, 0, 116))) < 1e-9);
    assert_true(fabs(lr_mesh_winding_number(m, lr_v3(0, 0, 60)) - 1) < 1e-9);
    assert_true(lr_mesh_hull_distance(m, lr_v3(0, 0, 116)) == 0.0);
    /* 10 mm above the top plane (z = 120), over the axis: 10 mm from the hull, to the
     * tolerance GJK promises (1e-9 of the mesh size). */
    assert_true(fabs(lr_mesh_hull_distance(m, lr_v3(0, 0, 130)) - 10.0) < 1e-6);
    lr_mesh_destroy(m);

    /* Open shade without rims: the bulb is in the hollow, winding ~0, hull distance 0. */
    lr_shade_desc sh = {.no_rims = true};
    assert_int_equal(lr_mesh_shade(&sh, &m, &e), LR_OK);
    assert_true(lr_mesh_hull_distance(m, lr_v3(0, 0, 75)) == 0.0);
    assert_true(lr_mesh_hull_distance(m, lr_v3(0, 0, 160)) > 9.0);
    lr_mesh_destroy(m);
}

/* A ray through the shared edge of two triangles hits one of them (render/mesh/triangle.h):
 * the cells of a 1 m square split at 7.8125 mm (its refinement to 12 mm edges), rays from
 * 500 mm above through points on their diagonals, at float positions as the mesh stores
 * them. With the exact bounds of Moller-Trumbore some slipped between the two halves
 * (test_calib_ar saw one reach the box's bottom). */
static void test_ray_through_shared_edge(void **state)
{
    (void)state;
    const double h = 1000.0 / 128;
    int missed = 0, rays = 0;
    for (int i = 0; i < 128; i += 3)
        for (int j = 0; j < 128; j += 5) {
            lr_vec3 a = lr_v3((float)(-500 + i * h), (float)(-500 + j * h), 0);
            lr_vec3 c = lr_v3((float)(-500 + (i + 1) * h), (float)(-500 + (j + 1) * h), 0);
            lr_vec3 b = lr_v3(c.x, a.y, 0), d = lr_v3(a.x, c.y, 0);
            for (int k = 1; k < 8; k++) {
                lr_vec3 x = lr_v3_add(a, lr_v3_scale(lr_v3_sub(c, a), k / 8.0));
                lr_vec3 o = lr_v3(0.0, 0.0, 500.0), dir = lr_v3_normalize(lr_v3_sub(x, o));
                double t, u, v;
                bool hit = lr_ray_triangle(o, dir, a, b, c, 0, INFINITY, &t, &u, &v) ||
                           lr_ray_triangle(o, dir, a, c, d, 0, INFINITY, &t, &u, &v);
                missed += !hit;
                rays++;
            }
        }
    printf("  %d rays through shared edges, %d missed\n", rays, missed);
    /* The longest edge the scene's refinement tests (lr_mesh_longest_edge): a 10 x 20 x 30 box
     * is two triangles a face, so its longest edge is the 20 x 30 face's diagonal. */
    lr_box_desc bd = {.size = lr_v3(10, 20, 30)};
    lr_mesh *m;
    lr_err e = {0};
    assert_int_equal(lr_mesh_box(&bd, &m, &e), LR_OK);
    assert_true(fabs(lr_mesh_longest_edge(m) - hypot(20.0, 30.0)) < 1e-5);
    lr_mesh_destroy(m);
    assert_int_equal(missed, 0);
    /* The tolerance is a hair: a ray 1e-6 of the cell outside the square misses both. */
    lr_vec3 a = lr_v3(0, 0, 0), b = lr_v3(1, 0, 0), c = lr_v3(1, 1, 0), d = lr_v3(0, 1, 0);
    double t, u, v;
    assert_false(lr_ray_triangle(lr_v3(1 + 1e-6, 0.5, 1), lr_v3(0, 0, -1), a, b, c, 0,
                                 INFINITY, &t, &u, &v));
    assert_false(lr_ray_triangle(lr_v3(-1e-6, 0.5, 1), lr_v3(0, 0, -1), a, c, d, 0, INFINITY,
                                 &t, &u, &v));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_watertight_area_volume),
        cmocka_unit_test(test_candle_watertight_area_volume),
        cmocka_unit_test(test_candle_rejects_bad_parameters),
        cmocka_unit_test(test_shade_loops_thickness_volume),
        cmocka_unit_test(test_box_and_quad),
        cmocka_unit_test(test_transform),
        cmocka_unit_test(test_create_rejects_nan_and_range),
        cmocka_unit_test(test_create_repairs),
        cmocka_unit_test(test_winding_repair),
        cmocka_unit_test(test_nonmanifold_and_open),
        cmocka_unit_test(test_ply_ascii),
        cmocka_unit_test(test_ply_binary_roundtrip_and_truncation),
        cmocka_unit_test(test_ply_binary_skips_and_bad_values),
        cmocka_unit_test(test_ply_nonmanifold_warns),
        cmocka_unit_test(test_obj_negative_indices_quads_normals),
        cmocka_unit_test(test_obj_errors),
        cmocka_unit_test(test_obj_crease_normals),
        cmocka_unit_test(test_bvh_matches_brute_force),
        cmocka_unit_test(test_closest_point_and_hits_exact),
        cmocka_unit_test(test_wall_thickness),
        cmocka_unit_test(test_winding_and_hull),
        cmocka_unit_test(test_nested_cavity_orientation),
        cmocka_unit_test(test_ray_through_shared_edge),
    };
    return cmocka_run_group_tests(tests, setup_dir, teardown_dir);
}
