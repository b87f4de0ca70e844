/* libFuzzer harness: render/photometry/ldt.c on arbitrary files. Built with clang:
 * `make build/fuzz/fuzz_ldt`, run as build/fuzz/fuzz_ldt -max_total_time=60 NEW/
 * tests/fuzz/corpus/ldt; tests/base/test_photometric_files.c runs the same function on the
 * committed corpus and on deterministic mutations of it. It checks what the parser promises,
 * not only that it does not crash: a file taken has sorted angles in range, finite
 * non-negative candela and a lookup within them; a file refused says "NAME:LINE: ...". */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "render/photometry/luminaire.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lr_luminaire l;
    lr_err e = {0};
    int rc = lr_ldt_parse((const char *)data, size, "f.ldt", &l, &e);
    if (rc) {
        /* Refused: a message naming the file and a line, nothing held. */
        if (strncmp(e.msg, "f.ldt:", 6) != 0 || e.msg[6] < '0' || e.msg[6] > '9' || l.cd)
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
