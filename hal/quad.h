/* lamprig hal — quadrature decoder for rotary encoders (pure: no I/O, no clock).
 *
 * State-table decoder over the 2-bit Gray code of the two contacts, ab = (A << 1) | B.
 * Clockwise (positive) is A leading B: 00 -> 10 -> 11 -> 01 -> 00 (set `reverse` when the
 * encoder is wired the other way). Every valid transition moves the position by one quarter
 * cycle; a detent step is emitted when the position has moved steps_per_detent transitions
 * away from the last detent, so contact bounce between two neighbouring states nets to zero
 * and never emits twice.
 *
 * Invalid input is counted, never acted on:
 *   - a sampled state in which both contacts changed (a transition was missed; the direction is
 *     unknowable), and
 *   - an edge reporting a level the contact already had (the opposite edge was missed).
 * After an invalid transition the half-finished detent is dropped when the encoder next rests
 * at a detent position, so one lost edge costs at most one detent and never shifts every later
 * detent by a half step.
 *
 * Acceleration is not done here (the control map does it from event timestamps).
 */
#ifndef LR_HAL_QUAD_H
#define LR_HAL_QUAD_H

#include <stdbool.h>
#include <stdint.h>

typedef struct lr_quad {
    uint8_t ab;         /* current (believed) contact state */
    uint8_t rest_phase; /* Gray phase of the detent the decoder started at */
    int8_t steps;       /* transitions per detent: 1, 2 or 4 */
    bool reverse;
    int pos;            /* transitions since the last emitted detent, |pos| < steps */
    uint32_t invalid;   /* invalid transitions and missed edges */
    uint32_t transitions;
} lr_quad;

/* steps_per_detent: 4 for most detented encoders (EC11 with one full cycle per click), 2 or 1
 * for half/quarter-cycle types; 0 means 4; others are clamped to the nearest of 1, 2, 4.
 * ab: the contacts' state at rest (read once after requesting the lines). */
void lr_quad_init(lr_quad *q, int steps_per_detent, unsigned ab, bool reverse);

/* Feeds a sampled state. Returns +1 or -1 when a detent step completes, else 0. */
int lr_quad_feed(lr_quad *q, unsigned ab);

/* Feeds an edge on one contact (line 0 = A, 1 = B) with the level after the edge, as GPIO edge
 * events report it. Returns +1, -1 or 0 like lr_quad_feed. */
int lr_quad_edge(lr_quad *q, int line, int level);

#endif
