/* lamprig — the thinnest wall of a closed mesh: how thin the body gets between its faces.
 *
 * A volumetric model on a grid (render/diffusion, seed 001) must put a few cells across every
 * wall that carries light: a jar candle burnt down to a 4 mm rim, a shell. The bounding radius
 * alone does not say that. Here each triangle casts a ray from its centroid along its inward
 * normal; the distance to the next face is the wall's local thickness there. The thinnest
 * wall is a low area-weighted percentile of those distances (LR_MESH_WALL_PERCENTILE of the
 * surface), so that a few slivers at a crease do not set it alone.
 */
#ifndef LR_MESH_WALL_H
#define LR_MESH_WALL_H

#include "render/mesh/bvh.h"

/* Per cent of the surface area allowed thinner than the reported wall. */
#define LR_MESH_WALL_PERCENTILE 1.0

/* The thinnest wall of the closed, outward-oriented mesh under b, in the mesh's units (mm);
 * 0 when no inward ray meets a face (an empty mesh). On an open mesh the answer means
 * nothing (rays leave through the openings or cross the cavity): the scene asks only for
 * closed ones. */
double lr_mesh_wall_thickness(const lr_bvh *b);

#endif
