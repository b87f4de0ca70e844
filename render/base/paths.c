#include "render/base/paths.h"

#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef LR_SOURCE_CONFIGS
#define LR_SOURCE_CONFIGS "configs"
#endif

static int is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

/* The installed configs beside the running binary, found once: the executable's path does
 * not change while the process runs, so this is a constant computed lazily, not state. */
static pthread_once_t installed_once = PTHREAD_ONCE_INIT;
static char installed[PATH_MAX];

static void find_installed(void)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return;
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash)
        return;
    *slash = '\0';
    char cand[PATH_MAX];
    int w = snprintf(cand, sizeof cand, "%s/../share/lamprig/configs", exe);
    if (w < 0 || (size_t)w >= sizeof cand || !is_dir(cand))
        return;
    /* Canonical, so messages name /usr/share/lamprig/configs, not /usr/bin/../share/... */
    if (!realpath(cand, installed))
        installed[0] = '\0';
}

const char *lr_configs_dir(void)
{
    const char *env = getenv("LAMPRIG_CONFIGS");
    if (env && env[0])
        return env;
    if (is_dir("configs/materials"))
        return "configs";
    pthread_once(&installed_once, find_installed);
    if (installed[0])
        return installed;
    return LR_SOURCE_CONFIGS;
}

int lr_shaders_dir(char *buf, size_t cap)
{
    const char *env = getenv("LAMPRIG_SHADERS");
    if (env && env[0])
        return lr_path_join(buf, cap, env, NULL, NULL);
    const char *configs = lr_configs_dir();
    if (lr_path_join(buf, cap, configs, "../render", "shaders") != 0)
        return -1;
    if (is_dir(buf))
        return 0;
    return lr_path_join(buf, cap, configs, "../shaders", NULL);
}

int lr_path_join(char *buf, size_t cap, const char *dir, const char *sub, const char *leaf)
{
    int n;
    if (sub && leaf)
        n = snprintf(buf, cap, "%s/%s/%s", dir, sub, leaf);
    else if (sub)
        n = snprintf(buf, cap, "%s/%s", dir, sub);
    else
        n = snprintf(buf, cap, "%s", dir);
    return (n < 0 || (size_t)n >= cap) ? -1 : 0;
}
