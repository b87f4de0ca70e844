/* hal/: the sACN (E1.31) and Art-Net packet parsers on packets built here byte by byte from the
 * standards' tables (not with the code under test), one broken field at a time; then the
 * libFuzzer harnesses (tests/fuzz/) on the committed corpus and on bounded deterministic
 * mutations of it, under ASan/UBSan. */
#include <dirent.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "hal/artnet_packet.h"
#include "hal/sacn_packet.h"
#include "tests/support/dmx_build.h"

/* The harnesses, under names of their own (each defines LLVMFuzzerTestOneInput). */
#define LLVMFuzzerTestOneInput fuzz_sacn
#include "tests/fuzz/fuzz_sacn_packet.c"
#undef LLVMFuzzerTestOneInput
#define LLVMFuzzerTestOneInput fuzz_artnet
#include "tests/fuzz/fuzz_artnet_packet.c"
#undef LLVMFuzzerTestOneInput

#define CORPUS LR_SOURCE_CONFIGS "/../tests/fuzz/corpus"

static void put16(uint8_t *p, unsigned v)
{
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}

/* tests/support/dmx_build.c lays the packets out per the standards' tables. */
static size_t sacn_build(uint8_t *b, int universe, int priority, int seq, int options, int start,
                         const uint8_t *slots, int n)
{
    return lr_test_sacn_build(b, universe, priority, seq, options, start, slots, n, 0xaf);
}

static void sacn_valid(void **state)
{
    (void)state;
    uint8_t b[LR_SACN_MAX_LEN], slots[512];
    for (int i = 0; i < 512; i++)
        slots[i] = (uint8_t)(i * 7);
    lr_sacn_packet p;
    size_t len = sacn_build(b, 63999, 200, 17, 0, 0, slots, 512);
    assert_int_equal(len, LR_SACN_MAX_LEN);
    assert_int_equal(lr_sacn_parse(b, len, &p), LR_SACN_OK);
    assert_int_equal(p.universe, 63999);
    assert_int_equal(p.priority, 200);
    assert_int_equal(p.sequence, 17);
    assert_int_equal(p.n_slots, 512);
    assert_ptr_equal(p.slots, b + 126);
    assert_int_equal(p.slots[511], (uint8_t)(511 * 7));
    assert_string_equal(p.source_name, "console");
    assert_int_equal(p.cid[15], 0xaf);
    assert_false(p.preview);
    assert_false(p.terminated);

    /* A short universe (24 slots), the options bits, a 64-byte name without its NUL. */
    len = sacn_build(b, 1, 0, 255, LR_SACN_BIT_PREVIEW | LR_SACN_BIT_TERMINATED, 0, slots, 24);
    memset(b + 44, 'x', 64);
    assert_int_equal(lr_sacn_parse(b, len, &p), LR_SACN_OK);
    assert_int_equal(p.n_slots, 24);
    assert_true(p.preview);
    assert_true(p.terminated);
    assert_int_equal(strlen(p.source_name), 63);

    /* No slots at all is a valid (if useless) packet: count 1, the START code. */
    len = sacn_build(b, 1, 100, 0, 0, 0, NULL, 0);
    assert_int_equal(lr_sacn_parse(b, len, &p), LR_SACN_OK);
    assert_int_equal(p.n_slots, 0);

    /* 0xDD per-address priority: well-formed, reported apart from level data. */
    len = sacn_build(b, 1, 100, 0, 0, 0xdd, slots, 8);
    assert_int_equal(lr_sacn_parse(b, len, &p), LR_SACN_START_CODE);
    assert_int_equal(p.start_code, 0xdd);

    /* Multicast group 239.255.hi.lo (E1.31 9.3.1): universe 1 and 63999 = 0xF9FF. */
    assert_int_equal(lr_sacn_multicast_group(1), 0xefff0001u);
    assert_int_equal(lr_sacn_multicast_group(63999), 0xeffff9ffu);
}

