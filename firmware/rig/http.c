/* lamprig firmware — the HTTP endpoint on libmicrohttpd in external-select mode (see http.h). */
#include "firmware/rig/http.h"

#include <arpa/inet.h>
#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <microhttpd.h>
#include <netinet/in.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#include "firmware/rig/config.h"
#include "firmware/rig/rig.h"
#include "firmware/rig/status_json.h"
#include "hal/dev.h"
#include "render/base/json.h"
#include "render/base/json_write.h"

/* One event stream (GET /api/events): bytes queued for it, and its connection while MHD has
 * it suspended for lack of data. */
typedef struct sse {
    lr_http *h;
    struct MHD_Connection *conn;
    char *buf;
    size_t len, off, cap;
    bool suspended, dropped;
    struct sse *next;
} sse;

/* A request in progress: its body, bounded; for POST /api/reload, the rig's answer it awaits
 * with its connection suspended (lr_rig_reload_async). */
typedef struct req {
    char body[LR_HTTP_BODY_MAX + 1];
    size_t len;
    bool too_big;
    struct lr_http *h;
    struct MHD_Connection *conn;
    bool reload_wait, reload_done, suspended;
    int reload_rc;
    char reload_msg[LR_ERR_MSG_MAX];
    struct req *next_wait;
} req;

struct lr_http {
    struct MHD_Daemon *d;
    struct lr_rig *rig;
    lr_log log;
    lr_log_limit log_limit;
    char token[LR_RIG_HTTP_TOKEN_MAX];
    bool loopback;
    int port;
    sse *streams;
    int n_streams;
    req *reloads; /* POST /api/reload requests awaiting the rig's answer */
    bool closing;
    bool controls_dirty;
    int64_t last_controls_ns, next_status_ns;
    double tokens; /* rate limit: a bucket of LR_HTTP_BURST refilled at LR_HTTP_RATE/s */
    int64_t bucket_ns;
    /* /frame.png: the last encoding and when */
    unsigned char *png;
    size_t png_len;
    uint64_t png_frame;
    int64_t png_ns;
};

/* ---- answers ---- */

static enum MHD_Result queue(struct MHD_Connection *c, unsigned status, char *body, size_t len,
                             const char *type)
{
    struct MHD_Response *r = MHD_create_response_from_buffer(len, body, MHD_RESPMEM_MUST_FREE);
    if (!r) {
        free(body);
        return MHD_NO;
    }
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, type);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(r, "X-Content-Type-Options", "nosniff");
    /* No other site may frame the page (a framed page could be clicked into moving the
     * controls); its script and style are inline, everything else comes from the rig. */
    MHD_add_response_header(r, "X-Frame-Options", "DENY");
    MHD_add_response_header(r, "Content-Security-Policy",
                            "default-src 'self'; script-src 'unsafe-inline'; "
                            "style-src 'unsafe-inline'; frame-ancestors 'none'");
    if (status == MHD_HTTP_UNAUTHORIZED)
        MHD_add_response_header(r, MHD_HTTP_HEADER_WWW_AUTHENTICATE, "Bearer realm=\"lamprig\"");
    if (status == MHD_HTTP_TOO_MANY_REQUESTS)
        MHD_add_response_header(r, MHD_HTTP_HEADER_RETRY_AFTER, "1");
    enum MHD_Result ret = MHD_queue_response(c, status, r);
    MHD_destroy_response(r);
    return ret;
}

/* A small JSON object from one writer call sequence: {"error": msg, "status": N} or the
 * caller's members. */
