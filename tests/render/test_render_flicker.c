/* Flicker on the renderer's clock (render/renderer.h lr_renderer_set_time): the signal
 * lr_light_flicker_at (three seeded sines at f, 1.618 f, 2.718 f with weights 0.5, 0.3, 0.2,
 * render/scene/light.c) and its use at composition.
 *
 *  - The signal: deterministic for a seed (and another seed gives another flame); its mean over
 *    many periods is 1 within the bound of a sampled sine's mean (below); it stays within
 *    1 +- amplitude and swings over most of it; its spectrum sits at frequency_hz (the largest
 *    bin) and its two partials, with nothing below frequency_hz / 2.
 *  - The renderer: a time with a flickering light re-runs composition alone and keeps
 *    accumulating; the image is the steady image times the factor (one light: transport is
 *    linear in the intensity) to float rounding; the same time gives the same image; no clock
 *    means steady; flicker.amplitude = 0 means steady and a new time asks for no frame.
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

#include "render/renderer.h"
#include "tests/support/gl.h"
#include "tests/support/near.h"
#include "tests/support/render.h"

LR_TEST_GL_FIXTURE(gl) /* tests/support/gl.h: setup(), teardown() */

static const double mult[3] = {1.0, 1.6180339887, 2.7182818285}; /* light.c's partials */
static const double weight[3] = {0.5, 0.3, 0.2};

static lr_light flame(double amplitude, double f, unsigned seed)
{
    lr_light l = {.type = LR_LIGHT_POINT, .intensity = 1.0, .color = {1, 1, 1},
                  .flicker = {.amplitude = amplitude, .frequency_hz = f, .seed = seed}};
    return l;
}

static double factor(const lr_light *l, double t)
{
    double s;
    lr_light_flicker_at(l, t, &s, NULL);
    return s;
}

static void test_signal_deterministic_mean_and_bounds(void **state)
{
    (void)state;
    const double a = 0.08, f = 7.0, dt = 0.01; /* candle.json's flame, sampled at 100 Hz */
    const int n = 10000;                      /* 100 s, 700 periods */
    lr_light l = flame(a, f, 3), same = flame(a, f, 3), other = flame(a, f, 4);
    double sum = 0.0, lo = INFINITY, hi = -INFINITY, diff = 0.0;
    for (int i = 0; i < n; i++) {
        double t = i * dt, s = factor(&l, t);
        assert_true(s == factor(&same, t)); /* deterministic in (seed, t) */
        diff = fmax(diff, fabs(s - factor(&other, t)));
        sum += s;
        lo = fmin(lo, s);
        hi = fmax(hi, s);
    }
    /* Another seed: other phases, another flame. */
    assert_true(diff > 0.5 * a);
    /* Mean. The mean of sin(2 pi f_i t_k + phi), t_k = k dt, over n samples is
     * sin(n x) sin(...) / (n sin x) with x = pi f_i dt, so |mean| <= 1 / (n |sin x|); summed over
     * the partials with their weights, times the amplitude (plus rounding, 1e-12). */
    double bound = 1e-12;
    for (int i = 0; i < 3; i++)
        bound += a * weight[i] / (n * fabs(sin(M_PI * f * mult[i] * dt)));
    print_message("mean factor %.9f, bound %.3g; range [%.4f, %.4f]\n", sum / n, bound, lo, hi);
    assert_near(sum / n, 1.0, bound);
    /* Within 1 +- amplitude (weights sum to 1), and it does swing over most of it. */
    assert_true(lo >= 1.0 - a - 1e-12 && hi <= 1.0 + a + 1e-12);
    assert_true(hi - lo > a);
    /* Steady: amplitude 0 is exactly 1. */
    lr_light steady = flame(0.0, f, 3);
    assert_true(factor(&steady, 1.234) == 1.0);
}

/* Power of x (n samples at dt) at frequency fr, Hann-windowed (Goertzel). */
static double power_at(const double *x, int n, double dt, double fr)
{
    double w = 2.0 * M_PI * fr * dt, c = 2.0 * cos(w), s1 = 0.0, s2 = 0.0;
    for (int k = 0; k < n; k++) {
        double hann = 0.5 - 0.5 * cos(2.0 * M_PI * k / (n - 1));
        double s0 = x[k] * hann + c * s1 - s2;
        s2 = s1;
        s1 = s0;
    }
    return s1 * s1 + s2 * s2 - c * s1 * s2;
}

