/* The renderer on a worker thread (render/async/async.h). */
#include "render/async/async.h"

#include <GLES3/gl31.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

#include "render/base/paths.h"
#include "render/gl/shader.h"
#include "render/gl/tex.h"
#include "render/passes/blend.h"
#include "render/passes/defines.h"
#include "render/passes/mix.h"
#include "render/passes/passes.h"

/* The worker runs at a lower priority than the caller (nice +3 relative: about half the CPU share of a nice-0 thread, so two busy loops beside the rig slow the transport but do not starve it): its threads (the
 * CPU solvers' pools and the GL driver's rasteriser threads, made from it and inheriting it)
 * yield to the caller's loop on a loaded 2-core board. */
#define WORKER_NICE 3

/* What lr_scene_set does to light transport: everything but a dimmer/colour (intensity) and
 * exposure (display). */
#define TRANSPORT_DIRTY (~(unsigned)(LR_DIRTY_INTENSITY | LR_DIRTY_DISPLAY))
/* Changes that re-run the maps anyway, so that the preview stage costs little extra. */
#define HEAVY_DIRTY                                                                       \
    ((unsigned)(LR_DIRTY_LIGHT_GEOMETRY | LR_DIRTY_GEOMETRY | LR_DIRTY_MATERIAL |           \
                LR_DIRTY_SETTINGS))

typedef struct set_rec {
    char *key, *value;
} set_rec;

typedef struct set_list {
    set_rec *v;
    int n, cap;
    unsigned dirty;
} set_list;

/* A publication: the per-light images of one worker frame, in textures both contexts see. */
typedef struct slot {
    lr_tex *tex;
    int n, w, h;
    float scale[LR_SCENE_MAX_LIGHTS];
    GLsync written; /* the worker's fence after its copy */
    GLsync read;    /* the caller's fence after its last blend from it */
    lr_frame_stats st;
    lr_async_stage stage;
    uint64_t batch;
} slot;

struct lr_async {
    /* ---- the caller's thread ---- */
    lr_gl *gl;
    lr_scene *scene;
    int width, height;
    bool no_vpl;
    char shader_dir[512];
    lr_shader_defines defines;
    lr_blend *blend;
    set_list rec; /* journal entries since the last commit */
    bool scene_detached; /* lr_async_stop: the caller's scene may be gone */
    uint64_t batches;
    bool blend_due, clock_set;
    double time_s;
    int efd;
    char preview_key[LR_ASYNC_MAX_PREVIEW][128];
    char preview_value[LR_ASYNC_MAX_PREVIEW][128];
    int n_preview;
    unsigned no_preview_dirty;
    bool preview_always;
    double gpu_budget_mb;
    double slice_ms;
    double preview_scale;
    /* The control-space cache (render/async/cache.h): the entries are under mu; the display
     * of one (or of a mix drawn into `mixed`) is the caller's. */
    bool rec_outside;    /* the batch being recorded changes transport outside the keys */
    lr_mix *mix;
    lr_tex *mixed;       /* the interpolated state's images */
    int mixed_n;
    struct {
        bool on, exact, drawn;
        uint64_t batch;  /* the batch whose state it shows */
        lr_cache_mix mix;
    } cached;

    /* ---- shared, under mu ---- */
    pthread_mutex_t mu;
    pthread_cond_t cv;
    set_list queue;      /* batches not yet replayed */
    uint64_t queue_batch; /* the last batch in queue */
    bool stop, busy, started, start_failed, exited;
    int shown, ready;    /* slot indices; -1: none */
    slot slots[2];
    uint64_t published;
    uint64_t n_stage[LR_ASYNC_STAGES]; /* publications per stage (cache ones: shown) */
    lr_state_cache *cache; /* NULL: none */
    uint64_t cache_epoch;  /* counts flushes: a state built across one is not stored */
    uint64_t served_exact, served_interp; /* the last batches the cache answered */
    lr_async_state *wishes; /* lr_async_anticipate's list */
    int n_wishes, next_wish;
    int err_rc;
    lr_err err;
    /* The renderer's token (lr_renderer_set_cancel): requested by a stop, and by a transport
     * batch while `cancellable` (the worker's frame then solves a stale state). */
    lr_cancel cancel;
    bool cancellable;
    uint64_t n_cancelled; /* worker frames cut short (by a newer batch or a stop) */

    /* ---- the worker's thread ---- */
    pthread_t th;
    bool joinable;
    lr_gl *wgl;
    lr_scene *wscene;
    lr_renderer *r;
    /* The preview stage's renderer (NULL: no preview stage), at preview_scale of the view's
     * size, and the scene's changes since its last frame. */
    lr_renderer *pr;
    unsigned pr_dirty;
    GLuint read_fb, draw_fb;
    /* Wall time of the last preview frame and of the last full frame that re-ran the maps:
     * a preview that costs more than half a full frame (a CPU solve dominates both) is not
     * worth its delay, and is skipped until a full frame gets dearer again. */
    double preview_ms, full_ms;
};

const char *lr_async_stage_name(lr_async_stage s)
{
    switch (s) {
    case LR_ASYNC_PREVIEW: return "preview";
    case LR_ASYNC_CACHED: return "cached";
    case LR_ASYNC_INTERPOLATED: return "interpolated";
    case LR_ASYNC_REFINING: return "refining";
    case LR_ASYNC_FINAL: return "final";
    default: return "none";
    }
}

bool lr_async_stage_converged(lr_async_stage s)
{
    return s == LR_ASYNC_FINAL || s == LR_ASYNC_CACHED;
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/* ---- set lists ---- */

static void list_clear(set_list *l)
{
    for (int i = 0; i < l->n; i++) {
        free(l->v[i].key);
        free(l->v[i].value);
    }
    l->n = 0;
    l->dirty = 0;
}

static void list_free(set_list *l)
{
    list_clear(l);
    free(l->v);
    *l = (set_list){0};
}

static bool list_push(set_list *l, const char *key, const char *value)
{
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 16;
        set_rec *v = realloc(l->v, (size_t)cap * sizeof *v);
        if (!v)
            return false;
        l->v = v;
        l->cap = cap;
    }
    char *k = strdup(key), *val = strdup(value);
    if (!k || !val) {
        free(k);
        free(val);
        return false;
    }
    l->v[l->n++] = (set_rec){k, val};
    return true;
}

