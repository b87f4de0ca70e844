/* lamprig firmware — the rig's HTTP endpoint: a JSON API, live updates and a small page
 * (config "http": {"listen": "127.0.0.1:8080", "token": "..."}; firmware/README.md has the
 * API reference).
 *
 *   GET  /                      the page, embedded in the binary (http_page.c): status, the
 *                               frame, a slider per control
 *   GET  /api/status            the status document (firmware/rig/status_json.h)
 *   GET  /api/controls          its "controls" array alone
 *   POST /api/controls/NAME     {"value": V}, V in the control's own 0..1 range (a level
 *                               binding's position; a cycle binding's floor(V * n)-th value)
 *   POST /api/scene             {"scene": "NAME"}: a scene of the config's scene binding, or a
 *                               shipped scene (configs/scenes/NAME.json)
 *   POST /api/reload            what SIGHUP does; the answer says whether it took
 *   GET  /api/events            Server-Sent Events: "status" (the document) every second and
 *                               on connect, "controls" when a control moved (at most 20 a
 *                               second)
 *   GET  /frame.png             the latest frame (X-Lamprig-Frame: its number), re-encoded
 *                               at most every LR_HTTP_PNG_MIN_MS, else the cached one
 * Every bad request gets a 4xx with {"error": "...", "status": N}.
 *
 * Why libmicrohttpd (Debian libmicrohttpd12): a small C library made to be embedded, with an
 * "external select" mode: it starts no thread and hands its sockets to the caller's loop. With
 * MHD_USE_EPOLL all of them are behind one epoll descriptor (MHD_DAEMON_INFO_EPOLL_FD), which
 * joins the rig's poll(2) set (lr_http_pollfd), and MHD_get_timeout gives its deadline; the
 * loop calls lr_http_dispatch, which runs MHD_run once: non-blocking sockets, no waits. So
 * every handler runs on the loop's own thread and reads the rig directly, and a POST becomes
 * an lr_event pushed into the same event ring the devices fill (lr_rig_post_control): it goes
 * through the control map like any device's event. libwebsockets would do the same with more
 * code (and a WebSocket the page does not need: the live updates only flow one way, which is
 * what Server-Sent Events are). An SSE stream with nothing to send is suspended
 * (MHD_suspend_connection) and resumed when there is, so an idle stream costs no wake-ups.
 *
 * Bounds: request bodies LR_HTTP_BODY_MAX bytes (413), headers MHD's connection memory
 * (LR_HTTP_CONN_MEM; MHD answers 431 itself), LR_HTTP_CONNS connections (LR_HTTP_CONNS_PER_IP
 * from one address), LR_HTTP_TIMEOUT_S idle timeout, requests LR_HTTP_RATE a second with a
 * burst of LR_HTTP_BURST (429 with Retry-After), LR_HTTP_SSE_CLIENTS event streams (503) and
 * LR_HTTP_SSE_BUF bytes queued per stream (a reader that stops reading is dropped).
 *
 * Security. Bound to the configured address only (127.0.0.1 by default in the shipped
 * config). With a token, every POST needs "Authorization: Bearer TOKEN" (401 otherwise,
 * compared in constant time); the config refuses a non-loopback address without one. POSTs
 * need "Content-Type: application/json", which a cross-site HTML form cannot send. On a
 * loopback address the Host header must name a loopback host (127.x, localhost, [::1]), so
 * a web page cannot reach the rig through DNS rebinding. Reads (status, the frame, the page)
 * need no token.
 */
#ifndef LR_RIG_HTTP_H
#define LR_RIG_HTTP_H

#include <poll.h>
#include <stdbool.h>
#include <stdint.h>

#include "hal/log.h"
#include "render/base/err.h"

#define LR_HTTP_BODY_MAX 4096
#define LR_HTTP_CONN_MEM (32 * 1024)
#define LR_HTTP_CONNS 32
#define LR_HTTP_CONNS_PER_IP 16
#define LR_HTTP_TIMEOUT_S 30
#define LR_HTTP_RATE 100.0
#define LR_HTTP_BURST 200.0
#define LR_HTTP_SSE_CLIENTS 8
#define LR_HTTP_SSE_BUF (256 * 1024)
#define LR_HTTP_STATUS_MS 1000
#define LR_HTTP_CONTROLS_MS 50
#define LR_HTTP_PNG_MIN_MS 100

struct lr_rig;
typedef struct lr_http lr_http;

typedef struct lr_http_desc {
    const char *host;  /* numeric address */
    int port;          /* 0: any free port (tests; lr_http_port says which) */
    bool loopback;     /* enforce a loopback Host header */
    const char *token; /* NULL or "": POSTs need none */
    struct lr_rig *rig;
    lr_log log;
} lr_http_desc;

/* Binds and listens (errors name the address: "http.listen 127.0.0.1:8080: Address already
 * in use"). */
int lr_http_create(const lr_http_desc *d, lr_http **out, lr_err *e);
/* Ends every stream and closes the sockets. NULL is a no-op. */
void lr_http_destroy(lr_http *h);
int lr_http_port(const lr_http *h);

/* The descriptor for the loop's poll set (POLLIN). */
int lr_http_pollfd(const lr_http *h);
/* The earliest time lr_http_dispatch has work without the descriptor: MHD's own timeouts,
 * a stream's next status or controls event; INT64_MAX: none. */
int64_t lr_http_deadline(const lr_http *h, int64_t now_ns);
/* Runs what is due: queues the streams' events, then MHD_run (handlers run inside). */
void lr_http_dispatch(lr_http *h, int64_t now_ns);
/* A control moved (the loop applied events or a fade step): the streams get a "controls"
 * event, at most every LR_HTTP_CONTROLS_MS. */
void lr_http_controls_changed(lr_http *h);
/* Open event streams. */
int lr_http_streams(const lr_http *h);

/* The page (http_page.c). */
extern const char lr_http_page_html[];

#endif
