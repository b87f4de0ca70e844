/* Test support: a lighting console (OLA's olad, QLC+) run as a real peer in a network namespace
 * of its own, joined to the test's namespace by a veth pair (NET.1 on this side, NET.2 on the
 * console's), and QLC+'s web socket (its Simple Desk: "CH|address|value").
 *
 * The consoles bind fixed ports (5568, 6454, 9010, 9999) and OLA's E1.31 output does not work
 * on bare loopback, so a test first moves itself into a namespace of its own
 * (lr_test_netns_ok: root, unshare(CLONE_NEWNET), its loopback up) and then starts each
 * console in another one. Every step that cannot be taken here (not root, a program missing,
 * the veth pair refused) gives a reason for the test to print and skip on. */
#ifndef LR_TEST_CONSOLE_PEER_H
#define LR_TEST_CONSOLE_PEER_H

#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

/* A shell command line (printf format); its exit status, -1 when it did not exit. */
int lr_test_sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
/* Whether `prog` is on PATH. */
bool lr_test_have(const char *prog);

/* The test process in a network namespace of its own with its loopback up; tried once per
 * process, the reason kept (why: "..., skipped"). */
bool lr_test_netns_ok(char *why, size_t n);

typedef struct lr_test_peer {
    char ns[64];  /* the console's namespace, "lamprig-NAME-PID"; "" when none */
    char dir[64]; /* its scratch folder (config, workspace, log) */
    pid_t pid;    /* the console's process; 0 when none */
} lr_test_peer;

/* Namespace "lamprig-NAME-PID" and the veth pair veth-lNAME (here, NET.1/24) to veth-NAME
 * (there, NET.2/24), both loopbacks up, a multicast route there; the scratch folder
 * /tmp/lamprig-NAME.XXXXXX. NAME at most 8 characters (interface names). False with why. */
bool lr_test_peer_ns(lr_test_peer *p, const char *name, const char *net, char *why, size_t n);
/* Stops the console (SIGTERM, reaped), deletes the namespace and the folder; idempotent, safe
 * after a failed assertion (a teardown's). */
void lr_test_peer_stop(lr_test_peer *p);

/* OLA's daemon in p's namespace as its own user (setpriv, user olad), a fresh config folder
 * p->dir with every plugin off but E1.31 and Art-Net (one output port each, bound to ip, the
 * namespace's veth address), its log olad.log there. True once its RPC answers and lists both
 * devices (ola_dev_info, written to p->dir/devs); false after 10 s. */
bool lr_test_olad_start(lr_test_peer *p, const char *ip);
/* The device number of the line naming `kind` ("E1.31", "ArtNet") in p->dir/devs; -1: none. */
int lr_test_olad_device(const lr_test_peer *p, const char *kind);

/* QLC+ headless (offscreen, --nogui --web) in p's namespace with `workspace` (a .qxw
 * document) written to p->dir/console.qxw, HOME and its log (qlcplus.log) in p->dir. Its
 * loopback goes down first: QLC+ sends its E1.31 and Art-Net output from the first address
 * its interface list gives, and 127.0.0.1 would come first. */
void lr_test_qlc_start(lr_test_peer *p, const char *workspace);
/* A web socket to QLC+ at host:9999 (RFC 6455, the smallest client: the upgrade answered 101);
 * -1 when it is not (yet) there. */
int lr_test_qlc_ws_open(const char *host);
/* One masked text frame (under 126 bytes), e.g. "CH|513|255". */
void lr_test_qlc_ws_text(int fd, const char *text);

#endif
