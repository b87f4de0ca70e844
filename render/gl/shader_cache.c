/* lamprig — Mesa's shader cache folder and whether it can take writes (shader_cache.h). */
#include "render/gl/shader_cache.h"

#include <pwd.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include "render/base/dir_check.h"

/* Mesa's env_var_as_boolean: 1/true/y/yes, 0/false/n/no (case-insensitive), else def. */
static bool env_bool(const char *name, bool def)
{
    const char *v = getenv(name);
    if (!v)
        return def;
    if (!strcmp(v, "1") || !strcasecmp(v, "true") || !strcasecmp(v, "y") || !strcasecmp(v, "yes"))
        return true;
    if (!strcmp(v, "0") || !strcasecmp(v, "false") || !strcasecmp(v, "n") || !strcasecmp(v, "no"))
        return false;
    return def;
}

const char *lr_gl_shader_cache_dir(char *buf, size_t cap)
{
    /* Mesa reads MESA_GLSL_CACHE_DISABLE only when the new name is absent. */
    const char *dis = getenv("MESA_SHADER_CACHE_DISABLE") ? "MESA_SHADER_CACHE_DISABLE"
                                                           : "MESA_GLSL_CACHE_DISABLE";
    if (env_bool(dis, false))
        return NULL;
    const char *leaf = env_bool("MESA_DISK_CACHE_SINGLE_FILE", false) ? "mesa_shader_cache_sf"
                       : env_bool("MESA_DISK_CACHE_DATABASE", false)  ? "mesa_shader_cache_db"
                                                                      : "mesa_shader_cache";
    const char *base = getenv("MESA_SHADER_CACHE_DIR");
    if (!base)
        base = getenv("MESA_GLSL_CACHE_DIR");
    if (!base)
        base = getenv("XDG_CACHE_HOME");
    int n;
    if (base) {
        n = snprintf(buf, cap, "%s/%s", base, leaf);
    } else {
        struct passwd pw, *res = NULL;
        char pwbuf[4096];
        if (getpwuid_r(getuid(), &pw, pwbuf, sizeof pwbuf, &res) != 0 || !res || !pw.pw_dir)
            return NULL;
        n = snprintf(buf, cap, "%s/.cache/%s", pw.pw_dir, leaf);
    }
    return n > 0 && (size_t)n < cap ? buf : NULL;
}

int lr_gl_shader_cache_check(lr_err *e)
{
    char dir[4096];
    if (!lr_gl_shader_cache_dir(dir, sizeof dir))
        return LR_OK;
    int rc = lr_dir_check_writable(dir, LR_GL_SHADER_CACHE_MIN_FREE, e);
    return rc ? lr_err_prefix(e, "Mesa shader cache") : LR_OK;
}
