/* lamprig planner — choosing, per object, a measured row that meets the budget.
 *
 * Cost is time to converge: the renderer accumulates render.frames frames and then runs no
 * pass until something changes (render/renderer.c, lr_renderer_needs_frame), so the time a
 * designer waits for the measured error is ms_gbuffer + frames x frame_ms (the first frame
 * adds the light G-buffer; later ones are accumulation frames of frame_ms each). A frame_ms
 * budget bounds one accumulation frame: the rate at which the preview refreshes while it
 * converges. */
#include "render/plan/plan.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/plan/choose.h"
#include "render/plan/limits.h"

#define MAX_SCENES 32

static void reason(lr_plan_choice *c, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void reason(lr_plan_choice *c, const char *fmt, ...)
{
    if (c->nreasons >= LR_PLAN_REASONS)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->reasons[c->nreasons++], LR_PLAN_REASON_MAX, fmt, ap);
    va_end(ap);
}

/* How the table's errors for a scene were filtered (issue 12): the smallest supersampling
 * factor among its rows. Errors from pixel-centre samples are biased high where a light pool
 * is a few pixels tall (the candle's 1.38 was 0.15 box-filtered), so the plan says which. */
static const char *pixel_filter(const lr_plan_table *t, const char *scene)
{
    int ss = -1;
    for (int i = 0; i < lr_plan_table_count(t); i++) {
        const lr_plan_row *r = lr_plan_table_row(t, i);
        if (!strcmp(r->scene, scene) && (ss < 0 || r->supersample < ss))
            ss = r->supersample;
    }
    return ss >= 2 ? "errors over whole pixels as in the reference (box-filtered supersampling)"
                   : "errors from pixel-centre samples (no supersample column: biased high on "
                     "small light pools)";
}

bool lr_plan_budget_from_scene(const lr_scene *s, lr_plan_budget *out)
{
    const lr_quality *q = lr_scene_quality(s);
    out->max_error = q->max_error;
    out->frame_ms = q->frame_ms;
    out->converge_ms = q->converge_ms;
    out->change_ms = q->change_ms;
    return q->max_error > 0 || q->frame_ms > 0 || q->converge_ms > 0;
}

bool lr_plan_budget_resolve(const lr_scene *s, const lr_plan_budget *given, lr_plan_budget *out)
{
    lr_plan_budget_from_scene(s, out);
    /* An error, frame or converge budget given is the budget's kind: it replaces the scene's
     * three (a frame-only budget is frame-only), while change_ms, no budget by itself, is kept
     * unless given. */
    if (given->max_error > 0 || given->frame_ms > 0 || given->converge_ms > 0) {
        out->max_error = given->max_error > 0 ? given->max_error : 0.0;
        out->frame_ms = given->frame_ms > 0 ? given->frame_ms : 0.0;
        out->converge_ms = given->converge_ms > 0 ? given->converge_ms : 0.0;
    }
    if (given->change_ms > 0)
        out->change_ms = given->change_ms;
    return out->max_error > 0 || out->frame_ms > 0 || out->converge_ms > 0;
}

/* The scene file's base name without extension: what the bench writes in `scene`. */
void lr_plan_scene_key(const lr_scene *s, char *buf, size_t cap)
{
    const char *p = lr_scene_path(s);
    if (!p || !*p)
        p = lr_scene_name(s);
    const char *slash = strrchr(p, '/');
    snprintf(buf, cap, "%s", slash ? slash + 1 : p);
    char *dot = strrchr(buf, '.');
    if (dot && dot != buf)
        *dot = '\0';
}

double lr_plan_feature_distance(const lr_plan_features *a, const lr_plan_features *b)
{
    /* Light inside or outside and solid or shell change which paths dominate (seed 003's
     * stereographic lookup; transmission through a wall); convexity changes coverage; the
     * size in diffusion lengths changes how far light spreads. Weights order these. */
    double d = 4.0 * (a->enclosed != b->enclosed) + 4.0 * (a->shell != b->shell) +
               2.0 * (a->convex != b->convex);
    if (a->size_tr > 0 && b->size_tr > 0)
        d += fabs(log(a->size_tr / b->size_tr));
    return d;
}

const char *lr_plan_features_text(const lr_plan_features *f, char *buf, size_t cap)
{
    snprintf(buf, cap, "%s, %s, %s, %.1f diffusion lengths",
             f->enclosed ? "light enclosed" : "light outside", f->shell ? "thin shell" : "solid",
             f->convex ? "convex" : "not convex", f->size_tr);
    return buf;
}

