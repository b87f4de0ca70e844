/* lamprig firmware — the rig's MQTT link on its poll loop (see mqtt.h). */
#include "firmware/rig/mqtt.h"

#include <errno.h>
#include <math.h>
#include <mosquitto.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hal/backoff.h"

#define S_NS 1000000000LL
#define MS_NS 1000000LL
/* One pending command per topic (every binding and the scene) and the last applied per topic. */
#define MAX_KEYS (LR_RIG_MAX_BINDINGS + 1)
/* Packets read per wake at most: a late joiner's retained burst is read in a few wakes without
 * holding the loop. */
#define READS_PER_WAKE 64
#define SHUTDOWN_FLUSH_MS 200
/* Bad payloads: every one logged up to this many, then one line per 100. */
#define BAD_LOG_ALL 20

typedef enum { DOWN, CONNECTING, UP } link_state;

typedef struct slot {
    bool used;
    lr_mqtt_cmd cmd;
} slot;

struct lr_mqtt {
    lr_rig_mqtt cfg;
    const lr_rig_config *rig_cfg;
    lr_log log;
    void (*status_fn)(void *user, lr_rig_status *st);
    void *user;
    struct mosquitto *mosq;
    link_state state;
    bool ever_connected; /* first attempt: mosquitto_connect_async, then reconnect_async */
    lr_backoff bo;
    int64_t retry_ns, connect_deadline_ns, next_misc_ns, next_status_ns;
    bool outage_logged;
    bool refused;        /* CONNACK refused: drop after the read */
    bool status_now;
    slot pending[MAX_KEYS], applied[MAX_KEYS];
    lr_mqtt_counters cnt;
    lr_mqtt_last last;
    char status_topic[LR_RIG_NAME_MAX + 32];
    char where[160]; /* "HOST:PORT" for messages */
};

int64_t lr_mqtt_realtime_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (int64_t)ts.tv_sec * S_NS + ts.tv_nsec;
}

static int64_t mono_ns(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (int64_t)ts.tv_sec * S_NS + ts.tv_nsec;
}

bool lr_mqtt_same(const lr_rig_mqtt *a, const lr_rig_mqtt *b)
{
    return a->enabled == b->enabled && strcmp(a->host, b->host) == 0 && a->port == b->port &&
           strcmp(a->rig, b->rig) == 0 && a->role == b->role &&
           a->status_period_s == b->status_period_s && a->keepalive_s == b->keepalive_s &&
           a->retry_min_ms == b->retry_min_ms && a->retry_max_ms == b->retry_max_ms &&
           a->lead_ms == b->lead_ms;
}

static slot *find(slot *tab, const lr_mqtt_cmd *c, bool create)
{
    slot *free_slot = NULL;
    for (int i = 0; i < MAX_KEYS; i++) {
        if (tab[i].used && tab[i].cmd.kind == c->kind && strcmp(tab[i].cmd.name, c->name) == 0)
            return &tab[i];
        if (!tab[i].used && !free_slot)
            free_slot = &tab[i];
    }
    return create ? free_slot : NULL;
}

static bool same_cmd(const lr_mqtt_cmd *a, const lr_mqtt_cmd *b)
{
    return a->kind == b->kind && strcmp(a->name, b->name) == 0 && a->value == b->value &&
           strcmp(a->scene, b->scene) == 0 && a->has_apply_at == b->has_apply_at &&
           a->apply_at_ns == b->apply_at_ns;
}

/* The binding a control command addresses: by its name (which defaults to its control). */
static bool known_control(const lr_mqtt *m, const char *name)
{
    for (int i = 0; i < m->rig_cfg->n_bindings; i++)
        if (strcmp(m->rig_cfg->bindings[i].name, name) == 0 &&
            strcmp(m->rig_cfg->bindings[i].param, "scene") != 0)
            return true;
    return false;
}

static void bad(lr_mqtt *m, const char *topic, const char *why)
{
    m->cnt.bad++;
    if (m->cnt.bad <= BAD_LOG_ALL || m->cnt.bad % 100 == 0)
        lr_log_write(&m->log, LR_LOG_WARN, "mqtt: %s: %s; ignored (%llu bad so far)",
                     topic, why, (unsigned long long)m->cnt.bad);
}

