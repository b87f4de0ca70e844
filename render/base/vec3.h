/* lamprig — double-precision 3-vectors for the CPU reference paths (header-only). */
#ifndef LR_VEC3_H
#define LR_VEC3_H

#include <math.h>

typedef struct lr_vec3 {
    double x, y, z;
} lr_vec3;

static inline lr_vec3 lr_v3(double x, double y, double z) { return (lr_vec3){x, y, z}; }
static inline lr_vec3 lr_v3_add(lr_vec3 a, lr_vec3 b) { return lr_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline lr_vec3 lr_v3_sub(lr_vec3 a, lr_vec3 b) { return lr_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline lr_vec3 lr_v3_scale(lr_vec3 a, double s) { return lr_v3(a.x * s, a.y * s, a.z * s); }
static inline double lr_v3_dot(lr_vec3 a, lr_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline lr_vec3 lr_v3_cross(lr_vec3 a, lr_vec3 b)
{
    return lr_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double lr_v3_len(lr_vec3 a) { return sqrt(lr_v3_dot(a, a)); }
/* Returns a/|a|, or the zero vector when |a| is zero (callers decide what that means). */
static inline lr_vec3 lr_v3_normalize(lr_vec3 a)
{
    double l = lr_v3_len(a);
    return l > 0.0 ? lr_v3_scale(a, 1.0 / l) : lr_v3(0.0, 0.0, 0.0);
}
static inline int lr_v3_isfinite(lr_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

#endif
