/* The rig's HTTP endpoint (firmware/rig/http.h) through real HTTP clients: curl (the program)
 * for every endpoint and every kind of bad request, and headless chromium driven through
 * chromedriver's WebDriver protocol (tests/fw/http_browser.py) for the page. The rig runs in
 * this process (its loop stepped while a client child runs), so each check reads the rig's
 * own state: the control map's positions and the scene's parameters, not what the server
 * says about them. Ports 18080-18099 (this area's range in the test plan). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "firmware/rig/config.h"
#include "firmware/rig/rig.h"
#include "firmware/rig/status_json.h"
#include "firmware/version.h"
#include "hal/dev.h"
#include "render/base/json.h"
#include "render/scene/scene.h"
#include "tests/support/fs.h"
#include "tests/support/hal_test.h"

#define MS 1000000LL
#define TOKEN "s3cret-token-0123456789"

static double scene_num(lr_rig *r, const char *key)
{
    char buf[128];
    lr_err e = {0};
    if (lr_scene_get(lr_rig_scene(r), key, buf, sizeof buf, &e))
        fail_msg("%s", e.msg);
    return strtod(buf, NULL);
}

static void scene_str(lr_rig *r, const char *key, char *buf, size_t cap)
{
    lr_err e = {0};
    if (lr_scene_get(lr_rig_scene(r), key, buf, cap, &e))
        fail_msg("%s", e.msg);
}

/* Runs argv as a child, its stdout captured, while the rig's loop runs in steps of 5 ms;
 * returns its exit status (-1: killed at timeout_s) and the output in *out (malloc'd). */
static int run_client(lr_rig *r, char *const argv[], char **out, double timeout_s)
{
    int p[2];
    assert_int_equal(pipe(p), 0);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        dup2(p[1], 1);
        close(p[0]);
        close(p[1]);
        execvp(argv[0], argv);
        fprintf(stderr, "exec %s: %s\n", argv[0], strerror(errno));
        _exit(127);
    }
    close(p[1]);
    fcntl(p[0], F_SETFL, O_NONBLOCK);
    size_t len = 0, cap = 4096;
    char *buf = malloc(cap);
    assert_non_null(buf);
    int64_t end = lr_now_ns() + (int64_t)(timeout_s * 1e9);
    int status = 0;
    bool exited = false, eof = false;
    lr_err e = {0};
    while (!(exited && eof)) {
        assert_int_equal(lr_rig_run_until(r, lr_now_ns() + 5 * MS, &e), LR_OK);
        for (;;) {
            if (len + 4096 > cap)
                assert_non_null(buf = realloc(buf, cap *= 2));
            ssize_t n = read(p[0], buf + len, cap - len - 1);
            if (n > 0) {
                len += (size_t)n;
                continue;
            }
            eof |= n == 0;
            break;
        }
        if (!exited && waitpid(pid, &status, WNOHANG) == pid)
            exited = true;
        if (!exited && lr_now_ns() > end) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            exited = true;
            status = -1;
        }
    }
    close(p[0]);
    buf[len] = '\0';
    *out = buf;
    return status == -1 ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* One request with curl: returns the body (malloc'd) and the HTTP status in *code. extra:
 * more curl arguments (headers), NULL-terminated. */
static char *http(lr_rig *r, int port, const char *method, const char *path, const char *body,
                  const char *const *extra, long *code)
{
    char url[128], tail[] = "\n%{http_code}";
    snprintf(url, sizeof url, "http://127.0.0.1:%d%s", port, path);
    const char *argv[32] = {"curl", "-s", "-S", "-m", "10", "-w", tail, "-X", method};
    int n = 9;
    if (body) {
        argv[n++] = "--data-binary";
        argv[n++] = body;
    }
    for (int i = 0; extra && extra[i]; i++)
        argv[n++] = extra[i];
    argv[n++] = url;
    argv[n] = NULL;
    char *out;
    int rc = run_client(r, (char *const *)argv, &out, 15);
    if (rc != 0)
        fail_msg("curl %s %s: exit %d: %s", method, url, rc, out);
    char *nl = strrchr(out, '\n');
    assert_non_null(nl);
    *nl = '\0';
    *code = strtol(nl + 1, NULL, 10);
    return out;
}

static const char *const JSON_CT[] = {"-H", "Content-Type: application/json", NULL};

/* A POST with a JSON content type. */
static char *post(lr_rig *r, int port, const char *path, const char *body, long *code)
{
    return http(r, port, "POST", path, body, JSON_CT, code);
}

/* A 4xx answer: the status expected and a JSON body {"error": non-empty, "status": same}. */
static void expect_error(char *body, const long *pcode, long want, const char *what)
{
    /* The status by pointer: read after the request, which is an argument of this call. */
    long code = *pcode;
    if (code != want)
        fail_msg("%s: status %ld, expected %ld: %s", what, code, want, body);
    lr_json *j;
    lr_err e = {0};
    if (lr_json_parse(body, strlen(body), what, &j, &e))
        fail_msg("%s: the error body is not JSON: %s: %s", what, e.msg, body);
    char msg[512] = "";
    long st = 0;
    assert_int_equal(lr_json_get_string(j, lr_json_root(j), "error", true, msg, sizeof msg, &e),
                     LR_OK);
    assert_int_equal(lr_json_get_int(j, lr_json_root(j), "status", true, &st, &e), LR_OK);
    assert_true(strlen(msg) > 0);
    assert_int_equal(st, want);
    lr_json_destroy(j);
    free(body);
}

/* Runs the loop for ms milliseconds (an event posted is drained at the next wake). */
static void run_ms(lr_rig *r, int ms)
{
    lr_err e = {0};
    assert_int_equal(lr_rig_run_until(r, lr_now_ns() + ms * MS, &e), LR_OK);
}

/* Turns the loop until the scene shown is file `name` (a scene loads and plans in a job, off
 * the loop: firmware/rig/job.h); a minute's guard. */
static void run_until_scene(lr_rig *r, const char *name)
{
    int64_t guard = lr_now_ns() + 60000 * MS;
    while (!strstr(lr_scene_path(lr_rig_scene(r)), name) && lr_now_ns() < guard)
        run_ms(r, 20);
    assert_non_null(strstr(lr_scene_path(lr_rig_scene(r)), name));
}

/* The rig of these tests: the candle's map cut to a dimmer, a material and a scene binding,
 * no devices (nothing else moves the controls). renderer "preview" (no GL, instant) or
 * "passes" with the planner (what the shipped sim rig shows), at w x h. */
static lr_rig *make_rig_at(const char *dir, int port, const char *http_extra,
                           const char *renderer, int w, int h, lr_test_log *log)
{
    char text[4096];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"scene_set\": {\"render.K\": 4, \"render.N\": 4, \"render.map_size\": 64,\n"
             "               \"render.gbuffer_size\": 64, \"render.vpl_map_size\": 32,\n"
             "               \"render.N_vpl\": 16, \"render.frames\": 8},\n"
             " \"devices\": [],\n"
             " \"controls\": [\n"
             "  {\"name\": \"dimmer\", \"control\": \"dimmer\", \"param\": \"light.level\",\n"
             "   \"range\": [0, 2], \"initial\": 0.5},\n"
             "  {\"name\": \"material\", \"control\": \"button1\",\n"
             "   \"param\": \"objects[0].material\", \"values\": [\"candle_wax\", \"marble\"],\n"
             "   \"initial\": 0},\n"
             "  {\"name\": \"scene\", \"control\": \"button2\", \"param\": \"scene\",\n"
             "   \"values\": [\"%s/scenes/candle.json\", \"%s/scenes/votive.json\"]}],\n"
             " \"output\": {\"width\": %d, \"height\": %d, \"fps\": 30, \"renderer\": \"%s\"},\n"
             " \"http\": {\"listen\": \"127.0.0.1:%d\"%s}}\n",
             LR_SOURCE_CONFIGS, LR_SOURCE_CONFIGS, LR_SOURCE_CONFIGS, w, h, renderer, port,
             http_extra);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, log},
                     .no_plan = strcmp(renderer, "passes") != 0};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    free(cfg);
    assert_int_equal(lr_rig_http_port(r), port);
    return r;
}

