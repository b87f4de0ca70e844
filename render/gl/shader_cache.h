/* lamprig — Mesa's on-disk shader cache on a full or read-only disk.
 *
 * Mesa (22.3, Debian 12) keeps compiled shaders under a folder of the user's cache and maps a
 * 1.3 MB sparse index file there. On a full file system the first store touches an index page
 * that cannot be allocated and the process dies with SIGBUS inside glLinkProgram (exit 135;
 * `lamprig run` before its first frame with XDG_CACHE_HOME on a full 1 MB tmpfs). Whoever
 * creates the first GL context checks the folder first and, when it is unusable, sets
 * MESA_SHADER_CACHE_DISABLE=true before eglInitialize (firmware/cli.c does, with one warning):
 * shaders are then compiled on every start, the rig runs. */
#ifndef LR_GL_SHADER_CACHE_H
#define LR_GL_SHADER_CACHE_H

#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"

/* Free space the shader cache's folder needs: the index at its full 1.3 MB and the compiled
 * programs (0.7 MB on disk for configs/rig/sim.json), many times over. */
#define LR_GL_SHADER_CACHE_MIN_FREE (16u << 20)

/* The folder Mesa 22.3 would use, by its rules: $MESA_SHADER_CACHE_DIR (else the deprecated
 * $MESA_GLSL_CACHE_DIR), else $XDG_CACHE_HOME, else the passwd entry's home + "/.cache", then
 * "/mesa_shader_cache" ("_sf" with MESA_DISK_CACHE_SINGLE_FILE, "_db" with
 * MESA_DISK_CACHE_DATABASE). NULL when the cache is disabled (MESA_SHADER_CACHE_DISABLE or
 * MESA_GLSL_CACHE_DISABLE true, Mesa's boolean words), when there is no home, or when the
 * path does not fit in buf. */
const char *lr_gl_shader_cache_dir(char *buf, size_t cap);

/* LR_OK when the shader cache is disabled or its folder can take writes
 * (lr_dir_check_writable with LR_GL_SHADER_CACHE_MIN_FREE); else LR_EIO with
 * "Mesa shader cache: DIR: reason" (render/base/dir_check.h). */
int lr_gl_shader_cache_check(lr_err *e);

#endif
