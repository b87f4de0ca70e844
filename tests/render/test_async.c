/* The renderer off the caller's loop (render/async/async.h): its converged image is the
 * renderer's own, a dimmer change during a solve is blended at once on the images already
 * published, the preview stage comes exactly once per change that re-runs the maps, and the
 * scene copy it renders is independent of the caller's scene (lr_scene_clone); a preview at
 * half the size is a half-size renderer's image scaled up. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "render/async/async.h"
#include "render/mesh/bvh.h"
#include "render/mesh/mesh.h"
#include "render/plan/limits.h"
#include "render/renderer.h"
#include "tests/support/gl.h"
#include "tests/support/render.h"

#define W 40
#define H 30
/* Minutes only under the sanitizers on a loaded machine; a hang guard, not a speed bound. */
#define WAIT_MS 600000

/* The candle with a deterministic model (a diffusion grid: no per-frame sample, so two
 * renderers that reach the same state draw the same image whatever their frame counts,
 * render/renderer.h) and a CPU solve long enough that the worker is still at it when the
 * caller turns the dimmer (a 5 mm grid: a few thousand cells, a solve of a fraction of a
 * second under the sanitizers, still far longer than the dimmer's blend). */
static const char *const grid_sets[] = {"objects[0].model=diffusion_grid", "objects[0].dgrid_h_mm=5",
                                        "lights[0].flicker.amplitude=0", NULL};

static const char *const preview[] = {"render.K=1", "render.N=1", "render.map_size=16",
                                      "render.frames=1"};

typedef struct fixture {
    lr_gl *gl;
} fixture;

static int setup(void **state)
{
    static fixture f;
    if (lr_test_gl_create(&f.gl))
        return -1;
    *state = &f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    lr_gl_destroy(f->gl);
    return 0;
}

static lr_async *make(lr_gl *gl, lr_scene *s, bool with_preview)
{
    lr_async_desc d = {.gl = gl, .scene = s, .width = W, .height = H};
    if (with_preview) {
        for (int i = 0; i < 4; i++)
            d.preview[i] = preview[i];
        d.n_preview = 4;
        d.preview_always = true; /* the grid's solve costs the preview as much as the rest */
    }
    lr_async *a = NULL;
    lr_err e = {0};
    if (lr_async_create(&d, &a, &e))
        fail_msg("lr_async_create: %s", e.msg);
    return a;
}

static void wait_final(lr_async *a, uint64_t batch)
{
    lr_err e = {0};
    if (lr_async_wait(a, batch, true, WAIT_MS, &e))
        fail_msg("lr_async_wait: %s", e.msg);
}

static float *frame_hdr(lr_async *a, lr_async_frame_stats *st)
{
    lr_err e = {0};
    if (lr_async_frame(a, st, &e))
        fail_msg("lr_async_frame: %s", e.msg);
    float *px = malloc((size_t)W * H * 3 * sizeof *px);
    assert_non_null(px);
    if (lr_async_read_hdr(a, px, &e))
        fail_msg("lr_async_read_hdr: %s", e.msg);
    return px;
}

static double max_abs(const float *x, size_t n)
{
    double m = 0;
    for (size_t i = 0; i < n; i++)
        m = fmax(m, fabs(x[i]));
    return m;
}

/* got against want within 1e-5 of want's peak (float rounding of the same sums). */
static void assert_same_image(const float *got, const float *want, const char *what)
{
    size_t n = (size_t)W * H * 3;
    double peak = max_abs(want, n), worst = 0;
    assert_true(peak > 0);
    for (size_t i = 0; i < n; i++)
        worst = fmax(worst, fabs((double)got[i] - want[i]));
    printf("%s: worst |diff| %.3g of peak %.3g\n", what, worst, peak);
    assert_true(worst <= 1e-5 * peak);
}

static void set(lr_scene *s, const char *key, const char *value, unsigned *dirty)
{
    lr_err e = {0};
    if (lr_scene_set(s, key, value, dirty, &e))
        fail_msg("%s", e.msg);
}

