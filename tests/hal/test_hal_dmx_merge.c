/* hal/: merging the sources of a universe (hal/dmx_merge.h) with explicit times: priority,
 * HTP among equals, the E1.31 sequence window, source loss and Stream_Terminated, the
 * max-sources refusal, Art-Net's two sources with HTP/LTP and the 10 s timeout. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "hal/dmx_merge.h"
#include "hal/reply_limit.h"

#define MS 1000000LL
#define S (1000 * MS)

static const uint8_t A[16] = {1}, B[16] = {2}, C[16] = {3};

static lr_dmx_merge_cfg sacn_cfg(int max_sources)
{
    return (lr_dmx_merge_cfg){.max_sources = max_sources, .timeout_ns = 2500 * MS,
                              .mode = LR_DMX_HTP, .check_sequence = true};
}

static int slot(const lr_dmx_merge *m, int i)
{
    const uint8_t *s;
    int n = lr_dmx_merge_get(m, &s);
    return i < n ? s[i] : -1;
}

static void priority_then_htp(void **state)
{
    (void)state;
    lr_dmx_merge m;
    lr_dmx_merge_cfg cfg = sacn_cfg(4);
    lr_dmx_merge_init(&m, &cfg);
    assert_int_equal(lr_dmx_merge_priority(&m), -1);
    const uint8_t *out;
    assert_int_equal(lr_dmx_merge_get(&m, &out), 0);

    uint8_t a[3] = {10, 200, 30}, b[2] = {50, 100}, c[4] = {1, 1, 1, 1};
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 0, a, 3, 0), LR_DMX_TAKEN);
    assert_int_equal(lr_dmx_merge_put(&m, B, 100, 0, b, 2, 0), LR_DMX_TAKEN);
    /* HTP at equal priority, slot by slot; slot 2 only A sent. */
    assert_int_equal(slot(&m, 0), 50);
    assert_int_equal(slot(&m, 1), 200);
    assert_int_equal(slot(&m, 2), 30);
    assert_int_equal(lr_dmx_merge_get(&m, &out), 3);
    /* A higher priority wins outright, even with lower values. */
    assert_int_equal(lr_dmx_merge_put(&m, C, 150, 0, c, 4, 0), LR_DMX_TAKEN);
    assert_int_equal(lr_dmx_merge_priority(&m), 150);
    assert_int_equal(slot(&m, 1), 1);
    assert_int_equal(lr_dmx_merge_get(&m, &out), 4);
    /* C drops its priority below the others: HTP of A and B again. */
    assert_int_equal(lr_dmx_merge_put(&m, C, 99, 1, c, 4, 0), LR_DMX_TAKEN);
    assert_int_equal(slot(&m, 1), 200);
    assert_int_equal(lr_dmx_merge_get(&m, &out), 3);
    /* A universe changing size: A shrinks to 1 slot; slot 2 has no sender left. */
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 1, a, 1, 0), LR_DMX_TAKEN);
    assert_int_equal(lr_dmx_merge_get(&m, &out), 2);
    assert_int_equal(slot(&m, 1), 100);
}

/* E1.31 6.7.2: take when (new - last) as int8 is > 0 or <= -20. */
static void sequence_window(void **state)
{
    (void)state;
    lr_dmx_merge m;
    lr_dmx_merge_cfg cfg = sacn_cfg(2);
    lr_dmx_merge_init(&m, &cfg);
    uint8_t v[1] = {1};
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 250, v, 1, 0), LR_DMX_TAKEN);
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 250, v, 1, 0), LR_DMX_SEQUENCE); /* d = 0 */
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 249, v, 1, 0), LR_DMX_SEQUENCE); /* d = -1 */
    /* Wrap-around: 250 -> 4 is d = +10. */
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 4, v, 1, 0), LR_DMX_TAKEN);
    /* 4 -> 241 is d = -19 (late): dropped; 4 -> 240 is d = -20: a restart, taken. */
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 241, v, 1, 0), LR_DMX_SEQUENCE);
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 240, v, 1, 0), LR_DMX_TAKEN);
    /* 240 -> 112 is d = -128 (as int8): <= -20, taken; 112 -> 239 is d = +127, taken. */
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 112, v, 1, 0), LR_DMX_TAKEN);
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 239, v, 1, 0), LR_DMX_TAKEN);
    /* Sequences are per source: B starts anywhere. */
    assert_int_equal(lr_dmx_merge_put(&m, B, 100, 239, v, 1, 0), LR_DMX_TAKEN);
    /* Without the check (Art-Net) nothing is dropped. */
    cfg.check_sequence = false;
    lr_dmx_merge_init(&m, &cfg);
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 5, v, 1, 0), LR_DMX_TAKEN);
    assert_int_equal(lr_dmx_merge_put(&m, A, 100, 5, v, 1, 0), LR_DMX_TAKEN);
}

