/* lamprig — the process's umask from /proc/self/status (umask.h). */
#include "render/base/umask.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FALLBACK 0077

mode_t lr_umask_get(void)
{
    FILE *f = fopen("/proc/self/status", "re");
    if (!f)
        return FALLBACK;
    char line[256];
    mode_t m = FALLBACK;
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "Umask:", 6) != 0)
            continue;
        char *end;
        unsigned long v = strtoul(line + 6, &end, 8);
        if (end != line + 6 && v <= 0777)
            m = (mode_t)v;
        break;
    }
    fclose(f);
    return m;
}