/* Moves src's entries to the end of dst (src left empty). */
static bool list_append(set_list *dst, set_list *src)
{
    for (int i = 0; i < src->n; i++) {
        if (!list_push(dst, src->v[i].key, src->v[i].value))
            return false;
    }
    dst->dirty |= src->dirty;
    list_clear(src);
    return true;
}

static void journal(void *user, const char *key, const char *value, unsigned dirty)
{
    lr_async *a = user;
    if (!list_push(&a->rec, key, value)) {
        /* Out of memory: the worker's copy would drift from the caller's scene. */
        pthread_mutex_lock(&a->mu);
        if (!a->err_rc)
            a->err_rc = lr_err_set(&a->err, LR_ENOMEM, "async: change %s: out of memory", key);
        pthread_mutex_unlock(&a->mu);
    }
    a->rec.dirty |= dirty;
    if (a->cache && (dirty & TRANSPORT_DIRTY) && !lr_state_cache_has_key(a->cache, key))
        a->rec_outside = true; /* the cache's keys are fixed at create: read without the lock */
}

/* ---- the worker ---- */

static void worker_fail(lr_async *a, int rc, const lr_err *e)
{
    pthread_mutex_lock(&a->mu);
    a->err_rc = rc;
    a->err = *e;
    pthread_mutex_unlock(&a->mu);
}

static void notify(lr_async *a)
{
    uint64_t one = 1;
    if (write(a->efd, &one, sizeof one) < 0) {
        /* EAGAIN: the counter is already non-zero, the caller will wake. */
    }
}

/* Copies n layers of src into dst (both the view's size) on the worker's context. */
/* Copies n layers of src (sw x sh) into dst (the view's size), scaled by the nearest texel
 * when the sizes differ (a preview's): float targets need not be filterable on the board. */
