/* lamprig — mesh files: a designer's own mockup as PLY or OBJ.
 *
 * PLY: "ascii 1.0" and "binary_little_endian 1.0"; a `vertex` element with x, y, z and
 * optionally nx, ny, nz (any numeric types; other properties are skipped), a `face` element
 * with a `vertex_indices` (or `vertex_index`) list; other elements are skipped. OBJ: v, vn and
 * f with the v, v/vt, v//vn and v/vt/vn forms, negative (relative) indices; vt, o, g, s,
 * usemtl, mtllib are ignored, other statements ignored with one warning each. Polygons are
 * fan-triangulated. A file without normals gets them computed by the loader, averaged over
 * the faces within LR_MESH_CREASE_DEG (60) degrees of each other and split along sharper edges
 * (a cup's floor and rim), as modelling tools' auto smooth (crease.c). Everything then goes through lr_mesh_create's validation and repair, with
 * messages that name the file and the line (or, in binary PLY, the element index).
 */
#ifndef LR_MESH_IO_H
#define LR_MESH_IO_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/mesh/mesh.h"

/* By extension (.ply or .obj, any case). checks may be NULL. */
int lr_mesh_load(const char *path, const lr_mesh_checks *checks, lr_mesh **out, lr_err *e);
int lr_mesh_load_ply(const char *path, const lr_mesh_checks *checks, lr_mesh **out, lr_err *e);
int lr_mesh_load_obj(const char *path, const lr_mesh_checks *checks, lr_mesh **out, lr_err *e);

/* Writers (atomic replace): PLY ascii or binary little-endian with normals, OBJ with v, vn and
 * f v//vn. */
int lr_mesh_save_ply(const lr_mesh *m, const char *path, bool binary, lr_err *e);
int lr_mesh_save_obj(const lr_mesh *m, const char *path, lr_err *e);

#endif
