/* lamprig — procedural meshes, parameters in millimetres.
 *
 * Every descriptor is zero-initialised to its documented defaults. Shapes of revolution stand
 * on z = 0 around the z axis (z is up in every scene); vertices lie on the exact surface and
 * sharp edges (rims, the candle's bottom) have split vertices with their own normals.
 *
 * Each generator first checks its parameters with the matching *_check function, which names
 * the offending field through *field so that a scene can point at the line that set it.
 */
#ifndef LR_SHAPES_H
#define LR_SHAPES_H

#include <stdbool.h>

#include "render/base/vec3.h"
#include "render/mesh/mesh.h"

/* Pillar candle: a closed cylinder whose top has a melt pool, a paraboloid dish
 * z(rho) = height - pool_depth (1 - (rho / pool_radius)^2) for rho <= pool_radius, inside a
 * flat rim ring. */
typedef struct lr_candle_desc {
    double radius;      /* mm; default 35 (a 70 mm pillar) */
    double height;      /* mm; default 120 */
    double pool_depth;  /* mm, < height; default 8 */
    double pool_radius; /* mm, <= radius; default radius - 3 (a 3 mm wax rim) */
    bool flat_top;      /* no pool (a new candle); pool_depth and pool_radius are ignored */
    int segments;       /* around the axis, >= 3; default 64 */
    int pool_rings;     /* rings from the pool's centre to its edge; default 12 */
    int side_rings;     /* along the height; default: square-ish quads */
    lr_mesh_checks checks;
} lr_candle_desc;

/* Lamp shade: the frustum between radius_bottom at z = 0 and radius_top at z = height, as a
 * shell of the given thickness. The outer surface passes through the two radii; the inner one
 * is offset inwards so that every inner facet is parallel to its outer facet at exactly
 * `thickness` (measured along the facet normal). Rims close the shell at top and bottom
 * (a watertight ring, which is what paper or porcelain is); without rims the two surfaces are
 * left open (two boundary loops per end). The shade itself is open at top and bottom. */
typedef struct lr_shade_desc {
    double radius_bottom; /* mm; default 100 */
    double radius_top;    /* mm; default 60 */
    double height;        /* mm; default 150 */
    double thickness;     /* mm; default 1.5 */
    bool single_surface;  /* zero thickness: one outward surface, no rims, thickness ignored */
    bool no_rims;         /* inner and outer surfaces without the rims joining them */
    int segments;         /* around the axis, >= 3; default 96 */
    int rings;            /* along the wall; default: square-ish quads */
    lr_mesh_checks checks;
} lr_shade_desc;

/* Sphere: a subdivided icosahedron with every vertex on the sphere. */
typedef struct lr_sphere_desc {
    double radius;    /* mm; default 50 */
    lr_vec3 center;   /* default the origin */
    int subdivisions; /* 0..7; 20 * 4^n triangles; default 4 (5120) */
    lr_mesh_checks checks;
} lr_sphere_desc;

/* Axis-aligned box. */
typedef struct lr_box_desc {
    lr_vec3 center; /* default the origin */
    lr_vec3 size;   /* mm, each > 0; default 100 x 100 x 100 */
    lr_mesh_checks checks;
} lr_box_desc;

/* One-sided rectangle (a receiver: table top, wall), front face along normal. */
typedef struct lr_quad_desc {
    lr_vec3 center;   /* default the origin */
    lr_vec3 normal;   /* default +z */
    lr_vec3 u_dir;    /* direction of the first side, projected into the plane; default +x,
                         or +y when the normal is along x */
    double size_u;    /* mm; default 1000 */
    double size_v;    /* mm; default 1000 */
    int subdivisions; /* quads per side; default 1 */
    lr_mesh_checks checks;
} lr_quad_desc;

/* Checks fill *resolved with the defaults applied; on error *field names the field. */
int lr_candle_check(const lr_candle_desc *d, lr_candle_desc *resolved, const char **field,
                    lr_err *e);
int lr_shade_check(const lr_shade_desc *d, lr_shade_desc *resolved, const char **field,
                   lr_err *e);
int lr_sphere_check(const lr_sphere_desc *d, lr_sphere_desc *resolved, const char **field,
                    lr_err *e);
int lr_box_check(const lr_box_desc *d, lr_box_desc *resolved, const char **field, lr_err *e);
int lr_quad_check(const lr_quad_desc *d, lr_quad_desc *resolved, const char **field, lr_err *e);

/* Generators; errors read "candle: field 'pool_depth': must be less than height (120 mm)". */
int lr_mesh_candle(const lr_candle_desc *d, lr_mesh **out, lr_err *e);
int lr_mesh_shade(const lr_shade_desc *d, lr_mesh **out, lr_err *e);
int lr_mesh_sphere(const lr_sphere_desc *d, lr_mesh **out, lr_err *e);
int lr_mesh_box(const lr_box_desc *d, lr_mesh **out, lr_err *e);
int lr_mesh_quad(const lr_quad_desc *d, lr_mesh **out, lr_err *e);

/* The inner offset of the shade's vertex radii for a given thickness (see lr_shade_desc):
 * t / (cos(pi / segments) cos(phi)), phi the slant of the facets from vertical. */
double lr_shade_radial_offset(const lr_shade_desc *resolved);

#endif
