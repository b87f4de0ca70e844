/* Test support: sACN and Art-Net packets laid out byte by byte from the standards' tables
 * (E1.31-2018 Table 4-1; Art-Net 4 ArtDmx/ArtPoll), independent of hal/'s parsers, a UDP
 * sender on loopback, and a TCP connect (the consoles' web sockets). */
#ifndef LR_TEST_DMX_BUILD_H
#define LR_TEST_DMX_BUILD_H

#include <stddef.h>
#include <stdint.h>

/* An E1.31 data packet; returns its length, 126 + n (b holds at least that). cid_last is the
 * CID's last byte (the rest fixed), so tests can speak as several sources. */
size_t lr_test_sacn_build(uint8_t *b, int universe, int priority, int seq, int options, int start,
                          const uint8_t *slots, int n, int cid_last);
/* ArtDmx: 18 + n bytes. */
size_t lr_test_artdmx_build(uint8_t *b, int port_address, const uint8_t *slots, int n);
/* ArtPoll: 14 bytes. */
size_t lr_test_artpoll_build(uint8_t *b);
/* A UDP socket bound to 127.0.0.1:port (0: any port); -1 on failure. */
int lr_test_udp_socket(int port);
/* Sends to 127.0.0.1:port; returns what sendto returns. */
long lr_test_udp_send(int fd, int port, const void *buf, size_t len);
/* A TCP connection to ip:port (IPv4 text), blocking; -1 when refused or unreachable. */
int lr_test_tcp_connect(const char *ip, int port);

#endif
