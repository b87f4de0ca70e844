/* Reference scene: media, objects (medium boundaries, receivers, area-light surfaces), lights. */
#include "render/reference/ref_priv.h"

#include "render/optics/optics.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void copy_name(char dst[LR_REF_NAME_MAX], const char *src, const char *fallback, int i)
{
    if (src && *src)
        snprintf(dst, LR_REF_NAME_MAX, "%s", src);
    else
        snprintf(dst, LR_REF_NAME_MAX, "%s %d", fallback, i);
}

/* Grows *arr (of *cap elements of size sz) to hold n + 1. */
static int grow(void **arr, int *cap, int n, size_t sz, lr_err *e)
{
    if (n < *cap)
        return LR_OK;
    int nc = *cap ? *cap * 2 : 8;
    void *p = realloc(*arr, (size_t)nc * sz);
    if (!p)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory growing the scene");
    *arr = p;
    *cap = nc;
    return LR_OK;
}

int lr_ref_scene_create(const lr_ref_scene_desc *desc, lr_ref_scene **out, lr_err *e)
{
    *out = NULL;
    double eta = desc && desc->ambient_eta != 0.0 ? desc->ambient_eta : 1.0;
    if (!isfinite(eta) || eta <= 0.0)
        return lr_err_set(e, LR_EINVAL, "reference: ambient_eta %g: must be finite and > 0", eta);
    lr_ref_scene *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory for a scene");
    lr_ref_hash_init(&s->hash);
    lr_ref_hash_str(&s->hash, "scene");
    lr_ref_hash_double(&s->hash, eta);
    int id;
    lr_ref_medium_desc ambient = {.eta = eta, .name = "ambient"};
    int rc = lr_ref_scene_add_medium(s, &ambient, &id, e);
    if (rc) {
        lr_ref_scene_destroy(s);
        return rc;
    }
    *out = s;
    return LR_OK;
}

void lr_ref_scene_destroy(lr_ref_scene *s)
{
    if (!s)
        return;
    for (int i = 0; i < s->n_objects; i++)
        lr_ref_shape_destroy(s->objects[i].shape);
    free(s->objects);
    free(s->media);
    for (int i = 0; i < s->n_lights; i++) {
        free(s->lights[i].profile);
        free(s->lights[i].sampler);
    }
    free(s->lights);
    free(s->light_pick);
    free(s->delta_pick);
    free(s);
}

static int not_finished(const lr_ref_scene *s, const char *what, lr_err *e)
{
    if (s->finished)
        return lr_err_set(e, LR_EINVAL, "reference: %s after lr_ref_scene_finish", what);
    return LR_OK;
}

void lr_ref_medium_from_optics(const lr_medium *m, lr_ref_medium_desc *out)
{
    *out = (lr_ref_medium_desc){.g = m->g, .eta = m->eta};
    for (int b = 0; b < 3; b++) {
        out->sigma_a[b] = m->sigma_a[b];
        /* Similarity relation sigma_s' = sigma_s (1 - g) (render/optics/optics.h). */
        out->sigma_s[b] = m->sigma_s_prime[b] / (1.0 - m->g);
    }
}

