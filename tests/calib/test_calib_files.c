/* Calibration files: every kind round-trips; corrupt, truncated, wrong-version and
 * wrong-kind files are refused with a message naming the file (and the field where there is
 * one); a failing calibration - through the library or the CLI - leaves the previous file
 * byte-identical and no temp files behind. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "calib/camcal.h"
#include "calib/camresp.h"
#include "calib/colormatrix.h"
#include "calib/graycode.h"
#include "calib/procam.h"
#include "calib/projresp.h"
#include "calib/rig.h"
#include "firmware/cli.h"
#include "tests/support/calib_sim.h"

static char *dir;

static int setup(void **state)
{
    (void)state;
    dir = sim_tempdir("calfiles");
    return dir ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    sim_rmdir(dir);
    free(dir);
    return 0;
}

static char *path_in(const char *leaf)
{
    static char buf[8][512];
    static int next;
    char *p = buf[next++ % 8];
    snprintf(p, 512, "%s/%s", dir, leaf);
    return p;
}

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)n + 1);
    assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    buf[n] = '\0';
    if (len)
        *len = (size_t)n;
    return buf;
}

static void spit(const char *path, const char *text, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, len, f), len);
    fclose(f);
}

/* Writes text with the first occurrence of `from` replaced by `to`. */
static void spit_replaced(const char *path, const char *text, const char *from, const char *to)
{
    const char *at = strstr(text, from);
    if (!at)
        fail_msg("'%s' not in the document", from);
    size_t n = strlen(text) + strlen(to) + 1;
    char *out = malloc(n);
    size_t head = (size_t)(at - text);
    memcpy(out, text, head);
    snprintf(out + head, n - head, "%s%s", to, at + strlen(from));
    spit(path, out, strlen(out));
    free(out);
}

