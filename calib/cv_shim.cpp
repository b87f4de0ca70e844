// lamprig calib — the one C++ file: extern "C" wrappers around OpenCV 4.6 (see cv_shim.h).
// Everything here converts between plain C buffers and cv::Mat, calls one OpenCV routine and
// turns exceptions into lr_err codes. Logic that is not "call OpenCV" belongs in calib/*.c.
#include "calib/cv_shim.h"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/mcc/checker_detector.hpp> // not mcc.hpp: its ccm.hpp trips -Wcomment
#include <opencv2/photo.hpp>
#include <opencv2/structured_light.hpp>
#include <opencv2/videoio.hpp>

namespace {

// Maps the exception in flight to an lr_err; `what` names the operation and its input.
int fail_current(lr_err *e, const char *what)
{
    try {
        throw;
    } catch (const cv::Exception &x) {
        return lr_err_set(e, LR_EINVAL, "%s: OpenCV: %s", what, x.err.c_str());
    } catch (const std::bad_alloc &) {
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", what);
    } catch (const std::exception &x) {
        return lr_err_set(e, LR_EINVAL, "%s: %s", what, x.what());
    } catch (...) {
        return lr_err_set(e, LR_EINVAL, "%s: unknown C++ exception", what);
    }
}

// cv::imread of a missing file logs a warning on stderr before returning nothing: check
// first so the caller's message is the only one.
cv::Mat read_gray(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return cv::Mat();
    return cv::imread(path, cv::IMREAD_GRAYSCALE);
}

int cv_depth(int depth)
{
    return depth == 1 ? CV_8U : depth == 2 ? CV_16U : CV_32F;
}

// A Mat header over an lr_img (no copy).
cv::Mat wrap(const lr_img *img)
{
    return cv::Mat(img->h, img->w, CV_MAKETYPE(cv_depth(img->depth), img->channels), img->px);
}

// Copies a Mat (1 or 3 channels, 8U/16U/32F, already RGB) into a new lr_img.
int to_img(const cv::Mat &m, lr_img *out, lr_err *e)
{
    int depth = m.depth() == CV_8U ? 1 : m.depth() == CV_16U ? 2 : 4;
    int rc = lr_img_alloc(out, m.cols, m.rows, m.channels(), depth, e);
    if (rc)
        return rc;
    cv::Mat dst = wrap(out);
    m.copyTo(dst);
    return LR_OK;
}

std::vector<cv::Point3f> obj_points(const lr_cv_views *v, size_t &at, int n)
{
    std::vector<cv::Point3f> p((size_t)n);
    for (int i = 0; i < n; i++, at++)
        p[(size_t)i] = cv::Point3f((float)v->obj[3 * at], (float)v->obj[3 * at + 1],
                                   (float)v->obj[3 * at + 2]);
    return p;
}

std::vector<cv::Point2f> img_points(const double *xy, size_t at, int n)
{
    std::vector<cv::Point2f> p((size_t)n);
    for (int i = 0; i < n; i++)
        p[(size_t)i] = cv::Point2f((float)xy[2 * (at + (size_t)i)],
                                   (float)xy[2 * (at + (size_t)i) + 1]);
    return p;
}

void copy_out(const cv::Mat &m, double *dst, int n)
{
    cv::Mat d;
    m.convertTo(d, CV_64F);
    d = d.reshape(1, 1);
    for (int i = 0; i < n; i++)
        dst[i] = i < d.cols ? d.at<double>(0, i) : 0.0;
}

} // namespace

