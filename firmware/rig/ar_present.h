/* lamprig firmware — spatial AR on the projector: the compensated frame (calib/ar_frame.h's
 * levels, 0..1, rows top to bottom) quantised to 8 bits, uploaded as an RGB8 texture and drawn
 * full-screen (render/shaders fullscreen.vert + blit.frag) into framebuffer 0, then presented.
 *
 * Same size as the target: NEAREST sampling, so every projector pixel gets exactly its level.
 * Different size (the calibration's projector resolution is not the KMS mode): the frame is
 * stretched over the whole target with LINEAR sampling (the caller logs that once).
 * All calls need the lr_gl's context current.
 */
#ifndef LR_RIG_AR_PRESENT_H
#define LR_RIG_AR_PRESENT_H

#include <stdint.h>

#include "render/base/err.h"
#include "render/gl/gl.h"
#include "render/image/image.h"

typedef struct lr_ar_present lr_ar_present;

/* Loads the blit program (render/shaders beside the configs directory; $LAMPRIG_SHADERS
 * overrides, as for the renderer). Errors: those of lr_program_create, prefixed
 * "spatial AR output". */
int lr_ar_present_create(lr_gl *gl, lr_ar_present **out, lr_err *e);
/* NULL is a no-op. */
void lr_ar_present_destroy(lr_ar_present *p);

/* levels (0..1) -> 8-bit: lrint(255 * clamp(v)), the same as the ar_NNNNNN.png files.
 * out: width * height * 3 bytes, rows top to bottom. */
void lr_ar_levels_to_rgb8(const lr_image *levels, uint8_t *out);

/* Uploads the frame (replacing the previous one). Errors: LR_EINVAL (empty image or larger
 * than the driver's texture limit), LR_ENOMEM, LR_EGL. */
int lr_ar_present_upload(lr_ar_present *p, const lr_image *levels, lr_err *e);
/* Draws the uploaded frame over the currently bound framebuffer, viewport 0,0,width,height. */
int lr_ar_present_draw(lr_ar_present *p, int width, int height, lr_err *e);
/* Upload, draw into framebuffer 0 at lr_gl_size, lr_gl_present. */
int lr_ar_present_show(lr_ar_present *p, const lr_image *levels, lr_err *e);

#endif
