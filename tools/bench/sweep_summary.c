/* build/bench/summary.md: per scene the reference and its noise, the units check, the Pareto
 * rows and the bias/noise split; the machine's load during the run. */
#include "tools/bench/sweep.h"

#include <math.h>
#include <stdlib.h>

#include "render/base/atomic_file.h"

static void scene_block(FILE *f, const lrb_scene_result *sc, const lr_eval_row *rows)
{
    fprintf(f, "## %s\n\n", sc->name);
    if (!sc->ok) {
        fprintf(f, "Failed: %s\n\n", sc->error);
        if (!sc->nrows)
            return;
    }
    fprintf(f, "Physical reference: %d spp at %d×%d, %s in %.0f s; relative standard error "
               "%.4f (objects) / %.4f (receivers) / %.4f (both). It is taken out of every error "
               "below in quadrature (E[rmse²] = error² + se²). %ld object and %ld receiver "
               "pixels.\n\n",
            LRB_SWEEP_SPP, LRB_SWEEP_W, LRB_SWEEP_H, sc->ref_hit ? "read from the cache" : "rendered",
            sc->ref_s, sc->ref_se_object, sc->ref_se_receivers, sc->ref_se_all, sc->object_px,
            sc->receiver_px);
    if (isfinite(sc->units_ratio))
        fprintf(f, "Units check: on the %ld receiver pixels the light reaches directly, the GPU "
                   "without VPLs (converged) / reference = %.3f ± %.3f (the reference also has "
                   "the emergent light there, so slightly below 1 is expected).\n\n",
                sc->units_px, sc->units_ratio, sc->units_se);
    else
        fprintf(f, "Units check: no receiver pixel is lit directly.\n\n");
    int n = sc->nrows;
    double *c = malloc(sizeof(double) * (size_t)(n ? n : 1)), *er = malloc(sizeof(double) * (size_t)(n ? n : 1));
    bool *front = malloc(sizeof(bool) * (size_t)(n ? n : 1));
    if (c && er && front) {
        for (int i = 0; i < n; i++)
            c[i] = lrb_sweep_time_ms(&rows[i]), er[i] = rows[i].rel_rmse;
        lr_eval_pareto(c, er, n, front);
        fprintf(f, "Pareto front (time to reach = frames × accumulation frame time):\n\n");
        fprintf(f, "| params | frame ms | time ms | rel_rmse | objects | receivers |\n"
                   "|---|---|---|---|---|---|\n");
        double last = -1.0;
        for (;;) {
            int best = -1;
            for (int i = 0; i < n; i++)
                if (front[i] && c[i] > last && (best < 0 || c[i] < c[best]))
                    best = i;
            if (best < 0)
                break;
            char p[160];
            lr_eval_row_params(&rows[best], p, sizeof p);
            fprintf(f, "| %s | %.1f | %.0f | %.4f | %.4f | %.4f |\n", p, rows[best].frame_ms,
                    c[best], rows[best].rel_rmse, rows[best].rel_rmse_object,
                    rows[best].rel_rmse_receivers);
            last = c[best];
        }
        fprintf(f, "\n");
    }
    free(c), free(er), free(front);
    fprintf(f, "Bias (converged model vs physical) and noise (F frames vs converged model), "
               "objects / receivers:\n\n");
    fprintf(f, "| params | frame ms | radiosity | vpl | compose | error obj | error rec | bias obj "
               "| bias rec | noise obj | noise rec |\n|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < n; i++) {
        const lr_eval_row *r = &rows[i];
        char p[160];
        lr_eval_row_params(r, p, sizeof p);
        fprintf(f, "| %s | %.1f | %.1f | %.1f | %.1f | %.4f | %.4f | %.4f | %.4f | %.4f | %.4f |\n",
                p, r->frame_ms, r->ms[1], r->ms[2], r->ms[3], r->rel_rmse_object,
                r->rel_rmse_receivers, r->bias_object, r->bias_receivers, r->noise_object,
                r->noise_receivers);
    }
    fprintf(f, "\n");
}

int lrb_sweep_summary(const char *path, const lr_eval_row *rows, int nrows,
                      const lrb_scene_result *scenes, int nscenes, const double load[2][3],
                      double total_s, const char *renderer, lr_err *e)
{
    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc)
        return rc;
    FILE *f = lr_atomic_file_stream(af);
    char cpu[256];
    lrb_cpu_name(cpu, sizeof cpu);
    fprintf(f, "# Speed against error (`lamprig-bench sweep`)\n\n");
    fprintf(f, "%d rows, %d scenes, %.0f s. Renderer: %s. CPU: %s. Load average (1, 5, 15 min) "
               "before %.2f %.2f %.2f, after %.2f %.2f %.2f: frame times on a loaded machine are "
               "upper bounds.\n\n",
            nrows, nscenes, total_s, renderer, cpu, load[0][0], load[0][1], load[0][2],
            load[1][0], load[1][1], load[1][2]);
    fprintf(f, "Errors: relative RMSE in linear light, sqrt(Σ(g−r)²/Σr²) over the bands of the "
               "object pixels, the receiver pixels, or both (rel_rmse), against the physical "
               "reference (render/reference), at %d×%d.\n\n",
            LRB_SWEEP_W, LRB_SWEEP_H);
    for (int k = 0; k < nscenes; k++)
        scene_block(f, &scenes[k], rows + scenes[k].row0);
    return lr_atomic_file_commit(af, e);
}
