#include "hal/quad.h"

/* Movement for index (old << 2) | new: +1 clockwise, -1 counter-clockwise, 0 no change,
 * 2 invalid (both contacts changed). */
static const int8_t TABLE[16] = {
    /* old 00 -> */ 0, -1, +1, 2,
    /* old 01 -> */ +1, 0, 2, -1,
    /* old 10 -> */ -1, 2, 0, +1,
    /* old 11 -> */ 2, +1, -1, 0,
};

/* Position of a state along the clockwise cycle 00, 10, 11, 01. */
static uint8_t phase(unsigned ab)
{
    static const uint8_t P[4] = {0, 3, 1, 2};
    return P[ab & 3];
}

void lr_quad_init(lr_quad *q, int steps_per_detent, unsigned ab, bool reverse)
{
    int s = steps_per_detent;
    if (s <= 0 || s >= 4)
        s = 4;
    else if (s == 3)
        s = 2;
    q->ab = (uint8_t)(ab & 3);
    q->rest_phase = phase(ab);
    q->steps = (int8_t)s;
    q->reverse = reverse;
    q->pos = 0;
    q->invalid = 0;
    q->transitions = 0;
}

int lr_quad_feed(lr_quad *q, unsigned ab)
{
    ab &= 3;
    int move = TABLE[(q->ab << 2) | ab];
    q->ab = (uint8_t)ab;
    if (move == 0)
        return 0;
    int out = 0;
    if (move == 2) {
        q->invalid++;
    } else {
        q->transitions++;
        q->pos += move;
        if (q->pos >= q->steps) {
            q->pos -= q->steps;
            out = 1;
        } else if (q->pos <= -q->steps) {
            q->pos += q->steps;
            out = -1;
        }
    }
    /* At a detent position the partial count is zero unless an invalid transition shifted it
     * by two; that half-step cannot be given a direction, so it is dropped here. */
    if (((phase(ab) - q->rest_phase) & 3) % q->steps == 0)
        q->pos = 0;
    return q->reverse ? -out : out;
}

int lr_quad_edge(lr_quad *q, int line, int level)
{
    unsigned bit = line == 0 ? 2u : 1u;
    unsigned ab = level ? (q->ab | bit) : (q->ab & ~bit);
    if (ab == q->ab) {
        /* The contact already had this level: its opposite edge was lost. */
        q->invalid++;
        return 0;
    }
    return lr_quad_feed(q, ab);
}
