/* lamprig — mesh internals shared by the files of render/mesh/ (not a public header). */
#ifndef LR_MESH_INTERNAL_H
#define LR_MESH_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "render/mesh/mesh.h"

struct lr_mesh {
    char *name;
    size_t nv, nt;
    float *pos;    /* 3 * nv */
    float *nrm;    /* 3 * nv */
    uint32_t *idx; /* 3 * nt */
};

/* Position classes: weld[v] is the same for vertices at bit-equal float positions (compared
 * as values, so -0 == +0). Returns a malloc'ed array, NULL on allocation failure; *classes
 * receives the number of distinct positions. */
uint32_t *lr_mesh_weld(const float *pos, size_t nv, size_t *classes);

/* One undirected edge between position classes a < b, used by triangle t. `forward` says the
 * triangle runs a -> b. */
typedef struct lr_mesh_edge {
    uint32_t a, b, t;
    uint8_t forward;
} lr_mesh_edge;

/* Topology of triangles idx[0..nt) over welded ids. Fills counts of *out (boundary, loops,
 * non-manifold, inconsistent, components, closed, oriented); other fields are untouched.
 * When edges_out is not NULL it receives the sorted edge array (3 * nt entries; caller frees).
 * Returns 0, or -1 on allocation failure. */
int lr_mesh_topology(const uint32_t *weld, size_t nclasses, const uint32_t *idx, size_t nt,
                     lr_mesh_report *out, lr_mesh_edge **edges_out);

/* Mesh files without normals (OBJ, PLY): vertex normals averaged (area-weighted) only over the
 * faces within LR_MESH_CREASE_DEG of each corner's face, so that a sharp edge (a votive's floor
 * and rim) gives each side its own normal (crease.c). Rewrites idx[0..3 nt) to the returned
 * vertices (*nv_out of them: positions *pos_out, unit normals *nrm_out, 3 doubles each, caller
 * frees); returns 0, 1 (nothing done) when an index is out of range or a coordinate not
 * finite (lr_mesh_create then reports it), or -1 on allocation failure. */
#define LR_MESH_CREASE_DEG 60.0
int lr_mesh_crease_normals(const double *pos, size_t nv, uint32_t *idx, size_t nt,
                           double cos_crease, double **pos_out, double **nrm_out,
                           size_t *nv_out);

/* Growable arrays for the generators. */
typedef struct lr_mesh_builder {
    double *pos, *nrm;
    size_t nv, cap_v;
    uint32_t *idx;
    size_t nt, cap_t;
    int oom;
} lr_mesh_builder;

uint32_t lr_mb_vertex(lr_mesh_builder *b, lr_vec3 p, lr_vec3 n);
void lr_mb_triangle(lr_mesh_builder *b, uint32_t a, uint32_t c, uint32_t d);
/* Hands the arrays to lr_mesh_create with the given name and checks, then frees them. */
int lr_mb_finish(lr_mesh_builder *b, const char *name, const lr_mesh_checks *checks,
                 lr_mesh **out, lr_err *e);
void lr_mb_free(lr_mesh_builder *b);

#endif

/* Surface of revolution about z: profile points (rho[k], z[k]) with outward normals
 * (nrho[k], nz[k]) in the meridian plane, joined k -> k+1 by rings of `segments` quads.
 * The profile must run so that (theta direction) x (profile direction) points outward. A point
 * with rho == 0 becomes one vertex (a fan). cs holds cos, sin of the `segments` angles, shared
 * by every section so that rings at the same radius and height are bit-identical. */
void lr_mb_revolve(lr_mesh_builder *b, const double (*cs)[2], int segments, const double *rho,
                   const double *z, const double *nrho, const double *nz, int count);
/* cos, sin of 2 pi j / segments (malloc'ed; NULL on failure). */
double (*lr_mb_angles(int segments))[2];

#define LR_MAX_SEGMENTS 4096
#define LR_MAX_RINGS 4096

/* Reads a whole mesh file (at most LR_MESH_FILE_MAX bytes) into a malloc'ed, NUL-terminated
 * buffer. */
#define LR_MESH_FILE_MAX ((size_t)512 << 20)
int lr_mesh_read_file(const char *path, char **buf, size_t *len, lr_err *e);
