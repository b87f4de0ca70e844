/* lamprig — an area light in the real-time transport (seed 004 Sec. 4, "Poisson gathering"):
 * the per-light, unit-radiance transport of a quad or disk light is accumulated over frames,
 * frame f treating the emitter as a point light at one sample point p_f with the emitter's
 * whole Lambertian profile I(w) = A cos(theta_e) (lr_light_shape). The running mean over
 * frames that the radiosity maps and the receivers' direct light keep is then
 *     (1/F) sum_f (point light at p_f)  ->  integral over the emitter,
 * because every p_f is area-uniform (the estimator of lr_area_irradiance_samples).
 *
 * The points: a Poisson-disk set of n <= LR_AREA_SEQ_MAX points in the emitter's parameter
 * square (toroidal distance, scaled by the edge lengths so that a long LED strip gets its
 * points spread along it), mapped by lr_area_point. Frames f = c n + j use point j shifted by
 * a Cranley-Patterson rotation r_c (r_0 = 0, then hashed from c): each shifted point is
 * uniform over the emitter, so every cycle of n frames is an unbiased, well stratified
 * estimate and further cycles keep converging. The GLES passes and the CPU twin both take
 * their points from lr_area_frame_point, so they sample the same p_f. */
#ifndef LR_AREA_FRAMES_H
#define LR_AREA_FRAMES_H

#include "render/area/emitter.h"
#include "render/scene/scene.h"

#define LR_AREA_SEQ_MAX 64

typedef struct lr_area_sequence {
    lr_area_emitter em;
    double uv[LR_AREA_SEQ_MAX][2];
    int n;
} lr_area_sequence;

/* The emitter of an area light (quad or disk); LR_EINVAL for other lights. */
int lr_area_from_light(const lr_light *l, lr_area_emitter *out, lr_err *e);

/* The light's frame sequence (deterministic: the same scene gives the same points). */
int lr_area_sequence_make(const lr_light *l, lr_area_sequence *out, lr_err *e);

/* The sample point of accumulation frame `frame` (>= 0). */
lr_vec3 lr_area_frame_point(const lr_area_sequence *seq, long frame);

/* The light as the transport sees it in frame `frame`: an area light's copy with position
 * p_frame; any other light unchanged. */
void lr_light_at_frame(const lr_light *l, long frame, lr_light *out);

#endif
