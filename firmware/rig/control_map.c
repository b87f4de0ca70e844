/* lamprig firmware — the control map (see control_map.h). */
#include "firmware/rig/control_map.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "firmware/control/accel.h"
#include "firmware/control/curve.h"
#include "firmware/control/fade.h"

typedef struct bstate {
    const lr_rig_binding *b;
    /* level */
    double x;      /* position 0..1 */
    lr_fade fade;  /* of the level y = curve(x) */
    lr_accel accel;
    /* cycle */
    int index;
    bool cycle_pending; /* index not yet written to the scene */
    bool cycle_applied; /* written at least once (re-written after a scene switch) */
    /* parameter group (level bindings on the same param multiply) */
    int group;
} bstate;

typedef struct group {
    const char *param;
    bool vector;                /* written as "r,g,b" */
    char last[128];             /* text last written; "" = rewrite */
    /* A light's "level" (param "light.level", "lights[i].level"): the value multiplies that
     * light's own strength in the scene as loaded, so one dimmer means the same in every scene
     * of a cycle (a tealight of 0.004 W/sr and a shade's bulb of 0.25 W/sr alike). */
    bool relative;
    bool need_base;             /* the scene was (re)loaded: read its own strength again */
    char target[160];           /* the light's "intensity" or "radiance" key */
    double base[3];
} group;

struct lr_control_map {
    const lr_rig_config *cfg;
    int n;
    bstate st[LR_RIG_MAX_BINDINGS];
    group groups[LR_RIG_MAX_BINDINGS];
    int n_groups;
    int lamp; /* binding index or -1 */
    char scene_request[LR_RIG_PATH_MAX];
    bool has_scene_request;
    unsigned garbage;
};

/* Length of the light key before ".level" ("light", "lights[bulb]"), or 0 when param is not a
 * light's level. */
static size_t level_prefix(const char *param)
{
    size_t n = strlen(param);
    if (n <= 6 || strcmp(param + n - 6, ".level") != 0)
        return 0;
    if (n == 11 && strncmp(param, "light", 5) == 0)
        return 5;
    if (strncmp(param, "lights[", 7) == 0 && param[n - 7] == ']')
        return n - 6;
    return 0;
}

/* Finds the relative group's light strength in `scene`: its intensity (point, spot) or its
 * radiance (directional, area), as the scene has it now. */
static int resolve_level(group *g, const lr_scene *scene, lr_err *e)
{
    size_t pre = level_prefix(g->param);
    char cur[256];
    lr_err le = {0};
    static const char *const fields[] = {"intensity", "radiance"};
    for (int k = 0; k < 2; k++) {
        snprintf(g->target, sizeof g->target, "%.*s.%s", (int)pre, g->param, fields[k]);
        lr_err fe = {0};
        if (lr_scene_get(scene, g->target, cur, sizeof cur, &fe) == LR_OK) {
            int n = sscanf(cur, "%lf,%lf,%lf", &g->base[0], &g->base[1], &g->base[2]);
            if (n == 1)
                g->base[1] = g->base[2] = g->base[0];
            else if (n != 3)
                return lr_err_set(e, LR_EINVAL, "%s = '%s' is not a number", g->target, cur);
            g->vector = n == 3;
            g->need_base = false;
            return LR_OK;
        }
        if (k == 0)
            le = fe;
    }
    return lr_err_set(e, le.code ? le.code : LR_EINVAL,
                      "'%s' is a light's level relative to its own intensity or radiance: %s",
                      g->param, le.msg);
}

/* The one place a curve is applied: control position → level. */
static double level_of(const lr_rig_binding *b, double x)
{
    return lr_curve_apply((enum lr_curve)b->curve, x);
}

static void value_of(const lr_rig_binding *b, double y, double out[3])
{
    if (b->is_color) {
        for (int k = 0; k < 3; k++)
            out[k] = b->colors[0][k] + (b->colors[1][k] - b->colors[0][k]) * y;
    } else {
        double v = b->range[0] + (b->range[1] - b->range[0]) * y;
        out[0] = out[1] = out[2] = v;
    }
}

static int param_fail(const lr_rig_config *cfg, int i, int line, const char *field, lr_err *e,
                      const char *msg)
{
    return lr_err_set(e, LR_EPARSE, "%s:%d: field 'controls[%d].%s': %s",
                      cfg->bindings[i].file, line, i, field, msg);
}

