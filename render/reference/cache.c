/* Reference cache: a rendered reference is stored under <dir>/<key>.pfm (+ .var.pfm, .json),
 * keyed by everything that changes its pixels, so the bench renders each reference once.
 *
 * The .json carries the content hash of both images (lr_ref_image_hash, 16 hex digits as
 * "mean_hash" and "var_hash"): the PFMs are plain files a user may open and a disk may damage,
 * and a reference is what every error is measured against, so an entry is served only when
 * both images match their hashes and every value is finite and non-negative (a radiance and a
 * variance cannot be anything else). An entry that fails is refused with a warning naming the
 * file and rendered again; one written before the hashes existed is stale, rendered again the
 * same way. */
#include "render/reference/ref_priv.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/base/atomic_file.h"
#include "render/base/json.h"

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

/* FNV-1a (hash.c) of the width, the height and every float's bits, little-endian, rows top
 * to bottom: the same on every host, and a change of any one bit of any value changes it. */
uint64_t lr_ref_image_hash(const lr_ref_image *img)
{
    lr_ref_hash h;
    lr_ref_hash_init(&h);
    lr_ref_hash_u64(&h, (uint64_t)img->width);
    lr_ref_hash_u64(&h, (uint64_t)img->height);
    size_t n = (size_t)img->width * (size_t)img->height * 3;
    for (size_t i = 0; i < n; i++) {
        uint32_t u;
        memcpy(&u, &img->rgb[i], sizeof u);
        unsigned char b[4] = {(unsigned char)u, (unsigned char)(u >> 8),
                              (unsigned char)(u >> 16), (unsigned char)(u >> 24)};
        lr_ref_hash_bytes(&h, b, sizeof b);
    }
    return h.h;
}

/* Values of img that are not finite and >= 0 (NaN fails the comparison); *first the index
 * of the first of them. */
static size_t implausible(const lr_ref_image *img, size_t *first)
{
    size_t n = (size_t)img->width * (size_t)img->height * 3, bad = 0;
    for (size_t i = 0; i < n; i++)
        if (!(img->rgb[i] >= 0.0f) || isinf(img->rgb[i]))
            if (!bad++)
                *first = i;
    return bad;
}

/* The paths of one entry. */
typedef struct entry {
    const char *key, *mean, *var, *meta;
} entry;

/* "mean_hash" or "var_hash" of the entry's .json: false when absent or not 16 hex digits. */
static bool meta_hash(const lr_json *j, const char *field, uint64_t *out)
{
    char buf[32];
    lr_err e = {0};
    lr_jnode n = lr_json_get(j, lr_json_root(j), field);
    if (n == LR_JNONE || lr_json_string(j, n, field, buf, sizeof buf, &e) || strlen(buf) != 16)
        return false;
    char *end;
    errno = 0;
    unsigned long long v = strtoull(buf, &end, 16);
    if (errno || *end)
        return false;
    *out = (uint64_t)v;
    return true;
}

/* One image of an entry: read, of the expected size, matching its hash, plausible. False
 * with the reason in *why (the file named) otherwise. */
static bool load_image(const char *path, int w, int h, uint64_t want, lr_ref_image *img,
                       lr_err *why)
{
    if (lr_image_read_pfm(path, img, why))
        return false;
    uint64_t got = lr_ref_image_hash(img);
    size_t first = 0, bad;
    if (img->width != w || img->height != h)
        lr_err_set(why, LR_EPARSE, "%s: %dx%d, the key says %dx%d", path, img->width,
                   img->height, w, h);
    else if (got != want)
        lr_err_set(why, LR_EPARSE, "%s: content hash %016llx, the entry's .json says %016llx "
                                   "(damaged or edited)",
                   path, (unsigned long long)got, (unsigned long long)want);
    else if ((bad = implausible(img, &first)))
        lr_err_set(why, LR_EPARSE, "%s: %zu of %zu values not finite and non-negative, the "
                                   "first %g (pixel %zu, %zu, channel %zu)",
                   path, bad, (size_t)w * (size_t)h * 3, (double)img->rgb[first],
                   first / 3 % (size_t)w, first / 3 / (size_t)w, first % 3);
    else
        return true;
    lr_ref_image_free(img);
    return false;
}

/* The entry, served only when it passes every check above. An absent entry (no mean image:
 * never rendered, or a crash before its last file) is a quiet miss; any other failure is a
 * warning naming the file, and a miss. */
static bool load(const entry *en, int w, int h, const lr_warn_sink *warn, lr_ref_image *mean,
                 lr_ref_image *var)
{
    if (access(en->mean, F_OK) != 0 && errno == ENOENT)
        return false;
    lr_json *j = NULL;
    lr_err why = {0};
    uint64_t hm = 0, hv = 0;
    char key[32] = "";
    bool ok = false;
    if (lr_json_load(en->meta, &j, &why)) {
        lr_warn(warn, "reference cache: %s; rendering it again", why.msg);
    } else if (!meta_hash(j, "mean_hash", &hm) || !meta_hash(j, "var_hash", &hv)) {
        lr_warn(warn, "reference cache: %s: no content hash (an older cache format): stale, "
                      "rendering it again", en->meta);
    } else if (lr_json_get_string(j, lr_json_root(j), "key", true, key, sizeof key, &why) ||
               strcmp(key, en->key) != 0) {
        lr_warn(warn, "reference cache: %s: key \"%s\" is not its name's; rendering it again",
                en->meta, key);
    } else if (!load_image(en->mean, w, h, hm, mean, &why) ||
               !load_image(en->var, w, h, hv, var, &why)) {
        lr_ref_image_free(mean);
        lr_warn(warn, "reference cache: %s: refused, rendering it again", why.msg);
    } else {
        ok = true;
    }
    lr_json_destroy(j);
    return ok;
}

