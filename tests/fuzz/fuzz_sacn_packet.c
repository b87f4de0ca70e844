/* libFuzzer harness: hal/sacn_packet.c on arbitrary datagrams. Built with clang by
 * `make fuzz` (build/fuzz/fuzz_sacn_packet tests/fuzz/corpus/sacn); tests/hal/
 * test_hal_dmx_packet.c runs the same function on the committed corpus and mutations of it.
 * It checks what the parser promises, not only that it does not crash: a packet taken as data
 * has its fields in range and its slots inside the datagram. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "hal/sacn_packet.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lr_sacn_packet p;
    lr_sacn_result r = lr_sacn_parse(data, size, &p);
    if ((unsigned)r >= LR_SACN_N_RESULTS)
        abort();
    if (r == LR_SACN_OK || r == LR_SACN_START_CODE) {
        if (p.universe < 1 || p.universe > LR_SACN_UNIVERSE_MAX || p.priority > 200 ||
            p.n_slots < 0 || p.n_slots > 512 || p.slots != data + 126 ||
            (size_t)p.n_slots + 126 != size || strlen(p.source_name) > 63 ||
            (r == LR_SACN_OK) != (p.start_code == 0))
            abort();
        /* Touch every slot the parser hands out: ASan catches one past the datagram. */
        unsigned sum = 0;
        for (int i = 0; i < p.n_slots; i++)
            sum += p.slots[i];
        if (sum > 255u * 512u)
            abort();
    }
    return 0;
}
