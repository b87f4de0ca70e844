/* lamprig calib — material fitting (issue 5 item 5; seed 001: inverse diffusion, material
 * parameters from captures of a lit object).
 *
 * Model: the CPU twin's converged render (render/cpu/frame.h, LR_CPU_REFERENCE) of the
 * scene's camera view at low resolution, fixed seed and sample counts, so the objective is a
 * deterministic function of the parameters (common random numbers: a small change of sigma
 * moves the estimate smoothly instead of redrawing its noise).
 *
 * Parameters, in log space (the coefficients are positive and span decades):
 *   LR_FIT_SIGMA  log sigma_a and log sigma_s' per band. The bands are independent in the
 *                 model (seed 003 Eq. 5 per band), so each band is its own 2-D problem:
 *                 three Nelder-Mead runs (calib/nelder_mead.h) advance in lockstep and each
 *                 render evaluates all three bands' current proposals at once.
 *   LR_FIT_SCALE  two scales on the object's preset, s_a on sigma_a and s_s on sigma_s',
 *                 shared by the bands: one 2-D run on the loss summed over bands.
 * Objective per band b, over the object mask (camera pixels whose first hit is the object,
 * ray-cast, with a finite target):
 *     L_b = sqrt( sum_i 2 rho(m_i - t_i) / sum_i t_i^2 ),
 *     rho(r) = r^2 / 2 (|r| <= delta), delta (|r| - delta / 2) otherwise  (Huber 1964),
 * delta = huber x the mean target over the mask: with no outliers L_b is the relative RMSE;
 * a specular glint or a mis-registered edge costs linearly, not quadratically. The squared
 * residual is estimated from two renders at half the samples with independent seeds,
 * (m1 - t)(m2 - t), whose expectation is the squared bias alone: (m - t)^2 would add the
 * model's Monte Carlo variance, and the fit would drift towards parameters whose estimate
 * is quieter (measured: from the truth to sigma 5-50x too large). The optimiser minimises
 * L_b^2 (which may go slightly negative near a perfect fit); L_b reports max(0, .).
 *
 * Uncertainty: at the result, the Jacobian of the model with respect to the log parameters
 * by central differences (4 renders, all bands at once) gives the Gauss-Newton covariance
 *     Cov = s^2 (J^T J)^-1,  s^2 = sum r_i^2 / (m - 2)
 * per band; its square roots are the standard errors reported and used by the test, and
 * J^T J's eigenvalue ratio the condition number. Two half-sample renders at the result give
 * the model's own noise (noise_rel). calib/fit_checks.h judges from these whether the data
 * determined the parameters.
 */
#ifndef LR_CALIB_FIT_H
#define LR_CALIB_FIT_H

#include <stdbool.h>

#include "render/base/err.h"
#include "render/base/progress.h"
#include "render/image/image.h"
#include "render/scene/scene.h"

typedef enum lr_fit_mode { LR_FIT_SIGMA = 0, LR_FIT_SCALE } lr_fit_mode;

typedef struct lr_fit_desc {
    lr_scene *scene;         /* the object's material is changed; left at the result */
    int object;              /* index of the object fitted */
    const lr_image *target;  /* linear radiance, W/(mm^2 sr), the render's size and view */
    lr_fit_mode mode;
    /* start: SIGMA: these when sigma_a_start[0] > 0, else the object's current material;
     * SCALE: scales 1 x the object's current material (the preset) times `scale_start`
     * (both 0: 1). */
    double sigma_a_start[3], sigma_s_start[3];
    double scale_start[2];
    int samples;             /* model: estimator samples per band per pixel; 0: 32 */
    int vpl_count;           /* 0: 64 */
    bool no_vpl;
    unsigned seed;           /* 0: 1 */
    int threads;             /* 0: all CPUs */
    double huber;            /* 0: 0.1 */
    int max_evals;           /* per run; 0: 200 */
    int restarts;            /* 0: 2; < 0: none */
    int min_pixels;          /* fewer object pixels is an error; 0: 16 */
    const lr_progress *progress; /* may be NULL: "evaluations" (of at most max_evals + 2;
                                  * the optimiser usually stops earlier), "uncertainty" (the
                                  * noise and Jacobian renders, 6) */
} lr_fit_desc;

typedef struct lr_fit_result {
    double sigma_a[3], sigma_s_prime[3];   /* fitted, mm^-1 */
    double scale[2];                       /* SCALE: s_a, s_s */
    double loss[3];                        /* L_b at the result (SCALE: the shared loss) */
    double rel_rmse[3];                    /* plain relative RMSE per band over the mask */
    double rel_rmse_all;                   /* over all bands */
    double start_rel_rmse;                 /* at the start, all bands */
    double stderr_log[3][2];               /* standard error of log sigma_a, log sigma_s'
                                            * (SCALE: of log s_a, log s_s, in row 0) */
    int iterations[3], evals[3];           /* per run (SCALE: index 0) */
    int renders;                           /* model renders in all */
    long object_pixels;                    /* the object's pixels in the view */
    long mask_pixels;                      /* of them used: a finite (unclipped) target */
    double noise_rel;                      /* the model's own relative RMS noise at the
                                            * result (two half-sample renders), all bands */
    double cond[3];                        /* condition number of J^T J per band (SCALE:
                                            * row 0), J in log parameters; inf: singular */
    double seconds;                        /* wall time of the fit, uncertainty included */
} lr_fit_result;

int lr_fit_run(const lr_fit_desc *d, lr_fit_result *r, lr_err *e);

/* The object mask of a scene's camera view at w x h (1 where the first hit is object
 * `object`); returns the count. mask: w*h bytes, rows from the top. */
long lr_fit_object_mask(const lr_scene *s, int object, int w, int h, unsigned char *mask);

/* Relative RMSE of a against b over mask, per band (out[3]) and over all bands (return). */
double lr_fit_rel_rmse(const lr_image *a, const lr_image *b, const unsigned char *mask,
                       double out[3]);

#endif
