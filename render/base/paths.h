/* lamprig — where shipped data (configs/) is found. */
#ifndef LR_PATHS_H
#define LR_PATHS_H

#include <stddef.h>

/* The configs directory: $LAMPRIG_CONFIGS when set, else ./configs when it exists, else the
 * source tree's configs/ compiled in by the Makefile. Returns a static string or the env. */
const char *lr_configs_dir(void);

/* Joins dir + "/" + a + "/" + b... into buf; returns 0, or -1 when it does not fit. */
int lr_path_join(char *buf, size_t cap, const char *dir, const char *sub, const char *leaf);

#endif
