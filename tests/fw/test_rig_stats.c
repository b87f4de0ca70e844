/* The rig's run statistics (firmware/rig/stats.h) and their latency histogram
 * (firmware/rig/lat_hist.h): quantiles against the exact ones of known samples, within the
 * bound the 1 % buckets give (√1.01 − 1 relative); n, min, max, mean exact; the stats file's
 * latency fields; memory that stays put over 10^6 events (it grew by 8 bytes an event, plus a
 * sorted copy at each write). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/rig/lat_hist.h"
#include "firmware/rig/stats.h"
#include "render/base/json.h"
#include "tests/support/fs.h"
#include "tests/support/near.h"
#include "tests/support/proc.h"

/* A fixed-seed generator: the samples are the same at every run. */
static double uniform(uint64_t *st)
{
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    return ((double)(*st >> 11) + 0.5) * 0x1p-53;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The stats' definition: linear interpolation between the order statistics around q(n−1). */
static double exact_quantile(const double *sorted, size_t n, double q)
{
    double pos = q * (double)(n - 1);
    size_t i = (size_t)floor(pos);
    if (i + 1 >= n)
        return sorted[n - 1];
    double f = pos - (double)i;
    return sorted[i] * (1 - f) + sorted[i + 1] * f;
}

static const double QS[] = {0, 0.001, 0.01, 0.1, 0.25, 0.5, 0.75, 0.9, 0.99, 0.999, 1};

/* Every quantile within the stated bound: δ·x, plus half the lowest bucket (0.005 ms) when the
 * lower of the two interpolated samples is below it; 1e-12 relative for the rounding of the
 * bucket index at a bucket's edge. */
static void check_quantiles(const lr_lat_hist *h, double *v, size_t n)
{
    qsort(v, n, sizeof *v, cmp_double);
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += v[i];
    assert_int_equal(lr_lat_hist_n(h), n);
    assert_true(lr_lat_hist_min(h) == v[0]);
    assert_true(lr_lat_hist_max(h) == v[n - 1]);
    assert_near_rel(lr_lat_hist_mean(h), sum / (double)n, 1e-12);
    double worst = 0;
    for (size_t k = 0; k < sizeof QS / sizeof QS[0]; k++) {
        double x = exact_quantile(v, n, QS[k]), got = lr_lat_hist_quantile(h, QS[k]);
        double tol = LR_LAT_HIST_REL_ERR * x * (1 + 1e-12);
        if (v[(size_t)floor(QS[k] * (double)(n - 1))] < LR_LAT_HIST_LO_MS)
            tol += 0.5 * LR_LAT_HIST_LO_MS;
        else
            worst = fmax(worst, fabs(got - x) / x);
        assert_near(got, x, tol);
    }
    print_message("n %zu: worst relative quantile error %.4f %% (bound %.4f %%)\n", n,
                  100 * worst, 100 * LR_LAT_HIST_REL_ERR);
}

/* Log-uniform over the whole range (0.01 ms .. 100 s) and an exponential of mean 4 ms (the
 * rig's usual latencies, with a few below 0.01 ms). */
static void test_hist_quantiles(void **state)
{
    (void)state;
    const size_t n = 200000;
    double *v = malloc(n * sizeof *v);
    assert_non_null(v);
    for (int dist = 0; dist < 2; dist++) {
        lr_lat_hist *h = lr_lat_hist_create();
        assert_non_null(h);
        uint64_t st = 42 + (uint64_t)dist;
        for (size_t i = 0; i < n; i++) {
            double u = uniform(&st);
            v[i] = dist == 0 ? LR_LAT_HIST_LO_MS * pow(LR_LAT_HIST_HI_MS / LR_LAT_HIST_LO_MS, u)
                             : -4.0 * log(u);
            lr_lat_hist_add(h, v[i]);
        }
        check_quantiles(h, v, n);
        lr_lat_hist_destroy(h);
    }
    free(v);
}

/* Few samples, far apart: the interpolation between two buckets, each within its bound; one
 * sample: every quantile is it, exactly (clamped to min = max). Negative and NaN not counted. */
static void test_hist_small(void **state)
{
    (void)state;
    lr_lat_hist *h = lr_lat_hist_create();
    assert_non_null(h);
    assert_true(isnan(lr_lat_hist_quantile(h, 0.5)));
    assert_true(isnan(lr_lat_hist_mean(h)));
    lr_lat_hist_add(h, 3.7);
    lr_lat_hist_add(h, -1);
    lr_lat_hist_add(h, NAN);
    assert_int_equal(lr_lat_hist_n(h), 1);
    assert_true(lr_lat_hist_quantile(h, 0.5) == 3.7);
    assert_true(lr_lat_hist_quantile(h, 0.99) == 3.7);
    double v[] = {3.7, 1.0, 250.0, 0.0, 2e5};
    for (size_t i = 1; i < 5; i++)
        lr_lat_hist_add(h, v[i]);
    /* 2e5 ms is above the range: the top quantile is the maximum, exactly. */
    assert_true(lr_lat_hist_quantile(h, 1) == 2e5);
    double s[] = {0.0, 1.0, 3.7, 250.0};
    lr_lat_hist *h2 = lr_lat_hist_create();
    for (size_t i = 0; i < 4; i++)
        lr_lat_hist_add(h2, s[i]);
    check_quantiles(h2, s, 4);
    lr_lat_hist_destroy(h2);
    lr_lat_hist_destroy(h);
}

static lr_frame_stats pass_frame(int index)
{
    lr_frame_stats f = {.index = index, .passes = 1u, .total_ms = 1, .samples = 1};
    return f;
}

/* Events through the stats: latency = frame end − event stamp; the file's latency_ms fields
 * (n, min, median, p99, max, mean) against the exact values of the same latencies. */
static void test_stats_latency_fields(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_rig_stats *s;
    assert_int_equal(lr_rig_stats_create(0, &s, &e), LR_OK);
    enum { N = 5000 };
    static double lat[N];
    uint64_t st = 7;
    int64_t t = 1000000;
    for (int i = 0; i < N; i++) {
        lr_event ev;
        int64_t d = 10000 + (int64_t)(uniform(&st) * 50e6); /* 0.01 .. 50 ms */
        lr_event_set(&ev, "sim", "knob1", LR_EV_DELTA, 1, t);
        lr_rig_stats_event(s, &ev);
        lr_frame_stats f = pass_frame(i);
        lr_rig_stats_frame(s, &f, t + d);
        lat[i] = (double)d * 1e-6;
        t += d + 1000;
    }
    assert_int_equal(lr_rig_stats_events(s), N);
    char *dir = lr_test_tmpdir();
    char *path = lr_test_path(dir, "stats.json");
    assert_int_equal(lr_rig_stats_write(s, path, NULL, t, 0, NULL, 0, &e), LR_OK);
    lr_json *j;
    assert_int_equal(lr_json_load(path, &j, &e), LR_OK);
    lr_jnode l = lr_json_get(j, lr_json_root(j), "latency_ms");
    long n = 0;
    double min, med, p99, max, mean;
    assert_int_equal(lr_json_get_int(j, l, "n", true, &n, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, l, "min", true, &min, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, l, "median", true, &med, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, l, "p99", true, &p99, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, l, "max", true, &max, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, l, "mean", true, &mean, &e), LR_OK);
    assert_int_equal(lr_json_count(j, lr_json_get(j, lr_json_root(j), "event_log")), 4096);
    lr_json_destroy(j);
    double sum = 0;
    for (int i = 0; i < N; i++)
        sum += lat[i];
    qsort(lat, N, sizeof lat[0], cmp_double);
    assert_int_equal(n, N);
    /* The JSON writer's %.17g round trip is exact; mean within summation rounding. */
    assert_near_rel(min, lat[0], 1e-12);
    assert_near_rel(max, lat[N - 1], 1e-12);
    assert_near_rel(mean, sum / N, 1e-12);
    assert_near_rel(med, exact_quantile(lat, N, 0.5), LR_LAT_HIST_REL_ERR * (1 + 1e-9));
    assert_near_rel(p99, exact_quantile(lat, N, 0.99), LR_LAT_HIST_REL_ERR * (1 + 1e-9));
    assert_near_rel(lr_rig_stats_latency_ms(s, 0.9), exact_quantile(lat, N, 0.9),
                    LR_LAT_HIST_REL_ERR * (1 + 1e-9));
    lr_rig_stats_destroy(s);
    lr_test_rmtree(dir);
    free(path);
}

/* settle_ms and "rested" (stats.h): a transport batch (events at 0 and 100 ms, batch 1 and 2)
 * refined, a dimmer event at 300 ms taking batch 0 (blend-only, applied with batch 2's images),
 * converged at 1300 ms: every event there converges, only the newest, the dimmer, rested, with
 * 1000 ms; a later press converged in the same frame that first shows it rests with its
 * latency. The earlier events' converge_ms run from their own times. */
static void test_stats_settle(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_rig_stats *s;
    assert_int_equal(lr_rig_stats_create(0, &s, &e), LR_OK);
    const int64_t ms = 1000000;
    lr_event ev;
    lr_event_set(&ev, "sim", "button1", LR_EV_PRESS, 1, 0);
    lr_rig_stats_event(s, &ev);
    lr_rig_stats_tag(s, 1);
    lr_event_set(&ev, "sim", "knob2", LR_EV_DELTA, 1, 100 * ms);
    lr_rig_stats_event(s, &ev);
    lr_rig_stats_tag(s, 2);
    lr_frame_stats f = pass_frame(0);
    lr_rig_stats_frame_shown(s, &f, &(lr_rig_frame_info){2, LR_ASYNC_PREVIEW, false}, 200 * ms);
    lr_event_set(&ev, "sim", "dimmer", LR_EV_ABSOLUTE, 0.5, 300 * ms);
    lr_rig_stats_event(s, &ev);
    lr_rig_stats_tag(s, 0);
    f = pass_frame(1);
    lr_rig_stats_frame_shown(s, &f, &(lr_rig_frame_info){2, LR_ASYNC_REFINING, false}, 600 * ms);
    f = pass_frame(2);
    lr_rig_stats_frame_shown(s, &f, &(lr_rig_frame_info){2, LR_ASYNC_FINAL, true}, 1300 * ms);
    lr_event_set(&ev, "sim", "button1", LR_EV_PRESS, 1, 2000 * ms);
    lr_rig_stats_event(s, &ev);
    lr_rig_stats_tag(s, 3);
    f = pass_frame(3);
    lr_rig_stats_frame_shown(s, &f, &(lr_rig_frame_info){3, LR_ASYNC_CACHED, true}, 2030 * ms);
    assert_near(lr_rig_stats_settle_ms(s, 0.0), 30.0, 30.0 * LR_LAT_HIST_REL_ERR);
    assert_near(lr_rig_stats_settle_ms(s, 1.0), 1000.0, 1000.0 * LR_LAT_HIST_REL_ERR);
    assert_near(lr_rig_stats_converge_ms(s, 1.0), 1300.0, 1300.0 * LR_LAT_HIST_REL_ERR);

    char *dir = lr_test_tmpdir();
    char *path = lr_test_path(dir, "stats.json");
    assert_int_equal(lr_rig_stats_write(s, path, NULL, 2100 * ms, 0, NULL, 0, &e), LR_OK);
    lr_json *j;
    assert_int_equal(lr_json_load(path, &j, &e), LR_OK);
    lr_jnode root = lr_json_root(j), log = lr_json_get(j, root, "event_log");
    long n = 0;
    assert_int_equal(lr_json_get_int(j, lr_json_get(j, root, "settle_ms"), "n", true, &n, &e),
                     LR_OK);
    assert_int_equal(n, 2);
    assert_int_equal(lr_json_count(j, log), 4);
    static const char *const control[] = {"button1", "knob2", "dimmer", "button1"};
    static const bool rested[] = {false, false, true, true};
    static const double conv[] = {1300, 1200, 1000, 30};
    for (int i = 0; i < 4; i++) {
        lr_jnode x = lr_json_at(j, log, i);
        char name[32];
        bool r;
        double c;
        assert_int_equal(lr_json_get_string(j, x, "control", true, name, sizeof name, &e), LR_OK);
        assert_string_equal(name, control[i]);
        assert_int_equal(lr_json_get_bool(j, x, "rested", true, &r, &e), LR_OK);
        assert_int_equal(r, rested[i]);
        assert_int_equal(lr_json_get_number(j, x, "converge_ms", true, &c, &e), LR_OK);
        assert_near(c, conv[i], 1e-9);
    }
    lr_json_destroy(j);
    lr_rig_stats_destroy(s);
    lr_test_rmtree(dir);
    free(path);
}

/* 10^6 events (a knob spun for days), a stats write every 10^5: the resident size after a
 * warm-up that fills the two logs (4096 events, 4096 frames) and writes once stays within
 * 1 MiB, the slack of the allocator (the JSON writer's buffers, ASan's quarantine of them).
 * What grew: 8 bytes per latency kept (8 MiB for 10^6, realloc doubling) and, at each write,
 * a sorted copy of them. */
static void test_stats_memory_constant(void **state)
{
    (void)state;
    lr_err e = {0};
    lr_rig_stats *s;
    assert_int_equal(lr_rig_stats_create(0, &s, &e), LR_OK);
    char *dir = lr_test_tmpdir();
    char *path = lr_test_path(dir, "stats.json");
    int64_t t = 0;
    int frame = 0;
    for (int i = 0; i < 10000; i++, t += 1000000) {
        lr_event ev;
        lr_event_set(&ev, "sim", "knob1", LR_EV_DELTA, 1, t);
        lr_rig_stats_event(s, &ev);
        lr_frame_stats f = pass_frame(frame++);
        lr_rig_stats_frame(s, &f, t + 2000000 + (i % 97) * 10000);
    }
    assert_int_equal(lr_rig_stats_write(s, path, "c.json", t, 0, NULL, 0, &e), LR_OK);
    long rss0 = lr_test_rss_kib(0);
    assert_true(rss0 > 0);
    for (int i = 0; i < 1000000; i++, t += 1000000) {
        lr_event ev;
        lr_event_set(&ev, "sim", "knob1", LR_EV_DELTA, 1, t);
        lr_rig_stats_event(s, &ev);
        lr_frame_stats f = pass_frame(frame++);
        lr_rig_stats_frame(s, &f, t + 2000000 + (i % 97) * 10000);
        if (i % 100000 == 99999)
            assert_int_equal(lr_rig_stats_write(s, path, "c.json", t, 0, NULL, 0, &e), LR_OK);
    }
    long rss1 = lr_test_rss_kib(0);
    print_message("VmRSS %ld KiB after warm-up, %ld KiB after 10^6 more events (%+ld)\n", rss0,
                  rss1, rss1 - rss0);
    assert_int_equal(lr_rig_stats_events(s), 1010000);
    assert_true(rss1 - rss0 <= 1024);
    lr_rig_stats_destroy(s);
    lr_test_rmtree(dir);
    free(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hist_quantiles),
        cmocka_unit_test(test_hist_small),
        cmocka_unit_test(test_stats_latency_fields),
        cmocka_unit_test(test_stats_settle),
        cmocka_unit_test(test_stats_memory_constant),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