/* The measured scene nearest to object `index` by features (see feature_distance). */
static int nearest_scene(const lr_scene *s, int index, const lr_plan_table *t,
                         const char *configs, char *out, size_t cap, char *why,
                         char *why_theirs, size_t whycap, lr_err *e)
{
    const char *names[MAX_SCENES];
    int n = 0;
    for (int i = 0; i < lr_plan_table_count(t) && n < MAX_SCENES; i++) {
        const char *nm = lr_plan_table_row(t, i)->scene;
        bool seen = false;
        for (int j = 0; j < n && !seen; j++)
            seen = !strcmp(names[j], nm);
        if (!seen)
            names[n++] = nm;
    }
    lr_plan_features mine;
    lr_plan_features_of(s, index, &mine);
    double best = INFINITY;
    lr_plan_features best_f = {0};
    char skipped[200] = "";
    for (int i = 0; i < n; i++) {
        char path[1024];
        char leaf[LR_PLAN_TEXT_MAX + 8];
        snprintf(leaf, sizeof leaf, "%s.json", names[i]);
        lr_scene *ms = NULL;
        lr_err le = {0};
        if (lr_path_join(path, sizeof path, configs, "scenes", leaf) ||
            lr_scene_load(path, NULL, &ms, &le)) {
            size_t l = strlen(skipped);
            snprintf(skipped + l, sizeof skipped - l, "%s%s", l ? ", " : "", names[i]);
            continue;
        }
        lr_plan_features f;
        lr_plan_features_of(ms, 0, &f);
        lr_scene_destroy(ms);
        double d = lr_plan_feature_distance(&mine, &f);
        if (d < best) {
            best = d;
            best_f = f;
            snprintf(out, cap, "%s", names[i]);
        }
    }
    if (!isfinite(best))
        return lr_err_set(e, LR_EINVAL,
                          "planner: scene '%s' is not in %s and none of its measured scenes "
                          "could be loaded from %s/scenes to compare features (%s)",
                          lr_scene_name(s), lr_plan_table_name(t), configs, skipped);
    lr_plan_features_text(&mine, why, whycap);
    lr_plan_features_text(&best_f, why_theirs, whycap);
    return LR_OK;
}

typedef struct cand {
    const lr_plan_row *row;
    double err, fms, conv;
} cand;

/* Whether a is better than b under the budget (both feasible). */
static bool better(const cand *a, const cand *b, const lr_plan_budget *bu)
{
    if (bu->max_error > 0) { /* soonest converged, then lower error, then faster frames */
        if (a->conv != b->conv)
            return a->conv < b->conv;
        if (a->err != b->err)
            return a->err < b->err;
        return a->fms < b->fms;
    }
    if (a->err != b->err) /* a time budget only: lowest error */
        return a->err < b->err;
    if (a->conv != b->conv)
        return a->conv < b->conv;
    return a->fms < b->fms;
}

static double shortfall(const cand *c, const lr_plan_budget *b)
{
    double r = 0.0;
    if (b->max_error > 0)
        r = fmax(r, c->err / b->max_error);
    if (b->frame_ms > 0)
        r = fmax(r, c->fms / b->frame_ms);
    if (b->converge_ms > 0)
        r = fmax(r, c->conv / b->converge_ms);
    return r;
}

/* Whether row model `model` is allowed and object o can render with it as it stands: its
 * geometry (lr_scene_object_model_unmet) and its material's validity limits
 * (lr_plan_model_limit); the first time a model is left out for the object, says why in the
 * reasons. */
static bool model_ok(const char *model, unsigned models, const lr_scene_object *o,
                     lr_plan_choice *c, unsigned *said)
{
    enum lr_sss_model m;
    if (!lr_sss_model_parse(model, &m) || !(models & LR_PLAN_MODEL_BIT(m)))
        return false;
    char buf[LR_PLAN_REASON_MAX - LR_PLAN_TEXT_MAX - 16];
    const char *why = lr_scene_object_model_unmet(o, m);
    if (!why)
        why = lr_plan_model_limit(o, m, buf, sizeof buf);
    if (why && !(*said & LR_PLAN_MODEL_BIT(m))) {
        *said |= LR_PLAN_MODEL_BIT(m);
        reason(c, "%s rows left out: %s", model, why);
    }
    return why == NULL;
}

