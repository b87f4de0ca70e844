/* lamprig — "say it once": remembers the keys (e.g. cache folders) a warning was given for, so
 * that a failure repeated at every rebuild (a read-only cache folder) is said once and not at
 * every store. Owned by the caller that outlives the objects that warn (a pass, a solver's
 * owner); library code keeps no such state of its own. Zero-initialised: nothing said yet.
 */
#ifndef LR_WARN_ONCE_H
#define LR_WARN_ONCE_H

#include <stdbool.h>
#include <stdint.h>

#define LR_WARN_ONCE_MAX 8 /* keys remembered; past that, each new key is said once more */

typedef struct lr_warn_once {
    uint64_t key[LR_WARN_ONCE_MAX]; /* FNV-1a of the key strings */
    int n;
} lr_warn_once;

/* True the first time key is seen by o (and remembers it); false after. o NULL: always true
 * (no dedup asked for). */
bool lr_warn_once_first(lr_warn_once *o, const char *key);

#endif
