/* What the photometric file parsers promise, checked on one input (fuzz_ies.c, fuzz_ldt.c): a
 * file taken has sorted angles in range, finite non-negative candela and a lookup within them;
 * a file refused says "NAME:LINE: ..." and holds nothing. abort() on a broken promise. */
#ifndef LR_FUZZ_LUMINAIRE_CHECK_H
#define LR_FUZZ_LUMINAIRE_CHECK_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "render/photometry/luminaire.h"

typedef int (*lr_fuzz_luminaire_parse)(const char *text, size_t len, const char *name,
                                       lr_luminaire *out, lr_err *e);

static int lr_fuzz_luminaire(lr_fuzz_luminaire_parse parse, const char *name,
                             const uint8_t *data, size_t size)
{
    lr_luminaire l;
    lr_err e = {0};
    size_t nl = strlen(name);
    if (parse((const char *)data, size, name, &l, &e)) {
        /* Refused: a message naming the file and a line, nothing held. */
        if (strncmp(e.msg, name, nl) != 0 || e.msg[nl] != ':' || e.msg[nl + 1] < '0' ||
            e.msg[nl + 1] > '9' || l.cd)
            abort();
        return 0;
    }
    if (l.n_v < 1 || l.n_h < 1 || l.n_v > LR_LUM_MAX_ANGLES ||
        (size_t)l.n_v * (size_t)l.n_h > LR_LUM_MAX_VALUES)
        abort();
    for (int i = 0; i < l.n_v; i++)
        if (!(l.v_deg[i] >= 0.0 && l.v_deg[i] <= 180.0) || (i && !(l.v_deg[i] > l.v_deg[i - 1])))
            abort();
    for (int j = 0; j < l.n_h; j++)
        if (!(l.h_deg[j] >= 0.0 && l.h_deg[j] <= 360.0) || (j && !(l.h_deg[j] > l.h_deg[j - 1])))
            abort();
    double max = lr_luminaire_max_cd(&l);
    if (!isfinite(max) || max < 0.0)
        abort();
    /* Bilinear lookups stay within the values, anywhere (any C angle folds). */
    for (int k = 0; k < 64; k++) {
        double c = lr_luminaire_cd(&l, -720.0 + 23.7 * k, 181.0 * k / 63.0);
        if (!(c >= 0.0 && c <= max * (1.0 + 1e-12)))
            abort();
    }
    lr_luminaire_free(&l);
    return 0;
}

#endif