extern "C" {

int lr_cv_imread(const char *path, int mode, lr_img *out, lr_err *e)
{
    *out = lr_img{};
    try {
        int flags = mode == LR_IMG_GRAY8 ? cv::IMREAD_GRAYSCALE
                    : mode == LR_IMG_RGB8 ? cv::IMREAD_COLOR
                                          : cv::IMREAD_UNCHANGED;
        struct stat st;
        if (stat(path, &st) != 0)
            return lr_err_set(e, LR_EIO, "%s: no such image file", path);
        cv::Mat m = cv::imread(path, flags);
        if (m.empty())
            return lr_err_set(e, LR_EPARSE, "%s: not an image OpenCV can decode", path);
        if (m.channels() == 4)
            cv::cvtColor(m, m, cv::COLOR_BGRA2RGB);
        else if (m.channels() == 3)
            cv::cvtColor(m, m, cv::COLOR_BGR2RGB);
        else if (m.channels() != 1)
            return lr_err_set(e, LR_EPARSE, "%s: %d channels (expected 1, 3 or 4)", path,
                              m.channels());
        if (m.depth() != CV_8U && m.depth() != CV_16U && m.depth() != CV_32F)
            m.convertTo(m, CV_32F);
        return to_img(m, out, e);
    } catch (...) {
        return fail_current(e, path);
    }
}

int lr_cv_imencode(const char *ext, const lr_img *img, void **buf, size_t *len, lr_err *e)
{
    *buf = nullptr;
    *len = 0;
    try {
        cv::Mat m = wrap(img);
        cv::Mat bgr;
        if (img->channels == 3)
            cv::cvtColor(m, bgr, cv::COLOR_RGB2BGR);
        else
            bgr = m;
        std::vector<uchar> out;
        if (!cv::imencode(ext, bgr, out))
            return lr_err_set(e, LR_EIO, "cannot encode a %dx%d image as %s", img->w, img->h,
                              ext);
        void *p = std::malloc(out.size() ? out.size() : 1);
        if (!p)
            return lr_err_set(e, LR_ENOMEM, "encoding %s: out of memory", ext);
        std::memcpy(p, out.data(), out.size());
        *buf = p;
        *len = out.size();
        return LR_OK;
    } catch (...) {
        return fail_current(e, ext);
    }
}

int lr_cv_find_board(const lr_img *gray, int pattern, int cols, int rows, int subpix_half,
                     double *xy, bool *found, lr_err *e)
{
    *found = false;
    try {
        if (gray->channels != 1 || gray->depth != 1)
            return lr_err_set(e, LR_EINVAL, "board detection needs an 8-bit grey image");
        cv::Mat m = wrap(gray);
        cv::Size size(cols, rows);
        std::vector<cv::Point2f> pts;
        bool ok;
        if (pattern == LR_BOARD_CHESSBOARD) {
            ok = cv::findChessboardCorners(m, size, pts,
                                           cv::CALIB_CB_ADAPTIVE_THRESH |
                                               cv::CALIB_CB_NORMALIZE_IMAGE);
            if (ok) {
                // Adaptive half-window: 40% of the smallest corner spacing, at most 11. On
                // OpenCV's sample photos a fixed 11 px window over-reaches where the squares
                // are small (left02.jpg: 21.7 px spacing, its RMS error 1.22 px; 0.17 px with
                // the adaptive window).
                double spacing = 1e9;
                for (int r = 0; r < rows; r++)
                    for (int c = 0; c < cols; c++) {
                        const cv::Point2f &p = pts[(size_t)(r * cols + c)];
                        if (c + 1 < cols)
                            spacing = std::min(spacing,
                                               (double)cv::norm(p - pts[(size_t)(r * cols + c + 1)]));
                        if (r + 1 < rows)
                            spacing = std::min(spacing,
                                               (double)cv::norm(p - pts[(size_t)((r + 1) * cols + c)]));
                    }
                int half = subpix_half > 0 ? subpix_half
                                           : std::max(2, std::min(11, (int)(0.4 * spacing)));
                cv::cornerSubPix(m, pts, cv::Size(half, half), cv::Size(-1, -1),
                                 cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT,
                                                  30, 0.0001));
            }
        } else {
            int flag = pattern == LR_BOARD_CIRCLES ? cv::CALIB_CB_SYMMETRIC_GRID
                                                   : cv::CALIB_CB_ASYMMETRIC_GRID;
            ok = cv::findCirclesGrid(m, size, pts, flag);
        }
        if (!ok || (int)pts.size() != cols * rows)
            return LR_OK;
        for (size_t i = 0; i < pts.size(); i++) {
            xy[2 * i] = pts[i].x;
            xy[2 * i + 1] = pts[i].y;
        }
        *found = true;
        return LR_OK;
    } catch (...) {
        return fail_current(e, "board detection");
    }
}

