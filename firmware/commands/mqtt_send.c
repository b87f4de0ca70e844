/* lamprig mqtt-send — publish one command to every rig (firmware/rig/mqtt.h): a control value
 * or a scene, retained, applied by each rig at now + --lead-ms on its own clock. */
#include <errno.h>
#include <math.h>
#include <mosquitto.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "firmware/commands/commands.h"
#include "firmware/rig/mqtt.h"
#include "firmware/rig/mqtt_payload.h"

static int mqtt_send(const lr_cli *c);

static const lr_argspec opts[] = {
    {.name = "--broker", .type = LR_ARG_STRING, .metavar = "HOST:PORT", .flags = LR_ARG_REQUIRED,
     .help = "the broker (the rigs' mqtt.broker)"},
    {.name = "--control", .type = LR_ARG_STRING, .metavar = "NAME",
     .help = "a binding's name (configs/controls/*.json: dimmer, flicker, ...)"},
    {.name = "--value", .type = LR_ARG_NUMBER, .metavar = "X", .flags = LR_ARG_FLOOR, .min = 0,
     .max = 1, .help = "the control's position, 0..1 (with --control)"},
    {.name = "--scene", .type = LR_ARG_STRING, .metavar = "NAME",
     .help = "a scene of the rigs' scene cycle or configs/scenes (candle, votive, ...)"},
    {.name = "--lead-ms", .type = LR_ARG_INT, .metavar = "MS", .flags = LR_ARG_FLOOR, .min = 0,
     .max = 3600000,
     .help = "apply_at = now + MS on this machine's clock (default 250: delivery to\n"
             "every rig on a LAN with margin)"},
    {.name = "--now", .help = "no apply_at: each rig applies it when it arrives"},
    {.name = "--clear", .help = "remove the retained command (with --control or --scene)"},
    {0},
};

const lr_command lr_mqtt_send_command = {
    .name = "mqtt-send",
    .summary = "publish a control value or a scene to every rig over MQTT, applied in step",
    .about =
        "Publishes one command, retained (QoS 1), on lamprig/all/control/NAME or\n"
        "lamprig/all/scene with apply_at = now + --lead-ms (ns since 1970 on this machine's\n"
        "CLOCK_REALTIME). Every rig with an \"mqtt\" block applies it at its first frame after\n"
        "that time on its own clock, and a rig that starts later takes it from the broker.",
    .opts = opts,
    .notes =
        "The clocks of this machine and the rigs must agree (chrony; tools/install/README.md):\n"
        "their offset adds to the difference between the rigs' frames.\n"
        "\n"
        "Exit status: 0 the broker acknowledged the message; 1 no connection, or no\n"
        "acknowledgement within 5 s of connecting; 2 bad arguments.\n"
        "\n"
        "Examples:\n"
        "  lamprig mqtt-send --broker 192.168.1.10:1883 --control dimmer --value 0.8\n"
        "  lamprig mqtt-send --broker 192.168.1.10:1883 --scene votive --lead-ms 500\n"
        "  mosquitto_pub -h 192.168.1.10 -r -q 1 -t lamprig/all/control/dimmer \\\n"
        "      -m \"{\\\"value\\\": 0.8, \\\"apply_at\\\": $(( $(date +%s%N) + 250000000 ))}\"",
    .run = mqtt_send,
};

typedef struct sent {
    int mid;
    bool acked;
} sent;

static void on_publish(struct mosquitto *m, void *obj, int mid)
{
    (void)m;
    sent *s = obj;
    if (mid == s->mid)
        s->acked = true;
}

