/* lamprig planner — re-planning an object after a material change (see replan.h). */
#include "render/plan/replan.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/paths.h"
#include "render/plan/choose.h"

#define MAX_SCENES 32

/* What decides an object's plan and can change with its material. */
typedef struct snapshot {
    double sigma_t_prime[3], albedo_prime[3], eta, thickness_mm;
} snapshot;

typedef struct measured {
    char name[LR_PLAN_TEXT_MAX];
    lr_plan_features f;
} measured;

struct lr_replan {
    lr_plan_table *table;
    lr_plan plan;
    unsigned models;
    char key[LR_PLAN_TEXT_MAX]; /* the scene's own name in the table */
    int nmeasured;
    measured scenes[MAX_SCENES];
    snapshot planned[LR_PLAN_MAX_OBJECTS];     /* each object's material when last planned */
    enum lr_sss_model model[LR_PLAN_MAX_OBJECTS]; /* the model the planner last applied */
    bool pinned[LR_PLAN_MAX_OBJECTS];
    lr_render_settings written; /* the settings the planner last wrote */
    int count;
};

static snapshot snap(const lr_scene_object *o)
{
    snapshot x;
    memset(&x, 0, sizeof x);
    memcpy(x.sigma_t_prime, o->coeffs.sigma_t_prime, sizeof x.sigma_t_prime);
    memcpy(x.albedo_prime, o->coeffs.albedo_prime, sizeof x.albedo_prime);
    x.eta = o->coeffs.eta;
    x.thickness_mm = o->thickness_mm;
    return x;
}

static bool same(const snapshot *a, const snapshot *b)
{
    for (int j = 0; j < 3; j++)
        if (a->sigma_t_prime[j] != b->sigma_t_prime[j] || a->albedo_prime[j] != b->albedo_prime[j])
            return false;
    return a->eta == b->eta && a->thickness_mm == b->thickness_mm;
}

int lr_replan_create(const lr_scene *s, lr_plan_table *t, const lr_plan *p,
                     const lr_plan_options *opt, lr_replan **out, lr_err *e)
{
    *out = NULL;
    if (p->nobjects != lr_scene_object_count(s) || p->nobjects > LR_PLAN_MAX_OBJECTS) {
        lr_plan_table_destroy(t);
        return lr_err_set(e, LR_EINVAL, "re-plan: the plan has %d objects, the scene %d",
                          p->nobjects, lr_scene_object_count(s));
    }
    lr_replan *r = calloc(1, sizeof *r);
    if (!r) {
        lr_plan_table_destroy(t);
        return lr_err_set(e, LR_ENOMEM, "re-plan: out of memory");
    }
    r->table = t;
    r->plan = *p;
    r->models = opt && opt->models ? opt->models : LR_PLAN_MODEL_ALL;
    r->written = p->settings;
    lr_plan_scene_key(s, r->key, sizeof r->key);
    for (int i = 0; i < p->nobjects; i++) {
        r->planned[i] = snap(lr_scene_object_at(s, i));
        if (!lr_sss_model_parse(p->objects[i].row.model, &r->model[i]))
            r->pinned[i] = true; /* cannot happen: the plan only picks rows of known models */
    }
    /* The measured scenes' features at their shipped materials, once: matching after a
     * change then costs a few comparisons, not a scene load (a knob fades through many
     * materials). */
    const char *configs = opt && opt->configs_dir ? opt->configs_dir : lr_configs_dir();
    for (int i = 0; i < lr_plan_table_count(t) && r->nmeasured < MAX_SCENES; i++) {
        const char *nm = lr_plan_table_row(t, i)->scene;
        bool seen = false;
        for (int j = 0; j < r->nmeasured && !seen; j++)
            seen = !strcmp(r->scenes[j].name, nm);
        if (seen)
            continue;
        char path[1024], leaf[LR_PLAN_TEXT_MAX + 8];
        snprintf(leaf, sizeof leaf, "%s.json", nm);
        lr_scene *ms = NULL;
        lr_err le = {0};
        if (lr_path_join(path, sizeof path, configs, "scenes", leaf) ||
            lr_scene_load(path, NULL, &ms, &le))
            continue; /* not matchable; its rows are still used when it is the load-time match */
        measured *m = &r->scenes[r->nmeasured++];
        snprintf(m->name, sizeof m->name, "%s", nm);
        lr_plan_features_of(ms, 0, &m->f);
        lr_scene_destroy(ms);
    }
    *out = r;
    return LR_OK;
}

