/* lamprig tests — several rigs in step over MQTT (firmware/rig/mqtt.h, mqtt_payload.h).
 *
 * Unit part: the payload parser's values and refusals (each naming the topic and field), the
 * committed fuzz corpus replayed through it (tests/fuzz/), the config's "mqtt" block.
 * System part (root: network namespaces): a real mosquitto broker with a config file of its
 * own and two `lamprig run --headless` rigs (this binary re-executed as lamprig, under the
 * same sanitizers) in two network namespaces joined by a veth pair; the broker and rig a in
 * one, rig b in the other. The rigs start before the broker and connect when it appears. A change published once reaches both and shows in frames whose
 * times differ by at most one frame interval; the broker restarts and a rig restarts, and the
 * restarted rig picks up the retained state; a reload keeps the link; a bad payload is
 * counted, never applied; a killed rig's last will says "offline".
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <fcntl.h>
#include <math.h>
#include <mosquitto.h>
#include <sched.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include <arpa/inet.h>
#include <netinet/in.h>

#include "firmware/cli.h"
#include "firmware/rig/config.h"
#include "firmware/rig/mqtt.h"
#include "firmware/rig/mqtt_payload.h"
#include "render/base/json.h"
#include "tests/support/fs.h"
#include "tests/support/modbus_server.h"

/* The libFuzzer harness itself, renamed: the corpus test runs its checks (tests/fuzz/). */
#define LLVMFuzzerTestOneInput fuzz_mqtt_payload
#include "tests/fuzz/fuzz_mqtt_payload.c"
#undef LLVMFuzzerTestOneInput

#define CHILD_FLAG "--as-lamprig"
#define PORT 18830
/* 10 fps: one frame interval (the bound) is 100 ms, above the scheduling delays of a loaded
 * 2-core machine running two sanitized rigs and a broker (5-9 ms measured idle, one run at
 * load: both rigs 365 ms late, 5 ms apart). */
#define FPS 10
#define FRAME_NS (1000000000LL / FPS)
/* The rigs run on one machine: one CLOCK_REALTIME, offset 0. */
#define CLOCK_OFFSET_NS 0
/* Time between publishing and apply_at: delivery to both rigs (a few ms on a veth pair) with
 * room for a loaded 2-core machine and the sanitizers. */
#define LEAD_NS 700000000LL

/* ---- unit part ---- */

static void test_payload_values(void **state)
{
    (void)state;
    lr_mqtt_cmd c;
    lr_err e = {0};
    const char *p = "{\"value\": 0.25, \"apply_at\": 1764720000123456789}";
    assert_int_equal(lr_mqtt_payload_parse("lamprig/all/control/dimmer", p, strlen(p), &c, &e),
                     LR_OK);
    assert_int_equal(c.kind, LR_MQTT_CONTROL);
    assert_string_equal(c.name, "dimmer");
    assert_true(c.value == 0.25);
    assert_true(c.has_apply_at);
    /* An integer of nanoseconds is read exactly (a double would round it to 256 ns). */
    assert_true(c.apply_at_ns == 1764720000123456789LL);
    p = "{\"value\": \"votive\", \"apply_at\": 1764720000.5}";
    assert_int_equal(lr_mqtt_payload_parse("lamprig/all/scene", p, strlen(p), &c, &e), LR_OK);
    assert_int_equal(c.kind, LR_MQTT_SCENE);
    assert_string_equal(c.scene, "votive");
    /* Seconds: 1764720000.5 s is exact in a double (33 bits of integer, one of fraction). */
    assert_true(c.apply_at_ns == 1764720000500000000LL);
    p = "{\"value\": 1}";
    assert_int_equal(lr_mqtt_payload_parse("lamprig/all/control/knob1", p, strlen(p), &c, &e),
                     LR_OK);
    assert_false(c.has_apply_at);
    assert_int_equal(lr_mqtt_payload_parse("lamprig/all/control/knob1", "", 0, &c, &e), LR_OK);
    assert_true(c.cleared);
    /* What mqtt-send writes reads back to the same command. */
    lr_mqtt_cmd w = {.kind = LR_MQTT_SCENE, .has_apply_at = true,
                     .apply_at_ns = 1764720000999999999LL};
    snprintf(w.scene, sizeof w.scene, "a \"quoted\" \\ name");
    char buf[512];
    int n = lr_mqtt_payload_format(&w, buf, sizeof buf);
    assert_true(n > 0);
    assert_int_equal(lr_mqtt_payload_parse("lamprig/all/scene", buf, (size_t)n, &c, &e), LR_OK);
    assert_string_equal(c.scene, w.scene);
    assert_true(c.apply_at_ns == w.apply_at_ns);
    w = (lr_mqtt_cmd){.kind = LR_MQTT_CONTROL, .value = 0.1};
    n = lr_mqtt_payload_format(&w, buf, sizeof buf);
    assert_int_equal(lr_mqtt_payload_parse("lamprig/all/control/x", buf, (size_t)n, &c, &e),
                     LR_OK);
    assert_true(c.value == 0.1); /* %.17g reads back to the same double */
}

