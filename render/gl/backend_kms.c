/* lamprig — projector back end: DRM/KMS mode setting, GBM scanout buffers, EGL window surface.
 *
 * Follows kmscube's legacy path (drm-common.c, drm-legacy.c): find a KMS device by probing
 * drmGetDevices2 rather than assuming card0, pick a connected connector and a mode, render
 * into a GBM surface, set the mode with the first frame, then drmModePageFlip each frame and
 * release the previous buffer when the flip event arrives on the DRM fd. The fd is exposed so
 * the firmware's poll loop waits on it together with the controls.
 */
#include "render/gl/gl_priv.h"

#include <errno.h>
#include <fcntl.h>
#include <gbm.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#define MAX_DRM_DEVICES 64
/* A flip completes at the next vblank (~17 ms at 60 Hz); a second without one means the
 * display went away or the driver is stuck, and the caller should hear about it. */
#define FLIP_TIMEOUT_MS 1000

typedef struct kms {
    int fd;
    char path[128];           /* DRM node, for messages */
    char connector_name[32];  /* e.g. "HDMI-A-1" */
    uint32_t connector_id, crtc_id;
    drmModeModeInfo mode;
    drmModeCrtc *saved_crtc;  /* what was on screen before us, restored at exit */
    struct gbm_device *gbm;
    struct gbm_surface *surface;
    struct gbm_bo *front;     /* being scanned out */
    struct gbm_bo *pending;   /* queued by drmModePageFlip, on screen after the next vblank */
    bool mode_set;
} kms;

typedef struct kms_fb {
    int fd;
    uint32_t fb_id;
} kms_fb;

static void connector_name(const drmModeConnector *c, char *buf, size_t cap)
{
    const char *type = drmModeGetConnectorTypeName(c->connector_type);
    snprintf(buf, cap, "%s-%u", type ? type : "Unknown", c->connector_type_id);
}

static bool mode_matches(const drmModeModeInfo *m, const lr_gl_desc *d)
{
    return m->hdisplay == d->width && m->vdisplay == d->height &&
           (d->refresh_hz == 0 || (int)m->vrefresh == d->refresh_hz);
}

/* Picks desc's mode, else the preferred one, else the largest (kmscube's rule). */
static int pick_mode(kms *k, const drmModeConnector *c, const lr_gl_desc *d, lr_err *e)
{
    int best = -1, area = 0;
    for (int i = 0; i < c->count_modes; i++) {
        const drmModeModeInfo *m = &c->modes[i];
        if (d->width > 0) {
            /* Among equal sizes prefer the connector's preferred timing. */
            if (mode_matches(m, d) && (best < 0 || (m->type & DRM_MODE_TYPE_PREFERRED)))
                best = i;
            continue;
        }
        if (m->type & DRM_MODE_TYPE_PREFERRED) {
            best = i;
            break;
        }
        if (m->hdisplay * m->vdisplay > area) {
            area = m->hdisplay * m->vdisplay;
            best = i;
        }
    }
    if (best < 0) {
        if (d->width > 0)
            return lr_err_set(e, LR_ENODEV, "KMS: %s on %s has no %dx%d%s mode", k->connector_name,
                              k->path, d->width, d->height, d->refresh_hz ? " at that refresh" : "");
        return lr_err_set(e, LR_ENODEV, "KMS: %s on %s reports no modes", k->connector_name, k->path);
    }
    k->mode = c->modes[best];
    return LR_OK;
}