static void format_value(double v[3], bool vector, char *buf, size_t cap)
{
    if (vector)
        snprintf(buf, cap, "%.9g,%.9g,%.9g", v[0], v[1], v[2]);
    else
        snprintf(buf, cap, "%.9g", v[0]);
}

/* Checks the range ends / colours and every cycle value against a scratch scene. */
static int check_values(const lr_rig_config *cfg, lr_control_map *m, lr_err *e)
{
    lr_scene *scratch = NULL;
    lr_err le = {0};
    if (lr_scene_load(cfg->scene, NULL, &scratch, &le))
        return lr_err_set(e, le.code, "%s", le.msg);
    if (lr_rig_config_apply_sets(cfg, scratch, e)) {
        lr_scene_destroy(scratch);
        return LR_EPARSE;
    }
    int rc = LR_OK;
    for (int i = 0; i < m->n && !rc; i++) {
        const lr_rig_binding *b = &cfg->bindings[i];
        if (b->kind == LR_BIND_LEVEL) {
            group g = m->groups[m->st[i].group];
            if (g.relative && resolve_level(&g, scratch, &le)) {
                rc = param_fail(cfg, i, b->line_param, "param", e, le.msg);
                break;
            }
            for (int end = 0; end < 2 && !rc; end++) {
                double v[3];
                value_of(b, end, v);
                if (g.relative)
                    for (int k = 0; k < 3; k++)
                        v[k] *= g.base[k];
                char text[128];
                format_value(v, g.vector, text, sizeof text);
                if (lr_scene_set(scratch, g.relative ? g.target : b->param, text, NULL, &le)) {
                    char msg[LR_ERR_MSG_MAX];
                    snprintf(msg, sizeof msg, "the scene rejects %s = %s: %.300s",
                             end ? "the upper end" : "the lower end", text, le.msg);
                    rc = param_fail(cfg, i, b->line_range, b->is_color ? "colors" : "range", e,
                                    msg);
                }
            }
        } else if (strcmp(b->param, "scene") == 0) {
            for (int k = 0; k < b->n_values && !rc; k++) {
                lr_scene *other = NULL;
                char f[32];
                snprintf(f, sizeof f, "values[%d]", k);
                if (lr_scene_load(b->values[k], NULL, &other, &le)) {
                    rc = param_fail(cfg, i, b->line_values[k], f, e, le.msg);
                } else {
                    /* Every scene of the cycle needs the light a level binding follows. */
                    for (int g = 0; g < m->n_groups && !rc; g++) {
                        group tmp = m->groups[g];
                        if (tmp.relative && resolve_level(&tmp, other, &le))
                            rc = param_fail(cfg, i, b->line_values[k], f, e, le.msg);
                    }
                }
                lr_scene_destroy(other);
            }
        } else {
            for (int k = 0; k < b->n_values && !rc; k++)
                if (lr_scene_set(scratch, b->param, b->values[k], NULL, &le)) {
                    char f[32];
                    snprintf(f, sizeof f, "values[%d]", k);
                    rc = param_fail(cfg, i, b->line_values[k], f, e, le.msg);
                }
        }
    }
    lr_scene_destroy(scratch);
    return rc;
}

