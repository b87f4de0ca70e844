/* lamprig — seed 001's diffusion grid as a per-object model (render/models/model.h).
 *
 * Its validity limit: the grid (render/diffusion/dgrid.h, 7-point finite differences of seed
 * 001 Eq. 1) must resolve the diffusion length 1/sigma_tr. Along a grid axis the discrete
 * solution of phi'' = sigma_tr^2 phi decays as e^{-lambda x} with
 * 2 (cosh(lambda h) - 1) / h^2 = sigma_tr^2, i.e. lambda h = acosh(1 + (sigma_tr h)^2 / 2): at
 * sigma_tr h = 1 the decay rate is 3.8 % low and the error grows as (sigma_tr h)^2 / 24 beyond.
 * The limit is LR_GRID_MAX_SIGMA_H for the largest band's sigma_tr and the spacing the object
 * gets (lr_dscene_spacing). A wall (thickness_mm) thinner than that spacing has cells with no
 * interior node and is refused too.
 */
#ifndef LR_MODELS_DIFFUSION_GRID_H
#define LR_MODELS_DIFFUSION_GRID_H

#define LR_GRID_MAX_SIGMA_H 1.0

#endif
