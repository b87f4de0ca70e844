#include "render/base/out_dir.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

int lr_out_dir_prepare(const char *path, lr_err *e)
{
    if (!path || !path[0])
        return lr_err_set(e, LR_EINVAL, "empty output folder");
    if (mkdir(path, 0777) != 0 && errno != EEXIST)
        return lr_err_set(e, LR_EIO, "%s: cannot create the folder: %s", path, strerror(errno));
    struct stat st;
    if (stat(path, &st) != 0)
        return lr_err_set(e, LR_EIO, "%s: %s", path, strerror(errno));
    if (!S_ISDIR(st.st_mode))
        return lr_err_set(e, LR_EINVAL, "%s: not a directory (expected a folder for the frames)",
                          path);
    if (access(path, W_OK | X_OK) != 0)
        return lr_err_set(e, LR_EIO, "%s: folder not writable: %s", path, strerror(errno));
    return LR_OK;
}
