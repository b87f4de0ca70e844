/* lamprig firmware — the rig config: devices, control map, output, scene, safe lamp level,
 * stats. One JSON file (configs/rig/NAME.json), validated completely before anything is
 * opened; every error reads "FILE:LINE: field 'F': what" (render/base/json.h).
 *
 * {
 *   "scene":    "PATH"                 scene file; relative paths resolve against this file
 *   "scene_set": {"render.K": 4, "light.color": [1, 0.6, 0.3], ...}   scene parameters set
 *                                      after every load of the scene (the rig's render budget:
 *                                      a small GPU needs smaller maps than the scene file's)
 *   "budget":   {"max_error": 0.2, "converge_ms": 2000, "frame_ms": 0, "change_ms": 3000}
 *                                      what the rig must meet, for every scene it loads: the
 *                                      planner (render/plan/plan.h) picks each scene's models
 *                                      and render settings from the measured table for it,
 *                                      and re-plans on material changes against it. It
 *                                      replaces the scene's quality block (max_error,
 *                                      frame_ms and converge_ms together; change_ms when
 *                                      given). At least one of max_error, frame_ms and
 *                                      converge_ms > 0. The presented frame interval is
 *                                      output.fps's, whatever the transport costs (the view
 *                                      runs it on a worker, render/async/); render.* in
 *                                      scene_set still win over the plan
 *   "devices":  [ DEVICE, ... ]        zero or more (names unique)
 *   "controls": [ BINDING, ... ] | "PATH"   the control map, inline or a file holding
 *                                      {"controls": [ ... ]} (configs/controls/NAME.json)
 *   "output":   {"mode": "headless" | "kms" (default headless),
 *                "connector": "HDMI-A-1" (kms; default the first connected),
 *                "drm_device": "/dev/dri/card1" (kms; default: probe),
 *                "mode_size": [W, H] (kms; default the preferred mode), "refresh_hz": 0,
 *                "width": 640, "height": 480 (headless image size),
 *                "fps": 30 (headless frame rate cap; kms follows vsync),
 *                "renderer": "passes" | "preview" (default: the first one built in),
 *                "gpu_memory_mb": 1024 (the renderer's textures at most: settings that need
 *                more are refused with what they need; 0: no limit),
 *                "cache_mb": 256 ("passes": converged images of the states the controls
 *                reach next, built ahead while the rig is idle, firmware/rig/ahead.h; 0: none),
 *                "cache_samples": 9 (states along each continuous material control: 2..48),
 *                "slice_ms": 8 ("passes": the worker's long GPU passes end a slice about
 *                this often, so a change waits about that long to cut a stale frame;
 *                0..1000, 0: fixed slices of a map or 64 grid rows)}
 *   "safe_level": 0                    lamp-driver level (0..1, as written to the driver,
 *                                      after any curve) set at shutdown
 *   "stats":    {"path": "PATH" (default none), "period_s": 10 (0: only at exit)}
 *   "calib":    "DIR"                  a calibration folder (calib/rig.h) with projector.json
 *                                      and pose.json's projector pose (albedo.json optional):
 *                                      spatial AR -- each change of the scene also renders a
 *                                      compensated projector frame (calib/ar_frame.h),
 *                                      written to out_dir/ar_NNNNNN.png and, with kms, shown
 *                                      on the projector instead of the view
 *                                      (firmware/rig/ar_present.h), its clipping logged and
 *                                      counted in the stats
 *   "ar_samples": 16                   CPU reference samples per band and pixel for it
 *   "http":     {"listen": "127.0.0.1:8080", "token": "..."}   the page and JSON API
 *                                      (firmware/rig/http.h); "listen" is an IPv4 literal or
 *                                      [IPv6] literal and a port. Any address outside
 *                                      127.0.0.0/8 and ::1 needs a "token" (at least
 *                                      LR_RIG_HTTP_TOKEN_MIN characters): without one the
 *                                      config is refused, naming the field. No object: no
 *                                      server, nothing listens.
 *   "mqtt":     {"broker": "HOST:PORT" (required; a numeric address: see mqtt.h),
 *                "rig": "NAME" (required; the topic lamprig/NAME/status),
 *                "role": "follower" (applies lamprig/all/...) | "status" (publishes only)
 *                        | "leader" (a follower that publishes its own devices' controls),
 *                "lead_ms": 250 (leader), "status_period_s": 5, "keepalive_s": 10,
 *                "retry_min_ms": 250, "retry_max_ms": 10000}   several rigs in step
 *                                      (firmware/rig/mqtt.h)
 * }
 *
 * DEVICE: "type" (sim, modbus, gpio, hid, usb, sacn, artnet, osc) and the options of that hal
 * back end, read through its descriptors (hal/opt.h: key, type, range, default, one number in one place);
 * the reference is firmware/README.md's table, written from them by
 * lr_rig_config_fields_markdown. sim needs "script" (a file) or "text"; modbus "inputs",
 * "lamp" (the lamp driver, default unit LR_RIG_LAMP_UNIT) or both; gpio "encoders",
 * "buttons" or both; usb one or more "watch" entries; sacn and artnet one or more "channels"
 * ({control, universe, channel, fine}: hal/dmx_in.h); osc optional "scenes" (names).
 *
 * BINDING (one control → one scene parameter; firmware/rig/control_map.h):
 *   "control": "SOURCE/CONTROL" | "CONTROL" (any source)      required
 *   "param":   scene parameter name (lr_scene_set) or "scene"  required; "light.level" /
 *              "lights[i].level": that light's own intensity (radiance) times the value
 *              (control_map.h)
 *   "name":    for logs and stats (default: the control)
 *   level bindings (a number or a colour following a position 0..1):
 *     "range": [MIN, MAX] (default [0, 1]) | "colors": [[r,g,b], [r,g,b]] (interpolated),
 *     "curve": "linear" | "square" | "s-curve" | "log" (default linear),
 *     "step": 0.02 (position per encoder detent), "accel": {"gain": 0, "rate0": 5, "max": 10},
 *     "fade_s": 0 (seconds a change takes), "initial": position 0..1 (default: from the
 *     scene's value), "lamp": false (this binding's curved level also drives the lamp driver)
 *   cycle bindings (a button or encoder steps through a list):
 *     "values": ["marble", "candle_wax", ...] (names, or scene files for "scene") or
 *               [[r,g,b], ...] (colours), "initial": index (default: not applied), "wrap": true
 */