/* call must fail with code and a message (in `err`) containing every string given. */
#define expect_error(call, code, ...)                                                         \
    do {                                                                                      \
        int rc_ = (call);                                                                     \
        if (rc_ != (code))                                                                    \
            fail_msg("%s returned %d, expected %d (%s)", #call, rc_, (code), err.msg);        \
        const char *needles_[] = {__VA_ARGS__, NULL};                                         \
        for (int i_ = 0; needles_[i_]; i_++)                                                  \
            if (!strstr(err.msg, needles_[i_]))                                               \
                fail_msg("message '%s' lacks '%s'", err.msg, needles_[i_]);                   \
    } while (0)

/* ---- fixtures ------------------------------------------------------------------------- */

static void camera_fixture(lr_camcal *c)
{
    memset(c, 0, sizeof *c);
    c->k = (lr_intrinsics){640, 480, 536.1, 536.1, 342.4, 235.6, {-0.265, -0.045, 0.0018, -0.0003, 0.25}};
    c->rms = 0.41;
    c->board = (lr_board){9, 6, 25.0, LR_BOARD_CHESSBOARD};
    c->fix_aspect = true;
    c->subpix_window = 11;
    c->nviews = 2;
    c->views = calloc(2, sizeof *c->views);
    c->views[0] = (lr_camcal_view){strdup("a \"quoted\" name.jpg"), 0.19, false, true};
    c->views[1] = (lr_camcal_view){strdup("left02.jpg"), 1.22, true, true};
    c->nrejected = 1;
    c->rejected = calloc(1, sizeof *c->rejected);
    c->rejected[0] = (lr_camcal_reject){strdup("blank.png"), strdup("9x6 chessboard not found")};
}

static void procam_fixture(lr_procam *p)
{
    memset(p, 0, sizeof *p);
    p->cam = (lr_intrinsics){640, 480, 620, 620, 318, 242, {-0.08, 0.02, 0, 0, 0}};
    p->proj = (lr_intrinsics){1280, 720, 1500, 1500, 640, 700, {0.03, 0, 0, 0, 0}};
    double c = cos(0.2), s = sin(0.2);
    double R[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
    memcpy(p->R, R, sizeof R);
    p->T[0] = -180;
    p->T[1] = 30;
    p->T[2] = 20;
    p->rms = 0.1;
    p->board = (lr_board){9, 6, 30, LR_BOARD_CHESSBOARD};
    p->nposes = 1;
    p->poses = calloc(1, sizeof *p->poses);
    p->poses[0] = (lr_procam_pose){strdup("pose_01"), 54, 120000, 0.08, 0.11};
}

/* ---- tests ---------------------------------------------------------------------------- */

static void test_camera_file(void **state)
{
    (void)state;
    lr_err err = {0};
    lr_camcal c, back;
    camera_fixture(&c);
    const char *good = path_in("camera.json");
    mode_t old_mask = umask(022);
    assert_int_equal(lr_camcal_save(good, &c, &err), LR_OK);
    umask(old_mask);
    /* A calibration is the rig's state: group-readable, not world-readable (LR_FILE_MODE_PRIVATE
     * less the umask 022; it was 0644). */
    struct stat st;
    assert_int_equal(stat(good, &st), 0);
    assert_int_equal(st.st_mode & 0777, 0640);
    assert_int_equal(lr_camcal_load(good, &back, &err), LR_OK);
    assert_true(back.k.fx == c.k.fx && back.k.dist[3] == c.k.dist[3]);
    assert_string_equal(back.views[0].image, "a \"quoted\" name.jpg");
    assert_true(back.views[1].outlier);
    assert_string_equal(back.rejected[0].reason, "9x6 chessboard not found");
    lr_camcal_free(&back);

    size_t len;
    char *text = slurp(good, &len);
    const char *bad = path_in("camera_bad.json");

    /* Truncated mid-document. */
    spit(bad, text, len / 2);
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad);
    /* Empty file. */
    spit(bad, "", 0);
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad);
    /* Binary garbage. */
    spit(bad, "\x89PNG\r\n\x1a\n\0\0", 10);
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad);
    /* Another version: refused by number, never guessed at. */
    spit_replaced(bad, text, "\"version\": 1", "\"version\": 2");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EINVAL, bad, "field 'version'",
                 "unsupported version 2");
    /* No version at all. */
    spit_replaced(bad, text, "\"version\": 1,", "");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad, "'version'", "missing");
    /* Wrong types and ranges, each naming the field and its line. */
    spit_replaced(bad, text, "\"fx\": 536.1", "\"fx\": \"536.1\"");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad, ":4:", "field 'fx'");
    spit_replaced(bad, text, "\"fx\": 536.1", "\"fx\": -536.1");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EINVAL, bad, "field 'fx'", "must be in");
    spit_replaced(bad, text, "\"fy\": 536.1", "\"fy\": 1e999");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad, "field 'fy'");
    spit_replaced(bad, text, "-0.265, ", "");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad, "field 'dist'",
                 "expected 5 numbers, got 4");
    spit_replaced(bad, text, "\"cx\": 342.4", "\"cx\": 5000");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EINVAL, bad, "field 'cx'");
    spit_replaced(bad, text, "\"image_size\": [640, 480]", "\"image_size\": [640.5, 480]");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EINVAL, bad, "image_size", "whole pixels");
    spit_replaced(bad, text, "\"rms\"", "\"rsm\"");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EPARSE, bad, "rsm");
    /* A projector-camera file where a camera file is expected. */
    spit_replaced(bad, text, "\"camera_intrinsics\"", "\"projector_camera\"");
    expect_error(lr_camcal_load(bad, &back, &err), LR_EINVAL, bad, "'projector_camera' file",
                 "expected 'camera_intrinsics'");
    free(text);
    lr_camcal_free(&c);
}

