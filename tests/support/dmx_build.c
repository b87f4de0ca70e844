#include "tests/support/dmx_build.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

static void put16(uint8_t *p, unsigned v)
{
    p[0] = (uint8_t)(v >> 8);
    p[1] = (uint8_t)v;
}

size_t lr_test_sacn_build(uint8_t *b, int universe, int priority, int seq, int options, int start,
                          const uint8_t *slots, int n, int cid_last)
{
    size_t len = 126 + (size_t)n;
    memset(b, 0, len);
    put16(b + 0, 0x0010);                         /* preamble size */
    put16(b + 2, 0x0000);                         /* postamble size */
    memcpy(b + 4, "ASC-E1.17\0\0\0", 12);         /* ACN packet identifier */
    put16(b + 16, 0x7000 | (unsigned)(len - 16)); /* root flags & length */
    b[21] = 0x04;                                 /* VECTOR_ROOT_E131_DATA */
    for (int i = 0; i < 15; i++)
        b[22 + i] = (uint8_t)(0xa0 + i);          /* CID */
    b[37] = (uint8_t)cid_last;
    put16(b + 38, 0x7000 | (unsigned)(len - 38)); /* framing flags & length */
    b[43] = 0x02;                                 /* VECTOR_E131_DATA_PACKET */
    memcpy(b + 44, "console", 7);                 /* source name */
    b[108] = (uint8_t)priority;
    b[111] = (uint8_t)seq;
    b[112] = (uint8_t)options;
    put16(b + 113, (unsigned)universe);
    put16(b + 115, 0x7000 | (unsigned)(len - 115)); /* DMP flags & length */
    b[117] = 0x02;                                /* VECTOR_DMP_SET_PROPERTY */
    b[118] = 0xa1;                                /* address & data type */
    put16(b + 119, 0x0000);                       /* first property address */
    put16(b + 121, 0x0001);                       /* address increment */
    put16(b + 123, (unsigned)n + 1);              /* property value count: START code + slots */
    b[125] = (uint8_t)start;
    if (n)
        memcpy(b + 126, slots, (size_t)n);
    return len;
}

size_t lr_test_artdmx_build(uint8_t *b, int port_address, const uint8_t *slots, int n)
{
    memcpy(b, "Art-Net\0", 8);
    b[8] = 0x00; /* OpDmx 0x5000, little-endian */
    b[9] = 0x50;
    b[10] = 0;   /* ProtVer 14, big-endian */
    b[11] = 14;
    b[12] = 1;   /* Sequence */
    b[13] = 0;   /* Physical */
    b[14] = (uint8_t)(port_address & 0xff); /* SubUni */
    b[15] = (uint8_t)(port_address >> 8);   /* Net */
    put16(b + 16, (unsigned)n);
    if (n)
        memcpy(b + 18, slots, (size_t)n);
    return 18 + (size_t)n;
}

size_t lr_test_artpoll_build(uint8_t *b)
{
    memcpy(b, "Art-Net\0\x00\x20\x00\x0e\x02\x00", 14); /* OpPoll, ProtVer 14, TalkToMe 2 */
    return 14;
}

int lr_test_udp_socket(int port)
{
    int s = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (s < 0)
        return -1;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port),
                            .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    if (bind(s, (struct sockaddr *)&a, sizeof a) != 0) {
        close(s);
        return -1;
    }
    return s;
}

long lr_test_udp_send(int fd, int port, const void *buf, size_t len)
{
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port),
                            .sin_addr.s_addr = htonl(INADDR_LOOPBACK)};
    return (long)sendto(fd, buf, len, 0, (struct sockaddr *)&a, sizeof a);
}

int lr_test_tcp_connect(const char *ip, int port)
{
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port)};
    if (inet_pton(AF_INET, ip, &a.sin_addr) != 1)
        return -1;
    int s = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (s < 0)
        return -1;
    if (connect(s, (struct sockaddr *)&a, sizeof a) != 0) {
        close(s);
        return -1;
    }
    return s;
}