int lr_ref_scene_add_medium(lr_ref_scene *s, const lr_ref_medium_desc *m, int *id, lr_err *e)
{
    int rc = not_finished(s, "add_medium", e);
    if (rc)
        return rc;
    lr_ref_medium md = {0};
    copy_name(md.name, m->name, "medium", s->n_media);
    md.eta = m->eta != 0.0 ? m->eta : 1.0;
    md.g = m->g;
    if (!isfinite(md.eta) || md.eta <= 0.0)
        return lr_err_set(e, LR_EINVAL, "reference: medium '%s': eta %g must be finite and > 0",
                          md.name, md.eta);
    if (!isfinite(md.g) || md.g <= -1.0 || md.g >= 1.0)
        return lr_err_set(e, LR_EINVAL, "reference: medium '%s': g %g must be in (-1, 1)",
                          md.name, md.g);
    for (int b = 0; b < 3; b++) {
        md.sigma_a[b] = m->sigma_a[b];
        md.sigma_s[b] = m->sigma_s[b];
        if (!isfinite(md.sigma_a[b]) || md.sigma_a[b] < 0.0 || !isfinite(md.sigma_s[b]) ||
            md.sigma_s[b] < 0.0)
            return lr_err_set(e, LR_EINVAL,
                              "reference: medium '%s': sigma_a[%d] = %g, sigma_s[%d] = %g: "
                              "must be finite and >= 0", md.name, b, md.sigma_a[b], b,
                              md.sigma_s[b]);
        md.sigma_t[b] = md.sigma_a[b] + md.sigma_s[b];
        md.albedo[b] = md.sigma_t[b] > 0.0 ? md.sigma_s[b] / md.sigma_t[b] : 0.0;
    }
    if ((rc = grow((void **)&s->media, &s->cap_media, s->n_media, sizeof md, e)))
        return rc;
    lr_ref_hash_str(&s->hash, "medium");
    for (int b = 0; b < 3; b++) {
        lr_ref_hash_double(&s->hash, md.sigma_a[b]);
        lr_ref_hash_double(&s->hash, md.sigma_s[b]);
    }
    lr_ref_hash_double(&s->hash, md.g);
    lr_ref_hash_double(&s->hash, md.eta);
    s->media[s->n_media] = md;
    *id = s->n_media++;
    return LR_OK;
}

/* Appends an object; takes ownership of shape (destroyed on failure). */
static int push_object(lr_ref_scene *s, const lr_ref_object *o, lr_err *e)
{
    int rc = grow((void **)&s->objects, &s->cap_objects, s->n_objects, sizeof *o, e);
    if (rc) {
        lr_ref_shape_destroy(o->shape);
        return rc;
    }
    s->objects[s->n_objects++] = *o;
    return LR_OK;
}

int lr_ref_scene_add_object(lr_ref_scene *s, const lr_ref_object_desc *d, lr_err *e)
{
    lr_ref_object o = {.shape = d->shape, .light = -1};
    copy_name(o.name, d->name, "object", s->n_objects);
    int rc = not_finished(s, "add_object", e);
    if (!rc && !d->shape)
        rc = lr_err_set(e, LR_EINVAL, "reference: object '%s' has no shape", o.name);
    if (!rc && d->kind == LR_REF_BOUNDARY) {
        o.kind = LR_REF_SURF_BOUNDARY;
        o.inside = d->inside;
        o.outside = d->outside;
        if (!d->shape->ops->closed)
            rc = lr_err_set(e, LR_EINVAL,
                            "reference: object '%s': a %s is not closed and cannot bound a "
                            "medium", o.name, d->shape->ops->name);
        else if (o.inside < 0 || o.inside >= s->n_media || o.outside < 0 ||
                 o.outside >= s->n_media)
            rc = lr_err_set(e, LR_EINVAL,
                            "reference: object '%s': medium ids %d (inside), %d (outside): "
                            "must be in 0..%d", o.name, o.inside, o.outside, s->n_media - 1);
        else if (o.inside == o.outside)
            rc = lr_err_set(e, LR_EINVAL,
                            "reference: object '%s': inside and outside are the same medium",
                            o.name);
    } else if (!rc && d->kind == LR_REF_RECEIVER) {
        o.kind = LR_REF_SURF_RECEIVER;
        for (int b = 0; b < 3 && !rc; b++) {
            o.albedo[b] = d->albedo[b];
            if (!(o.albedo[b] >= 0.0 && o.albedo[b] <= 1.0))
                rc = lr_err_set(e, LR_EINVAL,
                                "reference: receiver '%s': albedo[%d] = %g must be in [0, 1]",
                                o.name, b, o.albedo[b]);
        }
    } else if (!rc) {
        rc = lr_err_set(e, LR_EINVAL, "reference: object '%s': unknown kind %d", o.name,
                        (int)d->kind);
    }
    if (rc) {
        lr_ref_shape_destroy(d->shape);
        return rc;
    }
    lr_ref_hash_str(&s->hash, o.kind == LR_REF_SURF_BOUNDARY ? "boundary" : "receiver");
    d->shape->ops->hash(d->shape->self, &s->hash);
    lr_ref_hash_u64(&s->hash, (uint64_t)o.inside);
    lr_ref_hash_u64(&s->hash, (uint64_t)o.outside);
    for (int b = 0; b < 3; b++)
        lr_ref_hash_double(&s->hash, o.albedo[b]);
    return push_object(s, &o, e);
}