void lr_replan_destroy(lr_replan *r)
{
    if (!r)
        return;
    lr_plan_table_destroy(r->table);
    free(r);
}

const lr_plan *lr_replan_plan(const lr_replan *r) { return &r->plan; }
bool lr_replan_pinned(const lr_replan *r, int i)
{
    return i >= 0 && i < r->plan.nobjects && r->pinned[i];
}
int lr_replan_count(const lr_replan *r) { return r->count; }

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

/* The measured scene nearest to the object with its new material; -1 when none could be
 * loaded (then the load-time match stays). Ties go to the object's own scene. */
static int match(const lr_replan *r, const lr_plan_features *f)
{
    int best = -1;
    double bd = INFINITY;
    for (int pass = 0; pass < 2; pass++)
        for (int j = 0; j < r->nmeasured; j++) {
            bool own = !strcmp(r->scenes[j].name, r->key);
            if (own != (pass == 0))
                continue;
            double d = lr_plan_feature_distance(f, &r->scenes[j].f);
            if (d < bd) {
                bd = d;
                best = j;
            }
        }
    return best;
}

/* Re-chooses object i's row with its current material into *c. */
static int replan_object(lr_replan *r, const lr_scene *s, int i, lr_plan_choice *c, lr_err *e)
{
    const lr_plan_choice *old = &r->plan.objects[i];
    const lr_scene_object *o = lr_scene_object_at(s, i);
    memset(c, 0, sizeof *c);
    snprintf(c->object, sizeof c->object, "%s", old->object);
    c->analysis = old->analysis; /* geometry, lights and receivers did not change */
    c->analysis.features.size_tr = lr_plan_size_tr(o);
    const lr_plan_features *f = &c->analysis.features;
    int j = match(r, f);
    char mine[128], theirs[128];
    lr_plan_features_text(f, mine, sizeof mine);
    if (j < 0) {
        snprintf(c->table_scene, sizeof c->table_scene, "%s", old->table_scene);
        reason(c, "re-planned for material '%s' (%s): no measured scene could be loaded to "
                  "compare, rows of '%s' as at load", o->material.name, mine, c->table_scene);
    } else {
        const measured *m = &r->scenes[j];
        snprintf(c->table_scene, sizeof c->table_scene, "%s", m->name);
        double lr = m->f.size_tr > 0 && f->size_tr > 0 ? fabs(log(f->size_tr / m->f.size_tr))
                                                        : INFINITY;
        reason(c, "re-planned for material '%s' (%s): the table has no rows for it; rows of "
                  "'%s', measured with its own material at %.1f diffusion lengths (|ln| of the "
                  "size ratio %.2f): errors are that material's",
               o->material.name, mine, m->name, m->f.size_tr, lr);
        if (strcmp(m->name, r->key))
            reason(c, "'%s' is nearer by features than '%s' itself (%s)", m->name, r->key,
                   lr_plan_features_text(&m->f, theirs, sizeof theirs));
    }
    c->scene_matched = !strcmp(c->table_scene, r->key);
    bool need_vpl = c->analysis.receivers_seeing != 0;
    if (!need_vpl)
        reason(c, "no receiver sees %s: VPL pass off", o->name);
    else
        reason(c, "rows with the VPL pass %s only (the view's, fixed at load)",
               r->plan.vpl ? "on" : "off");
    return lr_plan_choose(s, i, r->table, &r->plan.budget, r->models,
                          need_vpl ? (r->plan.vpl ? 1 : 0) : -1,
                          lr_plan_table_has_scene(r->table, r->key) ? r->key : NULL, c, e);
}

