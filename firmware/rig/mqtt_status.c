/* lamprig firmware — the status document a rig publishes on lamprig/RIG/status (mqtt.h): the
 * rig's status as GET /api/status has it (firmware/rig/status_json.h, one producer) and the
 * link's own members. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "firmware/rig/mqtt.h"
#include "render/base/json_write.h"

char *lr_mqtt_status_json(const char *rig, const lr_rig_status *st, int64_t now_rt_ns,
                          const lr_mqtt_counters *c, const lr_mqtt_last *last)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return NULL;
    lr_jw *w = lr_jw_create(f);
    if (!w) {
        fclose(f);
        free(buf);
        return NULL;
    }
    lr_jw_object(w, NULL);
    lr_jw_string(w, "rig", rig);
    lr_jw_string(w, "state", "online");
    /* ns since 1970 as an integer: the receiver compares it with other rigs' times. */
    lr_jw_int(w, "time_ns", (long)now_rt_ns);
    lr_status_json_members(w, st); /* the members GET /api/status has */
    lr_jw_object(w, "mqtt");
    lr_jw_int(w, "received", (long)c->received);
    lr_jw_int(w, "applied", (long)c->applied);
    lr_jw_int(w, "bad", (long)c->bad);
    lr_jw_int(w, "connects", (long)c->connects);
    lr_jw_object_end(w);
    if (last && last->valid) {
        lr_jw_object(w, "last_change");
        if (last->cmd.kind == LR_MQTT_SCENE) {
            lr_jw_string(w, "topic", LR_MQTT_SCENE_TOPIC);
            lr_jw_string(w, "value", last->cmd.scene);
        } else {
            char topic[sizeof LR_MQTT_CONTROL_TOPIC + LR_MQTT_NAME_MAX];
            snprintf(topic, sizeof topic, "%s%s", LR_MQTT_CONTROL_TOPIC, last->cmd.name);
            lr_jw_string(w, "topic", topic);
            lr_jw_number(w, "value", last->cmd.value);
        }
        if (last->cmd.has_apply_at)
            lr_jw_int(w, "apply_at_ns", (long)last->cmd.apply_at_ns);
        else
            lr_jw_null(w, "apply_at_ns");
        lr_jw_int(w, "applied_ns", (long)last->applied_rt_ns);
        if (last->framed) {
            lr_jw_int(w, "frame", (long)last->frame);
            lr_jw_int(w, "frame_ns", (long)last->frame_rt_ns);
        } else {
            lr_jw_null(w, "frame");
            lr_jw_null(w, "frame_ns");
        }
        lr_jw_object_end(w);
    } else {
        lr_jw_null(w, "last_change");
    }
    lr_jw_object_end(w);
    lr_err e = {0};
    int rc = lr_jw_finish(w, &e);
    fclose(f);
    if (rc) {
        free(buf);
        return NULL;
    }
    return buf;
}