int lr_cv_calibrate(const lr_cv_views *v, int width, int height, int flags, double K[9],
                    double dist[5], double *rms, double *view_err, double *extr, lr_err *e)
{
    try {
        std::vector<std::vector<cv::Point3f>> obj;
        std::vector<std::vector<cv::Point2f>> img;
        size_t at = 0;
        for (int i = 0; i < v->nviews; i++) {
            size_t start = at;
            obj.push_back(obj_points(v, at, v->npoints[i]));
            img.push_back(img_points(v->img, start, v->npoints[i]));
        }
        cv::Mat k(3, 3, CV_64F), d(1, 5, CV_64F);
        for (int i = 0; i < 9; i++)
            k.at<double>(i / 3, i % 3) = K[i];
        for (int i = 0; i < 5; i++)
            d.at<double>(0, i) = dist[i];
        int cvf = 0;
        if (flags & LR_CV_FIX_ASPECT) {
            cvf |= cv::CALIB_FIX_ASPECT_RATIO;
            // Only the ratio fx/fy of the input is used without USE_GUESS: 1 unless given.
            if (!(k.at<double>(0, 0) > 0 && k.at<double>(1, 1) > 0)) {
                k.at<double>(0, 0) = k.at<double>(1, 1) = 1.0;
                k.at<double>(2, 2) = 1.0;
            }
        }
        if (flags & LR_CV_USE_GUESS)
            cvf |= cv::CALIB_USE_INTRINSIC_GUESS;
        if (flags & LR_CV_ZERO_TANGENT)
            cvf |= cv::CALIB_ZERO_TANGENT_DIST;
        if (flags & LR_CV_FIX_K3)
            cvf |= cv::CALIB_FIX_K3;
        std::vector<cv::Mat> rvecs, tvecs;
        cv::Mat sdi, sde, pve;
        double r = cv::calibrateCamera(obj, img, cv::Size(width, height), k, d, rvecs, tvecs, sdi,
                                       sde, pve, cvf);
        copy_out(k, K, 9);
        copy_out(d, dist, 5);
        *rms = r;
        for (int i = 0; i < v->nviews; i++) {
            if (view_err)
                view_err[i] = pve.at<double>(i);
            if (extr) {
                copy_out(rvecs[(size_t)i], extr + 6 * i, 3);
                copy_out(tvecs[(size_t)i], extr + 6 * i + 3, 3);
            }
        }
        return LR_OK;
    } catch (...) {
        return fail_current(e, "calibrateCamera");
    }
}

int lr_cv_stereo_calibrate(const lr_cv_views *v, int width, int height, const double K1[9],
                           const double d1[5], const double K2[9], const double d2[5],
                           double R[9], double T[3], double *rms, double *view_err, lr_err *e)
{
    try {
        if (!v->img2)
            return lr_err_set(e, LR_EINVAL, "stereoCalibrate: second point set missing");
        std::vector<std::vector<cv::Point3f>> obj;
        std::vector<std::vector<cv::Point2f>> img1, img2;
        size_t at = 0;
        for (int i = 0; i < v->nviews; i++) {
            size_t start = at;
            obj.push_back(obj_points(v, at, v->npoints[i]));
            img1.push_back(img_points(v->img, start, v->npoints[i]));
            img2.push_back(img_points(v->img2, start, v->npoints[i]));
        }
        cv::Mat k1(3, 3, CV_64F, (void *)K1), k2(3, 3, CV_64F, (void *)K2);
        cv::Mat dd1(1, 5, CV_64F, (void *)d1), dd2(1, 5, CV_64F, (void *)d2);
        k1 = k1.clone();
        k2 = k2.clone();
        dd1 = dd1.clone();
        dd2 = dd2.clone();
        cv::Mat r, t, E, F, pve;
        double err = cv::stereoCalibrate(obj, img1, img2, k1, dd1, k2, dd2, cv::Size(width, height),
                                         r, t, E, F, pve, cv::CALIB_FIX_INTRINSIC);
        copy_out(r, R, 9);
        copy_out(t, T, 3);
        *rms = err;
        if (view_err)
            for (int i = 0; i < v->nviews; i++) {
                view_err[2 * i] = pve.at<double>(i, 0);
                view_err[2 * i + 1] = pve.at<double>(i, 1);
            }
        return LR_OK;
    } catch (...) {
        return fail_current(e, "stereoCalibrate");
    }
}