static double smoothstep_power_factor(double cos_inner, double cos_outer)
{
    /* Solid-angle integral of the cone profile: 2 pi [(1 - ci) + (ci - co) / 2], the
     * smoothstep ramp integrating to one half of its width in cos theta. */
    return 2.0 * LR_REF_PI * ((1.0 - cos_inner) + 0.5 * (cos_inner - cos_outer));
}

int lr_ref_scene_add_light(lr_ref_scene *s, const lr_ref_light_desc *d, lr_err *e)
{
    int rc = not_finished(s, "add_light", e);
    if (rc)
        return rc;
    int idx = s->n_lights;
    lr_ref_light l = {.d = *d, .object = -1};
    for (int b = 0; b < 3; b++)
        if (!isfinite(d->emission[b]) || d->emission[b] < 0.0)
            return lr_err_set(e, LR_EINVAL, "reference: light %d: emission[%d] = %g must be "
                              "finite and >= 0", idx, b, d->emission[b]);
    if (!lr_v3_isfinite(d->position))
        return lr_err_set(e, LR_EINVAL, "reference: light %d: position is not finite", idx);
    lr_ref_shape *shape = NULL;
    double factor = 0.0; /* power = factor * emission */
    switch (d->kind) {
    case LR_REF_LIGHT_POINT:
        factor = 4.0 * LR_REF_PI;
        break;
    case LR_REF_LIGHT_SPOT: {
        double outer = d->outer_deg != 0.0 ? d->outer_deg : 30.0;
        double inner = d->inner_deg != 0.0 ? d->inner_deg : outer;
        if (!(lr_v3_len(d->direction) > 0.0) || !lr_v3_isfinite(d->direction))
            return lr_err_set(e, LR_EINVAL, "reference: spot light %d: direction must be "
                              "finite and non-zero", idx);
        if (!(outer > 0.0 && outer <= 180.0 && inner > 0.0 && inner <= outer))
            return lr_err_set(e, LR_EINVAL, "reference: spot light %d: need 0 < inner_deg "
                              "(%g) <= outer_deg (%g) <= 180", idx, inner, outer);
        l.normal = lr_v3_normalize(d->direction);
        l.cos_inner = cos(inner * LR_REF_PI / 180.0);
        l.cos_outer = cos(outer * LR_REF_PI / 180.0);
        l.d.inner_deg = inner;
        l.d.outer_deg = outer;
        factor = smoothstep_power_factor(l.cos_inner, l.cos_outer);
        break;
    }
    case LR_REF_LIGHT_QUAD:
        rc = lr_ref_quad_create(d->position, d->edge1, d->edge2, &shape, e);
        if (rc)
            return rc;
        l.normal = lr_v3_normalize(lr_v3_cross(d->edge1, d->edge2));
        l.area = lr_v3_len(lr_v3_cross(d->edge1, d->edge2));
        factor = LR_REF_PI * l.area;
        break;
    case LR_REF_LIGHT_DISK:
        rc = lr_ref_disk_create(d->position, d->direction, d->radius, &shape, e);
        if (rc)
            return rc;
        l.normal = lr_v3_normalize(d->direction);
        lr_ref_frame(l.normal, &l.t1, &l.t2);
        l.area = LR_REF_PI * d->radius * d->radius;
        factor = LR_REF_PI * l.area;
        break;
    default:
        return lr_err_set(e, LR_EINVAL, "reference: light %d: unknown kind %d", idx,
                          (int)d->kind);
    }
    if (d->profile && d->profile->on) {
        /* The profile's flux in place of the uniform or Lambertian one (profile.h omega). */
        bool area = d->kind == LR_REF_LIGHT_QUAD || d->kind == LR_REF_LIGHT_DISK;
        l.profile = malloc(sizeof *l.profile);
        l.sampler = malloc(sizeof *l.sampler);
        lr_err inner = {0};
        if (!l.profile || !l.sampler) {
            rc = lr_err_set(e, LR_ENOMEM, "reference: light %d: out of memory", idx);
        } else {
            *l.profile = *d->profile;
            rc = lr_profile_sampler_init(l.profile, area, l.sampler, &inner);
            if (rc)
                lr_err_set(e, rc, "reference: light %d: %s", idx, inner.msg);
        }
        if (rc) {
            free(l.profile);
            free(l.sampler);
            lr_ref_shape_destroy(shape);
            return rc;
        }
        factor = d->kind == LR_REF_LIGHT_POINT ? l.profile->omega
               : d->kind == LR_REF_LIGHT_SPOT
                   ? lr_light_profile_cone_omega(l.profile, l.d.inner_deg, l.d.outer_deg)
                   : l.profile->omega_down * l.area;
        l.d.profile = NULL; /* l.profile is the copy */
    }
    for (int b = 0; b < 3; b++)
        l.power[b] = factor * d->emission[b];
    if ((rc = grow((void **)&s->lights, &s->cap_lights, s->n_lights, sizeof l, e))) {
        free(l.profile);
        free(l.sampler);
        lr_ref_shape_destroy(shape);
        return rc;
    }
    if (shape) {
        lr_ref_object o = {.kind = LR_REF_SURF_LIGHT, .shape = shape, .light = idx};
        copy_name(o.name, NULL, "light", idx);
        if ((rc = push_object(s, &o, e))) {
            free(l.profile);
            free(l.sampler);
            return rc;
        }
        l.object = s->n_objects - 1;
    }
    lr_ref_hash_str(&s->hash, "light");
    lr_ref_hash_u64(&s->hash, (uint64_t)d->kind);
    lr_ref_hash_vec3(&s->hash, d->position);
    lr_ref_hash_vec3(&s->hash, d->direction);
    lr_ref_hash_vec3(&s->hash, d->edge1);
    lr_ref_hash_vec3(&s->hash, d->edge2);
    lr_ref_hash_double(&s->hash, d->radius);
    lr_ref_hash_double(&s->hash, l.d.inner_deg);
    lr_ref_hash_double(&s->hash, l.d.outer_deg);
    for (int b = 0; b < 3; b++)
        lr_ref_hash_double(&s->hash, d->emission[b]);
    if (l.profile) {
        lr_ref_hash_u64(&s->hash, l.profile->hash);
        lr_ref_hash_vec3(&s->hash, d->prof_x);
        lr_ref_hash_vec3(&s->hash, d->prof_y);
        lr_ref_hash_vec3(&s->hash, d->prof_z);
    }
    s->lights[s->n_lights++] = l;
    return LR_OK;
}

