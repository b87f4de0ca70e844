#include "render/base/mat4.h"

#include <math.h>
#include <string.h>

#define M(m, r, c) (m)[(c) * 4 + (r)]

void lr_mat4_identity(double out[16])
{
    memset(out, 0, 16 * sizeof *out);
    out[0] = out[5] = out[10] = out[15] = 1.0;
}

void lr_mat4_mul(const double a[16], const double b[16], double out[16])
{
    double t[16];
    for (int c = 0; c < 4; c++)
        for (int r = 0; r < 4; r++) {
            double s = 0.0;
            for (int k = 0; k < 4; k++)
                s += M(a, r, k) * M(b, k, c);
            M(t, r, c) = s;
        }
    memcpy(out, t, sizeof t);
}

void lr_mat4_translate(lr_vec3 t, double out[16])
{
    lr_mat4_identity(out);
    M(out, 0, 3) = t.x;
    M(out, 1, 3) = t.y;
    M(out, 2, 3) = t.z;
}

void lr_mat4_scale(lr_vec3 s, double out[16])
{
    lr_mat4_identity(out);
    out[0] = s.x;
    out[5] = s.y;
    out[10] = s.z;
}

/* Exact values at multiples of 90 degrees, so that a "rotate_deg": [90, 0, 0] in a scene
 * gives an exactly axis-aligned mesh (cos(pi/2) is 6e-17 otherwise). */
static void sincos_deg(double deg, double *s, double *c)
{
    double q = deg / 90.0;
    if (q == floor(q) && fabs(q) < 1e9) {
        long k = ((long)q % 4 + 4) % 4;
        static const double S[4] = {0, 1, 0, -1}, C[4] = {1, 0, -1, 0};
        *s = S[k];
        *c = C[k];
        return;
    }
    double r = deg * (M_PI / 180.0);
    *s = sin(r);
    *c = cos(r);
}

void lr_mat4_rotate_xyz_deg(lr_vec3 deg, double out[16])
{
    double sx, cx, sy, cy, sz, cz;
    sincos_deg(deg.x, &sx, &cx);
    sincos_deg(deg.y, &sy, &cy);
    sincos_deg(deg.z, &sz, &cz);
    double rx[16], ry[16], rz[16];
    lr_mat4_identity(rx);
    M(rx, 1, 1) = cx; M(rx, 1, 2) = -sx;
    M(rx, 2, 1) = sx; M(rx, 2, 2) = cx;
    lr_mat4_identity(ry);
    M(ry, 0, 0) = cy; M(ry, 0, 2) = sy;
    M(ry, 2, 0) = -sy; M(ry, 2, 2) = cy;
    lr_mat4_identity(rz);
    M(rz, 0, 0) = cz; M(rz, 0, 1) = -sz;
    M(rz, 1, 0) = sz; M(rz, 1, 1) = cz;
    lr_mat4_mul(ry, rx, out);
    lr_mat4_mul(rz, out, out);
}

int lr_mat4_look_at(lr_vec3 eye, lr_vec3 target, lr_vec3 up, double out[16])
{
    lr_vec3 f = lr_v3_normalize(lr_v3_sub(target, eye));
    lr_vec3 s = lr_v3_cross(f, up);
    double sl = lr_v3_len(s);
    if (lr_v3_len(f) == 0.0 || !(sl > 1e-12 * lr_v3_len(up)))
        return -1;
    s = lr_v3_scale(s, 1.0 / sl);
    lr_vec3 u = lr_v3_cross(s, f);
    lr_mat4_identity(out);
    M(out, 0, 0) = s.x; M(out, 0, 1) = s.y; M(out, 0, 2) = s.z;
    M(out, 1, 0) = u.x; M(out, 1, 1) = u.y; M(out, 1, 2) = u.z;
    M(out, 2, 0) = -f.x; M(out, 2, 1) = -f.y; M(out, 2, 2) = -f.z;
    M(out, 0, 3) = -lr_v3_dot(s, eye);
    M(out, 1, 3) = -lr_v3_dot(u, eye);
    M(out, 2, 3) = lr_v3_dot(f, eye);
    return 0;
}

