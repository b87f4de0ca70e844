/* lamprig tests — headless GL context, with the driver pinned for leak reports. */
#include "tests/support/gl.h"

#include <dlfcn.h>
#include <link.h>
#include <stdio.h>

static int pin(struct dl_phdr_info *info, size_t size, void *data)
{
    /* RTLD_NOLOAD only looks the library up; with RTLD_NODELETE it becomes permanent.
     * The handle is deliberately never closed. */
    if (info->dlpi_name && info->dlpi_name[0])
        dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD | RTLD_NODELETE);
    return 0;
}

void lr_test_pin_libraries(void)
{
    dl_iterate_phdr(pin, NULL);
}

int lr_test_gl_create(lr_gl **out)
{
    lr_err e = {0};
    int rc = lr_gl_create(NULL, out, &e);
    if (rc) {
        fprintf(stderr, "lr_gl_create: %s\n", e.msg);
        return rc;
    }
    lr_test_pin_libraries();
    return LR_OK;
}