static char *json_text(void (*fill)(lr_jw *, const void *), const void *arg, size_t *len)
{
    char *buf = NULL;
    size_t n = 0;
    FILE *f = open_memstream(&buf, &n);
    if (!f)
        return NULL;
    lr_jw *w = lr_jw_create(f);
    int rc = LR_ENOMEM;
    if (w) {
        lr_jw_object(w, NULL);
        fill(w, arg);
        lr_jw_object_end(w);
        lr_err e = {0};
        rc = lr_jw_finish(w, &e);
    }
    if (fclose(f) || rc) {
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

typedef struct err_arg {
    unsigned status;
    const char *msg;
} err_arg;

static void fill_error(lr_jw *w, const void *arg)
{
    const err_arg *a = arg;
    lr_jw_string(w, "error", a->msg);
    lr_jw_int(w, "status", (long)a->status);
}

static enum MHD_Result fail(struct MHD_Connection *c, unsigned status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static enum MHD_Result fail(struct MHD_Connection *c, unsigned status, const char *fmt, ...)
{
    char msg[LR_ERR_MSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    err_arg a = {status, msg};
    size_t len;
    char *body = json_text(fill_error, &a, &len);
    if (!body)
        return MHD_NO;
    return queue(c, status, body, len, "application/json");
}

static enum MHD_Result json_reply(struct MHD_Connection *c, char *body, size_t len)
{
    if (!body)
        return fail(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
    return queue(c, MHD_HTTP_OK, body, len, "application/json");
}

/* ---- status and controls ---- */

static char *status_text(lr_http *h, bool controls_only, size_t *len)
{
    lr_rig_status *st = calloc(1, sizeof *st);
    if (!st)
        return NULL;
    lr_rig_get_status(h->rig, st);
    char *s = lr_status_json_string(st, controls_only, len);
    free(st);
    return s;
}

/* ---- event streams ---- */

static void sse_append(sse *s, const char *event, const char *data)
{
    if (s->dropped)
        return;
    /* "event: NAME\ndata: LINE\n" per line of data, then a blank line (the SSE framing: a
     * multi-line document needs a "data:" per line; the browser joins them with '\n'). */
    size_t need = strlen(event) + 16;
    for (const char *p = data; *p; p++)
        need += *p == '\n' ? 7 : 1;
    if (s->len - s->off + need > LR_HTTP_SSE_BUF) {
        s->dropped = true; /* a reader that stopped reading: dropped, not buffered forever */
    } else {
        if (s->off) {
            memmove(s->buf, s->buf + s->off, s->len - s->off);
            s->len -= s->off;
            s->off = 0;
        }
        if (s->len + need > s->cap) {
            size_t cap = s->cap ? s->cap : 4096;
            while (cap < s->len + need)
                cap *= 2;
            char *b = realloc(s->buf, cap);
            if (!b) {
                s->dropped = true;
                goto resume;
            }
            s->buf = b;
            s->cap = cap;
        }
        char *o = s->buf + s->len;
        o += sprintf(o, "event: %s\ndata: ", event);
        for (const char *p = data; *p; p++) {
            if (*p == '\n') {
                memcpy(o, "\ndata: ", 7);
                o += 7;
            } else {
                *o++ = *p;
            }
        }
        *o++ = '\n';
        *o++ = '\n';
        s->len = (size_t)(o - s->buf);
    }
resume:
    if (s->suspended) {
        s->suspended = false;
        MHD_resume_connection(s->conn);
    }
}

static void broadcast(lr_http *h, const char *event, const char *data)
{
    for (sse *s = h->streams; s; s = s->next)
        sse_append(s, event, data);
}

static ssize_t sse_read(void *cls, uint64_t pos, char *buf, size_t max)
{
    (void)pos;
    sse *s = cls;
    if (s->dropped || s->h->closing)
        return s->dropped ? MHD_CONTENT_READER_END_WITH_ERROR : MHD_CONTENT_READER_END_OF_STREAM;
    if (s->off == s->len) {
        /* Nothing to send: out of MHD's event loop until sse_append resumes it. */
        s->suspended = true;
        MHD_suspend_connection(s->conn);
        return 0;
    }
    size_t n = s->len - s->off < max ? s->len - s->off : max;
    memcpy(buf, s->buf + s->off, n);
    s->off += n;
    if (s->off == s->len)
        s->off = s->len = 0;
    return (ssize_t)n;
}

static void sse_free(void *cls)
{
    sse *s = cls;
    lr_http *h = s->h;
    for (sse **p = &h->streams; *p; p = &(*p)->next)
        if (*p == s) {
            *p = s->next;
            break;
        }
    h->n_streams--;
    free(s->buf);
    free(s);
}

static enum MHD_Result events(lr_http *h, struct MHD_Connection *c)
{
    if (h->n_streams >= LR_HTTP_SSE_CLIENTS)
        return fail(c, MHD_HTTP_SERVICE_UNAVAILABLE, "at most %d event streams",
                    LR_HTTP_SSE_CLIENTS);
    sse *s = calloc(1, sizeof *s);
    if (!s)
        return fail(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
    s->h = h;
    s->conn = c;
    /* The stream starts with the whole state, so a client needs nothing else. */
    size_t len;
    char *st = status_text(h, false, &len);
    if (st)
        sse_append(s, "status", st);
    free(st);
    struct MHD_Response *r =
        MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 4096, sse_read, s, sse_free);
    if (!r) {
        free(s->buf);
        free(s);
        return MHD_NO;
    }
    s->next = h->streams;
    h->streams = s;
    h->n_streams++;
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, "text/event-stream");
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    enum MHD_Result ret = MHD_queue_response(c, MHD_HTTP_OK, r);
    MHD_destroy_response(r);
    return ret;
}

/* ---- the frame ---- */

static enum MHD_Result frame_png(lr_http *h, struct MHD_Connection *c, int64_t now)
{
    int w = 0, ht = 0;
    uint64_t frame = 0;
    lr_err e = {0};
    /* Re-encoded only for a newer frame, and at most every LR_HTTP_PNG_MIN_MS: a page (or a
     * script) polling fast gets the cached image, the loop spends no more than that on it. */
    if (!h->png || now - h->png_ns >= (int64_t)LR_HTTP_PNG_MIN_MS * 1000000) {
        const unsigned char *rgba = NULL;
        lr_rig_info info;
        lr_rig_get_info(h->rig, &info);
        if (!h->png || (info.frames && info.frames - 1 != h->png_frame))
            rgba = lr_rig_frame_rgba(h->rig, &w, &ht, &frame, &e);
        if (!rgba && !h->png)
            return fail(c, MHD_HTTP_SERVICE_UNAVAILABLE, "no frame yet: %s", e.msg);
        if (rgba) {
            unsigned char *rgb = malloc((size_t)w * (size_t)ht * 3);
            if (!rgb)
                return fail(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "out of memory");
            for (size_t i = 0; i < (size_t)w * (size_t)ht; i++)
                memcpy(rgb + 3 * i, rgba + 4 * i, 3);
            png_image pi;
            memset(&pi, 0, sizeof pi);
            pi.version = PNG_IMAGE_VERSION;
            pi.width = (png_uint_32)w;
            pi.height = (png_uint_32)ht;
            pi.format = PNG_FORMAT_RGB;
            png_alloc_size_t size = 0;
            unsigned char *out = NULL;
            int ok = png_image_write_to_memory(&pi, NULL, &size, 0, rgb, 0, NULL);
            if (ok && (out = malloc(size)))
                ok = png_image_write_to_memory(&pi, out, &size, 0, rgb, 0, NULL);
            free(rgb);
            if (!ok || !out) {
                free(out);
                return fail(c, MHD_HTTP_INTERNAL_SERVER_ERROR, "PNG encoding failed: %s",
                            pi.message);
            }
            free(h->png);
            h->png = out;
            h->png_len = size;
            h->png_frame = frame;
            h->png_ns = now;
        }
    }
    struct MHD_Response *r =
        MHD_create_response_from_buffer(h->png_len, h->png, MHD_RESPMEM_MUST_COPY);
    if (!r)
        return MHD_NO;
    char num[32];
    snprintf(num, sizeof num, "%llu", (unsigned long long)h->png_frame);
    MHD_add_response_header(r, MHD_HTTP_HEADER_CONTENT_TYPE, "image/png");
    MHD_add_response_header(r, MHD_HTTP_HEADER_CACHE_CONTROL, "no-store");
    MHD_add_response_header(r, "X-Lamprig-Frame", num);
    enum MHD_Result ret = MHD_queue_response(c, MHD_HTTP_OK, r);
    MHD_destroy_response(r);
    return ret;
}

/* ---- POSTs ---- */

/* Parses the body as a JSON object with exactly the one member `key`: a number (num) or a
 * string (str). Answers the 400 itself and returns false on anything else. */
static bool body_member(struct MHD_Connection *c, const req *q, const char *key, double *num,
                        char *str, size_t cap, enum MHD_Result *ret)
{
    lr_json *j = NULL;
    lr_err e = {0};
    if (lr_json_parse(q->body, q->len, "body", &j, &e)) {
        *ret = fail(c, MHD_HTTP_BAD_REQUEST, "malformed JSON: %s", e.msg);
        return false;
    }
    lr_jnode root = lr_json_root(j);
    const char *keys[] = {key, NULL};
    int rc = lr_json_type(j, root) != LR_JSON_OBJECT
                 ? lr_err_set(&e, LR_EPARSE, "expected an object {\"%s\": ...}", key)
                 : lr_json_check_keys(j, root, "body", keys, &e);
    if (!rc)
        rc = num ? lr_json_get_number(j, root, key, true, num, &e)
                 : lr_json_get_string(j, root, key, true, str, cap, &e);
    lr_json_destroy(j);
    if (rc) {
        *ret = fail(c, MHD_HTTP_BAD_REQUEST, "%s", e.msg);
        return false;
    }
    return true;
}

typedef struct ok_arg {
    const char *what, *name;
    double value;
    bool has_value;
} ok_arg;

static void fill_ok(lr_jw *w, const void *arg)
{
    const ok_arg *a = arg;
    lr_jw_bool(w, "ok", true);
    lr_jw_string(w, a->what, a->name);
    if (a->has_value)
        lr_jw_number(w, "value", a->value);
}

static enum MHD_Result ok_reply(struct MHD_Connection *c, const ok_arg *a)
{
    size_t len;
    char *body = json_text(fill_ok, a, &len);
    return json_reply(c, body, len);
}

static enum MHD_Result post_control(lr_http *h, struct MHD_Connection *c, const char *name,
                                    const req *q)
{
    double v;
    enum MHD_Result ret;
    if (!body_member(c, q, "value", &v, NULL, 0, &ret))
        return ret;
    if (!isfinite(v) || v < 0 || v > 1)
        return fail(c, MHD_HTTP_BAD_REQUEST, "field 'value': must be in 0..1, got %g", v);
    lr_err e = {0};
    int rc = lr_rig_post_control(h->rig, name, v, &e);
    if (rc == LR_ENODEV)
        return fail(c, MHD_HTTP_NOT_FOUND, "%s", e.msg);
    if (rc)
        return fail(c, MHD_HTTP_BAD_REQUEST, "%s", e.msg);
    ok_arg a = {"control", name, v, true};
    return ok_reply(c, &a);
}

static enum MHD_Result post_scene(lr_http *h, struct MHD_Connection *c, const req *q)
{
    char name[LR_RIG_PATH_MAX];
    enum MHD_Result ret;
    if (!body_member(c, q, "scene", NULL, name, sizeof name, &ret))
        return ret;
    lr_err e = {0};
    int rc = lr_rig_post_scene(h->rig, name, &e);
    if (rc == LR_ENODEV)
        return fail(c, MHD_HTTP_NOT_FOUND, "%s", e.msg);
    if (rc)
        return fail(c, MHD_HTTP_BAD_REQUEST, "%s", e.msg);
    ok_arg a = {"scene", name, 0, false};
    return ok_reply(c, &a);
}

static void wait_unlink(lr_http *h, req *q)
{
    for (req **p = &h->reloads; *p; p = &(*p)->next_wait)
        if (*p == q) {
            *p = q->next_wait;
            break;
        }
    q->next_wait = NULL;
}

/* The rig's answer to a reload (on the loop, or inside lr_rig_reload_async): kept for the
 * handler, which MHD calls again once the connection is resumed. */
static void reload_done(void *ctx, int rc, const lr_err *e)
{
    req *q = ctx;
    q->reload_done = true;
    q->reload_rc = rc;
    snprintf(q->reload_msg, sizeof q->reload_msg, "%s", rc && e ? e->msg : "");
    wait_unlink(q->h, q);
    if (q->suspended) {
        q->suspended = false;
        MHD_resume_connection(q->conn);
    }
}

static enum MHD_Result reload_reply(lr_http *h, struct MHD_Connection *c, const req *q)
{
    if (h->closing && q->reload_rc < 0)
        return fail(c, MHD_HTTP_SERVICE_UNAVAILABLE, "reload: the rig is shutting down");
    if (q->reload_rc)
        return fail(c, MHD_HTTP_UNPROCESSABLE_CONTENT, "reload: %s; keeping the running config",
                    q->reload_msg);
    ok_arg a = {"reloaded", "config", 0, false};
    return ok_reply(c, &a);
}

/* What SIGHUP does, answered when the new config runs or has failed: the config loads in a
 * job off the loop meanwhile, the connection suspended, so the loop never waits for it. */
static enum MHD_Result post_reload(lr_http *h, struct MHD_Connection *c, req *q)
{
    if (q->len) {
        /* An empty body or {}: nothing else is defined. */
        lr_json *j = NULL;
        lr_err e = {0};
        const char *none[] = {NULL};
        int rc = lr_json_parse(q->body, q->len, "body", &j, &e);
        if (!rc)
            rc = lr_json_type(j, lr_json_root(j)) != LR_JSON_OBJECT
                     ? lr_err_set(&e, LR_EPARSE, "expected {} or no body")
                     : lr_json_check_keys(j, lr_json_root(j), "body", none, &e);
        lr_json_destroy(j);
        if (rc)
            return fail(c, MHD_HTTP_BAD_REQUEST, "%s", e.msg);
    }
    lr_err e = {0};
    q->h = h;
    q->conn = c;
    q->reload_wait = true;
    q->next_wait = h->reloads;
    h->reloads = q;
    if (lr_rig_reload_async(h->rig, reload_done, q, &e)) {
        wait_unlink(h, q);
        q->reload_wait = false;
        return fail(c, MHD_HTTP_SERVICE_UNAVAILABLE, "%s", e.msg);
    }
    if (q->reload_done) /* answered at once: no job could be started */
        return reload_reply(h, c, q);
    q->suspended = true;
    MHD_suspend_connection(c);
    return MHD_YES;
}

/* ---- checks ---- */

static bool host_ok(struct MHD_Connection *c)
{
    const char *host = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_HOST);
    if (!host)
        return false;
    static const char *const ok[] = {"127.", "localhost", "[::1]"};
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; i++) {
        size_t n = strlen(ok[i]);
        if (strncmp(host, ok[i], n) == 0) {
            const char *rest = host + n;
            if (i == 0)
                rest += strspn(rest, "0123456789.");
            if (!*rest || *rest == ':')
                return true;
        }
    }
    return false;
}

/* Constant time in the token's length: a mismatch at the first byte takes as long as one at
 * the last. */
static bool token_ok(const lr_http *h, struct MHD_Connection *c)
{
    const char *auth =
        MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_AUTHORIZATION);
    if (!auth || strncmp(auth, "Bearer ", 7) != 0)
        return false;
    const char *t = auth + 7;
    size_t n = strlen(h->token), m = strlen(t);
    unsigned char diff = (unsigned char)(n != m);
    for (size_t i = 0; i < n; i++)
        diff |= (unsigned char)(h->token[i] ^ (i < m ? t[i] : 0));
    return diff == 0;
}

static bool rate_ok(lr_http *h, int64_t now)
{
    h->tokens += (double)(now - h->bucket_ns) * 1e-9 * LR_HTTP_RATE;
    if (h->tokens > LR_HTTP_BURST)
        h->tokens = LR_HTTP_BURST;
    h->bucket_ns = now;
    if (h->tokens < 1)
        return false;
    h->tokens -= 1;
    return true;
}

static bool is_json(struct MHD_Connection *c)
{
    const char *t = MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_TYPE);
    return t && strncasecmp(t, "application/json", 16) == 0 && (!t[16] || t[16] == ';');
}

