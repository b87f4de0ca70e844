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
 * identity); a present but invalid one is, naming the file: a rig never runs on a
 * calibration it could only half read.
 */
#ifndef LR_CALIB_RIG_H
#define LR_CALIB_RIG_H

#include <stdbool.h>
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

/* A camera pixel (8-bit RGB as captured) in linear reference RGB: the camera response, then
 * the colour matrix (each skipped when absent). The colour matrix must have been fitted on
 * values linearised with the same response (calib color --camera-response). */
void lr_rig_camera_to_linear(const lr_rig_calib *r, const uint8_t rgb[3], double out[3]);

/* Projector input levels (0..1 per channel) that give the wanted relative light (0..1 of
 * full, black already subtracted): the inverse projector response, identity when absent.
 * Spatial AR compensation divides by the mockup's albedo first and clips to [0, 1]. */
void lr_rig_projector_input(const lr_rig_calib *r, const double light[3], double level[3]);

#endif