static lr_rig *make_rig(const char *dir, int port, const char *http_extra, const char *renderer,
                        lr_test_log *log)
{
    return make_rig_at(dir, port, http_extra, renderer, 160, 120, log);
}

static lr_json *parse(const char *body)
{
    lr_json *j;
    lr_err e = {0};
    if (lr_json_parse(body, strlen(body), "answer", &j, &e))
        fail_msg("%s: %s", e.msg, body);
    return j;
}

/* The control named `name` in a controls array. */
static lr_jnode control_node(const lr_json *j, lr_jnode arr, const char *name)
{
    for (int i = 0; i < lr_json_count(j, arr); i++) {
        char n[64] = "";
        lr_json_get_string(j, lr_json_at(j, arr, i), "name", true, n, sizeof n, NULL);
        if (strcmp(n, name) == 0)
            return lr_json_at(j, arr, i);
    }
    fail_msg("no control %s", name);
    return LR_JNONE;
}

/* Every endpoint: status and controls documents, a control moved, a material and two scene
 * switches (configured and shipped), a reload, the frame, the event stream. */
static void test_http_api(void **state)
{
    (void)state;
    const int port = 18081;
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = make_rig(dir, port, "", "preview", &log);
    run_ms(r, 50);
    /* initial 0.5 on range [0, 2]: the factor 1, the candle's own intensity. */
    double base = scene_num(r, "light.intensity");
    assert_true(base > 0);

    long code;
    char *b = http(r, port, "GET", "/api/status", NULL, NULL, &code);
    assert_int_equal(code, 200);
    lr_json *j = parse(b);
    lr_jnode root = lr_json_root(j);
    char s[256];
    lr_err e = {0};
    assert_int_equal(lr_json_get_string(j, root, "version", true, s, sizeof s, &e), LR_OK);
    assert_string_equal(s, lr_version());
    assert_int_equal(lr_json_get_string(j, root, "scene", true, s, sizeof s, &e), LR_OK);
    assert_string_equal(s, "candle.json");
    long frames = 0;
    assert_int_equal(lr_json_get_int(j, root, "frames", true, &frames, &e), LR_OK);
    assert_true(frames >= 1);
    static const char *const members[] = {"uptime_s", "fps", "frame_interval_p99_ms",
                                          "latency_ms", "devices", "plan", "warnings",
                                          "errors", "controls"};
    for (size_t i = 0; i < sizeof members / sizeof members[0]; i++)
        if (lr_json_get(j, root, members[i]) == LR_JNONE)
            fail_msg("status without '%s'", members[i]);
    assert_int_equal(lr_json_count(j, lr_json_get(j, root, "controls")), 3);
    lr_json_destroy(j);
    free(b);

    b = post(r, port, "/api/controls/dimmer", "{\"value\": 0.25}", &code);
    assert_int_equal(code, 200);
    free(b);
    run_ms(r, 30);
    /* Through the control map: linear curve, no fade, range [0, 2] -> factor 2 * 0.25. */
    assert_true(fabs(scene_num(r, "light.intensity") - 0.5 * base) <= 1e-12 * base);
    b = http(r, port, "GET", "/api/controls", NULL, NULL, &code);
    assert_int_equal(code, 200);
    j = parse(b);
    double pos = -1;
    assert_int_equal(lr_json_get_number(j, control_node(j, lr_json_root(j), "dimmer"),
                                        "position", true, &pos, &e), LR_OK);
    assert_true(pos == 0.25); /* the event's value itself, written back exactly */
    lr_json_destroy(j);
    free(b);

    /* A cycle binding takes value floor(0.75 * 2) = 1. */
    b = post(r, port, "/api/controls/material", "{\"value\": 0.75}", &code);
    assert_int_equal(code, 200);
    free(b);
    run_ms(r, 30);
    scene_str(r, "objects[0].material.base", s, sizeof s);
    assert_string_equal(s, "marble");

    /* A configured scene (the binding's value, through the map), then a shipped one. */
    b = post(r, port, "/api/scene", "{\"scene\": \"votive\"}", &code);
    assert_int_equal(code, 200);
    free(b);
    run_until_scene(r, "votive.json");
    b = post(r, port, "/api/scene", "{\"scene\": \"lampshade.json\"}", &code);
    assert_int_equal(code, 200);
    free(b);
    run_until_scene(r, "lampshade.json");

    b = post(r, port, "/api/reload", "{}", &code);
    assert_int_equal(code, 200);
    free(b);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_int_equal(info.reloads, 1);
    /* Loaded in a job while the loop served the connection (suspended) and the frames. */
    assert_int_equal(lr_test_log_count(&log, "reload: loaded and planned off the loop in "), 1);
    assert_non_null(strstr(lr_scene_path(lr_rig_scene(r)), "candle.json"));

    /* The frame: a PNG of the output's size, numbered. */
    run_ms(r, 100);
    char *png = lr_test_path(dir, "frame.png");
    const char *const fx[] = {"-o", png, "-D", "-", NULL};
    b = http(r, port, "GET", "/frame.png", NULL, fx, &code);
    assert_int_equal(code, 200);
    assert_non_null(strstr(b, "Content-Type: image/png"));
    assert_non_null(strstr(b, "X-Lamprig-Frame: "));
    free(b);
    size_t n;
    unsigned char *p = lr_test_read(png, &n);
    assert_true(n > 33);
    assert_memory_equal(p, "\x89PNG\r\n\x1a\n", 8);
    /* IHDR: width and height big-endian at bytes 16 and 20. */
    assert_int_equal((p[16] << 24) | (p[17] << 16) | (p[18] << 8) | p[19], 160);
    assert_int_equal((p[20] << 24) | (p[21] << 16) | (p[22] << 8) | p[23], 120);
    free(p);
    free(png);

    /* The event stream: the status at once, then the control a POST moved. The shell runs
     * the stream for 1.5 s and the POST 0.5 s into it. */
    char script[512];
    snprintf(script, sizeof script,
             "curl -sN -m 1.5 http://127.0.0.1:%d/api/events & sleep 0.5; "
             "curl -s -o /dev/null -X POST -H 'Content-Type: application/json' "
             "--data-binary '{\"value\": 0.75}' http://127.0.0.1:%d/api/controls/dimmer; wait",
             port, port);
    char *const sh[] = {"sh", "-c", script, NULL};
    char *out;
    run_client(r, sh, &out, 10);
    assert_non_null(strstr(out, "event: status\ndata: {"));
    char *ctl = strstr(out, "event: controls\n");
    assert_non_null(ctl);
    assert_non_null(strstr(ctl, "\"position\": 0.75"));
    free(out);
    /* The producer the endpoint and other publishers share: the same position, valid JSON. */
    lr_rig_status *st = calloc(1, sizeof *st);
    assert_non_null(st);
    lr_rig_get_status(r, st);
    assert_string_equal(st->controls[0].name, "dimmer");
    assert_true(st->controls[0].position == 0.75);
    char *doc = lr_status_json_string(st, false, NULL);
    assert_non_null(doc);
    lr_json_destroy(parse(doc));
    free(doc);
    free(st);

    lr_rig_destroy(r);
    lr_test_rmtree(dir);
}