int lr_cv_find_homography(int n, const double *src, const double *dst, double ransac_px,
                          double H[9], int *inliers, lr_err *e)
{
    try {
        if (n < 4)
            return lr_err_set(e, LR_EINVAL, "homography: %d point pairs (need 4)", n);
        std::vector<cv::Point2d> s((size_t)n), d((size_t)n);
        for (int i = 0; i < n; i++) {
            s[(size_t)i] = cv::Point2d(src[2 * i], src[2 * i + 1]);
            d[(size_t)i] = cv::Point2d(dst[2 * i], dst[2 * i + 1]);
        }
        cv::Mat mask;
        cv::Mat h = cv::findHomography(s, d, ransac_px > 0 ? cv::RANSAC : 0,
                                       ransac_px > 0 ? ransac_px : 3.0, mask);
        if (h.empty())
            return lr_err_set(e, LR_EINVAL, "homography: degenerate point set (%d pairs)", n);
        copy_out(h, H, 9);
        if (inliers)
            *inliers = mask.empty() ? n : cv::countNonZero(mask);
        return LR_OK;
    } catch (...) {
        return fail_current(e, "findHomography");
    }
}

int lr_cv_project_points(int n, const double *X, const double rvec[3], const double tvec[3],
                         const double K[9], const double dist[5], double *uv, lr_err *e)
{
    try {
        std::vector<cv::Point3d> p((size_t)n);
        for (int i = 0; i < n; i++)
            p[(size_t)i] = cv::Point3d(X[3 * i], X[3 * i + 1], X[3 * i + 2]);
        cv::Mat r(3, 1, CV_64F, (void *)rvec), t(3, 1, CV_64F, (void *)tvec);
        cv::Mat k(3, 3, CV_64F, (void *)K), d(1, 5, CV_64F, (void *)dist);
        std::vector<cv::Point2d> out;
        cv::projectPoints(p, r, t, k, d, out);
        for (int i = 0; i < n; i++) {
            uv[2 * i] = out[(size_t)i].x;
            uv[2 * i + 1] = out[(size_t)i].y;
        }
        return LR_OK;
    } catch (...) {
        return fail_current(e, "projectPoints");
    }
}

int lr_cv_solve_pnp(int n, const double *obj, const double *img, const double K[9],
                    const double dist[5], bool planar, double rvec[3], double tvec[3],
                    double *rms, lr_err *e)
{
    if (n < (planar ? 4 : 6))
        return lr_err_set(e, LR_EINVAL, "solvePnP: %d points (need at least %d)", n,
                          planar ? 4 : 6);
    try {
        std::vector<cv::Point3d> p((size_t)n);
        std::vector<cv::Point2d> q((size_t)n);
        for (int i = 0; i < n; i++) {
            p[(size_t)i] = cv::Point3d(obj[3 * i], obj[3 * i + 1], obj[3 * i + 2]);
            q[(size_t)i] = cv::Point2d(img[2 * i], img[2 * i + 1]);
        }
        cv::Mat k(3, 3, CV_64F, (void *)K), d(1, 5, CV_64F, (void *)dist);
        cv::Mat r, t;
        if (!cv::solvePnP(p, q, k, d, r, t, false,
                          planar ? cv::SOLVEPNP_IPPE : cv::SOLVEPNP_ITERATIVE))
            return lr_err_set(e, LR_EINVAL, "solvePnP: no pose found for %d points", n);
        cv::solvePnPRefineLM(p, q, k, d, r, t);
        std::vector<cv::Point2d> back;
        cv::projectPoints(p, r, t, k, d, back);
        double ss = 0;
        for (int i = 0; i < n; i++) {
            cv::Point2d dd = back[(size_t)i] - q[(size_t)i];
            ss += dd.dot(dd);
        }
        for (int i = 0; i < 3; i++) {
            rvec[i] = r.at<double>(i);
            tvec[i] = t.at<double>(i);
        }
        if (rms)
            *rms = std::sqrt(ss / n);
        return LR_OK;
    } catch (...) {
        return fail_current(e, "solvePnP");
    }
}

