#include "firmware/control/fade.h"

void lr_fade_init(lr_fade *f, double value)
{
    f->from = f->to = value;
    f->t0_ns = 0;
    f->duration_ns = 0;
}

double lr_fade_value(const lr_fade *f, int64_t now_ns)
{
    if (f->duration_ns <= 0 || now_ns >= f->t0_ns + f->duration_ns)
        return f->to;
    if (now_ns <= f->t0_ns)
        return f->from;
    double s = (double)(now_ns - f->t0_ns) / (double)f->duration_ns;
    return f->from + (f->to - f->from) * s;
}

void lr_fade_to(lr_fade *f, double target, int64_t now_ns, double seconds)
{
    double current = lr_fade_value(f, now_ns);
    f->from = current;
    f->to = target;
    f->t0_ns = now_ns;
    f->duration_ns = seconds > 0.0 ? (int64_t)(seconds * 1e9 + 0.5) : 0;
}

bool lr_fade_active(const lr_fade *f, int64_t now_ns)
{
    return f->duration_ns > 0 && now_ns < f->t0_ns + f->duration_ns;
}

int64_t lr_fade_end_ns(const lr_fade *f) { return f->t0_ns + f->duration_ns; }