int lr_ref_scene_finish(lr_ref_scene *s, lr_err *e)
{
    int rc = not_finished(s, "finish", e);
    if (rc)
        return rc;
    /* Colour band groups: bands with identical coefficients in every medium take the same
     * random walk, so one path serves all of them. */
    s->n_groups = 0;
    for (int b = 0; b < 3; b++) {
        int g = 0;
        for (; g < s->n_groups; g++) {
            int h = s->group_hero[g];
            bool same = true;
            for (int m = 0; m < s->n_media && same; m++)
                same = s->media[m].sigma_a[b] == s->media[m].sigma_a[h] &&
                       s->media[m].sigma_s[b] == s->media[m].sigma_s[h];
            if (same)
                break;
        }
        if (g == s->n_groups) {
            s->group_hero[g] = b;
            s->group_mask[g] = 0;
            s->n_groups++;
        }
        s->group_mask[g] |= 1 << b;
    }
    /* The ambient medium is unbounded: scattering in it would never end. */
    for (int b = 0; b < 3; b++)
        if (s->media[0].sigma_t[b] != 0.0)
            return lr_err_set(e, LR_EINVAL, "reference: the ambient medium must not scatter "
                              "or absorb");
    double total = 0.0, delta = 0.0;
    for (int i = 0; i < s->n_lights; i++) {
        lr_ref_light *l = &s->lights[i];
        lr_vec3 p = l->d.position;
        if (l->d.kind == LR_REF_LIGHT_QUAD)
            p = lr_v3_add(p, lr_v3_scale(lr_v3_add(l->d.edge1, l->d.edge2), 0.5));
        if (l->object >= 0) /* area light: the medium it emits into, just in front */
            p = lr_v3_add(p, lr_v3_scale(l->normal, 1e3 * lr_ref_eps(p)));
        l->medium = lr_ref_scene_medium_at(s, p);
        double pw = l->power[0] + l->power[1] + l->power[2];
        total += pw;
        if (l->object < 0)
            delta += pw;
    }
    size_t n = (size_t)(s->n_lights ? s->n_lights : 1);
    s->light_pick = calloc(n, sizeof *s->light_pick);
    s->delta_pick = calloc(n, sizeof *s->delta_pick);
    if (!s->light_pick || !s->delta_pick)
        return lr_err_set(e, LR_ENOMEM, "reference: out of memory");
    for (int i = 0; i < s->n_lights; i++) {
        const double *pw = s->lights[i].power;
        double p = pw[0] + pw[1] + pw[2];
        s->light_pick[i] = total > 0.0 ? p / total : 0.0;
        s->delta_pick[i] = delta > 0.0 && s->lights[i].object < 0 ? p / delta : 0.0;
    }
    s->finished = true;
    return LR_OK;
}

