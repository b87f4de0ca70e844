/* Light shape and flicker: the parts of a light that are not its intensity. */
#include <math.h>

#include "render/photometry/photometry.h"
#include "render/scene/scene.h"

void lr_light_rgb(const lr_light *l, double out[3])
{
    for (int b = 0; b < 3; b++)
        out[b] = l->intensity * l->color[b];
}

double lr_light_lm_per_unit(const lr_light *l)
{
    double kv = LR_KM_LM_PER_W * lr_rgb_luminance(l->color), omega = 0.0;
    switch (l->type) {
    case LR_LIGHT_POINT: omega = l->profile.on ? l->profile.omega : 4.0 * M_PI; break;
    case LR_LIGHT_SPOT: {
        if (l->profile.on) {
            omega = lr_light_profile_cone_omega(&l->profile, l->inner_deg, l->outer_deg);
            break;
        }
        /* The flux of I shape(cos) over the sphere: 2 pi times the integral over cos of the
         * shape, 1 on [cos inner, 1], smoothstep between cos outer and cos inner (mean 1/2). */
        double ci = cos(l->inner_deg * (M_PI / 180.0)), co = cos(l->outer_deg * (M_PI / 180.0));
        omega = 2.0 * M_PI * ((1.0 - ci) + 0.5 * (ci - co));
        break;
    }
    case LR_LIGHT_QUAD:
    case LR_LIGHT_DISK:
        /* A Lambertian emitter of radiance L sends pi L per unit area and side. */
        omega = (l->profile.on ? l->profile.omega_down : M_PI) * lr_light_area(l) *
                (l->two_sided ? 2.0 : 1.0);
        break;
    case LR_LIGHT_DIRECTIONAL: omega = 0.0; break;
    }
    return kv * omega;
}

int lr_light_resolve_units(lr_light *l, const char **field, lr_err *e)
{
    if (l->color_temperature_k > 0.0)
        lr_cct_color(l->color_temperature_k, l->color);
    double kv = LR_KM_LM_PER_W * lr_rgb_luminance(l->color);
    double per = lr_light_lm_per_unit(l);
    if (l->from != LR_STRENGTH_RADIOMETRIC && !(kv > 0.0)) {
        *field = l->from == LR_STRENGTH_CD ? "intensity_cd" : "flux_lm";
        return lr_err_set(e, LR_EINVAL, "needs a colour with a luminous part (Y > 0), got color "
                          "%g, %g, %g", l->color[0], l->color[1], l->color[2]);
    }
    if (l->from == LR_STRENGTH_CD)
        l->intensity = l->intensity_cd / kv;
    else if (l->from == LR_STRENGTH_LM)
        l->intensity = per > 0.0 ? l->flux_lm / per : 0.0;
    if (l->type == LR_LIGHT_POINT || l->type == LR_LIGHT_SPOT)
        l->intensity_cd = kv * l->intensity;
    else
        l->intensity_cd = 0.0;
    l->flux_lm = per * l->intensity;
    return LR_OK;
}

lr_vec3 lr_light_area_normal(const lr_light *l)
{
    if (l->type == LR_LIGHT_QUAD)
        return lr_v3_normalize(lr_v3_cross(l->edge_u, l->edge_v));
    return lr_v3_normalize(l->direction);
}

double lr_light_area(const lr_light *l)
{
    if (l->type == LR_LIGHT_QUAD)
        return 4.0 * lr_v3_len(lr_v3_cross(l->edge_u, l->edge_v));
    if (l->type == LR_LIGHT_DISK)
        return M_PI * l->radius * l->radius;
    return 0.0;
}

void lr_light_profile_axes(const lr_light *l, lr_vec3 *x, lr_vec3 *y, lr_vec3 *z)
{
    lr_vec3 n = lr_light_is_area(l) ? lr_light_area_normal(l) : lr_v3_normalize(l->direction);
    lr_vec3 hint = l->profile_c0;
    if (!(lr_v3_len(hint) > 0.0))
        hint = l->type == LR_LIGHT_QUAD ? l->edge_u : lr_v3(1.0, 0.0, 0.0);
    lr_light_profile_frame(n, hint, x, y, z);
}

/* rel of the light's profile along world direction dir. */
static double profile_rel(const lr_light *l, lr_vec3 dir)
{
    lr_vec3 x, y, z;
    lr_light_profile_axes(l, &x, &y, &z);
    return lr_light_profile_eval(&l->profile,
                                 lr_v3(lr_v3_dot(dir, x), lr_v3_dot(dir, y), lr_v3_dot(dir, z)));
}

