/* Area lights as a frame sequence of point samples (frames.h). */
#include <math.h>

#include "render/area/frames.h"
#include "render/base/rng.h"

int lr_area_from_light(const lr_light *l, lr_area_emitter *out, lr_err *e)
{
    if (l->type == LR_LIGHT_QUAD)
        return lr_area_quad(l->position, l->edge_u, l->edge_v, l->two_sided, out, e);
    if (l->type == LR_LIGHT_DISK)
        return lr_area_disk(l->position, l->direction, l->radius, l->two_sided, out, e);
    return lr_err_set(e, LR_EINVAL, "light '%s' is not an area light", l->name);
}

int lr_area_sequence_make(const lr_light *l, lr_area_sequence *out, lr_err *e)
{
    int rc = lr_area_from_light(l, &out->em, e);
    if (rc)
        return rc;
    /* Dart throwing on the emitter's torus (emitter.h) at a radius that places about
     * LR_AREA_SEQ_MAX points, 2000 refusals in a row to stop; a long LED strip gets its points
     * spread along it. */
    double sx, sy;
    lr_area_param_scales(&out->em, &sx, &sy);
    lr_area_poisson_uv(sx, sy, lr_area_poisson_radius(sx * sy, LR_AREA_SEQ_MAX),
                       LR_AREA_SEQ_MAX, 2000, 0xA5EA, out->uv, &out->n);
    return LR_OK;
}

lr_vec3 lr_area_frame_point(const lr_area_sequence *seq, long frame)
{
    long f = frame < 0 ? 0 : frame;
    long c = f / seq->n;
    int j = (int)(f % seq->n);
    double s0 = 0.0, s1 = 0.0;
    if (c > 0) {
        lr_rng rng = lr_rng_init(lr_rng_key(0xC9A7, (uint64_t)c, 0, 0));
        s0 = lr_rng_next(&rng);
        s1 = lr_rng_next(&rng);
    }
    double u = seq->uv[j][0] + s0, v = seq->uv[j][1] + s1;
    return lr_area_point(&seq->em, u - floor(u), v - floor(v));
}

void lr_light_at_frame(const lr_light *l, long frame, lr_light *out)
{
    *out = *l;
    lr_area_sequence seq;
    if (!lr_light_is_area(l) || lr_area_sequence_make(l, &seq, NULL) != LR_OK)
        return;
    out->position = lr_area_frame_point(&seq, frame);
}
