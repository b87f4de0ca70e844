/* lamprig — finishing a cairo drawing as a PNG file (see cairo_png.h). */
#include "render/image/cairo_png.h"

#include <stdio.h>

#include "render/base/atomic_file.h"

static cairo_status_t write_stream(void *closure, const unsigned char *data, unsigned int len)
{
    return fwrite(data, 1, len, (FILE *)closure) == len ? CAIRO_STATUS_SUCCESS
                                                       : CAIRO_STATUS_WRITE_ERROR;
}

int lr_cairo_finish_png(cairo_t *cr, cairo_surface_t *s, const char *path, lr_err *e)
{
    cairo_status_t st = cairo_status(cr);
    cairo_destroy(cr);
    if (st != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        return lr_err_set(e, LR_EIO, "%s: drawing failed: %s", path, cairo_status_to_string(st));
    }
    lr_atomic_file *f = NULL;
    int rc = lr_atomic_file_open(path, &f, e);
    if (rc) {
        cairo_surface_destroy(s);
        return rc;
    }
    st = cairo_surface_write_to_png_stream(s, write_stream, lr_atomic_file_stream(f));
    cairo_surface_destroy(s);
    if (st != CAIRO_STATUS_SUCCESS) {
        lr_atomic_file_abort(f);
        return lr_err_set(e, LR_EIO, "%s: PNG encoding failed: %s", path,
                          cairo_status_to_string(st));
    }
    return lr_atomic_file_commit(f, e);
}
