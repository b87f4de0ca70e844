/* lamprig tests — a fine midpoint quadrature over a mesh's surface, for integrating a model's
 * exitance (an object's power) independently of the renderer's own maps. */
#ifndef LRT_MESH_QUAD_H
#define LRT_MESH_QUAD_H

#include <stddef.h>

#include "render/base/vec3.h"
#include "render/mesh/mesh.h"

/* One point: triangle t, the sub-triangle's centroid at barycentrics (u, w) (x = p0 + u e1 +
 * w e2), the triangle's normal n and the sub-triangle's area dA. */
typedef void (*lrt_mesh_point_fn)(void *user, size_t t, double u, double w, lr_vec3 x,
                                  lr_vec3 n, double dA);

/* Each triangle split into R^2 congruent sub-triangles (R = ceil(longest edge / max_edge)),
 * f called at each one's centroid: exact for linear integrands, and for a smooth one the error
 * falls as max_edge^2. */
void lrt_mesh_quadrature(const lr_mesh *m, double max_edge, lrt_mesh_point_fn f, void *user);

#endif
