/* Test support: a simulated projector-camera rig for calib/ tests.
 *
 * The test describes what each camera pixel sees as ss x ss samples (supersampling across the
 * pixel's footprint): the projector position lighting the sample (continuous OpenCV pixel
 * coordinates, NaN where the projector does not reach) and the surface albedo there. A frame
 * shown by the projector is turned into a camera image by integrating
 *     albedo * (ambient + gain * (black + (1 - black) * frame(round(p)) / 255))
 * over the samples, an optional Gaussian blur, Gaussian noise (deterministic per seed and
 * frame) and 8-bit quantisation. The projector pixel lighting point p is round(p): pixel c
 * covers [c - 0.5, c + 0.5) in OpenCV's convention.
 */
#ifndef LR_TEST_CALIB_SIM_H
#define LR_TEST_CALIB_SIM_H

#include "calib/image.h"

typedef struct sim_sample {
    float px, py; /* projector position, NaN when unlit */
    float albedo;
} sim_sample;

typedef struct sim_scene {
    int cam_w, cam_h, ss;
    sim_sample *samples; /* cam_w * cam_h * ss * ss, pixel-major */
    double ambient;      /* light without the projector, in units of full scale */
    double gain;         /* projector white on albedo 1, in units of full scale */
    double black;        /* projector black level as a fraction of its white */
    double noise_dn;     /* Gaussian noise, 8-bit digital values */
    double blur_sigma;   /* camera pixels, 0 = none */
    unsigned seed;
} sim_scene;

int sim_scene_alloc(sim_scene *s, int cam_w, int cam_h, int ss);
void sim_scene_free(sim_scene *s);
sim_sample *sim_at(sim_scene *s, int x, int y, int k);

/* Renders the projector frame (8-bit grey, pw x ph) into an 8-bit grey camera image. */
int sim_render(const sim_scene *s, const lr_img *frame, unsigned frame_seed, lr_img *out);

/* Shows the whole Gray-code sequence for a pw x ph projector and writes the simulated
 * captures into dir (created) with the names calib/graycode.h uses. */
int sim_write_graycode(const sim_scene *s, int pw, int ph, const char *dir);

/* mkdtemp under /tmp; the caller removes it with sim_rmdir. */
char *sim_tempdir(const char *tag);
void sim_rmdir(const char *dir);

/* Deterministic standard normal deviate from a caller-held state. */
double sim_gauss(unsigned long long *state);

#endif