int lr_control_map_create(const lr_rig_config *cfg, lr_scene *scene, bool check, int64_t now_ns,
                          lr_control_map **out, lr_err *e)
{
    lr_control_map *m = calloc(1, sizeof *m);
    if (!m)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    m->cfg = cfg;
    m->n = cfg->n_bindings;
    m->lamp = -1;
    int rc = LR_OK;
    for (int i = 0; i < m->n && !rc; i++) {
        const lr_rig_binding *b = &cfg->bindings[i];
        bstate *s = &m->st[i];
        s->b = b;
        s->group = -1;
        if (b->lamp)
            m->lamp = i;
        if (strcmp(b->param, "scene") == 0) {
            s->index = b->has_initial ? (int)b->initial : 0;
            continue;
        }
        char cur[256];
        lr_err le = {0};
        bool relative = level_prefix(b->param) > 0;
        if (relative && b->kind == LR_BIND_CYCLE) {
            rc = param_fail(cfg, i, b->line_param, "param", e,
                            "a light's level follows a position: give 'range', not 'values'");
            break;
        }
        if (relative && b->is_color) {
            rc = param_fail(cfg, i, b->line_range, "colors", e,
                            "a light's level is a number: give 'range', not 'colors'");
            break;
        }
        if (!relative && lr_scene_get(scene, b->param, cur, sizeof cur, &le)) {
            rc = param_fail(cfg, i, b->line_param, "param", e, le.msg);
            break;
        }
        if (b->kind == LR_BIND_CYCLE) {
            s->index = 0;
            for (int k = 0; k < b->n_values; k++)
                if (strcmp(b->values[k], cur) == 0)
                    s->index = k;
            if (b->has_initial) {
                s->index = (int)b->initial;
                s->cycle_pending = true;
            }
            continue;
        }
        /* Level: join (or open) the parameter's group. */
        for (int g = 0; g < m->n_groups; g++)
            if (strcmp(m->groups[g].param, b->param) == 0)
                s->group = g;
        if (s->group < 0) {
            s->group = m->n_groups++;
            m->groups[s->group].param = b->param;
        }
        group *g = &m->groups[s->group];
        if (relative) {
            g->relative = true;
            if ((rc = resolve_level(g, scene, &le))) {
                rc = param_fail(cfg, i, b->line_param, "param", e, le.msg);
                break;
            }
        } else {
            g->vector |= b->is_color || strchr(cur, ',') != NULL;
        }
        lr_accel_init(&s->accel, b->accel_gain, b->accel_rate0, b->accel_max);
    }
    /* Starting positions: `initial`, else the position that reproduces the scene's value
     * (alone on a parameter), else the position giving a factor of 1 (shared parameter). */
    for (int i = 0; i < m->n && !rc; i++) {
        bstate *s = &m->st[i];
        const lr_rig_binding *b = s->b;
        if (b->kind != LR_BIND_LEVEL)
            continue;
        int members = 0;
        for (int k = 0; k < m->n; k++)
            members += m->st[k].group == s->group;
        double x = 0;
        if (b->has_initial) {
            x = b->initial;
        } else if (!b->is_color) {
            double target = 1.0; /* shared, or a light's level: the scene's own value */
            if (members == 1 && !m->groups[s->group].relative) {
                char cur[256];
                lr_scene_get(scene, b->param, cur, sizeof cur, NULL);
                target = strtod(cur, NULL);
            }
            double t = (target - b->range[0]) / (b->range[1] - b->range[0]);
            t = t < 0 ? 0 : t > 1 ? 1 : t;
            x = lr_curve_invert((enum lr_curve)b->curve, isfinite(t) ? t : 0);
        }
        s->x = x;
        lr_fade_init(&s->fade, level_of(b, x));
    }
    (void)now_ns;
    if (!rc && check)
        rc = check_values(cfg, m, e);
    if (rc) {
        free(m);
        return rc;
    }
    *out = m;
    return LR_OK;
}

void lr_control_map_destroy(lr_control_map *m) { free(m); }

static bool matches(const lr_rig_binding *b, const lr_event *ev)
{
    if (b->source[0] && strcmp(b->source, ev->source) != 0)
        return false;
    return strcmp(b->control, ev->control) == 0;
}

static int event_level(lr_control_map *m, bstate *s, const lr_event *ev, int64_t now_ns)
{
    const lr_rig_binding *b = s->b;
    double x = s->x;
    switch (ev->kind) {
    case LR_EV_ABSOLUTE: x = ev->value; break;
    case LR_EV_DELTA: x += lr_accel_apply(&s->accel, ev->value, ev->t_ns) * b->step; break;
    default: return 0; /* buttons do not move a level */
    }
    (void)m;
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    if (x == s->x)
        return 0;
    s->x = x;
    lr_fade_to(&s->fade, level_of(b, x), now_ns, b->fade_s);
    return 1;
}

