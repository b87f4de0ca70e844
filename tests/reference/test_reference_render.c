/* Physical reference, rendering: next-event estimation against closed forms, refracted NEE
 * (Newton-solved connections through a Fresnel boundary) and the area-light hit/NEE partition
 * against photon counts, light tracing against an analytic mirror image, determinism, the
 * variance image, PFM files and scene files.
 *
 * Tolerances: |a - b| <= 4 sqrt(SE_a^2 + SE_b^2) (two-sided 4 sigma: false failure 6.3e-5 per
 * assertion), SE the Monte Carlo standard errors from sample variances; each test bounds the
 * SE it got so the comparison keeps its power. Deterministic parts are compared to 1e-12.
 */
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

#include "render/optics/optics.h"
#include "render/reference/ref_priv.h"
#include "render/area/emitter.h"
#include "render/scene/scene.h"
#include "tests/support/mc.h"

#define K_SIGMA 4.0

static int add_medium(lr_ref_scene *s, double ss, double sa, double g, double eta)
{
    lr_ref_medium_desc md = {.sigma_s = {ss, ss, ss}, .sigma_a = {sa, sa, sa}, .g = g, .eta = eta};
    int id;
    assert_int_equal(lr_ref_scene_add_medium(s, &md, &id, NULL), LR_OK);
    return id;
}

static void add_boundary(lr_ref_scene *s, lr_ref_shape *sh, int inside)
{
    lr_ref_object_desc od = {.kind = LR_REF_BOUNDARY, .shape = sh, .inside = inside};
    assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
}

static void add_receiver(lr_ref_scene *s, lr_ref_shape *sh, double albedo)
{
    lr_ref_object_desc od = {.kind = LR_REF_RECEIVER, .shape = sh,
                             .albedo = {albedo, albedo, albedo}};
    assert_int_equal(lr_ref_scene_add_object(s, &od, NULL), LR_OK);
}

static lr_ref_shape *quad(lr_vec3 c, lr_vec3 e1, lr_vec3 e2)
{
    lr_ref_shape *sh;
    assert_int_equal(lr_ref_quad_create(c, e1, e2, &sh, NULL), LR_OK);
    return sh;
}

/* ---- NEE on a receiver: closed forms -------------------------------------------------- */

/* A floor (albedo 0.6, facing up) under a point light at height 2 and a spot light: the
 * radiance the camera paths return is rho / pi * I cos / d^2 (times the spot profile), with
 * nothing else in the scene, so it must match to rounding: NEE to a delta light is
 * deterministic. Points inside the spot's inner cone, on its smoothstep ramp and outside. */
static void test_receiver_under_point_and_spot(void **state)
{
    (void)state;
    for (int spot = 0; spot < 2; spot++) {
        lr_ref_scene *s;
        assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
        add_receiver(s, quad(lr_v3(-50, -50, 0), lr_v3(100, 0, 0), lr_v3(0, 100, 0)), 0.6);
        lr_ref_light_desc ld = {.kind = spot ? LR_REF_LIGHT_SPOT : LR_REF_LIGHT_POINT,
                                .position = lr_v3(0, 0, 2), .direction = lr_v3(0, 0, -1),
                                .inner_deg = 20, .outer_deg = 40, .emission = {3, 3, 3}};
        assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
        assert_int_equal(lr_ref_scene_finish(s, NULL), LR_OK);
        const double xs[] = {0.0, 0.5, 1.2, 1.6, 3.0}; /* 0, 14, 31, 39, 56 degrees */
        for (size_t i = 0; i < sizeof xs / sizeof xs[0]; i++) {
            lr_vec3 p = lr_v3(xs[i], 0, 0);
            double d2 = xs[i] * xs[i] + 4.0, c = 2.0 / sqrt(d2);
            double prof = 1.0;
            if (spot) {
                double ci = cos(20 * LR_REF_PI / 180), co = cos(40 * LR_REF_PI / 180);
                double x = fmin(1.0, fmax(0.0, (c - co) / (ci - co)));
                prof = x * x * (3 - 2 * x);
            }
            double expect = 0.6 / LR_REF_PI * 3.0 * prof * c / d2;
            lr_ref_rng rng;
            lr_ref_rng_seed(&rng, 1, i);
            double L[3] = {0, 0, 0};
            lr_ref_radiance(s, lr_v3_add(p, lr_v3(0.1, 0.2, 1.0)),
                            lr_v3_normalize(lr_v3(-0.1, -0.2, -1.0)), 0, &rng, NULL, L);
            assert_true(fabs(L[0] - expect) <= 1e-12 * fmax(1.0, expect));
            assert_true(L[0] == L[1] && L[1] == L[2]);
        }
        lr_ref_scene_destroy(s);
    }
}

