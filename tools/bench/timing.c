#include "tools/bench/bench.h"

#include <math.h>
#include <sched.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

#include "render/base/paths.h"

volatile double lrb_sink;

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double lrb_quantile(double *v, int n, double q)
{
    if (n < 1)
        return NAN;
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    int i = (int)ceil(q * n) - 1;
    return v[i < 0 ? 0 : i >= n ? n - 1 : i];
}

double lrb_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double lrb_process_cpu_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

double lrb_min(const double *v, int n)
{
    double m = v[0];
    for (int i = 1; i < n; i++)
        m = v[i] < m ? v[i] : m;
    return m;
}

double lrb_thread_cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int lrb_pin_to_current_cpu(void)
{
    int cpu = sched_getcpu();
    if (cpu < 0)
        return -1;
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    return sched_setaffinity(0, sizeof set, &set) == 0 ? cpu : -1;
}

void lrb_cpu_name(char *buf, size_t len)
{
    snprintf(buf, len, "unknown CPU");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f)
        return;
    char line[256];
    /* x86 names the model; ARM boards often only have "Model" (the board) or "CPU part". */
    const char *keys[] = {"model name", "Model", "Hardware", "CPU part"};
    char found[4][200] = {{0}};
    while (fgets(line, sizeof line, f)) {
        for (int k = 0; k < 4; k++) {
            size_t kl = strlen(keys[k]);
            if (!found[k][0] && strncmp(line, keys[k], kl) == 0 && strchr(line, ':')) {
                char *v = strchr(line, ':') + 1;
                while (*v == ' ' || *v == '\t')
                    v++;
                v[strcspn(v, "\n")] = '\0';
                snprintf(found[k], sizeof found[k], "%s", v);
            }
        }
    }
    fclose(f);
    for (int k = 0; k < 4; k++)
        if (found[k][0]) {
            snprintf(buf, len, "%s", found[k]);
            return;
        }
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double lrb_measure_rate(lrb_body body, void *ctx, double min_run_s, int runs, double *rates)
{
    if (runs > 32)
        runs = 32;
    /* Calibrate: grow n until one run takes at least a tenth of the target, then scale. */
    long n = 1024;
    double dt;
    for (;;) {
        double t0 = lrb_thread_cpu_now();
        lrb_sink = body(ctx, n);
        dt = lrb_thread_cpu_now() - t0;
        if (dt >= 0.1 * min_run_s || n > (1L << 40))
            break;
        n *= 4;
    }
    n = (long)((double)n * min_run_s / (dt > 0.0 ? dt : 1e-9)) + 1;
    lrb_sink = body(ctx, n); /* warm-up at full length */
    double sorted[32];
    for (int r = 0; r < runs; r++) {
        double t0 = lrb_thread_cpu_now();
        lrb_sink = body(ctx, n);
        double t = lrb_thread_cpu_now() - t0;
        rates[r] = (double)n / t;
        sorted[r] = rates[r];
    }
    qsort(sorted, (size_t)runs, sizeof sorted[0], cmp_double);
    return runs % 2 ? sorted[runs / 2] : 0.5 * (sorted[runs / 2 - 1] + sorted[runs / 2]);
}

int lrb_rig_paths(const char *section, char *bindir, size_t bindir_cap, char *configs)
{
    ssize_t n = readlink("/proc/self/exe", bindir, bindir_cap - 1);
    if (n <= 0) {
        fprintf(stderr, "bench %s: /proc/self/exe cannot be read\n", section);
        return 1;
    }
    bindir[n] = '\0';
    char *sl = strrchr(bindir, '/');
    if (sl)
        *sl = '\0';
    if (!realpath(lr_configs_dir(), configs)) {
        fprintf(stderr, "bench %s: no configs directory '%s'\n", section, lr_configs_dir());
        return 1;
    }
    return 0;
}
