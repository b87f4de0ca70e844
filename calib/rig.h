/* lamprig calib — one rig's calibration set, as the steps that use it load it (comparison
 * runs, material fitting, spatial AR: issue 5 items 4-7; `--calib DIR`).
 *
 * A calibration folder (configs/rig/ by default) holds any of
 *   camera.json              camera intrinsics            (lamprig calib camera)
 *   projector.json           projector intrinsics + pose  (lamprig calib projector calibrate)
 *   camera_response.json     camera response              (lamprig calib camera-response)
 *   projector_response.json  projector response           (lamprig calib projector-response fit)
 *   color.json               colour matrix                (lamprig calib color)
 *   pose.json                camera (+ projector) pose in scene coordinates (lamprig calib pose)
 * A missing file is not an error (has_* is false and the conversions below fall back to
 * identity, except the camera response: see below); a present but invalid one is, naming
 * the file: a rig never runs on a calibration it could only half read.
 *
 * ONE rule for reading 8-bit captures, shared by `lamprig compare`, `lamprig fit`,
 * `lamprig-capsim` and `calib albedo` (lr_rig_camera_response; lr_rig_camera_to_linear reads
 * the same curve per pixel):
 *   camera_response.json present  ->  that curve (measured: lamprig calib camera-response);
 *   absent                        ->  the gamma curve lr_camresp_gamma(gamma), gamma from
 *                                     lr_rig_set_gamma (the commands' --gamma), default
 *                                     LR_CAMRESP_DEFAULT_GAMMA = 2.2 (an sRGB-like camera).
 * Both are relative exposure normalised to 1 at value 128, the units the capture simulator
 * encodes from (calib/capture_sim.h), so a simulated capture reads back as the radiance times
 * gain x time whichever tool reads it. Before this rule fit read captures without a response
 * file as linear (value / 255) while compare and capsim assumed gamma 2.2: a capture simulated
 * from a known material fitted to sigma_s' 100x too low (issue 10 item 4).
 */
#ifndef LR_CALIB_RIG_H
#define LR_CALIB_RIG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "calib/camcal.h"
#include "calib/camresp.h"
#include "calib/colormatrix.h"
#include "calib/pose.h"
#include "calib/procam.h"
#include "calib/projresp.h"

#define LR_RIG_CAMERA "camera.json"
#define LR_RIG_PROJECTOR "projector.json"
#define LR_RIG_CAMERA_RESPONSE "camera_response.json"
#define LR_RIG_PROJECTOR_RESPONSE "projector_response.json"
#define LR_RIG_COLOR "color.json"
#define LR_RIG_POSE "pose.json"

typedef struct lr_rig_calib {
    bool has_camera, has_procam, has_camresp, has_projresp, has_color, has_pose;
    double gamma; /* response assumed without camera_response.json; 0 -> 2.2 (lr_rig_set_gamma) */
    lr_camcal camera;
    lr_procam procam;
    lr_camresp camresp;
    lr_projresp projresp;
    lr_colormatrix color;
    lr_rig_pose pose;
} lr_rig_calib;

/* out is large (~25 kB): allocate it, do not put it on a small stack. */
int lr_rig_calib_load(const char *dir, lr_rig_calib *out, lr_err *e);
void lr_rig_calib_free(lr_rig_calib *r);

/* The camera response captures are read with (the rule above), as a table: camera_response.json
 * when the folder has one, else lr_camresp_gamma(r->gamma or 2.2). */
void lr_rig_camera_response(const lr_rig_calib *r, lr_camresp *out);

/* The gamma to assume without camera_response.json (--gamma G). LR_EINVAL when gamma is
 * outside 0.1..10, or when the folder HAS camera_response.json: the measured response is the
 * rule there, and a second one beside it is how captures end up read two ways. */
int lr_rig_set_gamma(lr_rig_calib *r, double gamma, lr_err *e);

/* One line for the commands to print: "camera_response.json" or "gamma 2.2 (assumed: no
 * camera_response.json; --gamma G to change)". Returns buf. */
const char *lr_rig_response_name(const lr_rig_calib *r, char *buf, size_t cap);

/* A camera pixel (8-bit RGB as captured) in linear reference RGB: the camera response (the
 * rule above, entry rgb[c] of lr_rig_camera_response's table), then the colour matrix
 * (skipped when absent). The colour matrix must have been fitted on values linearised with
 * the same response (calib color --camera-response). */
void lr_rig_camera_to_linear(const lr_rig_calib *r, const uint8_t rgb[3], double out[3]);

/* Projector input levels (0..1 per channel) that give the wanted relative light (0..1 of
 * full, black already subtracted): the inverse projector response, identity when absent.
 * Spatial AR compensation divides by the mockup's albedo first and clips to [0, 1]. */
void lr_rig_projector_input(const lr_rig_calib *r, const double light[3], double level[3]);

#endif