/* A disk light of radius a and radiance L_e facing down at height h over the floor: on its
 * axis the floor's irradiance is pi L_e a^2 / (a^2 + h^2) (e.g. Modest, Radiative Heat
 * Transfer, view factor of a coaxial disk). NEE samples the disk: 20 000 samples, SE about
 * 0.3 %. Also the camera paths must count the light when they see it directly (L_e). */
static void test_receiver_under_disk_light(void **state)
{
    (void)state;
    const double a = 0.5, h = 1.0, Le = 2.0, rho = 0.8;
    lr_ref_scene *s;
    assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
    add_receiver(s, quad(lr_v3(-50, -50, 0), lr_v3(100, 0, 0), lr_v3(0, 100, 0)), rho);
    lr_ref_light_desc ld = {.kind = LR_REF_LIGHT_DISK, .position = lr_v3(0, 0, h),
                            .direction = lr_v3(0, 0, -1), .radius = a, .emission = {Le, Le, Le}};
    assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
    assert_int_equal(lr_ref_scene_finish(s, NULL), LR_OK);
    double s1 = 0, s2 = 0;
    const int N = 20000;
    lr_ref_rng rng;
    lr_ref_rng_seed(&rng, 2, 0);
    for (int i = 0; i < N; i++) {
        double L[3] = {0, 0, 0};
        /* Looking at the axis point from the side, below the light. */
        lr_ref_radiance(s, lr_v3(0.3, 0, 0.5), lr_v3_normalize(lr_v3(-0.3, 0, -0.5)), 0, &rng,
                        NULL, L);
        s1 += L[0];
        s2 += L[0] * L[0];
    }
    /* Multiple bounces floor -> light: the light is black, and nothing else reflects. */
    double expect = rho / LR_REF_PI * LR_REF_PI * Le * a * a / (a * a + h * h);
    lr_ref_estimate got = lrt_mean_se(s1, s2, N);
    assert_true(got.se < 0.01 * expect);
    lrt_assert_agree("floor under a disk light", got, (lr_ref_estimate){expect, 0.0});
    lr_ref_rng_seed(&rng, 2, 1);
    double L[3] = {0, 0, 0};
    lr_ref_radiance(s, lr_v3(0.1, 0, 0.2), lr_v3(0, 0, 1), 0, &rng, NULL, L);
    assert_true(L[0] == Le);
    lr_ref_scene_destroy(s);
}

/* A project scene's quad lights (render/area: centre and half-edges; one- or two-sided) through
 * lr_ref_scene_from_scene: the table's radiance under them is rho / pi times Lambert's closed
 * form for the irradiance (lr_area_irradiance), within 4 standard errors (20 000 samples,
 * SE < 1 %). A one-sided quad facing up leaves the table dark; two-sided, it lights it as the
 * downward one does. */
