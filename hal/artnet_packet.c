#include "hal/artnet_packet.h"

#include <stdio.h>
#include <string.h>

static const uint8_t ID[8] = {'A', 'r', 't', '-', 'N', 'e', 't', 0};

/* No Art-Net packet is longer: ArtDmx is 530, ArtPollReply 239, ArtTodData 1012. */
#define MAX_DATAGRAM 1024

lr_artnet_result lr_artnet_parse(const uint8_t *buf, size_t len, lr_artnet_packet *out)
{
    memset(out, 0, sizeof *out);
    if (len < 10)
        return LR_ARTNET_SHORT;
    if (memcmp(buf, ID, sizeof ID) != 0)
        return LR_ARTNET_ID;
    if (len > MAX_DATAGRAM)
        return LR_ARTNET_LONG;
    out->opcode = buf[8] | buf[9] << 8;
    /* Another node's reply has no ProtVer field: it is not for us either way. */
    if (out->opcode == LR_ARTNET_OP_POLL_REPLY)
        return LR_ARTNET_OTHER;
    if (len < 12)
        return LR_ARTNET_SHORT;
    out->prot_ver = buf[10] << 8 | buf[11];
    if (out->prot_ver < LR_ARTNET_PROT_VER)
        return LR_ARTNET_PROT_VERSION;
    switch (out->opcode) {
    case LR_ARTNET_OP_DMX: {
        if (len < 18)
            return LR_ARTNET_SHORT;
        out->sequence = buf[12];
        out->physical = buf[13];
        out->port_address = (buf[15] & 0x7f) << 8 | buf[14];
        int n = buf[16] << 8 | buf[17];
        if (n < 2 || n > 512 || (n & 1) || (size_t)n > len - 18)
            return LR_ARTNET_LENGTH;
        out->n_slots = n;
        out->slots = buf + 18;
        return LR_ARTNET_DMX;
    }
    case LR_ARTNET_OP_POLL:
        if (len < 14)
            return LR_ARTNET_SHORT;
        out->flags = buf[12];
        return LR_ARTNET_POLL;
    default:
        return LR_ARTNET_OTHER;
    }
}

const char *lr_artnet_result_name(lr_artnet_result r)
{
    static const char *const names[LR_ARTNET_N_RESULTS] = {
        [LR_ARTNET_DMX] = "dmx",       [LR_ARTNET_POLL] = "poll",
        [LR_ARTNET_OTHER] = "other",   [LR_ARTNET_SHORT] = "short",
        [LR_ARTNET_ID] = "id",         [LR_ARTNET_PROT_VERSION] = "prot-ver",
        [LR_ARTNET_LENGTH] = "length", [LR_ARTNET_LONG] = "long",
    };
    return (unsigned)r < LR_ARTNET_N_RESULTS ? names[r] : "?";
}

static void put_text(uint8_t *dst, size_t cap, const char *s)
{
    if (s)
        snprintf((char *)dst, cap, "%s", s);
}

size_t lr_artnet_poll_reply(const lr_artnet_node *node, uint8_t out[LR_ARTNET_POLL_REPLY_LEN])
{
    memset(out, 0, LR_ARTNET_POLL_REPLY_LEN);
    memcpy(out, ID, sizeof ID);
    out[8] = LR_ARTNET_OP_POLL_REPLY & 0xff;
    out[9] = LR_ARTNET_OP_POLL_REPLY >> 8;
    out[10] = (uint8_t)(node->ip >> 24);
    out[11] = (uint8_t)(node->ip >> 16);
    out[12] = (uint8_t)(node->ip >> 8);
    out[13] = (uint8_t)node->ip;
    out[14] = LR_ARTNET_PORT & 0xff; /* the port is little-endian here */
    out[15] = LR_ARTNET_PORT >> 8;
    out[16] = 0; /* VersInfo: firmware 1 */
    out[17] = 1;
    out[18] = (uint8_t)(node->net & 0x7f);
    out[19] = (uint8_t)(node->sub_net & 0x0f);
    /* Oem 0x00ff: "unknown"; EstaMan 0: none registered. */
    out[20] = 0x00;
    out[21] = 0xff;
    /* Status1: indicators normal (bits 7-6 = 11), port-address set by front panel (5-4 = 01). */
    out[23] = 0xd0;
    put_text(out + 26, 18, node->short_name);
    put_text(out + 44, 64, node->long_name);
    put_text(out + 108, 64, node->report);
    int n = node->n_ports < 0 ? 0 : node->n_ports > 4 ? 4 : node->n_ports;
    out[172] = 0;
    out[173] = (uint8_t)n;
    for (int i = 0; i < n; i++) {
        out[174 + i] = 0x80;                          /* PortTypes: outputs DMX512 from Art-Net */
        out[182 + i] = node->active[i] ? 0x80 : 0x00; /* GoodOutput: data being output */
        out[190 + i] = (uint8_t)(node->universe[i] & 0x0f); /* SwOut */
    }
    out[200] = 0x00; /* Style: StNode */
    out[207] = out[10];
    out[208] = out[11];
    out[209] = out[12];
    out[210] = out[13];
    out[211] = (uint8_t)(node->bind_index > 0 ? node->bind_index : 1);
    /* Status2: Art-Net 4 (15-bit port-address) capable (bit 3). */
    out[212] = 0x08;
    return LR_ARTNET_POLL_REPLY_LEN;
}
