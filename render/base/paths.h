/* lamprig — where shipped data (configs/ and the GLSL shaders) is found.
 *
 * Two layouts: the source tree (configs/, render/shaders/) and an installed prefix
 * (PREFIX/bin/lamprig, PREFIX/share/lamprig/configs, PREFIX/share/lamprig/shaders; see
 * `make install`). The installed one is found relative to the running binary, so a staged
 * tree (DESTDIR, a package extracted into a scratch root) works as well as PREFIX itself. */
#ifndef LR_PATHS_H
#define LR_PATHS_H

#include <stddef.h>

/* The configs directory, first found of: $LAMPRIG_CONFIGS; ./configs when it holds
 * materials/; <dir of the executable>/../share/lamprig/configs (an installed prefix); the
 * source tree's configs/ compiled in by the Makefile. Returns the env, a static string or a
 * string computed once per process; never NULL. */
const char *lr_configs_dir(void);

/* The GLSL shader directory into buf: $LAMPRIG_SHADERS; else <configs>/../render/shaders
 * (source tree) when it exists; else <configs>/../shaders (installed prefix). Returns 0, or
 * -1 when it does not fit. */
int lr_shaders_dir(char *buf, size_t cap);

/* Joins dir + "/" + a + "/" + b... into buf; returns 0, or -1 when it does not fit. */
int lr_path_join(char *buf, size_t cap, const char *dir, const char *sub, const char *leaf);

#endif