/* Every kind of bad request gets its 4xx and a JSON error; the rig is unchanged by them. */
static void test_http_bad_requests(void **state)
{
    (void)state;
    const int port = 18082;
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = make_rig(dir, port, "", "preview", &log);
    run_ms(r, 50);
    double before = scene_num(r, "light.intensity");
    long code;
    expect_error(post(r, port, "/api/controls/dimmer", "{\"value\": ", &code), &code, 400,
                 "malformed JSON");
    expect_error(post(r, port, "/api/controls/dimmer", "[0.5]", &code), &code, 400, "an array");
    expect_error(post(r, port, "/api/controls/dimmer", "{\"value\": 1.5}", &code), &code, 400,
                 "out of 0..1");
    expect_error(post(r, port, "/api/controls/dimmer", "{\"value\": -0.1}", &code), &code, 400,
                 "negative");
    expect_error(post(r, port, "/api/controls/dimmer", "{\"value\": \"half\"}", &code), &code,
                 400, "a string value");
    expect_error(post(r, port, "/api/controls/dimmer", "{\"value\": 0.5, \"x\": 1}", &code),
                 &code, 400, "an unknown field");
    expect_error(post(r, port, "/api/controls/dimmer", "{}", &code), &code, 400, "no value");
    expect_error(post(r, port, "/api/controls/nosuch", "{\"value\": 0.5}", &code), &code, 404,
                 "an unknown control");
    expect_error(post(r, port, "/api/scene", "{\"scene\": \"../../etc/passwd\"}", &code), &code,
                 404, "a path as scene");
    expect_error(post(r, port, "/api/scene", "{\"scene\": \"nosuch\"}", &code), &code, 404,
                 "an unknown scene");
    expect_error(post(r, port, "/api/reload", "{\"now\": true}", &code), &code, 400,
                 "a reload with a field");
    expect_error(http(r, port, "GET", "/api/nothing", NULL, NULL, &code), &code, 404,
                 "an unknown path");
    expect_error(http(r, port, "DELETE", "/api/status", NULL, NULL, &code), &code, 405,
                 "DELETE");
    expect_error(http(r, port, "GET", "/api/controls/dimmer", NULL, NULL, &code), &code, 405,
                 "GET of a POST path");
    expect_error(http(r, port, "POST", "/api/controls/dimmer", "{\"value\": 0.5}", NULL, &code),
                 &code, 415, "a form POST (no JSON content type)");
    const char *const host[] = {"-H", "Host: rebind.example.com", NULL};
    expect_error(http(r, port, "GET", "/api/status", NULL, host, &code), &code, 403,
                 "a foreign Host header");
    /* LR_HTTP_BODY_MAX + 1 bytes: refused by its Content-Length before it is read. */
    char *big = malloc(4098);
    memset(big, ' ', 4097);
    big[4097] = '\0';
    big[0] = '{';
    big[4096] = '}';
    expect_error(post(r, port, "/api/controls/dimmer", big, &code), &code, 413,
                 "an oversized body");
    free(big);
    /* None of them moved anything. */
    run_ms(r, 30);
    assert_true(scene_num(r, "light.intensity") == before);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_int_equal(info.events, 0);
    assert_int_equal(info.reloads, 0);

    /* The rate limit: a bucket of LR_HTTP_BURST (200) refilled at LR_HTTP_RATE (100/s), so
     * N requests in T seconds get at least N - 200 - 100 T answers 429 (fewer only if the
     * bucket were bigger or faster); with N = 400 and T under 2 s that is more than 0. */
    char url[64];
    snprintf(url, sizeof url, "http://127.0.0.1:%d/api/status", port);
    enum { N = 400 };
    const char *argv[N + 8] = {"curl", "-s", "-o", "/dev/null", "-w", "%{http_code}\n"};
    for (int i = 0; i < N; i++)
        argv[6 + i] = url;
    argv[6 + N] = NULL;
    char *out;
    int64_t t0 = lr_now_ns();
    assert_int_equal(run_client(r, (char *const *)argv, &out, 30), 0);
    double took = (double)(lr_now_ns() - t0) * 1e-9;
    int ok = 0, limited = 0;
    for (char *l = out; *l; l++) {
        ok += strncmp(l, "200", 3) == 0;
        limited += strncmp(l, "429", 3) == 0;
        l = strchr(l, '\n');
        if (!l)
            break;
    }
    free(out);
    assert_int_equal(ok + limited, N);
    if (took < 2.0)
        assert_true(limited >= (int)floor(N - 200 - 100 * took));
    else
        print_message("rate limit: %d requests took %.2f s, the lower bound is vacuous\n", N,
                      took);
    assert_true(limited > 0 || took >= 2.0);
    lr_rig_destroy(r);
    lr_test_rmtree(dir);
}

