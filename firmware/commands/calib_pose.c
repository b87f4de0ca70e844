/* `lamprig calib pose`: the camera's (and projector's) pose in scene coordinates from a photo
 * of a board at a known place, or from pixels of known scene points (calib/pose.h). */
#include <stdio.h>
#include <stdlib.h>

#include "calib/calfile.h"
#include "calib/camcal.h"
#include "calib/pose.h"
#include "calib/procam.h"
#include "firmware/commands/calib_cli.h"

/* {"version":1, "kind":"pose_points", "points":[{"scene":[3], "pixel":[2]}, ...]} */
static int load_pose_points(const char *path, double **xyz, double **uv, int *n, lr_err *e)
{
    lr_json *j;
    lr_jnode root, arr;
    int count = 0;
    int rc = lr_calfile_load(path, "pose_points", &j, &root, e);
    if (rc)
        return rc;
    if ((rc = lr_calfile_array(j, root, NULL, "points", &arr, &count, e))) {
        lr_json_destroy(j);
        return rc;
    }
    *xyz = malloc((size_t)(count ? count : 1) * 3 * sizeof **xyz);
    *uv = malloc((size_t)(count ? count : 1) * 2 * sizeof **uv);
    if (!*xyz || !*uv)
        rc = lr_err_set(e, LR_ENOMEM, "out of memory");
    for (int i = 0; i < count && !rc; i++) {
        lr_jnode p = lr_json_at(j, arr, i);
        char prefix[32];
        snprintf(prefix, sizeof prefix, "points[%d]", i);
        if ((rc = lr_calfile_numbers(j, p, prefix, "scene", 3, -1e5, 1e5, *xyz + 3 * i, e)))
            break;
        rc = lr_calfile_numbers(j, p, prefix, "pixel", 2, -1e5, 1e5, *uv + 2 * i, e);
    }
    lr_json_destroy(j);
    if (rc) {
        free(*xyz);
        free(*uv);
        *xyz = *uv = NULL;
        return rc;
    }
    *n = count;
    return LR_OK;
}

static int run(const lr_cli *c)
{
    const lr_args *a = &c->args;
    const char *image = lr_args_get(a, "--image"), *points = lr_args_get(a, "--points");
    const char *camera = lr_args_get(a, "--camera"), *projector = lr_args_get(a, "--projector");
    const char *out = lr_args_get(a, "--out");
    int rc, n3 = 0;
    if (!image == !points)
        return lr_cli_usage(c->path, "give exactly one of --image PHOTO or --points FILE");
    lr_board b = {0};
    lr_board_placement pl;
    lr_err e = {0};
    if (image) {
        if ((rc = lr_cli_need(c, "--board")) || (rc = lr_cli_need(c, "--square")) ||
            (rc = lr_cli_need(c, "--origin")) || (rc = lr_cli_need(c, "--x-axis")) ||
            (rc = lr_cli_need(c, "--y-axis")) || (rc = lr_calib_board(c, &b)) ||
            (rc = lr_cli_check(c, lr_args_list(a, "--origin", pl.origin, 3, &n3, &e) ||
                                      lr_args_list(a, "--x-axis", pl.x_axis, 3, &n3, &e) ||
                                      lr_args_list(a, "--y-axis", pl.y_axis, 3, &n3, &e),
                               &e)))
            return rc;
    }
    lr_camcal cc;
    if (lr_camcal_load(camera, &cc, &e))
        return lr_cli_fail(c->path, "%s", e.msg);
    lr_intrinsics k = cc.k;
    lr_camcal_free(&cc);
    lr_procam pc;
    if (projector && lr_procam_load(projector, &pc, &e))
        return lr_cli_fail(c->path, "%s", e.msg);
    lr_rig_pose p;
    if (image) {
        lr_img gray;
        if (lr_img_read(image, LR_IMG_GRAY8, &gray, &e)) {
            rc = LR_EXIT_FAIL;
        } else {
            rc = lr_rig_pose_from_board(&gray, &b, &pl, &k, projector ? &pc : NULL, &p, &e);
            if (rc)
                lr_err_prefix(&e, "%s", image);
            lr_img_free(&gray);
        }
    } else {
        double *xyz, *uv;
        int n;
        rc = load_pose_points(points, &xyz, &uv, &n, &e);
        if (!rc) {
            rc = lr_rig_pose_from_points(n, xyz, uv, &k, projector ? &pc : NULL, &p, &e);
            free(xyz);
            free(uv);
        }
    }
    if (projector)
        lr_procam_free(&pc);
    if (rc || lr_rig_pose_save(out, &p, &e))
        return lr_cli_fail(c->path, "%s", e.msg);
    lr_vec3 cam = lr_pose_center(&p.camera);
    printf("camera at (%.2f, %.2f, %.2f) mm in the scene, %d points, rms %.4f px -> %s\n", cam.x,
           cam.y, cam.z, p.points, p.rms, out);
    if (p.has_projector) {
        lr_vec3 q = lr_pose_center(&p.projector);
        printf("projector at (%.2f, %.2f, %.2f) mm\n", q.x, q.y, q.z);
    }
    return LR_EXIT_OK;
}

static const lr_argspec opts[] = {
    {.name = "--image", .type = LR_ARG_PATH, .metavar = "PHOTO",
     .help = "a photo of the board lying at a known place (or --points)"},
    LR_CALIB_BOARD_OPTS(0),
    {.name = "--origin", .type = LR_ARG_TRIPLE, .metavar = "X,Y,Z",
     .help = "--image: the scene position of the board's first point, mm"},
    {.name = "--x-axis", .type = LR_ARG_TRIPLE, .metavar = "X,Y,Z",
     .help = "--image: the scene direction of the board's +x"},
    {.name = "--y-axis", .type = LR_ARG_TRIPLE, .metavar = "X,Y,Z",
     .help = "--image: the scene direction of the board's +y"},
    {.name = "--points", .type = LR_ARG_PATH, .metavar = "POINTS.json",
     .help = "pixels of known scene points (or --image): {\"version\":1,\n"
             "\"kind\":\"pose_points\", \"points\":[{\"scene\":[x,y,z],\n"
             "\"pixel\":[u,v]}, ...]}"},
    {.name = "--camera", .type = LR_ARG_PATH, .metavar = "CAMERA.json", .flags = LR_ARG_REQUIRED,
     .help = "the camera's intrinsics (lamprig calib camera)"},
    {.name = "--projector", .type = LR_ARG_PATH, .metavar = "PROJECTOR.json",
     .help = "the projector calibration: its pose too"},
    {.name = "--out", .type = LR_ARG_PATH, .metavar = "pose.json", .flags = LR_ARG_REQUIRED,
     .help = "the pose written"},
    {0},
};

const lr_command lr_calib_pose = {
    .name = "pose",
    .summary = "the camera's (and projector's) pose in scene coordinates (mm) from a photo of a\n"
               "board lying at a known place (its first point at --origin, its +x and +y axes\n"
               "along --x-axis / --y-axis), or from pixels of known scene points (--points)",
    .opts = opts,
    .notes = "--image needs --board, --square, --origin, --x-axis and --y-axis.\n\n"
             LR_CALIB_EXIT_NOTE,
    .run = run,
};
