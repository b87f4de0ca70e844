/* lamprig — the propagation stencil of the light-propagation volumes (seed 004 Sec. 4.4,
 * Eq. 9-16, after Kaplanyan & Dachsbacher 2010): a source cell s sends light to each of its
 * six face neighbours d; of d's six faces, the five other than the one it shares with s each
 * receive the flux that s's intensity sends through the face's solid angle (Eq. 9, 11-14:
 * Phi_f = v_f . c_s with v_f = integral over the face of y_lm), and that flux becomes, in d, a
 * new point light: the clamped-cosine lobe (Phi_f / pi) max(0, n_f . w) about the face's
 * outward normal n_f (Eq. 10, 15-16). The 30 faces of the six neighbours tile the sphere seen
 * from s exactly, so sum_f v_f . c_s is s's whole flux. Shared by the CPU volume (lpv.c) and
 * the compute shader (uploaded as uniforms, gpu.c). */
#ifndef LR_LPV_STENCIL_H
#define LR_LPV_STENCIL_H

#include "render/base/vec3.h"

typedef struct lr_lpv_stencil {
    int dir[6][3];        /* main direction s -> d: +x, -x, +y, -y, +z, -z */
    int face_n[6][5][3];  /* n_f: face 0 the front (= main), 1-4 the sides */
    double v[6][5][4];    /* Eq. 14's transfer vectors */
    double lobe[6][5][4]; /* Eq. 16's front matrix: the SH of max(0, n_f . w) / pi */
} lr_lpv_stencil;

/* Fills the stencil (about 1 ms: the face integrals' quadrature). */
void lr_lpv_stencil_make(lr_lpv_stencil *st);

#endif