/* ---- the handler ---- */

static enum MHD_Result route(lr_http *h, struct MHD_Connection *c, const char *url,
                             const char *method, req *q)
{
    int64_t now = lr_now_ns();
    bool get = strcmp(method, "GET") == 0 || strcmp(method, "HEAD") == 0;
    bool post = strcmp(method, "POST") == 0;
    if (h->loopback && !host_ok(c))
        return fail(c, MHD_HTTP_FORBIDDEN,
                    "Host header must name this machine (127.0.0.1, localhost, [::1]): the "
                    "rig listens on loopback only");
    if (!rate_ok(h, now))
        return fail(c, MHD_HTTP_TOO_MANY_REQUESTS, "more than %g requests a second",
                    LR_HTTP_RATE);
    if (q->too_big)
        return fail(c, MHD_HTTP_CONTENT_TOO_LARGE, "request body over %d bytes",
                    LR_HTTP_BODY_MAX);
    static const char ctl[] = "/api/controls/";
    bool is_post_path = strncmp(url, ctl, sizeof ctl - 1) == 0 ||
                        strcmp(url, "/api/scene") == 0 || strcmp(url, "/api/reload") == 0;
    bool is_get_path = strcmp(url, "/") == 0 || strcmp(url, "/api/status") == 0 ||
                       strcmp(url, "/api/controls") == 0 || strcmp(url, "/api/events") == 0 ||
                       strcmp(url, "/frame.png") == 0;
    if (!is_post_path && !is_get_path)
        return fail(c, MHD_HTTP_NOT_FOUND, "no such resource: %s", url);
    if (is_get_path && !get)
        return fail(c, MHD_HTTP_METHOD_NOT_ALLOWED, "%s takes GET, not %s", url, method);
    if (is_post_path && !post)
        return fail(c, MHD_HTTP_METHOD_NOT_ALLOWED, "%s takes POST, not %s", url, method);
    if (get) {
        if (strcmp(url, "/") == 0) {
            char *page = strdup(lr_http_page_html);
            if (!page)
                return MHD_NO;
            return queue(c, MHD_HTTP_OK, page, strlen(page), "text/html; charset=utf-8");
        }
        if (strcmp(url, "/frame.png") == 0)
            return frame_png(h, c, now);
        if (strcmp(url, "/api/events") == 0)
            return events(h, c);
        size_t len;
        char *body = status_text(h, strcmp(url, "/api/controls") == 0, &len);
        return json_reply(c, body, len);
    }
    if (h->token[0] && !token_ok(h, c))
        return fail(c, MHD_HTTP_UNAUTHORIZED,
                    "this rig needs \"Authorization: Bearer TOKEN\" (http.token) to change it");
    if (!is_json(c))
        return fail(c, MHD_HTTP_UNSUPPORTED_MEDIA_TYPE,
                    "POST bodies are JSON: Content-Type: application/json");
    if (strcmp(url, "/api/scene") == 0)
        return post_scene(h, c, q);
    if (strcmp(url, "/api/reload") == 0)
        return post_reload(h, c, q);
    const char *name = url + sizeof ctl - 1;
    if (!*name || strchr(name, '/'))
        return fail(c, MHD_HTTP_NOT_FOUND, "no such resource: %s", url);
    return post_control(h, c, name, q);
}

