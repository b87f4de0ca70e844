/* firmware/rig/config (+ the control map's checks against the scene): every bad field is
 * named with the file and line; truncated and garbage files are errors, never crashes; the
 * shipped rigs load. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/rig/config.h"
#include "firmware/rig/control_map.h"
#include "render/scene/scene.h"
#include "tests/support/doc_block.h"
#include "tests/support/fs.h"

#define CFG LR_SOURCE_CONFIGS

/* Loads text as DIR/rig.json (with the scene beside it) and returns the error message of
 * config + control map, or "" when both accept it. */
static void load_msg(const char *dir, const char *text, char *msg, size_t cap)
{
    char *path = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_rig_config *c = NULL;
    lr_err e = {0};
    int rc = lr_rig_config_load(path, &c, &e);
    if (!rc) {
        lr_scene *s = NULL;
        rc = lr_scene_load(c->scene, NULL, &s, &e);
        lr_control_map *m = NULL;
        if (!rc)
            rc = lr_control_map_create(c, s, true, 0, &m, &e);
        lr_control_map_destroy(m);
        lr_scene_destroy(s);
    }
    lr_rig_config_destroy(c);
    snprintf(msg, cap, "%s", rc ? e.msg : "");
    if (rc)
        assert_true(rc == LR_EPARSE || rc == LR_EIO);
    free(path);
}

