#include "calib/capture.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "calib/cv_shim.h"

typedef struct run_ctx {
    const lr_capture_desc *d;
    lr_cv_camera *cam;
    const char *dir;
    int total;
} run_ctx;

static void sleep_ms(int ms)
{
    struct timespec ts = {ms / 1000, (long)(ms % 1000) * 1000000L};
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
    }
}

static int show_and_grab(void *ctx, int index, const lr_img *frame, const char *name,
                         lr_err *e)
{
    run_ctx *r = ctx;
    int rc = r->d->show(r->d->show_ctx, index, frame, name, e);
    if (rc)
        return lr_err_prefix(e, "showing %s", name);
    sleep_ms(r->d->settle_ms > 0 ? r->d->settle_ms : 150);
    lr_img shot;
    if ((rc = lr_cv_camera_grab(r->cam, r->d->discard > 0 ? r->d->discard : 3, &shot, e)))
        return lr_err_prefix(e, "capturing %s", name);
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s", r->dir, name) >= (int)sizeof path) {
        lr_img_free(&shot);
        return lr_err_set(e, LR_EINVAL, "%s: path too long", r->dir);
    }
    rc = lr_img_write_frame(path, &shot, e);
    lr_img_free(&shot);
    char stage[4200];
    snprintf(stage, sizeof stage, "capture %s", r->dir);
    lr_progress_report(r->d->progress, stage, index + 1, r->total);
    return rc;
}

/* Counts the frames of a sequence without showing anything. */
static int count_frame(void *ctx, int index, const lr_img *frame, const char *name, lr_err *e)
{
    (void)index;
    (void)frame;
    (void)name;
    (void)e;
    (*(int *)ctx)++;
    return LR_OK;
}

int lr_capture_run(const lr_capture_desc *d, lr_sequence_fn sequence, int pw, int ph,
                   const char *out_dir, lr_err *e)
{
    if (!d->device || !d->show)
        return lr_err_set(e, LR_EINVAL, "capture needs a camera device and a projector output");
    lr_cv_camera *cam;
    int rc = lr_cv_camera_open(d->device, d->width, d->height, &cam, e);
    if (rc)
        return rc;
    if (mkdir(out_dir, 0755) != 0 && errno != EEXIST) {
        rc = lr_err_set(e, LR_EIO, "%s: cannot create: %s", out_dir, strerror(errno));
        lr_cv_camera_close(cam);
        return rc;
    }
    int total = 0;
    if ((rc = sequence(pw, ph, count_frame, &total, e))) {
        lr_cv_camera_close(cam);
        return rc;
    }
    run_ctx r = {d, cam, out_dir, total};
    rc = sequence(pw, ph, show_and_grab, &r, e);
    lr_cv_camera_close(cam);
    if (!rc && sequence == lr_gc_run_sequence)
        rc = lr_gc_write_sequence(out_dir, pw, ph, e);
    return rc;
}

int lr_capture_show_file(void *ctx, int index, const lr_img *frame, const char *name,
                         lr_err *e)
{
    (void)index;
    (void)name;
    return lr_img_write((const char *)ctx, frame, e);
}

int lr_capture_show_prompt(void *ctx, int index, const lr_img *frame, const char *name,
                           lr_err *e)
{
    (void)index;
    (void)frame;
    fprintf(stderr, "show %s/%s full screen on the projector, then press Enter: ",
            (const char *)ctx, name);
    fflush(stderr);
    int c;
    while ((c = getchar()) != '\n')
        if (c == EOF)
            return lr_err_set(e, LR_EIO, "stdin closed while waiting to show %s", name);
    return LR_OK;
}