static void test_signal_spectrum(void **state)
{
    (void)state;
    const double a = 0.08, f = 7.0, dt = 0.01;
    const int n = 4000; /* 40 s: bins of 0.025 Hz up to the 50 Hz Nyquist limit */
    lr_light l = flame(a, f, 3);
    double *x = malloc((size_t)n * sizeof *x);
    assert_non_null(x);
    for (int k = 0; k < n; k++)
        x[k] = factor(&l, k * dt) - 1.0;
    /* Every bin from 0.1 Hz to 49.9 Hz. */
    double df = 1.0 / (n * dt), total = 0.0, low = 0.0, near_partials = 0.0, peak = 0.0;
    double peak_f = 0.0;
    for (double fr = 4 * df; fr < 0.5 / dt - 4 * df; fr += df) {
        double p = power_at(x, n, dt, fr);
        total += p;
        if (fr < 0.5 * f)
            low += p;
        for (int i = 0; i < 3; i++)
            if (fabs(fr - f * mult[i]) <= 0.25)
                near_partials += p;
        if (p > peak) {
            peak = p;
            peak_f = fr;
        }
    }
    print_message("spectrum: peak at %.3f Hz (frequency_hz %.1f), %.4f of the power within "
                  "0.25 Hz of the partials, %.2g below f/2\n", peak_f, f, near_partials / total,
                  low / total);
    /* The dominant partial (weight 0.5) is the largest bin, to one Hann main lobe (2 bins). */
    assert_true(fabs(peak_f - f) <= 2.0 * df);
    /* Band-limited around frequency_hz: the Hann window's leakage beyond 10 bins is below
     * 1e-4 of a line's power, so >= 99 % sits at the partials and < 0.1 % below f / 2. */
    assert_true(near_partials >= 0.99 * total);
    assert_true(low < 1e-3 * total);
    free(x);
}

/* The candle with the small test settings and its flame flickering. */
static lr_scene *candle(void)
{
    static const char *const amp[] = {"lights[0].flicker.amplitude=0.3", NULL};
    return lr_test_scene("candle", lr_test_small_settings, amp);
}

enum { W = 40, H = 30 };

static void assert_scaled(const float *got, const float *ref, double f)
{
    double mx = 0.0;
    for (int i = 0; i < W * H * 3; i++)
        mx = fmax(mx, ref[i]);
    assert_true(mx > 0.0);
    for (int i = 0; i < W * H * 3; i++) {
        /* Composition computes I f B / pi in float: a few roundings, 1e-5 relative. */
        double want = f * ref[i];
        if (!(fabs(got[i] - want) <= 1e-5 * want + 1e-7 * mx))
            fail_msg("value %d: %.9g, expected %.6f x %.9g", i, got[i], f, ref[i]);
    }
}

static void test_renderer_applies_flicker_at_composition(void **state)
{
    (void)state;
    lr_scene *s = candle();
    lr_renderer *r = lr_test_renderer(gl, s, W, H, false, 5);
    const lr_light *l = lr_scene_light_at(s, 0);
    /* No clock: steady. */
    assert_true(lr_renderer_flicker(r, 0) == 1.0);
    lr_frame_stats st = lr_test_frame(r);
    assert_int_equal(st.samples, 1);
    /* A clock during accumulation: the next frame still accumulates (no restart). */
    lr_renderer_set_time(r, 0.05);
    st = lr_test_frame(r);
    assert_int_equal(st.samples, 2);
    assert_true(st.converged);
    assert_false(lr_renderer_needs_frame(r));
    float *h1 = lr_test_hdr(r);
    double f1 = lr_renderer_flicker(r, 0);
    assert_true(f1 == factor(l, 0.05));

    /* Further times: composition alone, the image scaled by the factor's ratio. */
    const double times[] = {0.1, 0.37, 1.9, 12.25};
    double seen_lo = INFINITY, seen_hi = -INFINITY;
    for (size_t i = 0; i < sizeof times / sizeof times[0]; i++) {
        lr_renderer_set_time(r, times[i]);
        assert_true(lr_renderer_needs_frame(r));
        st = lr_test_frame(r);
        assert_int_equal(st.passes, LR_PASS_BLEND);
        assert_int_equal(st.samples, 2);
        assert_near(st.time_s, times[i], 0.0);
        double f = lr_renderer_flicker(r, 0);
        assert_true(f == factor(l, times[i]));
        seen_lo = fmin(seen_lo, f);
        seen_hi = fmax(seen_hi, f);
        float *h = lr_test_hdr(r);
        assert_scaled(h, h1, f / f1);
        free(h);
        /* The same time again: nothing to do. */
        lr_renderer_set_time(r, times[i]);
        assert_false(lr_renderer_needs_frame(r));
    }
    assert_true(seen_hi - seen_lo > 0.05); /* the frames did differ */
    /* Back to 0.05: the very same image (deterministic). */
    lr_renderer_set_time(r, 0.05);
    lr_test_frame(r);
    float *again = lr_test_hdr(r);
    assert_memory_equal(again, h1, (size_t)W * H * 3 * sizeof *again);
    free(again);

    /* flicker.amplitude = 0: steady (factor 1, composition only), and a clock change asks
     * for no frame. */
    lr_test_set(s, r, "lights[0].flicker.amplitude", "0");
    st = lr_test_frame(r);
    assert_int_equal(st.passes, LR_PASS_BLEND);
    assert_true(lr_renderer_flicker(r, 0) == 1.0);
    float *steady = lr_test_hdr(r);
    assert_scaled(steady, h1, 1.0 / f1);
    lr_renderer_set_time(r, 3.0);
    assert_false(lr_renderer_needs_frame(r));
    free(steady);
    free(h1);
    lr_renderer_destroy(r);
    lr_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_signal_deterministic_mean_and_bounds),
        cmocka_unit_test(test_signal_spectrum),
        cmocka_unit_test(test_renderer_applies_flicker_at_composition),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