static double spot_cone(const lr_light *l, lr_vec3 dir)
{
    double c = lr_v3_dot(dir, l->direction);
    double ci = cos(l->inner_deg * (M_PI / 180.0)), co = cos(l->outer_deg * (M_PI / 180.0));
    if (c >= ci)
        return 1.0;
    if (c <= co)
        return 0.0;
    double t = (c - co) / (ci - co);
    return t * t * (3.0 - 2.0 * t);
}

double lr_light_shape(const lr_light *l, lr_vec3 dir)
{
    if (lr_light_is_area(l)) {
        /* The whole emitter as a point (render/area/emitter.h): I = L_e A cos(theta_e), or
         * L_e A rel(w) with a profile (the file's distribution in place of Lambert's). */
        lr_vec3 n = lr_light_area_normal(l);
        double c = lr_v3_dot(dir, n);
        if (l->profile.on) {
            if (c < 0.0 && l->two_sided) /* the back face: the front's pattern mirrored */
                dir = lr_v3_sub(dir, lr_v3_scale(n, 2.0 * c)), c = -c;
            return c > 0.0 ? lr_light_area(l) * profile_rel(l, dir) : 0.0;
        }
        if (l->two_sided)
            c = fabs(c);
        return c > 0.0 ? lr_light_area(l) * c : 0.0;
    }
    if (l->type == LR_LIGHT_DIRECTIONAL)
        return 1.0;
    double s = l->type == LR_LIGHT_SPOT ? spot_cone(l, dir) : 1.0;
    return l->profile.on && s > 0.0 ? s * profile_rel(l, dir) : s;
}

void lr_light_geometry_key(const lr_light *l, double k[LR_LIGHT_KEY_N])
{
    /* The table's hash in 48 bits (exact in a double) and the C0 hint as given: with the
     * fields above they fix the profile's frame (lr_light_profile_axes). */
    bool on = l->profile.on;
    double ph = on ? (double)(l->profile.hash >> 16) + 1.0 : 0.0;
    lr_vec3 c0 = on ? l->profile_c0 : lr_v3(0, 0, 0);
    double v[LR_LIGHT_KEY_N] = {l->type,      l->position.x,  l->position.y,  l->position.z,
                                l->direction.x, l->direction.y, l->direction.z, l->edge_u.x,
                                l->edge_u.y,  l->edge_u.z,    l->edge_v.x,    l->edge_v.y,
                                l->edge_v.z,  l->radius,      l->two_sided,   l->inner_deg,
                                l->outer_deg, ph,             c0.x,           c0.y,
                                c0.z};
    for (int i = 0; i < LR_LIGHT_KEY_N; i++)
        k[i] = v[i];
}

/* A phase in [0, 2 pi) from the seed and a channel number (splitmix64 finaliser). */
static double phase(unsigned seed, unsigned k)
{
    unsigned long long z = (unsigned long long)seed * 0x9E3779B97F4A7C15ull + k * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (2.0 * M_PI / 9007199254740992.0);
}

/* Sum of three sines at f, 1.618 f, 2.718 f (never in step), normalised to [-1, 1]. */
static double wobble(const lr_flicker *f, double t, unsigned channel)
{
    static const double mult[3] = {1.0, 1.6180339887, 2.7182818285};
    static const double weight[3] = {0.5, 0.3, 0.2};
    double s = 0.0;
    for (unsigned i = 0; i < 3; i++)
        s += weight[i] * sin(2.0 * M_PI * f->frequency_hz * mult[i] * t +
                             phase(f->seed, 3 * channel + i));
    return s;
}

bool lr_light_flickers(const lr_light *l)
{
    return l->flicker.amplitude > 0.0 && l->intensity > 0.0;
}

void lr_light_flicker_at(const lr_light *l, double t, double *scale, lr_vec3 *offset)
{
    const lr_flicker *f = &l->flicker;
    if (scale) {
        double s = 1.0 + f->amplitude * wobble(f, t, 0);
        *scale = s > 0.0 ? s : 0.0;
    }
    if (offset) {
        /* A flame sways sideways more than it bobs: the vertical channel at a third. */
        *offset = lr_v3(f->jitter_mm * wobble(f, t, 1), f->jitter_mm * wobble(f, t, 2),
                        f->jitter_mm * wobble(f, t, 3) / 3.0);
    }
}
