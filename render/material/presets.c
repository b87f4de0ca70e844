/* The list of shipped material presets: the *.json files of <configs>/materials. */
#include "render/material/material.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

void lr_material_names_free(char **names, int count)
{
    if (!names)
        return;
    for (int i = 0; i < count; i++)
        free(names[i]);
    free(names);
}

int lr_material_names(char ***names, int *count, lr_err *e)
{
    *names = NULL;
    *count = 0;
    char dir[PATH_MAX];
    if (lr_path_join(dir, sizeof dir, lr_configs_dir(), "materials", NULL) != 0)
        return lr_err_set(e, LR_EINVAL, "configs path too long: %s", lr_configs_dir());
    DIR *d = opendir(dir);
    if (!d)
        return lr_err_set(e, LR_EIO, "%s: cannot list material presets: %s", dir,
                          strerror(errno));
    char **list = NULL;
    int n = 0, cap = 0;
    struct dirent *de;
    while ((de = readdir(d)) != NULL) {
        size_t len = strlen(de->d_name);
        if (len <= 5 || strcmp(de->d_name + len - 5, ".json") != 0)
            continue;
        char stem[LR_MATERIAL_NAME_MAX];
        if (len - 5 >= sizeof stem)
            continue; /* longer than any preset name can be: not a preset */
        memcpy(stem, de->d_name, len - 5);
        stem[len - 5] = '\0';
        if (!lr_material_name_ok(stem))
            continue;
        if (n == cap) {
            cap = cap ? cap * 2 : 32;
            char **nl = realloc(list, (size_t)cap * sizeof *nl);
            if (!nl)
                goto oom;
            list = nl;
        }
        if (!(list[n] = strdup(stem)))
            goto oom;
        n++;
    }
    closedir(d);
    qsort(list, (size_t)n, sizeof *list, cmp_names);
    *names = list;
    *count = n;
    return LR_OK;
oom:
    closedir(d);
    lr_material_names_free(list, n);
    return lr_err_set(e, LR_ENOMEM, "%s: out of memory listing presets", dir);
}
