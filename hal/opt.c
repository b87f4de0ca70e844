#include "hal/opt.h"

#include <string.h>

bool lr_opt_in_range(const lr_opt *o, long v)
{
    return v >= o->lo && v <= o->hi;
}

bool lr_opt_hal_ok(const lr_opt *o, long v)
{
    return v == 0 || lr_opt_in_range(o, v);
}

long lr_opt_or_default(const lr_opt *o, long v)
{
    return v ? v : o->dflt;
}

int lr_opt_enum_index(const lr_opt *o, const char *name)
{
    for (int i = 0; o->names && o->names[i]; i++)
        if (strcmp(o->names[i], name) == 0)
            return i;
    return -1;
}

const lr_opt *lr_opt_find(const lr_opt *table, const char *key)
{
    for (const lr_opt *o = table; o->key; o++)
        if (strcmp(o->key, key) == 0)
            return o;
    return NULL;
}