static void test_bad_fields_named(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char *scene_text = (char *)lr_test_read(CFG "/scenes/candle.json", &(size_t){0});
    free(lr_test_write(dir, "candle.json", scene_text, (size_t)-1));
    free(lr_test_write(dir, "demo.sim", "0 dimmer absolute 0.5\n", (size_t)-1));
    free(scene_text);
    static const struct {
        const char *text, *msg;
    } cases[] = {
        {"{\"scene\": \"candle.json\",\n \"sceen\": 1}",
         "rig.json:2: field 'sceen': unknown field"},
        {"{\"devices\": []}", "rig.json:1: field 'scene': required field is missing"},
        {"{\"scene\": \"candle.json\",\n \"budget\": {\"change_ms\": 100}}",
         "rig.json:2: field 'budget': no budget: give max_error, frame_ms or converge_ms (> 0)"},
        {"{\"scene\": \"candle.json\",\n \"budget\": {\"max_error\": -0.1}}",
         "rig.json:2: field 'budget.max_error': must be in 0..1e+06, got -0.1"},
        {"{\"scene\": \"candle.json\",\n \"budget\": {\"converge_s\": 2}}",
         "rig.json:2: field 'budget.converge_s': unknown field"},
        {"{\"scene\": \"candle.json\",\n \"output\": {\"gpu_memory_mb\": -5}}",
         "rig.json:2: field 'output.gpu_memory_mb': must be in 0..1.04858e+06, got -5"},
        {"{\"scene\": \"candle.json\",\n \"output\": {\"slice_ms\": 2000}}",
         "rig.json:2: field 'output.slice_ms': must be in 0..1000, got 2000"},
        {"{\"scene\": \"nope.json\"}", "rig.json:1: field 'scene': '%D/nope.json': No such file "
                                       "or directory"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"serial\"}]}",
         "rig.json:3: field 'devices[0].type': unknown device type 'serial' (sim, modbus, gpio, "
         "hid, usb, sacn, artnet, osc)"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"sacn\", \"channels\": "
         "[\n   {\"control\": \"dimmer\", \"universe\": 0, \"channel\": 1}]}]}",
         "rig.json:4: field 'devices[0].channels[0].universe': must be in 1..63999, got 0"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"sacn\"}]}",
         "rig.json:3: field 'devices[0].channels': required field is missing"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"artnet\", \"channels\": "
         "[\n   {\"control\": \"d\", \"channel\": 5, \"fine\": 5}]}]}",
         "rig.json:4: field 'devices[0].channels[0].fine': the fine byte cannot be the channel "
         "itself (5)"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"artnet\", \"merge\": "
         "\"max\", \"channels\": [{\"control\": \"d\", \"channel\": 1}]}]}",
         "rig.json:3: field 'devices[0].merge': 'max' is not htp or ltp"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"osc\", \"prefix\": "
         "\"lamprig/\"}]}",
         "rig.json:3: field 'devices[0].prefix': 'lamprig/' is not /NAME[/NAME...] without a "
         "trailing '/'"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"sim\", \"script\": "
         "\"demo.sim\"},\n  {\"type\": \"sim\", \"text\": \"0 x press\"}]}",
         "rig.json:4: field 'devices[1].name': device name 'sim' is already used by devices[0]"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"modbus\",\n   \"url\": "
         "\"tcp://h:99999\", \"lamp\": {\"reg\": 0}}]}",
         "rig.json:4: field 'devices[0].url': modbus URL 'tcp://h:99999': port '99999' is not "
         "1..65535"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"modbus\", \"url\": "
         "\"tcp://127.0.0.1:1502\",\n   \"inputs\": [{\"reg\": 0,\n     \"raw_min\": 1000, "
         "\"raw_max\": 0}]}]}",
         "rig.json:4: field 'devices[0].inputs[0].raw_max': must be greater than raw_min "
         "(1000), got 0"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"modbus\", \"url\": "
         "\"tcp://127.0.0.1:1502\",\n   \"lamp\": {\"unit\": 300, \"reg\": 0}}]}",
         "rig.json:4: field 'devices[0].lamp.unit': must be in 1..255, got 300"},
        /* The back end's range (hal/modbus.c lr_modbus_opts), not a copy that disagreed. */
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"modbus\", \"url\": "
         "\"tcp://127.0.0.1:1502\",\n   \"poll_ms\": 600000, \"lamp\": {\"reg\": 0}}]}",
         "rig.json:4: field 'devices[0].poll_ms': must be in 1..60000, got 600000"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"gpio\", \"encoders\": "
         "[\n   {\"name\": \"knob1\", \"line_a\": \"17\", \"line_b\": \"27\",\n    "
         "\"steps_per_detent\": 3}]}]}",
         "rig.json:4: field 'devices[0].encoders[0].steps_per_detent': must be 1, 2 or 4, got 3"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [\n  {\"type\": \"hid\", \"vid\": "
         "\"077d\",\n   \"pid\": \"xyz\"}]}",
         "rig.json:4: field 'devices[0].pid': 'xyz' is not a 16-bit hex id like \"077d\""},
        {"{\"scene\": \"candle.json\",\n \"controls\": [\n  {\"control\": \"dimmer\", \"param\": "
         "\"light.intensity\"},\n  {\"control\": \"knob\", \"param\": \"light.intensity\",\n   "
         "\"curve\": \"cubic\"}]}",
         "rig.json:5: field 'controls[1].curve': unknown curve 'cubic' (linear, square, "
         "s-curve, log, warm-dim)"},
        {"{\"scene\": \"candle.json\",\n \"controls\": [\n  {\"control\": \"dimmer\", \"param\": "
         "\"light.intensity\",\n   \"range\": [1, 1]}]}",
         "rig.json:4: field 'controls[0].range': range is empty: [1, 1]"},
        {"{\"scene\": \"candle.json\",\n \"controls\": [\n  {\"control\": \"b\", \"param\": "
         "\"objects[0].material\",\n   \"values\": [\"marble\"], \"fade_s\": 1}]}",
         "rig.json:4: field 'controls[0].fade_s': not allowed with 'values' (a cycle binding)"},
        {"{\"scene\": \"candle.json\",\n \"controls\": [\n  {\"control\": \"a\", \"param\": "
         "\"light.intensity\", \"lamp\": true},\n  {\"control\": \"b\", \"param\": "
         "\"render.exposure\", \"lamp\": true}]}",
         "rig.json:4: field 'controls[1]': only one binding may drive the lamp driver ('lamp': "
         "true)"},
        {"{\"scene\": \"candle.json\",\n \"devices\": [{\"type\": \"modbus\", \"url\": "
         "\"tcp://127.0.0.1:1502\", \"lamp\": {\"reg\": 0}}],\n \"controls\": [\n  "
         "{\"control\": \"panel/dimmer\", \"param\": \"light.intensity\"}]}",
         "rig.json:4: field 'controls[0].control': no device named 'panel'"},
        {"{\"scene\": \"candle.json\",\n \"controls\": [\n  {\"control\": \"dimmer\",\n   "
         "\"param\": \"light.brightness\"}]}",
         "rig.json:4: field 'controls[0].param': light.brightness: a point light has no "
         "parameter 'brightness' (known: %P"},
        {"{\"scene\": \"candle.json\",\n \"controls\": [\n  {\"control\": \"dimmer\", "
         "\"param\": \"light.intensity\",\n   \"range\": [-1, 1]}]}",
         "rig.json:4: field 'controls[0].range': the scene rejects the lower end = -1: "
         "light.intensity: must be >= 0 (W/sr), got -1"},
        {"{\"scene\": \"candle.json\",\n \"controls\": [\n  {\"control\": \"button1\", "
         "\"param\": \"objects[0].material\",\n   \"values\": [\"marble\", \"unobtainium\"]}]}",
         "rig.json:4: field 'controls[0].values[1]': objects[0].material: no usable preset "
         "'unobtainium': %M"},
        {"{\"scene\": \"candle.json\",\n \"output\": {\"mode\": \"hdmi\"}}",
         "rig.json:2: field 'output.mode': 'hdmi' is not headless or kms"},
        {"{\"scene\": \"candle.json\",\n \"safe_level\": 1.5}",
         "rig.json:2: field 'safe_level': must be in 0..1, got 1.5"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char msg[LR_ERR_MSG_MAX];
        load_msg(dir, cases[i].text, msg, sizeof msg);
        /* Expected: the path prefix, and placeholders for messages owned by other modules
         * (checked to be there, by their start). */
        char want[1024];
        snprintf(want, sizeof want, "%s/%s", dir, cases[i].msg);
        char *ph = strstr(want, "%");
        if (ph && ph[1] == 'D') {
            char tail[512];
            snprintf(tail, sizeof tail, "%s", ph + 2);
            snprintf(ph, sizeof want - (size_t)(ph - want), "%s%s", dir, tail);
            assert_string_equal(msg, want);
        } else if (ph) {
            *ph = '\0';
            if (strncmp(msg, want, strlen(want)) != 0 || strlen(msg) <= strlen(want))
                fail_msg("case %zu: got '%s', want '%s...'", i, msg, want);
        } else if (strcmp(msg, want) != 0) {
            fail_msg("case %zu: got '%s', want '%s'", i, msg, want);
        }
    }
    lr_test_rmtree(dir);
}

/* A control map in its own file (configs/controls/NAME.json): its errors name that file and
 * its lines, and the scene-side checks (parameters) too. */
static void test_control_map_file_errors(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    free(lr_test_write(dir, "controls/a.json",
                       "{\"controls\": [\n {\"control\": \"dimmer\",\n  \"param\": "
                       "\"light.nope\"}]}\n", (size_t)-1));
    free(lr_test_write(dir, "controls/b.json",
                       "{\"controls\": [\n {\"control\": \"dimmer\", \"param\": "
                       "\"light.intensity\",\n  \"step\": 0}]}\n", (size_t)-1));
    free(lr_test_write(dir, "controls/c.json", "{\"bindings\": []}\n", (size_t)-1));
    char text[600], msg[LR_ERR_MSG_MAX], want[1200];
    const struct { const char *file, *msg; } cases[] = {
        {"a.json", "controls/a.json:3: field 'controls[0].param': light.nope: a point light has "
                   "no parameter 'nope' (known: intensity, intensity_cd, flux_lm, color, "
                   "color_temperature_k, position, direction, profile_c0, flicker.{amplitude, "
                   "frequency_hz, jitter_mm, seed})"},
        {"b.json", "controls/b.json:3: field 'controls[0].step': must be in 1e-06..1, got 0"},
        {"c.json", "controls/c.json:1: field 'bindings': unknown field"},
    };
    for (int i = 0; i < 3; i++) {
        snprintf(text, sizeof text,
                 "{\"scene\": \"%s/scenes/candle.json\",\n \"controls\": \"controls/%s\"}\n",
                 LR_SOURCE_CONFIGS, cases[i].file);
        load_msg(dir, text, msg, sizeof msg);
        snprintf(want, sizeof want, "%s/%s", dir, cases[i].msg);
        assert_string_equal(msg, want);
    }
    lr_test_rmtree(dir);
}

/* Truncated and garbage files: an error naming the file, never a crash. */
static void test_truncated_and_garbage(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    size_t len;
    char *good = (char *)lr_test_read(CFG "/rig/modbus-demo.json", &len);
    char msg[LR_ERR_MSG_MAX];
    char want[600];
    snprintf(want, sizeof want, "%s/rig.json:", dir);
    for (size_t cut = 0; cut < len; cut += 7) {
        char *t = strndup(good, cut);
        load_msg(dir, t, msg, sizeof msg);
        free(t);
        if (cut < len - 2) /* the file ends in "}\n": anything shorter is incomplete */
            assert_true(strncmp(msg, want, strlen(want)) == 0 ||
                        strstr(msg, "rig.json") != NULL);
    }
    unsigned seed = 12345;
    for (int k = 0; k < 200; k++) {
        char t[256];
        for (size_t i = 0; i < sizeof t - 1; i++) {
            seed = seed * 1103515245u + 12345u;
            t[i] = (char)(1 + (seed >> 16) % 255);
        }
        t[sizeof t - 1] = '\0';
        load_msg(dir, t, msg, sizeof msg);
        assert_true(msg[0] != '\0');
    }
    free(good);
    lr_test_rmtree(dir);
}

/* The shipped rigs and control map load, and say what firmware/README.md ("Shipped rigs") says
 * they do. */
static void test_shipped_rigs(void **state)
{
    (void)state;
    lr_rig_config *c;
    lr_err e = {0};
    if (lr_rig_config_load(CFG "/rig/modbus-demo.json", &c, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(c->n_devices, 1);
    const lr_rig_device *d = &c->devices[0];
    assert_int_equal(d->type, LR_RIG_DEV_MODBUS);
    assert_int_equal(d->n_inputs, 1);
    assert_int_equal(d->inputs[0].unit, 1);
    assert_int_equal(d->inputs[0].reg, 0);
    assert_false(d->inputs[0].input_regs);
    assert_int_equal(d->inputs[0].raw_min, 0);
    assert_int_equal(d->inputs[0].raw_max, 1000);
    assert_true(d->has_lamp);
    assert_int_equal(d->lamp.unit, 2);
    assert_int_equal(d->lamp.reg, 0);
    assert_int_equal(d->lamp.raw_max, 255);
    assert_int_equal(lr_rig_config_lamp_device(c), 0);
    assert_int_equal(c->n_bindings, 1);
    assert_true(c->bindings[0].lamp);
    assert_string_equal(c->bindings[0].source, "panel");
    assert_int_equal(c->bindings[0].curve, 0); /* linear */
    assert_int_equal(c->output.mode, LR_RIG_KMS);
    lr_rig_config_destroy(c);

    if (lr_rig_config_load(CFG "/rig/sim.json", &c, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(c->devices[0].type, LR_RIG_DEV_SIM);
    /* The shipped rigs state a budget, not render settings: the planner picks those. */
    assert_true(c->budget.given);
    assert_true(c->budget.max_error == 0.2 && c->budget.converge_ms == 2000);
    for (int i = 0; i < c->n_sets; i++)
        assert_null(strstr(c->sets[i].key, "render."));
    assert_true(c->devices[0].loop);
    assert_int_equal(c->n_bindings, 6);
    assert_int_equal(c->output.mode, LR_RIG_HEADLESS);
    assert_true(c->output.gpu_memory_mb == 1024); /* the default: a quarter of a 4 GB board */
    assert_true(c->output.slice_ms == 8);         /* the default: a quarter of 1/30 s */
    lr_scene *s;
    if (lr_scene_load(c->scene, NULL, &s, &e))
        fail_msg("%s", e.msg);
    lr_control_map *m;
    if (lr_control_map_create(c, s, true, 0, &m, &e))
        fail_msg("%s", e.msg);
    lr_control_map_destroy(m);
    /* The budget replaces the scene's quality block (its 600 ms a frame goes), change_ms
     * stays the scene's. */
    if (lr_rig_config_apply_sets(c, s, &e))
        fail_msg("%s", e.msg);
    const lr_quality *q = lr_scene_quality(s);
    assert_true(q->max_error == 0.2 && q->converge_ms == 2000 && q->frame_ms == 0);
    assert_true(q->change_ms == 3000);
    lr_scene_destroy(s);
    lr_rig_config_destroy(c);
}

/* firmware/README.md's device table is written from the hal option descriptors the loader
 * reads devices through: a range changed in hal/ shows up there, or this fails. */
static void test_readme_device_fields(void **state)
{
    (void)state;
    lr_test_doc_block("firmware/README.md", "rig-devices", lr_rig_config_fields_markdown);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bad_fields_named),
        cmocka_unit_test(test_control_map_file_errors),
        cmocka_unit_test(test_truncated_and_garbage),
        cmocka_unit_test(test_shipped_rigs),
        cmocka_unit_test(test_readme_device_fields),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='test_soak*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