/* The converged image through the worker (with its preview stage and the settings restored
 * after it) is the one the renderer draws on the caller's thread: the same passes on the same
 * state. Both are float sums of the same terms, so they agree to float rounding (1e-5 of the
 * image's peak, the dimmer's own bound in test_render_schedule). */
static void test_final_is_the_renderers_image(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_async *a = make(f->gl, s, true);
    wait_final(a, 0);
    lr_async_frame_stats st;
    float *got = frame_hdr(a, &st);
    assert_int_equal(st.stage, LR_ASYNC_FINAL);
    assert_true(st.new_images);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_PREVIEW), 1);

    lr_renderer *r = lr_test_renderer(f->gl, s, W, H, false, 1);
    lr_test_converge(r, 50);
    float *want = lr_test_hdr(r);
    assert_same_image(got, want, "async vs renderer");
    free(got);
    free(want);
    lr_renderer_destroy(r);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

/* A material change starts a grid solve on the worker; a dimmer change right after it is a
 * blend of the images already published (the old material at the new level: exactly half the
 * old image for half the intensity), at the caller's next frame, while the solve runs. Then
 * the new material's image arrives and is a different image. */
static void test_dimmer_does_not_wait_for_a_solve(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_async *a = make(f->gl, s, false);
    wait_final(a, 0);
    lr_async_frame_stats st;
    float *before = frame_hdr(a, &st);

    unsigned dirty = 0;
    set(s, "objects[0].material", "marble", &dirty);
    uint64_t b = lr_async_commit(a, dirty);
    assert_true(b > 0);
    double I0 = lr_scene_light_at(s, 0)->intensity;
    char half[64];
    snprintf(half, sizeof half, "%.17g", 0.5 * I0);
    dirty = 0;
    set(s, "lights[0].intensity", half, &dirty);
    assert_int_equal(lr_async_commit(a, dirty), 0); /* the blend's alone */
    assert_true(lr_async_needs_frame(a));
    /* The worker must still be solving for this to test anything: a grid solve of the candle
     * takes ~0.5 s in an optimised build and far longer under the sanitizers. */
    assert_true(lr_async_busy(a));
    float *dim = frame_hdr(a, &st);
    assert_true(st.batch < b);
    size_t n = (size_t)W * H * 3;
    double peak = max_abs(before, n), worst = 0;
    for (size_t i = 0; i < n; i++)
        worst = fmax(worst, fabs((double)dim[i] - 0.5 * before[i]));
    printf("dimmer during a solve: worst |dim - before/2| %.3g of peak %.3g\n", worst, peak);
    assert_true(worst <= 1e-5 * peak);

    wait_final(a, b);
    float *after = frame_hdr(a, &st);
    assert_true(st.batch >= b);
    assert_int_equal(st.stage, LR_ASYNC_FINAL);
    double diff = 0;
    for (size_t i = 0; i < n; i++)
        diff = fmax(diff, fabs((double)after[i] - dim[i]));
    assert_true(diff > 1e-3 * peak); /* marble is not candle wax */
    free(before);
    free(dim);
    free(after);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

/* The preview stage: once at start and once per change that re-runs the maps (a material),
 * none for a camera move (composition alone: a preview would cost a full re-run) nor for a
 * dimmer. Without preview_always, a preview as dear as the full frame (the grid's solve
 * dominates both) is skipped after the first. */
static void test_preview_once_per_heavy_change(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_async *a = make(f->gl, s, true);
    wait_final(a, 0);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_PREVIEW), 1);
    unsigned dirty = 0;
    set(s, "objects[0].material", "marble", &dirty);
    uint64_t b = lr_async_commit(a, dirty);
    wait_final(a, b);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_PREVIEW), 2);
    uint64_t finals = lr_async_publications(a, LR_ASYNC_FINAL);
    dirty = 0;
    set(s, "camera.position", "0,-420,160", &dirty);
    b = lr_async_commit(a, dirty);
    assert_true(b > 0);
    wait_final(a, b);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_PREVIEW), 2);
    assert_true(lr_async_publications(a, LR_ASYNC_FINAL) > finals);
    dirty = 0;
    set(s, "lights[0].intensity", "0.5", &dirty);
    assert_int_equal(lr_async_commit(a, dirty), 0);
    wait_final(a, b);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_PREVIEW), 2);
    lr_async_destroy(a);

    /* A "preview" at the scene's own settings costs what the full frame costs (the same
     * passes, the same solve): after the first it is skipped. */
    lr_async_desc d = {.gl = f->gl, .scene = s, .width = W, .height = H,
                       .preview = {"render.N=4", "render.frames=1"}, .n_preview = 2};
    lr_err e = {0};
    assert_int_equal(lr_async_create(&d, &a, &e), LR_OK);
    wait_final(a, 0);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_PREVIEW), 1);
    dirty = 0;
    set(s, "objects[0].material", "candle_wax", &dirty);
    b = lr_async_commit(a, dirty);
    wait_final(a, b);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_PREVIEW), 1);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