static void test_scene_quad_lights(void **state)
{
    (void)state;
    const double rho = 0.75, Le = 2e-3;
    /* edge_u x edge_v: (0,4,0) x (10,0,0) faces down, (10,0,0) x (0,4,0) up. */
    const char *edges[3] = {"[0, 4, 0], \"edge_v\": [10, 0, 0]",
                            "[10, 0, 0], \"edge_v\": [0, 4, 0]",
                            "[10, 0, 0], \"edge_v\": [0, 4, 0], \"two_sided\": true"};
    for (int k = 0; k < 3; k++) {
        char t[1024];
        snprintf(t, sizeof t,
                 "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": \"sphere\","
                 " \"radius\": 2}, \"transform\": {\"translate\": [300, 300, 50]}}],"
                 " \"lights\": [{\"type\": \"quad\", \"position\": [0, 0, 30], \"edge_u\": %s,"
                 " \"radiance\": %g}],"
                 " \"camera\": {\"position\": [0, -300, 100], \"target\": [0, 0, 0]},"
                 " \"receivers\": [{\"type\": \"plane\", \"center\": [0, 0, 0], \"normal\":"
                 " [0, 0, 1], \"size\": [400, 400], \"albedo\": [%g, %g, %g]}]}",
                 edges[k], Le, rho, rho, rho);
        lr_scene *sc;
        lr_err e = {0};
        if (lr_scene_parse(t, strlen(t), "quad.json", NULL, &sc, &e))
            fail_msg("%s", e.msg);
        lr_ref_scene *s;
        lr_ref_camera cam;
        if (lr_ref_scene_from_scene(sc, &s, &cam, &e))
            fail_msg("%s", e.msg);
        lr_area_emitter em;
        assert_int_equal(lr_area_quad(lr_v3(0, 0, 30), lr_v3(0, 4, 0), lr_v3(10, 0, 0), false,
                                      &em, &e), LR_OK);
        const lr_vec3 xs[] = {lr_v3(0, 0, 0), lr_v3(25, 10, 0)};
        for (int i = 0; i < 2; i++) {
            double expect = k == 1 ? 0.0
                                   : rho / M_PI * lr_area_irradiance(&em, Le, xs[i],
                                                                     lr_v3(0, 0, 1));
            double s1 = 0, s2 = 0;
            const int N = 20000;
            lr_ref_rng rng;
            lr_ref_rng_seed(&rng, 5, (uint64_t)(k * 2 + i));
            /* Looked at from the side, below the light. */
            lr_vec3 o = lr_v3_add(xs[i], lr_v3(40, -20, 10));
            for (int n = 0; n < N; n++) {
                double L[3] = {0, 0, 0};
                lr_ref_radiance(s, o, lr_v3_normalize(lr_v3_sub(xs[i], o)), 0, &rng, NULL, L);
                s1 += L[0];
                s2 += L[0] * L[0];
            }
            lr_ref_estimate got = lrt_mean_se(s1, s2, N);
            if (k == 1) {
                assert_true(got.value == 0.0);
                continue;
            }
            print_message("quad %d point %d: %.6g +- %.2g, closed form %.6g\n", k, i, got.value,
                          got.se, expect);
            assert_true(got.se < 0.01 * expect);
            /* The receiver sits 1e-3 mm lower in the reference (RECEIVER_GAP_MM) and a
             * two-sided light's back face 1e-3 mm lower too: < 1e-4 of the irradiance. */
            lrt_assert_agree("table under a scene's quad light", got,
                             (lr_ref_estimate){expect, 1e-4 * expect});
        }
        lr_ref_scene_destroy(s);
        lr_scene_destroy(sc);
    }
}

/* A project scene's photometric profiles (render/photometry/profile.h) through
 * lr_ref_scene_from_scene: a table lit only by a profiled point light (the oval LM-63 spot,
 * nadir down, C0 turned 30 degrees) and by a profiled quad (the EULUMDAT strip facing down).
 * The renderer's shape (lr_light_shape, which the twin, translucent radiosity and, through
 * the same table and arithmetic, the GPU passes use; test_render_lights) gives the expected
 * radiance: for the point rho / pi I shape(w) cos / d^2, deterministic NEE, so 1e-4 (the
 * receiver's 1e-3 mm gap, below); for the quad the same integrated over the emitter by the midpoint
 * rule (200 x 80 cells, ~1e-5), against 20 000 NEE samples within 4 standard errors. The
 * photons (light tracing) leave by the profile's distribution: their mean power is the
 * light's flux per band, and the share below 30 degrees from nadir the shape's integral
 * there, within 4 standard errors of 40 000 photons. */