uint64_t lr_ref_scene_hash(const lr_ref_scene *s)
{
    return s->hash.h;
}

bool lr_ref_scene_intersect(const lr_ref_scene *s, lr_vec3 o, lr_vec3 d, double tmin,
                            double tmax, lr_ref_surf *out)
{
    bool found = false;
    lr_ref_hit h;
    for (int i = 0; i < s->n_objects; i++) {
        const lr_ref_shape *sh = s->objects[i].shape;
        if (sh->ops->intersect(sh->self, o, d, tmin, tmax, &h)) {
            tmax = h.t;
            out->t = h.t;
            out->n = h.n;
            out->object = i;
            found = true;
        }
    }
    if (found)
        out->p = lr_v3_add(o, lr_v3_scale(d, out->t));
    return found;
}

int lr_ref_scene_medium_at(const lr_ref_scene *s, lr_vec3 p)
{
    /* A direction unlikely to graze anything axis-aligned; only boundaries count. */
    lr_vec3 d = lr_v3_normalize(lr_v3(0.5773502691896258, 0.5672612419124244,
                                      0.5870201381137884));
    double best = INFINITY;
    int medium = 0;
    lr_ref_hit h;
    for (int i = 0; i < s->n_objects; i++) {
        const lr_ref_object *ob = &s->objects[i];
        if (ob->kind != LR_REF_SURF_BOUNDARY)
            continue;
        if (ob->shape->ops->intersect(ob->shape->self, p, d, 0.0, best, &h)) {
            best = h.t;
            medium = lr_v3_dot(d, h.n) < 0.0 ? ob->outside : ob->inside;
        }
    }
    return medium;
}

void lr_ref_stats_add(lr_ref_stats *into, const lr_ref_stats *from)
{
    into->paths += from->paths;
    into->photons += from->photons;
    into->events += from->events;
    into->nee += from->nee;
    into->nee_refracted += from->nee_refracted;
    into->nee_unsolved += from->nee_unsolved;
    into->truncated += from->truncated;
    into->medium_mismatch += from->medium_mismatch;
    into->nonfinite += from->nonfinite;
}
