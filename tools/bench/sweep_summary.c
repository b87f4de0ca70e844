/* build/bench/summary.md: per scene the reference and its noise, the units check, the Pareto
 * rows and the bias/noise split; the machine's load during the run. */
#include "tools/bench/sweep.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/atomic_file.h"

static void scene_block(FILE *f, const lrb_scene_result *sc, const lr_eval_row *rows)
{
    fprintf(f, "## %s\n\n", sc->name);
    if (!sc->ok) {
        fprintf(f, "Failed: %s\n\n", sc->error);
        if (!sc->nrows)
            return;
    }
    char spp[96];
    if (sc->refs == 2)
        snprintf(spp, sizeof spp, "the mean of two of %d spp (seeds 0 and %d: %d spp in all)",
                 sc->ref_spp, LRB_SWEEP_SEED2, 2 * sc->ref_spp);
    else
        snprintf(spp, sizeof spp, "%d spp", sc->ref_spp);
    fprintf(f, "Physical reference: %s at %d×%d, %s in %.0f s; relative standard error "
               "%.4f (objects) / %.4f (receivers) / %.4f (both). It is taken out of every error "
               "below in quadrature (E[rmse²] = error² + se²). %ld object and %ld receiver "
               "pixels.\n\n",
            spp, LRB_SWEEP_W, LRB_SWEEP_H, sc->ref_hit ? "read from the cache" : "rendered",
            sc->ref_s, sc->ref_se_object, sc->ref_se_receivers, sc->ref_se_all, sc->object_px,
            sc->receiver_px);
    if (isfinite(sc->units_ratio))
        fprintf(f, "Units check (receivers and light alone, albedo 0.05, 32×24, 256 spp): GPU / "
                   "reference = %.4f ± %.4f over %ld lit receiver pixels (interreflection, "
                   "which only the reference has, is about a percent at this albedo).\n\n",
                sc->units_ratio, sc->units_se, sc->units_px);
    else
        fprintf(f, "Units check: failed (see the bench's stderr).\n\n");
    if (isfinite(sc->direct_ratio))
        fprintf(f, "In the full scene, on the %ld receiver pixels the light reaches directly, the "
                   "GPU without VPLs (converged) / reference = %.3f ± %.3f: the rest is emergent "
                   "light and interreflection.\n\n",
                sc->direct_px, sc->direct_ratio, sc->direct_se);
    int n = sc->nrows;
    double *c = malloc(sizeof(double) * (size_t)(n ? n : 1)), *er = malloc(sizeof(double) * (size_t)(n ? n : 1));
    bool *front = malloc(sizeof(bool) * (size_t)(n ? n : 1));
    if (c && er && front) {
        for (int i = 0; i < n; i++)
            c[i] = lrb_sweep_time_ms(&rows[i]), er[i] = rows[i].rel_rmse;
        lr_eval_pareto(c, er, n, front);
        fprintf(f, "Pareto front (time to reach = frames × accumulation frame time):\n\n");
        fprintf(f, "| model | params | frame ms | time ms | rel_rmse | objects | receivers |\n"
                   "|---|---|---|---|---|---|---|\n");
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
            fprintf(f, "| %s | %s | %.1f | %.0f | %.4f | %.4f | %.4f |\n", rows[best].model, p,
                    rows[best].frame_ms,
                    c[best], rows[best].rel_rmse, rows[best].rel_rmse_object,
                    rows[best].rel_rmse_receivers);
            last = c[best];
        }
        fprintf(f, "\n");
    }
    free(c), free(er), free(front);
    fprintf(f, "Bias (converged model vs physical) and noise (F frames vs converged model), "
               "objects / receivers:\n\n");
    fprintf(f, "| model | params | frame ms | radiosity | vpl | compose | error obj | error rec | "
               "bias obj | bias rec | noise obj | noise rec |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < n; i++) {
        const lr_eval_row *r = &rows[i];
        char p[160];
        lr_eval_row_params(r, p, sizeof p);
        fprintf(f, "| %s | %s | %.1f | %.1f | %.1f | %.1f | %.4f | %.4f | %.4f | %.4f | %.4f | "
                   "%.4f |\n",
                r->model, p, r->frame_ms, r->ms[1], r->ms[2], r->ms[3], r->rel_rmse_object,
                r->rel_rmse_receivers, r->bias_object, r->bias_receivers, r->noise_object,
                r->noise_receivers);
    }
    fprintf(f, "\n");
}

