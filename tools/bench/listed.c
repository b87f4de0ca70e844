/* lamprig-bench — selecting scenes and settings by name lists (bench.h, lrb_listed). */
#include <stdbool.h>
#include <string.h>

#include "tools/bench/bench.h"

/* Whether `name` is one of the comma-separated names of `list` (whole names: "candle" must
 * not select "candle_spot"). */
bool lrb_listed(const char *list, const char *name)
{
    size_t n = strlen(name);
    for (const char *p = list; *p;) {
        size_t len = strcspn(p, ",");
        if (len == n && !strncmp(p, name, n))
            return true;
        p += len;
        if (*p == ',')
            p++;
    }
    return false;
}