static void test_scene_profiled_lights(void **state)
{
    (void)state;
    const double rho = 0.75;
    const char *lights[2] = {
        "{\"type\": \"point\", \"position\": [0, 0, 40], \"intensity\": 2e-3,"
        " \"direction\": [0, 0, -1], \"profile_c0\": [0.866, 0.5, 0],"
        " \"profile\": \"" LR_SOURCE_CONFIGS "/photometry/led_spot_3000k.ies\"}",
        "{\"type\": \"quad\", \"position\": [0, 0, 30], \"edge_u\": [0, 4, 0],"
        " \"edge_v\": [10, 0, 0], \"radiance\": 2e-3,"
        " \"profile\": \"" LR_SOURCE_CONFIGS "/photometry/led_strip_4000k.ldt\"}"};
    for (int k = 0; k < 2; k++) {
        char t[2048];
        snprintf(t, sizeof t,
                 "{\"objects\": [{\"material\": \"marble\", \"mesh\": {\"type\": \"sphere\","
                 " \"radius\": 2}, \"transform\": {\"translate\": [300, 300, 50]}}],"
                 " \"lights\": [%s],"
                 " \"camera\": {\"position\": [0, -300, 100], \"target\": [0, 0, 0]},"
                 " \"receivers\": [{\"type\": \"plane\", \"center\": [0, 0, 0], \"normal\":"
                 " [0, 0, 1], \"size\": [400, 400], \"albedo\": [%g, %g, %g]}]}",
                 lights[k], rho, rho, rho);
        lr_scene *sc;
        lr_err e = {0};
        if (lr_scene_parse(t, strlen(t), "profile.json", NULL, &sc, &e))
            fail_msg("%s", e.msg);
        const lr_light *L = lr_scene_light_at(sc, 0);
        assert_true(L->profile.on);
        lr_ref_scene *s;
        lr_ref_camera cam;
        if (lr_ref_scene_from_scene(sc, &s, &cam, &e))
            fail_msg("%s", e.msg);
        /* Not straight under the point light: the oval example (1 + 0.3 cos 2C at every gamma)
         * is discontinuous at its nadir, where C is undefined. */
        const lr_vec3 xs[] = {lr_v3(3, -2, 0), lr_v3(20, 8, 0), lr_v3(-12, 25, 0)};
        for (int i = 0; i < 3; i++) {
            double expect = 0.0;
            if (k == 0) {
                lr_vec3 d = lr_v3_sub(xs[i], L->position);
                double d2 = lr_v3_dot(d, d), c = fabs(d.z) / sqrt(d2);
                expect = rho / M_PI * L->intensity *
                         lr_light_shape(L, lr_v3_scale(d, 1.0 / sqrt(d2))) * c / d2;
            } else {
                const int nu = 80, nv = 200;
                double A = lr_light_area(L), sum = 0.0;
                for (int a = 0; a < nu; a++)
                    for (int b = 0; b < nv; b++) {
                        double su = -1.0 + (a + 0.5) * 2.0 / nu, sv = -1.0 + (b + 0.5) * 2.0 / nv;
                        lr_vec3 y = lr_v3_add(L->position, lr_v3_add(lr_v3_scale(L->edge_u, su),
                                                                     lr_v3_scale(L->edge_v, sv)));
                        lr_vec3 d = lr_v3_sub(xs[i], y);
                        double d2 = lr_v3_dot(d, d), c = fabs(d.z) / sqrt(d2);
                        /* shape = A rel: per element dA = A / (nu nv), rel = shape / A. */
                        sum += lr_light_shape(L, lr_v3_scale(d, 1.0 / sqrt(d2))) / A * c / d2 *
                               (A / (nu * nv));
                    }
                expect = rho / M_PI * L->intensity * sum;
            }
            const int N = k == 0 ? 1 : 20000;
            double s1 = 0, s2 = 0;
            lr_ref_rng rng;
            lr_ref_rng_seed(&rng, 9, (uint64_t)(k * 3 + i));
            /* Straight down: the reference's table lies 1e-3 mm lower (RECEIVER_GAP_MM), which
             * moves a slanted ray's hit sideways but a vertical one's only in d (2 dd / d <
             * 6e-5 at 35-50 mm). */
            lr_vec3 o = lr_v3_add(xs[i], lr_v3(0, 0, 10));
            for (int n = 0; n < N; n++) {
                double Lr[3] = {0, 0, 0};
                lr_ref_radiance(s, o, lr_v3_normalize(lr_v3_sub(xs[i], o)), 0, &rng, NULL, Lr);
                s1 += Lr[0];
                s2 += Lr[0] * Lr[0];
            }
            lr_ref_estimate got = lrt_mean_se(s1, s2, N);
            print_message("profile %d point %d: %.6g +- %.2g, renderer's shape %.6g\n", k, i,
                          got.value, got.se, expect);
            assert_true(expect > 0.0);
            if (k == 0) {
                assert_true(fabs(got.value - expect) <= 1e-4 * expect);
            } else {
                assert_true(got.se < 0.01 * expect);
                lrt_assert_agree("table under a profiled quad", got,
                                 (lr_ref_estimate){expect, 1e-4 * expect});
            }
        }
        /* Photons: mean power (flux per band) and the share within 30 degrees of nadir. */
        const lr_ref_light *rl = &s->lights[0];
        const int N = 40000;
        double p1 = 0, p2 = 0, c1 = 0, c2 = 0, cap = cos(30.0 * M_PI / 180.0);
        lr_ref_rng rng;
        lr_ref_rng_seed(&rng, 10, (uint64_t)k);
        for (int n = 0; n < N; n++) {
            lr_vec3 o, d;
            double pw[3];
            lr_ref_light_emit_all(rl, &rng, &o, &d, pw);
            p1 += pw[0];
            p2 += pw[0] * pw[0];
            double in = d.z < -cap ? pw[0] : 0.0;
            c1 += in;
            c2 += in * in;
        }
        /* The expectations from the renderer's shape, by the midpoint rule over the sphere
         * (0.25 x 1 degree; the point's about its nadir, the quad's about its normal, -z). */
        double tot = 0.0, in_cap = 0.0;
        for (int a = 0; a < 720; a++) {
            double t0 = a * 0.25 * M_PI / 180.0, t1 = (a + 1) * 0.25 * M_PI / 180.0;
            double tm = 0.5 * (t0 + t1), dmu = cos(t0) - cos(t1);
            for (int b = 0; b < 360; b++) {
                double ph = (b + 0.5) * M_PI / 180.0;
                lr_vec3 w = lr_v3(sin(tm) * cos(ph), sin(tm) * sin(ph), -cos(tm));
                double f = lr_light_shape(L, w) * dmu * (M_PI / 180.0);
                tot += f;
                if (cos(tm) > cap)
                    in_cap += f;
            }
        }
        lr_ref_estimate gp = lrt_mean_se(p1, p2, N), gc = lrt_mean_se(c1, c2, N);
        double I = L->intensity * L->color[0];
        print_message("profile %d photons: power %.6g +- %.2g (shape %.6g), cap %.6g +- %.2g "
                      "(%.6g)\n", k, gp.value, gp.se, I * tot, gc.value, gc.se, I * in_cap);
        lrt_assert_agree("photon power", gp, (lr_ref_estimate){I * tot, 1e-4 * I * tot});
        lrt_assert_agree("photon power near nadir", gc,
                         (lr_ref_estimate){I * in_cap, 1e-4 * I * in_cap});
        lr_ref_scene_destroy(s);
        lr_scene_destroy(sc);
    }
}

