/* The calibrated camera's view and the mockup's pose: Rodrigues round trips; the camera view's
 * resampling reproduces the lens model (distortion, off-centre principal point) exactly on a
 * linear test pattern; ray-cast labels put the object where the intrinsics project it; the
 * camera pose recovered from a simulated photo of a board lying at a known scene placement;
 * pose.json round trip, refusal of a non-rotation, and the rig folder loader's has_pose. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "calib/camcal.h"
#include "calib/camview.h"
#include "calib/pose.h"
#include "calib/rig.h"
#include "firmware/commands/commands.h"
#include "render/base/atomic_file.h"
#include "tests/support/calib_sim.h"
#include "tests/support/near.h"

static const lr_intrinsics cam = {
    .width = 640, .height = 480, .fx = 610, .fy = 605, .cx = 331.5, .cy = 236.0,
    .dist = {-0.12, 0.03, 0.0005, -0.0003, 0}};

/* A camera at C looking at target with scene up z: X_cam = R (X - C). */
static lr_pose look_at(const double C[3], const double target[3])
{
    double f[3], r[3], d[3], up[3] = {0, 0, 1};
    for (int i = 0; i < 3; i++)
        f[i] = target[i] - C[i];
    double n = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (int i = 0; i < 3; i++)
        f[i] /= n;
    /* Device +X = right = f x up, +Y = down = f x right. */
    r[0] = f[1] * up[2] - f[2] * up[1];
    r[1] = f[2] * up[0] - f[0] * up[2];
    r[2] = f[0] * up[1] - f[1] * up[0];
    n = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int i = 0; i < 3; i++)
        r[i] /= n;
    d[0] = f[1] * r[2] - f[2] * r[1];
    d[1] = f[2] * r[0] - f[0] * r[2];
    d[2] = f[0] * r[1] - f[1] * r[0];
    lr_pose p;
    for (int i = 0; i < 3; i++) {
        p.R[i] = r[i];
        p.R[3 + i] = d[i];
        p.R[6 + i] = f[i];
    }
    for (int i = 0; i < 3; i++)
        p.T[i] = -(p.R[3 * i] * C[0] + p.R[3 * i + 1] * C[1] + p.R[3 * i + 2] * C[2]);
    return p;
}

/* Angle of R1 R2^T, degrees. */
static double angle_between(const double A[9], const double B[9])
{
    double tr = 0;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            tr += A[3 * i + k] * B[3 * i + k];
    double c = 0.5 * (tr - 1);
    return acos(c > 1 ? 1 : c < -1 ? -1 : c) * 180 / M_PI;
}

static void test_rodrigues(void **state)
{
    (void)state;
    const double rvs[4][3] = {{0.1, -0.2, 0.3}, {0, 0, 0}, {1e-8, 0, 0}, {0, M_PI - 1e-9, 0}};
    for (int t = 0; t < 4; t++) {
        double R[9], back[3];
        lr_pose_rodrigues(rvs[t], R);
        lr_pose_rvec(R, back);
        for (int i = 0; i < 3; i++)
            assert_near(back[i], rvs[t][i], 1e-7);
    }
}

/* A pinhole render whose pixels hold their own normalised coordinates (x', y') is a linear
 * function of position, so bilinear resampling reproduces it to float precision; each camera
 * pixel must then read the undistorted coordinates of its own centre, and projecting those
 * back (lr_intrinsics_project) must land on the pixel. */