/* The base setting's row of a scene after F frames; NULL when absent. */
static const lr_eval_row *base_row(const lr_eval_row *rows, int nrows, const char *scene, int F)
{
    lrb_setting b;
    lrb_sweep_settings(&b, 1);
    for (int i = 0; i < nrows; i++) {
        const lr_eval_row *r = &rows[i];
        if (!strcmp(r->scene, scene) && !strcmp(r->model, b.model) && r->K == b.K &&
            r->N == b.N && r->N_vpl == b.N_vpl && r->map_size == b.map_size &&
            r->gbuffer_size == b.gbuffer_size && r->vpl == b.vpl && r->frames == F)
            return r;
    }
    return NULL;
}

void lrb_sweep_table_md(FILE *f, const lr_eval_row *rows, int nrows, const lrb_timing_640 *t,
                        int nt)
{
    lrb_setting b;
    lrb_sweep_settings(&b, 1);
    char p[160];
    lr_eval_row pr = {.K = b.K, .N = b.N, .N_vpl = b.N_vpl, .map_size = b.map_size,
                      .gbuffer_size = b.gbuffer_size, .frames = 1, .vpl = b.vpl};
    lr_eval_row_params(&pr, p, sizeof p);
    fprintf(f, "640×480, base setting (%s; frames aside). Times in ms: full update per pass "
               "(median of 3), accumulation frame (radiosity + vpl + compose, median of 4), "
               "dimmer-only frame (compose alone, median of 5). Errors (relative RMSE against "
               "the physical reference, at the sweep's %d×%d, objects / receivers): after one "
               "frame, and converged (%d frames: the model's bias).\n\n",
            p, LRB_SWEEP_W, LRB_SWEEP_H, b.converge_frames);
    fprintf(f, "| scene | gbuffer | radiosity | vpl | compose | full update | accumulation | "
               "dimmer | full / dimmer | error, 1 frame | error, converged |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < nt; i++) {
        if (!t[i].ok)
            continue;
        const lr_eval_row *r1 = base_row(rows, nrows, t[i].scene, 1);
        fprintf(f, "| %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f |", t[i].scene,
                t[i].pass_ms[0], t[i].pass_ms[1], t[i].pass_ms[2], t[i].pass_ms[3], t[i].full_ms,
                t[i].accum_ms, t[i].dimmer_ms, t[i].full_ms / t[i].dimmer_ms);
        if (r1)
            fprintf(f, " %.3f / %.3f | %.3f / %.3f |\n", r1->rel_rmse_object,
                    r1->rel_rmse_receivers, r1->bias_object, r1->bias_receivers);
        else
            fprintf(f, " – | – |\n");
    }
    fprintf(f, "\n");
}

int lrb_sweep_summary(const char *path, const lr_eval_row *rows, int nrows,
                      const lrb_scene_result *scenes, int nscenes, const lrb_timing_640 *t640,
                      int nt640, const double load[2][3], double total_s, const char *renderer,
                      lr_err *e)
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
    if (nt640)
        lrb_sweep_table_md(f, rows, nrows, t640, nt640);
    lrb_sweep_fair_md(f, scenes, nscenes);
    for (int k = 0; k < nscenes; k++)
        scene_block(f, &scenes[k], rows + scenes[k].row0);
    return lr_atomic_file_commit(af, e);
}