#ifndef LR_RIG_CONFIG_H
#define LR_RIG_CONFIG_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "render/base/err.h"

#define LR_RIG_NAME_MAX 32
#define LR_RIG_PATH_MAX 512
#define LR_RIG_MAX_DEVICES 16
#define LR_RIG_MAX_BINDINGS 32
#define LR_RIG_MAX_VALUES 32
#define LR_RIG_MAX_ITEMS 16 /* inputs, encoders, buttons, watches per device */
#define LR_RIG_MAX_SETS 32
#define LR_RIG_HTTP_TOKEN_MAX 128
#define LR_RIG_HTTP_TOKEN_MIN 16 /* characters: a guessable token protects nothing */
/* The lamp driver's default Modbus unit: the rig's convention (the panel answers as unit 1, the
 * lamp driver as unit 2); hal/modbus.c's own default is 1 for both. */
#define LR_RIG_LAMP_UNIT 2

typedef enum lr_rig_dev_type {
    LR_RIG_DEV_SIM = 0,
    LR_RIG_DEV_MODBUS,
    LR_RIG_DEV_GPIO,
    LR_RIG_DEV_HID,
    LR_RIG_DEV_USB,
    LR_RIG_DEV_SACN,
    LR_RIG_DEV_ARTNET,
    LR_RIG_DEV_OSC,
} lr_rig_dev_type;

#define LR_RIG_MAX_CHANNELS 32 /* sacn/artnet channels per device */
#define LR_RIG_MAX_SCENE_NAMES 32 /* osc scenes */

typedef struct lr_rig_dmx_channel {
    char control[LR_RIG_NAME_MAX];
    int universe, channel, fine; /* fine 0: 8-bit */
} lr_rig_dmx_channel;

typedef struct lr_rig_modbus_reg {
    char control[LR_RIG_NAME_MAX];
    int unit, reg, base;
    bool input_regs; /* "type": "input" */
    int raw_min, raw_max;
    bool multiple;   /* lamp only */
} lr_rig_modbus_reg;