void lr_mqtt_refuse(lr_mqtt *m, const lr_mqtt_cmd *c, const char *why)
{
    char topic[sizeof LR_MQTT_CONTROL_TOPIC + LR_MQTT_NAME_MAX];
    if (c->kind == LR_MQTT_SCENE)
        snprintf(topic, sizeof topic, "%s", LR_MQTT_SCENE_TOPIC);
    else
        snprintf(topic, sizeof topic, "%s%s", LR_MQTT_CONTROL_TOPIC, c->name);
    if (m->cnt.applied)
        m->cnt.applied--;
    bad(m, topic, why);
}

static void on_message(struct mosquitto *mosq, void *obj, const struct mosquitto_message *msg)
{
    (void)mosq;
    lr_mqtt *m = obj;
    lr_mqtt_cmd c;
    lr_err e = {0};
    m->cnt.received++;
    if (lr_mqtt_payload_parse(msg->topic, msg->payload, msg->payloadlen > 0 ? (size_t)msg->payloadlen : 0,
                              &c, &e)) {
        /* The parser's message starts with the topic (its "file"). */
        m->cnt.bad++;
        if (m->cnt.bad <= BAD_LOG_ALL || m->cnt.bad % 100 == 0)
            lr_log_write(&m->log, LR_LOG_WARN, "mqtt: %s; ignored (%llu bad so far)", e.msg,
                         (unsigned long long)m->cnt.bad);
        return;
    }
    if (c.kind == LR_MQTT_CONTROL && !known_control(m, c.name)) {
        bad(m, msg->topic, "no level or cycle binding of that name in this rig's config");
        return;
    }
    slot *p = find(m->pending, &c, !c.cleared);
    if (c.cleared) {
        if (p)
            p->used = false;
        return;
    }
    /* The broker sends the retained state again after every (re)connect: what was applied
     * already is not applied again (a knob moved here since stays where it is). */
    slot *a = find(m->applied, &c, false);
    if (msg->retain && a && same_cmd(&a->cmd, &c)) {
        if (p && same_cmd(&p->cmd, &c))
            p->used = false;
        return;
    }
    if (!p) {
        bad(m, msg->topic, "too many pending commands");
        return;
    }
    p->used = true;
    p->cmd = c;
}

static void subscribe(lr_mqtt *m)
{
    static const char *const topics[] = {LR_MQTT_CONTROL_TOPIC "+", LR_MQTT_SCENE_TOPIC};
    for (int i = 0; i < 2; i++) {
        int rc = mosquitto_subscribe(m->mosq, NULL, topics[i], 1);
        if (rc != MOSQ_ERR_SUCCESS)
            lr_log_write(&m->log, LR_LOG_ERROR, "mqtt: subscribe %s: %s", topics[i],
                         mosquitto_strerror(rc));
    }
}

static void on_connect(struct mosquitto *mosq, void *obj, int rc)
{
    (void)mosq;
    lr_mqtt *m = obj;
    if (rc != 0) {
        lr_log_write(&m->log, LR_LOG_ERROR, "mqtt: broker %s refused the connection: %s",
                     m->where, mosquitto_connack_string(rc));
        m->refused = true;
        return;
    }
    m->state = UP;
    m->cnt.connects++;
    m->outage_logged = false;
    lr_backoff_reset(&m->bo);
    lr_log_write(&m->log, LR_LOG_INFO, "mqtt: connected to %s as rig '%s'%s", m->where,
                 m->cfg.rig,
                 m->cfg.role == LR_RIG_MQTT_STATUS   ? " (status only)"
                 : m->cfg.role == LR_RIG_MQTT_LEADER ? " (leader: its controls go to every rig)"
                                                     : "");
    if (m->cfg.role != LR_RIG_MQTT_STATUS)
        subscribe(m);
    m->status_now = true;
}

static void schedule_retry(lr_mqtt *m, int64_t now, const char *why)
{
    m->state = DOWN;
    m->retry_ns = lr_backoff_fail(&m->bo, now);
    if (!m->outage_logged) {
        lr_log_write(&m->log, LR_LOG_WARN,
                     "mqtt: broker %s: %s; retrying every %.3g..%.3g s until it answers",
                     m->where, why, m->bo.min_ns / 1e9, m->bo.max_ns / 1e9);
        m->outage_logged = true;
    }
}

