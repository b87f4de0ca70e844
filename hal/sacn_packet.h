/* lamprig hal — sACN (ANSI E1.31-2018) data packets, pure: parse and validate one UDP payload.
 *
 * Layout of a data packet (E1.31 Table 4-1; offsets in bytes, multi-byte fields big-endian):
 *
 *   root layer     0 preamble size 0x0010      2 postamble size 0x0000
 *                  4 ACN packet identifier "ASC-E1.17\0\0\0" (12 bytes)
 *                 16 flags & length (0x7000 | length from byte 16 to the end)
 *                 18 vector 0x00000004 (VECTOR_ROOT_E131_DATA; 0x00000008 is EXTENDED:
 *                    synchronization and universe discovery, reported as LR_SACN_EXTENDED)
 *                 22 CID (16 bytes, the source's UUID)
 *   framing layer 38 flags & length (from byte 38)   40 vector 0x00000002
 *                 44 source name (64 bytes, UTF-8, NUL-terminated)
 *                108 priority 0..200   109 synchronization address   111 sequence number
 *                112 options: 0x80 preview data, 0x40 stream terminated, 0x20 force sync
 *                113 universe 1..63999
 *   DMP layer    115 flags & length (from byte 115)   117 vector 0x02 (SET_PROPERTY)
 *                118 address & data type 0xa1   119 first property address 0x0000
 *                121 address increment 0x0001   123 property value count 1..513
 *                125 START code   126.. up to 512 slots
 *
 * A packet is 126..638 bytes; its three length fields and the value count must agree with the
 * datagram's size exactly. Every way a packet can be wrong has its own result, so a receiver
 * counts (and logs once) each kind. A non-zero START code (0xDD per-address priority, text,
 * test packets ...) is well-formed but not level data: LR_SACN_START_CODE, with the fields
 * parsed. */
#ifndef LR_HAL_SACN_PACKET_H
#define LR_HAL_SACN_PACKET_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define LR_SACN_PORT 5568
#define LR_SACN_MIN_LEN 126
#define LR_SACN_MAX_LEN 638
#define LR_SACN_UNIVERSE_MAX 63999
#define LR_SACN_PRIORITY_MAX 200
#define LR_SACN_BIT_PREVIEW 0x80
#define LR_SACN_BIT_TERMINATED 0x40
#define LR_SACN_BIT_FORCE_SYNC 0x20

typedef enum lr_sacn_result {
    LR_SACN_OK = 0,
    LR_SACN_SHORT,          /* fewer than 126 bytes */
    LR_SACN_LONG,           /* more than 638 bytes */
    LR_SACN_PREAMBLE,       /* preamble / postamble size not 0x0010 / 0x0000 */
    LR_SACN_ACN_ID,         /* not "ASC-E1.17" */
    LR_SACN_ROOT_LENGTH,    /* root flags not 0x7 or its length not the datagram's */
    LR_SACN_ROOT_VECTOR,    /* neither DATA nor EXTENDED */
    LR_SACN_EXTENDED,       /* a well-formed root of a sync or discovery packet: not data */
    LR_SACN_FRAMING_LENGTH,
    LR_SACN_FRAMING_VECTOR,
    LR_SACN_PRIORITY,       /* > 200 */
    LR_SACN_UNIVERSE,       /* 0 or > 63999 */
    LR_SACN_DMP_LENGTH,
    LR_SACN_DMP_VECTOR,
    LR_SACN_DMP_LAYOUT,     /* address type, first address or increment wrong */
    LR_SACN_COUNT,          /* property value count not 1..513 or not the datagram's */
    LR_SACN_START_CODE,     /* well-formed, START code not 0: ignored, not counted as bad */
    LR_SACN_N_RESULTS
} lr_sacn_result;

typedef struct lr_sacn_packet {
    uint8_t cid[16];
    char source_name[64];  /* NUL-terminated copy (a name filling all 64 bytes is cut at 63) */
    int priority;
    int sync_address;
    int sequence;
    int options;
    bool preview, terminated;
    int universe;
    int start_code;
    int n_slots;           /* 0..512 */
    const uint8_t *slots;  /* points into the parsed buffer */
} lr_sacn_packet;

/* Parses buf[0..len). Fills *out as far as the packet was read (all of it for LR_SACN_OK and
 * LR_SACN_START_CODE). Never reads outside buf. */
lr_sacn_result lr_sacn_parse(const uint8_t *buf, size_t len, lr_sacn_packet *out);
/* "ok", "short", "long", "preamble", "acn-id", ...: one word per kind, for stats and logs. */
const char *lr_sacn_result_name(lr_sacn_result r);
/* The multicast group of a universe (E1.31 9.3.1): 239.255.hi.lo, in host byte order. */
uint32_t lr_sacn_multicast_group(int universe);

#endif
