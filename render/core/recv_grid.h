/* lamprig — the receiver irradiance grid (issue 11; render/passes/PIPELINE.md, "Receiver
 * irradiance cache"), shared by the GPU pass (render/passes/irradiance.c) and the CPU twin
 * (frame.c) so that both discretise alike.
 *
 * The emergent light on a diffuse plane receiver, E_vpl(x) (PIPELINE.md pass 4), depends on
 * neither the camera nor the projector, and it is smooth: the bounded geometry term spreads
 * each VPL over at least its own patch size sqrt(A_v). So it is evaluated once per light at
 * unit intensity at the centres of an LR_RECV_GRID x LR_RECV_GRID grid over the plane and
 * read by bilinear interpolation; a view change then costs four fetches per receiver pixel,
 * not a sum over the VPLs. Texel (s, t) has its centre at
 *   x = c + ((s + 1/2) / R - 1/2) w a + ((t + 1/2) / R - 1/2) h b,
 * a = u_dir, b = normal x u_dir, w, h the plane's size. A point between the outermost texel
 * centres and the plane's edge takes the edge texels' values (clamped taps). Box receivers are
 * not cached (their VPL sum stays per pixel). */
#ifndef LR_CORE_RECV_GRID_H
#define LR_CORE_RECV_GRID_H

#include <stdbool.h>

#include "render/base/vec3.h"
#include "render/scene/scene.h"

/* Texels per side: 4.7 mm over the candle's 1200 mm table, against VPL patches of
 * sqrt(A_v) >= 10 mm at the shipped settings. */
#define LR_RECV_GRID 256

typedef struct lr_recv_grid_frame {
    lr_vec3 c, a, b; /* centre, unit axes along w and h */
    double w, h;     /* mm */
} lr_recv_grid_frame;

/* False for a receiver without a grid (a box). */
bool lr_recv_grid_frame_of(const lr_receiver *rc, lr_recv_grid_frame *f);
/* The centre of texel (s, t). */
lr_vec3 lr_recv_grid_point(const lr_recv_grid_frame *f, int s, int t);
/* The four bilinear taps of world point x (projected onto the plane): texel indices s + R t
 * and weights summing to 1. */
void lr_recv_grid_taps(const lr_recv_grid_frame *f, lr_vec3 x, int idx[4], double w[4]);

#endif