/* The status producer alone (firmware/rig/status_json.h), as any publisher uses it: known
 * values come back exactly, unmeasured ones (NaN, no lamp) as null, strings escaped. */
static void test_status_json(void **state)
{
    (void)state;
    lr_rig_status *st = calloc(1, sizeof *st);
    assert_non_null(st);
    lr_rig_status_line warn = {1.5, "a \"quoted\" line\nand a second"};
    *st = (lr_rig_status){.version = "9.9", .config = "c.json", .scene = "candle.json",
                          .output = "headless", .view = "preview", .uptime_s = 12.25,
                          .frames = 7, .events = 3, .lamp_level = -1, .fps = 29.5,
                          .frame_interval_p99_ms = NAN, .latency_n = 3,
                          .latency_median_ms = 2.5, .latency_p99_ms = NAN, .n_devices = 1,
                          .plan_text = "", .plan_error = NAN, .plan_frame_ms = NAN,
                          .n_warnings = 1, .warnings = &warn, .n_controls = 2};
    st->devices[0] = (lr_rig_status_dev){"sim", "sim", "open"};
    st->controls[0] = (lr_rig_status_control){.name = "dimmer", .source = "", .control = "d",
                                              .param = "light.level", .position = 0.25,
                                              .level = 0.0625};
    st->controls[1] = (lr_rig_status_control){.name = "m", .source = "panel", .control = "b",
                                              .param = "objects[0].material", .cycle = true,
                                              .index = 1, .n_values = 2,
                                              .values = {"wax", "marble"}};
    size_t len = 0;
    char *doc = lr_status_json_string(st, false, &len);
    assert_non_null(doc);
    assert_int_equal(len, strlen(doc));
    lr_json *j = parse(doc);
    lr_jnode root = lr_json_root(j);
    lr_err e = {0};
    double v;
    assert_int_equal(lr_json_get_number(j, root, "uptime_s", true, &v, &e), LR_OK);
    assert_true(v == 12.25);
    assert_int_equal(lr_json_get_number(j, root, "fps", true, &v, &e), LR_OK);
    assert_true(v == 29.5);
    assert_int_equal(lr_json_type(j, lr_json_get(j, root, "lamp_level")), LR_JSON_NULL);
    assert_int_equal(lr_json_type(j, lr_json_get(j, root, "frame_interval_p99_ms")),
                     LR_JSON_NULL);
    lr_jnode lat = lr_json_get(j, root, "latency_ms");
    assert_int_equal(lr_json_get_number(j, lat, "median", true, &v, &e), LR_OK);
    assert_true(v == 2.5);
    assert_int_equal(lr_json_type(j, lr_json_get(j, lat, "p99")), LR_JSON_NULL);
    char msg[128];
    lr_jnode w0 = lr_json_at(j, lr_json_get(j, root, "warnings"), 0);
    assert_int_equal(lr_json_get_string(j, w0, "msg", true, msg, sizeof msg, &e), LR_OK);
    assert_string_equal(msg, warn.msg);
    lr_jnode ctl = lr_json_get(j, root, "controls");
    assert_int_equal(lr_json_count(j, ctl), 2);
    assert_int_equal(lr_json_get_number(j, lr_json_at(j, ctl, 0), "level", true, &v, &e),
                     LR_OK);
    assert_true(v == 0.0625);
    lr_jnode vals = lr_json_get(j, lr_json_at(j, ctl, 1), "values");
    assert_int_equal(lr_json_count(j, vals), 2);
    assert_int_equal(lr_json_string(j, lr_json_at(j, vals, 1), "v", msg, sizeof msg, &e), LR_OK);
    assert_string_equal(msg, "marble");
    lr_json_destroy(j);
    free(doc);
    /* The controls alone: the same array. */
    doc = lr_status_json_string(st, true, NULL);
    assert_non_null(doc);
    j = parse(doc);
    assert_int_equal(lr_json_type(j, lr_json_root(j)), LR_JSON_ARRAY);
    assert_int_equal(lr_json_count(j, lr_json_root(j)), 2);
    lr_json_destroy(j);
    free(doc);
    free(st);
}