typedef struct lr_rig_gpio_line {
    char name[LR_RIG_NAME_MAX];
    char line_a[LR_RIG_NAME_MAX], line_b[LR_RIG_NAME_MAX]; /* buttons: line_a */
    int steps_per_detent;
    bool reverse;
    bool active_high;
    int debounce_ms;
} lr_rig_gpio_line;

typedef struct lr_rig_usb_watch {
    char name[LR_RIG_NAME_MAX];
    uint16_t vid, pid;
    bool read_reports;
    int interface;
    int proto; /* lr_hid_proto */
} lr_rig_usb_watch;

typedef struct lr_rig_device {
    lr_rig_dev_type type;
    char name[LR_RIG_NAME_MAX];
    int line; /* in the config file, for messages */
    bool required;
    int retry_min_ms, retry_max_ms;
    /* sim */
    char script[LR_RIG_PATH_MAX]; /* resolved path, or "" with text */
    char *text;                   /* owned; inline script */
    bool loop;
    /* modbus */
    char url[LR_RIG_PATH_MAX];
    int poll_ms, timeout_ms, byte_timeout_ms, max_timeouts;
    lr_rig_modbus_reg inputs[LR_RIG_MAX_ITEMS];
    int n_inputs;
    bool has_lamp;
    lr_rig_modbus_reg lamp;
    /* gpio */
    char chip[LR_RIG_NAME_MAX];
    int bias; /* lr_gpio_bias */
    lr_rig_gpio_line encoders[LR_RIG_MAX_ITEMS];
    int n_encoders;
    lr_rig_gpio_line buttons[LR_RIG_MAX_ITEMS];
    int n_buttons;
    /* hid */
    uint16_t vid, pid;
    char serial[64];
    int proto; /* lr_hid_proto */
    int report_id;
    /* usb */
    lr_rig_usb_watch watch[LR_RIG_MAX_ITEMS];
    int n_watch;
    int rescan_ms;
    bool no_hotplug;
    /* sacn, artnet, osc (port also osc; fade_ms, loss, max_packets all three or two) */
    char bind[64], interface[64], announce[64], short_name[18], prefix[64];
    char scene_control[LR_RIG_NAME_MAX];
    int port, max_sources, loss_ms, fade_ms, max_packets, merge_timeout_ms;
    int loss, merge; /* lr_dmx_loss, lr_dmx_merge_mode */
    bool unicast_only, preview;
    lr_rig_dmx_channel channels[LR_RIG_MAX_CHANNELS];
    int n_channels;
    char scenes[LR_RIG_MAX_SCENE_NAMES][LR_RIG_NAME_MAX];
    int n_scenes;
} lr_rig_device;

typedef enum lr_binding_kind {
    LR_BIND_LEVEL = 0, /* a position 0..1 → curve → range (number) or colors (RGB) */
    LR_BIND_CYCLE,     /* steps through `values` */
} lr_binding_kind;

typedef struct lr_rig_binding {
    char name[LR_RIG_NAME_MAX];
    char source[LR_RIG_NAME_MAX];  /* "" = any */
    char control[LR_RIG_NAME_MAX];
    char param[128];
    char file[LR_RIG_PATH_MAX]; /* the file it is in (the rig config or a control-map file) */
    int line;        /* of the binding; of its "param", "range"/"colors", each value: */
    int line_param, line_range, line_values[LR_RIG_MAX_VALUES];
    lr_binding_kind kind;
    /* level */
    bool is_color;
    double range[2];
    double colors[2][3];
    int curve; /* enum lr_curve */
    double step;
    double accel_gain, accel_rate0, accel_max;
    double fade_s;
    bool has_initial;
    double initial; /* level: position; cycle: index */
    bool lamp;
    /* cycle */
    int n_values;
    char values[LR_RIG_MAX_VALUES][LR_RIG_PATH_MAX]; /* names, resolved scene paths, "r,g,b" */
    bool wrap;
} lr_rig_binding;

typedef enum lr_rig_output_mode {
    LR_RIG_HEADLESS = 0,
    LR_RIG_KMS,
} lr_rig_output_mode;