/* The preview stage at preview_scale 0.5 is drawn by a renderer of its own at half the view's
 * width and height and shown scaled up by the nearest texel: the first image shown is a fresh
 * half-size renderer's image of the scene at the preview's assignments, each of its pixels
 * covering 2 x 2 of the view's (to the same 1e-5 of the peak: the same sums). The full frame
 * after it (a grid solve, a fraction of a second) is what the test races: when it was shown
 * first, the test tries again with a new worker. */
static void test_preview_at_scale(void **state)
{
    fixture *f = *state;
    static const char *const pv[][2] = {{"render.K", "1"}, {"render.N", "1"},
                                        {"render.map_size", "16"}, {"render.frames", "1"},
                                        {"objects[0].model", "directional_dipole"}};
    enum { NPV = sizeof pv / sizeof pv[0] };
    char sets[NPV][64];
    for (int attempt = 0; attempt < 5; attempt++) {
        lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
        lr_async_desc d = {.gl = f->gl, .scene = s, .width = W, .height = H, .n_preview = NPV,
                           .preview_always = true, .preview_scale = 0.5};
        for (int i = 0; i < NPV; i++) {
            snprintf(sets[i], sizeof sets[i], "%s=%s", pv[i][0], pv[i][1]);
            d.preview[i] = sets[i];
        }
        lr_async *a = NULL;
        lr_err e = {0};
        if (lr_async_create(&d, &a, &e))
            fail_msg("lr_async_create: %s", e.msg);
        if (lr_async_wait(a, 0, false, WAIT_MS, &e))
            fail_msg("lr_async_wait: %s", e.msg);
        /* The publication is taken once its fence has signalled: a few frames. */
        lr_async_frame_stats st = {0};
        for (int i = 0; i < WAIT_MS / 5 && st.stage == LR_ASYNC_NONE; i++) {
            if (lr_async_frame(a, &st, &e))
                fail_msg("lr_async_frame: %s", e.msg);
            struct timespec ts = {0, 5 * 1000 * 1000};
            if (st.stage == LR_ASYNC_NONE)
                nanosleep(&ts, NULL);
        }
        float *got = malloc((size_t)W * H * 3 * sizeof *got);
        assert_non_null(got);
        if (lr_async_read_hdr(a, got, &e))
            fail_msg("lr_async_read_hdr: %s", e.msg);
        lr_async_destroy(a);
        if (st.stage != LR_ASYNC_PREVIEW) {
            print_message("attempt %d: the first image shown was %s\n", attempt,
                          lr_async_stage_name(st.stage));
            free(got);
            lr_scene_destroy(s);
            continue;
        }
        unsigned dirty = 0;
        for (int i = 0; i < NPV; i++)
            set(s, pv[i][0], pv[i][1], &dirty);
        lr_renderer_desc rd = {.gl = f->gl, .scene = s, .width = W / 2, .height = H / 2};
        lr_renderer *r = lr_test_renderer_desc(&rd);
        lr_test_converge(r, 1);
        float *half = lr_test_hdr(r);
        float *want = malloc((size_t)W * H * 3 * sizeof *want);
        assert_non_null(want);
        for (int y = 0; y < H; y++)
            for (int x = 0; x < W; x++)
                for (int b = 0; b < 3; b++)
                    want[((size_t)y * W + x) * 3 + b] =
                        half[((size_t)(y / 2) * (W / 2) + x / 2) * 3 + b];
        assert_same_image(got, want, "half-size preview vs a half-size renderer, scaled up");
        free(half);
        free(want);
        free(got);
        lr_renderer_destroy(r);
        lr_scene_destroy(s);
        return;
    }
    fail_msg("the preview was never the first image shown in 5 tries");
}