static void refused(const char *topic, const char *payload, const char *needle)
{
    lr_mqtt_cmd c;
    lr_err e = {0};
    if (lr_mqtt_payload_parse(topic, payload, strlen(payload), &c, &e) != LR_EPARSE)
        fail_msg("'%s' on %s was accepted", payload, topic);
    if (!strstr(e.msg, topic) || !strstr(e.msg, needle))
        fail_msg("'%s' on %s: got '%s', expected the topic and '%s'", payload, topic, e.msg,
                 needle);
}

static void test_payload_refusals(void **state)
{
    (void)state;
    const char *t = "lamprig/all/control/dimmer";
    refused(t, "0.5", "expected an object");
    refused(t, "{\"value\": 1.5}", "field 'value': must be in 0..1");
    refused(t, "{\"value\": -0.1}", "field 'value'");
    refused(t, "{\"value\": \"x\"}", "field 'value'");
    refused(t, "{\"apply_at\": 1}", "field 'value': required");
    refused(t, "{\"value\": 0.5, \"at\": 1}", "at");
    refused(t, "{\"value\": 0.5, \"apply_at\": -1}", "field 'apply_at'");
    refused(t, "{\"value\": 0.5, \"apply_at\": 1500000000000.5}", "whole number");
    refused(t, "{\"value\": 0.5, \"apply_at\": 9999999999}", "2262");
    refused(t, "{\"value\": 0.5,}", t);
    refused(t, "{\"value\": NaN}", t);
    refused("lamprig/all/scene", "{\"value\": 2}", "field 'value'");
    refused("lamprig/all/scene", "{\"value\": \"\"}", "must not be empty");
    refused("lamprig/all/control/a/b", "{\"value\": 0}", "not a command topic");
    refused("lamprig/all/control/", "{\"value\": 0}", "not a command topic");
    char big[LR_MQTT_PAYLOAD_MAX + 2];
    memset(big, ' ', sizeof big - 1);
    big[sizeof big - 1] = '\0';
    refused(t, big, "bytes");
}

/* The fuzz corpus (tests/fuzz/corpus/mqtt_payload/, the harness's seeds and what it found):
 * the harness's checks hold on every file (an accepted command in range and reading back the
 * same when formatted), every file parses or is refused with a message naming its topic, and
 * nothing trips ASan/UBSan. A file's first line is the topic, the rest the payload (the harness's format). */
static void test_fuzz_corpus(void **state)
{
    (void)state;
    const char *dir = LR_SOURCE_CONFIGS "/../tests/fuzz/corpus/mqtt_payload";
    DIR *d = opendir(dir);
    assert_non_null(d);
    int files = 0, ok = 0;
    struct dirent *de;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.')
            continue;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        size_t len;
        unsigned char *b = lr_test_read(path, &len);
        unsigned char *nl = memchr(b, '\n', len);
        char topic[256] = "";
        size_t tl = nl ? (size_t)(nl - b) : len;
        if (tl >= sizeof topic)
            tl = sizeof topic - 1;
        memcpy(topic, b, tl);
        topic[tl] = '\0';
        size_t off = nl ? (size_t)(nl - b) + 1 : len;
        lr_mqtt_cmd c;
        lr_err e = {0};
        fuzz_mqtt_payload(b, len); /* the harness's own checks: it aborts on a violation */
        int rc = lr_mqtt_payload_parse(topic, b + off, len - off, &c, &e);
        if (rc)
            assert_non_null(strstr(e.msg, topic[0] ? topic : "(null)") ? e.msg : NULL);
        else
            ok++;
        files++;
        free(b);
    }
    closedir(d);
    /* The seeds hold valid commands of both kinds and refusals of each kind. */
    assert_true(files >= 12);
    assert_true(ok >= 3 && ok < files);
}

