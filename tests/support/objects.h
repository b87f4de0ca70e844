/* lamprig tests — translucent objects built in a test (mesh + BVH + material) as the CPU twin
 * sees them, without a scene file; and a hollow sphere (a shell around a cavity). */
#ifndef LR_TEST_OBJECTS_H
#define LR_TEST_OBJECTS_H

#include "render/mesh/bvh.h"
#include "render/mesh/mesh.h"
#include "render/scene/scene.h"

typedef struct lrt_object {
    lr_scene_object obj; /* mesh, bvh, coeffs, centre, radius, area filled */
    lr_mesh *mesh;
    lr_bvh *bvh;
} lrt_object;

/* A BVH over m; aborts the test binary on failure. */
lr_bvh *lrt_bvh(const lr_mesh *m);

/* Takes ownership of m; aborts the test binary on failure. */
void lrt_object_make(lr_mesh *m, const lr_medium *medium, lrt_object *out);
void lrt_object_free(lrt_object *o);

/* A sphere of radius ro around the origin (icosphere, `sub` subdivisions) with, when ri > 0, a
 * concentric spherical cavity of radius ri (inner faces turned to face the cavity). */
lr_mesh *lrt_shell_mesh(double ro, double ri, int sub);

/* A light of unit intensity and white colour. */
lr_light lrt_point_light(lr_vec3 p);
lr_light lrt_directional_light(lr_vec3 dir);

#endif
