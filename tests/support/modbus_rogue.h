/* lamprig tests — a misbehaving Modbus/TCP peer in a thread on 127.0.0.1 (a free port), for the
 * defects a well-behaved libmodbus server (modbus_server.h) cannot show. One client at a time
 * (a new connection replaces the old one). Registers: unit 2 is the lamp driver, every other
 * unit the panel; 16 holding registers each (default 0); writes are echoed and stored.
 *
 *  DRIP    every read is answered with a header declaring 250 data bytes, then one byte every
 *          drip_ms (the rest of the requests are read and ignored while a drip runs)
 *  LATE    every request is answered twice: first the previous request's answer with the
 *          previous transaction id (a late answer), then its own
 *  RANDOM  answers carry the right transaction id but cycle through a wrong unit, a wrong
 *          function, an exception (codes 1..11) and a good answer, each with varying numbers
 *  CLOSE   accepts a connection and closes it at once
 *
 * Its descriptors are close-on-exec: a test may start peers and then fork and exec the rig
 * (test_fw_loop's fast soak), whose descriptor count it watches.
 */
#ifndef LR_TEST_MODBUS_ROGUE_H
#define LR_TEST_MODBUS_ROGUE_H

typedef enum lr_test_rogue_mode {
    LR_ROGUE_DRIP = 0,
    LR_ROGUE_LATE,
    LR_ROGUE_RANDOM,
    LR_ROGUE_CLOSE,
} lr_test_rogue_mode;

typedef struct lr_test_rogue lr_test_rogue;

/* Aborts the test when the socket or thread cannot be set up. drip_ms: DRIP only. */
lr_test_rogue *lr_test_rogue_start(lr_test_rogue_mode mode, int drip_ms);
int lr_test_rogue_port(const lr_test_rogue *r);
/* The panel's register. */
void lr_test_rogue_set_reg(lr_test_rogue *r, int reg, int value);
/* The lamp driver's register (unit 2). */
int lr_test_rogue_driver(lr_test_rogue *r, int reg);
/* Connections accepted so far. */
int lr_test_rogue_accepted(lr_test_rogue *r);
/* Requests received so far. */
int lr_test_rogue_requests(lr_test_rogue *r);
void lr_test_rogue_free(lr_test_rogue *r);

#endif
