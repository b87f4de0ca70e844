/* The receivers' light on the objects (render/bounce/objlight.h, issue 12 part 3) against
 * closed forms, through the receiver bounce's own scene build (render.receiver_bounce): a
 * large table of albedo rho under a uniform VPL irradiance X and no direct light has the
 * uniform radiosity W = rho X (a plane does not see itself; objects absorb), and
 *  - a small sphere above it: each vertex of normal n gets E+ = W F, F its view factor to the
 *    finite table (quadrature; (1 - n_z) / 2 for an infinite plane, 1 % more at the horizon)
 *    within 2 % of W (512 rays), the mean error under 0.2 %; the bottom vertex, facing the
 *    table, the parallel-rectangle closed form (Howell B-3 over four corner rectangles);
 *  - occlusion: a square plate under the sphere takes exactly the parallel-square view factor
 *    from the bottom vertex (W (F_table - F_plate)), within 1 % of W;
 *  - a closed thin wall (a shade, multipole): E- is the far face's E+ (the opposite vertex's);
 *  - linearity: twice X gives twice E, vertex by vertex;
 *  - the factors: kR = <F_t> R_d / t_hem = R_d (the two integrals agree) for a half-space;
 *  - the field: default true, a SETTINGS change, off: no objects' light;
 *  - the on-disk cache of the rows: a second build reads them and gives the same light to
 *    the bit; a corrupt or truncated file is rebuilt (and rewritten), never read; a read-only
 *    cache folder is said once through the scene's warn sink, over the bounce's two stores
 *    (F and the rows) and its rebuild after a geometry change. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/bounce/objlight.h"
#include "render/bounce/rbounce.h"
#include "render/core/recv_grid.h"
#include "render/optics/optics.h"
#include "render/scene/dirty.h"
#include <dirent.h>
#include <errno.h>
#include <sys/stat.h>

#include "tests/support/fs.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

#define RHO 0.5
#define HALF 4000.0 /* table half-size, mm */
#define ZS 60.0     /* sphere centre height */
#define RS 10.0     /* sphere radius */

static const char *const on[] = {"render.receiver_bounce=true", NULL};

/* The table and the sphere, plus the given extra object JSON (or none). */
static lr_scene *scene(const char *extra)
{
    char doc[4096];
    snprintf(doc, sizeof doc,
             "{\"name\":\"t\",\"objects\":[{\"name\":\"s\",\"material\":\"candle_wax\","
             "\"mesh\":{\"type\":\"sphere\",\"radius\":%g},\"transform\":{\"translate\":"
             "[0,0,%g]}}%s%s],"
             "\"lights\":[{\"type\":\"point\",\"position\":[0,0,3000],\"intensity\":1}],"
             "\"camera\":{\"position\":[0,-3000,100],\"target\":[0,0,0]},"
             "\"receivers\":[{\"name\":\"table\",\"type\":\"plane\",\"center\":[0,0,0],"
             "\"normal\":[0,0,1],\"size\":[%g,%g],\"albedo\":[%g,%g,%g]}]}",
             RS, ZS, extra ? "," : "", extra ? extra : "", 2 * HALF, 2 * HALF, RHO, RHO, RHO);
    return lr_test_scene_text(doc, on);
}

/* The bounce with a uniform VPL irradiance X on the table and no direct light, solved. */
static lr_rbounce *solved(const lr_scene *s, double X)
{
    lr_rbounce *rb = NULL;
    lr_err e = {0};
    if (lr_rbounce_update(&rb, s, NULL, &e))
        fail_msg("%s", e.msg);
    assert_non_null(rb);
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *g = malloc(3 * n * sizeof *g);
    assert_non_null(g);
    for (size_t k = 0; k < 3 * n; k++)
        g[k] = X;
    lr_rbounce_vpl_d(rb, 0, g, 3);
    free(g);
    if (lr_rbounce_solve(rb, 0, NULL, &e))
        fail_msg("%s", e.msg);
    return rb;
}

/* Howell B-3: a differential element parallel to a rectangle a x b at distance c, its normal
 * through a corner. */
static double ff_corner(double a, double b, double c)
{
    double A = a / c, B = b / c;
    return (A / sqrt(1 + A * A) * atan(B / sqrt(1 + A * A)) +
            B / sqrt(1 + B * B) * atan(A / sqrt(1 + B * B))) /
           (2 * M_PI);
}

