/* lamprig tests — the emergent light a receiver point gets from the renderer's own VPLs,
 * evaluated in double on the CPU (render/passes/PIPELINE.md pass 4), for checking what
 * composition drew. */
#ifndef LR_TEST_VPL_PROBE_H
#define LR_TEST_VPL_PROBE_H

#include <stdbool.h>

#include "render/base/vec3.h"
#include "render/renderer.h"
#include "render/renderer_debug.h"
#include "render/scene/scene.h"

/* E_vpl at x (normal nx, unit intensity) over the n VPLs v, by the CPU twin's gather
 * (render/core/vpl.h: the bounded geometry term F_t(cos_v) / pi A cos_v cos_x / max(d^2, A)),
 * each VPL's B times the cavity gain composition applies to its object (PIPELINE.md
 * "Energy"); vis: with the twin's ray-cast visibility against the objects. */
void lr_test_vpl_irradiance(lr_renderer *r, const lr_scene *s, const lr_debug_vpl *v, int n,
                            lr_vec3 x, lr_vec3 nx, bool vis, double E[3]);
/* The same read as composition reads plane receiver rc at x: bilinear over the receiver
 * irradiance grid's texel centres (render/core/recv_grid.h), each evaluated as above. */
void lr_test_grid_irradiance(lr_renderer *r, const lr_scene *s, const lr_debug_vpl *v, int n,
                             const lr_receiver *rc, lr_vec3 x, bool vis, double E[3]);

#endif