static int event_cycle(lr_control_map *m, bstate *s, const lr_event *ev)
{
    const lr_rig_binding *b = s->b;
    int n = b->n_values, idx = s->index;
    switch (ev->kind) {
    case LR_EV_PRESS: idx += 1; break;
    case LR_EV_DELTA: {
        double d = ev->value;
        if (d == 0)
            return 0;
        /* At least one step per event, at most one full turn of the list. */
        long k = lround(d);
        if (k == 0)
            k = d > 0 ? 1 : -1;
        k %= n;
        idx += (int)k;
        break;
    }
    case LR_EV_ABSOLUTE: {
        double v = ev->value < 0 ? 0 : ev->value > 1 ? 1 : ev->value;
        idx = (int)floor(v * n);
        if (idx >= n)
            idx = n - 1;
        break;
    }
    default: return 0;
    }
    if (b->wrap)
        idx = ((idx % n) + n) % n;
    else
        idx = idx < 0 ? 0 : idx >= n ? n - 1 : idx;
    if (idx == s->index)
        return 0;
    s->index = idx;
    if (strcmp(b->param, "scene") == 0) {
        snprintf(m->scene_request, sizeof m->scene_request, "%s", b->values[idx]);
        m->has_scene_request = true;
        s->cycle_applied = true;
    } else {
        s->cycle_pending = true;
    }
    return 1;
}

int lr_control_map_event(lr_control_map *m, const lr_event *ev, int64_t now_ns)
{
    if (!isfinite(ev->value)) {
        m->garbage++;
        return -1;
    }
    int moved = -1;
    for (int i = 0; i < m->n; i++) {
        bstate *s = &m->st[i];
        if (!matches(s->b, ev))
            continue;
        int r = s->b->kind == LR_BIND_LEVEL ? event_level(m, s, ev, now_ns) : event_cycle(m, s, ev);
        if (r && moved < 0)
            moved = i;
    }
    return moved;
}

int lr_control_map_update(lr_control_map *m, lr_scene *scene, int64_t now_ns, unsigned *dirty,
                          lr_err *e)
{
    int rc = LR_OK;
    bool material_replaced = false;
    /* Cycles first: a new material preset replaces the whole material, scale included, so
     * the level parameters below must be written again after it. */
    for (int i = 0; i < m->n; i++) {
        bstate *s = &m->st[i];
        if (s->b->kind != LR_BIND_CYCLE || !s->cycle_pending)
            continue;
        lr_err le = {0};
        if (lr_scene_set(scene, s->b->param, s->b->values[s->index], dirty, &le)) {
            if (!rc)
                rc = lr_err_set(e, le.code, "control '%s': %s", s->b->name, le.msg);
        } else {
            material_replaced = true;
            s->cycle_applied = true;
        }
        s->cycle_pending = false;
    }
    for (int g = 0; g < m->n_groups; g++) {
        group *gr = &m->groups[g];
        lr_err le = {0};
        if (gr->relative && gr->need_base && resolve_level(gr, scene, &le)) {
            if (!rc)
                rc = lr_err_set(e, le.code, "parameter '%s': %s", gr->param, le.msg);
            continue;
        }
        double v[3] = {1, 1, 1};
        for (int i = 0; i < m->n; i++) {
            bstate *s = &m->st[i];
            if (s->group != g)
                continue;
            double bv[3];
            value_of(s->b, lr_fade_value(&s->fade, now_ns), bv);
            for (int k = 0; k < 3; k++)
                v[k] *= bv[k];
        }
        if (gr->relative)
            for (int k = 0; k < 3; k++)
                v[k] *= gr->base[k];
        char text[128];
        format_value(v, gr->vector, text, sizeof text);
        if (!material_replaced && strcmp(text, gr->last) == 0)
            continue;
        const char *key = gr->relative ? gr->target : gr->param;
        if (lr_scene_set(scene, key, text, dirty, &le)) {
            if (!rc)
                rc = lr_err_set(e, le.code, "parameter '%s' = %s: %s", key, text, le.msg);
            gr->last[0] = '\0';
        } else {
            snprintf(gr->last, sizeof gr->last, "%s", text);
        }
    }
    return rc;
}

void lr_control_map_carry(lr_control_map *to, const lr_control_map *from, int64_t now_ns)
{
    (void)now_ns;
    if (!to || !from)
        return;
    for (int i = 0; i < to->n; i++) {
        bstate *t = &to->st[i];
        const lr_rig_binding *tb = t->b;
        if (tb->kind != LR_BIND_LEVEL)
            continue;
        for (int j = 0; j < from->n; j++) {
            const lr_rig_binding *fb = from->st[j].b;
            if (fb->kind != LR_BIND_LEVEL || strcmp(fb->name, tb->name) ||
                strcmp(fb->source, tb->source) || strcmp(fb->control, tb->control) ||
                strcmp(fb->param, tb->param))
                continue;
            t->x = from->st[j].x;
            lr_fade_init(&t->fade, level_of(tb, t->x));
            break;
        }
    }
}