void lr_mat4_perspective(double fovy, double aspect, double znear, double zfar, double out[16])
{
    double f = 1.0 / tan(fovy / 2.0);
    memset(out, 0, 16 * sizeof *out);
    M(out, 0, 0) = f / aspect;
    M(out, 1, 1) = f;
    M(out, 2, 2) = (zfar + znear) / (znear - zfar);
    M(out, 2, 3) = 2.0 * zfar * znear / (znear - zfar);
    M(out, 3, 2) = -1.0;
}

void lr_mat4_ortho(double l, double r, double b, double t, double znear, double zfar,
                   double out[16])
{
    lr_mat4_identity(out);
    M(out, 0, 0) = 2.0 / (r - l);
    M(out, 1, 1) = 2.0 / (t - b);
    M(out, 2, 2) = -2.0 / (zfar - znear);
    M(out, 0, 3) = -(r + l) / (r - l);
    M(out, 1, 3) = -(t + b) / (t - b);
    M(out, 2, 3) = -(zfar + znear) / (zfar - znear);
}

int lr_mat4_inverse(const double m[16], double out[16])
{
    /* Cofactor expansion (as in MESA's gluInvertMatrix). */
    double inv[16];
    inv[0] = m[5] * m[10] * m[15] - m[5] * m[11] * m[14] - m[9] * m[6] * m[15] +
             m[9] * m[7] * m[14] + m[13] * m[6] * m[11] - m[13] * m[7] * m[10];
    inv[4] = -m[4] * m[10] * m[15] + m[4] * m[11] * m[14] + m[8] * m[6] * m[15] -
             m[8] * m[7] * m[14] - m[12] * m[6] * m[11] + m[12] * m[7] * m[10];
    inv[8] = m[4] * m[9] * m[15] - m[4] * m[11] * m[13] - m[8] * m[5] * m[15] +
             m[8] * m[7] * m[13] + m[12] * m[5] * m[11] - m[12] * m[7] * m[9];
    inv[12] = -m[4] * m[9] * m[14] + m[4] * m[10] * m[13] + m[8] * m[5] * m[14] -
              m[8] * m[6] * m[13] - m[12] * m[5] * m[10] + m[12] * m[6] * m[9];
    inv[1] = -m[1] * m[10] * m[15] + m[1] * m[11] * m[14] + m[9] * m[2] * m[15] -
             m[9] * m[3] * m[14] - m[13] * m[2] * m[11] + m[13] * m[3] * m[10];
    inv[5] = m[0] * m[10] * m[15] - m[0] * m[11] * m[14] - m[8] * m[2] * m[15] +
             m[8] * m[3] * m[14] + m[12] * m[2] * m[11] - m[12] * m[3] * m[10];
    inv[9] = -m[0] * m[9] * m[15] + m[0] * m[11] * m[13] + m[8] * m[1] * m[15] -
             m[8] * m[3] * m[13] - m[12] * m[1] * m[11] + m[12] * m[3] * m[9];
    inv[13] = m[0] * m[9] * m[14] - m[0] * m[10] * m[13] - m[8] * m[1] * m[14] +
              m[8] * m[2] * m[13] + m[12] * m[1] * m[10] - m[12] * m[2] * m[9];
    inv[2] = m[1] * m[6] * m[15] - m[1] * m[7] * m[14] - m[5] * m[2] * m[15] +
             m[5] * m[3] * m[14] + m[13] * m[2] * m[7] - m[13] * m[3] * m[6];
    inv[6] = -m[0] * m[6] * m[15] + m[0] * m[7] * m[14] + m[4] * m[2] * m[15] -
             m[4] * m[3] * m[14] - m[12] * m[2] * m[7] + m[12] * m[3] * m[6];
    inv[10] = m[0] * m[5] * m[15] - m[0] * m[7] * m[13] - m[4] * m[1] * m[15] +
              m[4] * m[3] * m[13] + m[12] * m[1] * m[7] - m[12] * m[3] * m[5];
    inv[14] = -m[0] * m[5] * m[14] + m[0] * m[6] * m[13] + m[4] * m[1] * m[14] -
              m[4] * m[2] * m[13] - m[12] * m[1] * m[6] + m[12] * m[2] * m[5];
    inv[3] = -m[1] * m[6] * m[11] + m[1] * m[7] * m[10] + m[5] * m[2] * m[11] -
             m[5] * m[3] * m[10] - m[9] * m[2] * m[7] + m[9] * m[3] * m[6];
    inv[7] = m[0] * m[6] * m[11] - m[0] * m[7] * m[10] - m[4] * m[2] * m[11] +
             m[4] * m[3] * m[10] + m[8] * m[2] * m[7] - m[8] * m[3] * m[6];
    inv[11] = -m[0] * m[5] * m[11] + m[0] * m[7] * m[9] + m[4] * m[1] * m[11] -
              m[4] * m[3] * m[9] - m[8] * m[1] * m[7] + m[8] * m[3] * m[5];
    inv[15] = m[0] * m[5] * m[10] - m[0] * m[6] * m[9] - m[4] * m[1] * m[10] +
              m[4] * m[2] * m[9] + m[8] * m[1] * m[6] - m[8] * m[2] * m[5];
    double det = m[0] * inv[0] + m[1] * inv[4] + m[2] * inv[8] + m[3] * inv[12];
    if (det == 0.0 || !isfinite(det))
        return -1;
    for (int i = 0; i < 16; i++)
        out[i] = inv[i] / det;
    return 0;
}

