/* lamprig run — controls in, frames out, until a signal or --duration. */
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "firmware/commands/commands.h"
#include "firmware/rig/rig.h"
#include "render/base/out_dir.h"

static int run_rig(const lr_cli *c);

static const lr_argspec opts[] = {
    {.name = "--config", .type = LR_ARG_PATH, .flags = LR_ARG_REQUIRED,
     .help = "the rig config (required)"},
    {.name = "--headless", .help = "no display, whatever output.mode says"},
    {.name = "--out-dir", .type = LR_ARG_PATH, .metavar = "DIR",
     .help = "headless: write every frame as DIR/frame_NNNNNN.png"},
    {.name = "--duration", .type = LR_ARG_NUMBER, .metavar = "SECONDS",
     .flags = LR_ARG_ABOVE_MIN, .min = 0, .max = 1e7,
     .help = "exit cleanly after this long (default: run until a signal)"},
    {.name = "--stats", .type = LR_ARG_PATH,
     .help = "latency and frame statistics, JSON (default: the config's\n"
             "stats.path), written atomically every stats.period_s and at exit"},
    {.name = "--modbus", .type = LR_ARG_STRING, .metavar = "URL",
     .help = "the Modbus endpoint instead of the config's: tcp://HOST:PORT or\n"
             "rtu:DEVICE?baud=19200&parity=E&data=8&stop=1"},
    {.name = "--no-plan",
     .help = "keep the scene's render settings even when it (or the config's\n"
             "scene_set) has a quality budget"},
    {.name = "--table", .type = LR_ARG_PATH, .metavar = "CSV",
     .help = "the planner's measured table (default: see `lamprig help plan`)"},
    {0},
};

const lr_command lr_run_command = {
    .name = "run",
    .summary = "run the rig: controls (gpio/hid/usb/modbus/sim) drive the scene, frames to the "
               "projector or headless",
    .about =
        "Runs the rig described by FILE (configs/rig/*.json): opens its devices, maps their\n"
        "controls onto the scene through the control map, writes the dimmer's curved level to the\n"
        "Modbus lamp driver, and renders a frame whenever something changed or the picture has not\n"
        "converged, on the projector (output.mode \"kms\", one frame per vblank) or headless.",
    .opts = opts,
    .notes =
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
        "  lamprig run --config configs/rig/modbus-demo.json --modbus tcp://127.0.0.1:1502",
    .run = run_rig,
};

static int run_rig(const lr_cli *c)
{
    const lr_args *a = &c->args;
    lr_err e = {0};
    lr_rig_opts o = {
        .config = lr_args_get(a, "--config"),
        .headless = lr_args_has(a, "--headless"),
        .out_dir = lr_args_get(a, "--out-dir"),
        .stats_path = lr_args_get(a, "--stats"),
        .modbus_url = lr_args_get(a, "--modbus"),
        .no_plan = lr_args_has(a, "--no-plan"),
        .plan_table = lr_args_get(a, "--table"),
    };
    int st = lr_cli_check(c, lr_args_double(a, "--duration", &o.duration_s, &e), &e);
    if (st)
        return st;
    /* A folder that cannot take the frames is a bad argument, refused before anything opens
     * (the rig would otherwise log one failed write per frame). */
    if (o.out_dir && lr_out_dir_prepare(o.out_dir, &e)) {
        lr_err_prefix(&e, "--out-dir");
        return lr_cli_usage(c->path, "%s", e.msg);
    }
    /* A peer that closes its socket must be an error return, never a fatal signal. */
    signal(SIGPIPE, SIG_IGN);
    lr_rig *r;
    if (lr_rig_create(&o, &r, &e))
        return lr_cli_fail(c->path, "%s", e.msg);
    int rc = lr_rig_run(r, &e);
    if (rc)
        lr_cli_fail(c->path, "%s", e.msg);
    lr_rig_destroy(r);
    return rc ? LR_EXIT_FAIL : LR_EXIT_OK;
}
