/* Reference cache: a rendered reference is stored under <dir>/<key>.pfm (+ .var.pfm, .json),
 * keyed by everything that changes its pixels, so the bench renders each reference once. */
#include "render/reference/ref_priv.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "render/base/atomic_file.h"

#define DEFAULT_DIR "build/reference-cache"

void lr_ref_cache_key(const lr_ref_scene *s, const lr_ref_camera *cam,
                      const lr_ref_render_desc *desc, char key[17])
{
    /* Defaults resolved first, so "0 = default" and the explicit default share a key. */
    lr_ref_render_desc d = lr_ref_render_desc_resolve(desc);
    lr_ref_camera c = lr_ref_camera_resolve(cam);
    lr_ref_hash h;
    lr_ref_hash_init(&h);
    lr_ref_hash_str(&h, LR_REF_VERSION);
    lr_ref_hash_u64(&h, lr_ref_scene_hash(s));
    lr_ref_hash_vec3(&h, c.position);
    lr_ref_hash_vec3(&h, c.look_at);
    lr_ref_hash_vec3(&h, c.up);
    lr_ref_hash_double(&h, c.fov_y_deg);
    lr_ref_hash_u64(&h, (uint64_t)d.width);
    lr_ref_hash_u64(&h, (uint64_t)d.height);
    lr_ref_hash_u64(&h, (uint64_t)d.spp);
    lr_ref_hash_u64(&h, d.seed);
    snprintf(key, 17, "%016llx", (unsigned long long)h.h);
}

/* mkdir -p. */
static int make_dirs(const char *dir, lr_err *e)
{
    char buf[4096];
    if (snprintf(buf, sizeof buf, "%s", dir) >= (int)sizeof buf)
        return lr_err_set(e, LR_EINVAL, "reference cache: directory name too long");
    for (char *p = buf + 1;; p++) {
        if (*p == '/' || *p == '\0') {
            char c = *p;
            *p = '\0';
            if (mkdir(buf, 0755) != 0 && errno != EEXIST)
                return lr_err_set(e, LR_EIO, "reference cache: mkdir %s: %s", buf,
                                  strerror(errno));
            *p = c;
            if (!c)
                return LR_OK;
        }
    }
}

static bool load(const char *mean_path, const char *var_path, int w, int h, lr_ref_image *mean,
                 lr_ref_image *var)
{
    if (lr_image_read_pfm(mean_path, mean, NULL) || lr_image_read_pfm(var_path, var, NULL) ||
        mean->width != w || mean->height != h || var->width != w || var->height != h) {
        lr_ref_image_free(mean);
        lr_ref_image_free(var);
        return false;
    }
    return true;
}

static int write_meta(const char *path, const char *key, const lr_ref_render *r, lr_err *e)
{
    const lr_ref_stats *st = lr_ref_render_stats(r);
    char buf[1024];
    int n = snprintf(buf, sizeof buf,
                     "{\n  \"key\": \"%s\",\n  \"version\": \"%s\",\n  \"spp\": %d,\n"
                     "  \"paths\": %llu,\n  \"nee\": %llu,\n  \"nee_refracted\": %llu,\n"
                     "  \"nee_unsolved\": %llu,\n  \"truncated\": %llu,\n"
                     "  \"medium_mismatch\": %llu,\n  \"nonfinite\": %llu\n}\n",
                     key, LR_REF_VERSION, lr_ref_render_spp_done(r),
                     (unsigned long long)st->paths, (unsigned long long)st->nee,
                     (unsigned long long)st->nee_refracted, (unsigned long long)st->nee_unsolved,
                     (unsigned long long)st->truncated, (unsigned long long)st->medium_mismatch,
                     (unsigned long long)st->nonfinite);
    return lr_atomic_write(path, buf, (size_t)n, e);
}

int lr_ref_render_cached(const lr_ref_scene *s, const lr_ref_camera *cam,
                         const lr_ref_render_desc *d, const char *dir,
                         void (*progress)(const lr_ref_render *r, void *user), void *user,
                         lr_ref_image *mean, lr_ref_image *var, bool *hit, lr_err *e)
{
    *mean = (lr_ref_image){0};
    *var = (lr_ref_image){0};
    *hit = false;
    if (!dir)
        dir = DEFAULT_DIR;
    char key[17], mp[4200], vp[4200], jp[4200];
    lr_ref_cache_key(s, cam, d, key);
    snprintf(mp, sizeof mp, "%s/%s.pfm", dir, key);
    snprintf(vp, sizeof vp, "%s/%s.var.pfm", dir, key);
    snprintf(jp, sizeof jp, "%s/%s.json", dir, key);
    lr_ref_render_desc rd = lr_ref_render_desc_resolve(d);
    if (load(mp, vp, rd.width, rd.height, mean, var)) {
        *hit = true;
        return LR_OK;
    }
    lr_ref_render *r;
    int rc = make_dirs(dir, e);
    if (!rc)
        rc = lr_ref_render_create(s, cam, &rd, &r, e);
    if (rc)
        return rc;
    if (!(rc = lr_ref_render_run(r, progress, user, e)) &&
        !(rc = lr_ref_render_mean(r, mean, e)) && !(rc = lr_ref_render_variance(r, var, e)) &&
        /* The mean goes last: a reader takes the pair only when both are complete, and a
         * crash in between leaves a variance without a mean, which is a miss. */
        !(rc = lr_image_write_pfm(vp, var, e)) && !(rc = write_meta(jp, key, r, e)))
        rc = lr_image_write_pfm(mp, mean, e);
    lr_ref_render_destroy(r);
    if (rc) {
        lr_ref_image_free(mean);
        lr_ref_image_free(var);
    }
    return rc;
}
