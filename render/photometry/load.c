/* A photometric file from disk, by its extension (luminaire.h). Apart from the parsers so
 * that their fuzz harnesses link without the file layer. */
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "render/base/file.h"
#include "render/photometry/luminaire.h"

int lr_luminaire_load(const char *path, lr_luminaire *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    const char *dot = strrchr(path, '.');
    bool ies = dot && strcasecmp(dot, ".ies") == 0, ldt = dot && strcasecmp(dot, ".ldt") == 0;
    if (!ies && !ldt)
        return lr_err_set(e, LR_EINVAL, "%s: not a photometric file (expected .ies or .ldt)",
                          path);
    char *text;
    size_t len;
    int rc = lr_file_read(path, 16u << 20, &text, &len, e);
    if (rc)
        return rc;
    rc = ies ? lr_ies_parse(text, len, path, out, e) : lr_ldt_parse(text, len, path, out, e);
    free(text);
    return rc;
}