/* "http": the rig's page and JSON API (firmware/rig/http.h). */
typedef struct lr_rig_http_config {
    bool enabled;
    char host[64];   /* an IPv4 or IPv6 literal, as written ("[::1]" without brackets) */
    int port;        /* 1..65535 */
    bool loopback;   /* 127.0.0.0/8 or ::1: only this machine can connect */
    char token[LR_RIG_HTTP_TOKEN_MAX]; /* "": none; required unless loopback */
} lr_rig_http_config;
/* "mqtt": the rig's MQTT link (firmware/rig/mqtt.h); enabled only when the field is given. */
typedef enum lr_rig_mqtt_role {
    LR_RIG_MQTT_FOLLOWER = 0, /* subscribes to lamprig/all/... and applies it */
    LR_RIG_MQTT_STATUS,       /* publishes its status only */
    LR_RIG_MQTT_LEADER,       /* a follower whose own devices' controls drive every rig */
} lr_rig_mqtt_role;

typedef struct lr_rig_mqtt {
    bool enabled;
    char host[128];
    int port;
    char rig[LR_RIG_NAME_MAX];
    lr_rig_mqtt_role role;
    double status_period_s;
    int keepalive_s;
    int retry_min_ms, retry_max_ms;
    int lead_ms; /* leader: apply_at = now + lead_ms for what its devices send */
    int line; /* of the "mqtt" object, for messages */
} lr_rig_mqtt;

/* "budget": the quality block every scene the rig loads is planned for. */
typedef struct lr_rig_budget {
    bool given;
    double max_error, frame_ms, converge_ms, change_ms; /* 0: not given */
    int line;
} lr_rig_budget;

typedef struct lr_rig_config {
    char path[LR_RIG_PATH_MAX];  /* the file it came from */
    char scene[LR_RIG_PATH_MAX]; /* resolved */
    struct {
        char key[128], value[256];
        int line;
    } sets[LR_RIG_MAX_SETS];
    int n_sets;
    lr_rig_budget budget;
    lr_rig_device devices[LR_RIG_MAX_DEVICES];
    int n_devices;
    lr_rig_binding bindings[LR_RIG_MAX_BINDINGS];
    int n_bindings;
    struct {
        lr_rig_output_mode mode;
        char connector[LR_RIG_NAME_MAX];
        char drm_device[LR_RIG_PATH_MAX];
        int mode_w, mode_h, refresh_hz;
        int width, height;
        double fps;
        char renderer[LR_RIG_NAME_MAX]; /* "" = default */
        double gpu_memory_mb;           /* the renderer's GPU memory budget; 0: none */
        double cache_mb;                /* the control-space cache's images; 0: none */
        int cache_samples;              /* states per continuous control built ahead */
        double slice_ms;                /* the worker's GPU slices ("passes"); 0: fixed */
    } output;
    double safe_level;
    char stats_path[LR_RIG_PATH_MAX];
    double stats_period_s;
    char calib[LR_RIG_PATH_MAX]; /* resolved calibration folder; "" = no spatial AR */
    int ar_samples;
    lr_rig_http_config http; /* "http"; off without the object */
    lr_rig_mqtt mqtt;
} lr_rig_config;

/* Loads and validates path completely (every device, binding and the output; file paths are
 * resolved and checked to exist; scene parameters are checked against the scene by the
 * control map, see lr_control_map_create). LR_EIO / LR_EPARSE naming file, line and field. */
int lr_rig_config_load(const char *path, lr_rig_config **out, lr_err *e);
/* The same from text; name is used in messages and as the base of relative paths. */
int lr_rig_config_parse(const char *text, const char *name, lr_rig_config **out, lr_err *e);
void lr_rig_config_destroy(lr_rig_config *c);

/* Applies "budget" (as the scene's quality block) and then "scene_set" to a freshly loaded
 * scene; errors name the config file, line and field. */
struct lr_scene;
int lr_rig_config_apply_sets(const lr_rig_config *c, struct lr_scene *scene, lr_err *e);

/* The modbus device the lamp driver is on, -1 when none. */
int lr_rig_config_lamp_device(const lr_rig_config *c);

/* Writes the reference of the device fields (markdown: device, field, value, range, default,
 * what) from the hal back ends' option descriptors (hal/opt.h) the loader reads them through;
 * firmware/README.md quotes it between "<!-- BEGIN rig-devices -->" and
 * "<!-- END rig-devices -->" (tests/fw/test_fw_config.c compares). */
void lr_rig_config_fields_markdown(FILE *f);

/* "sim", "modbus", "gpio", "hid", "usb", "sacn", "artnet", "osc". */
const char *lr_rig_dev_type_name(lr_rig_dev_type t);

#endif