/* The status's frame figures on a rig that wants a frame at every slot: a looping sim
 * script moves the dimmer every 10 ms, faster than the 20 ms slots of fps 50. Headless frames
 * start at least 1/fps apart (the loop's pacing), so over any span the measured rate is at
 * most fps, and every interval, the p99 included, is at least 1/fps = 20 ms. */
static void test_status_frame_rate(void **state)
{
    (void)state;
    char *dir = lr_test_tmpdir();
    char text[1024];
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\",\n"
             " \"devices\": [{\"type\": \"sim\", \"loop\": true, \"text\": "
             "\"0.00 dimmer absolute 0.2\\n0.01 dimmer absolute 0.4\\n0.02 end\\n\"}],\n"
             " \"controls\": [{\"control\": \"dimmer\", \"param\": \"light.level\", "
             "\"range\": [0, 2]}],\n"
             " \"output\": {\"width\": 16, \"height\": 16, \"fps\": 50, \"renderer\": \"preview\"},\n"
             " \"http\": {\"listen\": \"127.0.0.1:18087\"}}\n",
             LR_SOURCE_CONFIGS);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, &log},
                     .no_plan = true};
    lr_rig *r;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    run_ms(r, 1500);
    lr_rig_status *st = calloc(1, sizeof *st);
    assert_non_null(st);
    lr_rig_get_status(r, st);
    print_message("status: %.2f fps, interval p99 %.2f ms over %llu frames\n", st->fps,
                  st->frame_interval_p99_ms, (unsigned long long)st->frames);
    assert_true(st->frames >= 3);
    assert_true(st->fps > 0 && st->fps <= 50.0);
    assert_true(st->frame_interval_p99_ms >= 20.0);
    free(st);
    lr_rig_destroy(r);
    free(cfg);
    lr_test_rmtree(dir);
}

/* Replaces every occurrence of `from` in s (malloc'd, at most 8 KB) by `to`; returns it. */
static char *replace_all(const char *s, const char *from, const char *to)
{
    char *out = malloc(8192);
    assert_non_null(out);
    size_t o = 0, fl = strlen(from), tl = strlen(to);
    for (const char *p = s; *p;) {
        if (strncmp(p, from, fl) == 0) {
            assert_true(o + tl < 8192);
            memcpy(out + o, to, tl);
            o += tl;
            p += fl;
        } else {
            assert_true(o + 1 < 8192);
            out[o++] = *p++;
        }
    }
    out[o] = '\0';
    return out;
}

/* The shipped sim rig (configs/rig/sim.json) serves the page and the API on 127.0.0.1:8080;
 * run here on 18080 (its relative paths made absolute, the file copied to a scratch folder),
 * with its script moving the controls: the status names its device, the page is served, and
 * the stream carries the script's control moves. */
static void test_http_shipped_sim_rig(void **state)
{
    (void)state;
    lr_rig_config *c = NULL;
    lr_err e = {0};
    if (lr_rig_config_load(LR_SOURCE_CONFIGS "/rig/sim.json", &c, &e))
        fail_msg("%s", e.msg);
    assert_true(c->http.enabled && c->http.loopback);
    assert_string_equal(c->http.host, "127.0.0.1");
    assert_int_equal(c->http.port, 8080);
    assert_string_equal(c->http.token, "");
    lr_rig_config_destroy(c);
    size_t n;
    char *text = (char *)lr_test_read(LR_SOURCE_CONFIGS "/rig/sim.json", &n);
    char *a = replace_all(text, "\"../", "\"" LR_SOURCE_CONFIGS "/");
    char *b2 = replace_all(a, "\"sim-demo.sim\"", "\"" LR_SOURCE_CONFIGS "/rig/sim-demo.sim\"");
    char *t2 = replace_all(b2, "127.0.0.1:8080", "127.0.0.1:18080");
    assert_non_null(strstr(t2, "127.0.0.1:18080"));
    char *dir = lr_test_tmpdir();
    char *cfg = lr_test_write(dir, "sim.json", t2, (size_t)-1);
    free(text);
    free(a);
    free(b2);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, &log}};
    lr_rig *r;
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_rig_http_port(r), 18080);
    long code;
    char *body = http(r, 18080, "GET", "/api/status", NULL, NULL, &code);
    assert_int_equal(code, 200);
    assert_non_null(strstr(body, "\"name\": \"sim\""));
    assert_non_null(strstr(body, "\"state\": \"open\""));
    free(body);
    const char *const hdr[] = {"-D", "-", NULL};
    body = http(r, 18080, "GET", "/", NULL, hdr, &code);
    assert_int_equal(code, 200);
    assert_non_null(strstr(body, "Content-Type: text/html; charset=utf-8"));
    assert_non_null(strstr(body, "X-Frame-Options: DENY"));
    assert_non_null(strstr(body, "frame-ancestors 'none'"));
    assert_non_null(strstr(body, "<title>lamprig</title>"));
    assert_non_null(strstr(body, "/api/events"));
    free(body);
    /* configs/rig/sim-demo.sim moves a control at least every 0.95 s (its longest gap, and
     * it loops): 2 s of the stream hold at least one "controls" event. */
    char *const argv[] = {"curl", "-sN", "-m", "2", "http://127.0.0.1:18080/api/events", NULL};
    char *out;
    run_client(r, argv, &out, 10);
    assert_non_null(strstr(out, "event: status\n"));
    assert_non_null(strstr(out, "event: controls\n"));
    free(out);
    /* A reload that fails after its config loaded and its scene (the lamp shade) was
     * planned: a required HID knob that is not there. 422 with the reason, the old config
     * runs on, and the status still shows the running scene's plan, not the lamp shade's. */
    body = http(r, 18080, "GET", "/api/status", NULL, NULL, &code);
    lr_json *j = parse(body);
    lr_jnode plan = lr_json_get(j, lr_json_root(j), "plan");
    bool planned = false;
    char plan_text[512] = "";
    assert_int_equal(lr_json_get_bool(j, plan, "planned", true, &planned, &e), LR_OK);
    assert_true(planned);
    assert_int_equal(lr_json_get_string(j, plan, "text", true, plan_text, sizeof plan_text,
                                        &e), LR_OK);
    assert_true(strlen(plan_text) > 0);
    lr_json_destroy(j);
    free(body);
    char *t3 = replace_all(t2, "scenes/candle.json", "scenes/lampshade.json");
    char *t4 = replace_all(t3, "\"devices\": [",
                           "\"devices\": [{\"type\": \"hid\", \"name\": \"knob\", "
                           "\"vid\": \"dead\", \"pid\": \"beef\", \"required\": true},");
    assert_non_null(strstr(t4, "lampshade.json"));
    assert_non_null(strstr(t4, "\"required\": true"));
    lr_test_put(cfg, t4, (size_t)-1);
    free(t3);
    free(t4);
    free(t2);
    body = post(r, 18080, "/api/reload", NULL, &code);
    if (code != 422 || !strstr(body, "knob") || !strstr(body, "keeping the running config"))
        fail_msg("reload with a missing required device: %ld %s", code, body);
    free(body);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_int_equal(info.reload_failures, 1);
    body = http(r, 18080, "GET", "/api/status", NULL, NULL, &code);
    j = parse(body);
    plan = lr_json_get(j, lr_json_root(j), "plan");
    char text2[512] = "";
    assert_int_equal(lr_json_get_string(j, plan, "text", true, text2, sizeof text2, &e), LR_OK);
    assert_string_equal(text2, plan_text);
    assert_non_null(strstr(text2, "candle"));
    lr_json_destroy(j);
    free(body);
    lr_rig_destroy(r);
    free(cfg);
    lr_test_rmtree(dir);
}

