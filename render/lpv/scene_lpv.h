/* lamprig — the light-propagation volume of a scene (seed 004 Sec. 3.2, 4.1-4.4): the
 * indirect irradiance on the plane receivers that the maps and VPLs do not carry (issue 12
 * parts 3-4), per light at unit radiance, on the receivers' irradiance grids
 * (render/core/recv_grid.h), for composition to add to the direct light.
 *
 *  - Volume: n^3 cells around the objects' bounds, widened on every side by 1.25 times their
 *    largest extent (the table and wall near a lamp fall a few cells inside; light reaching
 *    the border leaves, so a receiver on it would gather nothing).
 *  - Blocking: diffuse samples on the plane receivers (a grid of spacing h/2 where the plane
 *    crosses the volume) and Poisson-disk samples on the objects (render/area/poisson_mesh.h,
 *    r_min = h/3), each blocking its interfaces (lpv.h).
 *  - Injection, per source group (each plane receiver, and the objects together):
 *      (a) DPDS on a receiver: its direct irradiance E from the area light (64 stratified
 *          emitter points, shadow rays through the objects) and E_TPL from the objects' TPLs
 *          (the light they emit where the VPLs carry it, Eq. 6b, tpl.h), reflected flux
 *          rho (E + E_TPL) A as the lobe of Eq. 3b-4 one cell off the plane;
 *      (b) TPDS on the objects: the part R of the direct light that the wall sends back to
 *          the side it came from (the slab's total diffuse reflectance, Donner-Jensen
 *          multipole for objects with thickness_mm, else the semi-infinite dipole's), as the
 *          lobe along the lit face's normal: light the inner face of a shade returns into the
 *          cavity and that leaves through the openings. Thin walls (thickness_mm) send T E A
 *          out of the other face (the multipole's total transmittance). Light leaving a side
 *          that is the outermost surface facing out (the VPLs' surface, render/core/vpl.h) is
 *          not injected but becomes a TPL: the VPLs give the receivers its first bounce, the
 *          volume the receivers' reflection of it (a votive's outer glow on the table, then
 *          table to wall). Light leaving any other side (a cavity's inner wall) is a lobe.
 *  - Propagation: 4 n steps per group (lpv.h; on the CPU, or the caller's, e.g. the compute
 *    shader), gather from the absorbed record at the receiver grid's texel centres. A group
 *    is never gathered on itself: a plane cannot light itself, but the volume's diffusion
 *    would return part of its own lobe. Light blocked by a surface is absorbed; with
 *    `bounces` > 0 the objects' samples gather what the volumes delivered to them and send
 *    R of it back in (and, with `transmit`, thin walls T of it out of the other face), once
 *    per bounce (the objects lit by the receivers and by their own cavity; a shade's cavity,
 *    whose inner wall returns R = 0.79 of paper's light, keeps most of its light for several
 *    bounces).
 *
 * Area lights (quad, disk) per unit radiance; point and spot lights per unit intensity, their
 * direct irradiance I cos / d^2 (spot: times the cone's shape) at every sample, 0 where an
 * object is in the way (lr_direct_irradiance: the renderer's shadow test, with rays);
 * directional lights get nothing (LR_OK, zero grids). */
#ifndef LR_LPV_SCENE_H
#define LR_LPV_SCENE_H

#include "render/base/err.h"
#include "render/lpv/lpv.h"
#include "render/lpv/objfield.h"
#include "render/scene/scene.h"

/* Propagates v by `steps` (lr_lpv_propagate, or a GPU round trip). */
typedef int (*lr_lpv_propagate_fn)(void *ctx, lr_lpv *v, int steps, lr_err *e);

typedef struct lr_lpv_scene_desc {
    int n;                         /* cells per axis; 0: 32 */
    int bounces;                   /* further bounces off the objects (0: one bounce) */
    bool transmit;                 /* in those bounces thin walls also send T of the volume's
                                    * light out of their other face (false: R only) */
    lr_lpv_propagate_fn propagate; /* NULL: the CPU */
    void *ctx;
    /* Non-NULL: reset to the volume's box and filled with the irradiance the receivers'
     * volumes deliver to the objects (objfield.h; the objects' own group is left out: its
     * light on the objects is a cavity's inter-reflection, the cavity closure's part,
     * PIPELINE.md "Energy"). */
    lr_lpv_objfield *objects;
} lr_lpv_scene_desc;

typedef struct lr_lpv_scene_stats {
    double injected[3];  /* flux injected over all groups, W per unit radiance */
    double gathered[3];  /* flux the receivers' grids account for (sum E A over the texels) */
    double injected_receivers[3]; /* the receivers' share of the first injection: sum over
                                   * their samples of albedo E A, W per unit radiance (area
                                   * lights) or intensity (point, spot) */
    double direct_receivers; /* the receivers' direct power from the light inside the volume
                              * (sum E A over their samples), W per unit radiance */
    double emergent[3];      /* flux the objects send out of their outermost surface (what the
                              * VPLs carry): the TPLs' total, sum R E A or T E A (tpl.h) */
    double injected_emergent[3]; /* the receivers' injection of it: sum rho E_TPL A (Eq. 6b),
                                  * included in injected[] (not in injected_receivers) */
    double gathered_objects[3];  /* the part of gathered[] from the objects' injections */
    double object_irradiance[3]; /* sum E A the objects' samples gathered from the volumes
                                  * (both sides of open sheets), over all bounces but the last */
    int tpls;
    int samples_receivers, samples_objects;
    double cell_mm;
} lr_lpv_scene_stats;

/* Fills out[i] (LR_RECV_GRID^2 * 3 doubles, rows t, columns s, RGB) for every plane receiver
 * i of the scene with light `light`'s indirect irradiance per unit radiance (area) or
 * intensity (point, spot); out[i] NULL for a receiver to skip (box receivers are always
 * skipped). stats may be NULL. LR_EINVAL for a
 * bad light index or n; LR_ENOMEM. */
int lr_lpv_scene_indirect(const lr_scene *s, int light, const lr_lpv_scene_desc *d,
                          double *const *out, lr_lpv_scene_stats *stats, lr_err *e);

#endif
