/* Projector calibration end to end on a simulated rig: a 640x480 camera with barrel
 * distortion, a 320x240 projector with lens shift and its own distortion, 180 mm to the
 * side and turned towards a 9x6 chessboard (30 mm squares) held in seven poses about 0.6 m
 * away. Every frame of the Gray-code sequence is rendered (2x2 supersampling, 1 DN noise),
 * written as PNGs into one folder per pose and calibrated from the folders, as a capture
 * session on the rig would be. Intrinsics and extrinsics must come back. */
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
#include "calib/procam.h"
#include "firmware/cli.h"
#include "tests/support/calib_sim.h"
#include "tests/support/near.h"

#define NPOSES 7

static const lr_intrinsics CAM = {640, 480, 620.0, 620.0, 318.0, 242.0, {-0.08, 0.02, 0, 0, 0}};
static const lr_intrinsics PROJ = {320, 240, 380.0, 380.0, 162.0, 214.0, {0.03, 0, 0, 0, 0}};

/* Rotation matrix (row-major) from an axis-angle vector (Rodrigues). */
static void rodrigues(const double r[3], double R[9])
{
    double th = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    double k[3] = {0, 0, 1};
    if (th > 0)
        for (int i = 0; i < 3; i++)
            k[i] = r[i] / th;
    double c = cos(th), s = sin(th), v = 1 - c;
    double m[9] = {c + k[0] * k[0] * v,        k[0] * k[1] * v - k[2] * s, k[0] * k[2] * v + k[1] * s,
                   k[1] * k[0] * v + k[2] * s, c + k[1] * k[1] * v,        k[1] * k[2] * v - k[0] * s,
                   k[2] * k[0] * v - k[1] * s, k[2] * k[1] * v + k[0] * s, c + k[2] * k[2] * v};
    memcpy(R, m, sizeof m);
}

static void mat_vec(const double R[9], const double x[3], double y[3])
{
    for (int i = 0; i < 3; i++)
        y[i] = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2];
}

/* Projector extrinsics: centre at C in the camera frame, yawed towards the board. */
static void rig_extrinsics(double R[9], double T[3])
{
    double r[3] = {0.3, 0.23, 0.01};
    rodrigues(r, R);
    double C[3] = {180.0, -40.0, -20.0}, RC[3];
    mat_vec(R, C, RC);
    for (int i = 0; i < 3; i++)
        T[i] = -RC[i];
}

/* Board poses (board frame -> camera frame). The board's first inner corner is its origin;
 * the middle of the 8 x 5 squares between inner corners is at (120, 75). */
static void board_pose(int i, double Rb[9], double Tb[3])
{
    static const double rv[NPOSES][3] = {
        {0.05, 0.02, 0.0},   {0.4, -0.1, 0.05},  {-0.35, 0.3, -0.1}, {0.1, 0.45, 0.15},
        {-0.2, -0.4, -0.05}, {0.3, 0.3, 0.3},    {-0.3, -0.2, -0.25}};
    static const double centre[NPOSES][3] = {
        {10, 0, 600},   {-50, 30, 580},  {60, -35, 620}, {-40, -30, 560},
        {50, 25, 640},  {-20, 35, 600},  {25, -20, 560}};
    rodrigues(rv[i], Rb);
    double mid[3] = {120, 75, 0}, Rm[3];
    mat_vec(Rb, mid, Rm);
    for (int k = 0; k < 3; k++)
        Tb[k] = centre[i][k] - Rm[k];
}

static float albedo_at(double u, double v)
{
    const double s = 30.0;
    if (u >= -s && u < 9 * s && v >= -s && v < 6 * s) {
        int i = (int)floor(u / s) + 1, j = (int)floor(v / s) + 1;
        return (i + j) % 2 == 0 ? 0.12f : 0.85f;
    }
    if (u >= -s - 25 && u < 9 * s + 25 && v >= -s - 25 && v < 6 * s + 25)
        return 0.85f; /* white margin around the squares */
    return 0.25f;     /* the wall the board is held against */
}