/* Polls until the worker runs a full frame that a batch would cut (it takes a batch within
 * milliseconds of its commit; the hang guard only bounds a broken worker). */
static void wait_cuttable(lr_async *a)
{
    for (int i = 0; i < WAIT_MS / 5 && !lr_async_cuttable(a); i++) {
        struct timespec ts = {0, 5 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    assert_true(lr_async_cuttable(a));
}

/* The image of `s` as a fresh renderer on the caller's thread draws it. */
static float *fresh_image(lr_gl *gl, lr_scene *s)
{
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 1);
    lr_test_converge(r, 50);
    float *px = lr_test_hdr(r);
    lr_renderer_destroy(r);
    return px;
}

/* A long solve does not delay the next change: a material change's grid solve (a fraction of
 * a second, hundreds of the cut's polls) is under way when a second material change arrives;
 * the worker cuts the stale solve at its next poll and solves the new state. So the
 * stale state is never published (one final image for the two batches, none of the first),
 * one frame was cut, and the image is the new state's as a fresh renderer draws it: the cut
 * solve left nothing behind. The cut solve's partial iterate is the next solve's warm start
 * and the fresh renderer starts cold; both solve to the grid's relative residual 1e-5
 * (render/diffusion/dscene.c), and the surface field is linear in the fluence, so the images
 * agree to about that: the same 1e-5 of the peak as above (measured: 3e-13). Without the cut the stale state is solved and
 * published first (two finals, no cut frame). */
static void test_newer_change_cuts_a_stale_solve(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_async *a = make(f->gl, s, false);
    wait_final(a, 0);
    uint64_t finals = lr_async_publications(a, LR_ASYNC_FINAL);
    assert_int_equal(lr_async_cancelled(a), 0);

    unsigned dirty = 0;
    set(s, "objects[0].material", "skin1", &dirty);
    uint64_t b1 = lr_async_commit(a, dirty);
    wait_cuttable(a);
    dirty = 0;
    set(s, "objects[0].material", "marble", &dirty);
    uint64_t b2 = lr_async_commit(a, dirty);
    assert_true(b2 > b1);
    wait_final(a, b2);
    printf("cut frames %llu, finals %llu\n", (unsigned long long)lr_async_cancelled(a),
           (unsigned long long)(lr_async_publications(a, LR_ASYNC_FINAL) - finals));
    assert_int_equal(lr_async_cancelled(a), 1);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_FINAL), finals + 1);
    lr_async_frame_stats st;
    float *got = frame_hdr(a, &st);
    assert_int_equal(st.batch, b2);
    assert_int_equal(st.stage, LR_ASYNC_FINAL);
    float *want = fresh_image(f->gl, s);
    assert_same_image(got, want, "after a cut vs a fresh renderer");
    free(got);
    free(want);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

/* A stop (a scene switch retiring the worker, or exit) cuts the frame under way instead of
 * waiting for its solve: the worker exits with that frame cut and nothing of its state
 * published. */