static int mqtt_send(const lr_cli *c)
{
    const lr_args *a = &c->args;
    lr_err e = {0};
    const char *control = lr_args_get(a, "--control"), *scene = lr_args_get(a, "--scene");
    bool clear = lr_args_has(a, "--clear");
    if (!control == !scene)
        return lr_cli_usage(c->path, "give one of --control NAME or --scene NAME");
    if (control && !clear && !lr_args_has(a, "--value"))
        return lr_cli_usage(c->path, "--control needs --value X (0..1)");
    if (scene && lr_args_has(a, "--value"))
        return lr_cli_usage(c->path, "--value goes with --control, not --scene");
    lr_mqtt_cmd cmd = {.kind = control ? LR_MQTT_CONTROL : LR_MQTT_SCENE};
    int st;
    if (control && !clear && (st = lr_cli_check(c, lr_args_double(a, "--value", &cmd.value, &e), &e)))
        return st;
    int lead_ms = 250;
    if (lr_args_has(a, "--lead-ms") &&
        (st = lr_cli_check(c, lr_args_int(a, "--lead-ms", &lead_ms, &e), &e)))
        return st;
    char topic[sizeof LR_MQTT_CONTROL_TOPIC + LR_MQTT_NAME_MAX];
    if (control) {
        char name[LR_MQTT_NAME_MAX];
        snprintf(topic, sizeof topic, "%s%s", LR_MQTT_CONTROL_TOPIC, control);
        if (strlen(control) >= LR_MQTT_NAME_MAX ||
            lr_mqtt_topic_parse(topic, name) != LR_MQTT_CONTROL || strpbrk(control, "+#"))
            return lr_cli_usage(c->path, "--control '%s': a binding name of 1..%d characters, "
                                "no '/', '+' or '#'", control, LR_MQTT_NAME_MAX - 1);
    } else {
        snprintf(topic, sizeof topic, "%s", LR_MQTT_SCENE_TOPIC);
        if (strlen(scene) >= LR_MQTT_SCENE_MAX)
            return lr_cli_usage(c->path, "--scene: at most %d characters", LR_MQTT_SCENE_MAX - 1);
        snprintf(cmd.scene, sizeof cmd.scene, "%s", scene);
    }
    const char *broker = lr_args_get(a, "--broker");
    char host[160];
    snprintf(host, sizeof host, "%s", broker);
    char *colon = strrchr(host, ':'), *end = NULL;
    long port = colon ? strtol(colon + 1, &end, 10) : 0;
    if (!colon || colon == host || !colon[1] || *end || port < 1 || port > 65535)
        return lr_cli_usage(c->path, "--broker '%s': expected HOST:PORT (port 1..65535)",
                            broker);
    *colon = '\0';
    char payload[6 * LR_MQTT_SCENE_MAX + 64] = "";
    int len = 0;
    if (!clear) {
        if (!lr_args_has(a, "--now")) {
            cmd.has_apply_at = true;
            cmd.apply_at_ns = lr_mqtt_realtime_ns() + (int64_t)lead_ms * 1000000LL;
        }
        len = lr_mqtt_payload_format(&cmd, payload, sizeof payload);
        if (len < 0)
            return lr_cli_fail(c->path, "payload too long");
    }
    mosquitto_lib_init();
    sent s = {0};
    struct mosquitto *m = mosquitto_new(NULL, true, &s);
    int rc = m ? MOSQ_ERR_SUCCESS : MOSQ_ERR_NOMEM;
    if (!rc) {
        mosquitto_publish_callback_set(m, on_publish);
        rc = mosquitto_connect(m, host, (int)port, 10);
    }
    if (!rc)
        rc = mosquitto_publish(m, &s.mid, topic, len, payload, 1, true);
    /* The broker's PUBACK, at most 5 s. */
    struct timespec t0, t;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    while (!rc && !s.acked) {
        rc = mosquitto_loop(m, 100, 1);
        clock_gettime(CLOCK_MONOTONIC, &t);
        if (!rc && t.tv_sec - t0.tv_sec >= 5)
            rc = MOSQ_ERR_TIMEOUT;
    }
    if (m && !rc)
        mosquitto_disconnect(m);
    int status = LR_EXIT_OK;
    if (rc)
        status = lr_cli_fail(c->path, "%s:%ld: %s", host, port,
                             rc == MOSQ_ERR_ERRNO ? strerror(errno) : mosquitto_strerror(rc));
    else
        printf("%s %s\n", topic, clear ? "(cleared)" : payload);
    mosquitto_destroy(m);
    mosquitto_lib_cleanup();
    return status;
}
