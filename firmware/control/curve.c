#include "firmware/control/curve.h"

#include <math.h>
#include <string.h>

static const char *const names[] = {"linear", "square", "s-curve", "log", "warm-dim"};

int lr_curve_parse(const char *name, enum lr_curve *out)
{
    for (unsigned i = 0; i < sizeof names / sizeof names[0]; i++) {
        if (strcmp(name, names[i]) == 0) {
            *out = (enum lr_curve)i;
            return 0;
        }
    }
    return -1;
}

const char *lr_curve_name(enum lr_curve c)
{
    return (unsigned)c < sizeof names / sizeof names[0] ? names[c] : "?";
}

static double clamp01(double x)
{
    if (!(x > 0.0)) /* also catches NaN */
        return 0.0;
    return x < 1.0 ? x : 1.0;
}

double lr_curve_apply(enum lr_curve c, double x)
{
    x = clamp01(x);
    switch (c) {
    case LR_CURVE_SQUARE: return x * x;
    case LR_CURVE_SCURVE: return x * x * (3.0 - 2.0 * x);
    case LR_CURVE_LOG: return log10(1.0 + 9.0 * x);
    case LR_CURVE_WARM_DIM: return pow(x, LR_CURVE_WARM_DIM_EXP);
    case LR_CURVE_LINEAR:
    default: return x;
    }
}

double lr_curve_invert(enum lr_curve c, double y)
{
    y = clamp01(y);
    switch (c) {
    case LR_CURVE_SQUARE: return sqrt(y);
    case LR_CURVE_SCURVE:
        /* The smoothstep's inverse in closed form: x = 1/2 - sin(asin(1 - 2y) / 3). */
        return 0.5 - sin(asin(1.0 - 2.0 * y) / 3.0);
    case LR_CURVE_LOG: return (pow(10.0, y) - 1.0) / 9.0;
    case LR_CURVE_WARM_DIM: return pow(y, 1.0 / LR_CURVE_WARM_DIM_EXP);
    case LR_CURVE_LINEAR:
    default: return y;
    }
}
