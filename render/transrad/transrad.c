/* lamprig — translucent radiosity: create (patches, F, S), destroy, geometry queries. */
#include "render/transrad/tr_priv.h"

#include <math.h>
#include <stdlib.h>

#include "render/optics/optics.h"

void lr_tr_rows_free(lr_tr_rows *r)
{
    free(r->row);
    free(r->col);
    free(r->val);
    *r = (lr_tr_rows){0};
}

static int check_surface(const lr_tr_surface_desc *d, int s, lr_err *e)
{
    if (!d->mesh || !d->bvh)
        return lr_err_set(e, LR_EINVAL, "transrad: surface %d: field 'mesh': none given", s);
    if (d->kind != LR_TR_TRANSLUCENT && d->kind != LR_TR_DIFFUSE && d->kind != LR_TR_PLANE)
        return lr_err_set(e, LR_EINVAL, "transrad: surface %d: field 'kind': %d unknown", s,
                          (int)d->kind);
    if (d->kind == LR_TR_TRANSLUCENT) {
        if (!d->coeffs)
            return lr_err_set(e, LR_EINVAL, "transrad: surface %d: field 'coeffs': none given",
                              s);
        if (lr_sss_model_props_of(d->model)->needs_thickness && !(d->thickness_mm > 0))
            return lr_err_set(e, LR_EINVAL,
                              "transrad: surface %d: field 'thickness_mm': the %s "
                              "needs the wall's thickness", s, lr_sss_model_name(d->model));
    } else {
        for (int b = 0; b < 3; b++)
            if (!(d->albedo[b] >= 0 && d->albedo[b] <= 1))
                return lr_err_set(e, LR_EINVAL,
                                  "transrad: surface %d: field 'albedo': band %d is %g, not in "
                                  "[0, 1]", s, b, d->albedo[b]);
    }
    if (!(d->patch_mm >= 0) || !isfinite(d->patch_mm))
        return lr_err_set(e, LR_EINVAL, "transrad: surface %d: field 'patch_mm': %g", s,
                          d->patch_mm);
    return LR_OK;
}

int lr_tr_create(const lr_tr_surface_desc *surfaces, int count, const lr_tr_settings *settings,
                 lr_tr **out, lr_err *e)
{
    *out = NULL;
    if (!surfaces || count < 1 || count > LR_TR_MAX_SURFACES)
        return lr_err_set(e, LR_EINVAL, "transrad: field 'surfaces': %d given, 1..%d accepted",
                          count, LR_TR_MAX_SURFACES);
    lr_tr_settings s = settings ? *settings : (lr_tr_settings){0};
    if (!(s.patch_mm >= 0) || !(s.receiver_mm >= 0) || !(s.tolerance >= 0) ||
        s.rays_per_patch < 0 || s.direct_samples < 0 || s.max_iterations < 0 ||
        !isfinite(s.patch_mm) || !isfinite(s.receiver_mm) || !isfinite(s.tolerance))
        return lr_err_set(e, LR_EINVAL, "transrad: field 'settings': negative or not finite");
    if (s.area_samples < 0 || s.area_samples > 256)
        return lr_err_set(e, LR_EINVAL, "transrad: field 'area_samples': %d outside [0, 256]",
                          s.area_samples);
    if (s.thin_wall < LR_TR_THIN_AUTO || s.thin_wall > LR_TR_THIN_ON)
        return lr_err_set(e, LR_EINVAL, "transrad: field 'thin_wall': %d, not auto (0), off (1) "
                          "or on (2)", s.thin_wall);
    if (s.patch_mm == 0)
        s.patch_mm = 12;
    if (s.receiver_mm == 0)
        s.receiver_mm = 30;
    if (s.rays_per_patch == 0)
        s.rays_per_patch = 512;
    if (s.direct_samples == 0)
        s.direct_samples = 16;
    if (s.area_samples == 0)
        s.area_samples = 16;
    if (s.max_iterations == 0)
        s.max_iterations = 50;
    if (s.tolerance == 0)
        s.tolerance = 1e-4;
    for (int i = 0; i < count; i++) {
        int rc = check_surface(&surfaces[i], i, e);
        if (rc)
            return rc;
    }
    lr_tr *t = calloc(1, sizeof *t);
    if (!t)
        return lr_err_set(e, LR_ENOMEM, "transrad: out of memory");
    t->set = s;
    t->nsurf = count;
    int rc = LR_OK;
    for (int i = 0; i < count; i++) {
        t->surf[i].d = surfaces[i];
        if (surfaces[i].kind == LR_TR_TRANSLUCENT)
            t->surf[i].t_hem = lr_hemi_transmittance(surfaces[i].coeffs->eta);
        if (surfaces[i].kind != LR_TR_PLANE && (rc = lr_tr_refine(t, i, e)))
            goto fail;
    }
    if ((rc = lr_tr_build_patches(t, e)) || (rc = lr_tr_build_cover(t, e)))
        goto fail;
    t->Edir = calloc(3 * (t->n ? t->n : 1), sizeof *t->Edir);
    t->Ein = calloc(3 * (t->n ? t->n : 1), sizeof *t->Ein);
    if (!t->Edir || !t->Ein) {
        rc = lr_err_set(e, LR_ENOMEM, "transrad: out of memory");
        goto fail;
    }
    uint64_t key = s.cache_dir ? lr_tr_cache_key(t) : 0;
    t->cache_hit = s.cache_dir && lr_tr_cache_load(t, key, s.cache_dir);
    if (!t->cache_hit) {
        if ((rc = lr_tr_build_form_factors(t, e)) || (rc = lr_tr_build_subsurface(t, e)))
            goto fail;
        /* Best effort: a folder that cannot be written costs the next start a rebuild, which
         * is said (once per folder: the same folder fails the same way at every rebuild). */
        lr_err ce = {0};
        if (s.cache_dir && lr_tr_cache_store(t, key, s.cache_dir, &ce) &&
            lr_warn_once_first(s.warned, s.cache_dir))
            lr_warn(&s.warn, "cache not stored: %s (F and S of %zu patches are rebuilt at every "
                    "start until the folder is writable)", ce.msg, t->n);
    }
    t->set.cache_dir = NULL; /* the caller's string: not kept */
    if ((rc = lr_tr_transfer_build(t, e)))
        goto fail;
    *out = t;
    return LR_OK;
fail:
    lr_tr_destroy(t);
    return rc;
}