int lr_cv_graycode_count(int pw, int ph, int *count, lr_err *e)
{
    try {
        if (pw < 2 || ph < 2 || pw > 16384 || ph > 16384)
            return lr_err_set(e, LR_EINVAL, "projector size %dx%d out of range (2..16384)", pw,
                              ph);
        cv::structured_light::GrayCodePattern::Params p;
        p.width = pw;
        p.height = ph;
        cv::Ptr<cv::structured_light::GrayCodePattern> g =
            cv::structured_light::GrayCodePattern::create(p);
        *count = (int)g->getNumberOfPatternImages();
        return LR_OK;
    } catch (...) {
        return fail_current(e, "Gray-code pattern");
    }
}

int lr_cv_graycode_generate(int pw, int ph, lr_cv_image_sink sink, void *ctx, lr_err *e)
{
    std::vector<cv::Mat> pattern;
    try {
        int n;
        int rc = lr_cv_graycode_count(pw, ph, &n, e);
        if (rc)
            return rc;
        cv::structured_light::GrayCodePattern::Params p;
        p.width = pw;
        p.height = ph;
        cv::Ptr<cv::structured_light::GrayCodePattern> g =
            cv::structured_light::GrayCodePattern::create(p);
        g->generate(pattern);
    } catch (...) {
        return fail_current(e, "Gray-code pattern");
    }
    for (size_t i = 0; i < pattern.size(); i++) {
        cv::Mat m = pattern[i];
        if (m.channels() != 1) // 4.6 makes CV_8UC1; older releases made CV_8UC3
            cv::cvtColor(m, m, cv::COLOR_BGR2GRAY);
        if (!m.isContinuous())
            m = m.clone();
        lr_img img = {m.cols, m.rows, 1, 1, m.data};
        int rc = sink(ctx, (int)i, &img, e);
        if (rc)
            return rc;
    }
    return LR_OK;
}