static uint32_t find_crtc(int fd, const drmModeRes *res, const drmModeConnector *c)
{
    /* The CRTC already driving this connector, if any: no visible mode change at start. */
    if (c->encoder_id) {
        drmModeEncoder *enc = drmModeGetEncoder(fd, c->encoder_id);
        uint32_t crtc = enc ? enc->crtc_id : 0;
        drmModeFreeEncoder(enc);
        if (crtc)
            return crtc;
    }
    /* Otherwise any CRTC one of its encoders can drive; possible_crtcs is a bit mask over the
     * resources' CRTC list. */
    for (int i = 0; i < c->count_encoders; i++) {
        drmModeEncoder *enc = drmModeGetEncoder(fd, c->encoders[i]);
        if (!enc)
            continue;
        uint32_t mask = enc->possible_crtcs;
        drmModeFreeEncoder(enc);
        for (int j = 0; j < res->count_crtcs && j < 32; j++)
            if (mask & (1u << j))
                return res->crtcs[j];
    }
    return 0;
}

/* Chooses connector, mode and CRTC on the open k->fd. LR_ENODEV names what is missing. */
static int pick_output(kms *k, const lr_gl_desc *d, lr_err *e)
{
    drmModeRes *res = drmModeGetResources(k->fd);
    if (!res)
        return lr_err_set(e, LR_ENODEV, "KMS: %s has no mode-setting resources (render-only GPU?)",
                          k->path);
    int rc = LR_OK;
    drmModeConnector *chosen = NULL;
    for (int i = 0; i < res->count_connectors && !chosen; i++) {
        drmModeConnector *c = drmModeGetConnector(k->fd, res->connectors[i]);
        if (!c)
            continue;
        char name[32];
        connector_name(c, name, sizeof name);
        bool wanted = d->connector ? strcmp(name, d->connector) == 0
                                   : c->connection == DRM_MODE_CONNECTED && c->count_modes > 0;
        if (wanted) {
            chosen = c;
            snprintf(k->connector_name, sizeof k->connector_name, "%s", name);
        } else {
            drmModeFreeConnector(c);
        }
    }
    if (!chosen) {
        rc = d->connector
                 ? lr_err_set(e, LR_ENODEV, "KMS: %s has no connector named %s", k->path, d->connector)
                 : lr_err_set(e, LR_ENODEV, "KMS: %s has no connected output", k->path);
    } else if (chosen->connection != DRM_MODE_CONNECTED) {
        rc = lr_err_set(e, LR_ENODEV, "KMS: %s on %s is not connected", k->connector_name, k->path);
    } else {
        rc = pick_mode(k, chosen, d, e);
    }
    if (rc == LR_OK) {
        k->connector_id = chosen->connector_id;
        k->crtc_id = find_crtc(k->fd, res, chosen);
        if (!k->crtc_id)
            rc = lr_err_set(e, LR_ENODEV, "KMS: no CRTC can drive %s on %s", k->connector_name,
                            k->path);
    }
    drmModeFreeConnector(chosen);
    drmModeFreeResources(res);
    return rc;
}

static int open_node(kms *k, const char *path, lr_err *e)
{
    snprintf(k->path, sizeof k->path, "%s", path);
    k->fd = open(path, O_RDWR | O_CLOEXEC);
    if (k->fd < 0)
        return lr_err_set(e, LR_ENODEV, "KMS: cannot open %s: %s", path, strerror(errno));
    return LR_OK;
}

static void close_node(kms *k)
{
    if (k->fd >= 0)
        close(k->fd);
    k->fd = -1;
}

