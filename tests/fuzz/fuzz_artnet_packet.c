/* libFuzzer harness: hal/artnet_packet.c on arbitrary datagrams (see fuzz_sacn_packet.c). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "hal/artnet_packet.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    lr_artnet_packet p;
    lr_artnet_result r = lr_artnet_parse(data, size, &p);
    if ((unsigned)r >= LR_ARTNET_N_RESULTS)
        abort();
    if (r == LR_ARTNET_DMX) {
        if (p.port_address < 0 || p.port_address > LR_ARTNET_PORT_ADDRESS_MAX || p.n_slots < 2 ||
            p.n_slots > 512 || (p.n_slots & 1) || p.slots != data + 18 ||
            (size_t)p.n_slots + 18 > size || p.prot_ver < LR_ARTNET_PROT_VER)
            abort();
        unsigned sum = 0;
        for (int i = 0; i < p.n_slots; i++)
            sum += p.slots[i];
        if (sum > 255u * 512u)
            abort();
    }
    return 0;
}
