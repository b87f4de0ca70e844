/* calib/cv_shim.h for the arm64 test binaries (make test-arm64): every entry point fails with
 * an error naming the missing modules. The arm64 OpenCV modules behind cv_shim.cpp (calib3d,
 * features2d, imgcodecs, videoio, contrib) are unpacked only for linking
 * (tools/cross/arm64.mk): their own dependencies (GDAL, Qt, FFmpeg, GStreamer, ...) are not
 * installed for arm64 here, so a test binary that linked them could not start under qemu.
 * The arm64 subset is the GL-free tests that never reach OpenCV; one that did would fail on
 * this error, never pass silently. The package's binaries link the real cv_shim.cpp. */
#include "calib/cv_shim.h"

#define ABSENT(e) lr_err_set((e), LR_ENODEV, "%s: OpenCV is not in the arm64 test build", __func__)

int lr_cv_imread(const char *path, int mode, lr_img *out, lr_err *e) { return ABSENT(e); }
int lr_cv_imencode(const char *ext, const lr_img *img, void **buf, size_t *len, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_find_board(const lr_img *gray, int pattern, int cols, int rows, int subpix_half,
                     double *xy, bool *found, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_calibrate(const lr_cv_views *v, int width, int height, int flags, double K[9],
                    double dist[5], double *rms, double *view_err, double *extr, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_stereo_calibrate(const lr_cv_views *v, int width, int height, const double K1[9],
                           const double d1[5], const double K2[9], const double d2[5],
                           double R[9], double T[3], double *rms, double *view_err, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_find_homography(int n, const double *src, const double *dst, double ransac_px,
                          double H[9], int *inliers, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_project_points(int n, const double *X, const double rvec[3], const double tvec[3],
                         const double K[9], const double dist[5], double *uv, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_solve_pnp(int n, const double *obj, const double *img, const double K[9],
                    const double dist[5], bool planar, double rvec[3], double tvec[3],
                    double *rms, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_graycode_count(int pw, int ph, int *count, lr_err *e) { return ABSENT(e); }
int lr_cv_graycode_generate(int pw, int ph, lr_cv_image_sink sink, void *ctx, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_graycode_decode(int pw, int ph, const char *const *patterns, int npatterns,
                          const char *white, const char *black, int contrast, int shadow,
                          const lr_progress *progress, const char *stage, int *cam_w,
                          int *cam_h, int32_t **proj_xy, uint8_t **status, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_debevec_response(const lr_img *imgs, const double *times, int n, int samples,
                           double lambda, double *response, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_detect_colorchecker(const lr_img *photo, double *rgb, lr_err *e) { return ABSENT(e); }
int lr_cv_camera_open(const char *device, int width, int height, lr_cv_camera **out, lr_err *e)
{
    return ABSENT(e);
}
int lr_cv_camera_grab(lr_cv_camera *cam, int discard, lr_img *out, lr_err *e) { return ABSENT(e); }
void lr_cv_camera_close(lr_cv_camera *cam) {}
