/* Section "memory": GPU memory and peak resident set per shipped scene, for a 4 GB board.
 *
 * Each scene runs as a user runs it, `lamprig render --scene S --frames 1 --stats F` (a child
 * process per row, so each peak RSS is that render's alone), twice: as planned (the planner's
 * settings for the scene's budget, what `lamprig render` and the rig use) and at the scene's
 * own settings (`--no-plan`). One frame allocates every texture and the CPU solvers' states
 * (the renderer counts its textures and renderbuffers at each frame: lr_renderer_gpu_bytes),
 * so more frames would not change the figures. GPU: the storage of the renderer's textures and
 * renderbuffers (lr_gl_memory; a driver adds alignment, shader code and vertex buffers are not
 * counted). RSS: getrusage's ru_maxrss of the child (the CPU solvers, meshes and BVHs, and
 * llvmpipe's own buffers: on a board with a GPU the textures are not in the process's RSS
 * twice, so the RSS column is an upper bound there). The rig's renderer is refused past
 * output.gpu_memory_mb (default 1024 MB). LRB_MEMORY_SCENES: a comma-separated list (default
 * every scene below); 640 x 480. */
#include "tools/bench/bench.h"
#include "tools/bench/proc.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "render/base/json.h"

static const char *const scenes[] = {"candle", "candle_spot", "jar_candle", "votive",
                                     "lampshade", "lampshade_led", "led_shade", "sphere_shell"};

/* Runs one render; fills MB figures and the settings it ran at. */
static int one(const char *bindir, const char *configs, const char *dir, const char *scene,
               bool planned, double *gpu, double *rss, long set[4])
{
    char lamprig[PATH_MAX + 16], path[PATH_MAX + 64], stats[PATH_MAX + 32], log[PATH_MAX + 32];
    snprintf(lamprig, sizeof lamprig, "%s/lamprig", bindir);
    snprintf(path, sizeof path, "%s/scenes/%s.json", configs, scene);
    snprintf(stats, sizeof stats, "%s/%s.json", dir, scene);
    snprintf(log, sizeof log, "%s/%s.log", dir, scene);
    char *argv[] = {lamprig, "render", "--scene", path, "--frames", "1", "--width", "640",
                    "--height", "480", "--stats", stats, "--allow-dark", "--quiet",
                    planned ? NULL : "--no-plan", NULL};
    pid_t pid = lrb_spawn(argv, log);
    int st = pid > 0 ? lrb_reap(pid, 1800) : -1;
    if (st < 0 || !WIFEXITED(st) || WEXITSTATUS(st) != 0) {
        fprintf(stderr, "bench memory: %s failed:\n", scene);
        lrb_print_log(log);
        return 1;
    }
    lr_json *j;
    lr_err e = {0};
    if (lr_json_load(stats, &j, &e)) {
        fprintf(stderr, "bench memory: %s\n", e.msg);
        return 1;
    }
    lr_jnode root = lr_json_root(j), s = lr_json_get(j, root, "settings");
    static const char *const keys[4] = {"K", "map_size", "gbuffer_size", "vpl_map_size"};
    int rc = lr_json_get_number(j, root, "gpu_mb", true, gpu, &e) ||
             lr_json_get_number(j, root, "peak_rss_mb", true, rss, &e);
    for (int k = 0; k < 4 && !rc; k++)
        rc = lr_json_get_int(j, s, keys[k], true, &set[k], &e);
    if (rc)
        fprintf(stderr, "bench memory: %s: %s\n", stats, e.msg);
    lr_json_destroy(j);
    return rc ? 1 : 0;
}

static bool wanted(const char *list, const char *name)
{
    if (!list || !*list)
        return true;
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)); p += n)
        if ((p == list || p[-1] == ',') && (p[n] == ',' || p[n] == '\0'))
            return true;
    return false;
}

static int run(FILE *out)
{
    char bindir[PATH_MAX], configs[PATH_MAX];
    if (lrb_rig_paths("memory", bindir, sizeof bindir, configs))
        return 1;
    char dir[] = "/tmp/lamprig-bench-memory-XXXXXX";
    if (!mkdtemp(dir))
        return 1;
    const char *list = getenv("LRB_MEMORY_SCENES");
    fprintf(out, "| scene | planned: K, map, G-buffer, VPL map | GPU MB | peak RSS MB | scene's "
                 "settings: K, map, G-buffer, VPL map | GPU MB | peak RSS MB |\n");
    fprintf(out, "|---|---|---|---|---|---|---|\n");
    double worst = 0.0;
    int rc = 0;
    for (size_t i = 0; i < sizeof scenes / sizeof *scenes && !rc; i++) {
        if (!wanted(list, scenes[i]))
            continue;
        fprintf(stderr, "bench memory: %s\n", scenes[i]);
        double g[2], r[2];
        long set[2][4];
        for (int own = 0; own < 2 && !rc; own++)
            rc = one(bindir, configs, dir, scenes[i], own == 0, &g[own], &r[own], set[own]);
        if (rc)
            break;
        fprintf(out, "| %s | %ld, %ld², %ld², %ld² | %.1f | %.0f | %ld, %ld², %ld², %ld² | %.1f | "
                     "%.0f |\n", scenes[i], set[0][0], set[0][1], set[0][2], set[0][3], g[0], r[0],
                set[1][0], set[1][1], set[1][2], set[1][3], g[1], r[1]);
        worst = g[1] > worst ? g[1] : worst;
    }
    if (!rc)
        fprintf(out, "\nLargest GPU need: %.0f MB, under the rig's default budget of 1024 MB "
                     "(`output.gpu_memory_mb`).\n", worst);
    char cmd[PATH_MAX + 16];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        fprintf(stderr, "bench memory: could not remove %s\n", dir);
    return rc;
}

const lrb_section lrb_memory_section = {
    .name = "memory",
    .summary = "GPU memory and peak RSS per shipped scene, planned and at its own settings",
    .run = run,
};