void lr_control_map_scene_replaced(lr_control_map *m)
{
    for (int g = 0; g < m->n_groups; g++) {
        m->groups[g].last[0] = '\0';
        m->groups[g].need_base = m->groups[g].relative;
    }
    for (int i = 0; i < m->n; i++)
        if (m->st[i].b->kind == LR_BIND_CYCLE && m->st[i].cycle_applied &&
            strcmp(m->st[i].b->param, "scene") != 0)
            m->st[i].cycle_pending = true;
}

bool lr_control_map_fading(const lr_control_map *m, int64_t now_ns)
{
    for (int i = 0; i < m->n; i++)
        if (m->st[i].b->kind == LR_BIND_LEVEL && lr_fade_active(&m->st[i].fade, now_ns))
            return true;
    return false;
}

bool lr_control_map_lamp_level(const lr_control_map *m, int64_t now_ns, double *level)
{
    if (m->lamp < 0)
        return false;
    *level = lr_fade_value(&m->st[m->lamp].fade, now_ns);
    return true;
}

const char *lr_control_map_scene_request(lr_control_map *m)
{
    if (!m->has_scene_request)
        return NULL;
    m->has_scene_request = false;
    return m->scene_request;
}

const char *lr_control_map_key(const lr_control_map *m, int i)
{
    if (i < 0 || i >= m->n)
        return NULL;
    const bstate *s = &m->st[i];
    if (s->group >= 0 && m->groups[s->group].relative)
        return m->groups[s->group].target;
    return s->b->param;
}

bool lr_control_map_is_cycle(const lr_control_map *m, int i)
{
    return i >= 0 && i < m->n && m->st[i].b->kind == LR_BIND_CYCLE;
}

int lr_control_map_values(const lr_control_map *m, int i)
{
    return lr_control_map_is_cycle(m, i) ? m->st[i].b->n_values : 0;
}

int lr_control_map_what_if(const lr_control_map *m, int i, double pos, lr_scene *scene,
                           int64_t now_ns, unsigned *dirty, lr_err *e)
{
    if (i < 0 || i >= m->n)
        return lr_err_set(e, LR_EINVAL, "control map: no binding %d", i);
    lr_control_map *t = malloc(sizeof *t);
    if (!t)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    *t = *m;
    for (int k = 0; k < t->n; k++) {
        bstate *s = &t->st[k];
        if (s->b->kind == LR_BIND_LEVEL)
            lr_fade_init(&s->fade, lr_fade_value(&s->fade, lr_fade_end_ns(&s->fade)));
        s->cycle_pending = false;
    }
    bstate *s = &t->st[i];
    if (s->b->kind == LR_BIND_LEVEL) {
        double x = pos < 0 ? 0 : pos > 1 ? 1 : pos;
        s->x = x;
        lr_fade_init(&s->fade, level_of(s->b, x));
    } else if (strcmp(s->b->param, "scene") != 0) {
        int n = s->b->n_values;
        s->index = n > 0 ? ((int)pos % n + n) % n : 0;
        s->cycle_pending = true;
    }
    for (int g = 0; g < t->n_groups; g++)
        t->groups[g].need_base = false; /* the live map's base stands */
    int rc = lr_control_map_update(t, scene, now_ns, dirty, e);
    free(t);
    return rc;
}

int lr_control_map_count(const lr_control_map *m) { return m->n; }

double lr_control_map_position(const lr_control_map *m, int i)
{
    return i >= 0 && i < m->n ? m->st[i].x : NAN;
}

double lr_control_map_level(const lr_control_map *m, int i, int64_t now_ns)
{
    return i >= 0 && i < m->n ? lr_fade_value(&m->st[i].fade, now_ns) : NAN;
}

int lr_control_map_index(const lr_control_map *m, int i)
{
    return i >= 0 && i < m->n ? m->st[i].index : -1;
}

unsigned lr_control_map_garbage(const lr_control_map *m) { return m->garbage; }
