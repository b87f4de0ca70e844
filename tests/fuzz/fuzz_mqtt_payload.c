/* lamprig fuzz — the MQTT command parser (firmware/rig/mqtt_payload.h) on arbitrary bytes.
 *
 * Input: a topic line, then the payload (the corpus files in corpus/mqtt_payload/ have this
 * form). Built with clang's libFuzzer by `make fuzz`; run it with a scratch folder first (new
 * inputs go to the first folder):
 *   build/fuzz/fuzz_mqtt_payload build/fuzz/mqtt_payload tests/fuzz/corpus/mqtt_payload \
 *       -max_total_time=60
 * tests/fw/test_fw_mqtt.c runs this same function on the corpus under ASan/UBSan in make test.
 * A refusal must name the topic; an accepted command must hold what the parser promises. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/rig/mqtt_payload.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const uint8_t *nl = memchr(data, '\n', size);
    size_t tl = nl ? (size_t)(nl - data) : size;
    char topic[128];
    if (tl >= sizeof topic)
        tl = sizeof topic - 1;
    memcpy(topic, data, tl);
    topic[tl] = '\0';
    size_t off = nl ? (size_t)(nl - data) + 1 : size;
    lr_mqtt_cmd c;
    lr_err e = {0};
    if (lr_mqtt_payload_parse(topic, data + off, size - off, &c, &e)) {
        if (!e.msg[0])
            abort(); /* a refusal without a message */
        return 0;
    }
    if (c.kind == LR_MQTT_NONE || c.cleared != (size == off))
        abort();
    if (!c.cleared && c.kind == LR_MQTT_CONTROL && !(c.value >= 0 && c.value <= 1))
        abort();
    if (!c.cleared && c.kind == LR_MQTT_SCENE && !c.scene[0])
        abort();
    if (c.has_apply_at && c.apply_at_ns < 0)
        abort();
    /* What the parser accepted formats and reads back to the same command. */
    if (!c.cleared) {
        char buf[6 * LR_MQTT_SCENE_MAX + 128];
        int n = lr_mqtt_payload_format(&c, buf, sizeof buf);
        lr_mqtt_cmd d;
        if (n < 0 || lr_mqtt_payload_parse(topic, buf, (size_t)n, &d, &e) ||
            d.value != c.value || strcmp(d.scene, c.scene) != 0 ||
            d.apply_at_ns != c.apply_at_ns)
            abort();
    }
    return 0;
}
