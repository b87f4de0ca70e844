/* lamprig tests — a real libmodbus TCP server on 127.0.0.1 in a thread, acting as the dimmer
 * panel (unit 1) and the lamp driver (unit 2) of configs/rig/modbus-demo.json, 10 holding
 * registers each. Answers with libmodbus's own modbus_reply. Can be stopped (every
 * connection closed, the port refused) and started again on the same port. */
#ifndef LR_TEST_MODBUS_SERVER_H
#define LR_TEST_MODBUS_SERVER_H

#include <stdbool.h>

typedef struct lr_test_mb_server lr_test_mb_server;

/* Binds a free port (aborts the test on failure) and starts serving. */
lr_test_mb_server *lr_test_mb_server_start(void);
int lr_test_mb_server_port(const lr_test_mb_server *s);
/* unit 1 = panel, 2 = driver. */
int lr_test_mb_server_reg(lr_test_mb_server *s, int unit, int reg);
void lr_test_mb_server_set_reg(lr_test_mb_server *s, int unit, int reg, int value);
/* Requests answered so far. */
int lr_test_mb_server_answered(lr_test_mb_server *s);
void lr_test_mb_server_stop(lr_test_mb_server *s);
/* Listens again on the same port. */
void lr_test_mb_server_restart(lr_test_mb_server *s);
bool lr_test_mb_server_running(const lr_test_mb_server *s);
void lr_test_mb_server_free(lr_test_mb_server *s);

#endif