static void on_disconnect(struct mosquitto *mosq, void *obj, int rc)
{
    (void)mosq;
    lr_mqtt *m = obj;
    if (m->state == DOWN)
        return;
    bool was_up = m->state == UP;
    char why[128];
    snprintf(why, sizeof why, "%s (%s)", was_up ? "connection lost" : "unreachable",
             rc == MOSQ_ERR_ERRNO ? strerror(errno) : mosquitto_strerror(rc));
    if (was_up)
        m->outage_logged = false; /* a new outage: say so once */
    schedule_retry(m, mono_ns(), why);
}

static void start_connect(lr_mqtt *m, int64_t now)
{
    m->refused = false;
    errno = 0;
    int rc = m->ever_connected
                 ? mosquitto_reconnect_async(m->mosq)
                 : mosquitto_connect_async(m->mosq, m->cfg.host, m->cfg.port, m->cfg.keepalive_s);
    m->ever_connected = true;
    if (rc != MOSQ_ERR_SUCCESS) {
        char why[128];
        snprintf(why, sizeof why, "unreachable (%s)",
                 rc == MOSQ_ERR_ERRNO ? strerror(errno) : mosquitto_strerror(rc));
        schedule_retry(m, now, why);
        return;
    }
    m->state = CONNECTING;
    /* No CONNACK within a keepalive: try again (a peer that accepts and says nothing). */
    m->connect_deadline_ns = now + (int64_t)m->cfg.keepalive_s * S_NS;
}

int lr_mqtt_create(const lr_mqtt_desc *d, int64_t now_ns, lr_mqtt **out, lr_err *e)
{
    *out = NULL;
    if (!d || !d->cfg || !d->cfg->mqtt.enabled)
        return lr_err_set(e, LR_EINVAL, "mqtt: no \"mqtt\" block in the config");
    lr_mqtt *m = calloc(1, sizeof *m);
    if (!m)
        return lr_err_set(e, LR_ENOMEM, "mqtt: out of memory");
    m->cfg = d->cfg->mqtt;
    m->rig_cfg = d->cfg;
    m->log = d->log;
    m->status_fn = d->status;
    m->user = d->user;
    snprintf(m->where, sizeof m->where, "%s:%d", m->cfg.host, m->cfg.port);
    snprintf(m->status_topic, sizeof m->status_topic, "%s/%s/status", LR_MQTT_PREFIX,
             m->cfg.rig);
    lr_backoff_init(&m->bo, m->cfg.retry_min_ms, m->cfg.retry_max_ms);
    mosquitto_lib_init(); /* reference-counted by libmosquitto 2 */
    char id[LR_RIG_NAME_MAX + 16];
    snprintf(id, sizeof id, "lamprig-%s", m->cfg.rig);
    m->mosq = mosquitto_new(id, true, m);
    if (!m->mosq) {
        mosquitto_lib_cleanup();
        free(m);
        return lr_err_set(e, LR_ENOMEM, "mqtt: mosquitto_new: %s", strerror(errno));
    }
    static const char offline[] = "offline";
    int rc = mosquitto_will_set(m->mosq, m->status_topic, (int)strlen(offline), offline, 1, true);
    if (rc != MOSQ_ERR_SUCCESS) {
        lr_err_set(e, LR_EINVAL, "mqtt: last will on %s: %s", m->status_topic,
                   mosquitto_strerror(rc));
        lr_mqtt_destroy(m);
        return LR_EINVAL;
    }
    mosquitto_connect_callback_set(m->mosq, on_connect);
    mosquitto_disconnect_callback_set(m->mosq, on_disconnect);
    mosquitto_message_callback_set(m->mosq, on_message);
    m->next_status_ns = INT64_MAX;
    start_connect(m, now_ns);
    *out = m;
    return LR_OK;
}

void lr_mqtt_set_config(lr_mqtt *m, const lr_rig_config *cfg)
{
    m->rig_cfg = cfg;
    /* Pending commands for bindings the new config does not have are dropped. */
    for (int i = 0; i < MAX_KEYS; i++)
        if (m->pending[i].used && m->pending[i].cmd.kind == LR_MQTT_CONTROL &&
            !known_control(m, m->pending[i].cmd.name))
            m->pending[i].used = false;
}

