/* lamprig firmware — the MQTT topics and payloads the rigs share (firmware/rig/mqtt.h).
 *
 *   lamprig/all/control/NAME   {"value": V, "apply_at": T}   V a number in 0..1: the binding
 *                              named NAME (its "name", default its control) moves to that
 *                              position, as an absolute event of that control would
 *   lamprig/all/scene          {"value": "NAME", "apply_at": T}   NAME a scene of the config's
 *                              "scene" cycle (file name with or without ".json", or the path)
 *                              or a shipped scene (configs/scenes/NAME.json)
 *
 * T, optional, is when to apply it on the rig's CLOCK_REALTIME: an integer >= 10^12 is
 * nanoseconds since 1970 (1e12 ns is 16 minutes after the epoch, 1e12 s the year 33658: the
 * two cannot be confused), any other number seconds since 1970 (fractions allowed). Absent:
 * at once. An empty payload (a retained message being cleared) is no command and no error.
 *
 * Parsing is pure (no MQTT library): the libFuzzer harness tests/fuzz/fuzz_mqtt_payload.c runs
 * it on arbitrary bytes. Every refusal is one message naming the topic and the field.
 */
#ifndef LR_RIG_MQTT_PAYLOAD_H
#define LR_RIG_MQTT_PAYLOAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"

#define LR_MQTT_PREFIX "lamprig"
#define LR_MQTT_CONTROL_TOPIC LR_MQTT_PREFIX "/all/control/"
#define LR_MQTT_SCENE_TOPIC LR_MQTT_PREFIX "/all/scene"
/* Payloads longer than this are refused unread (a command is tens of bytes). */
#define LR_MQTT_PAYLOAD_MAX 1024
#define LR_MQTT_NAME_MAX 32
#define LR_MQTT_SCENE_MAX 256
/* An integer apply_at at or above this is nanoseconds, below it seconds. */
#define LR_MQTT_NS_THRESHOLD 1000000000000LL

typedef enum lr_mqtt_kind {
    LR_MQTT_NONE = 0, /* not a command topic */
    LR_MQTT_CONTROL,
    LR_MQTT_SCENE,
} lr_mqtt_kind;

typedef struct lr_mqtt_cmd {
    lr_mqtt_kind kind;
    char name[LR_MQTT_NAME_MAX];   /* control: the binding's name */
    bool cleared;                  /* empty payload: nothing to apply */
    double value;                  /* control: 0..1 */
    char scene[LR_MQTT_SCENE_MAX]; /* scene: the name as sent */
    bool has_apply_at;
    int64_t apply_at_ns;           /* CLOCK_REALTIME ns */
} lr_mqtt_cmd;

/* The command topic's kind and (control) name; LR_MQTT_NONE for any other topic, or a
 * control name that is empty, too long or has a further level. */
lr_mqtt_kind lr_mqtt_topic_parse(const char *topic, char name[LR_MQTT_NAME_MAX]);

/* Parses a payload received on topic into out. LR_EPARSE with "TOPIC:LINE: field 'F': ..."
 * (or "TOPIC: ...") for anything else: not JSON, unknown fields, a value of the wrong type
 * or outside 0..1, a negative or non-integral-nanosecond apply_at, a payload over
 * LR_MQTT_PAYLOAD_MAX bytes, a topic that is not a command topic. */
int lr_mqtt_payload_parse(const char *topic, const void *payload, size_t len, lr_mqtt_cmd *out,
                          lr_err *e);

/* Writes a command's payload ({"value": ..., "apply_at": NS}) into buf; the length, or -1
 * when it does not fit (6 * LR_MQTT_SCENE_MAX + 64 bytes always do). The scene name is
 * JSON-escaped; an apply_at below LR_MQTT_NS_THRESHOLD ns is written in seconds, so that
 * every command reads back the same. */
int lr_mqtt_payload_format(const lr_mqtt_cmd *c, char *buf, size_t cap);

#endif