/* Each field broken on its own gives its own result. */
static void sacn_broken_fields(void **state)
{
    (void)state;
    uint8_t b[LR_SACN_MAX_LEN + 8], slots[512] = {0};
    lr_sacn_packet p;
    size_t len;
#define BREAK(stmt, want)                                                                        \
    do {                                                                                         \
        len = sacn_build(b, 1, 100, 0, 0, 0, slots, 16);                                         \
        stmt;                                                                                    \
        assert_string_equal(lr_sacn_result_name(lr_sacn_parse(b, len, &p)),                      \
                            lr_sacn_result_name(want));                                          \
    } while (0)
    BREAK((void)0, LR_SACN_OK);
    BREAK(len = 21, LR_SACN_SHORT);
    BREAK(b[1] = 0x11, LR_SACN_PREAMBLE);
    BREAK(b[3] = 0x01, LR_SACN_PREAMBLE);
    BREAK(b[8] = 'X', LR_SACN_ACN_ID);
    BREAK(b[15] = 1, LR_SACN_ACN_ID);
    BREAK(b[16] = 0x60 | (b[16] & 0x0f), LR_SACN_ROOT_LENGTH); /* flags 0x6 */
    BREAK(len -= 1, LR_SACN_ROOT_LENGTH);                       /* datagram cut */
    BREAK(b[21] = 0x05, LR_SACN_ROOT_VECTOR);
    BREAK(b[21] = 0x08, LR_SACN_EXTENDED);
    BREAK(b[39] += 1, LR_SACN_FRAMING_LENGTH);
    BREAK(b[43] = 0x01, LR_SACN_FRAMING_VECTOR);
    BREAK(b[108] = 201, LR_SACN_PRIORITY);
    BREAK(put16(b + 113, 0), LR_SACN_UNIVERSE);
    BREAK(put16(b + 113, 64000), LR_SACN_UNIVERSE);
    BREAK(b[116] -= 1, LR_SACN_DMP_LENGTH);
    BREAK(b[117] = 0x03, LR_SACN_DMP_VECTOR);
    BREAK(b[118] = 0xa2, LR_SACN_DMP_LAYOUT);
    BREAK(b[120] = 1, LR_SACN_DMP_LAYOUT);
    BREAK(b[122] = 2, LR_SACN_DMP_LAYOUT);
    BREAK(put16(b + 123, 16), LR_SACN_COUNT); /* one short of 17 */
    BREAK(put16(b + 123, 0), LR_SACN_COUNT);
    BREAK(b[125] = 0x17, LR_SACN_START_CODE);
#undef BREAK
    /* Truncated below the minimum with consistent lengths: short, not a field error. */
    len = sacn_build(b, 1, 100, 0, 0, 0, slots, 0) - 10;
    put16(b + 16, 0x7000 | (unsigned)(len - 16));
    assert_int_equal(lr_sacn_parse(b, len, &p), LR_SACN_SHORT);
    /* Oversized: 513 slots. */
    len = sacn_build(b, 1, 100, 0, 0, 0, slots, 512) + 1;
    assert_int_equal(lr_sacn_parse(b, len, &p), LR_SACN_LONG);
    /* Every result has its own name. */
    for (int i = 0; i < LR_SACN_N_RESULTS; i++)
        for (int k = 0; k < i; k++)
            assert_string_not_equal(lr_sacn_result_name(i), lr_sacn_result_name(k));
}

static size_t artdmx_build(uint8_t *b, int port_address, const uint8_t *slots, int n)
{
    return lr_test_artdmx_build(b, port_address, slots, n);
}