/* The element at (x, y) facing the centred square of half-size h at distance c. */
static double ff_square(double x, double y, double h, double c)
{
    double s = 0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            double a = i ? h - x : h + x, b = j ? h - y : h + y;
            s += ff_corner(a, b, c);
        }
    return s;
}

/* The view factor from an element at x of normal n (above the table, convex surroundings) to
 * the centred square of half-size h in the plane z = 0, by quadrature around the foot point:
 * r = z tan(alpha), 256 x 720 midpoints in alpha and phi (for the finite table, which the
 * infinite plane's (1 - n_z) / 2 overstates by up to 1 % at the horizon). */
static double ff_square_tilted(lr_vec3 x, lr_vec3 n, double h)
{
    const int NA = 256, NP = 720;
    double sum = 0;
    for (int j = 0; j < NP; j++) {
        double phi = (j + 0.5) * 2 * M_PI / NP, cx = cos(phi), sy = sin(phi);
        /* distance along (cx, sy) from the foot point to the square's edge */
        double tx = cx > 0 ? (h - x.x) / cx : cx < 0 ? (-h - x.x) / cx : INFINITY;
        double ty = sy > 0 ? (h - x.y) / sy : sy < 0 ? (-h - x.y) / sy : INFINITY;
        double amax = atan(fmin(tx, ty) / x.z);
        for (int i = 0; i < NA; i++) {
            double a = (i + 0.5) * amax / NA;
            /* unit direction to the plane point at angle a from straight down */
            lr_vec3 d = lr_v3(sin(a) * cx, sin(a) * sy, -cos(a));
            double cn = lr_v3_dot(n, d);
            if (cn <= 0)
                continue;
            /* dOmega = sin(a) da dphi; F = (1/pi) int cos_n dOmega */
            sum += cn * sin(a) * (amax / NA) * (2 * M_PI / NP);
        }
    }
    return sum / M_PI;
}

/* Index of the sphere's vertex with the lowest normal z. */
static size_t bottom_vertex(const lr_mesh *m)
{
    const float *N = lr_mesh_normals(m);
    size_t best = 0;
    for (size_t v = 1; v < lr_mesh_vertex_count(m); v++)
        if (N[3 * v + 2] < N[3 * best + 2])
            best = v;
    return best;
}