void lr_tr_set_cancel(lr_tr *t, const lr_cancel *cancel)
{
    if (t)
        t->set.cancel = cancel;
}

void lr_tr_destroy(lr_tr *t)
{
    if (!t)
        return;
    for (int i = 0; i < t->nsurf; i++) {
        free(t->surf[i].tri_patch);
        lr_bvh_destroy(t->surf[i].own_bvh);
        lr_mesh_destroy(t->surf[i].own_mesh);
    }
    for (int i = 0; i < LR_TR_MAX_SLOTS; i++) {
        free(t->slot[i].W);
        free(t->slot[i].Wsss);
        free(t->slot[i].H);
        free(t->slot[i].Hind);
    }
    lr_tr_transfer_free(&t->X);
    lr_tr_rows_free(&t->F);
    lr_tr_rows_free(&t->S);
    free(t->escape);
    free(t->cover_check);
    free(t->open);
    free(t->Edir);
    free(t->Ein);
    free(t->tris);
    free(t->p);
    free(t);
}

int lr_tr_set_albedo(lr_tr *t, int s, const double albedo[3], lr_err *e)
{
    if (!t || !albedo || s < 0 || s >= t->nsurf)
        return lr_err_set(e, LR_EINVAL, "transrad: set albedo: %s",
                          !t || !albedo ? "NULL argument" : "no such surface");
    lr_tr_surf *sf = &t->surf[s];
    if (sf->d.kind == LR_TR_TRANSLUCENT)
        return lr_err_set(e, LR_EINVAL, "transrad: surface %d: field 'albedo': a translucent "
                          "surface's S comes from its profile", s);
    if (t->X.built)
        return lr_err_set(e, LR_EINVAL, "transrad: surface %d: field 'albedo': the precomputed "
                          "transfer holds the old one", s);
    for (int b = 0; b < 3; b++)
        if (!(albedo[b] >= 0 && albedo[b] <= 1))
            return lr_err_set(e, LR_EINVAL, "transrad: surface %d: field 'albedo': %g outside "
                              "[0, 1]", s, albedo[b]);
    for (int b = 0; b < 3; b++)
        sf->d.albedo[b] = albedo[b];
    return LR_OK;
}

size_t lr_tr_patch_count(const lr_tr *t) { return t ? t->n : 0; }

bool lr_tr_cache_hit(const lr_tr *t) { return t && t->cache_hit; }

void lr_tr_surface_patches(const lr_tr *t, int s, size_t *first, size_t *count)
{
    bool ok = t && s >= 0 && s < t->nsurf;
    *first = ok ? t->surf[s].first : 0;
    *count = ok ? t->surf[s].count : 0;
}

void lr_tr_patch_geometry(const lr_tr *t, size_t p, lr_vec3 *centroid, lr_vec3 *normal,
                          double *area)
{
    if (p >= t->n)
        return;
    if (centroid)
        *centroid = t->p[p].c;
    if (normal)
        *normal = t->p[p].n;
    if (area)
        *area = t->p[p].area;
}

int lr_tr_patch_surface(const lr_tr *t, size_t p) { return p < t->n ? t->p[p].surface : -1; }

bool lr_tr_plane_grid(const lr_tr *t, int s, int *nu, int *nv)
{
    bool ok = t && s >= 0 && s < t->nsurf && t->surf[s].d.kind == LR_TR_PLANE;
    *nu = ok ? t->surf[s].nu : 0;
    *nv = ok ? t->surf[s].nv : 0;
    return ok;
}