static void copy_layers(lr_async *a, const lr_tex *src, int sw, int sh, lr_tex *dst, int n)
{
    for (int l = 0; l < n; l++) {
        glBindFramebuffer(GL_READ_FRAMEBUFFER, a->read_fb);
        glFramebufferTextureLayer(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, lr_tex_id(src), 0, l);
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, a->draw_fb);
        glFramebufferTextureLayer(GL_DRAW_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, lr_tex_id(dst), 0, l);
        GLenum att = GL_COLOR_ATTACHMENT0;
        glDrawBuffers(1, &att);
        glBlitFramebuffer(0, 0, sw, sh, 0, 0, a->width, a->height, GL_COLOR_BUFFER_BIT,
                          GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

/* Copies renderer r's images into the slot the caller is not reading and publishes them. */
static int publish(lr_async *a, lr_renderer *r, const lr_frame_stats *st, lr_async_stage stage,
                   uint64_t batch, lr_err *e)
{
    int n, sw, sh;
    float scale[LR_SCENE_MAX_LIGHTS];
    const lr_tex *src = lr_renderer_images(r, &n, scale);
    lr_renderer_size(r, &sw, &sh);
    if (!src || n < 1)
        return LR_OK;
    pthread_mutex_lock(&a->mu);
    int w = a->shown == 0 ? 1 : 0;
    if (a->ready == w)
        a->ready = -1; /* not taken yet: overwritten by the newer one */
    GLsync read = a->slots[w].read;
    a->slots[w].read = NULL;
    pthread_mutex_unlock(&a->mu);
    if (read) {
        /* The caller's last blend from this slot must finish before it is overwritten. */
        glWaitSync(read, 0, GL_TIMEOUT_IGNORED);
        glDeleteSync(read);
    }
    slot *s = &a->slots[w];
    if (!s->tex || s->n != n || s->w != a->width || s->h != a->height) {
        lr_tex_destroy(s->tex);
        s->tex = NULL;
        lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = a->width,
                          .height = a->height, .layers = n, .label = "published images"};
        int rc = lr_tex_create(a->wgl, &td, &s->tex, e);
        if (rc)
            return rc;
        s->n = n;
        s->w = a->width;
        s->h = a->height;
    }
    copy_layers(a, src, sw, sh, s->tex, n);
    int rc = lr_gl_check("async: publishing the images", e);
    if (rc)
        return rc;
    GLsync written = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    pthread_mutex_lock(&a->mu);
    if (s->written)
        glDeleteSync(s->written);
    s->written = written;
    memcpy(s->scale, scale, sizeof scale);
    s->st = *st;
    s->stage = stage;
    s->batch = batch;
    a->ready = w;
    a->n_stage[stage]++;
    if (batch > a->published)
        a->published = batch;
    pthread_cond_broadcast(&a->cv);
    pthread_mutex_unlock(&a->mu);
    notify(a);
    return LR_OK;
}

/* Replays a batch on the worker's copy. The caller's scene took every one of these changes,
 * and the copy went through the same ones before, so a refusal here is a defect: reported. */
static int replay(lr_async *a, set_list *l, unsigned *dirty, lr_err *e)
{
    for (int i = 0; i < l->n; i++) {
        int rc = lr_scene_set(a->wscene, l->v[i].key, l->v[i].value, dirty, e);
        if (rc)
            return lr_err_prefix(e, "async: the worker's copy refused a change the scene took");
    }
    return LR_OK;
}

/* The preview stage: its assignments applied, one frame of the preview's own renderer (with
 * the scene's changes since its last frame), published, the scene's own values back. The
 * view's renderer never sees the preview's values: its maps, grids and solver states stay
 * allocated for the scene's own settings. */
static int preview_frame(lr_async *a, uint64_t batch, lr_err *e)
{
    char old[LR_ASYNC_MAX_PREVIEW][256];
    int rc = LR_OK, applied = 0;
    unsigned d = a->pr_dirty;
    for (int i = 0; i < a->n_preview && !rc; i++)
        if (!(rc = lr_scene_get(a->wscene, a->preview_key[i], old[i], sizeof old[i], e)) &&
            !(rc = lr_scene_set(a->wscene, a->preview_key[i], a->preview_value[i], &d, e)))
            applied = i + 1;
    lr_frame_stats st;
    /* An assignment the copy refuses now (a preview model outside what the new material
     * allows): no preview this time, the refined image comes as usual. */
    bool skip = rc != LR_OK;
    if (skip)
        rc = LR_OK;
    if (!rc && !skip) {
        /* The preview's own assignments are not changes for its renderer: it sees them at
         * every frame (and whatever the scene's own values of those keys do in between). */
        lr_renderer_invalidate(a->pr, a->pr_dirty);
        rc = lr_renderer_frame(a->pr, &st, e);
        /* Its next frame redoes what this one did not finish (a cut: a stop). */
        if (!rc)
            a->pr_dirty = 0;
    }
    if (!rc && !skip)
        rc = publish(a, a->pr, &st, LR_ASYNC_PREVIEW, batch, e);
    /* Restored whatever happened: the copy must stay equal to the caller's scene. */
    unsigned back = 0;
    for (int i = applied - 1; i >= 0; i--) {
        lr_err re = {0};
        int rrc = lr_scene_set(a->wscene, a->preview_key[i], old[i], &back, &re);
        if (rrc && !rc) {
            rc = rrc;
            *e = re;
        }
    }
    return rc;
}

/* Starts a frame of a state built ahead: false when it must not (a stop, or a batch that
 * changes transport waits: the loop takes it first; a dimmer's batch waits for the end). */
static bool ahead_begin(lr_async *a)
{
    pthread_mutex_lock(&a->mu);
    bool go = !a->stop && !(a->queue.n > 0 && (a->queue.dirty & TRANSPORT_DIRTY));
    if (go) {
        lr_cancel_reset(&a->cancel);
        a->cancellable = true;
    }
    pthread_mutex_unlock(&a->mu);
    return go;
}

static void frame_end(lr_async *a);

/* Builds the next state of the anticipation list that is not cached yet: its assignments on
 * the copy, frames to convergence, its images into a new cache entry, the copy's values back
 * (their flags left in the renderer for the next frame that renders: the images shown stay
 * those of the scene's own state). Returns LR_OK with *did false when the list is done, and
 * LR_ECANCELED when a change or a stop cut it (the state is visited again later). */
static int build_ahead(lr_async *a, bool *did, lr_err *e)
{
    *did = false;
    pthread_mutex_lock(&a->mu);
    if (!a->cache || a->next_wish >= a->n_wishes || a->stop ||
        (a->queue.n > 0 && (a->queue.dirty & TRANSPORT_DIRTY))) {
        pthread_mutex_unlock(&a->mu);
        return LR_OK;
    }
    lr_async_state w = a->wishes[a->next_wish];
    uint64_t epoch = a->cache_epoch;
    int nkeys;
    const lr_cache_key *keys = lr_state_cache_keys(a->cache, &nkeys);
    pthread_mutex_unlock(&a->mu);
    *did = true;

    char old[LR_ASYNC_STATE_SETS][LR_CACHE_VALUE_MAX];
    int rc = LR_OK, applied = 0;
    unsigned d = 0;
    for (int i = 0; i < w.n && !rc; i++)
        if (!(rc = lr_scene_get(a->wscene, w.key[i], old[i], sizeof old[i], e)) &&
            !(rc = lr_scene_set(a->wscene, w.key[i], w.value[i], &d, e)))
            applied = i + 1;
    lr_state_tag tag;
    bool held = false;
    if (!rc && !(rc = lr_state_tag_of(a->wscene, keys, nkeys, &tag, e))) {
        pthread_mutex_lock(&a->mu);
        held = lr_state_cache_holds(a->cache, &tag);
        pthread_mutex_unlock(&a->mu);
    }
    /* A state the copy refuses (a value outside what the material allows): passed over, not
     * an error of the view. */
    bool skip = rc != LR_OK, rendered = false;
    rc = LR_OK;
    int n = 0;
    float scale[LR_SCENE_MAX_LIGHTS] = {0};
    if (!skip && !held) {
        lr_renderer_invalidate(a->r, d);
        do {
            if (!ahead_begin(a)) {
                rc = LR_ECANCELED;
                break;
            }
            lr_frame_stats st;
            rc = lr_renderer_frame(a->r, &st, e);
            frame_end(a);
            rendered = true;
        } while (!rc && lr_renderer_needs_frame(a->r));
        const lr_tex *src = rc ? NULL : lr_renderer_images(a->r, &n, scale);
        size_t bytes = (size_t)a->width * (size_t)a->height * 16u * (size_t)n;
        pthread_mutex_lock(&a->mu);
        bool fits = src && n > 0 && lr_state_cache_fits(a->cache, bytes);
        pthread_mutex_unlock(&a->mu);
        if (src && n > 0 && !fits) {
            /* Full of pinned entries or too small: the rest of the list would not fit either. */
            pthread_mutex_lock(&a->mu);
            a->next_wish = a->n_wishes;
            pthread_mutex_unlock(&a->mu);
        } else if (src && n > 0) {
            lr_tex *t = NULL;
            lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F,
                              .width = a->width, .height = a->height, .layers = n,
                              .label = "cached state's images"};
            if (!(rc = lr_tex_create(a->wgl, &td, &t, e))) {
                copy_layers(a, src, a->width, a->height, t, n);
                rc = lr_gl_check("async: caching a state's images", e);
                glFinish(); /* complete before the caller may read it */
            }
            pthread_mutex_lock(&a->mu);
            if (!rc && a->cache_epoch == epoch)
                lr_state_cache_store(a->cache, &tag, t, n, scale, bytes);
            else
                lr_tex_destroy(t);
            lr_state_cache_reap(a->cache);
            pthread_mutex_unlock(&a->mu);
        }
    }
    unsigned back = 0;
    for (int i = applied - 1; i >= 0; i--) {
        lr_err re = {0};
        int rrc = lr_scene_set(a->wscene, w.key[i], old[i], &back, &re);
        if (rrc && (!rc || rc == LR_ECANCELED)) {
            rc = rrc;
            *e = re;
        }
    }
    /* Nothing rendered: the renderer still holds the scene's own state. */
    if (rendered)
        lr_renderer_invalidate(a->r, back | d);
    if (rc == LR_OK) {
        pthread_mutex_lock(&a->mu);
        if (a->next_wish < a->n_wishes && a->cache_epoch == epoch)
            a->next_wish++;
        pthread_mutex_unlock(&a->mu);
    }
    return rc;
}

/* Starts a worker frame: false when it must not start (a stop; or, for a frame a newer batch
 * may cut, that batch already waits -- the loop takes it first). The token is reset here,
 * under the lock commit requests it under, so a request meant for an earlier frame never
 * cuts this one, and a stop's is never cleared. */
static bool frame_begin(lr_async *a, bool cancellable)
{
    pthread_mutex_lock(&a->mu);
    bool go = !a->stop && !(cancellable && a->queue.n > 0);
    if (go) {
        lr_cancel_reset(&a->cancel);
        a->cancellable = cancellable;
    }
    pthread_mutex_unlock(&a->mu);
    return go;
}

static void frame_end(lr_async *a)
{
    pthread_mutex_lock(&a->mu);
    a->cancellable = false;
    pthread_mutex_unlock(&a->mu);
}