/* ---- refracted NEE and the hit/NEE partition vs photons ------------------------------- */

/* A half-space of scattering medium (n = 1.5) lit from above by a point light, a spot, or a
 * disk area light. The power that leaves the surface within radius rho of the axis after
 * scattering at least once is computed twice:
 *   photons  from the light, counted where they leave (their last boundary crossing);
 *   camera   Phi = int_disk int_H L cos dw dA = pi rho^2 * pi * E[L(x, w)] with x uniform in
 *            the disk and w cosine-weighted: every scattering vertex connects to the light
 *            through the refracting surface (Newton, k = 1), and for the area light the walk's
 *            hits count only where NEE cannot connect (an internal reflection came first).
 * Light reflected by the surface before scattering never scatters here, so no light-traced
 * part is involved. The camera paths see the mirror image of the area light in the surface
 * (a path with no scattering that hits the light): for it the photons reflected at the
 * surface count too; a point or spot light has no visible mirror image. rho = 3 mm (1.5 light heights); 800 000 photons (SE about 1 %: only those
 * leaving through the disk count), 200 000 camera paths (SE about 0.3 %). */
typedef struct halfspace_job {
    const lr_ref_scene *s;
    double rho;
    bool camera, specular;
    int n;
    double sum[64], sum2[64];
} halfspace_job;

static void halfspace_batch(int b, void *user)
{
    halfspace_job *j = user;
    lr_ref_rng rng;
    lr_ref_rng_seed(&rng, j->camera ? 41 : 42, (uint64_t)b);
    for (int i = 0; i < j->n; i++) {
        double f = 0.0;
        if (j->camera) {
            double r = j->rho * sqrt(lr_ref_rng_uniform(&rng));
            double phi = 2 * LR_REF_PI * lr_ref_rng_uniform(&rng);
            lr_vec3 x = lr_v3(r * cos(phi), r * sin(phi), 0.0);
            double u1 = lr_ref_rng_uniform(&rng), u2 = lr_ref_rng_uniform(&rng);
            lr_vec3 w = lr_ref_cosine_sample(lr_v3(0, 0, 1), u1, u2);
            double L[3] = {0, 0, 0};
            lr_ref_radiance(j->s, lr_v3_add(x, lr_v3_scale(w, 0.01)), lr_v3_scale(w, -1.0), 0,
                            &rng, NULL, L);
            f = LR_REF_PI * j->rho * j->rho * LR_REF_PI * L[0];
        } else {
            lr_vec3 o, d;
            double power;
            int m = lr_ref_light_emit(j->s, 0, 0, &rng, &o, &d, &power);
            lr_ref_photon_exit x;
            lr_ref_photon_trace(j->s, o, d, m, 0, &rng, NULL, &x);
            /* What left the surface, whether it then escaped or was caught by the light's
             * black surface (the camera-side integral counts both). */
            if ((x.escaped || x.hit_light) && x.boundaries > 0 &&
                (x.scatterings > 0 || j->specular) &&
                x.position.x * x.position.x + x.position.y * x.position.y < j->rho * j->rho)
                f = x.weight * power;
        }
        j->sum[b] += f;
        j->sum2[b] += f * f;
    }
}