/* Undistorted ray (x', y', 1) of each sample: the same for every pose, computed once. */
static double *camera_rays(void)
{
    size_t n = (size_t)CAM.width * (size_t)CAM.height * 4;
    double *rays = malloc(sizeof *rays * 2 * n);
    assert_non_null(rays);
    lr_err e = {0};
    for (int y = 0; y < CAM.height; y++)
        for (int x = 0; x < CAM.width; x++)
            for (int k = 0; k < 4; k++) {
                double uv[2] = {x + (k % 2 ? 0.25 : -0.25), y + (k / 2 ? 0.25 : -0.25)};
                size_t i = ((size_t)y * (size_t)CAM.width + (size_t)x) * 4 + (size_t)k;
                assert_int_equal(lr_intrinsics_undistort(&CAM, uv, rays + 2 * i, &e), LR_OK);
            }
    return rays;
}

static void build_pose(sim_scene *s, const double *rays, int pose, const double R[9],
                       const double T[3])
{
    double Rb[9], Tb[3];
    board_pose(pose, Rb, Tb);
    double n[3] = {Rb[2], Rb[5], Rb[8]}; /* board normal in the camera frame */
    double nd = n[0] * Tb[0] + n[1] * Tb[1] + n[2] * Tb[2];
    size_t total = (size_t)CAM.width * (size_t)CAM.height * 4;
    for (size_t i = 0; i < total; i++) {
        sim_sample *p = &s->samples[i];
        double dir[3] = {rays[2 * i], rays[2 * i + 1], 1};
        double t = nd / (n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2]);
        double X[3] = {t * dir[0], t * dir[1], t * dir[2]};
        double d[3] = {X[0] - Tb[0], X[1] - Tb[1], X[2] - Tb[2]};
        double u = Rb[0] * d[0] + Rb[3] * d[1] + Rb[6] * d[2];
        double v = Rb[1] * d[0] + Rb[4] * d[1] + Rb[7] * d[2];
        p->albedo = albedo_at(u, v);
        double Xp[3];
        mat_vec(R, X, Xp);
        for (int k = 0; k < 3; k++)
            Xp[k] += T[k];
        double pp[2];
        lr_intrinsics_project(&PROJ, Xp, pp);
        p->px = Xp[2] > 0 ? (float)pp[0] : NAN;
        p->py = Xp[2] > 0 ? (float)pp[1] : NAN;
    }
}

/* The set-up itself must be sound: every board corner visible to both devices, inside a
 * margin (else a failure would be the test's fault). */
static void check_setup(const double R[9], const double T[3])
{
    for (int pose = 0; pose < NPOSES; pose++) {
        double Rb[9], Tb[3];
        board_pose(pose, Rb, Tb);
        for (int r = 0; r < 6; r++)
            for (int c = 0; c < 9; c++) {
                double B[3] = {30.0 * c, 30.0 * r, 0}, X[3], Xp[3], uv[2], pp[2];
                mat_vec(Rb, B, X);
                for (int i = 0; i < 3; i++)
                    X[i] += Tb[i];
                mat_vec(R, X, Xp);
                for (int i = 0; i < 3; i++)
                    Xp[i] += T[i];
                lr_intrinsics_project(&CAM, X, uv);
                lr_intrinsics_project(&PROJ, Xp, pp);
                if (!(uv[0] > 30 && uv[0] < 610 && uv[1] > 30 && uv[1] < 450 && pp[0] > 15 &&
                      pp[0] < 305 && pp[1] > 15 && pp[1] < 225))
                    fail_msg("pose %d corner (%d,%d): camera (%.0f,%.0f) projector (%.0f,%.0f)",
                             pose, c, r, uv[0], uv[1], pp[0], pp[1]);
            }
    }
}

static char *session;

static int render_session(void **state)
{
    (void)state;
    double R[9], T[3];
    rig_extrinsics(R, T);
    check_setup(R, T);
    session = sim_tempdir("procam");
    if (!session)
        return -1;
    sim_scene s;
    if (sim_scene_alloc(&s, CAM.width, CAM.height, 2))
        return -1;
    s.ambient = 0.03;
    s.gain = 1.0;
    s.black = 0.02;
    s.noise_dn = 1.0;
    double *rays = camera_rays();
    for (int pose = 0; pose < NPOSES; pose++) {
        build_pose(&s, rays, pose, R, T);
        s.seed = 100u + (unsigned)pose;
        char dir[512];
        snprintf(dir, sizeof dir, "%s/pose_%02d", session, pose + 1);
        if (sim_write_graycode(&s, PROJ.width, PROJ.height, dir))
            return -1;
    }
    free(rays);
    sim_scene_free(&s);
    return 0;
}

