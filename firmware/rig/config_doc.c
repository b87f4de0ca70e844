/* The device part of the rig config reference, written from the hal back ends' option
 * descriptors (hal/opt.h) that config.c reads devices through; firmware/README.md quotes it
 * (tests/fw/test_fw_config.c compares). */
#include <string.h>

#include "firmware/rig/config.h"
#include "hal/artnet.h"
#include "hal/dev.h"
#include "hal/dmx_in.h"
#include "hal/gpio.h"
#include "hal/hid.h"
#include "hal/modbus.h"
#include "hal/opt.h"
#include "hal/osc.h"
#include "hal/sacn.h"
#include "hal/sim.h"
#include "hal/usb.h"

static void row(FILE *out, const char *where, const lr_opt *o, long dflt)
{
    char value[160] = "", range[64] = "", def[64] = "";
    switch (o->type) {
    case LR_OPT_INT:
        snprintf(value, sizeof value, "integer");
        snprintf(range, sizeof range, "%ld..%ld", o->lo, o->hi);
        snprintf(def, sizeof def, "%ld", dflt);
        break;
    case LR_OPT_BOOL:
        snprintf(value, sizeof value, "true, false");
        snprintf(def, sizeof def, "%s", dflt ? "true" : "false");
        break;
    case LR_OPT_STRING:
        snprintf(value, sizeof value, "string");
        if (o->dflt_text)
            snprintf(def, sizeof def, "`%s`", o->dflt_text);
        break;
    case LR_OPT_ENUM:
        for (int i = 0; o->names[i]; i++)
            snprintf(value + strlen(value), sizeof value - strlen(value), "%s`%s`", i ? ", " : "",
                     o->names[i]);
        snprintf(def, sizeof def, "`%s`", o->names[dflt]);
        break;
    case LR_OPT_HEX16: snprintf(value, sizeof value, "hex string (`\"077d\"`)"); break;
    case LR_OPT_LIST: snprintf(value, sizeof value, "array"); break;
    case LR_OPT_OBJECT: snprintf(value, sizeof value, "object"); break;
    }
    if (o->required)
        snprintf(def, sizeof def, "required");
    fprintf(out, "| %s | `%s` | %s | %s | %s | %s |\n", where, o->key, value, range, def,
            o->help ? o->help : "");
}

static void rows(FILE *out, const char *where, const lr_opt *table)
{
    for (const lr_opt *o = table; o->key; o++)
        row(out, where, o, o->dflt);
}

void lr_rig_config_fields_markdown(FILE *out)
{
    fprintf(out, "| device | field | value | range | default | what |\n");
    fprintf(out, "|---|---|---|---|---|---|\n");
    rows(out, "every", lr_dev_opts);
    rows(out, "sim", lr_sim_opts);
    rows(out, "modbus", lr_modbus_opts);
    rows(out, "modbus `inputs[i]`", lr_modbus_input_opts);
    for (const lr_opt *o = lr_modbus_output_opts; o->key; o++) /* the rig's lamp unit */
        row(out, "modbus `lamp`", o, strcmp(o->key, "unit") == 0 ? LR_RIG_LAMP_UNIT : o->dflt);
    rows(out, "gpio", lr_gpio_opts);
    rows(out, "gpio `encoders[i]`", lr_gpio_encoder_opts);
    rows(out, "gpio `buttons[i]`", lr_gpio_button_opts);
    rows(out, "hid", lr_hid_opts);
    rows(out, "usb", lr_usb_opts);
    rows(out, "usb `watch[i]`", lr_usb_watch_opts);
    rows(out, "sacn", lr_sacn_opts);
    rows(out, "sacn `channels[i]`", lr_sacn_channel_opts);
    rows(out, "artnet", lr_artnet_opts);
    rows(out, "artnet `channels[i]`", lr_artnet_channel_opts);
    rows(out, "osc", lr_osc_opts);
}
