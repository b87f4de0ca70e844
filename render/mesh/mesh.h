/* lamprig — triangle meshes: the translucent objects and the receivers of every scene.
 *
 * A mesh holds what the GPU draws (float positions and per-vertex normals, uint32 indices,
 * counter-clockwise triangles seen from outside) and answers the geometric questions of the
 * CPU reference code (area, volume, bounds, ray casts through lr_bvh in bvh.h). Units: mm.
 *
 * Every mesh is made by lr_mesh_create(), which validates and repairs its input, so code that
 * holds an lr_mesh can rely on: finite coordinates, indices in range, no zero-area triangles,
 * no duplicate faces, no unreferenced vertices, unit normals. What cannot be repaired without
 * guessing (open boundaries, edges shared by more than two faces) is reported — as counts in
 * an lr_mesh_report and as warnings to the caller's sink — and kept.
 *
 * Topology is judged on positions, not vertex indices: generators and loaders split vertices
 * along sharp edges (a candle's rim) to give each side its own normal, and two vertices at the
 * same float position count as one point of the surface.
 *
 * A mesh is immutable after creation; create/destroy pairs are the only lifetime rule.
 */
#ifndef LR_MESH_H
#define LR_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "render/base/err.h"
#include "render/base/vec3.h"
#include "render/base/warn.h"

typedef struct lr_mesh lr_mesh;

/* What validation found and did (counts refer to the input). */
typedef struct lr_mesh_report {
    size_t degenerate_removed;   /* zero-area triangles (repeated or collinear corners) */
    size_t duplicate_removed;    /* a second face over the same three points */
    size_t unreferenced_removed; /* vertices no remaining face uses */
    size_t boundary_edges;       /* edges with one face: the mesh is open there */
    size_t boundary_loops;       /* connected chains of boundary edges */
    size_t nonmanifold_edges;    /* edges with more than two faces */
    size_t inconsistent_edges;   /* edges whose two faces run the same way (winding flips) */
    size_t flipped;              /* faces turned over by the repair (see LR_MESH_KEEP_WINDING) */
    size_t components;           /* edge-connected pieces */
    bool normals_computed;       /* the input had no (usable) normals */
    bool closed;                 /* watertight: every edge has exactly two faces */
    bool oriented;               /* every two-face edge is run in opposite directions */
} lr_mesh_report;

enum lr_mesh_flags {
    /* Open boundaries are intended (a lamp shade): count them, do not warn. */
    LR_MESH_OPEN_OK = 1u << 0,
    /* Detect and report inconsistent winding but do not turn faces over. By default faces
     * are flipped to agree with their neighbours, and a closed piece whose volume comes out
     * negative is turned inside out, so that normals point out of the material. */
    LR_MESH_KEEP_WINDING = 1u << 1,
};

/* How a mesh is checked; zero-initialised means: warnings discarded, no report, repair. */
typedef struct lr_mesh_checks {
    lr_warn_sink warn;      /* warnings, each prefixed with the mesh's name */
    lr_mesh_report *report; /* optional: filled on success */
    unsigned flags;         /* lr_mesh_flags */
} lr_mesh_checks;

typedef struct lr_mesh_desc {
    const char *name;         /* used in messages: a file path or "candle"; NULL: "mesh" */
    size_t vertex_count;
    const double *positions;  /* 3 per vertex, mm */
    const double *normals;    /* optional, 3 per vertex; NULL: computed (area-weighted) */
    size_t triangle_count;
    const uint32_t *indices;  /* 3 per triangle, counter-clockwise seen from outside */
    /* Optional, for messages: where triangle t came from in its file, origin[t], printed as
     * "NAME:origin" when origin_is_line, else "NAME: face origin" (a binary file's element
     * index). NULL: triangles are named by their index. */
    const uint32_t *origin;
    bool origin_is_line;
    lr_mesh_checks checks;
} lr_mesh_desc;

/* Validates, repairs and copies the input. Rejects (LR_EINVAL, naming the vertex or face and
 * its origin): NaN/Inf or float-overflowing coordinates, indices out of range, no triangles
 * left after repair. Normals given but NaN or zero are recomputed with a warning. */
int lr_mesh_create(const lr_mesh_desc *desc, lr_mesh **out, lr_err *e);
void lr_mesh_destroy(lr_mesh *m);

/* Transformed copy: positions by the affine 4x4 (column-major, see render/base/mat4.h),
 * normals by its inverse transpose; a mirroring transform reverses the winding so that the
 * faces stay outward. The copy keeps the name. */
int lr_mesh_transform(const lr_mesh *m, const double mat[16], lr_mesh **out, lr_err *e);

/* ---- Data for the GPU (valid until destroy) ------------------------------------------- */
const char *lr_mesh_name(const lr_mesh *m);
size_t lr_mesh_vertex_count(const lr_mesh *m);
size_t lr_mesh_triangle_count(const lr_mesh *m);
const float *lr_mesh_positions(const lr_mesh *m); /* xyz per vertex */
const float *lr_mesh_normals(const lr_mesh *m);   /* unit xyz per vertex */
const uint32_t *lr_mesh_indices(const lr_mesh *m);

/* ---- Geometry (double, from the float data) ------------------------------------------- */
lr_vec3 lr_mesh_vertex(const lr_mesh *m, size_t v);
void lr_mesh_triangle(const lr_mesh *m, size_t t, lr_vec3 p[3]);
/* Unit geometric normal of triangle t from its winding. */
lr_vec3 lr_mesh_triangle_normal(const lr_mesh *m, size_t t);
double lr_mesh_triangle_area(const lr_mesh *m, size_t t);
double lr_mesh_area(const lr_mesh *m);
/* The longest triangle edge, mm (0 for no triangles). */
double lr_mesh_longest_edge(const lr_mesh *m);
/* Signed enclosed volume (divergence theorem, about the origin): positive for a closed mesh
 * with outward faces; meaningless for an open one. */
double lr_mesh_volume(const lr_mesh *m);
void lr_mesh_bounds(const lr_mesh *m, lr_vec3 *lo, lr_vec3 *hi);
/* A sphere containing every vertex: centre of the bounding box, radius to the farthest vertex
 * (not the minimal sphere; within a factor sqrt(3) of it, exact for the symmetric shapes of
 * the shipped scenes). */
void lr_mesh_bounding_sphere(const lr_mesh *m, lr_vec3 *center, double *radius);

/* Topology of the mesh as it is (what lr_mesh_create reports, recomputed). */
void lr_mesh_analyze(const lr_mesh *m, lr_mesh_report *out);

/* Generalised winding number of point p (sum of signed solid angles of the triangles over
 * 4 pi; Van Oosterom & Strackee 1983): 1 inside a closed outward mesh, 0 outside, a fraction
 * near holes. */
double lr_mesh_winding_number(const lr_mesh *m, lr_vec3 p);
/* Euclidean distance from p to the convex hull of the vertices (0 inside or on it), by
 * Gilbert-Johnson-Keerthi iteration; within 1e-9 of the mesh size of the exact value. */
double lr_mesh_hull_distance(const lr_mesh *m, lr_vec3 p);

#endif