/* Probes every primary node (card*) for one with a connected output. */
static int find_device(kms *k, const lr_gl_desc *d, lr_err *e)
{
    if (d->drm_device) {
        int rc = open_node(k, d->drm_device, e);
        return rc ? rc : pick_output(k, d, e);
    }
    /* drmGetDevices2 answers "no devices" both for a machine without DRM and for one where
     * /dev/dri was not passed into the container; saying which is what the user needs. */
    if (access("/dev/dri", F_OK) != 0)
        return lr_err_set(e, LR_ENODEV,
                          "KMS: no /dev/dri on this machine (no display driver loaded, or the "
                          "device not passed into the container); use the surfaceless back end "
                          "for headless rendering");
    drmDevicePtr devs[MAX_DRM_DEVICES] = {0};
    int n = drmGetDevices2(0, devs, MAX_DRM_DEVICES);
    if (n < 0)
        return lr_err_set(e, LR_ENODEV, "KMS: drmGetDevices2: %s", strerror(-n));
    if (n == 0)
        return lr_err_set(e, LR_ENODEV, "KMS: no DRM devices under /dev/dri");
    int rc = LR_ENODEV;
    for (int i = 0; i < n && rc != LR_OK; i++) {
        if (!(devs[i]->available_nodes & (1 << DRM_NODE_PRIMARY)))
            continue; /* render-only nodes cannot scan out */
        /* Keep the last device's reason: with one GPU (the SBC) it is the useful one. */
        rc = open_node(k, devs[i]->nodes[DRM_NODE_PRIMARY], e);
        if (rc == LR_OK)
            rc = pick_output(k, d, e);
        if (rc)
            close_node(k);
    }
    drmFreeDevices(devs, n);
    if (rc == LR_ENODEV && !k->path[0])
        lr_err_set(e, LR_ENODEV, "KMS: no primary DRM node under /dev/dri (render nodes only)");
    return rc;
}

static void fb_destroy(struct gbm_bo *bo, void *data)
{
    kms_fb *fb = data;
    if (fb->fb_id)
        drmModeRmFB(fb->fd, fb->fb_id);
    free(fb);
}

/* The DRM framebuffer that scans out `bo`, made once and cached as the bo's user data. */
static int fb_for_bo(kms *k, struct gbm_bo *bo, uint32_t *fb_id, lr_err *e)
{
    kms_fb *fb = gbm_bo_get_user_data(bo);
    if (fb) {
        *fb_id = fb->fb_id;
        return LR_OK;
    }
    fb = calloc(1, sizeof *fb);
    if (!fb)
        return lr_err_set(e, LR_ENOMEM, "KMS: framebuffer");
    fb->fd = k->fd;
    uint32_t handles[4] = {0}, strides[4] = {0}, offsets[4] = {0};
    int planes = gbm_bo_get_plane_count(bo);
    for (int i = 0; i < planes && i < 4; i++) {
        handles[i] = gbm_bo_get_handle_for_plane(bo, i).u32;
        strides[i] = gbm_bo_get_stride_for_plane(bo, i);
        offsets[i] = gbm_bo_get_offset(bo, i);
    }
    int ret = drmModeAddFB2(k->fd, gbm_bo_get_width(bo), gbm_bo_get_height(bo),
                            gbm_bo_get_format(bo), handles, strides, offsets, &fb->fb_id, 0);
    if (ret)
        /* Older drivers without AddFB2: the legacy call knows XRGB8888 as depth 24, 32 bpp. */
        ret = drmModeAddFB(k->fd, gbm_bo_get_width(bo), gbm_bo_get_height(bo), 24, 32,
                           gbm_bo_get_stride(bo), gbm_bo_get_handle(bo).u32, &fb->fb_id);
    if (ret) {
        free(fb);
        return lr_err_set(e, LR_EIO, "KMS: drmModeAddFB on %s: %s", k->path, strerror(errno));
    }
    gbm_bo_set_user_data(bo, fb, fb_destroy);
    *fb_id = fb->fb_id;
    return LR_OK;
}

static void on_flip(int fd, unsigned frame, unsigned sec, unsigned usec, void *data)
{
    kms *k = data;
    /* The pending buffer is now on screen: the old front can be rendered into again. */
    if (k->front)
        gbm_surface_release_buffer(k->surface, k->front);
    k->front = k->pending;
    k->pending = NULL;
}

static int kms_dispatch(lr_gl *gl, lr_err *e)
{
    kms *k = gl->be;
    drmEventContext ev = {.version = 2, .page_flip_handler = on_flip};
    if (drmHandleEvent(k->fd, &ev) != 0)
        return lr_err_set(e, LR_EIO, "KMS: reading events from %s: %s", k->path, strerror(errno));
    return LR_OK;
}

