/* The control-space cache (render/async/cache.h, lr_async_anticipate): its lookup's per-band
 * weights, a cached state shown at the commit that asks for it and equal to the renderer's
 * own image of that state, an interpolated state within the bound of linear interpolation
 * and replaced by the exact one when it converges, the budget, and the flush on a change
 * outside the cache's keys. */
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
#include "render/async/cache.h"
#include "render/renderer.h"
#include "tests/support/gl.h"
#include "tests/support/render.h"

#define W 40
#define H 30
#define NPX ((size_t)W * H * 3)
#define WAIT_MS 600000 /* a hang guard under the sanitizers, not a speed bound */

/* A deterministic model (the diffusion grid: no per-frame sample), so that two renderers
 * reaching the same state draw the same image to float rounding (test_async.c). */
static const char *const grid_sets[] = {"objects[0].model=diffusion_grid", "objects[0].dgrid_h_mm=8",
                                        "lights[0].flicker.amplitude=0", NULL};

static const lr_cache_key keys[] = {
    {"objects[0].material.base", LR_CACHE_EXACT},
    {"objects[0].material.scale", LR_CACHE_LINEAR},
    {"objects[0].model", LR_CACHE_EXACT},
};
#define N_KEYS 3

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

static void set(lr_scene *s, const char *key, const char *value, unsigned *dirty)
{
    lr_err e = {0};
    if (lr_scene_set(s, key, value, dirty, &e))
        fail_msg("%s", e.msg);
}

/* ---- the lookup, without GL ---- */

static lr_state_tag tag3(const char *base, const char *scale, const char *model)
{
    lr_state_tag t = {.n = N_KEYS};
    snprintf(t.value[0], sizeof t.value[0], "%s", base);
    snprintf(t.value[1], sizeof t.value[1], "%s", scale);
    snprintf(t.value[2], sizeof t.value[2], "%s", model);
    return t;
}

/* Samples at scale 0.5, 1, 2: a tag of one scale per band takes per band the two samples
 * around its value, weighted by the position between them in ln(scale); an equal tag is exact;
 * a value outside the samples, or another model, misses. */
