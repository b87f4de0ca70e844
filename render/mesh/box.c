/* Boxes and rectangles (receivers). */
#include <math.h>

#include "render/mesh/mesh_internal.h"
#include "render/mesh/shapes.h"

int lr_box_check(const lr_box_desc *d, lr_box_desc *r, const char **field, lr_err *e)
{
    *r = *d;
    if (r->size.x == 0.0 && r->size.y == 0.0 && r->size.z == 0.0)
        r->size = lr_v3(100.0, 100.0, 100.0);
    if (!(r->size.x > 0.0 && r->size.y > 0.0 && r->size.z > 0.0 && r->size.x < 1e6 &&
          r->size.y < 1e6 && r->size.z < 1e6)) {
        *field = "size";
        return lr_err_set(e, LR_EINVAL, "each side must be > 0 and < 1e6 mm, got %g, %g, %g",
                          r->size.x, r->size.y, r->size.z);
    }
    if (!lr_v3_isfinite(r->center) || lr_v3_len(r->center) > 1e6) {
        *field = "center";
        return lr_err_set(e, LR_EINVAL, "must be finite and within 1e6 mm of the origin");
    }
    return LR_OK;
}

int lr_mesh_box(const lr_box_desc *d, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    lr_box_desc s;
    const char *field = NULL;
    int rc = lr_box_check(d, &s, &field, e);
    if (rc)
        return lr_err_prefix(e, "box: field '%s'", field);
    lr_mesh_builder b = {0};
    lr_vec3 h = lr_v3_scale(s.size, 0.5);
    /* Each face: normal n and two in-face axes u, v with u x v = n. */
    static const double F[6][3][3] = {
        {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
    for (int f = 0; f < 6; f++) {
        lr_vec3 n = lr_v3(F[f][0][0], F[f][0][1], F[f][0][2]);
        lr_vec3 u = lr_v3(F[f][1][0], F[f][1][1], F[f][1][2]);
        lr_vec3 v = lr_v3(F[f][2][0], F[f][2][1], F[f][2][2]);
        uint32_t first = 0;
        for (int k = 0; k < 4; k++) {
            double su = (k == 1 || k == 2) ? 1.0 : -1.0, sv = k >= 2 ? 1.0 : -1.0;
            lr_vec3 p = lr_v3(n.x * h.x + su * u.x * h.x + sv * v.x * h.x,
                              n.y * h.y + su * u.y * h.y + sv * v.y * h.y,
                              n.z * h.z + su * u.z * h.z + sv * v.z * h.z);
            uint32_t id = lr_mb_vertex(&b, lr_v3_add(s.center, p), n);
            if (k == 0)
                first = id;
        }
        lr_mb_triangle(&b, first, first + 1, first + 2);
        lr_mb_triangle(&b, first, first + 2, first + 3);
    }
    return lr_mb_finish(&b, "box", &s.checks, out, e);
}

int lr_quad_check(const lr_quad_desc *d, lr_quad_desc *r, const char **field, lr_err *e)
{
    *r = *d;
    if (lr_v3_len(r->normal) == 0.0)
        r->normal = lr_v3(0, 0, 1);
    if (r->size_u == 0.0) r->size_u = 1000.0;
    if (r->size_v == 0.0) r->size_v = 1000.0;
    if (r->subdivisions == 0) r->subdivisions = 1;
    if (!lr_v3_isfinite(r->normal)) {
        *field = "normal";
        return lr_err_set(e, LR_EINVAL, "must be a finite non-zero vector");
    }
    r->normal = lr_v3_normalize(r->normal);
    if (lr_v3_len(r->u_dir) == 0.0)
        r->u_dir = fabs(r->normal.x) > 0.9 ? lr_v3(0, 1, 0) : lr_v3(1, 0, 0);
    lr_vec3 u = lr_v3_sub(r->u_dir, lr_v3_scale(r->normal, lr_v3_dot(r->u_dir, r->normal)));
    if (!lr_v3_isfinite(u) || !(lr_v3_len(u) > 1e-6 * lr_v3_len(r->u_dir))) {
        *field = "u_dir";
        return lr_err_set(e, LR_EINVAL, "must not be parallel to the normal");
    }
    r->u_dir = lr_v3_normalize(u);
    if (!(r->size_u > 0.0 && r->size_u < 1e6)) {
        *field = "size";
        return lr_err_set(e, LR_EINVAL, "must be > 0 and < 1e6 mm, got %g", r->size_u);
    }
    if (!(r->size_v > 0.0 && r->size_v < 1e6)) {
        *field = "size";
        return lr_err_set(e, LR_EINVAL, "must be > 0 and < 1e6 mm, got %g", r->size_v);
    }
    if (!lr_v3_isfinite(r->center) || lr_v3_len(r->center) > 1e6) {
        *field = "center";
        return lr_err_set(e, LR_EINVAL, "must be finite and within 1e6 mm of the origin");
    }
    if (r->subdivisions < 1 || r->subdivisions > 1024) {
        *field = "subdivisions";
        return lr_err_set(e, LR_EINVAL, "must be between 1 and 1024, got %d", r->subdivisions);
    }
    return LR_OK;
}

int lr_mesh_quad(const lr_quad_desc *d, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    lr_quad_desc s;
    const char *field = NULL;
    int rc = lr_quad_check(d, &s, &field, e);
    if (rc)
        return lr_err_prefix(e, "quad: field '%s'", field);
    lr_vec3 u = s.u_dir, v = lr_v3_cross(s.normal, u); /* u x v = n: counter-clockwise */
    int k = s.subdivisions;
    lr_mesh_builder b = {0};
    for (int j = 0; j <= k; j++)
        for (int i = 0; i <= k; i++) {
            double a = (double)i / k - 0.5, c = (double)j / k - 0.5;
            lr_vec3 p = lr_v3_add(s.center, lr_v3_add(lr_v3_scale(u, a * s.size_u),
                                                      lr_v3_scale(v, c * s.size_v)));
            lr_mb_vertex(&b, p, s.normal);
        }
    for (int j = 0; j < k; j++)
        for (int i = 0; i < k; i++) {
            uint32_t p00 = (uint32_t)(j * (k + 1) + i), p10 = p00 + 1,
                     p01 = p00 + (uint32_t)(k + 1), p11 = p01 + 1;
            lr_mb_triangle(&b, p00, p10, p11);
            lr_mb_triangle(&b, p00, p11, p01);
        }
    lr_mesh_checks checks = s.checks;
    checks.flags |= LR_MESH_OPEN_OK;
    return lr_mb_finish(&b, "quad", &checks, out, e);
}