static lr_ref_estimate halfspace_power(const lr_ref_scene *s, double rho, bool camera, int n)
{
    halfspace_job *j = calloc(1, sizeof *j);
    j->s = s;
    j->specular = s->lights[0].object >= 0;
    j->rho = rho;
    j->camera = camera;
    j->n = n / 64;
    assert_int_equal(lr_ref_parallel(64, 0, halfspace_batch, j, NULL), LR_OK);
    double s1 = 0, s2 = 0;
    for (int b = 0; b < 64; b++) {
        s1 += j->sum[b];
        s2 += j->sum2[b];
    }
    lr_ref_estimate e = lrt_mean_se(s1, s2, 64.0 * j->n);
    free(j);
    return e;
}

static void test_refracted_nee_matches_photons(void **state)
{
    (void)state;
    const char *names[] = {"point light over n = 1.5", "spot light over n = 1.5",
                           "disk light over n = 1.5"};
    for (int kind = 0; kind < 3; kind++) {
        lr_ref_scene *s;
        assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
        int m = add_medium(s, 0.9, 0.1, 0.5, 1.5);
        lr_ref_shape *sh;
        assert_int_equal(lr_ref_slab_create(0.0, INFINITY, &sh, NULL), LR_OK);
        add_boundary(s, sh, m);
        lr_ref_light_desc ld = {.position = lr_v3(0.3, 0, 2), .direction = lr_v3(0, 0.3, -1),
                                .emission = {1, 1, 1}};
        ld.kind = kind == 0 ? LR_REF_LIGHT_POINT : kind == 1 ? LR_REF_LIGHT_SPOT
                                                             : LR_REF_LIGHT_DISK;
        ld.inner_deg = 25;
        ld.outer_deg = 50;
        ld.radius = 1.5;
        assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
        assert_int_equal(lr_ref_scene_finish(s, NULL), LR_OK);
        lr_ref_estimate ph = halfspace_power(s, 3.0, false, 800000);
        lr_ref_estimate cam = halfspace_power(s, 3.0, true, kind == 2 ? 320000 : 160000);
        lrt_assert_agree(names[kind], cam, ph);
        assert_true(cam.se < 0.01 * cam.value && ph.se < 0.01 * ph.value);
        lr_ref_scene_destroy(s);
    }
}

/* The refracted connection itself, through a plane: from a point at depth z below an
 * n = 1.5 surface to a unit point light at height H, the connection must obey Snell's law and
 * its flux density must equal the closed form of the refracted ray tube,
 *   E = I T(theta_i) cos(theta_t) / [u (H / cos^2 theta_i + (z / cos^2 theta_t) cos theta_i
 *       / (n cos theta_t)) (H tan theta_i ... )]
 * written below as E = I T sin(theta_i) / (D cos(theta_t) dD/dtheta_i) with D the horizontal
 * distance, dD/dtheta_i = H / cos^2 theta_i + z cos theta_i / (n cos^3 theta_t): the ray tube
 * of a point source refracted by a plane (sagittal width D dphi, meridional cos theta_t dD). */