static int plan_object(const lr_scene *s, int index, const lr_plan_table *t,
                       const lr_plan_budget *b, const char *configs, unsigned models,
                       lr_plan_choice *c, lr_err *e)
{
    memset(c, 0, sizeof *c);
    const lr_scene_object *o = lr_scene_object_at(s, index);
    snprintf(c->object, sizeof c->object, "%s", o->name);
    int rc = lr_plan_analyze(s, index, &c->analysis, e);
    if (rc)
        return rc;
    const lr_plan_analysis *a = &c->analysis;

    char key[LR_PLAN_TEXT_MAX];
    lr_plan_scene_key(s, key, sizeof key);
    if (lr_plan_table_has_scene(t, key)) {
        snprintf(c->table_scene, sizeof c->table_scene, "%s", key);
        c->scene_matched = true;
        reason(c, "measured on '%s', %s", key, pixel_filter(t, key));
    } else {
        char mine[128], theirs[128];
        if ((rc = nearest_scene(s, index, t, configs, c->table_scene, sizeof c->table_scene, mine,
                                theirs, sizeof mine, e)))
            return rc;
        reason(c, "scene '%s' is not in the table: nearest measured scene '%s' by features "
                  "(%s; '%s': %s)", key, c->table_scene, mine, c->table_scene, theirs);
    }

    /* VPLs carry emergent light to receivers; with none in sight they light nothing. */
    if (!a->receivers_seeing)
        reason(c, "no receiver sees %s%s: VPL pass off", o->name,
               a->receivers_checked ? "" : " (the scene has none)");

    if (a->features.convex)
        reason(c, "convex: %d map%s cover %.1f %% of the surface (no self-occlusion)", a->K_cover,
               a->K_cover == 1 ? "" : "s", 100.0 * a->coverage[a->K_cover - 1]);
    else
        reason(c, "not convex (vertices up to %.1f mm outside a face plane): %d maps to cover %.1f %%",
               a->convex_violation_mm, a->K_cover, 100.0 * a->coverage[a->K_cover - 1]);
    return lr_plan_choose(s, index, t, b, models, -1, NULL, c, e);
}

/* The row of scene `scene` with r's model and settings (any frames: a frame's cost does not
 * depend on how many are accumulated), the slowest when measured more than once; NULL when
 * none. */
static const lr_plan_row *timing_row(const lr_plan_table *t, const char *scene,
                                     const lr_plan_row *r)
{
    const lr_plan_row *best = NULL;
    for (int i = 0; i < lr_plan_table_count(t); i++) {
        const lr_plan_row *q = lr_plan_table_row(t, i);
        if (strcmp(q->scene, scene) || strcmp(q->model, r->model) || q->K != r->K ||
            q->N != r->N || q->N_vpl != r->N_vpl || q->map_size != r->map_size ||
            q->gbuffer_size != r->gbuffer_size || q->vpl != r->vpl || q->lpv != r->lpv ||
            !isfinite(q->frame_ms))
            continue;
        if (!best || q->frame_ms > best->frame_ms)
            best = q;
    }
    return best;
}

