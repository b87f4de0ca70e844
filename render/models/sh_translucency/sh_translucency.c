/* Seed 002's SH translucency: no S_d, one deterministic evaluation per point from each light's
 * environment projected through the G-buffer cameras (render/optics/sh_translucency.h, on the
 * CPU render/models/twin/sh.h, on the GPU lib/sh_translucency.glsl).
 *
 * Its validity limit: seed 002 attenuates by the crossed thickness d through
 * a_c = exp(-sigma_tr max(d, 1/sigma_t')) (the clamp at one transport mean free path). A wall
 * (thickness_mm) thinner than that mean free path in some band sits wholly in the clamp: the
 * model cannot tell that wall from a thicker one, so its figures do not carry over. */
#include <math.h>
#include <stdio.h>

#include "render/models/model.h"
#include "render/scene/scene.h"

static const char *limit(const lr_scene_object *o, char *buf, size_t cap)
{
    if (!(o->thickness_mm > 0.0))
        return NULL;
    const lr_coeffs *c = &o->coeffs;
    double mfp = fmax(c->mfp[0], fmax(c->mfp[1], c->mfp[2]));
    if (o->thickness_mm < mfp) {
        snprintf(buf, cap, "the wall (%.3g mm) is thinner than one transport mean free path "
                 "of the material (%.3g mm), where the SH attenuation is clamped",
                 o->thickness_mm, mfp);
        return buf;
    }
    return NULL;
}

const lr_model_ops lr_model_sh_translucency = {
    .name = "sh_translucency",
    .props = {.no_profile = true,
              .no_closure = "its energy is fitted, not closed",
              .no_openings = "its energy is fitted, not closed",
              .light_env = true},
    .limit = limit,
    .glsl_B = "lr_sh_translucency_B(obj, mat, xo, no)",
};
