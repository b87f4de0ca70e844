/* Test support: consoles as peers in network namespaces (console_peer.h). */
#include "tests/support/console_peer.h"

#include <errno.h>
#include <poll.h>
#include <sched.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "tests/support/dmx_build.h"

int lr_test_sh(const char *fmt, ...)
{
    char cmd[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

bool lr_test_have(const char *prog)
{
    return lr_test_sh("command -v %s >/dev/null 2>&1", prog) == 0;
}

bool lr_test_netns_ok(char *why, size_t n)
{
    static int state; /* 0 not tried, 1 ok, -1 failed (reason kept) */
    static char reason[160];
    if (state == 0) {
        state = -1;
        if (!lr_test_have("ip") || !lr_test_have("setpriv"))
            snprintf(reason, sizeof reason, "ip or setpriv not installed (Debian iproute2, "
                     "util-linux): skipped");
        else if (geteuid() != 0)
            snprintf(reason, sizeof reason,
                     "not root: network namespaces and the consoles' users need it: skipped");
        else if (unshare(CLONE_NEWNET) != 0)
            snprintf(reason, sizeof reason, "unshare(CLONE_NEWNET): %s: skipped",
                     strerror(errno));
        else if (lr_test_sh("ip link set lo up") != 0)
            snprintf(reason, sizeof reason, "ip link set lo up failed: skipped");
        else
            state = 1;
    }
    snprintf(why, n, "%s", reason);
    return state == 1;
}

bool lr_test_peer_ns(lr_test_peer *p, const char *name, const char *net, char *why, size_t n)
{
    assert_true(strlen(name) <= 8);
    snprintf(p->ns, sizeof p->ns, "lamprig-%s-%d", name, (int)getpid());
    if (lr_test_sh("ip netns add %s && "
                   "ip link add veth-l%s type veth peer name veth-%s netns %s && "
                   "ip addr add %s.1/24 brd + dev veth-l%s && ip link set veth-l%s up && "
                   "ip -n %s link set lo up && ip -n %s addr add %s.2/24 brd + dev veth-%s && "
                   "ip -n %s link set veth-%s up && ip -n %s route add 224.0.0.0/4 dev veth-%s",
                   p->ns, name, name, p->ns, net, name, name, p->ns, p->ns, net, name, p->ns,
                   name, p->ns, name) != 0) {
        snprintf(why, n, "could not set up the veth pair to %s: skipped", p->ns);
        return false;
    }
    snprintf(p->dir, sizeof p->dir, "/tmp/lamprig-%s.XXXXXX", name);
    assert_non_null(mkdtemp(p->dir));
    return true;
}

void lr_test_peer_stop(lr_test_peer *p)
{
    if (p->pid > 0) {
        kill(p->pid, SIGTERM);
        waitpid(p->pid, NULL, 0);
    }
    if (p->ns[0])
        lr_test_sh("ip netns del %s 2>/dev/null", p->ns);
    if (p->dir[0])
        lr_test_sh("rm -rf %s", p->dir);
    memset(p, 0, sizeof *p);
}

void lr_test_qlc_start(lr_test_peer *p, const char *workspace)
{
    assert_int_equal(lr_test_sh("ip -n %s link set lo down", p->ns), 0);
    char ws[128];
    snprintf(ws, sizeof ws, "%s/console.qxw", p->dir);
    FILE *f = fopen(ws, "w");
    assert_non_null(f);
    fputs(workspace, f);
    fclose(f);
    p->pid = fork();
    assert_true(p->pid >= 0);
    if (p->pid == 0) {
        char log[128], env_home[128];
        snprintf(log, sizeof log, "%s/qlcplus.log", p->dir);
        snprintf(env_home, sizeof env_home, "HOME=%s", p->dir);
        if (!freopen(log, "w", stdout) || !freopen(log, "a", stderr))
            _exit(127);
        /* A fresh HOME: QLC+ reads and writes its settings there, never the user's. */
        execlp("ip", "ip", "netns", "exec", p->ns, "env", "QT_QPA_PLATFORM=offscreen", env_home,
               "XDG_RUNTIME_DIR=/tmp", "qlcplus", "--nowm", "--nogui", "--web", "--open", ws,
               (char *)NULL);
        _exit(127);
    }
}

int lr_test_qlc_ws_open(const char *host)
{
    int fd = lr_test_tcp_connect(host, 9999);
    if (fd < 0)
        return -1;
    char req[256];
    int n = snprintf(req, sizeof req,
                     "GET /qlcplusWS HTTP/1.1\r\nHost: %s:9999\r\nUpgrade: websocket\r\n"
                     "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
                     "Sec-WebSocket-Version: 13\r\n\r\n", host);
    char resp[512] = "";
    size_t got = 0;
    if (write(fd, req, (size_t)n) != n)
        goto fail;
    /* The answer's head, up to its blank line (QLC+ sends nothing after it unasked). */
    while (got < sizeof resp - 1 && !strstr(resp, "\r\n\r\n")) {
        struct pollfd pf = {.fd = fd, .events = POLLIN};
        if (poll(&pf, 1, 2000) != 1)
            goto fail;
        ssize_t k = read(fd, resp + got, sizeof resp - 1 - got);
        if (k <= 0)
            goto fail;
        got += (size_t)k;
        resp[got] = '\0';
    }
    if (strncmp(resp, "HTTP/1.1 101", 12) == 0)
        return fd;
fail:
    close(fd);
    return -1;
}

void lr_test_qlc_ws_text(int fd, const char *text)
{
    size_t n = strlen(text);
    assert_true(n < 126);
    uint8_t f[140];
    const uint8_t mask[4] = {0x12, 0x34, 0x56, 0x78};
    f[0] = 0x81;              /* FIN, text */
    f[1] = 0x80 | (uint8_t)n; /* masked (a client must), length */
    memcpy(f + 2, mask, 4);
    for (size_t i = 0; i < n; i++)
        f[6 + i] = (uint8_t)text[i] ^ mask[i % 4];
    assert_int_equal(write(fd, f, 6 + n), (ssize_t)(6 + n));
}

/* OLA's plugins: all off but E1.31 and Art-Net, bound to ip (a plugin probing USB and serial
 * devices would only slow the start). */
static void write_ola_config(const char *dir, const char *ip)
{
    static const char *const off[] = {"dummy", "espnet", "ftdidmx", "gpio", "karate", "kinet",
                                      "milinst", "opendmx", "openpixelcontrol", "osc",
                                      "pathport", "renard", "sandnet", "shownet", "spi",
                                      "stageprofi", "uartdmx", "usbdmx", "usbserial", NULL};
    char path[256];
    for (int i = 0; off[i]; i++) {
        snprintf(path, sizeof path, "%s/ola-%s.conf", dir, off[i]);
        FILE *f = fopen(path, "w");
        assert_non_null(f);
        fputs("enabled = false\n", f);
        fclose(f);
    }
    snprintf(path, sizeof path, "%s/ola-e131.conf", dir);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "enabled = true\nip = %s\ninput_ports = 0\noutput_ports = 1\n", ip);
    fclose(f);
    snprintf(path, sizeof path, "%s/ola-artnet.conf", dir);
    f = fopen(path, "w");
    assert_non_null(f);
    fprintf(f, "enabled = true\nip = %s\noutput_ports = 1\n", ip);
    fclose(f);
}

bool lr_test_olad_start(lr_test_peer *p, const char *ip)
{
    write_ola_config(p->dir, ip);
    assert_int_equal(lr_test_sh("chown -R olad %s", p->dir), 0);
    p->pid = fork();
    assert_true(p->pid >= 0);
    if (p->pid == 0) {
        char log[128];
        snprintf(log, sizeof log, "%s/olad.log", p->dir);
        if (!freopen(log, "w", stdout) || !freopen(log, "a", stderr))
            _exit(127);
        /* setpriv execs olad itself (no forking wrapper): the pid is olad's. */
        execlp("ip", "ip", "netns", "exec", p->ns, "setpriv", "--reuid=olad", "--regid=nogroup",
               "--clear-groups", "olad", "-c", p->dir, "--no-http", "--no-register-with-dns-sd",
               "-l", "3", (char *)NULL);
        _exit(127);
    }
    /* Ready when its RPC answers (about a second). */
    bool ready = false;
    for (int i = 0; i < 100 && !ready; i++) {
        usleep(100000);
        ready = lr_test_sh("ip netns exec %s ola_dev_info >%s/devs 2>/dev/null", p->ns, p->dir) ==
                    0 &&
                lr_test_sh("grep -q E1.31 %s/devs && grep -q ArtNet %s/devs", p->dir, p->dir) == 0;
    }
    return ready;
}

int lr_test_olad_device(const lr_test_peer *p, const char *kind)
{
    char path[128], line[256];
    snprintf(path, sizeof path, "%s/devs", p->dir);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    int n = -1;
    while (fgets(line, sizeof line, f))
        if (strstr(line, kind) && sscanf(line, "Device %d:", &n) == 1)
            break;
    fclose(f);
    return n;
}