static enum MHD_Result handler(void *cls, struct MHD_Connection *c, const char *url,
                               const char *method, const char *version, const char *data,
                               size_t *data_size, void **con_cls)
{
    (void)version;
    lr_http *h = cls;
    req *q = *con_cls;
    if (!q) {
        /* The headers are in; the body (if any) follows in further calls. */
        if (!(q = calloc(1, sizeof *q)))
            return MHD_NO;
        *con_cls = q;
        const char *cl =
            MHD_lookup_connection_value(c, MHD_HEADER_KIND, MHD_HTTP_HEADER_CONTENT_LENGTH);
        if (cl && strtoull(cl, NULL, 10) > LR_HTTP_BODY_MAX) {
            q->too_big = true; /* answered now: MHD then discards the body and closes */
            return fail(c, MHD_HTTP_CONTENT_TOO_LARGE, "request body over %d bytes",
                        LR_HTTP_BODY_MAX);
        }
        return MHD_YES;
    }
    if (*data_size) {
        if (q->len + *data_size > LR_HTTP_BODY_MAX)
            q->too_big = true; /* chunked: counted and dropped, answered at the end */
        else {
            memcpy(q->body + q->len, data, *data_size);
            q->len += *data_size;
        }
        *data_size = 0;
        return MHD_YES;
    }
    /* A reload's request, called again once resumed: its answer (the checks were made). */
    if (q->reload_wait)
        return q->reload_done ? reload_reply(h, c, q) : MHD_YES;
    q->body[q->len] = '\0';
    return route(h, c, url, method, q);
}