static void *worker_main(void *arg)
{
    lr_async *a = arg;
    lr_err e = {0};
    /* Lower priority for this thread and every thread it starts (Linux: nice is per thread). */
    pid_t tid = (pid_t)syscall(SYS_gettid);
    errno = 0;
    int nice_now = getpriority(PRIO_PROCESS, (id_t)tid);
    if (errno == 0)
        setpriority(PRIO_PROCESS, (id_t)tid, nice_now + WORKER_NICE > 19 ? 19
                                                                           : nice_now + WORKER_NICE);
    int rc = lr_gl_create_shared(a->gl, &a->wgl, &e);
    if (!rc) {
        glGenFramebuffers(1, &a->read_fb);
        glGenFramebuffers(1, &a->draw_fb);
    }
    pthread_mutex_lock(&a->mu);
    a->started = true;
    a->start_failed = rc != LR_OK;
    if (rc) {
        a->err_rc = rc;
        a->err = e;
    }
    pthread_cond_broadcast(&a->cv);
    pthread_mutex_unlock(&a->mu);
    if (rc)
        return NULL;

    lr_renderer_desc rd = {.gl = a->wgl, .scene = a->wscene, .width = a->width,
                           .height = a->height, .no_vpl = a->no_vpl,
                           /* The caller blends the published images (lr_async_blend). */
                           .images_only = true, .gpu_budget_mb = a->gpu_budget_mb};
    if ((rc = lr_renderer_create(&rd, &a->r, &e)))
        worker_fail(a, rc, &e);
    else {
        lr_renderer_set_cancel(a->r, &a->cancel);
        lr_renderer_set_slice_ms(a->r, a->slice_ms);
    }
    if (a->r && a->n_preview) {
        double s = a->preview_scale > 0 && a->preview_scale < 1 ? a->preview_scale : 1.0;
        lr_renderer_desc pd = rd;
        pd.programs_of = a->r; /* destroyed after it */
        pd.width = a->width * s < 1 ? 1 : (int)lround(a->width * s);
        pd.height = a->height * s < 1 ? 1 : (int)lround(a->height * s);
        if ((rc = lr_renderer_create(&pd, &a->pr, &e))) {
            worker_fail(a, rc, &e);
            lr_renderer_destroy(a->r);
            a->r = NULL;
        } else {
            lr_renderer_set_cancel(a->pr, &a->cancel); /* a stop cuts it */
        }
    }
    a->pr_dirty = LR_DIRTY_SETTINGS; /* its first frame: everything */
    set_list batch = {0};
    unsigned dirty = LR_DIRTY_SETTINGS; /* the first frame: everything */
    bool converged = false, first = true;
    /* A frame was cut for a newer batch and nothing has been published since: the next full
     * frame runs to its end whatever arrives, so that a knob turned without rest on a scene
     * without a preview stage still shows images (one per full frame, as before cutting). */
    bool cut_unshown = false;
    uint64_t applied = 0;
    while (a->r) {
        pthread_mutex_lock(&a->mu);
        bool work = (dirty & TRANSPORT_DIRTY) || !converged;
        bool ahead = a->cache && a->next_wish < a->n_wishes;
        while (!a->stop && !a->queue.n && !work && !ahead) {
            a->busy = false;
            pthread_cond_broadcast(&a->cv);
            pthread_cond_wait(&a->cv, &a->mu);
            ahead = a->cache && a->next_wish < a->n_wishes;
        }
        if (a->stop) {
            pthread_mutex_unlock(&a->mu);
            break;
        }
        if (!a->queue.n && !work) {
            /* Nothing of the shown state left to do: build a state ahead (not "busy": the
             * view has converged; a change cuts it). */
            a->busy = false;
            pthread_cond_broadcast(&a->cv);
            pthread_mutex_unlock(&a->mu);
            bool did;
            rc = build_ahead(a, &did, &e);
            if (rc && rc != LR_ECANCELED) {
                worker_fail(a, rc, &e);
                pthread_mutex_lock(&a->mu);
                a->next_wish = a->n_wishes; /* not again until a new list */
                pthread_mutex_unlock(&a->mu);
            }
            continue;
        }
        a->busy = true;
        bool fresh = a->queue.n > 0;
        uint64_t b = a->queue_batch;
        uint64_t exact_b = a->served_exact, interp_b = a->served_interp;
        set_list tmp = a->queue;
        a->queue = batch; /* empty */
        batch = tmp;
        pthread_mutex_unlock(&a->mu);
        unsigned got = 0;
        if (fresh) {
            rc = replay(a, &batch, &got, &e);
            list_clear(&batch);
            applied = b;
            a->pr_dirty |= got;
            if (rc) {
                worker_fail(a, rc, &e);
                break;
            }
            dirty |= got;
            lr_renderer_invalidate(a->r, got);
            /* The caller shows this state's cached images: nothing to render (the renderer
             * keeps the flags for the next state that needs it). Or the batch changes no
             * transport: the published images stand for it too. */
            bool cached = applied == exact_b;
            if (cached || (!(got & TRANSPORT_DIRTY) && converged)) {
                if (cached) {
                    dirty = 0;
                    converged = true;
                }
                pthread_mutex_lock(&a->mu);
                if (applied > a->published)
                    a->published = applied;
                pthread_cond_broadcast(&a->cv);
                pthread_mutex_unlock(&a->mu);
                continue;
            }
        }
        bool heavy = first || (fresh && (got & HEAVY_DIRTY));
        bool worth = a->preview_always || !(a->preview_ms > 0.5 * a->full_ms && a->full_ms > 0);
        /* An interpolation of cached states shows until this state converges: no preview. */
        bool interpolated = fresh && applied == interp_b;
        if (a->n_preview && worth && !interpolated &&
            (first || (heavy && (got & ~a->no_preview_dirty & TRANSPORT_DIRTY)))) {
            if (!frame_begin(a, false))
                continue; /* a stop */
            double t0 = now_ms();
            rc = preview_frame(a, applied, &e);
            frame_end(a);
            a->preview_ms = now_ms() - t0;
            if (rc == LR_ECANCELED) {
                pthread_mutex_lock(&a->mu);
                a->n_cancelled++;
                pthread_mutex_unlock(&a->mu);
                converged = false; /* a stop: the loop's top ends it */
                continue;
            }
            if (!rc)
                cut_unshown = false;
            if (rc) {
                worker_fail(a, rc, &e);
                converged = true; /* wait for the next change */
                dirty = 0;
                continue;
            }
            /* A newer change already waits (a knob still turning): preview it next instead of
             * refining a state that is already stale; the refinement comes when the controls
             * rest. */
            pthread_mutex_lock(&a->mu);
            bool newer = a->queue.n > 0;
            pthread_mutex_unlock(&a->mu);
            if (newer) {
                first = false;
                continue;
            }
        }
        first = false;
        lr_frame_stats st;
        /* A newer batch arriving during this frame cuts it (lr_async_commit), unless the last
         * cut one left nothing shown. */
        if (!frame_begin(a, !cut_unshown)) {
            converged = false; /* a stop, or a newer batch waits: taken at the loop's top */
            continue;
        }
        double t0 = now_ms();
        rc = lr_renderer_frame(a->r, &st, &e);
        frame_end(a);
        if (rc == LR_ECANCELED) {
            /* The renderer kept everything due; the newer batch (or the stop) is taken at the
             * loop's top. */
            pthread_mutex_lock(&a->mu);
            a->n_cancelled++;
            cut_unshown = true;
            pthread_mutex_unlock(&a->mu);
            converged = false;
            continue;
        }
        if (heavy && !rc)
            a->full_ms = now_ms() - t0;
        if (rc) {
            worker_fail(a, rc, &e);
            converged = true;
            dirty = 0;
            continue;
        }
        dirty = 0;
        converged = !lr_renderer_needs_frame(a->r);
        if (st.passes & LR_PASS_COMPOSE)
            cut_unshown = false;
        if ((st.passes & LR_PASS_COMPOSE) &&
            (rc = publish(a, a->r, &st, converged ? LR_ASYNC_FINAL : LR_ASYNC_REFINING, applied,
                          &e))) {
            worker_fail(a, rc, &e);
            converged = true;
        } else if (!(st.passes & LR_PASS_COMPOSE)) {
            pthread_mutex_lock(&a->mu);
            if (applied > a->published)
                a->published = applied;
            pthread_mutex_unlock(&a->mu);
        }
    }
    list_free(&batch);
    lr_renderer_destroy(a->pr);
    a->pr = NULL;
    lr_renderer_destroy(a->r);
    a->r = NULL;
    /* The cache's textures were made on this context: freed with it (the caller no longer
     * draws: a stop, or lr_async_destroy, which finished its own GL work first). */
    pthread_mutex_lock(&a->mu);
    if (a->cache)
        lr_state_cache_drop_all(a->cache);
    pthread_mutex_unlock(&a->mu);
    /* The caller no longer reads the slots (lr_async_destroy freed its side first). */
    for (int i = 0; i < 2; i++) {
        lr_tex_destroy(a->slots[i].tex);
        a->slots[i].tex = NULL;
        if (a->slots[i].written)
            glDeleteSync(a->slots[i].written);
        if (a->slots[i].read)
            glDeleteSync(a->slots[i].read);
        a->slots[i].written = a->slots[i].read = NULL;
    }
    glDeleteFramebuffers(1, &a->read_fb);
    glDeleteFramebuffers(1, &a->draw_fb);
    glFinish();
    lr_gl_destroy(a->wgl);
    a->wgl = NULL;
    pthread_mutex_lock(&a->mu);
    a->busy = false;
    a->exited = true;
    pthread_cond_broadcast(&a->cv);
    pthread_mutex_unlock(&a->mu);
    return NULL;
}