/* Bytes that are not HTTP (tests/fw/http_garbage.py): libmicrohttpd answers them itself (400,
 * 414, 431) or closes; the over-limit chunked body gets the rig's 413; the rig answers
 * normally afterwards, and none of it reached the control map. */
static void test_http_garbage(void **state)
{
    (void)state;
    const int port = 18085;
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = make_rig(dir, port, "", "preview", &log);
    char ps[16];
    snprintf(ps, sizeof ps, "%d", port);
    char *const argv[] = {"python3", LR_SOURCE_CONFIGS "/../tests/fw/http_garbage.py", ps, "1",
                          NULL};
    char *out;
    int rc = run_client(r, argv, &out, 60);
    if (rc != 0)
        fail_msg("http_garbage.py: exit %d: %s", rc, out);
    print_message("garbage: %s", out);
    assert_non_null(strstr(out, "\"HTTP/1.1 400\""));
    assert_non_null(strstr(out, "\"HTTP/1.1 413\""));
    assert_non_null(strstr(out, "\"HTTP/1.1 414\""));
    assert_non_null(strstr(out, "\"HTTP/1.1 431\""));
    free(out);
    long code;
    char *b = http(r, port, "GET", "/api/status", NULL, NULL, &code);
    assert_int_equal(code, 200);
    free(b);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_int_equal(info.events, 0);
    /* MHD's own messages are rate-limited in the log: at most 5 in 10 s, plus the count. */
    assert_true(lr_test_log_count(&log, "http: ") <= 1 + 5 + 1);
    lr_rig_destroy(r);
    lr_test_rmtree(dir);
}

/* With a token, a POST needs it (Bearer); reads do not. */
static void test_http_token(void **state)
{
    (void)state;
    const int port = 18083;
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = make_rig(dir, port, ", \"token\": \"" TOKEN "\"", "preview", &log);
    long code;
    expect_error(post(r, port, "/api/controls/dimmer", "{\"value\": 0.1}", &code), &code, 401,
                 "no token");
    const char *const wrong[] = {"-H", "Content-Type: application/json", "-H",
                                 "Authorization: Bearer " TOKEN "x", NULL};
    expect_error(http(r, port, "POST", "/api/controls/dimmer", "{\"value\": 0.1}", wrong, &code),
                 &code, 401, "a wrong token");
    const char *const right[] = {"-H", "Content-Type: application/json", "-H",
                                 "Authorization: Bearer " TOKEN, NULL};
    char *b = http(r, port, "POST", "/api/controls/dimmer", "{\"value\": 0.1}", right, &code);
    assert_int_equal(code, 200);
    free(b);
    b = http(r, port, "GET", "/api/status", NULL, NULL, &code);
    assert_int_equal(code, 200);
    free(b);
    run_ms(r, 30);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    assert_int_equal(info.events, 1); /* the one with the token */
    lr_rig_destroy(r);
    lr_test_rmtree(dir);
}

/* The "http" block's checks, each naming its field; and a port already taken fails the
 * start with the address in the message. */