double lr_mat4_det3(const double m[16])
{
    return M(m, 0, 0) * (M(m, 1, 1) * M(m, 2, 2) - M(m, 1, 2) * M(m, 2, 1)) -
           M(m, 0, 1) * (M(m, 1, 0) * M(m, 2, 2) - M(m, 1, 2) * M(m, 2, 0)) +
           M(m, 0, 2) * (M(m, 1, 0) * M(m, 2, 1) - M(m, 1, 1) * M(m, 2, 0));
}

int lr_mat4_normal_matrix(const double m[16], double out[9])
{
    double det = lr_mat4_det3(m);
    if (det == 0.0 || !isfinite(det))
        return -1;
    /* (A^-1)^T = cofactor(A) / det; row-major out[r * 3 + c]. */
    double a = M(m, 0, 0), b = M(m, 0, 1), c = M(m, 0, 2);
    double d = M(m, 1, 0), e = M(m, 1, 1), f = M(m, 1, 2);
    double g = M(m, 2, 0), h = M(m, 2, 1), i = M(m, 2, 2);
    double cof[9] = {e * i - f * h, -(d * i - f * g), d * h - e * g,
                     -(b * i - c * h), a * i - c * g, -(a * h - b * g),
                     b * f - c * e, -(a * f - c * d), a * e - b * d};
    for (int k = 0; k < 9; k++)
        out[k] = cof[k] / det;
    return 0;
}

lr_vec3 lr_mat4_point(const double m[16], lr_vec3 p)
{
    return lr_v3(M(m, 0, 0) * p.x + M(m, 0, 1) * p.y + M(m, 0, 2) * p.z + M(m, 0, 3),
                 M(m, 1, 0) * p.x + M(m, 1, 1) * p.y + M(m, 1, 2) * p.z + M(m, 1, 3),
                 M(m, 2, 0) * p.x + M(m, 2, 1) * p.y + M(m, 2, 2) * p.z + M(m, 2, 3));
}

lr_vec3 lr_mat4_project(const double m[16], lr_vec3 p)
{
    lr_vec3 q = lr_mat4_point(m, p);
    double w = M(m, 3, 0) * p.x + M(m, 3, 1) * p.y + M(m, 3, 2) * p.z + M(m, 3, 3);
    return w != 0.0 ? lr_v3_scale(q, 1.0 / w) : q;
}

lr_vec3 lr_mat4_dir(const double m[16], lr_vec3 d)
{
    return lr_v3(M(m, 0, 0) * d.x + M(m, 0, 1) * d.y + M(m, 0, 2) * d.z,
                 M(m, 1, 0) * d.x + M(m, 1, 1) * d.y + M(m, 1, 2) * d.z,
                 M(m, 2, 0) * d.x + M(m, 2, 1) * d.y + M(m, 2, 2) * d.z);
}

lr_vec3 lr_mat3_apply(const double n[9], lr_vec3 v)
{
    return lr_v3(n[0] * v.x + n[1] * v.y + n[2] * v.z, n[3] * v.x + n[4] * v.y + n[5] * v.z,
                 n[6] * v.x + n[7] * v.y + n[8] * v.z);
}

void lr_mat4_to_float(const double m[16], float out[16])
{
    for (int i = 0; i < 16; i++)
        out[i] = (float)m[i];
}
