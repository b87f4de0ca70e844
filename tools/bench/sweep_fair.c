/* Issue 12's fair figures as markdown (stdout and build/bench/summary.md): per scene the old
 * (pixel-centre) and fair (box-filtered) bias, the median |ln ratio| over object pixels with
 * the two-reference floor, the receivers' power ratio, and per region and band the power ratio
 * model / reference with the reference's standard error. */
#include "tools/bench/sweep.h"

#include <math.h>

static void ratio_cell(FILE *f, lr_eval_ratio r)
{
    if (!isfinite(r.ratio))
        fprintf(f, " – |");
    else if (lr_eval_ratio_differs(r))
        fprintf(f, " %.2f ± %.2f |", r.ratio, r.se);
    else /* within 2 standard errors of 1: the reference cannot tell */
        fprintf(f, " (%.2f ± %.2f) |", r.ratio, r.se);
}

static void pair(FILE *f, double a, double b)
{
    if (isfinite(a) || isfinite(b))
        fprintf(f, " %.3f → %.3f |", a, b);
    else
        fprintf(f, " – |");
}

void lrb_sweep_fair_md(FILE *f, const lrb_scene_result *sc, int n)
{
    int ss = n ? sc[0].supersample : lrb_sweep_supersample();
    fprintf(f, "Fair figures (issue 12; base setting converged): the model box-filtered like the "
               "reference's pixels (rendered %d×%d per pixel) against pixel-centre samples (the "
               "bench before). Bias = relative RMSE with both images' noise taken out; median "
               "|ln| over object pixels of ln(model / reference) on the band sums; floor = the "
               "same between two references of independent seeds (scaled to %d spp each); "
               "receiver power = Σ model / Σ reference over receiver pixels ± the reference's "
               "standard error.\n\n",
            ss, ss, LRB_SWEEP_SPP);
    fprintf(f, "| scene | bias objects, centre → fair | bias receivers, centre → fair | median "
               "\\|ln\\| objects, centre → fair | floor (two references) | receiver power, "
               "centre → fair |\n|---|---|---|---|---|---|\n");
    for (int k = 0; k < n; k++) {
        const lrb_scene_result *s = &sc[k];
        fprintf(f, "| %s |", s->name);
        pair(f, s->centre_bias_object, s->fair_bias_object);
        pair(f, s->centre_bias_receivers, s->fair_bias_receivers);
        pair(f, s->mal_centre, s->mal_fair);
        if (isfinite(s->mal_floor))
            fprintf(f, " %.3f (%d vs %d spp: %.3f) |", s->mal_floor, LRB_SWEEP_SPP, s->ref2_spp,
                    s->mal_floor_raw);
        else
            fprintf(f, " – |");
        if (isfinite(s->receiver_ratio.ratio))
            fprintf(f, " %.3f → %.3f ± %.3f |\n", s->centre_receiver_ratio.ratio,
                    s->receiver_ratio.ratio, s->receiver_ratio.se);
        else
            fprintf(f, " – |\n");
    }
    fprintf(f, "\nPower model / reference per region and band (fair, base setting converged; "
               "regions from the geometry: render/eval/eval.h). In parentheses: within two of "
               "the reference's standard errors of 1, so the reference cannot tell it from "
               "1.\n\n| scene | region | pixels | R | G | B | all |\n|---|---|---|---|---|---|---|\n");
    for (int k = 0; k < n; k++)
        for (int r = 1; r < LR_EVAL_REGION_COUNT; r++) {
            if (!sc[k].region_px[r])
                continue;
            fprintf(f, "| %s | %s | %ld |", sc[k].name, lr_eval_region_name(r),
                    sc[k].region_px[r]);
            for (int b = 0; b < 4; b++)
                ratio_cell(f, sc[k].region_ratio[r][b]);
            fprintf(f, "\n");
        }
    bool check = false;
    for (int k = 0; k < n; k++)
        check |= sc[k].nss > 0;
    if (check) {
        fprintf(f, "\nSupersampling convergence (LRB_SWEEP_SS_CHECK; base setting converged): "
                   "bias objects / receivers, median |ln| objects.\n\n| scene | factor | bias "
                   "objects | bias receivers | median \\|ln\\| |\n|---|---|---|---|---|\n");
        for (int k = 0; k < n; k++)
            for (int j = 0; j < sc[k].nss; j++)
                fprintf(f, "| %s | %d×%d | %.4f | %.4f | %.4f |\n", sc[k].name, sc[k].ss[j],
                        sc[k].ss[j], sc[k].ss_bias_object[j], sc[k].ss_bias_receivers[j],
                        sc[k].ss_mal[j]);
    }
    fprintf(f, "\n");
}