static void completed(void *cls, struct MHD_Connection *c, void **con_cls,
                      enum MHD_RequestTerminationCode why)
{
    lr_http *h = cls;
    (void)c;
    (void)why;
    req *q = *con_cls;
    if (q && q->reload_wait && !q->reload_done) {
        lr_rig_reload_forget(h->rig, q);
        wait_unlink(h, q);
    }
    free(*con_cls);
    *con_cls = NULL;
}

/* MHD's own messages into the rig's log, at info level and at most 5 in 10 s: most are a
 * client's doing (a stream closed by its reader, a malformed request), and a peer must not
 * be able to flood the log or push the rig's own warnings out of the status. A failure to
 * listen is reported by lr_http_create itself. */
static void mhd_log(void *cls, const char *fmt, va_list ap)
{
    lr_http *h = cls;
    unsigned dropped = 0;
    if (!lr_log_limit_take(&h->log_limit, lr_now_ns(), &dropped))
        return;
    char msg[512];
    vsnprintf(msg, sizeof msg, fmt, ap);
    size_t n = strlen(msg);
    while (n && (msg[n - 1] == '\n' || msg[n - 1] == '\r'))
        msg[--n] = '\0';
    if (dropped)
        lr_log_write(&h->log, LR_LOG_INFO, "http: %s (%u more lines dropped)", msg, dropped);
    else
        lr_log_write(&h->log, LR_LOG_INFO, "http: %s", msg);
}