/* ---- the caller's side ---- */

static int caller_programs(lr_async *a, lr_err *e)
{
    if (lr_shaders_dir(a->shader_dir, sizeof a->shader_dir) != 0)
        return lr_err_set(e, LR_EINVAL, "async: shader directory path too long");
    lr_passes_defines(&a->defines);
    lr_blend_desc bd = {.gl = a->gl, .width = a->width, .height = a->height,
                        .shader_dir = a->shader_dir, .defines = a->defines.list};
    int rc = lr_blend_create(&bd, &a->blend, e);
    if (!rc && a->cache)
        rc = lr_mix_create(a->gl, a->shader_dir, &a->mix, e);
    return rc;
}

/* The cache over desc's keys, each checked against the scene. */
static int cache_create(lr_async *a, const lr_async_desc *d, lr_err *e)
{
    if (!d->cache_keys || d->n_cache_keys <= 0 || !(d->cache_mb > 0.0))
        return LR_OK;
    lr_state_tag tag;
    int rc = lr_state_tag_of(d->scene, d->cache_keys, d->n_cache_keys, &tag, e);
    if (rc)
        return lr_err_prefix(e, "async");
    return lr_state_cache_create(d->cache_keys, d->n_cache_keys,
                                 (size_t)(d->cache_mb * 1024.0 * 1024.0), &a->cache, e);
}

static int check_preview(lr_async *a, const lr_async_desc *d, lr_err *e)
{
    for (int i = 0; i < d->n_preview; i++) {
        const char *p = d->preview[i];
        const char *eq = p ? strchr(p, '=') : NULL;
        if (!eq || eq == p || (size_t)(eq - p) >= sizeof a->preview_key[0] ||
            strlen(eq + 1) >= sizeof a->preview_value[0])
            return lr_err_set(e, LR_EINVAL, "async: preview '%s': expected key=value",
                              p ? p : "(null)");
        snprintf(a->preview_key[i], sizeof a->preview_key[i], "%.*s", (int)(eq - p), p);
        snprintf(a->preview_value[i], sizeof a->preview_value[i], "%s", eq + 1);
        char cur[256];
        int rc = lr_scene_get(d->scene, a->preview_key[i], cur, sizeof cur, e);
        if (rc)
            return lr_err_prefix(e, "async: preview");
    }
    a->n_preview = d->n_preview;
    return LR_OK;
}

