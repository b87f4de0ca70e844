/* lamprig — materials: optical properties of a translucent medium, from a preset file
 * (configs/materials/NAME.json) or from an object embedded in a scene.
 *
 * File format (every field validated; unknown or duplicate fields are errors):
 *   name           string, 1..63 bytes
 *   source         string, 1..511 bytes: the citation or derivation of the numbers (required)
 *   sigma_a        [R, G, B] absorption, mm^-1, >= 0
 *   sigma_s_prime  [R, G, B] reduced scattering sigma_s (1 - g), mm^-1, >= 0
 *   eta            relative index of refraction inside / outside, > 0
 *   g              optional Henyey-Greenstein mean cosine in (-1, 1), default 0
 *   sh_scale       optional number or [R, G, B] > 0: the sh_translucency model's energy scale,
 *                  lr_sh_fit_scale at 10 mm (render/optics/sh_translucency.h); absent: fitted
 *                  when the object loads. Not inherited from a base.
 * or, for a scaled preset,
 *   base           name of another preset (resolved as below); its medium is the starting point
 *   scale          optional number or [R, G, B] > 0 (default 1) multiplying both sigma_a and
 *                  sigma_s_prime of the base: scaling the coefficients by s is the same as
 *                  shrinking the object by s (every length in the diffusion models is measured
 *                  in mean free paths, Jensen et al. 2001 Sec. 2.4)
 *   sigma_a, sigma_s_prime, eta, g   optional overrides, taken as given (not scaled)
 * Finally the medium must pass lr_medium_validate (render/optics/optics.h).
 *
 * Errors are LR_EPARSE (bad file content), LR_EINVAL (a value out of range), LR_EIO (missing
 * file) with a message "FILE:LINE: field 'F': what is wrong".
 */
#ifndef LR_MATERIAL_H
#define LR_MATERIAL_H

#include "render/base/err.h"
#include "render/base/json.h"
#include "render/optics/optics.h"

#define LR_MATERIAL_NAME_MAX 64
#define LR_MATERIAL_SOURCE_MAX 512
/* Longest chain of `base` references followed before giving up (a cycle is reported as such
 * before this is reached; the limit only bounds work on a pathological tree of presets). */
#define LR_MATERIAL_BASE_DEPTH 16

typedef struct lr_material {
    char name[LR_MATERIAL_NAME_MAX];
    char source[LR_MATERIAL_SOURCE_MAX]; /* where the numbers come from (citation / derivation) */
    lr_medium medium;                    /* sigma_a, sigma_s_prime (mm^-1, RGB), eta, g */
    double sh_scale[3];                  /* "sh_scale": seed 002's fitted energy scale per band
                                          * (render/optics/sh_translucency.h); 0: not given */
} lr_material;

/* Loads a material file. A `base` in it names a preset in the same directory as `path`. */
int lr_material_load(const char *path, lr_material *out, lr_err *e);

/* A material object embedded in another JSON file (a scene): the same fields; `where` names the
 * object in messages (e.g. "objects[2].material", fields then read
 * "objects[2].material.sigma_a[1]"). A `base` names a preset of lr_material_find. */
int lr_material_from_json(const lr_json *j, lr_jnode obj, const char *where, lr_material *out,
                          lr_err *e);

/* NAME -> <lr_configs_dir()>/materials/NAME.json; NAME must be a plain name (letters, digits,
 * '_', '-', '.', not starting with '.': no '/', no ".."), and the file's `name` must equal NAME. */
int lr_material_find(const char *name, lr_material *out, lr_err *e);

/* Whether NAME is acceptable to lr_material_find (see above). */
int lr_material_name_ok(const char *name);

/* Names of the shipped presets (the *.json files of <lr_configs_dir()>/materials with a plain
 * name), sorted with strcmp; caller frees with lr_material_names_free. */
int lr_material_names(char ***names, int *count, lr_err *e);
void lr_material_names_free(char **names, int count);

#endif
