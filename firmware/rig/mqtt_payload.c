/* lamprig firmware — MQTT command topics and payloads (see mqtt_payload.h). */
#include "firmware/rig/mqtt_payload.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/json.h"

lr_mqtt_kind lr_mqtt_topic_parse(const char *topic, char name[LR_MQTT_NAME_MAX])
{
    name[0] = '\0';
    if (!topic)
        return LR_MQTT_NONE;
    if (strcmp(topic, LR_MQTT_SCENE_TOPIC) == 0)
        return LR_MQTT_SCENE;
    size_t n = strlen(LR_MQTT_CONTROL_TOPIC);
    if (strncmp(topic, LR_MQTT_CONTROL_TOPIC, n) != 0)
        return LR_MQTT_NONE;
    const char *rest = topic + n;
    size_t len = strlen(rest);
    if (!len || len >= LR_MQTT_NAME_MAX || strchr(rest, '/'))
        return LR_MQTT_NONE;
    memcpy(name, rest, len + 1);
    return LR_MQTT_CONTROL;
}

/* apply_at: an integer >= LR_MQTT_NS_THRESHOLD is ns (read exactly, as a long: a double
 * holds today's ns only to 256 ns), any other number seconds. */
static int apply_at(const lr_json *j, lr_jnode n, lr_mqtt_cmd *out, lr_err *e)
{
    double s;
    int rc = lr_json_number(j, n, "apply_at", &s, e);
    if (rc)
        return rc;
    if (s < 0)
        return lr_json_fail(j, n, "apply_at", e, LR_EPARSE, "must be >= 0, got %g", s);
    if (s >= (double)LR_MQTT_NS_THRESHOLD) {
        long ns;
        lr_err ie = {0};
        if (lr_json_int(j, n, "apply_at", &ns, &ie))
            return lr_json_fail(j, n, "apply_at", e, LR_EPARSE,
                                "%g: nanoseconds must be a whole number below 2^63", s);
        out->apply_at_ns = ns;
    } else if (s >= 9.2e9) {
        /* Seconds past 2^63 ns (the year 2262) do not fit the clock. */
        return lr_json_fail(j, n, "apply_at", e, LR_EPARSE,
                            "%g s is past the year 2262 (give nanoseconds as an integer)", s);
    } else {
        out->apply_at_ns = (int64_t)llround(s * 1e9);
    }
    out->has_apply_at = true;
    return LR_OK;
}

int lr_mqtt_payload_parse(const char *topic, const void *payload, size_t len, lr_mqtt_cmd *out,
                          lr_err *e)
{
    memset(out, 0, sizeof *out);
    out->kind = lr_mqtt_topic_parse(topic, out->name);
    if (out->kind == LR_MQTT_NONE)
        return lr_err_set(e, LR_EPARSE, "%s: not a command topic (%s+ or %s)",
                          topic ? topic : "(null)", LR_MQTT_CONTROL_TOPIC, LR_MQTT_SCENE_TOPIC);
    if (len == 0) {
        out->cleared = true;
        return LR_OK;
    }
    if (len > LR_MQTT_PAYLOAD_MAX)
        return lr_err_set(e, LR_EPARSE, "%s: payload of %zu bytes (at most %d)", topic, len,
                          LR_MQTT_PAYLOAD_MAX);
    lr_json *j;
    int rc = lr_json_parse(payload, len, topic, &j, e);
    if (rc)
        return rc;
    lr_jnode root = lr_json_root(j);
    static const char *const ok[] = {"value", "apply_at", NULL};
    if (lr_json_type(j, root) != LR_JSON_OBJECT)
        rc = lr_json_fail(j, root, "payload", e, LR_EPARSE, "expected an object, got %s",
                          lr_json_type_name(lr_json_type(j, root)));
    if (!rc)
        rc = lr_json_check_keys(j, root, "payload", ok, e);
    lr_jnode v = lr_json_get(j, root, "value");
    if (!rc && v == LR_JNONE)
        rc = lr_json_fail(j, root, "value", e, LR_EPARSE, "required field is missing");
    if (!rc && out->kind == LR_MQTT_CONTROL) {
        rc = lr_json_number(j, v, "value", &out->value, e);
        if (!rc && !(out->value >= 0 && out->value <= 1))
            rc = lr_json_fail(j, v, "value", e, LR_EPARSE,
                              "must be in 0..1 (the control's position), got %g", out->value);
    } else if (!rc) {
        rc = lr_json_string(j, v, "value", out->scene, sizeof out->scene, e);
        if (!rc && !out->scene[0])
            rc = lr_json_fail(j, v, "value", e, LR_EPARSE, "must not be empty");
    }
    lr_jnode at = lr_json_get(j, root, "apply_at");
    if (!rc && at != LR_JNONE)
        rc = apply_at(j, at, out, e);
    lr_json_destroy(j);
    return rc;
}

int lr_mqtt_payload_format(const lr_mqtt_cmd *c, char *buf, size_t cap)
{
    char val[6 * LR_MQTT_SCENE_MAX + 8]; /* every byte escaped as \u00XX at worst */
    if (c->kind == LR_MQTT_SCENE) {
        size_t k = 0;
        val[k++] = '"';
        for (const char *s = c->scene; *s; s++) {
            unsigned char ch = (unsigned char)*s;
            if (ch == '"' || ch == '\\') {
                val[k++] = '\\';
                val[k++] = (char)ch;
            } else if (ch < 0x20) {
                k += (size_t)snprintf(val + k, sizeof val - k, "\\u%04x", ch);
            } else {
                val[k++] = (char)ch;
            }
        }
        val[k++] = '"';
        val[k] = '\0';
    } else {
        /* The shortest of 15 and 17 significant digits that reads back to the same double
         * (17 always do): 0.4, not 0.40000000000000002. */
        snprintf(val, sizeof val, "%.15g", c->value);
        if (strtod(val, NULL) != c->value)
            snprintf(val, sizeof val, "%.17g", c->value);
    }
    int w;
    if (!c->has_apply_at)
        w = snprintf(buf, cap, "{\"value\": %s}", val);
    else if (c->apply_at_ns >= LR_MQTT_NS_THRESHOLD)
        w = snprintf(buf, cap, "{\"value\": %s, \"apply_at\": %lld}", val,
                     (long long)c->apply_at_ns);
    else /* below the threshold an integer would read as seconds: write seconds */
        w = snprintf(buf, cap, "{\"value\": %s, \"apply_at\": %lld.%09lld}", val,
                     (long long)(c->apply_at_ns / 1000000000LL),
                     (long long)(c->apply_at_ns % 1000000000LL));
    return w < 0 || (size_t)w >= cap ? -1 : w;
}