static int remove_session(void **state)
{
    (void)state;
    if (session) {
        sim_rmdir(session);
        free(session);
    }
    return 0;
}

static void rotation_angle_deg(const double A[9], const double B[9], double *deg)
{
    /* angle of A B^T */
    double tr = 0;
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++)
            tr += A[3 * i + k] * B[3 * i + k];
    double c = (tr - 1) / 2;
    *deg = acos(c > 1 ? 1 : c < -1 ? -1 : c) * 180 / M_PI;
}

static void check_result(const lr_procam *p, double f_tol, double c_tol, double t_tol,
                         double r_tol_deg)
{
    double R[9], T[3];
    rig_extrinsics(R, T);
    print_message("projector fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f (truth 380 380 162 214 "
                  "0.03), rms %.3f\n",
                  p->proj.fx, p->proj.fy, p->proj.cx, p->proj.cy, p->proj.dist[0], p->proj_rms);
    print_message("camera fx %.2f cx %.2f cy %.2f; T (%.2f %.2f %.2f) truth (%.2f %.2f %.2f); "
                  "stereo rms %.3f\n",
                  p->cam.fx, p->cam.cx, p->cam.cy, p->T[0], p->T[1], p->T[2], T[0], T[1], T[2],
                  p->rms);
    assert_int_equal(p->nposes, NPOSES);
    assert_int_equal(p->nrejected, 0);
    assert_int_equal(p->proj.width, 320);
    assert_int_equal(p->proj.height, 240);
    assert_near(p->proj.fx, PROJ.fx, f_tol);
    assert_near(p->proj.fy, PROJ.fy, f_tol);
    assert_near(p->proj.cx, PROJ.cx, c_tol);
    assert_near(p->proj.cy, PROJ.cy, c_tol);
    for (int i = 0; i < 3; i++)
        assert_near(p->T[i], T[i], t_tol);
    double deg;
    rotation_angle_deg(p->R, R, &deg);
    print_message("rotation error %.4f deg\n", deg);
    assert_true(deg < r_tol_deg);
    /* The projector sees each corner through a local homography of quantised decodings;
     * sub-pixel RMS on both devices means the correspondences are right. */
    assert_true(p->rms < 0.3);
    for (int i = 0; i < p->nposes; i++)
        assert_int_equal(p->poses[i].corners, 54);
}

static void test_projector_with_camera_file(void **state)
{
    (void)state;
    /* Through the CLI, as on the rig: a camera calibration file, the session folder, the
     * result file. */
    char campath[512], out[512];
    snprintf(campath, sizeof campath, "%s/camera.json", session);
    snprintf(out, sizeof out, "%s/projector.json", session);
    lr_camcal cam = {.k = CAM, .rms = 0.05, .board = {9, 6, 30.0, LR_BOARD_CHESSBOARD},
                     .subpix_window = 11};
    lr_err e = {0};
    assert_int_equal(lr_camcal_save(campath, &cam, &e), LR_OK);
    char *argv[] = {"lamprig", "calib", "projector", "calibrate", "--captures", session,
                    "--board", "9x6", "--square", "30", "--camera", campath, "--out", out, NULL};
    assert_int_equal(lr_cli_main(14, argv), LR_EXIT_OK);
    lr_procam p;
    int rc = lr_procam_load(out, &p, &e);
    if (rc)
        fail_msg("load: %s", e.msg);
    /* Tolerances: projector corners come out of local homographies to ~0.05 px (graycode
     * test) and camera corners from 2x2-supersampled edges to ~0.05 px; seven poses of 54
     * corners pin the projector's focal length to a few tenths of a pixel (measured 0.1 px)
     * and its principal point to about a pixel (measured 0.9 px: the board covers rows
     * 37..208 of 240, and the principal point trades off against the rotation). So: 1.5 px
     * on f (0.4 %), 2 px on the principal point, the 187 mm baseline to 2 mm (measured
     * 0.5 mm), the rotation to 0.3 degrees (a 1 px principal-point shift alone is 0.15 deg
     * at f = 380; measured 0.15 deg). */
    check_result(&p, 1.5, 2.0, 2.0, 0.3);
    assert_true(p.camera_from_file);
    assert_true(p.cam_rms == 0.05);
    assert_true(p.cam.fx == CAM.fx);
    assert_string_equal(p.poses[2].name + strlen(p.poses[2].name) - 7, "pose_03");
    /* The projector pose in a world frame composes with the camera's. */
    double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, Z[3] = {0, 0, 0}, Rp[9], Tp[3];
    lr_procam_projector_pose(&p, I, Z, Rp, Tp);
    for (int i = 0; i < 9; i++)
        assert_near(Rp[i], p.R[i], 1e-15);

    /* decode of one pose through the CLI, with the map written. */
    char pose[512], map[512];
    snprintf(pose, sizeof pose, "%s/pose_01", session);
    snprintf(map, sizeof map, "%s/map.png", session);
    char *argv2[] = {"lamprig", "calib", "projector", "decode", "--captures", pose, "--map", map,
                     NULL};
    assert_int_equal(lr_cli_main(8, argv2), LR_EXIT_OK);
    lr_gc_map *m;
    assert_int_equal(lr_gc_map_load(map, 320, 240, &m, &e), LR_OK);
    /* The board's white squares and margin decode; its black squares (12 % albedo, 30 DN
     * white-black) fall under the 40 DN shadow threshold. Roughly half the frame is board. */
    assert_true(lr_gc_map_count(m, LR_GC_VALID) > 640 * 480 / 5);
    assert_true(lr_gc_map_count(m, LR_GC_SHADOW) > 0);
    lr_gc_map_destroy(m);
    unlink(map);
    unlink(out);
    unlink(campath);
    lr_procam_free(&p);
}