static void artnet_packets(void **state)
{
    (void)state;
    uint8_t b[1100], slots[512];
    for (int i = 0; i < 512; i++)
        slots[i] = (uint8_t)(255 - i);
    lr_artnet_packet p;
    size_t len = artdmx_build(b, 0x7fff, slots, 512);
    assert_int_equal(lr_artnet_parse(b, len, &p), LR_ARTNET_DMX);
    assert_int_equal(p.port_address, 0x7fff);
    assert_int_equal(p.n_slots, 512);
    assert_int_equal(p.slots[1], 254);
    /* Net 1, Sub-Net 2, Universe 3 = port-address 0x0123. */
    len = artdmx_build(b, 0x0123, slots, 2);
    assert_int_equal(lr_artnet_parse(b, len, &p), LR_ARTNET_DMX);
    assert_int_equal(p.port_address, 0x0123);
    /* Trailing bytes after Length slots are tolerated; fewer are not. */
    assert_int_equal(lr_artnet_parse(b, len + 4, &p), LR_ARTNET_DMX);
    assert_int_equal(lr_artnet_parse(b, len - 1, &p), LR_ARTNET_LENGTH);
    len = artdmx_build(b, 0, slots, 3);
    assert_int_equal(lr_artnet_parse(b, len, &p), LR_ARTNET_LENGTH); /* odd */
    len = artdmx_build(b, 0, slots, 0);
    assert_int_equal(lr_artnet_parse(b, len, &p), LR_ARTNET_LENGTH);
    len = artdmx_build(b, 0, slots, 512);
    put16(b + 16, 514);
    memset(b + len, 0, 2);
    assert_int_equal(lr_artnet_parse(b, len + 2, &p), LR_ARTNET_LENGTH);
    len = artdmx_build(b, 0, slots, 2);
    assert_int_equal(lr_artnet_parse(b, 17, &p), LR_ARTNET_SHORT);
    b[11] = 13;
    assert_int_equal(lr_artnet_parse(b, len, &p), LR_ARTNET_PROT_VERSION);
    b[11] = 14;
    b[7] = 'x';
    assert_int_equal(lr_artnet_parse(b, len, &p), LR_ARTNET_ID);
    assert_int_equal(lr_artnet_parse(b, 5, &p), LR_ARTNET_SHORT);
    memset(b, 0, sizeof b);
    memcpy(b, "Art-Net\0", 8);
    assert_int_equal(lr_artnet_parse(b, 1025, &p), LR_ARTNET_LONG);

    /* ArtPoll: 14 bytes; Art-Net 4's targeted form is longer and accepted. */
    memcpy(b, "Art-Net\0\x00\x20\x00\x0e\x02\x00", 14);
    assert_int_equal(lr_artnet_parse(b, 14, &p), LR_ARTNET_POLL);
    assert_int_equal(p.flags, 2);
    assert_int_equal(lr_artnet_parse(b, 20, &p), LR_ARTNET_POLL);
    assert_int_equal(lr_artnet_parse(b, 13, &p), LR_ARTNET_SHORT);
    /* ArtSync, and another node's ArtPollReply (no ProtVer): not ours, not bad. */
    b[9] = 0x52;
    assert_int_equal(lr_artnet_parse(b, 14, &p), LR_ARTNET_OTHER);
    b[9] = 0x21;
    b[11] = 0;
    assert_int_equal(lr_artnet_parse(b, 10, &p), LR_ARTNET_OTHER);
}