static void test_procam_file(void **state)
{
    (void)state;
    lr_err err = {0};
    lr_procam p, back;
    procam_fixture(&p);
    const char *good = path_in("projector.json");
    assert_int_equal(lr_procam_save(good, &p, &err), LR_OK);
    assert_int_equal(lr_procam_load(good, &back, &err), LR_OK);
    assert_true(memcmp(back.R, p.R, sizeof p.R) == 0);
    assert_int_equal(back.proj.width, 1280);
    assert_int_equal(back.poses[0].corners, 54);
    lr_procam_free(&back);
    size_t len;
    char *text = slurp(good, &len);
    const char *bad = path_in("projector_bad.json");
    spit(bad, text, len - 3);
    expect_error(lr_procam_load(bad, &back, &err), LR_EPARSE, bad);
    spit_replaced(bad, text, "\"version\": 1", "\"version\": 0");
    expect_error(lr_procam_load(bad, &back, &err), LR_EINVAL, bad, "unsupported version 0");
    /* A matrix that is not a rotation (scaled), and one of the wrong size. */
    char rrow[128];
    snprintf(rrow, sizeof rrow, "[0, 1, 0]");
    spit_replaced(bad, text, rrow, "[0, 0.99, 0]");
    expect_error(lr_procam_load(bad, &back, &err), LR_EINVAL, bad, "field 'R'",
                 "not a rotation");
    spit_replaced(bad, text, rrow, "[0, 1]");
    expect_error(lr_procam_load(bad, &back, &err), LR_EPARSE, bad, "R[1]", "expected 3 numbers");
    /* A nested field names its object. */
    spit_replaced(bad, text, "\"fx\": 1500", "\"fx\": 0");
    expect_error(lr_procam_load(bad, &back, &err), LR_EINVAL, bad, "projector.fx");
    spit_replaced(bad, text, "\"T\": [-180", "\"T\": [null");
    expect_error(lr_procam_load(bad, &back, &err), LR_EPARSE, bad, "T[0]");
    free(text);
    lr_procam_free(&p);
}

static void test_radiometry_files(void **state)
{
    (void)state;
    lr_err err = {0};
    /* Camera response. */
    lr_camresp r, rback;
    lr_camresp_gamma(&r, 2.2);
    const char *good = path_in("camera_response.json");
    assert_int_equal(lr_camresp_save(good, &r, &err), LR_OK);
    assert_int_equal(lr_camresp_load(good, &rback, &err), LR_OK);
    assert_true(memcmp(rback.curve, r.curve, sizeof r.curve) == 0);
    size_t len;
    char *text = slurp(good, &len);
    const char *bad = path_in("camera_response_bad.json");
    spit(bad, text, len * 3 / 4);
    expect_error(lr_camresp_load(bad, &rback, &err), LR_EPARSE, bad);
    spit_replaced(bad, text, "\"version\": 1", "\"version\": 3");
    expect_error(lr_camresp_load(bad, &rback, &err), LR_EINVAL, bad, "unsupported version 3");
    /* A falling response: channel 0's entry for value 5 replaced by a tiny number. */
    char num[40];
    for (int prec = 15; prec <= 17; prec++) {
        snprintf(num, sizeof num, "%.*g", prec, r.curve[0][5]);
        if (strtod(num, NULL) == r.curve[0][5])
            break;
    }
    spit_replaced(bad, text, num, "1e-30");
    expect_error(lr_camresp_load(bad, &rback, &err), LR_EINVAL, bad, "field 'curve'",
                 "decreases at value 5");
    free(text);

    /* Projector response. */
    lr_projresp *pr = calloc(1, sizeof *pr), *pback = calloc(1, sizeof *pback);
    double lv[3] = {0, 0.5, 1}, light[9] = {0.1, 0.1, 0.1, 0.3, 0.3, 0.3, 1.1, 1.1, 1.1};
    assert_int_equal(lr_projresp_fit(lv, light, 3, pr, &err), LR_OK);
    good = path_in("projector_response.json");
    assert_int_equal(lr_projresp_save(good, pr, &err), LR_OK);
    assert_int_equal(lr_projresp_load(good, pback, &err), LR_OK);
    assert_true(memcmp(pback->lut, pr->lut, sizeof pr->lut) == 0);
    text = slurp(good, &len);
    bad = path_in("projector_response_bad.json");
    spit(bad, text, 40);
    expect_error(lr_projresp_load(bad, pback, &err), LR_EPARSE, bad);
    spit_replaced(bad, text, "\"version\": 1", "\"version\": \"1\"");
    expect_error(lr_projresp_load(bad, pback, &err), LR_EPARSE, bad, "field 'version'");
    spit_replaced(bad, text, "\"lut\": [\n    [0,", "\"lut\": [\n    [0.5,");
    expect_error(lr_projresp_load(bad, pback, &err), LR_EINVAL, bad, "field 'lut'");
    spit_replaced(bad, text, "\"black\": [", "\"black\": [2, ");
    expect_error(lr_projresp_load(bad, pback, &err), LR_EPARSE, bad, "field 'black'");
    free(text);
    free(pr);
    free(pback);

    /* Colour matrix. */
    lr_colormatrix m = {{1.5, -0.3, -0.2, -0.2, 1.4, -0.2, 0, -0.4, 1.4}, 0.01, 0.02, 24, "pairs"};
    lr_colormatrix mback;
    good = path_in("color.json");
    assert_int_equal(lr_colormatrix_save(good, &m, &err), LR_OK);
    assert_int_equal(lr_colormatrix_load(good, &mback, &err), LR_OK);
    assert_true(memcmp(mback.m, m.m, sizeof m.m) == 0);
    text = slurp(good, &len);
    bad = path_in("color_bad.json");
    spit(bad, text, len - 2);
    expect_error(lr_colormatrix_load(bad, &mback, &err), LR_EPARSE, bad);
    spit_replaced(bad, text, "\"version\": 1", "\"version\": 1.5");
    expect_error(lr_colormatrix_load(bad, &mback, &err), LR_EPARSE, bad, "field 'version'",
                 "integer");
    spit_replaced(bad, text, "[1.5, -0.3, -0.2]", "[0, 0, 0]");
    expect_error(lr_colormatrix_load(bad, &mback, &err), LR_EINVAL, bad, "singular");
    free(text);
}