static void test_http_config(void **state)
{
    (void)state;
    static const struct {
        const char *http, *field, *says;
    } bad[] = {
        {"{\"listen\": \"0.0.0.0:8080\"}", "http.token", "not a loopback address"},
        {"{\"listen\": \"[::]:8080\"}", "http.token", "not a loopback address"},
        {"{\"listen\": \"192.168.1.5:8080\", \"token\": \"short\"}", "http.token",
         "at least 16"},
        {"{\"listen\": \"localhost:8080\"}", "http.listen", "not a numeric"},
        {"{\"listen\": \"127.0.0.1\"}", "http.listen", "ADDRESS:PORT"},
        {"{\"listen\": \"127.0.0.1:0\"}", "http.listen", "ADDRESS:PORT"},
        {"{\"listen\": \"127.0.0.1:65536\"}", "http.listen", "ADDRESS:PORT"},
        {"{\"port\": 8080}", "http.port", "unknown field"},
        {"{\"listen\": \"127.0.0.1:8080\", \"token\": \"has a space in it!!\"}", "http.token",
         "without spaces"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "{\"scene\": \"%s/scenes/candle.json\", \"controls\": [],\n \"http\": %s}\n",
                 LR_SOURCE_CONFIGS, bad[i].http);
        lr_rig_config *c = NULL;
        lr_err e = {0};
        assert_int_not_equal(lr_rig_config_parse(text, "rig.json", &c, &e), LR_OK);
        char want[64];
        snprintf(want, sizeof want, "field '%s'", bad[i].field);
        if (!strstr(e.msg, want) || !strstr(e.msg, bad[i].says) || !strstr(e.msg, "rig.json:2"))
            fail_msg("%s: %s", bad[i].http, e.msg);
    }
    static const struct {
        const char *http;
        bool loopback;
    } good[] = {
        {"{\"listen\": \"127.0.0.1:8080\"}", true},
        {"{\"listen\": \"127.1.2.3:8080\"}", true},
        {"{\"listen\": \"[::1]:8080\"}", true},
        {"{\"listen\": \"0.0.0.0:8080\", \"token\": \"" TOKEN "\"}", false},
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "{\"scene\": \"%s/scenes/candle.json\", \"controls\": [], \"http\": %s}\n",
                 LR_SOURCE_CONFIGS, good[i].http);
        lr_rig_config *c = NULL;
        lr_err e = {0};
        if (lr_rig_config_parse(text, "rig.json", &c, &e))
            fail_msg("%s: %s", good[i].http, e.msg);
        assert_true(c->http.enabled);
        assert_int_equal(c->http.port, 8080);
        assert_int_equal(c->http.loopback, good[i].loopback);
        lr_rig_config_destroy(c);
    }
    /* No "http": nothing listens. */
    lr_rig_config *c = NULL;
    char text[512];
    snprintf(text, sizeof text, "{\"scene\": \"%s/scenes/candle.json\", \"controls\": []}\n",
             LR_SOURCE_CONFIGS);
    assert_int_equal(lr_rig_config_parse(text, "rig.json", &c, NULL), LR_OK);
    assert_false(c->http.enabled);
    lr_rig_config_destroy(c);

    /* A port in use: the rig runs without the endpoint, says so once, and listens as soon
     * as the port is free (retried every 2 s). */
    const int port = 18084;
    int s = socket(AF_INET, SOCK_STREAM, 0);
    assert_true(s >= 0);
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons(port)};
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(s, (struct sockaddr *)&a, sizeof a), 0);
    assert_int_equal(listen(s, 1), 0);
    char *dir = lr_test_tmpdir();
    snprintf(text, sizeof text,
             "{\"scene\": \"%s/scenes/candle.json\", \"controls\": [],\n"
             " \"output\": {\"width\": 16, \"height\": 16, \"renderer\": \"preview\"},\n"
             " \"http\": {\"listen\": \"127.0.0.1:%d\"}}\n",
             LR_SOURCE_CONFIGS, port);
    char *cfg = lr_test_write(dir, "rig.json", text, (size_t)-1);
    lr_test_log log = {0};
    lr_rig_opts o = {.config = cfg, .no_signals = true, .log = {lr_test_log_fn, &log}};
    lr_rig *r = NULL;
    lr_err e = {0};
    if (lr_rig_create(&o, &r, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(lr_rig_http_port(r), 0);
    assert_int_equal(lr_test_log_count(&log, "http.listen 127.0.0.1:18084: cannot listen"), 1);
    run_ms(r, 300);
    assert_int_equal(lr_test_log_count(&log, "cannot listen"), 1); /* once, not per retry */
    close(s);
    run_ms(r, 2200);
    assert_int_equal(lr_rig_http_port(r), port);
    long code;
    char *b = http(r, port, "GET", "/api/status", NULL, NULL, &code);
    assert_int_equal(code, 200);
    free(b);
    lr_rig_destroy(r);
    free(cfg);
    lr_test_rmtree(dir);
}

/* The page in headless chromium (tests/fw/http_browser.py over chromedriver): it loads,
 * shows the frame, the dimmer's slider moved with the keyboard reaches the rig through the
 * control map (the scene's light changes), the page shows the rig's new position and a newer
 * frame; the screenshot is build/test/http-page.png (firmware/README.md, README.md show it).
 * The real renderer, so that the picture is the rig's: the browser starts once the view has
 * converged (within 6 s: under load the picture may then be a coarse preview, the checks
 * are the same). */
static void test_http_browser(void **state)
{
    (void)state;
    const int port = 18086;
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = make_rig_at(dir, port, "", "passes", 320, 240, &log);
    lr_rig_info info;
    int64_t t0 = lr_now_ns();
    do {
        run_ms(r, 50);
        lr_rig_get_info(r, &info);
    } while (!info.idle && lr_now_ns() - t0 < 6000 * MS);
    print_message("browser: the view converged in %.1f s%s\n", (double)(lr_now_ns() - t0) * 1e-9,
                  info.idle ? "" : " (not within the 6 s bound: the screenshot may show a preview)");
    double base = scene_num(r, "light.intensity");
    char url[64];
    snprintf(url, sizeof url, "http://127.0.0.1:%d/", port);
    const char *shot = LR_SOURCE_CONFIGS "/../build/test/http-page.png";
    char *const argv[] = {"python3", LR_SOURCE_CONFIGS "/../tests/fw/http_browser.py", url,
                          "18096", (char *)shot, NULL};
    char *out;
    int rc = run_client(r, argv, &out, 90);
    if (rc != 0)
        fail_msg("http_browser.py: exit %d: %s", rc, out);
    print_message("browser: %s", out);
    lr_json *j = parse(out);
    lr_jnode root = lr_json_root(j);
    char shown[32] = "";
    double f0 = -1, f1 = -1;
    lr_err e = {0};
    assert_int_equal(lr_json_get_string(j, root, "shown_after", true, shown, sizeof shown, &e),
                     LR_OK);
    assert_string_equal(shown, "1.000");
    assert_int_equal(lr_json_get_number(j, root, "frame_before", true, &f0, &e), LR_OK);
    assert_int_equal(lr_json_get_number(j, root, "frame_after", true, &f1, &e), LR_OK);
    assert_true(f1 > f0);
    char mat[32] = "";
    assert_int_equal(lr_json_get_string(j, root, "material", true, mat, sizeof mat, &e), LR_OK);
    assert_string_equal(mat, "marble");
    lr_json_destroy(j);
    free(out);
    /* The rig's own state: the slider's end is position 1, range [0, 2], linear, no fade:
     * twice the candle's own light (initial 0.5 was once). */
    run_ms(r, 30);
    assert_true(fabs(scene_num(r, "light.intensity") - 2 * base) <= 1e-12 * base);
    lr_rig_status *st = calloc(1, sizeof *st);
    assert_non_null(st);
    lr_rig_get_status(r, st);
    assert_true(st->controls[0].position == 1.0);
    assert_int_equal(st->controls[1].index, 1);
    free(st);
    char buf[64];
    scene_str(r, "objects[0].material.base", buf, sizeof buf);
    assert_string_equal(buf, "marble");
    size_t n;
    unsigned char *p = lr_test_read(shot, &n);
    assert_true(n > 33);
    assert_memory_equal(p, "\x89PNG\r\n\x1a\n", 8);
    free(p);
    lr_rig_destroy(r);
    lr_test_rmtree(dir);
}

/* lr_rig_reload_async, POST /api/reload's way: each answer is a reload that started after its
 * request (a request made while a reload runs waits for the next one), on the loop, with the
 * loop turning meanwhile; a forgotten request is not answered; at most LR_RIG_RELOAD_WAITERS
 * wait at once. */
typedef struct answers {
    int n, rc;
    uint64_t reloads; /* the rig's count when answered */
    lr_rig *r;
} answers;

static void answered(void *ctx, int rc, const lr_err *e)
{
    (void)e;
    answers *a = ctx;
    lr_rig_info info;
    lr_rig_get_info(a->r, &info);
    a->n++;
    a->rc = rc;
    a->reloads = info.reloads;
}

static void test_reload_answers(void **state)
{
    (void)state;
    const int port = 18089;
    char *dir = lr_test_tmpdir();
    lr_test_log log = {0};
    lr_rig *r = make_rig(dir, port, "", "preview", &log);
    run_ms(r, 50);
    lr_rig_info info;
    lr_rig_get_info(r, &info);
    uint64_t frames0 = info.frames;
    answers a = {.r = r}, b = {.r = r}, c = {.r = r};
    lr_err e = {0};
    assert_int_equal(lr_rig_reload_async(r, answered, &a, &e), LR_OK);
    assert_int_equal(lr_rig_reload_async(r, answered, &b, &e), LR_OK); /* during the first */
    assert_int_equal(lr_rig_reload_async(r, answered, &c, &e), LR_OK);
    lr_rig_reload_forget(r, &c);
    assert_int_equal(a.n + b.n, 0); /* not inside the calls: a job runs */
    int64_t guard = lr_now_ns() + 60000 * MS;
    while (b.n == 0 && lr_now_ns() < guard)
        run_ms(r, 10);
    assert_int_equal(a.n, 1);
    assert_int_equal(a.rc, LR_OK);
    assert_int_equal(a.reloads, 1);
    assert_int_equal(b.n, 1);
    assert_int_equal(b.rc, LR_OK);
    assert_int_equal(b.reloads, 2); /* the one after: its request came during the first */
    assert_int_equal(c.n, 0);
    lr_rig_get_info(r, &info);
    assert_true(info.frames > frames0); /* the loop drew meanwhile */
    assert_int_equal(lr_test_log_count(&log, "reload: loaded and planned off the loop in "), 2);

    /* At most LR_RIG_RELOAD_WAITERS at once: the next is refused, naming why. */
    answers w[LR_RIG_RELOAD_WAITERS];
    for (int i = 0; i < LR_RIG_RELOAD_WAITERS; i++) {
        w[i] = (answers){.r = r};
        assert_int_equal(lr_rig_reload_async(r, answered, &w[i], &e), LR_OK);
    }
    assert_int_equal(lr_rig_reload_async(r, answered, &c, &e), LR_EUNSUPPORTED);
    assert_non_null(strstr(e.msg, "reloads already waiting"));
    while (w[LR_RIG_RELOAD_WAITERS - 1].n == 0 && lr_now_ns() < guard)
        run_ms(r, 10);
    /* The first started reload 3; the others came while it ran: one more answers them all. */
    for (int i = 0; i < LR_RIG_RELOAD_WAITERS; i++) {
        assert_int_equal(w[i].n, 1);
        assert_int_equal(w[i].reloads, i == 0 ? 3 : 4);
    }
    lr_rig_destroy(r);
    lr_test_rmtree(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_status_json),
        cmocka_unit_test(test_status_frame_rate),
        cmocka_unit_test(test_http_config),
        cmocka_unit_test(test_http_api),
        cmocka_unit_test(test_reload_answers),
        cmocka_unit_test(test_http_bad_requests),
        cmocka_unit_test(test_http_token),
        cmocka_unit_test(test_http_garbage),
        cmocka_unit_test(test_http_shipped_sim_rig),
        cmocka_unit_test(test_http_browser),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
