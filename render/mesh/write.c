/* Mesh writers (PLY, OBJ), through atomic replacement like every file lamprig writes. */
#include <stdio.h>
#include <string.h>

#include "render/base/atomic_file.h"
#include "render/mesh/mesh_internal.h"
#include "render/mesh/mesh_io.h"

static void put_le32(FILE *f, uint32_t v)
{
    unsigned char b[4] = {(unsigned char)v, (unsigned char)(v >> 8), (unsigned char)(v >> 16),
                          (unsigned char)(v >> 24)};
    fwrite(b, 1, 4, f);
}

static void put_f32(FILE *f, float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    put_le32(f, u);
}

int lr_mesh_save_ply(const lr_mesh *m, const char *path, bool binary, lr_err *e)
{
    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc)
        return rc;
    FILE *f = lr_atomic_file_stream(af);
    fprintf(f, "ply\nformat %s 1.0\ncomment lamprig mesh '%s', millimetres\n"
               "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
               "property float nx\nproperty float ny\nproperty float nz\n"
               "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
            binary ? "binary_little_endian" : "ascii", m->name, m->nv, m->nt);
    for (size_t v = 0; v < m->nv; v++) {
        const float *p = &m->pos[3 * v], *n = &m->nrm[3 * v];
        if (binary) {
            for (int k = 0; k < 3; k++)
                put_f32(f, p[k]);
            for (int k = 0; k < 3; k++)
                put_f32(f, n[k]);
        } else {
            /* %.9g round-trips a float exactly. */
            fprintf(f, "%.9g %.9g %.9g %.9g %.9g %.9g\n", p[0], p[1], p[2], n[0], n[1], n[2]);
        }
    }
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *i = &m->idx[3 * t];
        if (binary) {
            fputc(3, f);
            for (int k = 0; k < 3; k++)
                put_le32(f, i[k]);
        } else {
            fprintf(f, "3 %u %u %u\n", (unsigned)i[0], (unsigned)i[1], (unsigned)i[2]);
        }
    }
    return lr_atomic_file_commit(af, e);
}

int lr_mesh_save_obj(const lr_mesh *m, const char *path, lr_err *e)
{
    lr_atomic_file *af;
    int rc = lr_atomic_file_open(path, &af, e);
    if (rc)
        return rc;
    FILE *f = lr_atomic_file_stream(af);
    fprintf(f, "# lamprig mesh '%s', millimetres\n", m->name);
    for (size_t v = 0; v < m->nv; v++)
        fprintf(f, "v %.9g %.9g %.9g\n", m->pos[3 * v], m->pos[3 * v + 1], m->pos[3 * v + 2]);
    for (size_t v = 0; v < m->nv; v++)
        fprintf(f, "vn %.9g %.9g %.9g\n", m->nrm[3 * v], m->nrm[3 * v + 1], m->nrm[3 * v + 2]);
    for (size_t t = 0; t < m->nt; t++) {
        const uint32_t *i = &m->idx[3 * t];
        fprintf(f, "f %u//%u %u//%u %u//%u\n", i[0] + 1, i[0] + 1, i[1] + 1, i[1] + 1,
                i[2] + 1, i[2] + 1);
    }
    return lr_atomic_file_commit(af, e);
}
