/* lamprig — the LPV propagation stencil (see stencil.h). */
#include "render/lpv/stencil.h"

#include <math.h>
#include <string.h>

#include "render/lpv/sh4.h"

static lr_vec3 iv(const int d[3]) { return lr_v3(d[0], d[1], d[2]); }

void lr_lpv_stencil_make(lr_lpv_stencil *st)
{
    memset(st, 0, sizeof *st);
    lr_sh4_faces f;
    lr_sh4_face_moments(&f);
    for (int m = 0; m < 6; m++) {
        int axis = m / 2, sign = (m % 2) ? -1 : 1;
        st->dir[m][axis] = sign;
        lr_vec3 main = iv(st->dir[m]);
        int k = 0;
        memcpy(st->face_n[m][k], st->dir[m], sizeof st->dir[m]);
        lr_sh4_face_transfer(&f, main, lr_v3(0, 0, 0), 0, st->v[m][k]);
        k++;
        for (int t = 0; t < 6; t++) {
            if (t / 2 == axis)
                continue;
            int side[3] = {0, 0, 0};
            side[t / 2] = (t % 2) ? -1 : 1;
            memcpy(st->face_n[m][k], side, sizeof side);
            lr_sh4_face_transfer(&f, main, iv(side), 1, st->v[m][k]);
            k++;
        }
        for (int j = 0; j < 5; j++) {
            lr_sh4_cosine_lobe(iv(st->face_n[m][j]), st->lobe[m][j]);
            for (int i = 0; i < 4; i++)
                st->lobe[m][j][i] /= M_PI;
        }
    }
}