int lr_cv_graycode_decode(int pw, int ph, const char *const *patterns, int npatterns,
                          const char *white, const char *black, int contrast, int shadow,
                          const lr_progress *progress, const char *stage, int *cam_w,
                          int *cam_h, int32_t **proj_xy, uint8_t **status, lr_err *e)
{
    *proj_xy = nullptr;
    *status = nullptr;
    const char *current = white;
    try {
        int n;
        int rc = lr_cv_graycode_count(pw, ph, &n, e);
        if (rc)
            return rc;
        if (npatterns != n)
            return lr_err_set(e, LR_EINVAL,
                              "%s: %d pattern captures, but a %dx%d projector needs %d", stage,
                              npatterns, pw, ph, n);
        int total = n + 2;
        cv::Mat w = read_gray(white);
        if (w.empty())
            return lr_err_set(e, LR_EIO, "%s: missing or not an image", white);
        lr_progress_report(progress, stage, 1, total);
        current = black;
        cv::Mat b = read_gray(black);
        if (b.empty())
            return lr_err_set(e, LR_EIO, "%s: missing or not an image", black);
        if (b.size() != w.size())
            return lr_err_set(e, LR_EINVAL, "%s: %dx%d, but %s is %dx%d", black, b.cols, b.rows,
                              white, w.cols, w.rows);
        lr_progress_report(progress, stage, 2, total);
        std::vector<cv::Mat> imgs((size_t)n);
        for (int i = 0; i < n; i++) {
            current = patterns[i];
            imgs[(size_t)i] = read_gray(patterns[i]);
            if (imgs[(size_t)i].empty())
                return lr_err_set(e, LR_EIO, "%s: missing or not an image", patterns[i]);
            if (imgs[(size_t)i].size() != w.size())
                return lr_err_set(e, LR_EINVAL, "%s: %dx%d, but %s is %dx%d", patterns[i],
                                  imgs[(size_t)i].cols, imgs[(size_t)i].rows, white, w.cols,
                                  w.rows);
            lr_progress_report(progress, stage, 3 + i, total);
        }
        current = stage;
        cv::structured_light::GrayCodePattern::Params p;
        p.width = pw;
        p.height = ph;
        cv::Ptr<cv::structured_light::GrayCodePattern> g =
            cv::structured_light::GrayCodePattern::create(p);
        g->setWhiteThreshold((size_t)contrast);
        int W = w.cols, H = w.rows;
        int32_t *xy = (int32_t *)std::malloc(sizeof(int32_t) * 2 * (size_t)W * (size_t)H);
        uint8_t *st = (uint8_t *)std::malloc((size_t)W * (size_t)H);
        if (!xy || !st) {
            std::free(xy);
            std::free(st);
            return lr_err_set(e, LR_ENOMEM, "%s: out of memory for a %dx%d map", stage, W, H);
        }
        for (int y = 0; y < H; y++) {
            for (int x = 0; x < W; x++) {
                size_t i = (size_t)y * (size_t)W + (size_t)x;
                xy[2 * i] = xy[2 * i + 1] = -1;
                if ((int)w.at<uchar>(y, x) - (int)b.at<uchar>(y, x) <= shadow) {
                    st[i] = LR_GC_SHADOW;
                    continue;
                }
                cv::Point pp;
                // getProjPixel returns true on *error* (some pair below the threshold).
                if (g->getProjPixel(imgs, x, y, pp)) {
                    st[i] = LR_GC_LOW_CONTRAST;
                    continue;
                }
                // OpenCV checks x > width (not >=): the code for one past the edge slips by.
                if (pp.x < 0 || pp.y < 0 || pp.x >= pw || pp.y >= ph) {
                    st[i] = LR_GC_OUT_OF_RANGE;
                    continue;
                }
                st[i] = LR_GC_VALID;
                xy[2 * i] = pp.x;
                xy[2 * i + 1] = pp.y;
            }
            if ((y + 1) % 64 == 0 || y + 1 == H)
                lr_progress_report(progress, stage, n + 2 + (y + 1) * n / H, total + n);
        }
        *cam_w = W;
        *cam_h = H;
        *proj_xy = xy;
        *status = st;
        return LR_OK;
    } catch (...) {
        return fail_current(e, current);
    }
}

int lr_cv_debevec_response(const lr_img *imgs, const double *times, int n, int samples,
                           double lambda, double *response, lr_err *e)
{
    try {
        std::vector<cv::Mat> m;
        std::vector<float> t;
        for (int i = 0; i < n; i++) {
            if (imgs[i].channels != 3 || imgs[i].depth != 1)
                return lr_err_set(e, LR_EINVAL, "exposure %d: need 8-bit RGB", i);
            m.push_back(wrap(&imgs[i]));
            t.push_back((float)times[i]);
        }
        cv::Ptr<cv::CalibrateDebevec> cal =
            cv::createCalibrateDebevec(samples, (float)lambda, false);
        cv::Mat resp;
        cal->process(m, resp, t);
        // resp: 256x1 CV_32FC3, channels in the order of the input (RGB here).
        for (int c = 0; c < 3; c++)
            for (int z = 0; z < 256; z++)
                response[c * 256 + z] = resp.at<cv::Vec3f>(z, 0)[c];
        return LR_OK;
    } catch (...) {
        return fail_current(e, "CalibrateDebevec");
    }
}

