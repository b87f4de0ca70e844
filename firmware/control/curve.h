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
    /* "warm-dim": y = x^(0.42 / 3.38), for a colour temperature driven by the same control
     * as the level (range [T_dim, T_full] on light.color_temperature_k): an incandescent's
     * lamp laws (flux ~ V^3.38, colour temperature ~ V^0.42; the exponents of the classic GE
     * lamp formulas) give T ~ flux^0.124, so the light stays near full temperature over most
     * of the travel and reddens in the last part, as filament and dim-to-warm LED lamps do. */
    LR_CURVE_WARM_DIM,
};

/* The warm-dim exponent: colour temperature over flux in the lamp laws. */
#define LR_CURVE_WARM_DIM_EXP (0.42 / 3.38)

/* "linear", "square", "s-curve", "log", "warm-dim"; returns 0, or -1 for an unknown name. */
int lr_curve_parse(const char *name, enum lr_curve *out);
const char *lr_curve_name(enum lr_curve c);

/* x is clamped to [0, 1]; NaN counts as 0 so garbage from a device never reaches the scene. */
double lr_curve_apply(enum lr_curve c, double x);
/* The inverse on [0, 1]: lr_curve_apply(c, lr_curve_invert(c, y)) == y to rounding. */
double lr_curve_invert(enum lr_curve c, double y);

#endif