static void test_camview_remap_is_lens_model(void **state)
{
    (void)state;
    double C[3] = {0, -400, 300}, tgt[3] = {0, 0, 40};
    lr_pose pose = look_at(C, tgt);
    lr_camview *v;
    lr_err e = {0};
    assert_int_equal(lr_camview_create(&cam, &pose, 0, &v, &e), LR_OK);
    int rw, rh;
    lr_camview_render_size(v, &rw, &rh);
    assert_true(rw >= 640 && rh >= 480);
    double f_r = fmax(cam.fx, cam.fy);
    lr_image pin;
    assert_int_equal(lr_image_alloc(&pin, rw, rh, &e), LR_OK);
    for (int y = 0; y < rh; y++)
        for (int x = 0; x < rw; x++) {
            float *p = pin.rgb + 3 * ((size_t)y * rw + x);
            p[0] = (float)((x + 0.5 - 0.5 * rw) / f_r);
            p[1] = (float)((y + 0.5 - 0.5 * rh) / f_r);
        }
    lr_image out;
    assert_int_equal(lr_camview_remap(v, &pin, &out, &e), LR_OK);
    for (int y = 0; y < 480; y += 37)
        for (int x = 0; x < 640; x += 41) {
            const float *p = out.rgb + 3 * ((size_t)y * 640 + x);
            double X[3] = {p[0], p[1], 1}, uv[2];
            lr_intrinsics_project(&cam, X, uv);
            /* float storage: 1e-7 relative in x' (|x'| < 1) is 1e-4 px at f = 610. */
            assert_near(uv[0], x, 2e-3);
            assert_near(uv[1], y, 2e-3);
        }
    lr_image_free(&out);
    lr_image_free(&pin);
    lr_camview_destroy(v);
}

/* ---- board photo simulation -------------------------------------------------------------- */

/* The board (9 x 6 inner corners, 25 mm) lies on the table (z = 0) with its first corner at
 * ORIGIN, its +x along scene +x and its +y along scene -y. White margin one square wide
 * beyond the outer squares; grey table around. */
#define BC 9
#define BR 6
#define SQ 25.0
static const double ORIGIN[3] = {-100, 60, 0};

static double board_albedo(double bx, double by)
{
    if (bx < -2 * SQ || bx > (BC + 1) * SQ || by < -2 * SQ || by > (BR + 1) * SQ)
        return 0.45; /* table */
    if (bx < -SQ || bx > BC * SQ || by < -SQ || by > BR * SQ)
        return 0.95; /* margin */
    int i = (int)floor(bx / SQ), j = (int)floor(by / SQ);
    return ((i + j) & 1) ? 0.95 : 0.05;
}

/* 3 x 3 samples per pixel; each sample undistorted and cast onto the table plane. Noise
 * sigma 2 DN, 8-bit. */
static lr_img board_photo(const lr_pose *pose, double noise_dn)
{
    lr_img g;
    lr_err e = {0};
    assert_int_equal(lr_img_alloc(&g, cam.width, cam.height, 1, 1, &e), LR_OK);
    lr_vec3 C = lr_pose_center(pose);
    unsigned long long st = 99;
    const double *R = pose->R;
    for (int y = 0; y < cam.height; y++)
        for (int x = 0; x < cam.width; x++) {
            double acc = 0;
            for (int sy = 0; sy < 3; sy++)
                for (int sx = 0; sx < 3; sx++) {
                    double uv[2] = {x + (sx - 1) / 3.0, y + (sy - 1) / 3.0}, xy[2];
                    if (lr_intrinsics_undistort(&cam, uv, xy, NULL))
                        continue;
                    double d[3] = {R[0] * xy[0] + R[3] * xy[1] + R[6], R[1] * xy[0] + R[4] * xy[1] + R[7],
                                   R[2] * xy[0] + R[5] * xy[1] + R[8]};
                    if (d[2] >= 0)
                        continue;
                    double t = -C.z / d[2];
                    double px = C.x + t * d[0], py = C.y + t * d[1];
                    /* Board frame: bx along +x, by along -y from the origin. */
                    acc += board_albedo(px - ORIGIN[0], -(py - ORIGIN[1]));
                }
            double dn = 255 * acc / 9 + noise_dn * sim_gauss(&st);
            ((uint8_t *)g.px)[y * cam.width + x] = (uint8_t)(dn < 0 ? 0 : dn > 255 ? 255 : lround(dn));
        }
    return g;
}

/* Expected accuracy: corner noise with sigma_n = 2 DN on an edge of ~230 DN contrast is
 * ~0.02-0.05 px after cornerSubPix; the 3 x 3 box sampling of the simulated edges under
 * distortion adds a bias of the same order (measured reprojection rms 0.056 px). 54 corners
 * at Z ~ 550 mm and f ~ 605 px: ~0.05 px -> 0.05 mm laterally, a few times that in depth,
 * and ~0.05 px / (board extent ~300 px) ~ 0.01 deg of rotation (measured: 0.010 deg,
 * 0.15 mm). Tolerances 0.1 deg and 1 mm are therefore well above what a correct chain gives
 * and far below what a wrong axis, a flipped board or an uncomposed placement gives (tens of
 * mm, degrees). */