static bool dir_has_only(const char *d, const char *leaf)
{
    DIR *dd = opendir(d);
    struct dirent *ent;
    bool only = true;
    while ((ent = readdir(dd)))
        if (strcmp(ent->d_name, ".") && strcmp(ent->d_name, "..") && strcmp(ent->d_name, leaf))
            only = false;
    closedir(dd);
    return only;
}

static void test_failed_calibration_keeps_file(void **state)
{
    (void)state;
    char *sub = sim_tempdir("keep");
    char good[512];
    snprintf(good, sizeof good, "%s/camera.json", sub);
    lr_err err = {0};
    lr_camcal c;
    camera_fixture(&c);
    assert_int_equal(lr_camcal_save(good, &c, &err), LR_OK);
    size_t len0;
    char *before = slurp(good, &len0);

    /* 1. A result the loader would refuse (NaN, or a negative focal length) is not written. */
    c.k.fx = NAN;
    expect_error(lr_camcal_save(good, &c, &err), LR_EINVAL, good, "not written", "fx");
    c.k.fx = -1;
    expect_error(lr_camcal_save(good, &c, &err), LR_EINVAL, "refusing to write", good,
                 "field 'fx'");
    lr_camcal_free(&c);

    /* 2. The CLI, with photos where no board is found: exit 1, nothing written. */
    char blank[512];
    for (int i = 0; i < 3; i++) {
        snprintf(blank, sizeof blank, "%s/blank%d.png", dir, i);
        lr_img img;
        assert_int_equal(lr_img_alloc(&img, 64, 48, 1, 1, &err), LR_OK);
        memset(img.px, 40 * i, 64 * 48);
        assert_int_equal(lr_img_write(blank, &img, &err), LR_OK);
        lr_img_free(&img);
    }
    char glob[512];
    snprintf(glob, sizeof glob, "%s/blank*.png", dir);
    char *argv[] = {"lamprig", "calib", "camera", "--images", glob, "--board", "9x6",
                    "--square", "25", "--out", good, NULL};
    assert_int_equal(lr_cli_main(11, argv), LR_EXIT_FAIL);

    /* 3. The CLI's projector-response fit on a folder without captures. */
    char *argv2[] = {"lamprig", "calib", "projector-response", "fit", "--captures", dir,
                     "--out", good, NULL};
    assert_int_equal(lr_cli_main(8, argv2), LR_EXIT_FAIL);

    /* 4. Bad arguments never touch the output either (exit 2). */
    char *argv3[] = {"lamprig", "calib", "camera", "--images", glob, "--board", "9by6",
                     "--square", "25", "--out", good, NULL};
    assert_int_equal(lr_cli_main(11, argv3), LR_EXIT_USAGE);

    size_t len1;
    char *after = slurp(good, &len1);
    assert_int_equal(len0, len1);
    assert_memory_equal(before, after, len0);
    /* No temp files left beside it. */
    assert_true(dir_has_only(sub, "camera.json"));
    free(before);
    free(after);

    /* 5. The kept file still loads. */
    char *argv4[] = {"lamprig", "calib", "check", good, NULL};
    assert_int_equal(lr_cli_main(4, argv4), LR_EXIT_OK);
    sim_rmdir(sub);
    free(sub);
}

