/* lamprig — keeping an on-disk cache folder bounded.
 *
 * Cache files are written atomically (atomic_file.h): NAME.tmpXXXXXX beside NAME, then a
 * rename. A process killed in between leaves the temp for ever, and every new scene or
 * setting adds a file of megabytes; nothing else ever removes them. The program's start
 * (firmware/cli.c) sweeps its cache folder with lr_cache_dir_tidy. */
#ifndef LR_CACHE_DIR_H
#define LR_CACHE_DIR_H

#include <stdint.h>
#include <time.h>

#include "render/base/err.h"

/* The cache's size cap when $LAMPRIG_CACHE_MAX_MB does not give one. */
#define LR_CACHE_MAX_BYTES_DEFAULT ((uint64_t)256 << 20)
/* A temp file younger than this may belong to a running writer: kept. */
#define LR_CACHE_TEMP_AGE_S 60

typedef struct lr_cache_tidy {
    int temps_removed;     /* stale temps of ours */
    int files_removed;     /* cache files evicted for the cap */
    uint64_t bytes_before; /* cache files' bytes before eviction (temps not counted) */
    uint64_t bytes_after;
} lr_cache_tidy;

/* Whether name is one of ours: a cache file "WORD-<16 hex digits>.bin" (WORD: lower-case
 * letters; transrad-, objlight-) or its temp, that name + ".tmp" + 6 characters of mkstemp's
 * [A-Za-z0-9]. *temp says which. Nothing else in the folder is ever touched. */
int lr_cache_dir_ours(const char *name, int *temp);

/* In folder dir: removes our temps last modified more than LR_CACHE_TEMP_AGE_S before now,
 * then, while our cache files total more than max_bytes, removes the least recently used
 * (latest of access and modification time) first. A missing folder is fine (nothing to do).
 * LR_EIO "DIR: <strerror>" when it cannot be listed; a file that cannot be removed is left. */
int lr_cache_dir_tidy(const char *dir, uint64_t max_bytes, time_t now, lr_cache_tidy *out,
                      lr_err *e);

/* The cap: $LAMPRIG_CACHE_MAX_MB (a positive integer of MiB), else the default. LR_EINVAL
 * naming the variable when it is set but not a positive integer (*out = the default). */
int lr_cache_max_bytes(uint64_t *out, lr_err *e);

#endif