static void test_lookup_weights(void **state)
{
    (void)state;
    lr_state_cache *c;
    lr_err e = {0};
    assert_int_equal(lr_state_cache_create(keys, N_KEYS, 1000, &c, &e), LR_OK);
    const float one = 1.0f;
    const char *const at[3] = {"0.5", "1", "2"};
    for (int i = 0; i < 3; i++) {
        lr_state_tag t = tag3("candle_wax", at[i], "diffusion_grid");
        /* No textures: the lookup is what is tested (lr_tex_destroy(NULL) is a no-op). */
        assert_true(lr_state_cache_store(c, &t, NULL, 1, &one, 100));
    }
    lr_cache_mix m, m2;
    lr_state_tag t = tag3("candle_wax", "1", "diffusion_grid");
    assert_true(lr_state_cache_find(c, &t, &m));
    assert_true(m.exact);
    assert_int_equal(m.n, 1);

    t = tag3("candle_wax", "0.7,1,1.6", "diffusion_grid");
    assert_true(lr_state_cache_find(c, &t, &m));
    assert_false(m.exact);
    double sum[3] = {0};
    for (int k = 0; k < m.n; k++)
        for (int b = 0; b < 3; b++)
            sum[b] += m.w[k][b];
    for (int b = 0; b < 3; b++)
        assert_float_equal(sum[b], 1.0, 1e-12);
    /* Band 0: 0.7 between 0.5 and 1, t = 0.4 on the sample at 1; band 2: 1.6 between 1 and 2,
     * t = 0.6 on the sample at 2. */
    double t0 = 0.4, t2 = 0.6;
    int found0 = 0, found2 = 0;
    for (int k = 0; k < m.n; k++) {
        if (m.w[k][0] > 0 && fabs(m.w[k][0] - t0) < 1e-9)
            found0++;
        if (m.w[k][2] > 0 && fabs(m.w[k][2] - t2) < 1e-9)
            found2++;
    }
    assert_int_equal(found0, 1);
    assert_int_equal(found2, 1);

    t = tag3("candle_wax", "3", "diffusion_grid");
    assert_false(lr_state_cache_find(c, &t, &m)); /* above the last sample */
    t = tag3("candle_wax", "1.2", "standard_dipole");
    assert_false(lr_state_cache_find(c, &t, &m)); /* another model: nothing to interpolate */

    /* The budget: 1000 bytes hold ten of 100; an 11th evicts the least recently used. */
    for (int i = 0; i < 8; i++) {
        char v[16];
        snprintf(v, sizeof v, "%d", 3 + i);
        lr_state_tag x = tag3("candle_wax", v, "diffusion_grid");
        assert_true(lr_state_cache_store(c, &x, NULL, 1, &one, 100));
    }
    lr_state_cache_stats st;
    lr_state_cache_get_stats(c, &st);
    assert_int_equal(st.entries, 10);
    assert_true(st.bytes <= st.budget);
    assert_int_equal(st.evicted, 1);
    /* The one evicted was the least recently used: "2" (last used by the first
     * interpolation; "0.5" and "1" by the exact hit and the tint's bands after it... both
     * lookups used "1"; the order of the rest is the stores'). */
    t = tag3("candle_wax", "1", "diffusion_grid");
    assert_true(lr_state_cache_holds(c, &t));
    /* A pinned entry survives a flush until unpinned. */
    assert_true(lr_state_cache_find(c, &t, &m));
    lr_state_cache_pin(c, &m);
    lr_state_cache_flush(c);
    lr_state_cache_get_stats(c, &st);
    assert_int_equal(st.entries, 0);     /* nothing to find any more */
    assert_int_equal((long)st.bytes, 100); /* but the pinned one's storage stays */
    assert_false(lr_state_cache_find(c, &t, &m2));
    lr_state_cache_unpin(c, &m);
    lr_state_cache_get_stats(c, &st);
    assert_int_equal((long)st.bytes, 0);
    lr_state_cache_destroy(c);
}

/* ---- through the worker ---- */

static lr_async *make(lr_gl *gl, lr_scene *s, double cache_mb)
{
    lr_async_desc d = {.gl = gl, .scene = s, .width = W, .height = H, .cache_keys = keys,
                       .n_cache_keys = N_KEYS, .cache_mb = cache_mb};
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

/* Waits until the anticipation list is done (the worker builds it when idle). */
static void wait_built(lr_async *a)
{
    struct timespec t0, t;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (;;) {
        lr_state_cache_stats st;
        int pending;
        lr_async_cache_stats(a, &st, &pending);
        if (pending == 0 && !lr_async_busy(a))
            return;
        lr_err e = {0};
        if (lr_async_error(a, &e))
            fail_msg("worker: %s", e.msg);
        clock_gettime(CLOCK_MONOTONIC, &t);
        if ((t.tv_sec - t0.tv_sec) * 1000 > WAIT_MS)
            fail_msg("the states were not built");
        nanosleep(&(struct timespec){0, 5000000}, NULL);
    }
}

static lr_async_state state1(const char *key, const char *value)
{
    lr_async_state s = {.n = 1};
    snprintf(s.key[0], sizeof s.key[0], "%s", key);
    snprintf(s.value[0], sizeof s.value[0], "%s", value);
    return s;
}

static float *frame_hdr(lr_async *a, lr_async_frame_stats *st)
{
    lr_err e = {0};
    if (lr_async_frame(a, st, &e))
        fail_msg("lr_async_frame: %s", e.msg);
    float *px = malloc(NPX * sizeof *px);
    assert_non_null(px);
    if (lr_async_read_hdr(a, px, &e))
        fail_msg("lr_async_read_hdr: %s", e.msg);
    return px;
}

/* The renderer's own converged image of the candle at material scale `scale`, reached from
 * the scene's own state as the worker reaches it (the grid's solve starts from the last
 * solution and stops at a relative residual of 1e-5, render/diffusion/dscene.c: two
 * starting points give images about 1e-4 of the peak apart, so "the same image" needs the
 * same path). */
static float *exact_at(lr_gl *gl, const char *scale)
{
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 1);
    lr_test_converge(r, 50);
    unsigned dirty = 0;
    set(s, "objects[0].material.scale", scale, &dirty);
    lr_renderer_invalidate(r, dirty);
    lr_test_converge(r, 50);
    float *px = lr_test_hdr(r);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
    return px;
}

