/* lamprig hal — GPIO controls through libgpiod (v1.6 API, as on Debian 12 / Raspberry Pi OS 12).
 *
 * Rotary encoders (two lines, quadrature; hal/quad.h) emit LR_EV_DELTA ±1 per detent step,
 * stamped with the kernel's edge timestamp. Push buttons (one line; hal/debounce.h) emit
 * LR_EV_PRESS / LR_EV_RELEASE. Every line is requested for both edges
 * (gpiod_line_request_both_edges_events_flags) and its event fd made non-blocking; dispatch
 * drains the fds with gpiod_line_event_read_fd_multiple and feeds the A and B edges of an encoder
 * to the decoder in timestamp order (they arrive on two fds).
 *
 * Lines are named by the kernel line name ("GPIO17") or by offset on the chip ("17"). The chip
 * is anything gpiod_chip_open_lookup accepts: "gpiochip0", "/dev/gpiochip0", "0" or its label
 * ("pinctrl-bcm2711"). Polarity is handled here, not by the kernel's active-low flag, so edge
 * types stay physical levels.
 *
 * A chip that is missing or removed (a USB/I2C GPIO expander unplugged) makes the device
 * MISSING and it is reopened with backoff; events are lost meanwhile, never invented.
 *
 * Edge timestamps are CLOCK_MONOTONIC on kernels >= 5.7 (older ones used CLOCK_REALTIME); a
 * timestamp more than 10 s from now is replaced by the read time.
 */
#ifndef LR_HAL_GPIO_H
#define LR_HAL_GPIO_H

#include <stdbool.h>

#include "hal/dev.h"
#include "hal/opt.h"
#include "render/base/err.h"

typedef struct lr_gpio_encoder {
    const char *name;      /* control name, e.g. "knob1" */
    const char *line_a;    /* line name or offset */
    const char *line_b;
    int steps_per_detent;  /* quadrature transitions per detent: 1, 2 or 4; 0 means 4 */
    bool reverse;          /* swap the direction */
} lr_gpio_encoder;

typedef struct lr_gpio_button {
    const char *name;      /* control name, e.g. "button1" */
    const char *line;      /* line name or offset */
    bool active_high;      /* default false: pressed pulls the line low (pull-up wiring) */
    int debounce_ms;       /* default and range: lr_gpio_button_opts */
} lr_gpio_button;

typedef enum lr_gpio_bias {
    LR_GPIO_BIAS_PULL_UP = 0, /* default: encoders and buttons switch to ground */
    LR_GPIO_BIAS_AS_IS,       /* leave the line's bias as the board configured it */
    LR_GPIO_BIAS_DISABLE,     /* external resistors */
    LR_GPIO_BIAS_PULL_DOWN,
} lr_gpio_bias;

#define LR_GPIO_MAX_LINES 64

typedef struct lr_gpio_desc {
    lr_dev_desc dev;          /* name default "gpio" */
    const char *chip;         /* default "gpiochip0" */
    const char *consumer;     /* label shown by gpioinfo; default "lamprig" */
    lr_gpio_bias bias;
    const lr_gpio_encoder *encoders;
    int n_encoders;
    const lr_gpio_button *buttons;
    int n_buttons;            /* 2 * n_encoders + n_buttons <= LR_GPIO_MAX_LINES */
} lr_gpio_desc;

/* The options above as the rig config reads them (hal/opt.h). */
enum { LR_GPIO_OPT_CHIP = 0, LR_GPIO_OPT_BIAS, LR_GPIO_OPT_ENCODERS, LR_GPIO_OPT_BUTTONS };
extern const lr_opt lr_gpio_opts[];
enum {
    LR_GPIO_ENC_NAME = 0,
    LR_GPIO_ENC_LINE_A,
    LR_GPIO_ENC_LINE_B,
    LR_GPIO_ENC_STEPS_PER_DETENT,
    LR_GPIO_ENC_REVERSE,
};
extern const lr_opt lr_gpio_encoder_opts[];
enum { LR_GPIO_BTN_NAME = 0, LR_GPIO_BTN_LINE, LR_GPIO_BTN_ACTIVE_HIGH, LR_GPIO_BTN_DEBOUNCE_MS };
extern const lr_opt lr_gpio_button_opts[];

typedef struct lr_gpio lr_gpio;

/* Validates the descriptor (names, lines, ranges; LR_EINVAL naming the field), then opens the
 * chip. A missing chip or line is LR_ENODEV when dev.required, else logged and retried. */
int lr_gpio_create(const lr_gpio_desc *desc, lr_gpio **out, lr_err *e);
void lr_gpio_destroy(lr_gpio *g);
lr_dev *lr_gpio_dev(lr_gpio *g);
/* Invalid transitions (missed edges) counted by encoder i's decoder since create. */
unsigned lr_gpio_encoder_invalid(const lr_gpio *g, int i);

#endif
