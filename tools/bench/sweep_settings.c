/* The sweep's settings: a base cheap enough for 256 frames per scene, and one-at-a-time
 * changes around it (issue 6: K, N, N_vpl, map sizes, frames, VPLs on/off, model). */
#include <stdlib.h>

#include "tools/bench/sweep.h"

#include <stdlib.h>
#include <string.h>

/* Base: K 8 maps of 64^2, N 4, 64 VPLs, G-buffer 128. Its radiosity is 1/128 of the scenes'
 * own (K 16, 256^2, N 16), so a frame is tens of ms on llvmpipe. */
static const lrb_setting base = {
    .label = "base", .K = 8, .N = 4, .N_vpl = 64, .map_size = 64, .gbuffer_size = 128,
    .vpl = true, .model = "directional_dipole",
    /* The frame series: the model's noise falls as 1/sqrt(F) towards its bias. */
    .checkpoints = {1, 4, 16, 64}, .ncheck = 4, .converge_frames = 128,
};

int lrb_sweep_settings(lrb_setting *out, int cap)
{
    int n = 0;
#define ADD(lbl, field, value)                                                               \
    do {                                                                                     \
        if (n < cap) {                                                                       \
            lrb_setting s = base;                                                            \
            s.label = lbl;                                                                   \
            s.field = value;                                                                 \
            /* Variants: frames 1, 4, 16 against a 32-frame converged image (the bench must  \
             * fit 25 minutes on two cores). */                                              \
            s.checkpoints[0] = 1, s.checkpoints[1] = 4, s.checkpoints[2] = 16, s.ncheck = 3; \
            s.converge_frames = 32;                                                          \
            out[n++] = s;                                                                    \
        }                                                                                    \
    } while (0)
    if (n < cap) {
        out[n] = base;
        /* LRB_SWEEP_MODEL=NAME: the base setting (and so the fair figures) with that model. */
        const char *m = getenv("LRB_SWEEP_MODEL");
        if (m && *m)
            out[n].model = m;
        n++;
    }
    ADD("K=4", K, 4);
    ADD("K=16", K, 16);
    ADD("N=1", N, 1);
    ADD("N=16", N, 16);
    ADD("N_vpl=16", N_vpl, 16);
    ADD("N_vpl=256", N_vpl, 256);
    ADD("map=32", map_size, 32);
    ADD("map=128", map_size, 128);
    ADD("gbuf=64", gbuffer_size, 64);
    ADD("gbuf=256", gbuffer_size, 256);
    ADD("vpl=off", vpl, false);
    ADD("standard", model, "standard_dipole");
    /* Scenes whose objects have a wall thickness (thickness_mm) only; with K 16 as well, since
     * the lamp shade needs 15 maps to cover its inside (the planner's K_cover). */
    ADD("multipole", model, "multipole");
    ADD("multipole+K=16", model, "multipole");
    if (n > 0 && !strcmp(out[n - 1].label, "multipole+K=16"))
        out[n - 1].K = 16;
    ADD("transrad", model, "translucent_radiosity");
    /* The lamp shade's K_cover is 15: the planner can pick the model there only with K 16. */
    ADD("transrad+K=16", model, "translucent_radiosity");
    if (n > 0 && !strcmp(out[n - 1].label, "transrad+K=16"))
        out[n - 1].K = 16;
    ADD("diffusion_grid", model, "diffusion_grid"); /* seed 001 (render/diffusion/) */
    /* The candles' rims by the flame need K 16 maps with the grid as with the dipole
     * (measured: candle 0.172 at K 8, 0.088 at K 16). */
    ADD("diffusion_grid+K=16", model, "diffusion_grid");
    if (n > 0 && !strcmp(out[n - 1].label, "diffusion_grid+K=16"))
        out[n - 1].K = 16;
    ADD("sh", model, "sh_translucency"); /* seed 002: deterministic, one evaluation per texel */
#undef ADD
    return n;
}

lrb_setting lrb_sweep_shipped(void)
{
    lrb_setting s = base;
    s.label = "shipped";
    s.model = NULL;
    s.N_vpl = 0;
    s.K = 0; /* the file's: every shipped scene renders K 16 maps (the field's default) */
    return s;
}