static void test_pose_from_board(void **state)
{
    (void)state;
    double C[3] = {60, -380, 420}, tgt[3] = {0, 0, 0};
    lr_pose truth = look_at(C, tgt);
    lr_img photo = board_photo(&truth, 2.0);
    lr_board b = {BC, BR, SQ, LR_BOARD_CHESSBOARD};
    lr_board_placement pl = {{ORIGIN[0], ORIGIN[1], ORIGIN[2]}, {1, 0, 0}, {0, -1, 0}};
    lr_rig_pose p;
    lr_err e = {0};
    int rc = lr_rig_pose_from_board(&photo, &b, &pl, &cam, NULL, &p, &e);
    if (rc)
        fail_msg("%s", e.msg);
    lr_vec3 c = lr_pose_center(&p.camera);
    printf("board pose: rms %.4f px, rotation off %.5f deg, centre off (%.4f, %.4f, %.4f) mm\n",
           p.rms, angle_between(p.camera.R, truth.R), c.x - C[0], c.y - C[1], c.z - C[2]);
    assert_true(p.rms < 0.2);
    assert_true(angle_between(p.camera.R, truth.R) < 0.1);
    assert_near(c.x, C[0], 1.0);
    assert_near(c.y, C[1], 1.0);
    assert_near(c.z, C[2], 1.0);
    assert_false(p.has_projector);
    lr_img_free(&photo);
}

/* A projector 80 mm to the camera's right, turned 5 degrees: its scene pose is the procam
 * extrinsics composed with the camera's. */
static void test_projector_pose_and_file(void **state)
{
    (void)state;
    double C[3] = {60, -380, 420}, tgt[3] = {0, 0, 0};
    lr_pose truth = look_at(C, tgt);
    lr_procam pc;
    memset(&pc, 0, sizeof pc);
    double rv[3] = {0, 5 * M_PI / 180, 0};
    lr_pose_rodrigues(rv, pc.R);
    pc.T[0] = -80;
    /* Board photo replaced by exact projections: points mode, 8 non-coplanar scene points. */
    double X[8 * 3], uv[8 * 2];
    for (int i = 0; i < 8; i++) {
        X[3 * i] = (i & 1) ? 60 : -50;
        X[3 * i + 1] = (i & 2) ? 40 : -70;
        X[3 * i + 2] = (i & 4) ? 120 : 0;
        double Xc[3];
        for (int r = 0; r < 3; r++)
            Xc[r] = truth.R[3 * r] * X[3 * i] + truth.R[3 * r + 1] * X[3 * i + 1] +
                    truth.R[3 * r + 2] * X[3 * i + 2] + truth.T[r];
        lr_intrinsics_project(&cam, Xc, uv + 2 * i);
    }
    lr_rig_pose p;
    lr_err e = {0};
    assert_int_equal(lr_rig_pose_from_points(8, X, uv, &cam, &pc, &p, &e), LR_OK);
    /* Exact data: only the solver's convergence limits it. */
    assert_true(angle_between(p.camera.R, truth.R) < 1e-5);
    for (int i = 0; i < 3; i++)
        assert_near(p.camera.T[i], truth.T[i], 1e-4);
    assert_true(p.has_projector);
    lr_pose ext = {{0}, {0}};
    memcpy(ext.R, pc.R, sizeof ext.R);
    memcpy(ext.T, pc.T, sizeof ext.T);
    lr_pose want;
    lr_pose_compose(&ext, &truth, &want);
    assert_true(angle_between(p.projector.R, want.R) < 1e-5);
    for (int i = 0; i < 3; i++)
        assert_near(p.projector.T[i], want.T[i], 1e-3);

    /* pose.json round trip through the rig folder. */
    char *dir = sim_tempdir("pose");
    char path[512];
    snprintf(path, sizeof path, "%s/pose.json", dir);
    assert_int_equal(lr_rig_pose_save(path, &p, &e), LR_OK);
    lr_rig_calib *rig = calloc(1, sizeof *rig);
    assert_int_equal(lr_rig_calib_load(dir, rig, &e), LR_OK);
    assert_true(rig->has_pose);
    assert_true(rig->pose.has_projector);
    assert_memory_equal(rig->pose.camera.R, p.camera.R, sizeof p.camera.R);
    assert_memory_equal(rig->pose.camera.T, p.camera.T, sizeof p.camera.T);
    lr_rig_calib_free(rig);

    /* A non-rotation is refused naming the field and the file. */
    const char *bad = "{\"version\":1,\"kind\":\"pose\",\"source\":\"points\",\n"
                      "\"camera\":{\"R\":[[1,0,0],[0,1,0],[0,0.5,1]],\"T\":[0,0,0]},\n"
                      "\"rms\":0.1,\"points\":8}\n";
    lr_err fe = {0};
    assert_int_equal(lr_atomic_write(path, bad, strlen(bad), &fe), LR_OK);
    assert_int_equal(lr_rig_calib_load(dir, rig, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "pose.json"));
    assert_non_null(strstr(e.msg, "camera.R"));
    free(rig);
    sim_rmdir(dir);
    free(dir);
}

