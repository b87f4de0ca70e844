#include "render/base/paths.h"

#include <stdio.h>
#include <stdlib.h>
#include <sys/stat.h>

#ifndef LR_SOURCE_CONFIGS
#define LR_SOURCE_CONFIGS "configs"
#endif

const char *lr_configs_dir(void)
{
    const char *env = getenv("LAMPRIG_CONFIGS");
    if (env && env[0])
        return env;
    struct stat st;
    if (stat("configs/materials", &st) == 0 && S_ISDIR(st.st_mode))
        return "configs";
    return LR_SOURCE_CONFIGS;
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
