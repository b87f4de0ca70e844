/* libFuzzer harness: render/photometry/ies.c on arbitrary files. Built with clang:
 * `make build/fuzz/fuzz_ies`, run as build/fuzz/fuzz_ies -max_total_time=60 NEW/
 * tests/fuzz/corpus/ies; tests/base/test_photometric_files.c runs the same function on the
 * committed corpus and on deterministic mutations of it. It checks what the parser promises
 * (luminaire_check.h), not only that it does not crash. */
#include <stddef.h>
#include <stdint.h>

#include "tests/fuzz/luminaire_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    return lr_fuzz_luminaire(lr_ies_parse, "f.ies", data, size);
}