static void test_check_command(void **state)
{
    (void)state;
    /* `calib check` names the bad file and fails; good ones pass. */
    lr_err err = {0};
    lr_camcal c;
    camera_fixture(&c);
    const char *good = path_in("check_good.json");
    assert_int_equal(lr_camcal_save(good, &c, &err), LR_OK);
    lr_camcal_free(&c);
    const char *bad = path_in("check_bad.json");
    spit(bad, "{\"version\": 7, \"kind\": \"camera_intrinsics\"}", 44);
    char *argv[] = {"lamprig", "calib", "check", (char *)good, NULL};
    assert_int_equal(lr_cli_main(4, argv), LR_EXIT_OK);
    char *argv2[] = {"lamprig", "calib", "check", (char *)good, (char *)bad, NULL};
    assert_int_equal(lr_cli_main(5, argv2), LR_EXIT_FAIL);
    /* The Gray-code sequence metadata is a versioned file too. */
    assert_int_equal(lr_gc_write_sequence(dir, 800, 600, &err), LR_OK);
    int pw, ph;
    assert_int_equal(lr_gc_read_sequence(dir, &pw, &ph, &err), LR_OK);
    assert_int_equal(pw, 800);
    char *seq = slurp(path_in("sequence.json"), NULL);
    spit_replaced(path_in("sequence.json"), seq, "\"version\": 1", "\"version\": 2");
    expect_error(lr_gc_read_sequence(dir, &pw, &ph, &err), LR_EINVAL, "sequence.json",
                 "unsupported version 2");
    free(seq);
}