/* The scene-wide settings from the choices, as lr_plan_create merges them. */
static void merge(lr_plan *p, const lr_scene *s)
{
    lr_render_settings *rs = &p->settings;
    rs->K = rs->N = rs->map_size = rs->gbuffer_size = rs->frames = 0;
    int nvpl = 0;
    p->feasible = true;
    for (int i = 0; i < p->nobjects; i++) {
        const lr_plan_row *w = &p->objects[i].row;
        rs->K = w->K > rs->K ? w->K : rs->K;
        rs->N = w->N > rs->N ? w->N : rs->N;
        rs->map_size = w->map_size > rs->map_size ? w->map_size : rs->map_size;
        rs->gbuffer_size = w->gbuffer_size > rs->gbuffer_size ? w->gbuffer_size : rs->gbuffer_size;
        rs->frames = w->frames > rs->frames ? w->frames : rs->frames;
        if (p->objects[i].vpl)
            nvpl = w->N_vpl > nvpl ? w->N_vpl : nvpl;
        p->feasible &= p->objects[i].feasible;
    }
    rs->N_vpl = p->vpl && nvpl ? nvpl : lr_scene_render(s)->N_vpl;
}

/* Writes the merged settings where they changed and nobody else has touched them. */
static int write_settings(lr_replan *r, lr_scene *s, unsigned *dirty, lr_err *e)
{
    const lr_render_settings *now = lr_scene_render(s), *want = &r->plan.settings;
    lr_render_settings *w = &r->written;
    struct {
        const char *key;
        int now, want, *written;
    } f[] = {{"render.K", now->K, want->K, &w->K},
             {"render.N", now->N, want->N, &w->N},
             {"render.N_vpl", now->N_vpl, want->N_vpl, &w->N_vpl},
             {"render.map_size", now->map_size, want->map_size, &w->map_size},
             {"render.gbuffer_size", now->gbuffer_size, want->gbuffer_size, &w->gbuffer_size},
             {"render.frames", now->frames, want->frames, &w->frames}};
    for (size_t k = 0; k < sizeof f / sizeof *f; k++) {
        if (f[k].want == *f[k].written || f[k].now != *f[k].written)
            continue;
        char v[32];
        snprintf(v, sizeof v, "%d", f[k].want);
        int rc = lr_scene_set(s, f[k].key, v, dirty, e);
        if (rc)
            return lr_err_prefix(e, "re-plan");
        *f[k].written = f[k].want;
    }
    return LR_OK;
}

typedef struct text {
    char *buf;
    size_t len, cap;
} text;

static int append(text *t, const char *s, size_t n)
{
    if (t->len + n + 1 > t->cap) {
        size_t cap = 2 * (t->len + n + 1);
        char *b = realloc(t->buf, cap);
        if (!b)
            return LR_ENOMEM;
        t->buf = b;
        t->cap = cap;
    }
    memcpy(t->buf + t->len, s, n);
    t->len += n;
    t->buf[t->len] = '\0';
    return LR_OK;
}