int lr_async_create(const lr_async_desc *d, lr_async **out, lr_err *e)
{
    *out = NULL;
    if (!d || !d->gl || !d->scene)
        return lr_err_set(e, LR_EINVAL, "async: a GL context and a scene are required");
    if (d->n_preview < 0 || d->n_preview > LR_ASYNC_MAX_PREVIEW)
        return lr_err_set(e, LR_EINVAL, "async: %d preview assignments; at most %d",
                          d->n_preview, LR_ASYNC_MAX_PREVIEW);
    lr_async *a = calloc(1, sizeof *a);
    if (!a)
        return lr_err_set(e, LR_ENOMEM, "async: out of memory");
    a->gl = d->gl;
    a->scene = d->scene;
    a->width = d->width > 0 ? d->width : 640;
    a->height = d->height > 0 ? d->height : 480;
    a->no_vpl = d->no_vpl;
    a->no_preview_dirty = d->no_preview_dirty;
    a->preview_always = d->preview_always;
    a->gpu_budget_mb = d->gpu_budget_mb;
    a->slice_ms = d->slice_ms;
    a->preview_scale = d->preview_scale;
    a->shown = a->ready = -1;
    a->efd = -1;
    pthread_mutex_init(&a->mu, NULL);
    pthread_cond_init(&a->cv, NULL);
    lr_cancel_init(&a->cancel);
    int rc = check_preview(a, d, e);
    if (!rc)
        rc = cache_create(a, d, e);
    if (!rc && (a->efd = eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) < 0)
        rc = lr_err_set(e, LR_EIO, "async: eventfd: %s", strerror(errno));
    if (!rc)
        rc = caller_programs(a, e);
    if (!rc)
        rc = lr_scene_clone(d->scene, NULL, &a->wscene, e);
    if (!rc && pthread_create(&a->th, NULL, worker_main, a) != 0)
        rc = lr_err_set(e, LR_ENOMEM, "async: cannot start the worker thread");
    if (!rc) {
        a->joinable = true;
        /* Only the context is waited for (milliseconds): a driver that cannot share one is
         * an error here, not a black output later. */
        pthread_mutex_lock(&a->mu);
        while (!a->started)
            pthread_cond_wait(&a->cv, &a->mu);
        if (a->start_failed) {
            rc = a->err_rc;
            *e = a->err;
        }
        pthread_mutex_unlock(&a->mu);
    }
    if (rc) {
        lr_async_destroy(a);
        return rc;
    }
    lr_scene_set_journal(d->scene, &(lr_scene_journal){journal, a});
    /* The caller's GL state: the worker's context creation may have changed nothing here,
     * but be explicit that this thread keeps its own context. */
    *out = a;
    return LR_OK;
}

void lr_async_stop(lr_async *a)
{
    if (!a)
        return;
    if (a->scene)
        lr_scene_set_journal(a->scene, NULL);
    a->scene_detached = true;
    pthread_mutex_lock(&a->mu);
    a->stop = true;
    lr_cancel_request(&a->cancel, LR_CANCEL_STOP); /* what runs ends at its next poll */
    pthread_cond_broadcast(&a->cv);
    pthread_mutex_unlock(&a->mu);
}

bool lr_async_stopped(const lr_async *a)
{
    lr_async *m = (lr_async *)a;
    pthread_mutex_lock(&m->mu);
    bool x = a->exited || !a->joinable;
    pthread_mutex_unlock(&m->mu);
    return x;
}

void lr_async_destroy(lr_async *a)
{
    if (!a)
        return;
    if (a->scene && !a->scene_detached)
        lr_scene_set_journal(a->scene, NULL);
    /* The caller's side first: after this nothing here reads the slots. */
    if (a->blend)
        glFinish();
    lr_blend_destroy(a->blend);
    if (a->joinable) {
        pthread_mutex_lock(&a->mu);
        a->stop = true;
        lr_cancel_request(&a->cancel, LR_CANCEL_STOP);
        pthread_cond_broadcast(&a->cv);
        pthread_mutex_unlock(&a->mu);
        pthread_join(a->th, NULL);
    }
    /* The worker freed the entries' textures as it exited (they are its context's). */
    lr_state_cache_destroy(a->cache);
    lr_tex_destroy(a->mixed);
    lr_mix_destroy(a->mix);
    free(a->wishes);
    lr_scene_destroy(a->wscene);
    list_free(&a->rec);
    list_free(&a->queue);
    if (a->efd >= 0)
        close(a->efd);
    pthread_cond_destroy(&a->cv);
    pthread_mutex_destroy(&a->mu);
    free(a);
}

uint64_t lr_async_commit(lr_async *a, unsigned dirty)
{
    if (dirty & (LR_DIRTY_INTENSITY | LR_DIRTY_DISPLAY))
        a->blend_due = true;
    if (!a->rec.n)
        return 0;
    /* The committed state's tag, read before the lock (the caller's scene is this thread's). */
    lr_state_tag tag;
    int nkeys = 0;
    const lr_cache_key *keys = a->cache ? lr_state_cache_keys(a->cache, &nkeys) : NULL;
    lr_err te = {0};
    bool tagged = a->cache && (dirty & TRANSPORT_DIRTY) &&
                  lr_state_tag_of(a->scene, keys, nkeys, &tag, &te) == LR_OK;
    pthread_mutex_lock(&a->mu);
    uint64_t b = ++a->batches;
    if (a->cache && a->rec_outside) {
        /* A change outside the keys: every entry was built on a scene that no longer is. */
        lr_state_cache_flush(a->cache);
        a->cache_epoch++;
    }
    a->rec_outside = false;
    /* A dimmer's batch right after one the cache answered is the same state: answered too
     * (else the worker would render the cached state because the batches merged). */
    if (!(dirty & TRANSPORT_DIRTY) && b > 1) {
        if (a->served_exact && a->served_exact == b - 1)
            a->served_exact = b;
        if (a->served_interp && a->served_interp == b - 1)
            a->served_interp = b;
        if (a->cached.on && a->cached.batch == b - 1)
            a->cached.batch = b; /* what replaces it is the worker's image of this batch */
    }
    if (a->cache && (dirty & TRANSPORT_DIRTY)) {
        lr_cache_mix mix;
        /* A miss leaves a cached image shown until the worker publishes this state (a
         * newer batch): an older state's image would step back. */
        bool hit = tagged && lr_state_cache_find(a->cache, &tag, &mix);
        if (hit) {
            if (a->cached.on)
                lr_state_cache_unpin(a->cache, &a->cached.mix);
            a->cached.on = true;
            lr_state_cache_pin(a->cache, &mix);
            a->cached.mix = mix;
            a->cached.exact = mix.exact;
            a->cached.drawn = false;
            a->cached.batch = b;
            if (mix.exact)
                a->served_exact = b;
            else
                a->served_interp = b;
        }
    }
    if (!list_append(&a->queue, &a->rec) && !a->err_rc)
        a->err_rc = lr_err_set(&a->err, LR_ENOMEM, "async: a batch of changes: out of memory");
    a->queue_batch = b;
    a->busy = true;
    /* The worker's frame solves a state this batch replaces: cut it (render/base/cancel.h),
     * so that the new state's first image does not wait for the stale one's. A batch that
     * restarts the maps cuts inside their accumulation too (render/passes/slice.h); one that
     * does not (a camera move, a receiver) cuts between the radiosity pass's slices only
     * after them, and a later batch that restarts them may still raise the request. */
    if ((dirty & TRANSPORT_DIRTY) && a->cancellable) {
        bool restarts = (lr_dirty_passes(dirty) & LR_PASS_RADIOSITY) != 0;
        lr_cancel_request(&a->cancel, restarts ? LR_CANCEL_RESTART : LR_CANCEL_STALE);
        a->cancellable = !restarts;
    }
    pthread_cond_broadcast(&a->cv);
    pthread_mutex_unlock(&a->mu);
    /* A dimmer, colour, flicker or exposure change: the caller's next blend shows it (the
     * worker replays it only to keep its copy equal). */
    return (dirty & TRANSPORT_DIRTY) ? b : 0;
}