/* ---- lifecycle ---- */

int lr_http_create(const lr_http_desc *d, lr_http **out, lr_err *e)
{
    lr_http *h = calloc(1, sizeof *h);
    if (!h)
        return lr_err_set(e, LR_ENOMEM, "out of memory");
    h->rig = d->rig;
    h->log = d->log;
    h->loopback = d->loopback;
    snprintf(h->token, sizeof h->token, "%s", d->token ? d->token : "");
    h->tokens = LR_HTTP_BURST;
    h->bucket_ns = lr_now_ns();
    struct sockaddr_storage ss;
    memset(&ss, 0, sizeof ss);
    struct sockaddr_in *a4 = (struct sockaddr_in *)&ss;
    struct sockaddr_in6 *a6 = (struct sockaddr_in6 *)&ss;
    unsigned flags = MHD_USE_EPOLL | MHD_ALLOW_SUSPEND_RESUME | MHD_USE_ERROR_LOG;
    if (inet_pton(AF_INET, d->host, &a4->sin_addr) == 1) {
        a4->sin_family = AF_INET;
        a4->sin_port = htons((uint16_t)d->port);
    } else if (inet_pton(AF_INET6, d->host, &a6->sin6_addr) == 1) {
        a6->sin6_family = AF_INET6;
        a6->sin6_port = htons((uint16_t)d->port);
        flags |= MHD_USE_IPv6;
    } else {
        free(h);
        return lr_err_set(e, LR_EINVAL, "http.listen: '%s' is not a numeric address", d->host);
    }
    errno = 0;
    lr_log_limit_init(&h->log_limit, 5, 10000000000LL);
    /* The logger first: MHD reads the options in order and warns about a later one. */
    h->d = MHD_start_daemon(flags, (uint16_t)d->port, NULL, NULL, handler, h,
                            MHD_OPTION_EXTERNAL_LOGGER, mhd_log, h,
                            MHD_OPTION_SOCK_ADDR, (struct sockaddr *)&ss,
                            MHD_OPTION_CONNECTION_LIMIT, (unsigned)LR_HTTP_CONNS,
                            MHD_OPTION_PER_IP_CONNECTION_LIMIT, (unsigned)LR_HTTP_CONNS_PER_IP,
                            MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)LR_HTTP_TIMEOUT_S,
                            MHD_OPTION_CONNECTION_MEMORY_LIMIT, (size_t)LR_HTTP_CONN_MEM,
                            MHD_OPTION_NOTIFY_COMPLETED, completed, h, MHD_OPTION_END);
    if (!h->d) {
        int err = errno;
        free(h);
        return lr_err_set(e, LR_EIO, "http.listen %s%s%s:%d: cannot listen%s%s",
                          strchr(d->host, ':') ? "[" : "", d->host,
                          strchr(d->host, ':') ? "]" : "", d->port, err ? ": " : "",
                          err ? strerror(err) : "");
    }
    const union MHD_DaemonInfo *pi = MHD_get_daemon_info(h->d, MHD_DAEMON_INFO_BIND_PORT);
    h->port = pi ? pi->port : d->port;
    *out = h;
    return LR_OK;
}