int lr_plan_choose(const lr_scene *s, int index, const lr_plan_table *t, const lr_plan_budget *b,
                   unsigned models, int vpl_rows, const char *time_scene, lr_plan_choice *c,
                   lr_err *e)
{
    /* Times from another scene than the errors (the re-plan: time_scene is the object's own). */
    bool other_times = time_scene && strcmp(time_scene, c->table_scene);
    const char *cost_scene = other_times ? time_scene : c->table_scene;
    int n_timed = 0;
    const lr_scene_object *o = lr_scene_object_at(s, index);
    const lr_plan_analysis *a = &c->analysis;
    bool need_vpl = a->receivers_seeing != 0;
    /* Candidates: the measured scene's rows with a model the renderer runs and at least
     * K_cover maps (the bench measures one view; coverage must hold for every view). */
    int n = lr_plan_table_count(t), ncand = 0, nscene = 0, kmax = 0, ndark = 0;
    unsigned said = 0;
    cand *cs = malloc((size_t)(n > 0 ? n : 1) * sizeof *cs);
    if (!cs)
        return lr_err_set(e, LR_ENOMEM, "planner: out of memory");
    /* Models whose material change is measured slower than the budget's change_ms are left
     * out while another remains (change_slow: one bit per model, said once). */
    unsigned change_slow = 0;
    for (int m = 0; m < LR_SSS_MODEL_COUNT && b->change_ms > 0; m++) {
        if (!(models & LR_PLAN_MODEL_BIT(m)))
            continue;
        const char *name = lr_sss_model_name((enum lr_sss_model)m);
        /* The cost measured on the matched scene; a scene the models table lacks takes the
         * model's slowest measured scene (a rebuild's cost grows with the object, and a
         * designer waits on the worst). */
        const lr_plan_row *here = NULL, *worst = NULL;
        for (int i = 0; i < n; i++) {
            const lr_plan_row *r = lr_plan_table_row(t, i);
            if (strcmp(r->model, name) || !isfinite(r->ms_change))
                continue;
            if (!strcmp(r->scene, cost_scene))
                here = r;
            if (!worst || r->ms_change > worst->ms_change)
                worst = r;
        }
        const lr_plan_row *cost = here ? here : worst;
        if (!cost || !(cost->ms_change > b->change_ms))
            continue;
        change_slow |= LR_PLAN_MODEL_BIT(m);
        said |= LR_PLAN_MODEL_BIT(m);
        reason(c, "%s rows left out: a material change costs %.1f s on '%s'%s "
                  "(configs/bench/models.csv), over the budget's change_ms %.0f",
               name, cost->ms_change * 1e-3, cost->scene,
               here ? "" : " (its slowest measured scene)", b->change_ms);
    }
retry:
    for (int pass = 0; pass < 2 && !ncand; pass++) {
        for (int i = 0; i < n; i++) {
            const lr_plan_row *r = lr_plan_table_row(t, i);
            enum lr_sss_model rm;
            if (strcmp(r->scene, c->table_scene) || (vpl_rows >= 0 && r->vpl != (vpl_rows > 0)) ||
                (lr_sss_model_parse(r->model, &rm) && (change_slow & LR_PLAN_MODEL_BIT(rm))) ||
                !model_ok(r->model, models, o, c, &said))
                continue;
            /* A row that leaves a region of the measured view dark (lr_plan_row_dark: band
             * power at a tenth of the reference's or less, inf for the wall of a row without
             * VPLs): while a receiver sees the object, its light would be missing there, so
             * the row never wins, however small its error reads elsewhere. */
            if (need_vpl && lr_plan_row_dark(r)) {
                ndark += !pass;
                continue;
            }
            if (!pass) {
                nscene++;
                if (r->K > kmax)
                    kmax = r->K;
            }
            /* pass 0: K >= K_cover; pass 1 (none had that many maps): the most maps measured */
            if (pass == 0 ? r->K < a->K_cover : r->K < kmax)
                continue;
            const lr_plan_row *tr = other_times ? timing_row(t, time_scene, r) : NULL;
            n_timed += !pass && tr;
            if (!tr)
                tr = r;
            cand x = {.row = r, .err = lr_plan_row_error(r), .fms = tr->frame_ms};
            if (!need_vpl && tr->vpl && isfinite(tr->ms_vpl))
                x.fms = fmax(tr->frame_ms - tr->ms_vpl, 0.0);
            x.conv = (isfinite(tr->ms_gbuffer) ? tr->ms_gbuffer : 0.0) + r->frames * x.fms;
            /* render.lpv: the volume is built once, on the first frame (its own pass). */
            if (r->lpv > 0 && isfinite(tr->ms_lpv))
                x.conv += tr->ms_lpv;
            cs[ncand++] = x;
        }
        if (!pass && ndark)
            reason(c, "%d row%s left out: %s a region dark (at a tenth of its light or "
                      "less), and a receiver sees %s", ndark, ndark == 1 ? "" : "s",
                   ndark == 1 ? "it leaves" : "they leave", o->name);
        if (!ncand && nscene && !pass)
            reason(c, "no measured row has K >= %d: using the most maps measured (K = %d)",
                   a->K_cover, kmax);
        if (!nscene)
            break;
    }
    if (!ncand && change_slow) {
        reason(c, "no other model has usable rows: the slow material changes kept");
        change_slow = 0;
        nscene = kmax = ndark = 0;
        goto retry;
    }
    if (!ncand) {
        free(cs);
        return lr_err_set(e, LR_EINVAL, "planner: %s: no row of scene '%s' in %s with a model "
                          "allowed (--models) that the object can take%s",
                          o->name, c->table_scene, lr_plan_table_name(t),
                          ndark ? " and that lights every region in sight (the others leave "
                                  "one dark)" : "");
    }

    if (other_times)
        reason(c, "times from '%s' itself at the same settings for %d of %d rows (a frame's "
                  "cost follows the geometry, receivers and image, not the material)%s%s%s",
               time_scene, n_timed, nscene, n_timed < nscene ? "; the others from '" : "",
               n_timed < nscene ? c->table_scene : "", n_timed < nscene ? "'" : "");
    const cand *best = NULL;
    int nfeas = 0;
    for (int i = 0; i < ncand; i++) {
        const cand *x = &cs[i];
        /* A budget holds only with a finite predicted error and every region lit: a
         * frame-only budget says nothing of the error, but a row that leaves a region dark
         * (no receiver in sight, so still a candidate) meets nothing. */
        bool ok = isfinite(x->err) && !lr_plan_row_dark(x->row) &&
                  (b->max_error <= 0 || x->err <= b->max_error) &&
                  (b->frame_ms <= 0 || x->fms <= b->frame_ms) &&
                  (b->converge_ms <= 0 || x->conv <= b->converge_ms);
        if (!ok)
            continue;
        nfeas++;
        if (!best || better(x, best, b))
            best = x;
    }
    c->feasible = best != NULL;
    if (best) {
        reason(c, "%s of %d measured settings meeting the budget (of %d)",
               b->max_error > 0 ? "soonest converged" : "lowest error", nfeas, ncand);
    } else {
        for (int i = 0; i < ncand; i++)
            if (!best || shortfall(&cs[i], b) < shortfall(best, b) ||
                (shortfall(&cs[i], b) == shortfall(best, b) && better(&cs[i], best, b)))
                best = &cs[i];
        reason(c, "INFEASIBLE: none of %d measured settings meets the budget; closest picked "
                  "(%.2fx the budget)", ncand, shortfall(best, b));
    }
    c->row = *best->row;
    c->vpl = need_vpl && best->row->vpl;
    c->predicted_error = best->err;
    c->predicted_frame_ms = best->fms;
    c->predicted_converge_ms = best->conv;
    free(cs);
    return LR_OK;
}