static void artnet_poll_reply_layout(void **state)
{
    (void)state;
    uint8_t r[LR_ARTNET_POLL_REPLY_LEN];
    lr_artnet_node n = {.ip = 0x7f000001, .short_name = "lamprig",
                        .long_name = "lamprig light table", .net = 1, .sub_net = 2,
                        .n_ports = 2, .universe = {3, 4}, .active = {true, false}};
    assert_int_equal(lr_artnet_poll_reply(&n, r), 239);
    assert_memory_equal(r, "Art-Net\0", 8);
    assert_int_equal(r[8] | r[9] << 8, LR_ARTNET_OP_POLL_REPLY);
    assert_memory_equal(r + 10, "\x7f\x00\x00\x01", 4);
    assert_int_equal(r[14] | r[15] << 8, 6454); /* Port: little-endian 0x1936 */
    assert_int_equal(r[18], 1);                 /* NetSwitch */
    assert_int_equal(r[19], 2);                 /* SubSwitch */
    assert_string_equal((const char *)r + 26, "lamprig");
    assert_string_equal((const char *)r + 44, "lamprig light table");
    assert_int_equal(r[173], 2);                /* NumPorts lo */
    assert_int_equal(r[174], 0x80);             /* PortTypes: output */
    assert_int_equal(r[182], 0x80);             /* GoodOutput */
    assert_int_equal(r[183], 0x00);
    assert_int_equal(r[190], 3);                /* SwOut */
    assert_int_equal(r[191], 4);
    assert_int_equal(r[211], 1);                /* BindIndex */
    /* The reply is what an Art-Net parser calls another node's traffic. */
    lr_artnet_packet p;
    assert_int_equal(lr_artnet_parse(r, sizeof r, &p), LR_ARTNET_OTHER);
}

/* Reads every file of a corpus folder and runs fn on it and on `mutations` variants of it
 * (xorshift-chosen byte flips, truncations, extensions). Returns the number of inputs run. */
static int run_corpus(const char *dir, int (*fn)(const uint8_t *, size_t), int mutations)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    struct dirent *de;
    int files = 0, runs = 0;
    uint64_t x = 0x9e3779b97f4a7c15ull;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.')
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        FILE *f = fopen(path, "rb");
        assert_non_null(f);
        uint8_t buf[2048];
        size_t n = fread(buf, 1, sizeof buf, f);
        fclose(f);
        files++;
        fn(buf, n);
        runs++;
        for (int m = 0; m < mutations; m++) {
            /* A heap copy of exactly the mutated length, so ASan sees one byte too far. */
            x ^= x << 13, x ^= x >> 7, x ^= x << 17;
            size_t len = n;
            switch (x % 4) {
            case 0: len = n ? (size_t)(x >> 8) % n : 0; break;    /* truncate */
            case 1: len = n + (size_t)(x >> 8) % 64; break;        /* extend */
            default: break;                                        /* flip bytes */
            }
            if (len > sizeof buf)
                len = sizeof buf;
            uint8_t *copy = malloc(len ? len : 1);
            for (size_t i = 0; i < len; i++)
                copy[i] = i < n ? buf[i] : (uint8_t)(x >> (i % 56));
            for (int k = 0; k < 1 + (int)((x >> 20) % 4) && len; k++) {
                x ^= x << 13, x ^= x >> 7, x ^= x << 17;
                copy[(size_t)(x >> 16) % len] ^= (uint8_t)(1u << (x % 8));
            }
            fn(copy, len);
            free(copy);
            runs++;
        }
    }
    closedir(d);
    assert_true(files >= 5); /* the committed seeds are there */
    return runs;
}

static int sacn_fn(const uint8_t *d, size_t n) { return fuzz_sacn(d, n); }
static int artnet_fn(const uint8_t *d, size_t n) { return fuzz_artnet(d, n); }

static void fuzz_corpus(void **state)
{
    (void)state;
    /* 2000 variants per seed: about 40000 parses, well under a second under ASan. */
    int a = run_corpus(CORPUS "/sacn", sacn_fn, 2000);
    int b = run_corpus(CORPUS "/artnet", artnet_fn, 2000);
    assert_true(a > 20000 && b > 10000);
    /* The seeds parse as their names say. */
    FILE *f = fopen(CORPUS "/sacn/full_512.bin", "rb");
    assert_non_null(f);
    uint8_t buf[1024];
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    lr_sacn_packet p;
    assert_int_equal(lr_sacn_parse(buf, n, &p), LR_SACN_OK);
    assert_int_equal(p.n_slots, 512);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(sacn_valid),
        cmocka_unit_test(sacn_broken_fields),
        cmocka_unit_test(artnet_packets),
        cmocka_unit_test(artnet_poll_reply_layout),
        cmocka_unit_test(fuzz_corpus),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
