/* lamprig — dimmer curves as lighting consoles offer them.
 *
 * A curve maps a control position x in [0, 1] (a fader, a knob's accumulated value, a Modbus
 * panel's scaled register) to a level y in [0, 1]; the control map then scales y into the
 * parameter's range. Every curve is continuous, strictly increasing, and maps 0 -> 0 and
 * 1 -> 1, so a dimmer at its ends means "off" and "full" whatever the curve.
 */
#ifndef LR_CURVE_H
#define LR_CURVE_H

enum lr_curve {
    LR_CURVE_LINEAR, /* y = x */
    LR_CURVE_SQUARE, /* "square law": y = x^2, fine control at the dim end */
    LR_CURVE_SCURVE, /* smoothstep y = x^2 (3 - 2x): gentle at both ends */
    LR_CURVE_LOG,    /* y = log10(1 + 9x): fast at the dim end, like an inverse square law */
};

/* "linear", "square", "s-curve", "log"; returns 0, or -1 for an unknown name. */
int lr_curve_parse(const char *name, enum lr_curve *out);
const char *lr_curve_name(enum lr_curve c);

/* x is clamped to [0, 1]; NaN counts as 0 so garbage from a device never reaches the scene. */
double lr_curve_apply(enum lr_curve c, double x);
/* The inverse on [0, 1]: lr_curve_apply(c, lr_curve_invert(c, y)) == y to rounding. */
double lr_curve_invert(enum lr_curve c, double y);

#endif
