// GLSL port of render/optics/{fresnel,dirpole,dipole,multipole,model,sampling}.c (the C versions
// are the reference; tests/render/test_render_optics_glsl.c compares the two on a grid). Float instead
// of double: the guards that the C code needs for the double range are kept with float thresholds.

const float LR_PI = 3.14159265358979;

// Per-object material coefficients (lr_coeffs), band-wise in .x/.y/.z. de < 0 stands for
// de = +Inf (albedo' == 0: the virtual source is at infinity and contributes nothing).
struct lr_coeffs_gl {
    vec3 sigma_tr;
    vec3 D;
    vec3 de;
    vec3 sigma_t;
    vec3 mfp;
    float C_phi_norm;
    float C_phi;
    float C_E;
    float A_dir;
    float eta;
};

// lr_fresnel_reflectance (fresnel.c).
float lr_fresnel_reflectance(float cos_i, float eta)
{
    if (eta == 1.0)
        return 0.0;
    cos_i = clamp(cos_i, 0.0, 1.0);
    float sin_t2 = (1.0 - cos_i) * (1.0 + cos_i) / (eta * eta);
    if (sin_t2 >= 1.0)
        return 1.0;
    float cos_t = sqrt(1.0 - sin_t2);
    float rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    float rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

float lr_fresnel_transmittance(float cos_i, float eta)
{
    return 1.0 - lr_fresnel_reflectance(cos_i, eta);
}

// log(1 + x) and exp(x) - 1 without cancellation for small x (Goldberg 1991, Theorem 4;
// Kahan's expm1 trick): GLSL ES has neither.
float lr_log1p(float x)
{
    float u = 1.0 + x;
    return u == 1.0 ? x : log(u) * x / (u - 1.0);
}

float lr_expm1(float x)
{
    if (abs(x) < 1e-5)
        return x + 0.5 * x * x;
    float u = exp(x);
    if (u == 1.0)
        return x;
    float um1 = u - 1.0;
    return um1 == -1.0 ? -1.0 : um1 * x / log(u);
}

// lr_exp_radius_sample (sampling.c): seed 003 Eq. 11-12 truncated to [0, r_max].
float lr_exp_radius_sample(float sigma_tr, float r_max, float xi)
{
    float sr = sigma_tr * r_max;
    if (sr < 1e-30)
        return xi * r_max;
    float mass = -lr_expm1(-sr);
    float r = -lr_log1p(-xi * mass) / sigma_tr;
    return min(r, r_max);
}

// lr_exp_radius_pdf.
float lr_exp_radius_pdf(float sigma_tr, float r_max, float r)
{
    if (!(r >= 0.0 && r <= r_max))
        return 0.0;
    float sr = sigma_tr * r_max;
    if (sr < 1e-30)
        return 1.0 / r_max;
    return sigma_tr * exp(-sigma_tr * r) / -lr_expm1(-sr);
}

// [14] S'_d for one source (dirpole.c sp_d), band values passed in.
float lr_sp_d(lr_coeffs_gl c, float sigma_tr, float D, vec3 x, vec3 w, float r, vec3 n)
{
    float s = sigma_tr * r;
    // e^-87 is below the smallest normal float: the term is 0 there (C: 745 for double).
    if (!(s < 87.0))
        return 0.0;
    float inv_r = 1.0 / r;
    float one_s = 1.0 + s;
    float uw = dot(x, w) * inv_r;
    float un = dot(x, n) * inv_r;
    float wn = dot(w, n);
    float phi = 1.0 / D + 3.0 * one_s * uw * inv_r;
    float E = 3.0 * D * one_s * wn * inv_r * inv_r -
              (one_s * inv_r + 3.0 * D * (3.0 * one_s + s * s) * uw * inv_r * inv_r) * un;
    return c.C_phi_norm / (4.0 * LR_PI * LR_PI) * exp(-s) * inv_r * (c.C_phi * phi - c.C_E * E);
}

// lr_dirpole_sd for band j (0, 1, 2): S_d without Fresnel transmission, clamped >= 0.
float lr_dirpole_sd_band(lr_coeffs_gl c, int j, vec3 xi, vec3 ni, vec3 wi, vec3 xo, vec3 no)
{
    vec3 x = xo - xi;
    float r = length(x);
    vec3 nis = ni;
    if (r > 0.0) {
        vec3 xh = x / r;
        vec3 p = ni - xh * dot(ni, xh);
        float lp = length(p);
        if (lp > 1e-6)
            nis = p / lp;
    }
    float inv_eta = 1.0 / c.eta;
    float cos_i = dot(wi, ni);
    float sin_t2 = inv_eta * inv_eta * (1.0 - cos_i) * (1.0 + cos_i);
    float cos_t = sin_t2 < 1.0 ? sqrt(1.0 - sin_t2) : 0.0;
    vec3 wr = -inv_eta * wi + (inv_eta * cos_i - cos_t) * ni;
    float lwr = length(wr);
    wr = lwr > 0.0 ? wr / lwr : -ni;
    vec3 wv = wr - 2.0 * dot(wr, nis) * nis;
    float mu0 = -dot(no, wr);
    float x_perp_wr = length(cross(x, wr));

    float D = c.D[j], de = c.de[j], sigma_tr = c.sigma_tr[j];
    float floor_d = 1e-6 * c.mfp[j];
    float dr;
    if (mu0 > 0.0) {
        float q = de < 0.0 ? x_perp_wr : x_perp_wr / sqrt(1.0 + (r / de) * (r / de));
        dr = sqrt(D * mu0 * (D * mu0 + 2.0 * q) + r * r);
    } else {
        float z = 1.0 / (3.0 * c.sigma_t[j]);
        dr = sqrt(z * z + r * r);
    }
    dr = max(dr, floor_d);
    float real = lr_sp_d(c, sigma_tr, D, x, wr, dr, no);
    float virt = 0.0;
    if (de >= 0.0) {
        float zv = 2.0 * c.A_dir * de;
        vec3 xv = x - nis * zv;
        float dv = max(length(xv), floor_d);
        virt = lr_sp_d(c, sigma_tr, D, xv, wv, dv, no);
    }
    return max(real - virt, 0.0);
}

vec3 lr_dirpole_sd(lr_coeffs_gl c, vec3 xi, vec3 ni, vec3 wi, vec3 xo, vec3 no)
{
    return vec3(lr_dirpole_sd_band(c, 0, xi, ni, wi, xo, no),
                lr_dirpole_sd_band(c, 1, xi, ni, wi, xo, no),
                lr_dirpole_sd_band(c, 2, xi, ni, wi, xo, no));
}

// lr_dirpole_sd_fresnel: times F_t(w_i); 0 for light from behind.
vec3 lr_dirpole_sd_fresnel(lr_coeffs_gl c, vec3 xi, vec3 ni, vec3 wi, vec3 xo, vec3 no)
{
    float cos_i = dot(wi, ni);
    float t = cos_i > 0.0 ? lr_fresnel_transmittance(cos_i, c.eta) : 0.0;
    if (!(t > 0.0))
        return vec3(0.0);
    return t * lr_dirpole_sd(c, xi, ni, wi, xo, no);
}

// Standard dipole (render/optics/dipole.c): the coefficients lr_coeffs_gl lacks, per object,
// and the model switch (LR_MODEL_SD_BAND, generated from render/models/registry.c; the
// multipole with the slab's thickness and pole-pair count).
struct lr_sss_gl {
    int model;
    vec3 albedo_prime;
    vec3 z_r;
    vec3 z_v;
    float thickness;
    int pairs;
};

// dipole.c source_term: z (sigma_tr d + 1) e^{-sigma_tr d} / d^3, d = sqrt(r^2 + z^2).
float lr_dipole_source(float sigma_tr, float z, float r)
{
    float d = sqrt(r * r + z * z);
    float s = sigma_tr * d;
    if (!(s < 87.0)) // e^-87: below the smallest normal float (as lr_sp_d)
        return 0.0;
    return z * (s + 1.0) * exp(-s) / (d * d * d);
}

// lr_dipole_sd for band j: R_d(|x_o - x_i|) / pi (Jensen et al. 2001, Eq. 5 without F_t).
float lr_dipole_sd_band(lr_coeffs_gl c, lr_sss_gl s, int j, vec3 xi, vec3 xo)
{
    float r = length(xo - xi);
    float rd = s.albedo_prime[j] / (4.0 * LR_PI) *
               (lr_dipole_source(c.sigma_tr[j], s.z_r[j], r) +
                lr_dipole_source(c.sigma_tr[j], s.z_v[j], r));
    return rd / LR_PI;
}

// multipole.c pole(): the signed source term P(z) = z (sigma_tr s + 1) e^{-sigma_tr s} / s^3,
// s = sqrt(r^2 + z^2).
float lr_multipole_pole(float sigma_tr, float z, float r)
{
    float d = sqrt(r * r + z * z);
    float s = sigma_tr * d;
    if (!(s < 87.0) || !(d > 0.0))
        return 0.0;
    return z * (s + 1.0) * exp(-s) / (d * d * d);
}

// lr_multipole_sd for band j (render/optics/multipole.c, Donner & Jensen 2005): T(r_perp) / pi
// across the wall (n_i . n_o < 0), R(|x_o - x_i|) / pi on the same face; s.pairs pole pairs
// (lr_multipole_pairs, packed by lr_passes_pack_multipole).
float lr_multipole_sd_band(lr_coeffs_gl c, lr_sss_gl s, int j, vec3 xi, vec3 ni, vec3 xo,
                           vec3 no)
{
    vec3 x = xo - xi;
    float d = s.thickness, st = c.sigma_tr[j];
    float zb = 0.5 * (s.z_v[j] - s.z_r[j]);
    float l = min(s.z_r[j], 0.5 * d);
    float L = d + 2.0 * zb;
    // Across: sqrt(|x|^2 - d^2), the tangent-plane distance on a flat slab, ~|x| for the two
    // sides of a shade across its inside (multipole.c says why).
    bool across = dot(ni, no) < 0.0;
    float r = across ? sqrt(max(dot(x, x) - d * d, 0.0)) : length(x);
    float sum = 0.0;
    for (int i = -s.pairs; i <= s.pairs; i++) {
        float zr = 2.0 * float(i) * L + l, zv = 2.0 * float(i) * L - l - 2.0 * zb;
        if (across)
            sum += lr_multipole_pole(st, d - zr, r) - lr_multipole_pole(st, d - zv, r);
        else
            sum += lr_multipole_pole(st, zr, r) - lr_multipole_pole(st, zv, r);
    }
    return max(s.albedo_prime[j] / (4.0 * LR_PI) * sum, 0.0) / LR_PI;
}

// The model switch (lr_sss_sd_fresnel without the F_t(w_i) factor), band j.
float lr_sss_sd_band(lr_coeffs_gl c, lr_sss_gl s, int j, vec3 xi, vec3 ni, vec3 wi, vec3 xo,
                     vec3 no)
{
    // Each model's glsl_sd expression (render/models/*/); 0 for a model without a profile,
    // whose B radiosity.frag takes from LR_MODEL_B instead.
    return LR_MODEL_SD_BAND(c, s, j, xi, ni, wi, xo, no);
}