int lr_cv_detect_colorchecker(const lr_img *photo, double *rgb, lr_err *e)
{
    try {
        if (photo->channels != 3 || photo->depth != 1)
            return lr_err_set(e, LR_EINVAL, "ColorChecker detection needs an 8-bit RGB photo");
        cv::Mat bgr;
        cv::cvtColor(wrap(photo), bgr, cv::COLOR_RGB2BGR);
        // mcc converts to Lab on several threads at once, and OpenCV 4.6 builds its Lab
        // lookup tables lazily without a lock: every thread that loses the race leaks its
        // copy (megabytes, reported by LeakSanitizer). Building them here first, on one
        // thread, leaves nothing to race for.
        {
            cv::Mat px8(1, 1, CV_8UC3, cv::Scalar(0, 0, 0)), px32(1, 1, CV_32FC3, cv::Scalar(0, 0, 0));
            cv::Mat lab;
            cv::cvtColor(px8, lab, cv::COLOR_BGR2Lab);
            cv::cvtColor(px32, lab, cv::COLOR_BGR2Lab);
            cv::cvtColor(px8, lab, cv::COLOR_RGB2Lab);
            cv::cvtColor(px32, lab, cv::COLOR_RGB2Lab);
        }
        cv::Ptr<cv::mcc::CCheckerDetector> det = cv::mcc::CCheckerDetector::create();
        if (!det->process(bgr, cv::mcc::MCC24, 1))
            return lr_err_set(e, LR_EINVAL, "no ColorChecker (24 patches) found");
        cv::Ptr<cv::mcc::CChecker> c = det->getBestColorChecker();
        if (!c)
            return lr_err_set(e, LR_EINVAL, "no ColorChecker (24 patches) found");
        // getChartsRGB: one row per (patch, channel), column 1 = mean value 0..255, in RGB
        // channel order (the layout OpenCV's ccm sample reshapes to 24 RGB triples).
        cv::Mat charts = c->getChartsRGB();
        if (charts.rows != 24 * 3 || charts.cols < 2)
            return lr_err_set(e, LR_EINVAL, "ColorChecker: unexpected %dx%d patch table",
                              charts.rows, charts.cols);
        cv::Mat f;
        charts.convertTo(f, CV_64F);
        for (int i = 0; i < 24 * 3; i++)
            rgb[i] = f.at<double>(i, 1) / 255.0;
        return LR_OK;
    } catch (...) {
        return fail_current(e, "ColorChecker detection");
    }
}

struct lr_cv_camera {
    cv::VideoCapture cap;
    std::string device;
};

int lr_cv_camera_open(const char *device, int width, int height, lr_cv_camera **out, lr_err *e)
{
    *out = nullptr;
    struct stat st;
    // Checked first: OpenCV's own message for a missing node is a warning on stderr.
    if (stat(device, &st) != 0)
        return lr_err_set(e, LR_ENODEV, "%s: no such camera device (is the camera plugged in?)",
                          device);
    if (!S_ISCHR(st.st_mode))
        return lr_err_set(e, LR_ENODEV, "%s: not a V4L2 character device", device);
    lr_cv_camera *c = nullptr;
    try {
        c = new lr_cv_camera();
        c->device = device;
        if (!c->cap.open(device, cv::CAP_V4L2)) {
            delete c;
            return lr_err_set(e, LR_ENODEV, "%s: cannot open as a V4L2 camera (OpenCV VideoCapture)",
                              device);
        }
        if (width > 0 && height > 0) {
            c->cap.set(cv::CAP_PROP_FRAME_WIDTH, width);
            c->cap.set(cv::CAP_PROP_FRAME_HEIGHT, height);
        }
        *out = c;
        return LR_OK;
    } catch (...) {
        delete c;
        return fail_current(e, device);
    }
}

int lr_cv_camera_grab(lr_cv_camera *cam, int discard, lr_img *out, lr_err *e)
{
    *out = lr_img{};
    try {
        for (int i = 0; i < discard; i++)
            if (!cam->cap.grab())
                return lr_err_set(e, LR_EIO, "%s: frame grab failed (camera unplugged?)",
                                  cam->device.c_str());
        cv::Mat frame;
        if (!cam->cap.read(frame) || frame.empty())
            return lr_err_set(e, LR_EIO, "%s: frame read failed (camera unplugged?)",
                              cam->device.c_str());
        if (frame.channels() == 3)
            cv::cvtColor(frame, frame, cv::COLOR_BGR2RGB);
        else if (frame.channels() == 1)
            cv::cvtColor(frame, frame, cv::COLOR_GRAY2RGB);
        if (frame.depth() != CV_8U)
            frame.convertTo(frame, CV_8U);
        return to_img(frame, out, e);
    } catch (...) {
        return fail_current(e, cam->device.c_str());
    }
}

void lr_cv_camera_close(lr_cv_camera *cam)
{
    if (!cam)
        return;
    try {
        cam->cap.release();
    } catch (...) {
    }
    delete cam;
}

} // extern "C"