/* One renderer walked through several states (the interpolation test's references: any
 * path is within the solves' tolerance, which its bound allows for). */
typedef struct walk {
    lr_scene *s;
    lr_renderer *r;
} walk;

static walk walk_make(lr_gl *gl)
{
    walk w = {lr_test_scene("candle", lr_test_small_settings, grid_sets), NULL};
    w.r = lr_test_renderer(gl, w.s, W, H, false, 1);
    return w;
}

static float *walk_at(walk *w, const char *scale)
{
    unsigned dirty = 0;
    set(w->s, "objects[0].material.scale", scale, &dirty);
    lr_renderer_invalidate(w->r, dirty);
    lr_test_converge(w->r, 50);
    return lr_test_hdr(w->r);
}

static void walk_free(walk *w)
{
    lr_renderer_destroy(w->r);
    lr_scene_destroy(w->s);
}

static double peak_of(const float *x)
{
    double m = 0;
    for (size_t i = 0; i < NPX; i++)
        m = fmax(m, fabs(x[i]));
    return m;
}

/* A state built ahead is shown at the commit that asks for it, as LR_ASYNC_CACHED, equal to
 * the renderer's own image of it (1e-5 of the peak: the same passes on the same state, float
 * rounding), and the worker renders nothing for it. */
static void test_cached_state_is_exact(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_async *a = make(f->gl, s, 8);
    wait_final(a, 0);
    lr_async_state w = state1("objects[0].material.scale", "2");
    lr_err e = {0};
    assert_int_equal(lr_async_anticipate(a, &w, 1, &e), LR_OK);
    wait_built(a);
    lr_state_cache_stats cs;
    lr_async_cache_stats(a, &cs, NULL);
    assert_int_equal(cs.entries, 1);
    uint64_t finals = lr_async_publications(a, LR_ASYNC_FINAL);

    unsigned dirty = 0;
    set(s, "objects[0].material.scale", "2", &dirty);
    uint64_t b = lr_async_commit(a, dirty);
    assert_true(b > 0);
    assert_true(lr_async_needs_frame(a));
    lr_async_frame_stats st;
    float *got = frame_hdr(a, &st); /* no wait: the cache answers at once */
    assert_int_equal(st.stage, LR_ASYNC_CACHED);
    assert_int_equal(st.batch, b);
    assert_true(st.new_images);
    float *want = exact_at(f->gl, "2");
    double peak = peak_of(want), worst = 0;
    for (size_t i = 0; i < NPX; i++)
        worst = fmax(worst, fabs((double)got[i] - want[i]));
    printf("cached state vs renderer: worst |diff| %.3g of peak %.3g\n", worst, peak);
    assert_true(peak > 0);
    assert_true(worst <= 1e-5 * peak);

    /* A dimmer turned right after it is the same state: still nothing to render, even when
     * the worker takes both batches together. */
    dirty = 0;
    set(s, "lights[0].intensity", "0.001", &dirty);
    assert_int_equal(lr_async_commit(a, dirty), 0);
    wait_final(a, b);
    free(frame_hdr(a, &st));
    assert_int_equal(st.stage, LR_ASYNC_CACHED);
    assert_int_equal(lr_async_publications(a, LR_ASYNC_FINAL), finals); /* nothing rendered */
    assert_int_equal(lr_async_publications(a, LR_ASYNC_CACHED), 1);
    free(got);
    free(want);

    /* A change outside the keys (the light moves) drops the entries: built on another scene. */
    dirty = 0;
    set(s, "lights[0].position", "0,0,118", &dirty);
    b = lr_async_commit(a, dirty);
    lr_async_cache_stats(a, &cs, NULL);
    assert_int_equal(cs.entries, 0);
    assert_true(cs.flushed >= 1);
    wait_final(a, b);
    free(frame_hdr(a, &st));
    assert_int_equal(st.stage, LR_ASYNC_FINAL);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

/* The images are interpolated geometrically, linearly in s for ln f (render/async/cache.h):
 * the chord errs by at most h^2/8 max|g''| in g = ln f per pixel. Samples at s = 0.5 ... 2.5,
 * h = 0.5, give the second differences D(s) = g(s-h) - 2 g(s) + g(s+h) = h^2 g'' at s = 1,
 * 1.5 and 2, around the intervals [1, 1.5] and [1.5, 2] interpolated in; where g'' is
 * monotone (convex g, smooth in the coefficient) the largest |D|/8 bounds the error in g, so
 * |got - want| <= want (exp(|D|max/8) - 1). Added: 2e-4 of the peak, for the solves' own
 * tolerance (the samples and the exact state are one renderer's walk through them, each
 * converged to a relative residual of 1e-5 from the last: about 1e-4 of the peak from the
 * worker's images of the same states, reached from other ones, exact_at). Pixels dark in a
 * sample (below 1e-6 of the peak: the floor's edge, where ln f is noise) take the floor alone.
 * Both cases: a uniform scale (the translucency knob) and a different scale per band (a
 * tint), from the same samples. Then the exact state replaces the interpolated one once it
 * converges. */
static void test_interpolated_within_bound(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    lr_async *a = make(f->gl, s, 8);
    wait_final(a, 0);
    enum { NS = 5 };
    const char *const at[NS] = {"0.5", "1", "1.5", "2", "2.5"};
    lr_async_state w[NS];
    for (int i = 0; i < NS; i++)
        w[i] = state1("objects[0].material.scale", at[i]);
    lr_err e = {0};
    assert_int_equal(lr_async_anticipate(a, w, NS, &e), LR_OK);
    wait_built(a);
    lr_state_cache_stats cs;
    lr_async_cache_stats(a, &cs, NULL);
    assert_int_equal(cs.entries, NS);
    walk ref = walk_make(f->gl);
    float *fs[NS];
    for (int i = 0; i < NS; i++)
        fs[i] = walk_at(&ref, at[i]);

    const char *const cases[2] = {"1.41421356", "1.1,1.4,1.8"};
    for (int c = 0; c < 2; c++) {
        unsigned dirty = 0;
        set(s, "objects[0].material.scale", cases[c], &dirty);
        uint64_t b = lr_async_commit(a, dirty);
        lr_async_frame_stats st;
        float *got = frame_hdr(a, &st);
        assert_int_equal(st.stage, LR_ASYNC_INTERPOLATED);
        assert_int_equal(st.batch, b);
        float *want = walk_at(&ref, cases[c]);
        double peak = peak_of(want), worst_excess = -INFINITY, rel = 0, rel_bound = 0;
        size_t wi = 0, lit = 0;
        for (size_t i = 0; i < NPX; i++) {
            double dmax = 0;
            bool dark = false;
            for (int k = 1; k + 1 < NS; k++) {
                dark |= fs[k - 1][i] < 1e-6 * peak || fs[k][i] < 1e-6 * peak ||
                        fs[k + 1][i] < 1e-6 * peak;
                if (!dark)
                    dmax = fmax(dmax, fabs(log(fs[k - 1][i]) - 2 * log(fs[k][i]) +
                                           log(fs[k + 1][i])));
            }
            double diff = fabs((double)got[i] - want[i]);
            double bound = (dark ? 0 : want[i] * expm1(dmax / 8)) + 2e-4 * peak;
            if (diff - bound > worst_excess) {
                worst_excess = diff - bound;
                wi = i;
            }
            if (!dark && want[i] > 1e-3 * peak) {
                rel += diff / want[i];
                rel_bound += expm1(dmax / 8);
                lit++;
            }
        }
        printf("interpolated at scale %s: mean relative error %.3g (bound %.3g) over %zu lit "
               "pixels, peak %.3g, worst excess over the per-pixel bound %.3g of the peak\n",
               cases[c], rel / (double)lit, rel_bound / (double)lit, lit, peak,
               worst_excess / peak);
        printf("  worst at pixel %zu band %zu: got %.4g want %.4g\n", wi / 3, wi % 3, got[wi],
               want[wi]);
        assert_true(lit > NPX / 20);
        assert_true(worst_excess <= 0);
        /* The interpolation is not one of the samples: it moved. */
        double moved = 0;
        for (size_t i = 0; i < NPX; i++)
            moved = fmax(moved, fabs((double)got[i] - fs[1][i]));
        assert_true(moved > 1e-2 * peak);

        /* Once the state converges its own image replaces the interpolated one. */
        wait_final(a, b);
        free(got);
        got = frame_hdr(a, &st);
        assert_int_equal(st.stage, LR_ASYNC_FINAL);
        double worst = 0;
        for (size_t i = 0; i < NPX; i++)
            worst = fmax(worst, fabs((double)got[i] - want[i]));
        printf("  exact state after convergence: worst |diff| %.3g of the peak\n", worst / peak);
        /* Another path again (the worker built five states since): the solves' tolerance,
         * measured at 2.4e-4 of the peak; 5e-4 allowed. */
        assert_true(worst <= 5e-4 * peak);
        free(got);
        free(want);
    }
    for (int i = 0; i < NS; i++)
        free(fs[i]);
    walk_free(&ref);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

/* The budget holds two states of this view (one light, W x H RGBA32F: 19200 bytes each):
 * building three evicts one, and the bytes never exceed the budget. */
static void test_budget(void **state)
{
    fixture *f = *state;
    lr_scene *s = lr_test_scene("candle", lr_test_small_settings, grid_sets);
    double mb = 2.5 * W * H * 16 / (1024.0 * 1024.0);
    lr_async *a = make(f->gl, s, mb);
    wait_final(a, 0);
    lr_async_state w[3] = {state1("objects[0].material.scale", "0.5"),
                           state1("objects[0].material.scale", "2"),
                           state1("objects[0].material.scale", "4")};
    lr_err e = {0};
    assert_int_equal(lr_async_anticipate(a, w, 3, &e), LR_OK);
    wait_built(a);
    lr_state_cache_stats cs;
    lr_async_cache_stats(a, &cs, NULL);
    printf("budget %zu bytes: %d entries, %zu bytes, %llu stored, %llu evicted\n", cs.budget,
           cs.entries, cs.bytes, (unsigned long long)cs.stored, (unsigned long long)cs.evicted);
    assert_int_equal(cs.entries, 2);
    assert_int_equal(cs.stored, 3);
    assert_int_equal(cs.evicted, 1);
    assert_true(cs.bytes <= cs.budget);
    /* The state kept last is found; the scene's own is unchanged by the building. */
    unsigned dirty = 0;
    set(s, "objects[0].material.scale", "4", &dirty);
    uint64_t b = lr_async_commit(a, dirty);
    lr_async_frame_stats st;
    free(frame_hdr(a, &st));
    assert_int_equal(st.stage, LR_ASYNC_CACHED);
    assert_int_equal(st.batch, b);
    assert_int_equal(lr_async_anticipate(a, w, LR_ASYNC_MAX_STATES + 1, &e), LR_EINVAL);
    lr_async_destroy(a);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lookup_weights),
        cmocka_unit_test(test_cached_state_is_exact),
        cmocka_unit_test(test_interpolated_within_bound),
        cmocka_unit_test(test_budget),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='test_budget' */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, setup, teardown);
}
