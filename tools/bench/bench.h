/* lamprig-bench — speed (and, as sections are added, error against a reference) of each part of
 * the renderer, one section per module. Each section prints a markdown block that can be pasted
 * into tools/bench/README.md as it is. */
#ifndef LRB_BENCH_H
#define LRB_BENCH_H

#include <stdbool.h>
#include <stdio.h>

/* Command-line options that sections may read. */
typedef struct lrb_options {
    bool update_front; /* --update-front: sweep also writes configs/bench/front.csv */
} lrb_options;

typedef struct lrb_section {
    const char *name;    /* selects the section on the command line */
    const char *summary; /* one line for --list */
    /* Prints the section's markdown to out; returns 0 or a nonzero exit status. */
    int (*run)(FILE *out);
    /* The same with the options; used instead of run when set. */
    int (*run_opts)(FILE *out, const lrb_options *opt);
} lrb_section;

/* Sections (one file each). */
extern const lrb_section lrb_optics_section;
extern const lrb_section lrb_cpu_section;
extern const lrb_section lrb_render_section;
extern const lrb_section lrb_rig_section;
extern const lrb_section lrb_sweep_section;
extern const lrb_section lrb_models_section;
extern const lrb_section lrb_dimmer_section;
extern const lrb_section lrb_camera_section;
extern const lrb_section lrb_console_section;
extern const lrb_section lrb_memory_section;

/* Shared timing helpers (timing.c). */

/* Monotonic wall clock in seconds. */
double lrb_now(void);
/* The q-quantile (0..1, nearest rank) of v[0..n), sorting v in place; NaN when n < 1. */
double lrb_quantile(double *v, int n, double q);
/* CPU time of the calling thread in seconds: what the rates are measured in, so that time the
 * scheduler gives to other processes on a shared machine does not count (on an idle core it
 * equals wall time). */
double lrb_thread_cpu_now(void);
/* Pins the calling thread to the CPU it is running on, so that "one core" means one core and
 * the scheduler does not migrate it mid-run. Returns the CPU number, or -1 if pinning failed
 * (the figures are then still single-threaded, only noisier). */
int lrb_pin_to_current_cpu(void);
/* The folder of the running lamprig-bench (where build/bin/lamprig sits beside it) and the
 * configs folder as an absolute path (the rig sections write rig configs into a scratch
 * folder); nonzero with a line on stderr naming `section` when either cannot be found. */
int lrb_rig_paths(const char *section, char *bindir, size_t bindir_cap, char *configs);
/* A loopback port free now for sock_type (SOCK_STREAM, SOCK_DGRAM), or -1 (scratch.c). */
int lrb_free_port(int sock_type);
/* Writes text to path (a scratch file); 0, or nonzero when it could not be written. */
int lrb_write_file(const char *path, const char *text);
/* The shipped configs/rig/NAME (configs: lrb_rig_paths) as a malloc'd string, NULL when it
 * cannot be read. */
char *lrb_read_rig_file(const char *configs, const char *name);
/* One line naming the host CPU (from /proc/cpuinfo), for the record under each table. */
void lrb_cpu_name(char *buf, size_t len);
/* The rig section's per-control table (rig_controls.c): runs the shipped sim rig from bindir
 * with configs' files, scratch files in dir. Nonzero when a run failed. */
/* README.md's figures block (figures.c): mode "print" writes it to stdout, "check" compares
 * README.md's block with it (1: differs), "write" replaces README.md's block; readme: another
 * file than the tree's README.md (NULL: that one). */
#define LRB_FIGURES_BEGIN "<!-- BEGIN figures -->"
#define LRB_FIGURES_END "<!-- END figures -->"
int lrb_figures(const char *mode, const char *readme);
/* csv (may be NULL): "run,control,figure,value" rows for build/bench/rig.csv (figures.c). */
int lrb_rig_controls(FILE *out, FILE *csv, const char *bindir, const char *configs,
                     const char *dir);
/* The Modbus demo rig's rows (rig_modbus.c): poll cadence and panel -> lamp, idle and loaded,
 * against lamprig-modbus-sim on 127.0.0.1:port. */
int lrb_rig_modbus(FILE *out, FILE *csv, const char *bindir, const char *configs,
                   const char *dir, int port);

/* Rate measurement: calls body(ctx, n) (which must perform n evaluations and return a value
 * depending on all of them), choosing n so that one run lasts about min_run_s of thread CPU
 * time, then times `runs` runs after one warm-up. Fills evaluations/s of each run into
 * rates[] (runs <= 32) and returns the median. */
typedef double (*lrb_body)(void *ctx, long n);
double lrb_measure_rate(lrb_body body, void *ctx, double min_run_s, int runs, double *rates);

/* CPU time of the whole process (all threads) in ms: a frame's cost on the machine, whatever
 * llvmpipe's threads did, beside its wall time. */
double lrb_process_cpu_ms(void);
/* The smallest of v[0..n-1] (n >= 1). */
double lrb_min(const double *v, int n);

/* lr_scene_set, its message printed as "WHO: KEY=VALUE: why" (scene_set.c); the dirty bits are
 * or-ed into *dirty when it is not NULL. Returns 0, or 1 on a refused value. */
typedef struct lr_scene lr_scene;
int lrb_scene_set(const char *who, lr_scene *s, const char *key, const char *value,
                  unsigned *dirty);

/* Whether `name` is one of the comma-separated names of `list` (whole names: "candle" must
 * not select "candle_spot"; listed.c). */
bool lrb_listed(const char *list, const char *name);
/* The same, where an unset or empty list selects every name (the LRB_*_SCENES knobs). */
static inline bool lrb_wanted(const char *list, const char *name)
{
    return !list || !*list || lrb_listed(list, name);
}

/* Result sink: the bodies' return values go here so the compiler cannot drop the work. */
extern volatile double lrb_sink;

#endif