static void test_sphere_over_plane(void **state)
{
    (void)state;
    const double X = 2.0e-3, W = RHO * X;
    lr_scene *s = scene(NULL);
    lr_rbounce *rb = solved(s, X);
    const lr_objlight *ol = lr_rbounce_objects(rb);
    assert_non_null(ol);
    const lr_mesh *m = lr_scene_object_at(s, 0)->mesh;
    size_t nv = lr_mesh_vertex_count(m);
    assert_int_equal(lr_objlight_vertex_count(ol, 0), nv);
    const float *E = lr_objlight_E(ol, 0, 0), *N = lr_mesh_normals(m), *P = lr_mesh_positions(m);
    assert_non_null(E);
    double worst = 0, mean = 0;
    double worst_inf = 0;
    size_t checked = 0;
    for (size_t v = 0; v < nv; v++) {
        double inf = W * (1 - N[3 * v + 2]) / 2;
        worst_inf = fmax(worst_inf, fabs(E[6 * v] - inf) / W);
        for (int b = 0; b < 3; b++)
            assert_true(E[6 * v + 3 + (size_t)b] == 0.0f); /* closed, no thickness: E- 0 */
        if (v % 8)
            continue; /* the finite table's quadrature on every 8th vertex */
        lr_vec3 x = lr_v3(P[3 * v], P[3 * v + 1], P[3 * v + 2]);
        lr_vec3 nn = lr_v3(N[3 * v], N[3 * v + 1], N[3 * v + 2]);
        double want = W * ff_square_tilted(x, nn, HALF);
        for (int b = 0; b < 3; b++)
            worst = fmax(worst, fabs(E[6 * v + (size_t)b] - want) / W);
        mean += (E[6 * v] - want) / W;
        checked++;
    }
    mean /= (double)checked;
    size_t vb = bottom_vertex(m);
    double c = P[3 * vb + 2], Fb = ff_square(P[3 * vb], P[3 * vb + 1], HALF, c);
    print_message("sphere over a uniform table: %zu vertices; against the finite table (%zu): "
                  "worst |E+ - W F| / W %.4f, mean %+.5f; against the infinite plane's "
                  "(1 - n_z)/2: worst %.4f; bottom vertex (n_z %.4f) E+ / W %.5f, closed form "
                  "%.5f\n",
                  nv, checked, worst, mean, worst_inf, N[3 * vb + 2], E[6 * vb] / W, Fb);
    assert_true(N[3 * vb + 2] < -0.999);
    assert_true(worst < 0.02);
    assert_true(worst_inf < 0.03);
    assert_true(fabs(mean) < 0.002);
    assert_near_rel(E[6 * vb] / W, Fb, 0.005);

    /* Linearity: twice the light, twice E. */
    lr_err e = {0};
    const size_t n = (size_t)LR_RECV_GRID * LR_RECV_GRID;
    double *g = malloc(3 * n * sizeof *g);
    assert_non_null(g);
    for (size_t k = 0; k < 3 * n; k++)
        g[k] = 2 * X;
    lr_rbounce_vpl_d(rb, 0, g, 3);
    free(g);
    if (lr_rbounce_solve(rb, 1, NULL, &e))
        fail_msg("%s", e.msg);
    const float *E2 = lr_objlight_E(ol, 0, 1);
    assert_non_null(E2);
    for (size_t v = 0; v < nv; v++)
        assert_near_rel(E2[6 * v], 2 * E[6 * v], 1e-5 + (E[6 * v] == 0 ? 1 : 0));

    /* The barycentric evaluation at a corner is the vertex's value. */
    double at[6];
    const uint32_t *idx = lr_mesh_indices(m);
    lr_objlight_at(ol, 0, 0, 0, 1.0, 0.0, at);
    assert_near_rel(at[0], E[6 * (size_t)idx[1]], 1e-6);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

static void test_occluder(void **state)
{
    (void)state;
    const double X = 1.0e-3, W = RHO * X, a = 20, top = 36; /* plate z 34..36 */
    char plate[512];
    snprintf(plate, sizeof plate,
             "{\"name\":\"p\",\"material\":\"candle_wax\",\"mesh\":{\"type\":\"box\","
             "\"size\":[%g,%g,2]},\"transform\":{\"translate\":[0,0,%g]}}",
             2 * a, 2 * a, top - 1);
    lr_scene *s = scene(plate);
    lr_rbounce *rb = solved(s, X);
    const lr_objlight *ol = lr_rbounce_objects(rb);
    assert_non_null(ol);
    const lr_mesh *m = lr_scene_object_at(s, 0)->mesh;
    const float *E = lr_objlight_E(ol, 0, 0), *P = lr_mesh_positions(m);
    size_t vb = bottom_vertex(m);
    double x = P[3 * vb], y = P[3 * vb + 1], z = P[3 * vb + 2];
    double want = ff_square(x, y, HALF, z) - ff_square(x, y, a, z - top);
    print_message("plate under the sphere: bottom vertex E+ / W %.5f, closed form %.5f "
                  "(table %.5f minus plate %.5f)\n",
                  E[6 * vb] / W, want, ff_square(x, y, HALF, z), ff_square(x, y, a, z - top));
    assert_true(fabs(E[6 * vb] / W - want) < 0.01);
    /* The plate's top faces the sphere, its bottom the table: its top vertices see no
     * receiver (the sphere absorbs), its bottom ones the table. */
    const lr_mesh *pm = lr_scene_object_at(s, 1)->mesh;
    const float *PE = lr_objlight_E(ol, 1, 0), *PN = lr_mesh_normals(pm);
    for (size_t v = 0; v < lr_mesh_vertex_count(pm); v++) {
        if (PN[3 * v + 2] > 0.99)
            assert_true(PE[6 * v] == 0.0f);
        if (PN[3 * v + 2] < -0.99)
            assert_true(PE[6 * v] > 0.95 * W);
    }
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

/* A closed thin wall (a shade of 2 mm porcelain, rims, multipole): E- of a vertex is E+ of the
 * wall's far face where the ray along -n leaves it; the shade's inner and outer faces are
 * meshed ring by ring, so that point is near the opposite face's vertex nearest x - d n.
 * The walls' vertices find their far face (a rim's, 2 mm wide, lies beyond 2 d along -n, and
 * a top rim sees no receiver), and there E- matches that
 * vertex's E+ within 2 % of W (E varies over the segment, 6 mm here, much less). */
static void test_far_face(void **state)
{
    (void)state;
    const double X = 1.0e-3, W = RHO * X, d = 2;
    char doc[2048];
    snprintf(doc, sizeof doc,
             "{\"name\":\"t\",\"objects\":[{\"name\":\"s\",\"material\":\"porcelain\","
             "\"model\":\"multipole\",\"thickness_mm\":%g,\"mesh\":{\"type\":\"shade\","
             "\"radius_bottom\":60,\"radius_top\":40,\"height\":80,\"thickness\":%g,"
             "\"rims\":true,\"segments\":48},\"transform\":{\"translate\":[0,0,100]}}],"
             "\"lights\":[{\"type\":\"point\",\"position\":[0,0,3000],\"intensity\":1}],"
             "\"camera\":{\"position\":[0,-3000,100],\"target\":[0,0,0]},"
             "\"receivers\":[{\"name\":\"table\",\"type\":\"plane\",\"center\":[0,0,0],"
             "\"normal\":[0,0,1],\"size\":[%g,%g],\"albedo\":[%g,%g,%g]}]}",
             d, d, 2 * HALF, 2 * HALF, RHO, RHO, RHO);
    lr_scene *s = lr_test_scene_text(doc, on);
    assert_true(lr_scene_object_at(s, 0)->closed);
    lr_rbounce *rb = solved(s, X);
    const lr_objlight *ol = lr_rbounce_objects(rb);
    assert_non_null(ol);
    const lr_mesh *m = lr_scene_object_at(s, 0)->mesh;
    const float *E = lr_objlight_E(ol, 0, 0), *P = lr_mesh_positions(m), *N = lr_mesh_normals(m);
    size_t nv = lr_mesh_vertex_count(m), found = 0, compared = 0, walls = 0;
    double worst = 0;
    for (size_t v = 0; v < nv; v++) {
        /* Not a rim nor a wall's end ring (whose ray along -n may leave through a rim that
         * sees no receiver): the far face lies within 2 d. */
        double z = P[3 * v + 2];
        bool wall = fabs(N[3 * v + 2]) < 0.9 && z > 100 + 3 * d && z < 180 - 3 * d;
        walls += wall;
        if (!(E[6 * v + 3] > 0.0f))
            continue;
        found += wall;
        lr_vec3 n = lr_v3(N[3 * v], N[3 * v + 1], N[3 * v + 2]);
        lr_vec3 y = lr_v3_sub(lr_v3(P[3 * v], P[3 * v + 1], P[3 * v + 2]), lr_v3_scale(n, d));
        size_t best = nv;
        double bd = INFINITY;
        for (size_t u = 0; u < nv; u++) {
            lr_vec3 nu = lr_v3(N[3 * u], N[3 * u + 1], N[3 * u + 2]);
            if (lr_v3_dot(nu, n) > -0.9)
                continue;
            double du = lr_v3_len(lr_v3_sub(lr_v3(P[3 * u], P[3 * u + 1], P[3 * u + 2]), y));
            if (du < bd) {
                bd = du;
                best = u;
            }
        }
        if (best == nv || bd > 1.0)
            continue; /* no opposite vertex at the far point (rims, slanted ends) */
        compared++;
        worst = fmax(worst, fabs(E[6 * v + 3] - E[6 * best]) / W);
    }
    print_message("thin wall: %zu vertices, %zu of the %zu wall vertices (off the rims) found their "
                  "far face, %zu compared with the opposite vertex: worst |E- - E+(opposite)| / "
                  "W %.4f\n",
                  nv, found, walls, compared, worst);
    assert_true(found >= walls * 98 / 100);
    assert_true(compared > nv / 2);
    assert_true(worst < 0.02);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

/* The thin wall's E (E+ and the far faces' E-) of a fresh build; *hit: read from the cache. */
static float *shade_light(const lr_scene *s, double X, bool *hit, size_t *n)
{
    lr_rbounce *rb = solved(s, X);
    const lr_objlight *ol = lr_rbounce_objects(rb);
    assert_non_null(ol);
    *hit = lr_objlight_cache_hit(ol);
    *n = 6 * lr_objlight_vertex_count(ol, 0);
    float *E = malloc(*n * sizeof *E);
    assert_non_null(E);
    memcpy(E, lr_objlight_E(ol, 0, 0), *n * sizeof *E);
    lr_rbounce_destroy(rb);
    return E;
}

/* The cache file of the rows in dir (one), or NULL. */
static char *rows_file(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return NULL;
    char *found = NULL;
    struct dirent *de;
    while ((de = readdir(d)))
        if (!strncmp(de->d_name, "objlight-", 9))
            found = lr_test_path(dir, de->d_name);
    closedir(d);
    return found;
}

static void test_cache(void **state)
{
    (void)state;
    char *home = lr_test_tmpdir();
    const char *old = getenv("XDG_CACHE_HOME");
    char *saved = old ? strdup(old) : NULL;
    setenv("XDG_CACHE_HOME", home, 1);
    char doc[2048];
    snprintf(doc, sizeof doc,
             "{\"name\":\"t\",\"objects\":[{\"name\":\"s\",\"material\":\"porcelain\","
             "\"model\":\"multipole\",\"thickness_mm\":2,\"mesh\":{\"type\":\"shade\","
             "\"radius_bottom\":60,\"radius_top\":40,\"height\":80,\"thickness\":2,"
             "\"rims\":true,\"segments\":24},\"transform\":{\"translate\":[0,0,100]}}],"
             "\"lights\":[{\"type\":\"point\",\"position\":[0,0,3000],\"intensity\":1}],"
             "\"camera\":{\"position\":[0,-3000,100],\"target\":[0,0,0]},"
             "\"receivers\":[{\"name\":\"table\",\"type\":\"plane\",\"center\":[0,0,0],"
             "\"normal\":[0,0,1],\"size\":[%g,%g],\"albedo\":[%g,%g,%g]}]}",
             2 * HALF, 2 * HALF, RHO, RHO, RHO);
    lr_scene *s = lr_test_scene_text(doc, on);
    const double X = 1.0e-3;
    bool hit;
    size_t n, n2;
    float *E = shade_light(s, X, &hit, &n);
    assert_false(hit);
    char *dir = lr_test_path(home, "lamprig");
    char *file = rows_file(dir);
    assert_non_null(file);
    float *E2 = shade_light(s, X, &hit, &n2);
    assert_true(hit);
    assert_int_equal(n2, n);
    assert_memory_equal(E2, E, n * sizeof *E);
    free(E2);
    /* a flipped byte in the payload, then a file cut in half: rebuilt, the same light */
    size_t len;
    unsigned char *bytes = lr_test_read(file, &len);
    assert_true(len > 200);
    bytes[len - 7] ^= 0x5a;
    lr_test_put(file, bytes, len);
    E2 = shade_light(s, X, &hit, &n2);
    assert_false(hit);
    assert_memory_equal(E2, E, n * sizeof *E);
    free(E2);
    lr_test_put(file, bytes, len / 2);
    E2 = shade_light(s, X, &hit, &n2);
    assert_false(hit);
    assert_memory_equal(E2, E, n * sizeof *E);
    free(E2);
    /* the rebuild wrote it again */
    E2 = shade_light(s, X, &hit, &n2);
    assert_true(hit);
    assert_memory_equal(E2, E, n * sizeof *E);
    free(E2);
    print_message("rows cache: %zu bytes, hit after a build; a flipped byte and a half file "
                  "rebuilt to the same light\n", len);
    free(bytes);
    free(E);
    free(file);
    free(dir);
    lr_scene_destroy(s);
    if (saved)
        setenv("XDG_CACHE_HOME", saved, 1);
    else
        unsetenv("XDG_CACHE_HOME");
    free(saved);
    lr_test_rmtree(home);
}

static void count_not_stored(void *user, const char *msg)
{
    if (strstr(msg, "cache not stored"))
        ++*(int *)user;
}

static void test_cache_read_only_said_once(void **state)
{
    (void)state;
    char *home = lr_test_tmpdir();
    char *dir = lr_test_path(home, "lamprig");
    assert_int_equal(mkdir(dir, 0700), 0);
    if (lr_test_mount_tmpfs(dir, 256, 1) != 0) {
        print_message("skipped: mount: %s (needs root)\n", strerror(errno));
        free(dir);
        lr_test_rmtree(home);
        skip();
    }
    const char *old = getenv("XDG_CACHE_HOME");
    char *saved = old ? strdup(old) : NULL;
    setenv("XDG_CACHE_HOME", home, 1);
    char doc[2048];
    snprintf(doc, sizeof doc,
             "{\"name\":\"t\",\"objects\":[{\"name\":\"s\",\"material\":\"candle_wax\","
             "\"mesh\":{\"type\":\"sphere\",\"radius\":%g},\"transform\":{\"translate\":"
             "[0,0,%g]}}],"
             "\"lights\":[{\"type\":\"point\",\"position\":[0,0,3000],\"intensity\":1}],"
             "\"camera\":{\"position\":[0,-3000,100],\"target\":[0,0,0]},"
             "\"receivers\":[{\"name\":\"table\",\"type\":\"plane\",\"center\":[0,0,0],"
             "\"normal\":[0,0,1],\"size\":[%g,%g],\"albedo\":[%g,%g,%g]}]}",
             RS, ZS, 2 * HALF, 2 * HALF, RHO, RHO, RHO);
    int said = 0;
    lr_warn_sink warn = {count_not_stored, &said};
    lr_scene *s;
    lr_err e = {0};
    if (lr_scene_parse(doc, strlen(doc), "t.json", &warn, &s, &e) ||
        lr_scene_set_assignment(s, on[0], NULL, &e))
        fail_msg("%s", e.msg);
    lr_rbounce *rb = NULL;
    assert_int_equal(lr_rbounce_update(&rb, s, NULL, &e), LR_OK);
    assert_non_null(lr_rbounce_objects(rb));
    assert_false(lr_objlight_cache_hit(lr_rbounce_objects(rb)));
    assert_int_equal(said, 1);
    /* Another table: the geometry's key changes, the bounce rebuilds and stores again. */
    if (lr_scene_set_assignment(s, "receivers[0].size=[7000,7000]", NULL, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_rbounce_update(&rb, s, NULL, &e), LR_OK);
    double build_s, direct_s, solve_s;
    lr_rbounce_times(rb, &build_s, &direct_s, &solve_s);
    assert_true(build_s > 0);
    assert_int_equal(said, 1);
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
    lr_test_umount(dir);
    if (saved)
        setenv("XDG_CACHE_HOME", saved, 1);
    else
        unsetenv("XDG_CACHE_HOME");
    free(saved);
    free(dir);
    lr_test_rmtree(home);
}

static void test_factors_and_field(void **state)
{
    (void)state;
    lr_scene *s = scene(NULL);
    const lr_scene_object *o = lr_scene_object_at(s, 0);
    double kR[3], kT[3], Rd[3];
    lr_objlight_factors(o, kR, kT);
    lr_dipole_rd_total(&o->coeffs, Rd);
    for (int c = 0; c < 3; c++) {
        assert_near_rel(kR[c], Rd[c], 1e-3);
        assert_true(kT[c] == 0.0);
    }
    assert_true(lr_scene_render(s)->receiver_light_on_objects); /* default */
    lr_err e = {0};
    unsigned d = 0;
    if (lr_scene_set(s, "render.receiver_light_on_objects", "false", &d, &e))
        fail_msg("%s", e.msg);
    assert_true(d & LR_DIRTY_SETTINGS);
    assert_int_not_equal(lr_scene_set(s, "render.receiver_light_on_objects", "2", NULL, &e), 0);
    lr_rbounce *rb = solved(s, 1e-3);
    assert_null(lr_rbounce_objects(rb));
    lr_rbounce_destroy(rb);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_over_plane),
        cmocka_unit_test(test_occluder),
        cmocka_unit_test(test_far_face),
        cmocka_unit_test(test_cache),
        cmocka_unit_test(test_cache_read_only_said_once),
        cmocka_unit_test(test_factors_and_field),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