int lr_mqtt_pollfd(const lr_mqtt *m, struct pollfd *fd)
{
    if (m->state == DOWN)
        return 0;
    int s = mosquitto_socket(m->mosq);
    if (s < 0)
        return 0;
    *fd = (struct pollfd){s, POLLIN, 0};
    if (mosquitto_want_write(m->mosq))
        fd->events |= POLLOUT;
    return 1;
}

int64_t lr_mqtt_deadline(const lr_mqtt *m, int64_t now_ns, int64_t now_rt_ns)
{
    int64_t t = INT64_MAX;
    switch (m->state) {
    case DOWN:
        t = m->retry_ns;
        break;
    case CONNECTING:
        t = m->connect_deadline_ns;
        break;
    case UP:
        t = m->status_now ? now_ns : m->next_status_ns;
        if (m->next_misc_ns < t)
            t = m->next_misc_ns;
        break;
    }
    if (m->refused)
        t = now_ns;
    for (int i = 0; i < MAX_KEYS; i++) {
        if (!m->pending[i].used)
            continue;
        const lr_mqtt_cmd *c = &m->pending[i].cmd;
        int64_t d = !c->has_apply_at || c->apply_at_ns <= now_rt_ns
                        ? now_ns
                        : now_ns + (c->apply_at_ns - now_rt_ns);
        if (d < t)
            t = d;
    }
    return t;
}

static void publish_status(lr_mqtt *m, int64_t now)
{
    m->status_now = false;
    m->next_status_ns = now + (int64_t)(m->cfg.status_period_s * 1e9);
    /* The rig's status is large (its controls): off the stack. */
    lr_rig_status *st = calloc(1, sizeof *st);
    if (!st)
        return;
    if (m->status_fn)
        m->status_fn(m->user, st);
    char *doc = lr_mqtt_status_json(m->cfg.rig, st, lr_mqtt_realtime_ns(), &m->cnt, &m->last);
    free(st);
    if (!doc)
        return;
    int rc = mosquitto_publish(m->mosq, NULL, m->status_topic, (int)strlen(doc), doc, 1, true);
    if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_NO_CONN && rc != MOSQ_ERR_CONN_LOST)
        lr_log_write(&m->log, LR_LOG_WARN, "mqtt: publish %s: %s", m->status_topic,
                     mosquitto_strerror(rc));
    free(doc);
}

void lr_mqtt_dispatch(lr_mqtt *m, short revents, int64_t now_ns)
{
    if (m->state == DOWN && now_ns >= m->retry_ns)
        start_connect(m, now_ns);
    if (m->state != DOWN && (revents & (POLLIN | POLLERR | POLLHUP))) {
        /* One packet per call when nothing is queued (libmosquitto): read on while the socket
         * has more, up to READS_PER_WAKE. */
        for (int i = 0; i < READS_PER_WAKE && m->state != DOWN; i++) {
            if (mosquitto_loop_read(m->mosq, 1) != MOSQ_ERR_SUCCESS)
                break;
            struct pollfd p = {mosquitto_socket(m->mosq), POLLIN, 0};
            if (p.fd < 0 || poll(&p, 1, 0) != 1)
                break;
        }
    }
    if (m->state != DOWN && (revents & POLLOUT) && mosquitto_want_write(m->mosq))
        mosquitto_loop_write(m->mosq, 1);
    if (m->refused) {
        m->refused = false;
        m->state = DOWN; /* before the disconnect: its callback then says nothing */
        mosquitto_disconnect(m->mosq);
        m->retry_ns = lr_backoff_fail(&m->bo, now_ns);
        return;
    }
    if (m->state == CONNECTING && now_ns >= m->connect_deadline_ns) {
        schedule_retry(m, now_ns, "no answer to CONNECT within the keepalive");
        return;
    }
    if (m->state == UP && now_ns >= m->next_misc_ns) {
        /* The keepalive: a PINGREQ when due, and a broker that stopped answering is dropped. */
        mosquitto_loop_misc(m->mosq);
        m->next_misc_ns = now_ns + (int64_t)m->cfg.keepalive_s * S_NS / 2;
    }
    if (m->state == UP && (m->status_now || now_ns >= m->next_status_ns))
        publish_status(m, now_ns);
}

