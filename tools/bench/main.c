/* lamprig-bench: `lamprig-bench` runs every section; `lamprig-bench NAME...` runs those;
 * `lamprig-bench --list` lists them; `--update-front` makes the sweep also write
 * configs/bench/front.csv. Output is markdown, ready for tools/bench/README.md.
 * `lamprig-bench --figures [--check|--write]` prints README.md's figures block from the
 * committed results (figures.c), checks README.md's against it, or replaces it. The options
 * are the table below (firmware/tool.h: the generated --help, one line naming the flag and
 * exit 2 for a bad argument). */
#include "tools/bench/bench.h"

#include "firmware/tool.h"

#include <sched.h>
#include <stdbool.h>
#include <stdio.h>
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
    &lrb_console_section,
    &lrb_memory_section,
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

#define PROGRAM "lamprig-bench"
#define MAX_NAMES 64

/* --figures, --check and --write read as one synopsis word. */
#define FIGURES_GROUP "[--figures [--check|--write [README]]]"

static const lr_argspec opts[] = {
    {.name = "--list", .flags = LR_ARG_ALONE, .help = "the sections, one line each"},
    {.name = "--update-front",
     .help = "the sweep also copies its results.csv to configs/bench/front.csv"},
    {.name = "--figures",
     .help = "print README.md's figures block from the committed results (figures.c)\n"
             "instead of running sections",
     .group = FIGURES_GROUP},
    {.name = "--check", .help = "with --figures: compare README.md's block (or README's, the\n"
                                "operand) with it; exit 1 when they differ",
     .group = FIGURES_GROUP},
    {.name = "--write", .help = "with --figures: replace README.md's block (or README's)",
     .group = FIGURES_GROUP},
    {0},
};

static void list_sections(FILE *f)
{
    for (size_t k = 0; k < NSECTIONS; k++)
        fprintf(f, "  %-10s %s\n", sections[k]->name, sections[k]->summary);
}

/* `--figures [--check|--write] [README]`. */
static int figures(const lr_args *a)
{
    int check = lr_args_has(a, "--check"), write = lr_args_has(a, "--write");
    if (check && write)
        return lr_tool_usage(PROGRAM, "--figures takes --check or --write, not both");
    if (lr_args_has(a, "--update-front"))
        return lr_tool_usage(PROGRAM, "--update-front runs the sweep; not with --figures");
    if (a->npos > 1 || (a->npos == 1 && !check && !write))
        return lr_tool_usage(PROGRAM, "unexpected argument '%s' (--figures takes one README "
                             "with --check or --write)", a->pos[a->npos > 1 ? 1 : 0]);
    const char *readme = a->npos ? a->pos[0] : NULL;
    return lrb_figures(check ? "check" : write ? "write" : "print", readme);
}

int main(int argc, char **argv)
{
    /* The tables (stdout) a line at a time: with both streams in one file (`lamprig-bench rig
     * > log 2>&1`) a fully buffered table was cut by the progress lines (stderr). */
    setvbuf(stdout, NULL, _IOLBF, 0);
    /* The sections' list is the help's notes: built here from the table above. */
    char notes[2048];
    size_t n = (size_t)snprintf(notes, sizeof notes, "SECTION: the sections to run, in the "
                                "order given (default every one, in this order):");
    for (size_t k = 0; k < NSECTIONS && n < sizeof notes; k++)
        n += (size_t)snprintf(notes + n, sizeof notes - n, "\n  %-10s %s", sections[k]->name,
                              sections[k]->summary);
    if (n < sizeof notes)
        snprintf(notes + n, sizeof notes - n, "\n\nExit status 0, 1 (a section failed; "
                 "--figures --check: the block differs),\n2 (bad arguments).");
    const lr_command tool = {
        .name = PROGRAM,
        .about = "Speed and error figures as markdown tables on stdout (tools/bench/README.md);\n"
                 "progress on stderr. Run it from the repository root.",
        .opts = opts,
        .operands = "[SECTION...]",
        .max_operands = MAX_NAMES,
        .notes = notes,
    };
    lr_args args;
    int st = lr_tool_args(&tool, argc, argv, &args);
    if (st >= 0)
        return st;
    if (lr_args_has(&args, "--list")) {
        list_sections(stdout);
        return 0;
    }
    if (lr_args_has(&args, "--figures"))
        return figures(&args);
    if (lr_args_has(&args, "--check") || lr_args_has(&args, "--write"))
        return lr_tool_usage(PROGRAM, "%s needs --figures",
                             lr_args_has(&args, "--check") ? "--check" : "--write");
    lrb_options opt = {.update_front = lr_args_has(&args, "--update-front")};
    for (int i = 0; i < args.npos; i++)
        if (!find(args.pos[i])) {
            fprintf(stderr, "lamprig-bench: unknown section '%s' (see --list)\n", args.pos[i]);
            return 2;
        }
    int status = 0;
    if (!args.npos) {
        for (size_t k = 0; k < NSECTIONS; k++)
            if (run_one(sections[k], &opt))
                status = 1;
    } else {
        for (int i = 0; i < args.npos; i++)
            if (run_one(find(args.pos[i]), &opt))
                status = 1;
    }
    return status;
}