void lr_async_set_time(lr_async *a, double t)
{
    if (!isfinite(t) || (a->clock_set && t == a->time_s))
        return;
    for (int l = 0; l < lr_scene_light_count(a->scene); l++)
        if (lr_light_flickers(lr_scene_light_at(a->scene, l)))
            a->blend_due = true;
    a->clock_set = true;
    a->time_s = t;
}

bool lr_async_needs_frame(const lr_async *a)
{
    lr_async *m = (lr_async *)a; /* the mutex only */
    pthread_mutex_lock(&m->mu);
    bool ready = a->ready >= 0;
    bool shown = a->shown >= 0 || a->cached.on;
    pthread_mutex_unlock(&m->mu);
    return ready || (a->cached.on && !a->cached.drawn) || (a->blend_due && shown);
}

bool lr_async_busy(const lr_async *a)
{
    lr_async *m = (lr_async *)a;
    pthread_mutex_lock(&m->mu);
    bool b = a->busy || a->queue.n > 0;
    pthread_mutex_unlock(&m->mu);
    return b;
}

/* A counter the worker writes, read under the lock. */
static uint64_t locked_u64(const lr_async *a, const uint64_t *field)
{
    lr_async *m = (lr_async *)a; /* the mutex only */
    pthread_mutex_lock(&m->mu);
    uint64_t v = *field;
    pthread_mutex_unlock(&m->mu);
    return v;
}

uint64_t lr_async_published(const lr_async *a) { return locked_u64(a, &a->published); }

/* Takes the ready publication once the worker's copy has finished on the GPU. While a
 * cached state shows, only a publication of a newer state replaces it, or the converged image
 * of the interpolated state itself; an older state's is dropped. */
static bool take_ready(lr_async *a)
{
    bool took = false;
    pthread_mutex_lock(&a->mu);
    if (a->ready >= 0) {
        slot *s = &a->slots[a->ready];
        GLenum w = s->written ? glClientWaitSync(s->written, 0, 0) : GL_ALREADY_SIGNALED;
        if (w == GL_ALREADY_SIGNALED || w == GL_CONDITION_SATISFIED) {
            bool replaces = !a->cached.on || s->batch > a->cached.batch ||
                            (s->batch == a->cached.batch && !a->cached.exact &&
                             s->stage == LR_ASYNC_FINAL);
            if (replaces) {
                a->shown = a->ready;
                took = true;
                if (a->cached.on) {
                    lr_state_cache_unpin(a->cache, &a->cached.mix);
                    a->cached.on = false;
                }
            }
            a->ready = -1;
        }
    }
    pthread_mutex_unlock(&a->mu);
    return took;
}

/* The shown cached state's images: an exact entry's own, or its mix drawn once into `mixed`
 * (scale 1). Under mu for the entries. */
static int cached_images(lr_async *a, const lr_tex **images, int *n, float *scale, lr_err *e)
{
    pthread_mutex_lock(&a->mu);
    const lr_cache_mix *m = &a->cached.mix;
    const float *sc = NULL;
    const lr_tex *t0 = lr_state_cache_images(a->cache, m->entry[0], n, &sc);
    if (!t0) {
        pthread_mutex_unlock(&a->mu);
        return lr_err_set(e, LR_EINVAL, "async: a pinned cache entry is gone");
    }
    if (m->exact) {
        memcpy(scale, sc, (size_t)*n * sizeof *scale);
        *images = t0;
        pthread_mutex_unlock(&a->mu);
        return LR_OK;
    }
    lr_mix_input in = {.n = m->n, .layers = *n};
    for (int k = 0; k < m->n; k++) {
        int nk = 0;
        const float *sk = NULL;
        in.sets[k] = lr_state_cache_images(a->cache, m->entry[k], &nk, &sk);
        if (!in.sets[k] || nk != *n) {
            pthread_mutex_unlock(&a->mu);
            return lr_err_set(e, LR_EINVAL, "async: cached states differ in their lights");
        }
        for (int b = 0; b < 3; b++)
            in.a[k][b] = m->w[k][b];
        for (int l = 0; l < *n; l++)
            in.d[k][l] = sk[l] > 0.0f ? sk[l] : 1.0;
    }
    pthread_mutex_unlock(&a->mu);
    for (int l = 0; l < *n; l++)
        scale[l] = 1.0f;
    *images = a->mixed;
    if (a->cached.drawn)
        return LR_OK;
    if (!a->mixed || a->mixed_n != *n) {
        lr_tex_destroy(a->mixed);
        a->mixed = NULL;
        lr_tex_desc td = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F, .width = a->width,
                          .height = a->height, .layers = *n, .label = "interpolated images"};
        int rc = lr_tex_create(a->gl, &td, &a->mixed, e);
        if (rc)
            return rc;
        a->mixed_n = *n;
    }
    *images = a->mixed;
    return lr_mix_run(a->mix, &in, a->mixed, e);
}

