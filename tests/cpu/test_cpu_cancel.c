/* The cancellation token (render/base/cancel.h) in the CPU loops it cuts: a parallel loop
 * starts no chunk once the token is requested (at the loop's level) and says so; without a
 * request (or without a token) every item runs exactly once. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdatomic.h>
#include <stdlib.h>

#include "render/base/cancel.h"
#include "render/base/parallel.h"

#define COUNT 100000L

typedef struct ctx {
    atomic_long ran;
    unsigned char *hit;
    lr_cancel *cancel;
    long cut_at; /* the item that requests the cancel; -1: none */
    enum lr_cancel_level request; /* what it requests (0: stale) */
} ctx;

static void item(void *p, long i)
{
    ctx *c = p;
    c->hit[i]++;
    atomic_fetch_add(&c->ran, 1);
    if (i == c->cut_at)
        lr_cancel_request(c->cancel, c->request ? c->request : LR_CANCEL_STALE);
}

static void run_at(ctx *c, const lr_cancel *token, int threads, enum lr_cancel_level level,
                   bool *all)
{
    c->hit = calloc(COUNT, 1);
    assert_non_null(c->hit);
    atomic_init(&c->ran, 0);
    *all = lr_parallel_for_cancel(COUNT, threads, item, c, token, level);
}

static void run(ctx *c, const lr_cancel *token, int threads, bool *all)
{
    run_at(c, token, threads, LR_CANCEL_STALE, all);
}

static void test_no_request_runs_every_item_once(void **state)
{
    (void)state;
    lr_cancel t;
    lr_cancel_init(&t);
    for (int threads = 1; threads <= 4; threads++) {
        ctx c = {.cancel = &t, .cut_at = -1};
        bool all;
        run(&c, threads % 2 ? &t : NULL, threads, &all);
        assert_true(all);
        assert_int_equal(atomic_load(&c.ran), COUNT);
        for (long i = 0; i < COUNT; i++)
            assert_int_equal(c.hit[i], 1);
        free(c.hit);
    }
}

static void test_request_before_runs_nothing(void **state)
{
    (void)state;
    lr_cancel t;
    lr_cancel_init(&t);
    lr_cancel_request(&t, LR_CANCEL_STALE);
    assert_true(lr_cancel_requested(&t));
    ctx c = {.cancel = &t, .cut_at = -1};
    bool all;
    run(&c, &t, 2, &all);
    assert_false(all);
    assert_int_equal(atomic_load(&c.ran), 0);
    free(c.hit);
    lr_cancel_reset(&t);
    assert_false(lr_cancel_requested(&t));
    assert_false(lr_cancel_requested(NULL));
}

/* A request from inside the loop (as another thread's would land): the chunks under way end
 * (16 items each, LR_CPU_CHUNK), no new one starts, and the call reports the cut. Every item
 * that ran ran once. */
static void test_request_midway_stops_new_chunks(void **state)
{
    (void)state;
    for (int threads = 1; threads <= 3; threads++) {
        lr_cancel t;
        lr_cancel_init(&t);
        ctx c = {.cancel = &t, .cut_at = 1000};
        bool all;
        run(&c, &t, threads, &all);
        assert_false(all);
        long ran = atomic_load(&c.ran);
        assert_true(ran >= 1001 - 16 * threads && ran < COUNT);
        /* At most the chunks the threads held when the request landed, 16 items each. */
        assert_true(ran <= 1001 + 16L * threads * 2);
        for (long i = 0; i < COUNT; i++)
            assert_true(c.hit[i] <= 1);
        free(c.hit);
        lr_err e = {0};
        assert_int_equal(lr_cancel_check(&t, "the loop", &e), LR_ECANCELED);
        assert_string_equal(e.msg, "the loop: cancelled");
    }
}

/* A loop that only a stop may cut (a cache build that outlives the state): a stale request
 * lets every item run; a stop midway cuts it; a stop is never lowered back to stale. */
static void test_levels(void **state)
{
    (void)state;
    lr_cancel t;
    lr_cancel_init(&t);
    ctx c = {.cancel = &t, .cut_at = 1000, .request = LR_CANCEL_STALE};
    bool all;
    run_at(&c, &t, 2, LR_CANCEL_STOP, &all);
    assert_true(all);
    assert_int_equal(atomic_load(&c.ran), COUNT);
    assert_true(lr_cancel_requested(&t));
    assert_false(lr_cancel_at(&t, LR_CANCEL_STOP));
    free(c.hit);
    lr_cancel_reset(&t);
    ctx d = {.cancel = &t, .cut_at = 1000, .request = LR_CANCEL_STOP};
    run_at(&d, &t, 2, LR_CANCEL_STOP, &all);
    assert_false(all);
    assert_true(atomic_load(&d.ran) < COUNT);
    free(d.hit);
    lr_cancel_request(&t, LR_CANCEL_STALE);
    assert_true(lr_cancel_at(&t, LR_CANCEL_STOP));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_no_request_runs_every_item_once),
        cmocka_unit_test(test_request_before_runs_nothing),
        cmocka_unit_test(test_request_midway_stops_new_chunks),
        cmocka_unit_test(test_levels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