int lr_plan_create(const lr_scene *s, const lr_plan_table *t, const lr_plan_budget *b,
                   const lr_plan_options *opt, lr_plan *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    if (!(b->max_error > 0) && !(b->frame_ms > 0) && !(b->converge_ms > 0))
        return lr_err_set(e, LR_EINVAL, "planner: no budget (quality.max_error, "
                                        "quality.frame_ms or quality.converge_ms, > 0)");
    if (!isfinite(b->max_error) || !isfinite(b->frame_ms) || !isfinite(b->converge_ms) ||
        b->max_error < 0 || b->frame_ms < 0 || b->converge_ms < 0)
        return lr_err_set(e, LR_EINVAL, "planner: budget must be finite and >= 0");
    int no = lr_scene_object_count(s);
    if (no > LR_PLAN_MAX_OBJECTS)
        return lr_err_set(e, LR_EINVAL, "planner: %d objects, at most %d", no,
                          LR_PLAN_MAX_OBJECTS);
    const char *configs = opt && opt->configs_dir ? opt->configs_dir : lr_configs_dir();
    unsigned models = opt && opt->models ? opt->models : LR_PLAN_MODEL_ALL;
    snprintf(out->scene, sizeof out->scene, "%s", lr_scene_name(s));
    out->budget = *b;
    out->nobjects = no;
    out->settings = *lr_scene_render(s);
    lr_render_settings *rs = &out->settings;
    rs->K = rs->N = rs->N_vpl = rs->map_size = rs->gbuffer_size = rs->frames = 0;
    rs->lpv = 0;
    out->feasible = true;
    for (int i = 0; i < no; i++) {
        lr_plan_choice *c = &out->objects[i];
        int rc = plan_object(s, i, t, b, configs, models, c, e);
        if (rc)
            return rc;
        /* One settings block drives every object: the most demanding choice wins. */
        const lr_plan_row *r = &c->row;
        rs->K = r->K > rs->K ? r->K : rs->K;
        rs->N = r->N > rs->N ? r->N : rs->N;
        rs->map_size = r->map_size > rs->map_size ? r->map_size : rs->map_size;
        rs->gbuffer_size = r->gbuffer_size > rs->gbuffer_size ? r->gbuffer_size : rs->gbuffer_size;
        rs->frames = r->frames > rs->frames ? r->frames : rs->frames;
        rs->lpv = r->lpv > rs->lpv ? r->lpv : rs->lpv;
        if (c->vpl) {
            out->vpl = true;
            rs->N_vpl = r->N_vpl > rs->N_vpl ? r->N_vpl : rs->N_vpl;
        }
        out->feasible &= c->feasible;
    }
    if (!out->vpl) /* the renderer needs a valid count even with the pass off */
        rs->N_vpl = lr_scene_render(s)->N_vpl;
    /* The light paths the scene needs with the chosen models (transport.c). */
    enum lr_sss_model chosen[LR_PLAN_MAX_OBJECTS];
    for (int i = 0; i < no; i++)
        if (!lr_sss_model_parse(out->objects[i].row.model, &chosen[i]))
            chosen[i] = lr_scene_object_at(s, i)->sss_model;
    int rc = lr_plan_transport_decide(s, chosen, &out->transport, e);
    if (rc)
        return rc;
    if (rs->lpv > 0) /* a chosen row's volume carries the receivers' light (render/lpv) */
        for (int k = 0; k < LR_PLAN_TRANSPORT_COUNT; k++) {
            out->transport.needed[k] = out->transport.on[k] = false;
            snprintf(out->transport.why[k], LR_PLAN_REASON_MAX,
                     "render.lpv's volumes carry the receivers' light");
        }
    return LR_OK;
}

