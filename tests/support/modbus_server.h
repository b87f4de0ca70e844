/* lamprig tests — a real libmodbus server in a thread, acting as the dimmer panel (unit 1) and
 * the lamp driver (unit 2) of configs/rig/modbus-demo.json, 10 holding registers each. Answers
 * with libmodbus's own modbus_reply. Two transports:
 *  - TCP on 127.0.0.1, a free port;
 *  - RTU on a pseudo-terminal pair: the server holds the master end, the firmware opens the
 *    slave (/dev/pts/N, or a symlink to it, as udev's /dev/serial/by-id links are).
 * Can be stopped and started again: TCP closes every connection and refuses the port; RTU closes
 * the pty, so the slave hangs up and the device node disappears, and a restart opens a new pty
 * and points the symlink at it. Used by tests/hal/test_hal_modbus.c and tests/fw/test_fw_modbus.c. */
#ifndef LR_TEST_MODBUS_SERVER_H
#define LR_TEST_MODBUS_SERVER_H

#include <stdbool.h>

typedef struct lr_test_mb_server lr_test_mb_server;

/* TCP: binds a free port (aborts the test on failure) and starts serving. */
lr_test_mb_server *lr_test_mb_server_start(void);
/* RTU (19200 8E1 framing on the pty). link: a path made a symlink to the pty's slave, kept
 * pointing at the current pty across restarts; NULL for none. */
lr_test_mb_server *lr_test_mb_server_start_rtu(const char *link);
int lr_test_mb_server_port(const lr_test_mb_server *s);
/* RTU: the device the master opens: the link if one was given, else /dev/pts/N. */
const char *lr_test_mb_server_device(const lr_test_mb_server *s);
/* unit 1 = panel, 2 = driver. */
int lr_test_mb_server_reg(lr_test_mb_server *s, int unit, int reg);
void lr_test_mb_server_set_reg(lr_test_mb_server *s, int unit, int reg, int value);
/* Requests answered so far. */
int lr_test_mb_server_answered(lr_test_mb_server *s);
/* Silent: requests are read and never answered. */
void lr_test_mb_server_set_silent(lr_test_mb_server *s, bool silent);
/* RTU: damage the CRC of the next n replies. */
void lr_test_mb_server_corrupt(lr_test_mb_server *s, int n);
void lr_test_mb_server_stop(lr_test_mb_server *s);
/* TCP: listens again on the same port. RTU: a new pty (the link follows it). */
void lr_test_mb_server_restart(lr_test_mb_server *s);
bool lr_test_mb_server_running(const lr_test_mb_server *s);
void lr_test_mb_server_free(lr_test_mb_server *s);

#endif