static int wait_flip(lr_gl *gl, lr_err *e)
{
    kms *k = gl->be;
    while (k->pending) {
        struct pollfd p = {.fd = k->fd, .events = POLLIN};
        int n = poll(&p, 1, FLIP_TIMEOUT_MS);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            return lr_err_set(e, LR_EIO, "KMS: poll on %s: %s", k->path, strerror(errno));
        if (n == 0)
            return lr_err_set(e, LR_ETIMEOUT, "KMS: page flip on %s did not complete within %d ms",
                              k->connector_name, FLIP_TIMEOUT_MS);
        int rc = kms_dispatch(gl, e);
        if (rc)
            return rc;
    }
    return LR_OK;
}

static int kms_present(lr_gl *gl, lr_err *e)
{
    kms *k = gl->be;
    int rc = wait_flip(gl, e);
    if (rc)
        return rc;
    if (!eglSwapBuffers(gl->dpy, gl->surface))
        return lr_err_set(e, LR_EGL, "EGL: eglSwapBuffers: %s", lr_gl__egl_error_str(eglGetError()));
    struct gbm_bo *next = gbm_surface_lock_front_buffer(k->surface);
    if (!next)
        return lr_err_set(e, LR_EGL, "KMS: gbm_surface_lock_front_buffer failed");
    uint32_t fb_id = 0;
    rc = fb_for_bo(k, next, &fb_id, e);
    if (rc) {
        gbm_surface_release_buffer(k->surface, next);
        return rc;
    }
    if (!k->mode_set) {
        /* First frame: set the mode (synchronous, no flip event). */
        k->saved_crtc = drmModeGetCrtc(k->fd, k->crtc_id);
        if (drmModeSetCrtc(k->fd, k->crtc_id, fb_id, 0, 0, &k->connector_id, 1, &k->mode)) {
            gbm_surface_release_buffer(k->surface, next);
            return lr_err_set(e, LR_EIO, "KMS: drmModeSetCrtc %s %dx%d on %s: %s",
                              k->connector_name, k->mode.hdisplay, k->mode.vdisplay, k->path,
                              strerror(errno));
        }
        k->mode_set = true;
        k->front = next;
        return LR_OK;
    }
    if (drmModePageFlip(k->fd, k->crtc_id, fb_id, DRM_MODE_PAGE_FLIP_EVENT, k)) {
        gbm_surface_release_buffer(k->surface, next);
        return lr_err_set(e, LR_EIO, "KMS: drmModePageFlip on %s: %s", k->connector_name,
                          strerror(errno));
    }
    k->pending = next;
    return LR_OK;
}

static int kms_event_fd(const lr_gl *gl) { return ((const kms *)gl->be)->fd; }
static bool kms_flip_pending(const lr_gl *gl) { return ((const kms *)gl->be)->pending != NULL; }

static void kms_fini(lr_gl *gl)
{
    kms *k = gl->be;
    if (!k)
        return;
    /* Never free a buffer the display is still about to scan out. */
    if (k->pending && wait_flip(gl, NULL) != LR_OK && k->surface) {
        gbm_surface_release_buffer(k->surface, k->pending);
        k->pending = NULL;
    }
    if (k->saved_crtc) {
        drmModeCrtc *s = k->saved_crtc;
        drmModeSetCrtc(k->fd, s->crtc_id, s->buffer_id, s->x, s->y, &k->connector_id, 1, &s->mode);
        drmModeFreeCrtc(s);
    }
    if (k->front)
        gbm_surface_release_buffer(k->surface, k->front);
    if (k->surface)
        gbm_surface_destroy(k->surface); /* drops the bos; fb_destroy removes their DRM fbs */
    if (k->gbm)
        gbm_device_destroy(k->gbm);
    close_node(k);
    free(k);
    gl->be = NULL;
}

