/* lamprig planner — which of the light paths beyond seed 003 a scene needs (plan.h,
 * "The light transport a scene needs").
 *
 * Seed 003's receivers get the direct light and the VPLs' (the objects' emergent light, each
 * VPL unshadowed). Issue 12 measured three paths it lacks: light bounced between the
 * receivers (18-23 % of the reference's receiver light), light leaving an object's inner
 * faces through its openings (28 % of the lamp shade's), and the VPLs' light that the
 * objects block (the jar candle's pool VPLs lit the wall through its rim: the wall at 1.8x).
 * Each has its own pass and cost; the geometry says which matter. */
#include "render/plan/plan.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/core/vpl.h"
#include "render/mesh/bvh.h"
#include "render/openings/openings.h"

/* Points per side of each plane receiver for the blocked share. */
#define RECEIVER_POINTS 16

static const char *const keys[LR_PLAN_TRANSPORT_COUNT] = {"receiver_bounce", "opening_light",
                                                          "vpl_visibility"};

const char *lr_plan_transport_key(enum lr_plan_transport_kind k)
{
    return (unsigned)k < LR_PLAN_TRANSPORT_COUNT ? keys[k] : "";
}

static void why(lr_plan_transport *t, int k, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void why(lr_plan_transport *t, int k, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(t->why[k], LR_PLAN_REASON_MAX, fmt, ap);
    va_end(ap);
}

static bool render_flag(const lr_render_settings *r, int k)
{
    return k == LR_PLAN_RECEIVER_BOUNCE ? r->receiver_bounce
           : k == LR_PLAN_OPENING_LIGHT ? r->opening_light
                                        : r->vpl_visibility;
}

static bool is_local_light(const lr_light *l)
{
    return l->type == LR_LIGHT_POINT || l->type == LR_LIGHT_SPOT;
}

/* Receivers that exchange light: a plane receiver whose front faces another plane receiver
 * (each one's centre in front of the other) or an object (its centre in front). */
static bool facing_pair(const lr_scene *s, char *what, size_t cap)
{
    for (int a = 0; a < lr_scene_receiver_count(s); a++) {
        const lr_receiver *A = lr_scene_receiver_at(s, a);
        if (A->type != LR_RECEIVER_PLANE)
            continue;
        for (int b = a + 1; b < lr_scene_receiver_count(s); b++) {
            const lr_receiver *B = lr_scene_receiver_at(s, b);
            if (B->type == LR_RECEIVER_PLANE &&
                lr_v3_dot(A->normal, lr_v3_sub(B->center, A->center)) > 0.0 &&
                lr_v3_dot(B->normal, lr_v3_sub(A->center, B->center)) > 0.0) {
                snprintf(what, cap, "'%s' and '%s' face each other", A->name, B->name);
                return true;
            }
        }
        for (int i = 0; i < lr_scene_object_count(s); i++) {
            const lr_scene_object *o = lr_scene_object_at(s, i);
            if (lr_v3_dot(A->normal, lr_v3_sub(o->center, A->center)) > 0.0) {
                snprintf(what, cap, "'%s' faces '%s', which sends its light back", A->name,
                         o->name);
                return true;
            }
        }
    }
    return false;
}

/* The share of the VPLs' light on the plane receivers that the objects block (plan.h). */
static int blocked_share(const lr_scene *s, double *share, lr_err *e)
{
    enum { NV = LR_PLAN_VPL_SAMPLES };
    lr_vpl_point *v = malloc(NV * sizeof *v);
    if (!v)
        return lr_err_set(e, LR_ENOMEM, "planner: out of memory (VPL samples)");
    double all = 0.0, blocked = 0.0;
    const int no = lr_scene_object_count(s);
    for (int oi = 0; oi < no; oi++) {
        lr_vpl_place(lr_scene_object_at(s, oi), NV, v);
        for (int i = 0; i < NV; i++) {
            if (!v[i].valid)
                continue;
            /* The lights' irradiance at the VPL ignoring the body: seed 003's VPLs carry
             * light that left the wax near where it entered. */
            double lit = 0.0;
            for (int l = 0; l < lr_scene_light_count(s); l++) {
                const lr_light *L = lr_scene_light_at(s, l);
                double I = L->intensity * (L->color[0] + L->color[1] + L->color[2]);
                if (L->type == LR_LIGHT_DIRECTIONAL) { /* from afar: irradiance ~ |cos| */
                    lit += I * fabs(lr_v3_dot(v[i].n, L->direction));
                    continue;
                }
                /* Point, spot, and an area light seen as a point (lr_light_shape: A cos). */
                lr_vec3 d = lr_v3_sub(v[i].x, L->position);
                double d2 = lr_v3_dot(d, d);
                if (d2 > 0.0)
                    lit += I * lr_light_shape(L, lr_v3_scale(d, 1.0 / sqrt(d2))) *
                           fabs(lr_v3_dot(v[i].n, d)) / (sqrt(d2) * d2);
            }
            double w = lit * v[i].area;
            if (!(w > 0.0))
                continue;
            for (int r = 0; r < lr_scene_receiver_count(s); r++) {
                const lr_receiver *R = lr_scene_receiver_at(s, r);
                if (R->type != LR_RECEIVER_PLANE)
                    continue;
                lr_vec3 rv = lr_v3_cross(R->normal, R->u_dir);
                for (int gy = 0; gy < RECEIVER_POINTS; gy++)
                    for (int gx = 0; gx < RECEIVER_POINTS; gx++) {
                        double fu = (gx + 0.5) / RECEIVER_POINTS - 0.5;
                        double fv = (gy + 0.5) / RECEIVER_POINTS - 0.5;
                        lr_vec3 x = lr_v3_add(R->center,
                                              lr_v3_add(lr_v3_scale(R->u_dir, fu * R->size[0]),
                                                        lr_v3_scale(rv, fv * R->size[1])));
                        lr_vec3 d = lr_v3_sub(x, v[i].x);
                        double dist = lr_v3_len(d);
                        if (!(dist > 0.0))
                            continue;
                        lr_vec3 u = lr_v3_scale(d, 1.0 / dist);
                        double cv = lr_v3_dot(v[i].n, u), cx = -lr_v3_dot(R->normal, u);
                        if (!(cv > 0.0) || !(cx > 0.0))
                            continue;
                        /* The VPL kernel's geometry (PIPELINE.md, bounded as the VPLs are). */
                        double k = w * cv * cx / fmax(dist * dist, v[i].area);
                        all += k;
                        bool hit = false;
                        for (int j = 0; j < no && !hit; j++)
                            hit = lr_bvh_occluded(lr_scene_object_at(s, j)->bvh, v[i].x, u,
                                                  1e-4 * lr_scene_object_at(s, j)->radius,
                                                  dist);
                        blocked += hit ? k : 0.0;
                    }
            }
        }
    }
    free(v);
    *share = all > 0.0 ? blocked / all : 0.0;
    return LR_OK;
}

int lr_plan_transport_decide(const lr_scene *s, const enum lr_sss_model *models,
                             lr_plan_transport *out, lr_err *e)
{
    memset(out, 0, sizeof *out);
    const lr_render_settings *rs = lr_scene_render(s);
    for (int k = 0; k < LR_PLAN_TRANSPORT_COUNT; k++)
        out->given[k] = lr_scene_render_given(s, keys[k]);
    bool local = false, plane = false, transrad = false;
    for (int l = 0; l < lr_scene_light_count(s); l++)
        local |= is_local_light(lr_scene_light_at(s, l));
    for (int r = 0; r < lr_scene_receiver_count(s); r++)
        plane |= lr_scene_receiver_at(s, r)->type == LR_RECEIVER_PLANE;
    const int no = lr_scene_object_count(s);
    for (int i = 0; i < no; i++)
        transrad |= lr_sss_model_props_of(models ? models[i]
                                                 : lr_scene_object_at(s, i)->sss_model)
                        ->patch_solve;

    const char *none = lr_scene_light_count(s) < 1 ? "no light"
                       : !plane ? "no plane receiver"
                       : rs->lpv > 0 ? "render.lpv's volumes carry the receivers' light"
                                     : NULL;
    for (int k = 0; none && k < LR_PLAN_TRANSPORT_COUNT; k++)
        why(out, k, "%s", none);
    if (!none) {
        char what[LR_PLAN_REASON_MAX];
        if (transrad) {
            why(out, LR_PLAN_RECEIVER_BOUNCE, "translucent radiosity's F has the receivers");
            why(out, LR_PLAN_OPENING_LIGHT, "translucent radiosity's F has the receivers");
        } else {
            out->needed[LR_PLAN_RECEIVER_BOUNCE] = facing_pair(s, what, sizeof what);
            if (out->needed[LR_PLAN_RECEIVER_BOUNCE])
                why(out, LR_PLAN_RECEIVER_BOUNCE, "%s", what);
            else
                why(out, LR_PLAN_RECEIVER_BOUNCE, "no receiver faces another or an object");
            int best = -1;
            for (int i = 0; local && i < no; i++) {
                enum lr_sss_model m = models ? models[i] : lr_scene_object_at(s, i)->sss_model;
                if (lr_sss_model_props_of(m)->no_openings)
                    continue;
                double f = lr_openings_inner_fraction(lr_scene_object_at(s, i), i);
                if (f > out->inner_fraction || best < 0) {
                    out->inner_fraction = f;
                    best = i;
                }
            }
            out->needed[LR_PLAN_OPENING_LIGHT] = best >= 0 &&
                                                 out->inner_fraction >= LR_PLAN_INNER_MIN;
            if (!local) /* the inner faces' B is the cavity closure's (render/openings) */
                why(out, LR_PLAN_OPENING_LIGHT, "no point or spot light");
            else if (best < 0)
                why(out, LR_PLAN_OPENING_LIGHT, "no object's model has a B at its inner faces");
            else
                why(out, LR_PLAN_OPENING_LIGHT, "'%s': %.0f %% of its area on inner faces (%s %.0f %%)",
                    lr_scene_object_at(s, best)->name, 100.0 * out->inner_fraction,
                    out->needed[LR_PLAN_OPENING_LIGHT] ? "at least" : "under",
                    100.0 * LR_PLAN_INNER_MIN);
        }
        int rc = blocked_share(s, &out->vpl_blocked, e);
        if (rc)
            return rc;
        out->needed[LR_PLAN_VPL_VISIBILITY] = out->vpl_blocked >= LR_PLAN_BLOCKED_MIN;
        why(out, LR_PLAN_VPL_VISIBILITY, "the objects block %.1f %% of the VPLs' light on the "
            "receivers (%s %.0f %%)", 100.0 * out->vpl_blocked,
            out->needed[LR_PLAN_VPL_VISIBILITY] ? "at least" : "under",
            100.0 * LR_PLAN_BLOCKED_MIN);
    }
    for (int k = 0; k < LR_PLAN_TRANSPORT_COUNT; k++)
        out->on[k] = out->needed[k] && !out->given[k] && !render_flag(rs, k);
    return LR_OK;
}

int lr_plan_transport_apply(const lr_plan_transport *t, lr_scene *s, unsigned *dirty,
                            lr_err *e)
{
    for (int k = 0; k < LR_PLAN_TRANSPORT_COUNT; k++) {
        if (!t->on[k])
            continue;
        char key[48];
        snprintf(key, sizeof key, "render.%s", keys[k]);
        int rc = lr_scene_set(s, key, "true", dirty, e);
        if (rc)
            return lr_err_prefix(e, "applying the plan's transport");
    }
    return LR_OK;
}

size_t lr_plan_transport_format(const lr_plan_transport *t, const char *scene, char *buf,
                                size_t cap)
{
    char line[LR_PLAN_TRANSPORT_COUNT * (LR_PLAN_REASON_MAX + 64) + LR_SCENE_NAME_MAX + 32];
    int n = snprintf(line, sizeof line, "plan: %s: transport:", scene);
    for (int k = 0; k < LR_PLAN_TRANSPORT_COUNT && n > 0 && (size_t)n < sizeof line; k++)
        n += snprintf(line + n, sizeof line - (size_t)n, " %s %s (%s)%s", keys[k],
                      t->on[k] || (t->needed[k] && !t->given[k]) ? "on"
                      : t->given[k]                              ? "as the scene sets it"
                                                                 : "not needed",
                      t->why[k], k + 1 < LR_PLAN_TRANSPORT_COUNT ? ";" : "\n");
    if (cap)
        snprintf(buf, cap, "%s", line);
    return strlen(line);
}