static void test_stop_cuts_the_frame(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_async *a = make(f->gl, s, false);
    wait_final(a, 0);
    uint64_t published = lr_async_publications(a, LR_ASYNC_FINAL) +
                         lr_async_publications(a, LR_ASYNC_REFINING);
    unsigned dirty = 0;
    set(s, "objects[0].material", "skin1", &dirty);
    assert_true(lr_async_commit(a, dirty) > 0);
    wait_cuttable(a);
    lr_async_stop(a);
    for (int i = 0; i < WAIT_MS / 5 && !lr_async_stopped(a); i++) {
        struct timespec ts = {0, 5 * 1000 * 1000};
        nanosleep(&ts, NULL);
    }
    assert_true(lr_async_stopped(a));
    assert_int_equal(lr_async_cancelled(a), 1);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_FINAL) +
                         lr_async_publications(a, LR_ASYNC_REFINING),
                     published);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

/* A bad preview assignment is refused at create, naming it. */
static void test_bad_preview_refused(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_async_desc d = {.gl = f->gl, .scene = s, .width = W, .height = H,
                       .preview = {"render.nonsense=1"}, .n_preview = 1};
    lr_async *a = NULL;
    lr_err e = {0};
    assert_int_not_equal(lr_async_create(&d, &a, &e), LR_OK);
    assert_null(a);
    assert_non_null(strstr(e.msg, "nonsense"));
    d.preview[0] = "render.K";
    assert_int_not_equal(lr_async_create(&d, &a, &e), LR_OK);
    assert_non_null(strstr(e.msg, "key=value"));
    lr_scene_destroy(s);
}

/* The copy is deep: changing or destroying the original leaves it whole (ASan sees any
 * shared mesh), and it reads back every value the original had. */
static void test_clone_is_independent(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, NULL);
    lr_scene *c = NULL;
    lr_err e = {0};
    assert_int_equal(lr_scene_clone(s, NULL, &c, &e), LR_OK);
    const char *keys[] = {"objects[0].material", "objects[0].material.scale", "render.K",
                          "lights[0].position", "camera.position", "receivers[0].albedo"};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        char a[256], b[256];
        assert_int_equal(lr_scene_get(s, keys[i], a, sizeof a, &e), LR_OK);
        assert_int_equal(lr_scene_get(c, keys[i], b, sizeof b, &e), LR_OK);
        assert_string_equal(a, b);
    }
    size_t tris = lr_mesh_triangle_count(lr_scene_object_at(s, 0)->mesh);
    set(s, "objects[0].material", "marble", NULL);
    set(s, "objects[0].mesh.radius", "40", NULL);
    char v[256];
    assert_int_equal(lr_scene_get(c, "objects[0].material", v, sizeof v, &e), LR_OK);
    assert_string_not_equal(v, "marble");
    lr_scene_destroy(s);
    const lr_scene_object *o = lr_scene_object_at(c, 0);
    assert_int_equal(lr_mesh_triangle_count(o->mesh), tris);
    assert_ptr_equal(lr_bvh_mesh(o->bvh), o->mesh);
    set(c, "lights[0].intensity", "2", NULL);
    lr_scene_destroy(c);
}

/* The rig previews an object whose model solves on the CPU with a profile model the planner
 * allows, and leaves an object whose model needs no solve as it is. */
static void test_preview_model(void **state)
{
    (void)state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    const char *m = lr_plan_preview_model(lr_scene_object_at(s, 0));
    assert_non_null(m);
    assert_string_equal(m, "directional_dipole");
    set(s, "objects[0].model", "translucent_radiosity", NULL);
    assert_non_null(lr_plan_preview_model(lr_scene_object_at(s, 0)));
    set(s, "objects[0].model", "standard_dipole", NULL);
    assert_null(lr_plan_preview_model(lr_scene_object_at(s, 0)));
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_clone_is_independent),
        cmocka_unit_test(test_bad_preview_refused),
        cmocka_unit_test(test_preview_model),
        cmocka_unit_test(test_final_is_the_renderers_image),
        cmocka_unit_test(test_dimmer_does_not_wait_for_a_solve),
        cmocka_unit_test(test_preview_once_per_heavy_change),
        cmocka_unit_test(test_preview_at_scale),
        cmocka_unit_test(test_newer_change_cuts_a_stale_solve),
        cmocka_unit_test(test_stop_cuts_the_frame),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