/* `lamprig calib pose` on a simulated photo: writes pose.json that the rig loader reads,
 * with the same pose as the library call; a photo without the board fails (exit 1) and
 * leaves no file. */
static void test_pose_cli(void **state)
{
    (void)state;
    double C[3] = {-40, -420, 380}, tgt[3] = {10, 0, 0};
    lr_pose truth = look_at(C, tgt);
    lr_img photo = board_photo(&truth, 1.0);
    char *dir = sim_tempdir("posecli");
    char img[600], blank[600], camf[600], out[600];
    snprintf(img, sizeof img, "%s/board.png", dir);
    snprintf(blank, sizeof blank, "%s/blank.png", dir);
    snprintf(camf, sizeof camf, "%s/camera.json", dir);
    snprintf(out, sizeof out, "%s/pose.json", dir);
    lr_err e = {0};
    assert_int_equal(lr_img_write(img, &photo, &e), LR_OK);
    memset(photo.px, 128, (size_t)photo.w * photo.h);
    assert_int_equal(lr_img_write(blank, &photo, &e), LR_OK);
    lr_camcal cc;
    memset(&cc, 0, sizeof cc);
    cc.k = cam;
    cc.rms = 0.1;
    cc.board = (lr_board){BC, BR, SQ, LR_BOARD_CHESSBOARD};
    cc.subpix_window = 11;
    assert_int_equal(lr_camcal_save(camf, &cc, &e), LR_OK);
    char origin[64];
    snprintf(origin, sizeof origin, "%g,%g,%g", ORIGIN[0], ORIGIN[1], ORIGIN[2]);
    char *argv[] = {"calib", "pose", "--image", img, "--board", "9x6", "--square", "25",
                    "--origin", origin, "--x-axis", "1,0,0", "--y-axis", "0,-1,0",
                    "--camera", camf, "--out", out};
    assert_int_equal(lr_cmd_calib(18, argv), 0);
    lr_rig_calib *rig = calloc(1, sizeof *rig);
    assert_int_equal(lr_rig_calib_load(dir, rig, &e), LR_OK);
    assert_true(rig->has_pose && rig->has_camera);
    assert_true(angle_between(rig->pose.camera.R, truth.R) < 0.1);
    lr_vec3 c = lr_pose_center(&rig->pose.camera);
    assert_near(c.x, C[0], 1.0);
    assert_near(c.y, C[1], 1.0);
    assert_near(c.z, C[2], 1.0);
    lr_rig_calib_free(rig);
    free(rig);
    assert_int_equal(unlink(out), 0);
    argv[3] = blank;
    assert_int_equal(lr_cmd_calib(18, argv), 1);
    assert_int_equal(access(out, F_OK), -1);
    lr_img_free(&photo);
    sim_rmdir(dir);
    free(dir);
}

static void test_bad_placement(void **state)
{
    (void)state;
    lr_board_placement pl = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
    lr_pose p;
    lr_err e = {0};
    assert_int_equal(lr_board_placement_pose(&pl, &p, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "parallel"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_rodrigues),
        cmocka_unit_test(test_camview_remap_is_lens_model),
        cmocka_unit_test(test_pose_from_board),
        cmocka_unit_test(test_projector_pose_and_file),
        cmocka_unit_test(test_pose_cli),
        cmocka_unit_test(test_bad_placement),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