static void test_rig_folder(void **state)
{
    (void)state;
    char *rigdir = sim_tempdir("rig");
    lr_err err = {0};
    lr_rig_calib *rig = malloc(sizeof *rig);
    /* An empty folder: nothing calibrated, conversions are identities except the camera
     * response, which is the assumed gamma 2.2 normalised to 1 at value 128 (the one rule,
     * calib/rig.h). */
    assert_int_equal(lr_rig_calib_load(rigdir, rig, &err), LR_OK);
    assert_false(rig->has_camera || rig->has_procam || rig->has_camresp || rig->has_projresp ||
                 rig->has_color);
    uint8_t px[3] = {255, 128, 0};
    double lin[3], level[3], want[3] = {0.25, 1.5, -0.1};
    lr_rig_camera_to_linear(rig, px, lin);
    assert_true(fabs(lin[0] - pow(255 / 128.0, 2.2)) < 1e-12 && fabs(lin[1] - 1.0) < 1e-12 &&
                lin[2] > 0 && lin[2] < 1e-4);
    lr_rig_projector_input(rig, want, level);
    assert_true(level[0] == 0.25 && level[1] == 1.0 && level[2] == 0.0); /* clipped */
    lr_rig_calib_free(rig);

    /* A full set under the standard names. */
    char path[512];
    lr_camcal c;
    camera_fixture(&c);
    snprintf(path, sizeof path, "%s/%s", rigdir, LR_RIG_CAMERA);
    assert_int_equal(lr_camcal_save(path, &c, &err), LR_OK);
    lr_camcal_free(&c);
    lr_procam p;
    procam_fixture(&p);
    snprintf(path, sizeof path, "%s/%s", rigdir, LR_RIG_PROJECTOR);
    assert_int_equal(lr_procam_save(path, &p, &err), LR_OK);
    lr_procam_free(&p);
    lr_camresp r;
    lr_camresp_gamma(&r, 2.0);
    snprintf(path, sizeof path, "%s/%s", rigdir, LR_RIG_CAMERA_RESPONSE);
    assert_int_equal(lr_camresp_save(path, &r, &err), LR_OK);
    lr_projresp *pr = calloc(1, sizeof *pr);
    double lv[5] = {0, 0.25, 0.5, 0.75, 1}, light[15];
    for (int k = 0; k < 5; k++)
        for (int ch = 0; ch < 3; ch++)
            light[3 * k + ch] = 0.05 + pow(lv[k], 2.0);
    assert_int_equal(lr_projresp_fit(lv, light, 5, pr, &err), LR_OK);
    snprintf(path, sizeof path, "%s/%s", rigdir, LR_RIG_PROJECTOR_RESPONSE);
    assert_int_equal(lr_projresp_save(path, pr, &err), LR_OK);
    free(pr);
    lr_colormatrix m = {{2, 0, 0, 0, 1, 0, 0, 0, 0.5}, 0, 0, 24, "pairs"};
    snprintf(path, sizeof path, "%s/%s", rigdir, LR_RIG_COLOR);
    assert_int_equal(lr_colormatrix_save(path, &m, &err), LR_OK);

    assert_int_equal(lr_rig_calib_load(rigdir, rig, &err), LR_OK);
    assert_true(rig->has_camera && rig->has_procam && rig->has_camresp && rig->has_projresp &&
                rig->has_color);
    assert_int_equal(rig->procam.proj.width, 1280);
    /* Camera value 128 is exposure 1 by the response's normalisation; the matrix doubles
     * red and halves blue. */
    uint8_t mid[3] = {128, 128, 128};
    lr_rig_camera_to_linear(rig, mid, lin);
    assert_true(fabs(lin[0] - 2.0) < 1e-12 && fabs(lin[1] - 1.0) < 1e-12 &&
                fabs(lin[2] - 0.5) < 1e-12);
    /* A squared projector: light 0.25 needs level 0.5 (power-law interpolation is exact for a
     * pure power law; the inverse then to 1e-3 from the table's linear segments). */
    double quarter[3] = {0.25, 0.25, 0.25};
    lr_rig_projector_input(rig, quarter, level);
    for (int ch = 0; ch < 3; ch++)
        assert_true(fabs(level[ch] - 0.5) < 1e-3);
    lr_rig_calib_free(rig);

    /* One bad file fails the whole load, naming it. */
    snprintf(path, sizeof path, "%s/%s", rigdir, LR_RIG_COLOR);
    spit(path, "{\"version\": 1, \"kind\": \"color_matrix\"}", 38);
    expect_error(lr_rig_calib_load(rigdir, rig, &err), LR_EPARSE, path, "'matrix'", "missing");
    assert_false(rig->has_camera);
    free(rig);
    sim_rmdir(rigdir);
    free(rigdir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_camera_file),
        cmocka_unit_test(test_procam_file),
        cmocka_unit_test(test_radiometry_files),
        cmocka_unit_test(test_failed_calibration_keeps_file),
        cmocka_unit_test(test_check_command),
        cmocka_unit_test(test_rig_folder),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