static void loss_and_termination(void **state)
{
    (void)state;
    lr_dmx_merge m;
    lr_dmx_merge_cfg cfg = sacn_cfg(2);
    lr_dmx_merge_init(&m, &cfg);
    uint8_t hi[1] = {200}, lo[1] = {40};
    lr_dmx_merge_put(&m, A, 150, 0, hi, 1, 0);
    lr_dmx_merge_put(&m, B, 100, 0, lo, 1, 0);
    assert_int_equal(lr_dmx_merge_next_expiry(&m), 2500 * MS);
    /* B keeps streaming every second; A goes quiet. At 2.499 s A is still there. */
    lr_dmx_merge_put(&m, B, 100, 1, lo, 1, 1 * S);
    lr_dmx_merge_put(&m, B, 100, 2, lo, 1, 2 * S);
    assert_int_equal(lr_dmx_merge_expire(&m, 2499 * MS), 0);
    assert_int_equal(slot(&m, 0), 200);
    /* At 2.5 s A is lost; the lower priority takes over. */
    assert_int_equal(lr_dmx_merge_expire(&m, 2500 * MS), 1);
    assert_int_equal(lr_dmx_merge_count(&m), 1);
    assert_int_equal(slot(&m, 0), 40);
    assert_int_equal(lr_dmx_merge_next_expiry(&m), 2 * S + 2500 * MS);
    /* A third source is refused while two are in (max 2) ... */
    lr_dmx_merge_put(&m, A, 150, 0, hi, 1, 3 * S);
    assert_int_equal(lr_dmx_merge_put(&m, C, 200, 0, hi, 1, 3 * S), LR_DMX_FULL);
    assert_int_equal(lr_dmx_merge_priority(&m), 150);
    /* ... and taken once Stream_Terminated has removed one at once. */
    assert_true(lr_dmx_merge_terminate(&m, A));
    assert_false(lr_dmx_merge_terminate(&m, A));
    assert_int_equal(slot(&m, 0), 40);
    assert_int_equal(lr_dmx_merge_put(&m, C, 200, 0, hi, 1, 3 * S), LR_DMX_TAKEN);
    /* Everything lost: no slots, no priority. */
    assert_int_equal(lr_dmx_merge_expire(&m, 10 * S), 2);
    const uint8_t *out;
    assert_int_equal(lr_dmx_merge_get(&m, &out), 0);
    assert_int_equal(lr_dmx_merge_priority(&m), -1);
    assert_int_equal(lr_dmx_merge_next_expiry(&m), INT64_MAX);
}

static void artnet_htp_ltp(void **state)
{
    (void)state;
    lr_dmx_merge m;
    lr_dmx_merge_cfg cfg = {.max_sources = 2, .timeout_ns = 10 * S, .mode = LR_DMX_LTP};
    lr_dmx_merge_init(&m, &cfg);
    uint8_t a[2] = {200, 10}, b[2] = {50, 60};
    lr_dmx_merge_put(&m, A, 0, -1, a, 2, 0);
    lr_dmx_merge_put(&m, B, 0, -1, b, 2, 1 * S);
    /* LTP: the latest packet's slots, lower or not. */
    assert_int_equal(slot(&m, 0), 50);
    assert_int_equal(slot(&m, 1), 60);
    lr_dmx_merge_put(&m, A, 0, -1, a, 2, 2 * S);
    assert_int_equal(slot(&m, 0), 200);
    /* A third sender is refused (Art-Net merges two). */
    assert_int_equal(lr_dmx_merge_put(&m, C, 0, -1, b, 2, 2 * S), LR_DMX_FULL);
    /* 10 s merge timeout: B (last at 1 s) leaves at 11 s, not at 10.999 s. */
    assert_int_equal(lr_dmx_merge_expire(&m, 11 * S - 1), 0);
    assert_int_equal(lr_dmx_merge_expire(&m, 11 * S), 1);
    assert_int_equal(lr_dmx_merge_count(&m), 1);

    cfg.mode = LR_DMX_HTP;
    lr_dmx_merge_init(&m, &cfg);
    lr_dmx_merge_put(&m, A, 0, -1, a, 2, 0);
    lr_dmx_merge_put(&m, B, 0, -1, b, 2, 1 * S);
    assert_int_equal(slot(&m, 0), 200);
    assert_int_equal(slot(&m, 1), 60);
}

/* The ArtPollReply limit (hal/reply_limit.h): one reply per poller per second; over all
 * pollers a bucket of 20 refilled at 20 a second, so 40 distinct pollers at once get 20
 * replies, half a second later 10 more. */
static void reply_limit(void **state)
{
    (void)state;
    lr_reply_limit l;
    lr_reply_limit_init(&l, 1000, 20.0, 20.0);
    uint8_t k[LR_REPLY_LIMIT_KEY] = {127, 0, 0, 1, 0, 0};
    int64_t t = 100 * S;
    assert_true(lr_reply_limit_take(&l, k, t));
    assert_false(lr_reply_limit_take(&l, k, t + S / 2));
    assert_false(lr_reply_limit_take(&l, k, t + S - 1));
    assert_true(lr_reply_limit_take(&l, k, t + S));
    t += 10 * S; /* the bucket full again */
    int answered = 0;
    for (int i = 0; i < 40; i++) {
        k[5] = (uint8_t)(i + 1);
        answered += lr_reply_limit_take(&l, k, t);
    }
    assert_int_equal(answered, 20);
    answered = 0;
    for (int i = 20; i < 40; i++) {
        k[5] = (uint8_t)(i + 1);
        answered += lr_reply_limit_take(&l, k, t + S / 2);
    }
    assert_int_equal(answered, 10);
    /* 16 pollers are remembered: the 17th replaces the least recently answered, which is
     * then answered again inside its second (a reply more, never a controller lost). */
    t += 20 * S;
    for (int j = 0; j < 16; j++) {
        k[5] = (uint8_t)(101 + j);
        assert_true(lr_reply_limit_take(&l, k, t + j * MS));
    }
    k[5] = 101;
    assert_false(lr_reply_limit_take(&l, k, t + 20 * MS));
    k[5] = 117;
    assert_true(lr_reply_limit_take(&l, k, t + 21 * MS));
    k[5] = 101;
    assert_true(lr_reply_limit_take(&l, k, t + 22 * MS));
    k[5] = 103;
    assert_false(lr_reply_limit_take(&l, k, t + 23 * MS));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(priority_then_htp),
        cmocka_unit_test(sequence_window),
        cmocka_unit_test(loss_and_termination),
        cmocka_unit_test(artnet_htp_ltp),
        cmocka_unit_test(reply_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