int lr_replan_update(lr_replan *r, lr_scene *s, unsigned changed, unsigned *dirty, char **out,
                     int *replanned, lr_err *e)
{
    if (out)
        *out = NULL;
    if (replanned)
        *replanned = 0;
    if (!(changed & LR_DIRTY_MATERIAL) || r->plan.nobjects != lr_scene_object_count(s))
        return LR_OK;
    text t = {0};
    int n = 0, said = 0, rc = LR_OK;
    lr_plan_choice *c = malloc(sizeof *c);
    if (!c)
        return lr_err_set(e, LR_ENOMEM, "re-plan: out of memory");
    for (int i = 0; i < r->plan.nobjects && !rc; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        if (!r->pinned[i] && o->sss_model != r->model[i])
            r->pinned[i] = true; /* someone else chose its model: leave it to them */
        snapshot now = snap(o);
        if (r->pinned[i] || same(&now, &r->planned[i]))
            continue;
        lr_err pe = {0};
        const char *was = r->plan.objects[i].row.model;
        char line[LR_PLAN_REASON_MAX + 128];
        if (replan_object(r, s, i, c, &pe)) {
            int k = snprintf(line, sizeof line, "plan: %s: re-plan for material '%s' failed: "
                             "%s; keeping %s\n", o->name, o->material.name, pe.msg, was);
            if (append(&t, line, (size_t)k < sizeof line ? (size_t)k : sizeof line - 1))
                rc = LR_ENOMEM;
            r->planned[i] = now; /* do not retry the same material every frame */
            continue;
        }
        bool changed_model = strcmp(c->row.model, was) != 0;
        /* Said only when the choice changed: a knob fading through materials re-plans every
         * frame of the fade, mostly to the same row. */
        bool changed_row = changed_model || c->row.line != r->plan.objects[i].row.line ||
                           c->predicted_error != r->plan.objects[i].predicted_error;
        char prev[LR_PLAN_TEXT_MAX];
        snprintf(prev, sizeof prev, "%s", was);
        r->plan.objects[i] = *c;
        r->planned[i] = now;
        n++;
        if (changed_model) {
            char key[32];
            snprintf(key, sizeof key, "objects[%d].model", i);
            if ((rc = lr_scene_set(s, key, c->row.model, dirty, e)))
                break;
            lr_sss_model_parse(c->row.model, &r->model[i]);
        }
        if (!changed_row)
            continue;
        said++;
        size_t need = lr_plan_format_choice(c, NULL, 0);
        char *buf = malloc(need + 1);
        if (!buf) {
            rc = LR_ENOMEM;
            break;
        }
        lr_plan_format_choice(c, buf, need + 1);
        rc = append(&t, buf, need);
        free(buf);
        int k = snprintf(line, sizeof line, "plan: %s: model %s%s%s after the material change\n",
                         c->object, changed_model ? prev : c->row.model,
                         changed_model ? " -> " : " kept", changed_model ? c->row.model : "");
        if (!rc)
            rc = append(&t, line, (size_t)k < sizeof line ? (size_t)k : sizeof line - 1);
    }
    free(c);
    if (!rc && n) {
        merge(&r->plan, s);
        rc = write_settings(r, s, dirty, e);
    }
    if (!rc && said) {
        const lr_render_settings *rs = lr_scene_render(s);
        char line[400];
        int k = snprintf(line, sizeof line, "plan: %s: re-planned %d object%s; budget %s; render "
                         "K=%d N=%d N_vpl=%d map_size=%d gbuffer_size=%d frames=%d\n",
                         r->plan.scene, said, said == 1 ? "" : "s",
                         r->plan.feasible ? "met" : "NOT MET (closest settings chosen)", rs->K,
                         rs->N, rs->N_vpl, rs->map_size, rs->gbuffer_size, rs->frames);
        if (!rc)
            rc = append(&t, line, (size_t)k < sizeof line ? (size_t)k : sizeof line - 1);
    }
    r->count += n;
    if (rc) {
        free(t.buf);
        return rc == LR_ENOMEM ? lr_err_set(e, LR_ENOMEM, "re-plan: out of memory") : rc;
    }
    if (replanned)
        *replanned = n;
    if (out)
        *out = t.buf;
    else
        free(t.buf);
    return LR_OK;
}

int lr_replan_what_if(const lr_replan *r, lr_scene *s, unsigned changed, unsigned *dirty,
                      lr_err *e)
{
    /* A copy takes the choices, snapshots and pins; the table is only read. */
    lr_replan *t = malloc(sizeof *t);
    if (!t)
        return lr_err_set(e, LR_ENOMEM, "re-plan: out of memory");
    *t = *r;
    int rc = lr_replan_update(t, s, changed, dirty, NULL, NULL, e);
    free(t);
    return rc;
}
