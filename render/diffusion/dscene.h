/* lamprig — the diffusion_grid model of a scene's objects (seed 001): per object a grid solve
 * per light, turned into the surface radiosity field the radiosity pass (GPU) and the CPU twin
 * interpolate (render/diffusion/dgrid.h, field.c).
 *
 * lr_dscene_update re-solves what changed: an object whose mesh, material, grid spacing or
 * volume file changed gets a new grid (solved coarse-to-fine); otherwise each light's solve is
 * warm-started from that light's last solution (seed 001 Sec. 5.3), so a light move costs a
 * few BiCGSTAB iterations. Objects with another model are skipped.
 *
 * The incident light q(b) per unit intensity (PIPELINE.md's units): point and spot lights
 * F_t(cos) times cos / r^2 averaged over the grid cell's patch of surface around b (the solid
 * angle it subtends over its area; spot: times the pass's smoothstep profile), directional
 * lights F_t(cos) cos; zero where the object itself shadows b (a ray against its BVH; other objects do not
 * shadow, as in the pass: "no scattering between objects").
 *
 * Cavity closure: q is the direct light only. When a point or spot light sits in the object's
 * hull (the flame in its melt pool), the light the lit surface sends back into the cavity and
 * that meets the object again is the closure's gain (render/core/cavity.h), measured from the
 * solved field itself (lr_cavity_measure_field) and applied to the field.
 */
#ifndef LR_DSCENE_H
#define LR_DSCENE_H

#include "render/base/err.h"
#include "render/diffusion/dgrid.h"
#include "render/scene/scene.h"

/* Default grid spacing (objects[i].dgrid_h_mm = 0): the object's bounding radius over
 * LR_DSCENE_AUTO_CELLS, finer where its thinnest wall (lr_scene_object.wall_mm) would get fewer
 * than LR_DSCENE_WALL_CELLS cells across: with about one cell across a wall, its two faces'
 * boundary conditions share nodes and the wall passes too much light (jar_candle's 4 mm rim
 * at 3.2 mm: the outer face's blue 1.26 of the reference's, 1.17 at 1.6 mm;
 * render/diffusion/README.md). Never finer than the radius over LR_DSCENE_MAX_CELLS (the
 * grid's memory and solve go as the cube). */
#define LR_DSCENE_AUTO_CELLS 20.0
#define LR_DSCENE_WALL_CELLS 2.5
#define LR_DSCENE_MAX_CELLS 64.0
/* The cavity closure's measurement (render/core/cavity.h): light directions and surface points;
 * the field is cheap to evaluate, so many points (a few ms). */
#define LR_DSCENE_CAVITY_DIRECTIONS 4096
#define LR_DSCENE_CAVITY_POINTS 8192
/* Rays per surface point for the first bounce across a cavity (bounce.h). */
#define LR_DSCENE_BOUNCE_RAYS 64
/* Objects per scene this holds (the passes' LR_MAX_OBJECTS). */
#define LR_DSCENE_MAX_OBJECTS 8

typedef struct lr_dscene lr_dscene;

/* A solved field: 4 floats per node (B_r, B_g, B_b, valid), x fastest, per unit intensity. */
typedef struct lr_dfield_view {
    const float *data;
    int n[3];
    lr_vec3 origin;
    double h;
} lr_dfield_view;

int lr_dscene_create(lr_dscene **out, lr_err *e);
void lr_dscene_destroy(lr_dscene *d);
/* Brings every diffusion_grid object of s up to date for every light. An object that turns to
 * another model keeps its grid (inactive: no field) for when it turns back. */
int lr_dscene_update(lr_dscene *d, const lr_scene *s, lr_err *e);
/* Polled by the updates' solves from now on (NULL: never cancelled; render/base/cancel.h): a
 * cancelled update returns LR_ECANCELED; the objects keep their grids, and the next update
 * solves every light again (a field then may be the last state's until it does). */
void lr_dscene_set_cancel(lr_dscene *d, const lr_cancel *cancel);
/* Object i's field for light l; false when the object has none (another model). The field
 * includes the cavity closure's gain when the light sits in the object's hull. */
bool lr_dscene_field(const lr_dscene *d, int object, int light, lr_dfield_view *out);
/* The cavity gain per band applied to object i's field for light l (1 where the closure does
 * not apply); false when the object has no field. */
bool lr_dscene_cavity_gain(const lr_dscene *d, int object, int light, double gain[3]);
/* Whether the last update rebuilt object i's grid (a change of geometry or material). */
bool lr_dscene_rebuilt(const lr_dscene *d, int object);
/* Finest-grid BiCGSTAB iterations of the last update, all objects, lights and bands. */
int lr_dscene_last_iters(const lr_dscene *d);
/* The grid spacing object o gets (its dgrid_h_mm, or the auto rule above). */
double lr_dscene_spacing(const lr_scene_object *o);

/* q for a unit-intensity light at b (normal n out of the object); shadowed by obj's mesh.
 * Point and spot lights: the mean over the square of side `cell` centred at b in its tangent
 * plane (render/optics/near_light.h: Omega / cell^2, bounded as the light nears the surface;
 * the point sample cos / r^2 when cell is 0). */
double lr_dscene_irradiance(const lr_scene_object *obj, const lr_light *light, lr_vec3 b,
                            lr_vec3 n, double cell);

#endif
