/* Colour temperature and photometric scale (photometry.h). */
#include <math.h>

#include "render/photometry/photometry.h"

/* Relative spectral radiance of a Planckian radiator at lambda_nm (Planck's law without c1,
 * which the normalisations cancel). */
static double planck(double lambda_nm, double t_k)
{
    double l = lambda_nm * 1e-9;
    return 1.0 / (l * l * l * l * l * expm1(LR_PLANCK_C2 / (l * t_k))) * 1e-30;
}

static void planck_sums(double t_k, double xyz[3], double *power)
{
    double s[3] = {0, 0, 0}, p = 0.0;
    for (int i = 0; i < LR_CIE_N; i++) {
        double b = planck(LR_CIE_LAMBDA0_NM + LR_CIE_STEP_NM * i, t_k);
        for (int c = 0; c < 3; c++)
            s[c] += lr_cie1931_cmf[i][c] * b;
        p += b;
    }
    for (int c = 0; c < 3; c++)
        xyz[c] = s[c];
    *power = p;
}

void lr_planck_xyz(double t_k, double xyz[3])
{
    double p;
    planck_sums(t_k, xyz, &p);
    double y = xyz[1];
    for (int c = 0; c < 3; c++)
        xyz[c] /= y;
}

double lr_planck_efficacy(double t_k)
{
    double xyz[3], p;
    planck_sums(t_k, xyz, &p);
    return LR_KM_LM_PER_W * xyz[1] / p;
}

/* 3x3 inverse by cofactors (row-major). */
static void inv3(const double m[9], double r[9])
{
    double c0 = m[4] * m[8] - m[5] * m[7], c1 = m[5] * m[6] - m[3] * m[8],
           c2 = m[3] * m[7] - m[4] * m[6];
    double det = m[0] * c0 + m[1] * c1 + m[2] * c2;
    r[0] = c0 / det;
    r[1] = (m[2] * m[7] - m[1] * m[8]) / det;
    r[2] = (m[1] * m[5] - m[2] * m[4]) / det;
    r[3] = c1 / det;
    r[4] = (m[0] * m[8] - m[2] * m[6]) / det;
    r[5] = (m[2] * m[3] - m[0] * m[5]) / det;
    r[6] = c2 / det;
    r[7] = (m[1] * m[6] - m[0] * m[7]) / det;
    r[8] = (m[0] * m[4] - m[1] * m[3]) / det;
}

/* RGB -> XYZ from the sRGB primaries and D65: the primaries' XYZ at Y = 1 as columns, each
 * scaled so that RGB (1, 1, 1) is the white (the usual construction, e.g. SMPTE RP 177). */
static void rgb_to_xyz(double m[9])
{
    static const double px[3] = {0.64, 0.30, 0.15}, py[3] = {0.33, 0.60, 0.06};
    static const double wx = 0.3127, wy = 0.3290;
    double p[9], pi[9];
    for (int c = 0; c < 3; c++) {
        p[0 + c] = px[c] / py[c];
        p[3 + c] = 1.0;
        p[6 + c] = (1.0 - px[c] - py[c]) / py[c];
    }
    inv3(p, pi);
    double w[3] = {wx / wy, 1.0, (1.0 - wx - wy) / wy}, s[3];
    for (int r = 0; r < 3; r++)
        s[r] = pi[3 * r] * w[0] + pi[3 * r + 1] * w[1] + pi[3 * r + 2] * w[2];
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++)
            m[3 * r + c] = p[3 * r + c] * s[c];
}

void lr_xyz_to_rgb(const double xyz[3], double rgb[3])
{
    double m[9], mi[9];
    rgb_to_xyz(m);
    inv3(m, mi);
    for (int r = 0; r < 3; r++)
        rgb[r] = mi[3 * r] * xyz[0] + mi[3 * r + 1] * xyz[1] + mi[3 * r + 2] * xyz[2];
}

double lr_rgb_luminance(const double rgb[3])
{
    double m[9];
    rgb_to_xyz(m);
    return m[3] * rgb[0] + m[4] * rgb[1] + m[5] * rgb[2];
}

void lr_cct_color(double t_k, double rgb[3])
{
    double xyz[3];
    lr_planck_xyz(t_k, xyz);
    lr_xyz_to_rgb(xyz, rgb);
    for (int c = 0; c < 3; c++)
        if (rgb[c] < 0.0)
            rgb[c] = 0.0;
    double y = lr_rgb_luminance(rgb);
    double k = lr_planck_efficacy(t_k) / LR_KM_LM_PER_W / y;
    for (int c = 0; c < 3; c++)
        rgb[c] *= k;
}

void lr_xy_to_uv1960(double x, double y, double *u, double *v)
{
    double d = -2.0 * x + 12.0 * y + 3.0;
    *u = 4.0 * x / d;
    *v = 6.0 * y / d;
}

/* photometry.h: the multiplier that shows the meter's luminance at mid grey. */
static double ev0_exposure(void)
{
    return LR_EV_MID_GREY * LR_KM_LM_PER_W * 1e6 / (LR_METER_K_CD_M2 / 100.0);
}

double lr_ev_to_exposure(double ev100)
{
    return ev0_exposure() * exp2(-ev100);
}

double lr_exposure_to_ev(double exposure)
{
    return log2(ev0_exposure() / exposure);
}