static const lr_gl_ops kms_ops = {
    .name = "kms",
    .present = kms_present,
    .dispatch = kms_dispatch,
    .event_fd = kms_event_fd,
    .flip_pending = kms_flip_pending,
    .fini = kms_fini,
};

/* An EGL config whose native visual is the GBM format we scan out. */
static int choose_config(lr_gl *gl, uint32_t format, lr_err *e)
{
    static const EGLint attribs[] = {
        EGL_SURFACE_TYPE, EGL_WINDOW_BIT,
        EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT,
        EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
        EGL_NONE,
    };
    EGLint n = 0;
    if (!eglChooseConfig(gl->dpy, attribs, NULL, 0, &n) || n < 1)
        return lr_err_set(e, LR_EUNSUPPORTED, "EGL: no GLES 3 window config on GBM");
    EGLConfig *configs = calloc((size_t)n, sizeof *configs);
    if (!configs)
        return lr_err_set(e, LR_ENOMEM, "EGL: configs");
    eglChooseConfig(gl->dpy, attribs, configs, n, &n);
    int found = 0;
    for (EGLint i = 0; i < n && !found; i++) {
        EGLint id;
        if (eglGetConfigAttrib(gl->dpy, configs[i], EGL_NATIVE_VISUAL_ID, &id) &&
            (uint32_t)id == format) {
            gl->config = configs[i];
            found = 1;
        }
    }
    free(configs);
    return found ? LR_OK
                 : lr_err_set(e, LR_EUNSUPPORTED, "EGL: no config for GBM format XRGB8888");
}

int lr_gl__kms_init(lr_gl *gl, const lr_gl_desc *desc, lr_err *e)
{
    kms *k = calloc(1, sizeof *k);
    if (!k)
        return lr_err_set(e, LR_ENOMEM, "KMS: state");
    k->fd = -1;
    gl->be = k;
    gl->ops = &kms_ops;

    int rc = find_device(k, desc, e);
    if (rc)
        return rc;
    k->gbm = gbm_create_device(k->fd);
    if (!k->gbm)
        return lr_err_set(e, LR_ENODEV, "KMS: gbm_create_device on %s failed", k->path);

    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    const char *platform_ext = lr_gl__has_ext(client, "EGL_KHR_platform_gbm") ? "EGL_KHR_platform_gbm"
                                                                             : "EGL_MESA_platform_gbm";
    rc = lr_gl__egl_display(gl, EGL_PLATFORM_GBM_KHR, k->gbm, platform_ext, e);
    if (rc)
        return rc;
    const uint32_t format = GBM_FORMAT_XRGB8888;
    rc = choose_config(gl, format, e);
    if (rc)
        return rc;

    gl->width = k->mode.hdisplay;
    gl->height = k->mode.vdisplay;
    k->surface = gbm_surface_create(k->gbm, (uint32_t)gl->width, (uint32_t)gl->height, format,
                                    GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
    if (!k->surface)
        return lr_err_set(e, LR_ENODEV, "KMS: gbm_surface_create %dx%d on %s: %s", gl->width,
                          gl->height, k->path, strerror(errno));
    rc = lr_gl__egl_context(gl, e);
    if (rc)
        return rc;
    PFNEGLCREATEPLATFORMWINDOWSURFACEEXTPROC create_surface =
        (PFNEGLCREATEPLATFORMWINDOWSURFACEEXTPROC)eglGetProcAddress(
            "eglCreatePlatformWindowSurfaceEXT");
    gl->surface = create_surface ? create_surface(gl->dpy, gl->config, k->surface, NULL)
                                 : eglCreateWindowSurface(gl->dpy, gl->config,
                                                          (EGLNativeWindowType)k->surface, NULL);
    if (gl->surface == EGL_NO_SURFACE)
        return lr_err_set(e, LR_EGL, "EGL: window surface on %s: %s", k->path,
                          lr_gl__egl_error_str(eglGetError()));
    return LR_OK;
}
