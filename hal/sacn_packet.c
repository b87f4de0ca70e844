#include "hal/sacn_packet.h"

#include <string.h>

static const uint8_t ACN_ID[12] = {'A', 'S', 'C', '-', 'E', '1', '.', '1', '7', 0, 0, 0};

static unsigned be16(const uint8_t *p) { return (unsigned)p[0] << 8 | p[1]; }
static uint32_t be32(const uint8_t *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* A PDU's flags & length at off: flags 0x7, length covering the rest of the datagram. */
static bool flags_length_ok(const uint8_t *buf, size_t len, size_t off)
{
    unsigned v = be16(buf + off);
    return (v >> 12) == 0x7 && (v & 0x0fff) == len - off;
}

lr_sacn_result lr_sacn_parse(const uint8_t *buf, size_t len, lr_sacn_packet *out)
{
    memset(out, 0, sizeof *out);
    if (len < 22)
        return LR_SACN_SHORT;
    if (be16(buf) != 0x0010 || be16(buf + 2) != 0x0000)
        return LR_SACN_PREAMBLE;
    if (memcmp(buf + 4, ACN_ID, sizeof ACN_ID) != 0)
        return LR_SACN_ACN_ID;
    if (len > LR_SACN_MAX_LEN)
        return LR_SACN_LONG;
    uint32_t root_vector = be32(buf + 18);
    /* A data packet cut short is "short", not a length mismatch of its root layer. */
    if (root_vector == 0x00000004 && len < LR_SACN_MIN_LEN)
        return LR_SACN_SHORT;
    if (!flags_length_ok(buf, len, 16))
        return LR_SACN_ROOT_LENGTH;
    if (root_vector == 0x00000008)
        return LR_SACN_EXTENDED;
    if (root_vector != 0x00000004)
        return LR_SACN_ROOT_VECTOR;
    memcpy(out->cid, buf + 22, 16);
    if (!flags_length_ok(buf, len, 38))
        return LR_SACN_FRAMING_LENGTH;
    if (be32(buf + 40) != 0x00000002)
        return LR_SACN_FRAMING_VECTOR;
    memcpy(out->source_name, buf + 44, 63);
    out->source_name[63] = '\0';
    out->priority = buf[108];
    out->sync_address = (int)be16(buf + 109);
    out->sequence = buf[111];
    out->options = buf[112];
    out->preview = (buf[112] & LR_SACN_BIT_PREVIEW) != 0;
    out->terminated = (buf[112] & LR_SACN_BIT_TERMINATED) != 0;
    out->universe = (int)be16(buf + 113);
    if (out->priority > LR_SACN_PRIORITY_MAX)
        return LR_SACN_PRIORITY;
    if (out->universe < 1 || out->universe > LR_SACN_UNIVERSE_MAX)
        return LR_SACN_UNIVERSE;
    if (!flags_length_ok(buf, len, 115))
        return LR_SACN_DMP_LENGTH;
    if (buf[117] != 0x02)
        return LR_SACN_DMP_VECTOR;
    if (buf[118] != 0xa1 || be16(buf + 119) != 0x0000 || be16(buf + 121) != 0x0001)
        return LR_SACN_DMP_LAYOUT;
    unsigned count = be16(buf + 123);
    /* The count includes the START code; the datagram holds exactly that many values. */
    if (count < 1 || count > 513 || count != len - 125)
        return LR_SACN_COUNT;
    out->start_code = buf[125];
    out->n_slots = (int)count - 1;
    out->slots = buf + 126;
    return out->start_code == 0 ? LR_SACN_OK : LR_SACN_START_CODE;
}

const char *lr_sacn_result_name(lr_sacn_result r)
{
    static const char *const names[LR_SACN_N_RESULTS] = {
        [LR_SACN_OK] = "ok",
        [LR_SACN_SHORT] = "short",
        [LR_SACN_LONG] = "long",
        [LR_SACN_PREAMBLE] = "preamble",
        [LR_SACN_ACN_ID] = "acn-id",
        [LR_SACN_ROOT_LENGTH] = "root-length",
        [LR_SACN_ROOT_VECTOR] = "root-vector",
        [LR_SACN_EXTENDED] = "extended",
        [LR_SACN_FRAMING_LENGTH] = "framing-length",
        [LR_SACN_FRAMING_VECTOR] = "framing-vector",
        [LR_SACN_PRIORITY] = "priority",
        [LR_SACN_UNIVERSE] = "universe",
        [LR_SACN_DMP_LENGTH] = "dmp-length",
        [LR_SACN_DMP_VECTOR] = "dmp-vector",
        [LR_SACN_DMP_LAYOUT] = "dmp-layout",
        [LR_SACN_COUNT] = "count",
        [LR_SACN_START_CODE] = "start-code",
    };
    return (unsigned)r < LR_SACN_N_RESULTS ? names[r] : "?";
}

uint32_t lr_sacn_multicast_group(int universe)
{
    return (239u << 24) | (255u << 16) | ((unsigned)(universe >> 8) & 0xff) << 8 |
           ((unsigned)universe & 0xff);
}