static void test_refracted_connection_closed_form(void **state)
{
    (void)state;
    const double n = 1.5, H = 2.0, z = 0.3, D = 1.7;
    lr_ref_scene *s;
    assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
    int m = add_medium(s, 0.0, 0.2, 0.0, n);
    lr_ref_shape *sh;
    assert_int_equal(lr_ref_slab_create(0.0, INFINITY, &sh, NULL), LR_OK);
    add_boundary(s, sh, m);
    lr_ref_light_desc ld = {.kind = LR_REF_LIGHT_POINT, .position = lr_v3(0, 0, H),
                            .emission = {1, 1, 1}};
    assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
    assert_int_equal(lr_ref_scene_finish(s, NULL), LR_OK);
    /* Solve Snell for the horizontal position u of the refraction point by bisection. */
    double lo = 0.0, hi = D;
    for (int i = 0; i < 200; i++) {
        double u = 0.5 * (lo + hi);
        double si = u / hypot(u, H), st = (D - u) / hypot(D - u, z);
        if (si - n * st > 0.0)
            hi = u;
        else
            lo = u;
    }
    double u = 0.5 * (lo + hi);
    double ti = atan2(u, H), tt = atan2(D - u, z);
    double dDdti = H / (cos(ti) * cos(ti)) + z * cos(ti) / (n * pow(cos(tt), 3));
    double T = lr_fresnel_transmittance(cos(ti), n);
    double path_in = hypot(D - u, z);
    double expect = T * sin(ti) / (D * cos(tt) * dDdti) * exp(-0.2 * path_in);
    lr_ref_emitter em = {.light = &s->lights[0], .p = ld.position, .medium = 0,
                         .area_weight = 1.0};
    double E[3];
    lr_vec3 w_in;
    lr_ref_stats st = {0};
    assert_true(lr_ref_connect(s, &em, lr_v3(D, 0, -z), m, 7, NULL, &st, E, &w_in));
    printf("  refracted flux density %.12g, closed form %.12g\n", E[0], expect);
    assert_true(fabs(E[0] / expect - 1.0) < 1e-6);
    /* The arriving direction points back toward the refraction point (u, 0, 0). */
    lr_vec3 back = lr_v3_normalize(lr_v3(u - D, 0, z));
    assert_true(lr_v3_len(lr_v3_sub(w_in, back)) < 1e-7);
    assert_int_equal(st.nee_refracted, 1);
    assert_int_equal(st.nee_unsolved, 0);

    /* Backwards: an emitter inside the medium (at the former receiving point) lighting the
     * former light position outside. The connection is then solved from the outside end and
     * converted by etendue conservation, det J_{p->x} = (n_p / n_x)^2 det J_{x->p}: the same
     * pencil of rays, so E_back = E_forward (n_out / n_in)^2 (the Fresnel factor is the same
     * both ways). */
    lr_ref_emitter in = {.light = NULL, .p = lr_v3(D, 0, -z), .medium = m, .area_weight = 1.0,
                         .power = {1, 1, 1}, .g = 0.0};
    double Eb[3];
    lr_vec3 wb;
    assert_true(lr_ref_connect(s, &in, ld.position, 0, 7, NULL, &st, Eb, &wb));
    /* The vertex emitter is an isotropic HG (g = 0) of power 1: intensity 1 / (4 pi). */
    double expect_back = expect / (n * n) / (4.0 * LR_REF_PI);
    printf("  backwards %.12g, expected %.12g\n", Eb[0], expect_back);
    assert_true(fabs(Eb[0] / expect_back - 1.0) < 1e-6);
    assert_true(lr_v3_len(lr_v3_sub(wb, lr_v3_normalize(lr_v3(u, 0, -H)))) < 1e-7);
    lr_ref_scene_destroy(s);
}

/* ---- light tracing: a mirror image ---------------------------------------------------- */

/* A point light at L = (0.25, 0.1, 1) over a dielectric half-space (n = 1.5, strongly
 * absorbing: what refracts in never comes back) and a small white ceiling (1.2 x 1.2 at
 * height 2) facing down. The ceiling gets the direct light (camera-path NEE) and the light the
 * dielectric reflects, which no camera path can find (light -> reflection -> ceiling): light
 * tracing splats it. By the method of images the reflected part comes from the mirror source
 * L' = (0.25, 0.1, -1) of intensity I R(theta_i), so the ceiling's irradiance is
 *   E = I / d1^2 * (1 / d1) + I R(cos theta_i) / d2^2 * (3 / d2),   cos theta_i = 3 / d2,
 * d1, d2 the distances to L and L'. A camera at (0, 0, 0.5) looking up sees only the ceiling
 * (40 degree field); each pixel's expected value is the average of rho / pi E over its
 * footprint (16 x 16 midpoint quadrature; E is smooth, error < 1e-5 relative). Light the
 * ceiling sends down and the dielectric mirrors back onto it is in the render but not in E:
 * at most R (< 0.05 here) times the ceiling's mirror image's view factor (1.44 / (pi 4^2)
 * < 0.03), under 0.15 % of the total, which the total's assertion allows on top of 4 SE
 * (SE about 0.2 %). The same for each 6 x 6 quadrant of the image, which checks where the
 * splats land. (Single pixels are not tested: a pixel receives only a dozen light-traced
 * splats here, too few for its variance estimate to make a normal z-score.) */
static const lr_vec3 mirror_light = {0.25, 0.1, 1.0};

static double ceiling_E(double x, double y)
{
    double dx = x - mirror_light.x, dy = y - mirror_light.y;
    double d1 = sqrt(dx * dx + dy * dy + 1.0), d2 = sqrt(dx * dx + dy * dy + 9.0);
    return 1.0 / (d1 * d1 * d1) + lr_fresnel_reflectance(3.0 / d2, 1.5) * 3.0 / (d2 * d2 * d2);
}

