/* Seed 000's translucent radiosity: the scene's patch system (its Eq. 14) solved on the CPU
 * (render/transrad/), receivers included in the form factors F, so its B is per vertex and the
 * receiver bounce and openings are its own. Its S integrates the profile of another model over
 * each patch: the slab multipole where the object gives a wall, the standard dipole otherwise. */
#include "render/models/model.h"

static enum lr_sss_model profile(double thickness_mm)
{
    return thickness_mm > 0 ? LR_SSS_MULTIPOLE : LR_SSS_STANDARD_DIPOLE;
}

const lr_model_ops lr_model_translucent_radiosity = {
    .name = "translucent_radiosity",
    .props = {.solves = "its patch system is solved on the CPU",
              .no_closure = "translucent radiosity solves the cavity's inter-reflection itself",
              .no_openings = "its receiver grid carries the inner faces' light "
                             "(render/transrad/tr_scene.h)",
              /* S integrates the profile over each entry patch with 256 points about 0.75 mm
               * apart on the renderer's 12 mm patches and scales each column to the profile's
               * total (render/transrad/subsurface.c). e^{-sigma_tr r} falls below DBL_MIN at
               * sigma_tr r = 708: at 500 /mm that is r = 1.4 mm, twice the points' spacing, so
               * every patch keeps points whose profile is a normal double. Measured on the
               * candle: right at 980 /mm; Inf in S (the total over a subnormal sum) at
               * 1340 /mm, columns lost (sum 0: the light that enters vanishes) at 1470 /mm. */
              .max_sigma_tr = 500.0,
              .max_sigma_tr_why = "a diffusion length of at least 2 um: its S samples the "
                                  "profile about 0.75 mm apart on each 12 mm patch, and a "
                                  "narrower profile underflows between the points",
              .patch_solve = true,
              .measures_thickness = true},
    .profile = profile,
};