static void test_config_mqtt(void **state)
{
    (void)state;
    const char *base = "{\"scene\": \"" LR_SOURCE_CONFIGS "/scenes/candle.json\", "
                       "\"controls\": [], ";
    char text[1024];
    lr_rig_config *c;
    lr_err e = {0};
    snprintf(text, sizeof text, "%s\n\"mqtt\": {\"broker\": \"10.0.0.1:1883\", \"rig\": \"r1\"}}",
             base);
    assert_int_equal(lr_rig_config_parse(text, "t.json", &c, &e), LR_OK);
    assert_true(c->mqtt.enabled);
    assert_string_equal(c->mqtt.host, "10.0.0.1");
    assert_int_equal(c->mqtt.port, 1883);
    assert_int_equal(c->mqtt.role, LR_RIG_MQTT_FOLLOWER);
    lr_rig_config_destroy(c);
    static const struct {
        const char *mqtt, *needle;
    } bad[] = {
        {"{\"broker\": \"10.0.0.1\", \"rig\": \"r\"}", "t.json:2: field 'mqtt.broker'"},
        {"{\"broker\": \"h:0\", \"rig\": \"r\"}", "field 'mqtt.broker'"},
        {"{\"broker\": \"h:1\", \"rig\": \"a/b\"}", "field 'mqtt.rig'"},
        {"{\"broker\": \"h:1\", \"rig\": \"#\"}", "field 'mqtt.rig'"},
        {"{\"broker\": \"h:1\"}", "field 'mqtt.rig': required"},
        {"{\"broker\": \"h:1\", \"rig\": \"r\", \"role\": \"boss\"}", "field 'mqtt.role'"},
        {"{\"broker\": \"h:1\", \"rig\": \"r\", \"keepalive_s\": 1}", "field 'mqtt.keepalive_s'"},
        {"{\"broker\": \"h:1\", \"rig\": \"r\", \"port\": 1}", "field 'mqtt.port': unknown"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        snprintf(text, sizeof text, "%s\n\"mqtt\": %s}", base, bad[i].mqtt);
        assert_int_equal(lr_rig_config_parse(text, "t.json", &c, &e), LR_EPARSE);
        if (!strstr(e.msg, bad[i].needle))
            fail_msg("%s: got '%s', expected '%s'", bad[i].mqtt, e.msg, bad[i].needle);
    }
}

/* ---- system part ---- */

typedef struct rigview {
    char doc[8192]; /* the last status document */
    bool offline;
    int docs;
} rigview;

typedef struct world {
    char *dir;
    char ns_a[32], ns_b[32];
    char addr_a[32], addr_b[32];
    int home_ns; /* this process's own network namespace */
    char self[1024];
    pid_t broker, rig_a, rig_b;
    struct mosquitto *cli;
    rigview a, b;
    bool lib; /* mosquitto_lib_init done */
    lr_test_mb_server *panel; /* rig a's Modbus dimmer panel (rig a is the leader) */
} world;

static int64_t rt_ns(void) { return lr_mqtt_realtime_ns(); }

static int sh(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static int sh(const char *fmt, ...)
{
    char cmd[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    return system(cmd);
}

static void enter_ns(const char *name)
{
    char p[128];
    snprintf(p, sizeof p, "/var/run/netns/%s", name);
    int fd = open(p, O_RDONLY | O_CLOEXEC);
    if (fd < 0 || setns(fd, CLONE_NEWNET) != 0)
        _exit(126);
    close(fd);
}

/* fork + exec with output to dir/log, in network namespace ns. */
static pid_t spawn(world *w, const char *ns, const char *log, char *const argv[])
{
    char *out = lr_test_path(w->dir, log);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        prctl(PR_SET_PDEATHSIG, SIGKILL); /* a test that dies leaves no broker or rig behind */
        enter_ns(ns);
        int fd = open(out, O_WRONLY | O_CREAT | O_APPEND, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
        }
        execv(argv[0], argv);
        _exit(127);
    }
    free(out);
    return pid;
}

static void dump(world *w);

/* The child's wait status (-1: none running). */
static int stop(pid_t *pid, int sig)
{
    if (*pid <= 0)
        return -1;
    kill(*pid, sig);
    int st = -1;
    waitpid(*pid, &st, 0);
    *pid = 0;
    return st;
}

/* A rig stopped with SIGTERM exits 0: a clean shutdown, and no sanitizer report (ASan and
 * LSan make the status non-zero). */
static void assert_clean_exit(world *w, int st)
{
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        dump(w);
        fail_msg("rig exit status %d", st);
    }
}

static pid_t start_broker(world *w)
{
    char *conf = lr_test_path(w->dir, "mosquitto.conf");
    char *argv[] = {"/usr/sbin/mosquitto", "-c", conf, NULL};
    pid_t p = spawn(w, w->ns_a, "broker.log", argv);
    free(conf);
    /* Listening when a TCP connect from its namespace succeeds (this process is in it). */
    for (int i = 0; i < 300; i++) {
        int s = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        struct sockaddr_in sa = {.sin_family = AF_INET, .sin_port = htons(PORT)};
        inet_pton(AF_INET, w->addr_a, &sa.sin_addr);
        int rc = connect(s, (struct sockaddr *)&sa, sizeof sa);
        close(s);
        if (rc == 0)
            return p;
        usleep(10000);
    }
    fail_msg("the broker did not listen on %s:%d", w->addr_a, PORT);
    return p;
}

static pid_t start_rig(world *w, const char *name, const char *ns)
{
    char cfg[32], log[32];
    snprintf(cfg, sizeof cfg, "rig-%s.json", name);
    snprintf(log, sizeof log, "rig-%s.log", name);
    char *cp = lr_test_path(w->dir, cfg);
    /* --no-plan: the preview view needs no render settings; start-up and reload are faster. */
    char *argv[] = {w->self, CHILD_FLAG, "run", "--config", cp, "--headless", "--no-plan", NULL};
    pid_t p = spawn(w, ns, log, argv);
    free(cp);
    return p;
}

static void on_msg(struct mosquitto *m, void *obj, const struct mosquitto_message *msg)
{
    (void)m;
    world *w = obj;
    rigview *v = strcmp(msg->topic, "lamprig/a/status") == 0   ? &w->a
                 : strcmp(msg->topic, "lamprig/b/status") == 0 ? &w->b
                                                               : NULL;
    if (!v)
        return;
    size_t n = msg->payloadlen < (int)sizeof v->doc ? (size_t)msg->payloadlen : sizeof v->doc - 1;
    memcpy(v->doc, msg->payload, n);
    v->doc[n] = '\0';
    v->offline = strcmp(v->doc, "offline") == 0;
    v->docs++;
}

static void client_connect(world *w)
{
    if (w->cli) {
        mosquitto_destroy(w->cli);
        w->cli = NULL;
    }
    w->cli = mosquitto_new(NULL, true, w);
    assert_non_null(w->cli);
    mosquitto_message_callback_set(w->cli, on_msg);
    assert_int_equal(mosquitto_connect(w->cli, w->addr_a, PORT, 30), MOSQ_ERR_SUCCESS);
    assert_int_equal(mosquitto_subscribe(w->cli, NULL, "lamprig/+/status", 1), MOSQ_ERR_SUCCESS);
}

/* A number or integer field of a status document ("a.b" for a nested one); NAN when absent
 * or null. ns fields are read exactly as integers. */
static bool field(const char *doc, const char *key, const char *sub, int64_t *iv, double *dv)
{
    lr_json *j;
    if (lr_json_parse(doc, strlen(doc), "status", &j, NULL))
        return false;
    lr_jnode n = lr_json_get(j, lr_json_root(j), key);
    if (sub)
        n = lr_json_get(j, n, sub);
    bool ok = false;
    long l;
    double d;
    if (iv && lr_json_int(j, n, key, &l, NULL) == LR_OK) {
        *iv = l;
        ok = true;
    } else if (dv && lr_json_number(j, n, key, &d, NULL) == LR_OK) {
        *dv = d;
        ok = true;
    }
    lr_json_destroy(j);
    return ok;
}

static int64_t ifield(const char *doc, const char *key, const char *sub)
{
    int64_t v = -1;
    return field(doc, key, sub, &v, NULL) ? v : -1;
}

/* Runs the client until pred(w) or timeout; false on timeout. */
static bool wait_for(world *w, bool (*pred)(world *, const void *), const void *arg, int ms)
{
    for (int64_t end = rt_ns() + ms * 1000000LL; rt_ns() < end;) {
        if (pred(w, arg))
            return true;
        int rc = mosquitto_loop(w->cli, 50, 1);
        if (rc == MOSQ_ERR_CONN_LOST || rc == MOSQ_ERR_NO_CONN) {
            usleep(100000);
            mosquitto_reconnect(w->cli);
        }
    }
    return pred(w, arg);
}

static bool both_online(world *w, const void *arg)
{
    (void)arg;
    return w->a.docs && w->b.docs && !w->a.offline && !w->b.offline;
}

static bool connects_at_least(world *w, const void *arg)
{
    int64_t n = *(const int64_t *)arg;
    return !w->a.offline && !w->b.offline && ifield(w->a.doc, "mqtt", "connects") >= n &&
           ifield(w->b.doc, "mqtt", "connects") >= n;
}

/* Both rigs' last change is the one with this apply_at, and its frame is recorded. */
static bool framed(const rigview *v, int64_t at)
{
    return ifield(v->doc, "last_change", "apply_at_ns") == at &&
           ifield(v->doc, "last_change", "frame_ns") > 0;
}

static bool both_framed(world *w, const void *arg)
{
    int64_t at = *(const int64_t *)arg;
    return framed(&w->a, at) && framed(&w->b, at);
}

/* Both rigs' last change is a dimmer at 0.55 with the same apply_at. */
static bool both_leader_value(world *w, const void *arg)
{
    (void)arg;
    double va = NAN, vb = NAN;
    field(w->a.doc, "last_change", "value", NULL, &va);
    field(w->b.doc, "last_change", "value", NULL, &vb);
    int64_t at = ifield(w->a.doc, "last_change", "apply_at_ns");
    return va == 0.55 && vb == 0.55 && at > 0 &&
           at == ifield(w->b.doc, "last_change", "apply_at_ns");
}

static bool b_framed(world *w, const void *arg)
{
    return framed(&w->b, *(const int64_t *)arg) && !w->b.offline;
}

static bool b_bad(world *w, const void *arg)
{
    return ifield(w->b.doc, "mqtt", "bad") >= *(const int64_t *)arg;
}

static bool a_reloaded(world *w, const void *arg)
{
    (void)arg;
    return ifield(w->a.doc, "reloads", NULL) == 1;
}

static bool a_offline(world *w, const void *arg)
{
    (void)arg;
    return w->a.offline;
}

static bool b_offline(world *w, const void *arg)
{
    (void)arg;
    return w->b.offline;
}

static int64_t publish(world *w, const char *topic_leaf, const char *value_json, int64_t at)
{
    char topic[128], payload[256];
    snprintf(topic, sizeof topic, "lamprig/all/%s", topic_leaf);
    snprintf(payload, sizeof payload, "{\"value\": %s, \"apply_at\": %lld}", value_json,
             (long long)at);
    assert_int_equal(mosquitto_publish(w->cli, NULL, topic, (int)strlen(payload), payload, 1,
                                       true),
                     MOSQ_ERR_SUCCESS);
    return at;
}

/* Waits until dir/name holds needle. */
static bool log_has(world *w, const char *name, const char *needle, int ms)
{
    char *p = lr_test_path(w->dir, name);
    bool found = false;
    for (int i = 0; i <= ms / 20 && !found; i++) {
        FILE *f = fopen(p, "r");
        char line[4096];
        while (f && !found && fgets(line, sizeof line, f))
            found = strstr(line, needle) != NULL;
        if (f)
            fclose(f);
        if (!found)
            usleep(20000);
    }
    free(p);
    return found;
}

/* `lamprig mqtt-send --control NAME --value V --lead-ms LEAD_NS` from the broker's namespace:
 * exit 0 and the line it prints; returns its apply_at. */
static int64_t mqtt_send(world *w, const char *name, const char *value)
{
    char broker[64], lead[32];
    snprintf(broker, sizeof broker, "%s:%d", w->addr_a, PORT);
    snprintf(lead, sizeof lead, "%lld", LEAD_NS / 1000000LL);
    char *argv[] = {w->self, CHILD_FLAG, "mqtt-send", "--broker", broker, "--control",
                    (char *)name, "--value", (char *)value, "--lead-ms", lead, NULL};
    int64_t before = rt_ns();
    pid_t p = spawn(w, w->ns_a, "send.log", argv);
    int st = stop(&p, 0);
    char *path = lr_test_path(w->dir, "send.log");
    size_t len;
    char *text = (char *)lr_test_read(path, &len);
    free(path);
    char topic[64];
    snprintf(topic, sizeof topic, "lamprig/all/control/%s {\"value\": %s, \"apply_at\": ", name,
             value);
    const char *at = strstr(text, topic);
    int64_t t = at ? strtoll(at + strlen(topic), NULL, 10) : -1;
    if (!WIFEXITED(st) || WEXITSTATUS(st) != 0 || t < before + LEAD_NS) {
        dump(w);
        fail_msg("mqtt-send: status %d, printed '%s'", st, text);
    }
    free(text);
    return t;
}

static void dump(world *w)
{
    static const char *const logs[] = {"broker.log", "rig-a.log", "rig-b.log"};
    for (int i = 0; i < 3; i++) {
        char *p = lr_test_path(w->dir, logs[i]);
        FILE *f = fopen(p, "r");
        if (f) {
            char line[1024];
            fprintf(stderr, "---- %s ----\n", logs[i]);
            while (fgets(line, sizeof line, f))
                fputs(line, stderr);
            fclose(f);
        }
        free(p);
    }
    fprintf(stderr, "---- a: %s\n---- b: %s\n", w->a.doc, w->b.doc);
}

/* The change with this apply_at showed on both rigs in step: neither before apply_at, and
 * their first frames after it differ by at most one frame interval plus the clocks' offset.
 * Why one interval: each rig wakes at apply_at (its poll deadline) and renders at once when
 * its previous frame is older than 1/fps, else at its next frame slot, at most 1/fps later;
 * the two rigs' slots are unrelated, so the two frames are within one interval of each other
 * (plus the wake-up and render time, which on an idle rig with the preview view is
 * milliseconds, and both rigs see the same load). */
static void check_in_step(world *w, int64_t at, const char *what)
{
    if (!wait_for(w, both_framed, &at, 15000)) {
        dump(w);
        fail_msg("%s: the change did not show on both rigs", what);
    }
    int64_t fa = ifield(w->a.doc, "last_change", "frame_ns");
    int64_t fb = ifield(w->b.doc, "last_change", "frame_ns");
    int64_t d = fa > fb ? fa - fb : fb - fa;
    fprintf(stderr, "%s: frames %.1f ms (a) and %.1f ms (b) after apply_at, %.1f ms apart\n",
            what, (fa - at) / 1e6, (fb - at) / 1e6, d / 1e6);
    assert_true(fa >= at && fb >= at);
    if (d > FRAME_NS + CLOCK_OFFSET_NS) {
        dump(w);
        fail_msg("%s: frames %lld ns apart, more than one frame interval (%lld ns)", what,
                 (long long)d, (long long)FRAME_NS);
    }
}

static void write_files(world *w)
{
    char text[2048];
    snprintf(text, sizeof text,
             "listener %d %s\nallow_anonymous true\npersistence true\n"
             "persistence_location %s/\nuser root\n",
             PORT, w->addr_a, w->dir);
    free(lr_test_write(w->dir, "mosquitto.conf", text, (size_t)-1));
    for (int i = 0; i < 2; i++) {
        /* Rig a is the leader, its dimmer a Modbus panel (this process serves it, in rig a's
         * namespace); rig b has no device. */
        char dev[256] = "";
        if (i == 0)
            snprintf(dev, sizeof dev,
                     "{\"type\": \"modbus\", \"name\": \"panel\", \"url\": "
                     "\"tcp://127.0.0.1:%d\", \"poll_ms\": 20, \"inputs\": [{\"control\": "
                     "\"dimmer\", \"unit\": 1, \"reg\": 0, \"raw_max\": 1000}]}",
                     lr_test_mb_server_port(w->panel));
        /* preview: a cheap CPU view; the flame steady, so an idle rig renders only changes. */
        snprintf(text, sizeof text,
                 "{\"scene\": \"%s/scenes/candle.json\",\n"
                 " \"scene_set\": {\"lights[0].flicker.amplitude\": 0},\n"
                 " \"devices\": [%s],\n"
                 " \"controls\": \"%s/controls/candle.json\",\n"
                 " \"output\": {\"mode\": \"headless\", \"width\": 64, \"height\": 48, "
                 "\"fps\": %d, \"renderer\": \"preview\"},\n"
                 " \"mqtt\": {\"broker\": \"%s:%d\", \"rig\": \"%s\", \"status_period_s\": 1,\n"
                 "          \"retry_min_ms\": 100, \"retry_max_ms\": 400%s}}\n",
                 LR_SOURCE_CONFIGS, dev, LR_SOURCE_CONFIGS, FPS, w->addr_a, PORT, i ? "b" : "a",
                 i ? "" : ", \"role\": \"leader\", \"lead_ms\": 700");
        free(lr_test_write(w->dir, i ? "rig-b.json" : "rig-a.json", text, (size_t)-1));
    }
}

/* cmocka's teardown: runs after a failed assertion too, so nothing is left behind. */
static int teardown_world(void **state)
{
    world *w = *state;
    if (w->cli)
        mosquitto_destroy(w->cli);
    stop(&w->rig_a, SIGKILL);
    stop(&w->rig_b, SIGKILL);
    stop(&w->broker, SIGKILL);
    if (w->home_ns >= 0) {
        setns(w->home_ns, CLONE_NEWNET);
        close(w->home_ns);
    }
    if (w->ns_a[0])
        sh("ip netns del %s 2>/dev/null; ip netns del %s 2>/dev/null", w->ns_a, w->ns_b);
    if (w->lib)
        mosquitto_lib_cleanup();
    if (w->panel) {
        lr_test_mb_server_stop(w->panel);
        lr_test_mb_server_free(w->panel);
    }
    if (w->dir)
        lr_test_rmtree(w->dir);
    free(w);
    return 0;
}

static int setup_world(void **state)
{
    world *w = calloc(1, sizeof *w);
    if (!w)
        return -1;
    w->home_ns = -1;
    *state = w;
    return 0;
}

static void test_two_rigs(void **state)
{
    if (geteuid() != 0 || access("/usr/sbin/mosquitto", X_OK) != 0 ||
        sh("command -v ip >/dev/null") != 0) {
        fprintf(stderr, "two rigs: needs root, ip(8) and mosquitto: skipped\n");
        skip();
    }
    world *w = *state;
    w->dir = lr_test_tmpdir();
    int id = (int)(getpid() % 200) + 20;
    snprintf(w->ns_a, sizeof w->ns_a, "lrmq-a-%d", (int)getpid());
    snprintf(w->ns_b, sizeof w->ns_b, "lrmq-b-%d", (int)getpid());
    snprintf(w->addr_a, sizeof w->addr_a, "10.231.%d.1", id);
    snprintf(w->addr_b, sizeof w->addr_b, "10.231.%d.2", id);
    ssize_t sl = readlink("/proc/self/exe", w->self, sizeof w->self - 1);
    assert_true(sl > 0);
    w->self[sl] = '\0';
    char va[16], vb[16];
    snprintf(va, sizeof va, "lrmqa%d", (int)getpid() % 100000);
    snprintf(vb, sizeof vb, "lrmqb%d", (int)getpid() % 100000);
    int rc = sh("ip netns add %s && ip netns add %s && "
                "ip link add %s type veth peer name %s && "
                "ip link set %s netns %s && ip link set %s netns %s && "
                "ip -n %s addr add %s/24 dev %s && ip -n %s addr add %s/24 dev %s && "
                "ip -n %s link set %s up && ip -n %s link set %s up && "
                "ip -n %s link set lo up && ip -n %s link set lo up",
                w->ns_a, w->ns_b, va, vb, va, w->ns_a, vb, w->ns_b, w->ns_a, w->addr_a, va, w->ns_b,
                w->addr_b, vb, w->ns_a, va, w->ns_b, vb, w->ns_a, w->ns_b);
    if (rc != 0) {
        fprintf(stderr, "two rigs: cannot create network namespaces here: skipped\n");
        skip();
    }
    w->home_ns = open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
    enter_ns(w->ns_a); /* this process's client talks to the broker from its namespace */
    mosquitto_lib_init();
    w->lib = true;
    w->panel = lr_test_mb_server_start(); /* on 127.0.0.1 of this namespace */
    write_files(w);

    /* The rigs start before the broker: each says once that it is unreachable, runs on, and
     * connects when it appears (the backoff's retries). */
    w->rig_a = start_rig(w, "a", w->ns_a);
    w->rig_b = start_rig(w, "b", w->ns_b); /* across the veth pair */
    if (!log_has(w, "rig-a.log", "unreachable", 60000) ||
        !log_has(w, "rig-b.log", "unreachable", 60000)) {
        dump(w);
        fail_msg("the rigs did not report the missing broker");
    }
    w->broker = start_broker(w);
    client_connect(w);
    int64_t at;
    if (!wait_for(w, both_online, NULL, 60000)) { /* start-up under the sanitizers */
        dump(w);
        fail_msg("the rigs did not come online");
    }

    /* 0. The leader's own panel moves (0 -> 0.55): rig a sends the position to every rig and
     * applies it when it comes back, in step with rig b, and only then (one event, not two). */
    int64_t ev_a = ifield(w->a.doc, "events", NULL);
    lr_test_mb_server_set_reg(w->panel, 1, 0, 550);
    if (!wait_for(w, both_leader_value, NULL, 15000)) {
        dump(w);
        fail_msg("the leader's panel did not reach both rigs");
    }
    at = ifield(w->a.doc, "last_change", "apply_at_ns");
    check_in_step(w, at, "dimmer 0.55 from the leader's panel");
    assert_int_equal(ifield(w->a.doc, "events", NULL), ev_a + 1);

    /* 1. One change, published once, in step on both rigs. */
    at = publish(w, "control/dimmer", "0.8", rt_ns() + LEAD_NS);
    check_in_step(w, at, "dimmer 0.8");
    assert_true(ifield(w->a.doc, "events", NULL) >= 1 && ifield(w->b.doc, "events", NULL) >= 1);

    /* 2. A bad payload: logged with its topic, counted, the rigs run on. */
    const char *junk = "{\"value\": \"loud\"}";
    int64_t bad0 = ifield(w->b.doc, "mqtt", "bad") + 1;
    assert_int_equal(mosquitto_publish(w->cli, NULL, "lamprig/all/control/dimmer",
                                       (int)strlen(junk), junk, 1, false),
                     MOSQ_ERR_SUCCESS);
    assert_true(wait_for(w, b_bad, &bad0, 10000));

    /* 3. The broker restarts (its retained messages persisted); both rigs reconnect and the
     * next change is in step again. */
    stop(&w->broker, SIGTERM);
    w->broker = start_broker(w);
    client_connect(w);
    int64_t two = 2;
    if (!wait_for(w, connects_at_least, &two, 20000)) {
        dump(w);
        fail_msg("the rigs did not reconnect after the broker restart");
    }
    at = mqtt_send(w, "dimmer", "0.3");
    check_in_step(w, at, "dimmer 0.3 (lamprig mqtt-send) after a broker restart");

    /* 4. Rig b restarts: "offline" on a clean stop, then it takes the retained state. */
    assert_clean_exit(w, stop(&w->rig_b, SIGTERM));
    assert_true(wait_for(w, b_offline, NULL, 10000));
    w->rig_b = start_rig(w, "b", w->ns_b);
    if (!wait_for(w, b_framed, &at, 60000)) {
        dump(w);
        fail_msg("the restarted rig did not pick up the retained dimmer");
    }
    double v = NAN;
    field(w->b.doc, "last_change", "value", NULL, &v);
    assert_true(v == 0.3);

    /* 5. Rig a reloads its config (SIGHUP, the same "mqtt" block): the link stays (no new
     * connect) and the next change, a scene of the cycle, is in step on both. */
    int64_t conn_a = ifield(w->a.doc, "mqtt", "connects");
    /* The panel first where the dimmer is (0.3): the reloaded panel's first reading then moves
     * nothing, so the leader sends nothing beside the scene below (a dimmer sent with about
     * the same apply_at would be each rig's last change instead). */
    lr_test_mb_server_set_reg(w->panel, 1, 0, 300);
    usleep(300000); /* 15 polls */
    kill(w->rig_a, SIGHUP);
    if (!wait_for(w, a_reloaded, NULL, 30000)) { /* seconds under the sanitizers */
        dump(w);
        fail_msg("rig a did not reload");
    }
    at = publish(w, "scene", "\"votive\"", rt_ns() + LEAD_NS);
    check_in_step(w, at, "scene votive after a reload of rig a");
    assert_int_equal(ifield(w->a.doc, "mqtt", "connects"), conn_a);
    assert_int_equal(ifield(w->a.doc, "reloads", NULL), 1);

    /* 6. A rig that dies: the broker publishes its last will. */
    stop(&w->rig_a, SIGKILL);
    assert_true(wait_for(w, a_offline, NULL, 10000));

    assert_clean_exit(w, stop(&w->rig_b, SIGTERM));
    /* The bad payload was logged naming its topic. */
    char *lb = lr_test_path(w->dir, "rig-b.log");
    size_t len;
    char *text = (char *)lr_test_read(lb, &len);
    free(lb);
    bool named = strstr(text, "mqtt: lamprig/all/control/dimmer:1: field 'value'") != NULL;
    free(text);
    if (!named)
        dump(w);
    assert_true(named);
}

int main(int argc, char **argv)
{
    if (argc >= 2 && !strcmp(argv[1], CHILD_FLAG))
        return lr_cli_main(argc - 1, argv + 1);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_payload_values),
        cmocka_unit_test(test_payload_refusals),
        cmocka_unit_test(test_fuzz_corpus),
        cmocka_unit_test(test_config_mqtt),
        cmocka_unit_test_setup_teardown(test_two_rigs, setup_world, teardown_world),
    };
    if (getenv("LR_TEST_FILTER"))
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