static void test_projector_and_camera(void **state)
{
    (void)state;
    /* Camera intrinsics calibrated from the same five poses (no camera file). */
    lr_procam_desc d = {.captures = session, .board = {9, 6, 30.0, LR_BOARD_CHESSBOARD}};
    lr_procam p;
    lr_err e = {0};
    int rc = lr_procam_run(&d, &p, &e);
    if (rc)
        fail_msg("procam: %s", e.msg);
    /* The camera's own errors (measured 0.9 px on f, 2 px on cx) now propagate into the
     * extrinsics: tolerances about twice as loose. */
    assert_near(p.cam.fx, CAM.fx, 3.0);
    assert_near(p.cam.cx, CAM.cx, 3.0);
    assert_near(p.cam.dist[0], CAM.dist[0], 0.02);
    check_result(&p, 3.0, 3.0, 4.0, 0.5);
    assert_false(p.camera_from_file);
    lr_procam_free(&p);
}

static void test_too_few_poses(void **state)
{
    (void)state;
    /* Two poses only (links into the session): a clear error, nothing half-done. */
    char *two = sim_tempdir("procam_two");
    assert_non_null(two);
    for (int i = 1; i <= 2; i++) {
        char target[512], link[512];
        snprintf(target, sizeof target, "%s/pose_%02d", session, i);
        snprintf(link, sizeof link, "%s/pose_%02d", two, i);
        assert_int_equal(symlink(target, link), 0);
    }
    lr_procam_desc d = {.captures = two, .board = {9, 6, 30.0, LR_BOARD_CHESSBOARD},
                        .camera = &CAM};
    lr_procam p;
    lr_err e = {0};
    assert_int_equal(lr_procam_run(&d, &p, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "2 usable poses of 2"));
    assert_non_null(strstr(e.msg, "need at least 3"));
    /* The wrong board: every pose rejected, the first reason named. */
    d.board = (lr_board){7, 5, 30.0, LR_BOARD_CHESSBOARD};
    assert_int_equal(lr_procam_run(&d, &p, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "0 usable poses of 2"));
    assert_non_null(strstr(e.msg, "board not found"));
    /* Camera intrinsics for another image size are refused. */
    lr_intrinsics other = CAM;
    other.width = 800;
    other.cx = 400;
    d.board = (lr_board){9, 6, 30.0, LR_BOARD_CHESSBOARD};
    d.camera = &other;
    d.min_poses = 2;
    assert_int_equal(lr_procam_run(&d, &p, &e), LR_EINVAL);
    assert_non_null(strstr(e.msg, "camera intrinsics are for 800x480 images"));
    sim_rmdir(two);
    free(two);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_projector_with_camera_file),
        cmocka_unit_test(test_projector_and_camera),
        cmocka_unit_test(test_too_few_poses),
    };
    return cmocka_run_group_tests(tests, render_session, remove_session);
}
