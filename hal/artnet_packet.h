/* lamprig hal — Art-Net 4 packets, pure: parse ArtDmx and ArtPoll, build ArtPollReply.
 *
 * Every packet starts "Art-Net\0" (8 bytes) and a little-endian OpCode; all others but
 * ArtPollReply follow with ProtVer (big-endian, >= 14).
 *
 *   ArtDmx (OpCode 0x5000)  12 sequence (0: off)  13 physical  14 SubUni  15 Net (7 bits)
 *                           16 length, big-endian, even, 2..512   18.. the slots
 *                           port-address = Net << 8 | SubUni (15 bits: net, sub-net, universe)
 *   ArtPoll (0x2000)        12 flags  13 diagnostics priority (Art-Net 4 adds optional target
 *                           fields after these: accepted, not used)
 *   ArtPollReply (0x2100)   239 bytes, built by lr_artnet_poll_reply.
 *
 * Other OpCodes (ArtSync, ArtAddress, ArtTodRequest, another node's ArtPollReply ...) are
 * well-formed traffic the receiver does not act on: LR_ARTNET_OTHER, not counted as bad. */
#ifndef LR_HAL_ARTNET_PACKET_H
#define LR_HAL_ARTNET_PACKET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define LR_ARTNET_PORT 6454
#define LR_ARTNET_OP_POLL 0x2000
#define LR_ARTNET_OP_POLL_REPLY 0x2100
#define LR_ARTNET_OP_DMX 0x5000
#define LR_ARTNET_PROT_VER 14
#define LR_ARTNET_PORT_ADDRESS_MAX 0x7fff
#define LR_ARTNET_POLL_REPLY_LEN 239

typedef enum lr_artnet_result {
    LR_ARTNET_DMX = 0,      /* a valid ArtDmx */
    LR_ARTNET_POLL,         /* a valid ArtPoll */
    LR_ARTNET_OTHER,        /* a valid header, an OpCode not acted on */
    LR_ARTNET_SHORT,        /* shorter than its header or fixed fields */
    LR_ARTNET_ID,           /* not "Art-Net\0" */
    LR_ARTNET_PROT_VERSION, /* ProtVer < 14 */
    LR_ARTNET_LENGTH,       /* ArtDmx length odd, 0, > 512 or more than the datagram holds */
    LR_ARTNET_LONG,         /* a datagram longer than any Art-Net packet (> 1024 bytes) */
    LR_ARTNET_N_RESULTS
} lr_artnet_result;

typedef struct lr_artnet_packet {
    int opcode;
    int prot_ver;
    /* ArtDmx */
    int sequence;
    int physical;
    int port_address;      /* 0..32767 */
    int n_slots;           /* 2..512, even */
    const uint8_t *slots;  /* into the parsed buffer */
    /* ArtPoll */
    int flags;
} lr_artnet_packet;

lr_artnet_result lr_artnet_parse(const uint8_t *buf, size_t len, lr_artnet_packet *out);
const char *lr_artnet_result_name(lr_artnet_result r);

/* What an ArtPollReply says about this node. */
typedef struct lr_artnet_node {
    uint32_t ip;           /* host byte order */
    const char *short_name; /* up to 17 characters are sent */
    const char *long_name;  /* up to 63 */
    int net, sub_net;      /* the ports' shared Net (0..127) and Sub-Net (0..15) */
    int n_ports;           /* 0..4 */
    int universe[4];       /* low nibble of each port's port-address */
    bool active[4];        /* data received on that port (GoodOutput 0x80) */
    int bind_index;        /* 1.. for the second and further replies of a node */
    const char *report;    /* NodeReport text, up to 63 */
} lr_artnet_node;

/* Writes an ArtPollReply into out (LR_ARTNET_POLL_REPLY_LEN bytes) and returns its length. */
size_t lr_artnet_poll_reply(const lr_artnet_node *node, uint8_t out[LR_ARTNET_POLL_REPLY_LEN]);

#endif