bool lr_mqtt_take(lr_mqtt *m, int64_t now_rt_ns, lr_mqtt_cmd *out)
{
    slot *best = NULL;
    for (int i = 0; i < MAX_KEYS; i++) {
        slot *s = &m->pending[i];
        if (!s->used || (s->cmd.has_apply_at && s->cmd.apply_at_ns > now_rt_ns))
            continue;
        if (!best)
            best = s;
        else if ((s->cmd.kind == LR_MQTT_SCENE) != (best->cmd.kind == LR_MQTT_SCENE))
            best = s->cmd.kind == LR_MQTT_SCENE ? s : best;
        else if (s->cmd.apply_at_ns < best->cmd.apply_at_ns)
            best = s;
    }
    if (!best)
        return false;
    *out = best->cmd;
    best->used = false;
    slot *a = find(m->applied, out, true);
    if (a) {
        a->used = true;
        a->cmd = *out;
    }
    m->cnt.applied++;
    m->last = (lr_mqtt_last){.valid = true, .cmd = *out, .applied_rt_ns = now_rt_ns};
    return true;
}

bool lr_mqtt_pending_scene(const lr_mqtt *m, lr_mqtt_cmd *out)
{
    for (int i = 0; i < MAX_KEYS; i++)
        if (m->pending[i].used && m->pending[i].cmd.kind == LR_MQTT_SCENE) {
            *out = m->pending[i].cmd;
            return true;
        }
    return false;
}

void lr_mqtt_frame(lr_mqtt *m, uint64_t index, int64_t now_rt_ns)
{
    if (!m->last.valid || m->last.framed)
        return;
    m->last.framed = true;
    m->last.frame = index;
    m->last.frame_rt_ns = now_rt_ns;
    m->status_now = true; /* the change and its frame, published at once */
}

bool lr_mqtt_connected(const lr_mqtt *m) { return m->state == UP; }

bool lr_mqtt_publish_cmd(lr_mqtt *m, const lr_mqtt_cmd *c)
{
    if (m->state != UP)
        return false;
    char topic[sizeof LR_MQTT_CONTROL_TOPIC + LR_MQTT_NAME_MAX];
    if (c->kind == LR_MQTT_SCENE)
        snprintf(topic, sizeof topic, "%s", LR_MQTT_SCENE_TOPIC);
    else
        snprintf(topic, sizeof topic, "%s%s", LR_MQTT_CONTROL_TOPIC, c->name);
    char payload[6 * LR_MQTT_SCENE_MAX + 64];
    int len = lr_mqtt_payload_format(c, payload, sizeof payload);
    if (len < 0)
        return false;
    int rc = mosquitto_publish(m->mosq, NULL, topic, len, payload, 1, true);
    if (rc != MOSQ_ERR_SUCCESS) {
        lr_log_write(&m->log, LR_LOG_WARN, "mqtt: publish %s: %s", topic, mosquitto_strerror(rc));
        return false;
    }
    return true;
}

void lr_mqtt_get_counters(const lr_mqtt *m, lr_mqtt_counters *out) { *out = m->cnt; }

void lr_mqtt_destroy(lr_mqtt *m)
{
    if (!m)
        return;
    if (m->mosq && m->state == UP) {
        /* A clean disconnect sends no will: say "offline" ourselves, then let the socket take
         * it (bounded: shutdown must not hang on a stalled broker). */
        static const char offline[] = "offline";
        mosquitto_publish(m->mosq, NULL, m->status_topic, (int)strlen(offline), offline, 1,
                          true);
        m->state = DOWN; /* the disconnect's callback is no outage */
        mosquitto_disconnect(m->mosq);
        int64_t end = mono_ns() + SHUTDOWN_FLUSH_MS * MS_NS;
        while (mosquitto_want_write(m->mosq) && mosquitto_socket(m->mosq) >= 0) {
            int64_t left = end - mono_ns();
            if (left <= 0)
                break;
            struct pollfd p = {mosquitto_socket(m->mosq), POLLOUT, 0};
            if (poll(&p, 1, (int)(left / MS_NS) + 1) <= 0 ||
                mosquitto_loop_write(m->mosq, 1) != MOSQ_ERR_SUCCESS)
                break;
        }
        lr_log_write(&m->log, LR_LOG_INFO, "mqtt: disconnected from %s (status offline)",
                     m->where);
    }
    if (m->mosq) {
        mosquitto_destroy(m->mosq);
        mosquitto_lib_cleanup();
    }
    free(m);
}