static void test_light_tracing_mirror_image(void **state)
{
    (void)state;
    lr_ref_scene *s;
    assert_int_equal(lr_ref_scene_create(NULL, &s, NULL), LR_OK);
    int m = add_medium(s, 0.0, 50.0, 0.0, 1.5);
    lr_ref_shape *sh;
    assert_int_equal(lr_ref_slab_create(0.0, INFINITY, &sh, NULL), LR_OK);
    add_boundary(s, sh, m);
    add_receiver(s, quad(lr_v3(-0.6, -0.6, 2), lr_v3(0, 1.2, 0), lr_v3(1.2, 0, 0)), 1.0);
    lr_ref_light_desc ld = {.kind = LR_REF_LIGHT_POINT, .position = mirror_light,
                            .emission = {1, 1, 1}};
    assert_int_equal(lr_ref_scene_add_light(s, &ld, NULL), LR_OK);
    assert_int_equal(lr_ref_scene_finish(s, NULL), LR_OK);
    lr_ref_camera cam = {.position = lr_v3(0, 0, 0.5), .look_at = lr_v3(0, 0, 2),
                         .up = lr_v3(0, 1, 0), .fov_y_deg = 40};
    lr_ref_render_desc d = {.width = 12, .height = 12, .spp = 256, .spp_per_pass = 64, .seed = 9};
    lr_ref_render *r;
    assert_int_equal(lr_ref_render_create(s, &cam, &d, &r, NULL), LR_OK);
    assert_int_equal(lr_ref_render_run(r, NULL, NULL, NULL), LR_OK);
    lr_ref_image mean, var;
    assert_int_equal(lr_ref_render_mean(r, &mean, NULL), LR_OK);
    assert_int_equal(lr_ref_render_variance(r, &var, NULL), LR_OK);
    assert_true(lr_ref_render_stats(r)->photons > 0);
    lr_ref_pinhole pin;
    lr_ref_pinhole_init(&pin, &cam, 12, 12, 0);
    double tot[5] = {0}, tot_exp[5] = {0}, tot_var[5] = {0}; /* quadrants, then all */
    for (int py = 0; py < 12; py++) {
        for (int px = 0; px < 12; px++) {
            double acc = 0.0;
            for (int qy = 0; qy < 16; qy++)
                for (int qx = 0; qx < 16; qx++) {
                    double sx = 2.0 * (px + (qx + 0.5) / 16) / 12 - 1.0;
                    double sy = 1.0 - 2.0 * (py + (qy + 0.5) / 16) / 12;
                    lr_vec3 dir = lr_v3_add(pin.f, lr_v3_add(lr_v3_scale(pin.r, sx * pin.tx),
                                                             lr_v3_scale(pin.u, sy * pin.ty)));
                    double t = (2.0 - pin.c.z) / dir.z;
                    acc += ceiling_E(pin.c.x + t * dir.x, pin.c.y + t * dir.y) / LR_REF_PI;
                }
            size_t i = 3 * ((size_t)py * 12 + (size_t)px);
            int q = (py / 6) * 2 + px / 6;
            for (int k = 0; k < 2; k++) {
                int slot = k ? 4 : q;
                tot[slot] += mean.rgb[i];
                tot_exp[slot] += acc / 256.0;
                tot_var[slot] += var.rgb[i];
            }
        }
    }
    for (int k = 0; k < 5; k++) {
        lr_ref_estimate got = {tot[k], sqrt(tot_var[k])};
        printf("  %s %d: %.5g +- %.2g vs images method %.5g (%+.2f SE)\n",
               k < 4 ? "quadrant" : "image total", k, tot[k], got.se, tot_exp[k],
               (tot[k] - tot_exp[k]) / got.se);
        assert_true(got.se < 0.01 * tot_exp[k]);
        assert_true(fabs(tot[k] - tot_exp[k]) <= K_SIGMA * got.se + 0.0015 * tot_exp[k]);
    }
    lr_ref_image_free(&mean);
    lr_ref_image_free(&var);
    lr_ref_render_destroy(r);
    lr_ref_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_receiver_under_point_and_spot),
        cmocka_unit_test(test_receiver_under_disk_light),
        cmocka_unit_test(test_scene_quad_lights),
        cmocka_unit_test(test_scene_profiled_lights),
        cmocka_unit_test(test_refracted_connection_closed_form),
        cmocka_unit_test(test_refracted_nee_matches_photons),
        cmocka_unit_test(test_light_tracing_mirror_image),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