int lr_plan_apply(const lr_plan *p, lr_scene *s, unsigned *dirty, lr_err *e)
{
    const struct {
        const char *key;
        int v;
    } sets[] = {{"render.K", p->settings.K},
                {"render.N", p->settings.N},
                {"render.N_vpl", p->settings.N_vpl},
                {"render.map_size", p->settings.map_size},
                {"render.gbuffer_size", p->settings.gbuffer_size},
                {"render.frames", p->settings.frames},
                {"render.lpv", p->settings.lpv}};
    for (size_t i = 0; i < sizeof sets / sizeof *sets; i++) {
        /* render.lpv only where a chosen row measured the volume: rows without it leave the
         * scene's own setting. */
        if (!strcmp(sets[i].key, "render.lpv") && sets[i].v <= 0)
            continue;
        char v[32];
        snprintf(v, sizeof v, "%d", sets[i].v);
        int rc = lr_scene_set(s, sets[i].key, v, dirty, e);
        if (rc)
            return lr_err_prefix(e, "applying the plan");
    }
    return lr_plan_apply_models(p, s, dirty, e);
}

int lr_plan_apply_models(const lr_plan *p, lr_scene *s, unsigned *dirty, lr_err *e)
{
    /* The model is the one per-object choice the renderer takes as it is. */
    for (int i = 0; i < p->nobjects; i++) {
        char key[32];
        snprintf(key, sizeof key, "objects[%d].model", i);
        int rc = lr_scene_set(s, key, p->objects[i].row.model, dirty, e);
        if (rc)
            return lr_err_prefix(e, "applying the plan");
    }
    /* The transport goes with the models: it was decided for them. */
    return lr_plan_transport_apply(&p->transport, s, dirty, e);
}

/* ---- output ---- */

typedef struct out {
    char *buf;
    size_t cap, len;
} out;