int lr_async_frame(lr_async *a, lr_async_frame_stats *st, lr_err *e)
{
    uint64_t drain;
    if (read(a->efd, &drain, sizeof drain) < 0) {
        /* EAGAIN: nothing was signalled */
    }
    double t0 = now_ms();
    lr_async_frame_stats out = {0};
    out.new_images = take_ready(a);
    if (a->shown < 0 && !a->cached.on) {
        if (st)
            *st = out;
        return LR_OK; /* nothing published yet: nothing to draw */
    }
    slot *s = a->cached.on ? NULL : &a->slots[a->shown]; /* the worker leaves it alone */
    const lr_tex *images = s ? s->tex : NULL;
    int n_images = s ? s->n : 0;
    float cscale[LR_SCENE_MAX_LIGHTS];
    const float *scale = s ? s->scale : cscale;
    if (!s) {
        int rc = cached_images(a, &images, &n_images, cscale, e);
        if (rc)
            return rc;
        if (!a->cached.drawn) {
            a->cached.drawn = true;
            out.new_images = true;
            pthread_mutex_lock(&a->mu);
            a->n_stage[a->cached.exact ? LR_ASYNC_CACHED : LR_ASYNC_INTERPOLATED]++;
            pthread_mutex_unlock(&a->mu);
        }
    }
    lr_blend_input in = {.images = images, .n = n_images, .exposure =
                         (float)lr_scene_render(a->scene)->exposure,
                         .tonemap_op = LR_RENDER_TONEMAP};
    int nl = lr_scene_light_count(a->scene);
    if (in.n > nl)
        in.n = nl;
    if (in.n > LR_BLEND_MAX_IMAGES)
        in.n = LR_BLEND_MAX_IMAGES;
    for (int l = 0; l < in.n; l++) {
        const lr_light *light = lr_scene_light_at(a->scene, l);
        double I[3], f = 1.0;
        lr_light_rgb(light, I);
        if (a->clock_set && light->flicker.amplitude > 0.0)
            lr_light_flicker_at(light, a->time_s, &f, NULL);
        for (int b = 0; b < 3; b++)
            in.w[l][b] = I[b] * f / scale[l];
    }
    int rc = lr_blend_run(a->blend, &in, e);
    if (rc)
        return rc;
    GLsync read = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    pthread_mutex_lock(&a->mu);
    if (s) {
        if (s->read)
            glDeleteSync(s->read);
        s->read = read;
        out.worker = s->st;
        out.stage = s->stage;
        out.batch = s->batch;
    } else {
        /* The cache's textures are only ever dropped by the worker once unpinned; its
         * deletion waits for the GL's own use of them. */
        glDeleteSync(read);
        out.worker.converged = a->cached.exact;
        out.stage = a->cached.exact ? LR_ASYNC_CACHED : LR_ASYNC_INTERPOLATED;
        out.batch = a->cached.batch;
    }
    pthread_mutex_unlock(&a->mu);
    a->blend_due = false;
    out.blend_ms = now_ms() - t0;
    if (st)
        *st = out;
    return LR_OK;
}

int lr_async_wait(lr_async *a, uint64_t batch, bool final, int timeout_ms, lr_err *e)
{
    struct timespec until;
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_sec += timeout_ms / 1000;
    until.tv_nsec += (long)(timeout_ms % 1000) * 1000000L;
    if (until.tv_nsec >= 1000000000L) {
        until.tv_sec++;
        until.tv_nsec -= 1000000000L;
    }
    int rc = LR_OK;
    pthread_mutex_lock(&a->mu);
    for (;;) {
        bool have = (a->ready >= 0 || a->shown >= 0 || a->cached.on) && a->published >= batch;
        if (have && (!final || (!a->busy && !a->queue.n)))
            break;
        if (a->err_rc) {
            rc = a->err_rc;
            *e = a->err;
            a->err_rc = LR_OK;
            break;
        }
        if (pthread_cond_timedwait(&a->cv, &a->mu, &until) == ETIMEDOUT) {
            rc = lr_err_set(e, LR_ETIMEOUT, "async: no image of change %llu within %d ms",
                            (unsigned long long)batch, timeout_ms);
            break;
        }
    }
    pthread_mutex_unlock(&a->mu);
    return rc;
}

int lr_async_error(lr_async *a, lr_err *e)
{
    pthread_mutex_lock(&a->mu);
    int rc = a->err_rc;
    if (rc) {
        *e = a->err;
        a->err_rc = LR_OK;
    }
    pthread_mutex_unlock(&a->mu);
    return rc;
}

uint64_t lr_async_publications(const lr_async *a, lr_async_stage stage)
{
    return (unsigned)stage < LR_ASYNC_STAGES ? locked_u64(a, &a->n_stage[stage]) : 0;
}

bool lr_async_cuttable(const lr_async *a)
{
    lr_async *m = (lr_async *)a;
    pthread_mutex_lock(&m->mu);
    bool c = a->cancellable;
    pthread_mutex_unlock(&m->mu);
    return c;
}

uint64_t lr_async_cancelled(const lr_async *a) { return locked_u64(a, &a->n_cancelled); }

int lr_async_event_fd(const lr_async *a) { return a->efd; }

int lr_async_anticipate(lr_async *a, const lr_async_state *states, int n, lr_err *e)
{
    if (n < 0 || n > LR_ASYNC_MAX_STATES)
        return lr_err_set(e, LR_EINVAL, "async: %d states to build ahead; at most %d", n,
                          LR_ASYNC_MAX_STATES);
    if (!a->cache)
        return LR_OK;
    lr_async_state *w = NULL;
    if (n > 0) {
        w = malloc((size_t)n * sizeof *w);
        if (!w)
            return lr_err_set(e, LR_ENOMEM, "async: out of memory");
        memcpy(w, states, (size_t)n * sizeof *w);
    }
    pthread_mutex_lock(&a->mu);
    free(a->wishes);
    a->wishes = w;
    a->n_wishes = n;
    a->next_wish = 0;
    pthread_cond_broadcast(&a->cv);
    pthread_mutex_unlock(&a->mu);
    return LR_OK;
}

void lr_async_cache_stats(const lr_async *a, lr_state_cache_stats *st, int *pending)
{
    lr_async *m = (lr_async *)a;
    *st = (lr_state_cache_stats){0};
    pthread_mutex_lock(&m->mu);
    if (a->cache)
        lr_state_cache_get_stats(a->cache, st);
    if (pending)
        *pending = a->n_wishes - a->next_wish;
    pthread_mutex_unlock(&m->mu);
}

int lr_async_read_rgba8(lr_async *a, unsigned char *out, lr_err *e)
{
    return lr_blend_read_rgba8(a->blend, out, e);
}

int lr_async_read_hdr(lr_async *a, float *rgb, lr_err *e)
{
    if (a->shown < 0 && !a->cached.on)
        return lr_err_set(e, LR_EINVAL, "async: no image yet");
    return lr_blend_read_hdr(a->blend, rgb, e);
}

int lr_async_present(lr_async *a, lr_err *e) { return lr_blend_present(a->blend, e); }

void lr_async_size(const lr_async *a, int *width, int *height)
{
    if (width)
        *width = a->width;
    if (height)
        *height = a->height;
}
