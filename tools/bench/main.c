/* lamprig-bench: `lamprig-bench` runs every section; `lamprig-bench NAME...` runs those;
 * `lamprig-bench --list` lists them; `--update-front` makes the sweep also write
 * configs/bench/front.csv. Output is markdown, ready for tools/bench/README.md.
 * `lamprig-bench --figures [--check|--write]` prints README.md's figures block from the
 * committed results (figures.c), checks README.md's against it, or replaces it. */
#include "tools/bench/bench.h"

#include <sched.h>
#include <stdbool.h>
#include <string.h>

static const lrb_section *const sections[] = {
    &lrb_optics_section,
    &lrb_cpu_section,
    &lrb_render_section,
    &lrb_rig_section,
    &lrb_sweep_section,
    &lrb_models_section,
    &lrb_dimmer_section,
    &lrb_camera_section,
};
#define NSECTIONS (sizeof sections / sizeof sections[0])

static const lrb_section *find(const char *name)
{
    for (size_t k = 0; k < NSECTIONS; k++)
        if (strcmp(sections[k]->name, name) == 0)
            return sections[k];
    return NULL;
}

/* A section may pin the process to one CPU for its single-threaded timings (optics, cpu:
 * lrb_pin_to_current_cpu); the next section gets the CPUs the process started with back, or
 * llvmpipe, the rig's children and every later figure would run on one core (a whole
 * `make bench` without this did, after the optics section). */
static int run_one(const lrb_section *s, const lrb_options *opt)
{
    cpu_set_t cpus;
    bool saved = sched_getaffinity(0, sizeof cpus, &cpus) == 0;
    int rc = s->run_opts ? s->run_opts(stdout, opt) : s->run(stdout);
    if (saved && sched_setaffinity(0, sizeof cpus, &cpus) != 0)
        fprintf(stderr, "lamprig-bench: %s: could not restore the CPU affinity\n", s->name);
    return rc;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (!strcmp(argv[1], "--list") || !strcmp(argv[1], "--help") ||
                      !strcmp(argv[1], "-h"))) {
        printf("usage: lamprig-bench [--update-front] [SECTION...]\n"
               "       lamprig-bench --figures [--check|--write [README]]   README.md's figures "
               "block\n"
               "\nsections:\n");
        for (size_t k = 0; k < NSECTIONS; k++)
            printf("  %-10s %s\n", sections[k]->name, sections[k]->summary);
        return 0;
    }
    if (argc >= 2 && !strcmp(argv[1], "--figures")) {
        if (argc == 2)
            return lrb_figures("print", NULL);
        if ((argc == 3 || argc == 4) && !strcmp(argv[2], "--check"))
            return lrb_figures("check", argc == 4 ? argv[3] : NULL);
        if ((argc == 3 || argc == 4) && !strcmp(argv[2], "--write"))
            return lrb_figures("write", argc == 4 ? argv[3] : NULL);
        fprintf(stderr, "usage: lamprig-bench --figures [--check|--write [README]]\n");
        return 2;
    }
    lrb_options opt = {0};
    const char *names[64];
    int n = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--update-front")) {
            opt.update_front = true;
            continue;
        }
        if (!find(argv[i])) {
            fprintf(stderr, "lamprig-bench: unknown section '%s' (see --list)\n", argv[i]);
            return 2;
        }
        if (n < 64)
            names[n++] = argv[i];
    }
    int status = 0;
    if (!n) {
        for (size_t k = 0; k < NSECTIONS; k++)
            if (run_one(sections[k], &opt))
                status = 1;
    } else {
        for (int i = 0; i < n; i++)
            if (run_one(find(names[i]), &opt))
                status = 1;
    }
    return status;
}