static void put(out *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(out *o, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    size_t room = o->len < o->cap ? o->cap - o->len : 0;
    int n = vsnprintf(room ? o->buf + o->len : NULL, room, fmt, ap);
    va_end(ap);
    if (n > 0)
        o->len += (size_t)n;
}

/* The budget's parts joined by `sep`, the frame budget as "<= T" + `per_frame`: the plan line
 * says "error <= 0.05 and <= 100 ms/frame", the sentence "error <= 0.05, <= 100 ms a frame". */
static void put_budget_as(out *o, const lr_plan_budget *b, const char *sep,
                          const char *per_frame)
{
    const char *s = "";
    if (b->max_error > 0) {
        put(o, "error <= %g", b->max_error);
        s = sep;
    }
    if (b->frame_ms > 0) {
        put(o, "%s<= %g%s", s, b->frame_ms, per_frame);
        s = sep;
    }
    if (b->converge_ms > 0)
        put(o, "%sconverged in <= %g s", s, b->converge_ms * 1e-3);
}

static void put_budget(out *o, const lr_plan_budget *b)
{
    put_budget_as(o, b, " and ", " ms/frame");
}

/* Whether the predicted error (the largest part) is the RMSE part's noise floor: the row's
 * error is at most that. */
static bool error_at_most(const lr_plan_error_parts *p)
{
    return p->rmse_at_most && !(p->median > p->rmse) && !(p->band > p->rmse);
}

static void put_choice(out *o, const lr_plan_choice *c)
{
    const lr_plan_row *r = &c->row;
    lr_plan_error_parts ep = lr_plan_row_error_parts(r);
    put(o, "plan: %s: %s K=%d N=%d N_vpl=%d map=%d gbuffer=%d frames=%d vpl=%s, error %s%.3g, "
           "%.0f ms/frame, converged in %.1f s%s",
        c->object, r->model, r->K, r->N, c->vpl ? r->N_vpl : 0, r->map_size, r->gbuffer_size,
        r->frames, c->vpl ? "on" : "off", error_at_most(&ep) ? "at most " : "",
        c->predicted_error, c->predicted_frame_ms, c->predicted_converge_ms / 1000.0,
        c->feasible ? "" : " [INFEASIBLE]");
    if (r->lpv > 0)
        put(o, ", light-propagation volume %d^3", r->lpv);
    if (isfinite(ep.median) || isfinite(ep.band))
        put(o, " (error: RMSE %s%.3g, median |ln| over the references' floor %.3g, worst band "
               "%.3g)", ep.rmse_at_most ? "at most " : "", ep.rmse, ep.median, ep.band);
    else if (ep.rmse_at_most)
        put(o, " (error: RMSE at most %.3g, under the reference's noise)", ep.rmse);
    for (int k = 0; k < c->nreasons; k++)
        put(o, "%s%s", k ? "; " : " (", c->reasons[k]);
    put(o, "%s\n", c->nreasons ? ")" : "");
}

size_t lr_plan_format_choice(const lr_plan_choice *c, char *buf, size_t cap)
{
    out o = {buf, cap, 0};
    if (cap)
        buf[0] = '\0';
    put_choice(&o, c);
    return o.len;
}

size_t lr_plan_format(const lr_plan *p, char *buf, size_t cap)
{
    out o = {buf, cap, 0};
    if (cap)
        buf[0] = '\0';
    for (int i = 0; i < p->nobjects; i++)
        put_choice(&o, &p->objects[i]);
    const lr_render_settings *s = &p->settings;
    put(&o, "plan: %s: budget ", p->scene);
    put_budget(&o, &p->budget);
    put(&o, "%s; render K=%d N=%d N_vpl=%d map_size=%d gbuffer_size=%d frames=%d, VPL pass %s",
        p->feasible ? " met" : " NOT MET (infeasible: closest settings chosen)", s->K, s->N,
        p->vpl ? s->N_vpl : 0, s->map_size, s->gbuffer_size, s->frames, p->vpl ? "on" : "off");
    if (s->lpv > 0)
        put(&o, ", lpv=%d", s->lpv);
    put(&o, "; after %d frames no pass runs until something changes\n", s->frames);
    char tline[LR_PLAN_TRANSPORT_COUNT * (LR_PLAN_REASON_MAX + 64) + LR_SCENE_NAME_MAX + 32];
    lr_plan_transport_format(&p->transport, p->scene, tline, sizeof tline);
    put(&o, "%s", tline);
    return o.len;
}

/* The budget as a reader says it: "error <= 0.05, <= 100 ms a frame". */
static void put_budget_words(out *o, const lr_plan_budget *b)
{
    put_budget_as(o, b, ", ", " ms a frame");
}

size_t lr_plan_format_brief(const lr_plan *p, char *buf, size_t cap)
{
    out o = {buf, cap, 0};
    if (cap)
        buf[0] = '\0';
    /* The scene's figures are its worst object's: one settings block renders them all. */
    double err = 0.0, fms = 0.0, conv = 0.0, over = 0.0;
    bool at_most = false; /* the worst error is a noise floor (error_at_most) */
    bool dark = false;    /* a chosen row leaves a region dark (lr_plan_row_dark) */
    put(&o, "plan: %s: ", p->scene);
    for (int i = 0; i < p->nobjects; i++) {
        const lr_plan_choice *c = &p->objects[i];
        put(&o, "%s%s K %d", i ? ", " : "", c->row.model, c->row.K);
        if (p->nobjects > 1)
            put(&o, " for %s", c->object);
        if (!i || !(c->predicted_error <= err)) {
            lr_plan_error_parts ep = lr_plan_row_error_parts(&c->row);
            at_most = error_at_most(&ep);
        }
        err = isfinite(c->predicted_error) && isfinite(err) ? fmax(err, c->predicted_error)
                                                            : INFINITY;
        fms = fmax(fms, c->predicted_frame_ms);
        conv = fmax(conv, c->predicted_converge_ms);
        dark |= lr_plan_row_dark(&c->row);
        over = fmax(over, shortfall(&(cand){.err = c->predicted_error,
                                            .fms = c->predicted_frame_ms,
                                            .conv = c->predicted_converge_ms},
                                    &p->budget));
    }
    if (isfinite(err))
        put(&o, ", predicted error %s%.3g%s", at_most ? "at most " : "", err,
            dark ? " (a region left dark)" : "");
    else
        put(&o, ", no finite predicted error (a region left dark)");
    if (p->budget.converge_ms > 0) /* the budget's own figure, said where it is judged */
        put(&o, ", %.0f ms a frame, converged in %.1f s on this table; the budget (", fms,
            conv * 1e-3);
    else
        put(&o, ", %.0f ms a frame on this table; the budget (", fms);
    put_budget_words(&o, &p->budget);
    if (p->feasible)
        put(&o, ") holds\n");
    else
        put(&o, isfinite(over) && over > 1.0
                    ? ") is not reachable here, the closest row shown (%.2gx over; --verbose: why)\n"
                    : ") is not reachable here, the closest row shown (--verbose: why)\n",
            over);
    return o.len;
}

static void put_json_string(out *o, const char *s)
{
    put(o, "\"");
    for (; *s; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\')
            put(o, "\\%c", ch);
        else if (ch < 0x20)
            put(o, "\\u%04x", ch);
        else
            put(o, "%c", ch);
    }
    put(o, "\"");
}

size_t lr_plan_format_json(const lr_plan *p, char *buf, size_t cap)
{
    out o = {buf, cap, 0};
    if (cap)
        buf[0] = '\0';
    put(&o, "{\"scene\":");
    put_json_string(&o, p->scene);
    put(&o, ",\"budget\":{\"max_error\":%.17g,\"frame_ms\":%.17g,\"converge_ms\":%.17g,"
            "\"change_ms\":%.17g},\"feasible\":%s,\"objects\":[",
        p->budget.max_error, p->budget.frame_ms, p->budget.converge_ms, p->budget.change_ms,
        p->feasible ? "true" : "false");
    for (int i = 0; i < p->nobjects; i++) {
        const lr_plan_choice *c = &p->objects[i];
        const lr_plan_row *r = &c->row;
        const lr_plan_analysis *a = &c->analysis;
        /* JSON has no Inf: a row that leaves a region dark (band_excess inf) writes null. */
        char error_text[32] = "null";
        if (isfinite(c->predicted_error))
            snprintf(error_text, sizeof error_text, "%.6g", c->predicted_error);
        put(&o, "%s{\"object\":", i ? "," : "");
        put_json_string(&o, c->object);
        put(&o, ",\"table_scene\":");
        put_json_string(&o, c->table_scene);
        put(&o, ",\"scene_matched\":%s,\"model\":\"%s\",\"K\":%d,\"N\":%d,\"N_vpl\":%d,"
                "\"map_size\":%d,\"gbuffer_size\":%d,\"frames\":%d,\"vpl\":%s,\"table_line\":%d,"
                "\"predicted_error\":%s,\"predicted_frame_ms\":%.6g,"
                "\"predicted_converge_ms\":%.6g,\"feasible\":%s,",
            c->scene_matched ? "true" : "false", r->model, r->K, r->N, r->N_vpl, r->map_size,
            r->gbuffer_size, r->frames, c->vpl ? "true" : "false", r->line, error_text,
            c->predicted_frame_ms, c->predicted_converge_ms, c->feasible ? "true" : "false");
        /* The error's parts where the table has them (JSON has no NaN). */
        lr_plan_error_parts ep = lr_plan_row_error_parts(r);
        const struct {
            const char *key;
            double v;
        } parts[] = {{"predicted_rmse", ep.rmse}, {"predicted_median_excess", ep.median},
                     {"predicted_band_excess", ep.band}};
        for (size_t k = 0; k < sizeof parts / sizeof parts[0]; k++)
            if (isfinite(parts[k].v))
                put(&o, "\"%s\":%.6g,", parts[k].key, parts[k].v);
        /* The RMSE part is a noise floor: the error is at most it (not measured as 0). */
        if (ep.rmse_at_most)
            put(&o, "\"predicted_rmse_at_most\":true,");
        put(&o, "\"convex\":%s,\"shell\":%s,\"enclosed\":%s,\"K_cover\":%d,\"coverage\":%.4f,"
                "\"receivers_seeing\":%d,\"reasons\":[",
            a->features.convex ? "true" : "false", a->features.shell ? "true" : "false",
            a->features.enclosed ? "true" : "false", a->K_cover, a->coverage[LR_PLAN_KMAX - 1],
            __builtin_popcount(a->receivers_seeing));
        for (int k = 0; k < c->nreasons; k++) {
            put(&o, "%s", k ? "," : "");
            put_json_string(&o, c->reasons[k]);
        }
        put(&o, "]}");
    }
    const lr_render_settings *s = &p->settings;
    put(&o, "],\"settings\":{\"K\":%d,\"N\":%d,\"N_vpl\":%d,\"map_size\":%d,\"gbuffer_size\":%d,"
            "\"frames\":%d,\"vpl\":%s},\"transport\":{",
        s->K, s->N, s->N_vpl, s->map_size, s->gbuffer_size, s->frames, p->vpl ? "true" : "false");
    /* Per path: needed, given (the scene's value stays), on (the plan turns it on), why. */
    const lr_plan_transport *t = &p->transport;
    for (int k = 0; k < LR_PLAN_TRANSPORT_COUNT; k++) {
        put(&o, "%s\"%s\":{\"needed\":%s,\"given\":%s,\"on\":%s,\"why\":", k ? "," : "",
            lr_plan_transport_key(k), t->needed[k] ? "true" : "false",
            t->given[k] ? "true" : "false", t->on[k] ? "true" : "false");
        put_json_string(&o, t->why[k]);
        put(&o, "}");
    }
    put(&o, ",\"inner_fraction\":%.4f,\"vpl_blocked\":%.4f}}\n", t->inner_fraction,
        t->vpl_blocked);
    return o.len;
}