void lr_http_destroy(lr_http *h)
{
    if (!h)
        return;
    /* Suspended streams must be resumed before MHD_stop_daemon (microhttpd.h); the readers
     * then end their streams. */
    h->closing = true;
    for (sse *s = h->streams; s; s = s->next)
        if (s->suspended) {
            s->suspended = false;
            MHD_resume_connection(s->conn);
        }
    /* Reloads still awaited are answered 503: the rig will not call them. */
    while (h->reloads) {
        req *q = h->reloads;
        lr_rig_reload_forget(h->rig, q);
        lr_err e = {0};
        reload_done(q, -1, &e); /* unlinks it, resumes its connection */
    }
    MHD_run(h->d);
    MHD_stop_daemon(h->d);
    free(h->png);
    free(h);
}

int lr_http_port(const lr_http *h) { return h ? h->port : 0; }

int lr_http_pollfd(const lr_http *h)
{
    const union MHD_DaemonInfo *i = MHD_get_daemon_info(h->d, MHD_DAEMON_INFO_EPOLL_FD);
    return i ? i->epoll_fd : -1;
}

int64_t lr_http_deadline(const lr_http *h, int64_t now_ns)
{
    int64_t t = INT64_MAX;
    MHD_UNSIGNED_LONG_LONG ms;
    if (MHD_get_timeout(h->d, &ms) == MHD_YES)
        t = now_ns + (int64_t)(ms > 86400000ULL ? 86400000ULL : ms) * 1000000;
    if (h->n_streams) {
        if (h->next_status_ns < t)
            t = h->next_status_ns;
        if (h->controls_dirty) {
            int64_t c = h->last_controls_ns + (int64_t)LR_HTTP_CONTROLS_MS * 1000000;
            if (c < t)
                t = c;
        }
    }
    return t;
}

void lr_http_dispatch(lr_http *h, int64_t now_ns)
{
    if (h->n_streams) {
        if (h->controls_dirty &&
            now_ns >= h->last_controls_ns + (int64_t)LR_HTTP_CONTROLS_MS * 1000000) {
            size_t len;
            char *c = status_text(h, true, &len);
            if (c)
                broadcast(h, "controls", c);
            free(c);
            h->controls_dirty = false;
            h->last_controls_ns = now_ns;
        }
        if (now_ns >= h->next_status_ns) {
            size_t len;
            char *s = status_text(h, false, &len);
            if (s)
                broadcast(h, "status", s);
            free(s);
            h->next_status_ns = now_ns + (int64_t)LR_HTTP_STATUS_MS * 1000000;
        }
    } else {
        h->controls_dirty = false;
        h->next_status_ns = now_ns + (int64_t)LR_HTTP_STATUS_MS * 1000000;
    }
    MHD_run(h->d);
}

void lr_http_controls_changed(lr_http *h)
{
    if (h)
        h->controls_dirty = true;
}

int lr_http_streams(const lr_http *h) { return h ? h->n_streams : 0; }