static int write_meta(const char *path, const char *key, const lr_ref_render *r,
                      const lr_ref_image *mean, const lr_ref_image *var, lr_err *e)
{
    const lr_ref_stats *st = lr_ref_render_stats(r);
    char buf[1024];
    int n = snprintf(buf, sizeof buf,
                     "{\n  \"key\": \"%s\",\n  \"version\": \"%s\",\n"
                     "  \"mean_hash\": \"%016llx\",\n  \"var_hash\": \"%016llx\",\n"
                     "  \"spp\": %d,\n"
                     "  \"paths\": %llu,\n  \"nee\": %llu,\n  \"nee_refracted\": %llu,\n"
                     "  \"nee_unsolved\": %llu,\n  \"truncated\": %llu,\n"
                     "  \"medium_mismatch\": %llu,\n  \"nonfinite\": %llu\n}\n",
                     key, LR_REF_VERSION, (unsigned long long)lr_ref_image_hash(mean),
                     (unsigned long long)lr_ref_image_hash(var), lr_ref_render_spp_done(r),
                     (unsigned long long)st->paths, (unsigned long long)st->nee,
                     (unsigned long long)st->nee_refracted, (unsigned long long)st->nee_unsolved,
                     (unsigned long long)st->truncated, (unsigned long long)st->medium_mismatch,
                     (unsigned long long)st->nonfinite);
    return lr_atomic_write(path, buf, (size_t)n, e);
}

/* What the loader would refuse is not stored (it would be rendered again at every call):
 * an error naming the count. The renderer drops non-finite samples, so this takes a float
 * overflow of a mean or a variance. */
static int check_rendered(const char *path, const lr_ref_image *img, lr_err *e)
{
    size_t first = 0, bad = implausible(img, &first);
    if (bad)
        return lr_err_set(e, LR_EINVAL, "reference cache: %s not written: %zu of the render's "
                                        "values not finite and non-negative, the first %g",
                          path, bad, (double)img->rgb[first]);
    return LR_OK;
}

/* The paths of entry key under dir (each 4200 bytes). */
static entry entry_paths(const char *dir, const char *key, char *mp, char *vp, char *jp)
{
    snprintf(mp, 4200, "%s/%s.pfm", dir, key);
    snprintf(vp, 4200, "%s/%s.var.pfm", dir, key);
    snprintf(jp, 4200, "%s/%s.json", dir, key);
    return (entry){key, mp, vp, jp};
}

bool lr_ref_cache_load(const char *dir, const char key[17], int width, int height,
                       const lr_warn_sink *warn, lr_ref_image *mean, lr_ref_image *var)
{
    *mean = (lr_ref_image){0};
    *var = (lr_ref_image){0};
    char k[17], mp[4200], vp[4200], jp[4200];
    snprintf(k, sizeof k, "%s", key);
    const entry en = entry_paths(dir ? dir : DEFAULT_DIR, k, mp, vp, jp);
    return load(&en, width, height, warn, mean, var);
}

int lr_ref_render_cached(const lr_ref_scene *s, const lr_ref_camera *cam,
                         const lr_ref_render_desc *d, const char *dir,
                         void (*progress)(const lr_ref_render *r, void *user), void *user,
                         const lr_warn_sink *warn, lr_ref_image *mean, lr_ref_image *var,
                         bool *hit, lr_err *e)
{
    *mean = (lr_ref_image){0};
    *var = (lr_ref_image){0};
    *hit = false;
    if (!dir)
        dir = DEFAULT_DIR;
    char key[17], mp[4200], vp[4200], jp[4200];
    lr_ref_cache_key(s, cam, d, key);
    lr_ref_render_desc rd = lr_ref_render_desc_resolve(d);
    const entry en = entry_paths(dir, key, mp, vp, jp);
    if (load(&en, rd.width, rd.height, warn, mean, var)) {
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
        !(rc = check_rendered(mp, mean, e)) && !(rc = check_rendered(vp, var, e)) &&
        /* The mean goes last: a reader takes the entry only when it is there, and a crash
         * before it leaves a variance (and a .json) without a mean, which is a miss; an old
         * mean under a new .json fails its hash. */
        !(rc = lr_image_write_pfm(vp, var, e)) &&
        !(rc = write_meta(jp, key, r, mean, var, e)))
        rc = lr_image_write_pfm(mp, mean, e);
    lr_ref_render_destroy(r);
    if (rc) {
        lr_ref_image_free(mean);
        lr_ref_image_free(var);
    }
    return rc;
}
