/* lamprig run — controls in, frames out, until a signal or --duration. */
#include "firmware/cmd_run.h"

#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "firmware/args.h"
#include "firmware/cli.h"
#include "firmware/rig/rig.h"
#include "render/base/out_dir.h"

const char lr_run_summary[] = "run the rig: controls (gpio/hid/usb/modbus/sim) drive the scene, "
                              "frames to the projector or headless";

const char lr_run_usage[] =
    "usage: lamprig run --config FILE [--headless] [--out-dir DIR] [--duration SECONDS]\n"
    "                   [--stats FILE] [--modbus URL] [--no-plan] [--table CSV]\n"
    "\n"
    "Runs the rig described by FILE (configs/rig/*.json): opens its devices, maps their\n"
    "controls onto the scene through the control map, writes the dimmer's curved level to the\n"
    "Modbus lamp driver, and renders a frame whenever something changed or the picture has not\n"
    "converged, on the projector (output.mode \"kms\", one frame per vblank) or headless.\n"
    "\n"
    "  --config FILE       the rig config (required)\n"
    "  --headless          no display, whatever output.mode says\n"
    "  --out-dir DIR       headless: write every frame as DIR/frame_NNNNNN.png\n"
    "  --duration SECONDS  exit cleanly after this long (default: run until a signal)\n"
    "  --stats FILE        latency and frame statistics, JSON (default: the config's\n"
    "                      stats.path), written atomically every stats.period_s and at exit\n"
    "  --modbus URL        the Modbus endpoint instead of the config's: tcp://HOST:PORT or\n"
    "                      rtu:DEVICE?baud=19200&parity=E&data=8&stop=1\n"
    "  --no-plan           keep the scene's render settings even when it (or the config's\n"
    "                      scene_set) has a quality budget\n"
    "  --table CSV         the planner's measured table (default: see `lamprig help plan`)\n"
    "\n"
    "A scene with a quality budget is planned at every load (`lamprig plan`): the log has one\n"
    "line per object with the choice, predicted error and time; the config's scene_set is\n"
    "applied after the plan and wins.\n"
    "\n"
    "Signals: SIGINT/SIGTERM shut down cleanly (lamp driver to its safe level, devices closed,\n"
    "stats written, exit 0); SIGHUP reloads the config (a broken one is reported with file,\n"
    "line and field, and the running one stays).\n"
    "\n"
    "Exit status: 0 clean shutdown; 1 the config, scene or output could not be set up (the\n"
    "message names the file, line and field, or the device); 2 bad arguments, among them an\n"
    "--out-dir that is not a folder or cannot be created or written (checked at start).\n"
    "\n"
    "Examples:\n"
    "  lamprig run --config configs/rig/sim.json --headless --duration 10 --out-dir /tmp/f\n"
    "  lamprig run --config configs/rig/modbus-demo.json --modbus tcp://127.0.0.1:1502";

static int usage_error(const char *msg)
{
    char buf[LR_ERR_MSG_MAX];
    snprintf(buf, sizeof buf, "%s", msg);
    for (char *c = buf; *c; c++)
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    fprintf(stderr, "lamprig run: %s (see `lamprig help run`)\n", buf);
    return LR_EXIT_USAGE;
}

int lr_cmd_run(int argc, char **argv)
{
    static const lr_argspec specs[] = {
        {"--config", 1}, {"--headless", 0}, {"--out-dir", 1}, {"--duration", 1},
        {"--stats", 1},  {"--modbus", 1},   {"--no-plan", 0}, {"--table", 1}, {NULL, 0},
    };
    lr_args a;
    lr_err e = {0};
    if (lr_args_parse(argc - 1, argv + 1, specs, 0, &a, &e))
        return usage_error(e.msg);
    if (!lr_args_has(&a, "--config"))
        return usage_error("--config FILE is required");
    lr_rig_opts o = {
        .config = lr_args_get(&a, "--config"),
        .headless = lr_args_has(&a, "--headless"),
        .out_dir = lr_args_get(&a, "--out-dir"),
        .stats_path = lr_args_get(&a, "--stats"),
        .modbus_url = lr_args_get(&a, "--modbus"),
        .no_plan = lr_args_has(&a, "--no-plan"),
        .plan_table = lr_args_get(&a, "--table"),
    };
    const char *d = lr_args_get(&a, "--duration");
    if (d) {
        if (lr_args_number("--duration", d, &o.duration_s, &e))
            return usage_error(e.msg);
        if (!(o.duration_s > 0) || o.duration_s > 1e7)
            return usage_error("--duration: must be > 0 seconds");
    }
    /* A folder that cannot take the frames is a bad argument, refused before anything opens
     * (the rig would otherwise log one failed write per frame). */
    if (o.out_dir && lr_out_dir_prepare(o.out_dir, &e)) {
        lr_err_prefix(&e, "--out-dir");
        return usage_error(e.msg);
    }
    /* A peer that closes its socket must be an error return, never a fatal signal. */
    signal(SIGPIPE, SIG_IGN);
    lr_rig *r;
    if (lr_rig_create(&o, &r, &e)) {
        fprintf(stderr, "lamprig run: %s\n", e.msg);
        return LR_EXIT_FAIL;
    }
    int rc = lr_rig_run(r, &e);
    if (rc)
        fprintf(stderr, "lamprig run: %s\n", e.msg);
    lr_rig_destroy(r);
    return rc ? LR_EXIT_FAIL : LR_EXIT_OK;
}
