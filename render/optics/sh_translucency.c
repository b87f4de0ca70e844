/* Seed 002 (Banterle & Chalmers): SH accumulation of the entering light and its evaluation along
 * the exit direction with a thickness attenuation. See sh_translucency.h for the model. */
#include "render/optics/sh_translucency.h"

#include <math.h>
#include <string.h>

#include "render/base/mat4.h"

void lr_sh_env_clear(lr_sh_env *env) { memset(env, 0, sizeof *env); }

lr_vec3 lr_sh_refract(lr_vec3 v, lr_vec3 n, double eta)
{
    double cos_i = -lr_v3_dot(v, n);
    double k = 1.0 / eta;
    double sin2_t = k * k * fmax(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0)
        return lr_v3_add(v, lr_v3_scale(n, 2.0 * cos_i));
    double cos_t = sqrt(1.0 - sin2_t);
    /* Snell: t = v / eta + (cos_i / eta - cos_t) n. */
    return lr_v3_normalize(lr_v3_add(lr_v3_scale(v, k), lr_v3_scale(n, k * cos_i - cos_t)));
}

void lr_sh_env_add(lr_sh_env *env, lr_vec3 v, lr_vec3 n_i, double flux, double area, double eta)
{
    double cos_i = -lr_v3_dot(v, n_i);
    if (!(cos_i > LR_SH_MIN_COS) || !(flux > 0.0) || !(area > 0.0))
        return;
    /* Seed 002 Sec. 2.1: each texel's irradiance scaled by the transmittance F_t(eta, w_in). */
    double p = lr_fresnel_transmittance(cos_i, eta) * flux;
    double y[9];
    lr_sh9_basis(lr_sh_refract(v, n_i, eta), y); /* Eq. 6-9, along the refracted direction */
    for (int k = 0; k < 9; k++)
        env->E[k] += p * y[k];
    env->power += p;
    env->area += area;
}

void lr_sh_env_finish(lr_sh_env *env)
{
    double inv = env->area > 0.0 ? 1.0 / env->area : 0.0;
    for (int k = 0; k < 9; k++)
        env->E[k] *= inv;
}

double lr_sh_env_irradiance(const lr_sh_env *env, lr_vec3 n)
{
    return fmax(0.0, lr_sh9_irradiance(env->E, n));
}

double lr_sh_eq12(double sigma_tr, double sigma_t_prime, double d)
{
    d = fmax(d, 1.0 / sigma_t_prime);
    return (sigma_tr * d + 1.0) * exp(-sigma_tr * d) / (sigma_t_prime * d * d * d);
}

double lr_sh_atten(double sigma_tr, double sigma_t_prime, double d)
{
    return exp(-sigma_tr * fmax(d, 1.0 / sigma_t_prime));
}

void lr_sh_translucency_B(const lr_coeffs *c, const double scale[3], const lr_sh_env *env,
                          lr_vec3 n_out, double d, double out[3])
{
    double e = lr_sh_env_irradiance(env, n_out);
    for (int b = 0; b < 3; b++)
        out[b] = scale[b] * lr_sh_atten(c->sigma_tr[b], c->sigma_t_prime[b], d) * e;
}

bool lr_sh_lit(const lr_coeffs *c, double radius, double d, double ni_dot_no)
{
    double mfp = (c->mfp[0] + c->mfp[1] + c->mfp[2]) / 3.0;
    return ni_dot_no > 0.0 && d <= LR_SH_LIT_RADII * radius + mfp;
}

void lr_sh_direct(const lr_coeffs *c, double cos_i, double out[3])
{
    double rho[3];
    lr_dipole_rd_total(c, rho);
    double f = cos_i > 0.0 ? lr_fresnel_transmittance(cos_i, c->eta) * cos_i : 0.0;
    for (int b = 0; b < 3; b++)
        out[b] = rho[b] * f;
}

void lr_sh_fit_scale(const lr_coeffs *c, double d_fit, double out[3])
{
    /* T(d_fit) / a(d_fit) as (T e^{sigma_tr d_fit}) e^{sigma_tr (max(d_fit, mfp) - d_fit)}: an
     * optically thick material (sigma_tr d_fit beyond about 745: sigma_a 100 /mm, or sigma_s'
     * 1e6 /mm) makes both T and a underflow to 0, and their quotient NaN or Inf in every map
     * texel; the limit is finite (lr_multipole_transmission_gain, at most alpha' e^{sqrt 3},
     * and the second factor at most e^{sigma_tr mfp} <= e^{sqrt 3}). B = s a E then goes to 0
     * with a: a thick material transmits nothing. */
    double g[3];
    lr_multipole_transmission_gain(c, d_fit, g);
    for (int b = 0; b < 3; b++) {
        double k = c->sigma_tr[b], clamp = fmax(d_fit, 1.0 / c->sigma_t_prime[b]);
        out[b] = g[b] * exp(k * (clamp - d_fit)) / LR_SH_DELTA_GAIN;
    }
}

void lr_sh_object_scale(const lr_coeffs *c, const double preset[3], double out[3])
{
    if (preset && preset[0] > 0.0 && preset[1] > 0.0 && preset[2] > 0.0) {
        memcpy(out, preset, 3 * sizeof *out);
        return;
    }
    lr_sh_fit_scale(c, LR_SH_FIT_MM, out);
}

/* Solid angle of the spherical triangle (a, b, c), unit vectors (Van Oosterom & Strackee 1983). */
static double triangle_solid_angle(lr_vec3 a, lr_vec3 b, lr_vec3 c)
{
    double num = fabs(lr_v3_dot(a, lr_v3_cross(b, c)));
    double den = 1.0 + lr_v3_dot(a, b) + lr_v3_dot(b, c) + lr_v3_dot(c, a);
    return 2.0 * atan2(num, den);
}

bool lr_sh_texel_ray(const double vp[16], bool ortho, int n, int i, int j, lr_vec3 *org,
                     lr_vec3 *dir, double *weight)
{
    double inv[16];
    if (n <= 0 || lr_mat4_inverse(vp, inv) != 0)
        return false;
    double h = 1.0 / n;
    /* Corners (x, y) in NDC, counter-clockwise, and the centre last. */
    const double cx[5] = {-1, 1, 1, -1, 0}, cy[5] = {-1, -1, 1, 1, 0};
    lr_vec3 nearp[5], farp[5], u[5];
    for (int k = 0; k < 5; k++) {
        double x = (2.0 * i + 1.0 + cx[k]) * h - 1.0, y = (2.0 * j + 1.0 + cy[k]) * h - 1.0;
        nearp[k] = lr_mat4_project(inv, lr_v3(x, y, -1.0));
        farp[k] = lr_mat4_project(inv, lr_v3(x, y, 1.0));
        u[k] = lr_v3_normalize(lr_v3_sub(farp[k], nearp[k]));
    }
    *org = nearp[4];
    *dir = u[4];
    if (ortho) {
        lr_vec3 a = lr_v3_sub(nearp[1], nearp[0]), b = lr_v3_sub(nearp[3], nearp[0]);
        *weight = lr_v3_len(lr_v3_cross(a, b));
    } else {
        *weight = triangle_solid_angle(u[0], u[1], u[2]) + triangle_solid_angle(u[0], u[2], u[3]);
    }
    return true;
}
