/* lamprig-bench — a scene change with its refusal printed (bench.h, lrb_scene_set). */
#include <stdio.h>

#include "render/scene/scene.h"
#include "tools/bench/bench.h"

int lrb_scene_set(const char *who, lr_scene *s, const char *key, const char *value,
                  unsigned *dirty)
{
    lr_err e = {0};
    unsigned d = 0;
    if (lr_scene_set(s, key, value, &d, &e)) {
        fprintf(stderr, "%s: %s=%s: %s\n", who, key, value, e.msg);
        return 1;
    }
    if (dirty)
        *dirty |= d;
    return 0;
}
