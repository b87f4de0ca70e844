#include "hal/gpio.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <gpiod.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/debounce.h"
#include "hal/dev_impl.h"
#include "hal/quad.h"

typedef struct gline {
    char spec[LR_EVENT_NAME_MAX];     /* as configured: name or offset */
    char what[LR_EVENT_NAME_MAX + 8]; /* "knob1.a", "button1": for messages */
    struct gpiod_line *line;
    int fd;
} gline;

typedef struct encoder {
    char name[LR_EVENT_NAME_MAX];
    gline l[2];
    int steps;
    bool reverse;
    lr_quad q;
    unsigned invalid_before; /* invalid counts of previous opens */
} encoder;

typedef struct button {
    char name[LR_EVENT_NAME_MAX];
    gline l;
    bool active_high;
    int64_t window_ns;
    lr_debounce db;
} button;

struct lr_gpio {
    lr_dev base;
    char chip_name[128];
    char consumer[64];
    int flags;
    struct gpiod_chip *chip;
    encoder *enc;
    int n_enc;
    button *btn;
    int n_btn;
};

#define NS_PER_S 1000000000LL

static const char *const BIASES[] = {"pull-up", "as-is", "disable", "pull-down", NULL};

const lr_opt lr_gpio_opts[] = {
    [LR_GPIO_OPT_CHIP] = {"chip", LR_OPT_STRING, .dflt_text = "gpiochip0",
                          .help = "gpiochip name or path"},
    [LR_GPIO_OPT_BIAS] = {"bias", LR_OPT_ENUM, .dflt = LR_GPIO_BIAS_PULL_UP, .names = BIASES,
                          .help = "line bias (lr_gpio_bias order)"},
    [LR_GPIO_OPT_ENCODERS] = {"encoders", LR_OPT_LIST, .help = "rotary encoders (below)"},
    [LR_GPIO_OPT_BUTTONS] = {"buttons", LR_OPT_LIST, .help = "push buttons (below)"},
    LR_OPT_END,
};

/* steps_per_detent is 1, 2 or 4 (checked below): quadrature has no 3-step detent. */
const lr_opt lr_gpio_encoder_opts[] = {
    [LR_GPIO_ENC_NAME] = {"name", LR_OPT_STRING, .required = true, .help = "control name"},
    [LR_GPIO_ENC_LINE_A] = {"line_a", LR_OPT_STRING, .required = true,
                            .help = "line name or offset"},
    [LR_GPIO_ENC_LINE_B] = {"line_b", LR_OPT_STRING, .required = true,
                            .help = "line name or offset"},
    [LR_GPIO_ENC_STEPS_PER_DETENT] = {"steps_per_detent", LR_OPT_INT, 1, 4, 4,
                                      .help = "quadrature transitions per detent: 1, 2 or 4"},
    [LR_GPIO_ENC_REVERSE] = {"reverse", LR_OPT_BOOL, .dflt = 0, .help = "swap the direction"},
    LR_OPT_END,
};

const lr_opt lr_gpio_button_opts[] = {
    [LR_GPIO_BTN_NAME] = {"name", LR_OPT_STRING, .required = true, .help = "control name"},
    [LR_GPIO_BTN_LINE] = {"line", LR_OPT_STRING, .required = true, .help = "line name or offset"},
    [LR_GPIO_BTN_ACTIVE_HIGH] = {"active_high", LR_OPT_BOOL, .dflt = 0,
                                 .help = "pressed drives the line high"},
    [LR_GPIO_BTN_DEBOUNCE_MS] = {"debounce_ms", LR_OPT_INT, 0, 1000, 5,
                                 .help = "debounce window (0: the default)"},
    LR_OPT_END,
};

static int64_t event_time(const struct gpiod_line_event *ev, int64_t now_ns)
{
    int64_t t = (int64_t)ev->ts.tv_sec * NS_PER_S + ev->ts.tv_nsec;
    /* Kernels before 5.7 stamp with CLOCK_REALTIME: use the read time then. */
    if (t > now_ns + 10 * NS_PER_S || t < now_ns - 10 * NS_PER_S)
        return now_ns;
    return t;
}

static bool is_offset(const char *s)
{
    if (!*s)
        return false;
    for (; *s; s++)
        if (!isdigit((unsigned char)*s))
            return false;
    return true;
}

static void release_line(gline *l)
{
    if (l->line)
        gpiod_line_release(l->line);
    l->line = NULL;
    l->fd = -1;
}

static void gpio_close(lr_dev *d)
{
    lr_gpio *g = (lr_gpio *)d;
    for (int i = 0; i < g->n_enc; i++) {
        if (g->enc[i].l[0].line)
            g->enc[i].invalid_before += g->enc[i].q.invalid;
        g->enc[i].q.invalid = 0;
        release_line(&g->enc[i].l[0]);
        release_line(&g->enc[i].l[1]);
    }
    for (int i = 0; i < g->n_btn; i++)
        release_line(&g->btn[i].l);
    if (g->chip)
        gpiod_chip_close(g->chip);
    g->chip = NULL;
}

/* Finds, requests (both edges) and reads one line; returns its level or -1 with e set. */
static int request_line(lr_gpio *g, gline *l, lr_err *e)
{
    const char *chip = g->chip_name;
    struct gpiod_line *line;
    errno = 0;
    if (is_offset(l->spec)) {
        unsigned off = (unsigned)strtoul(l->spec, NULL, 10);
        line = gpiod_chip_get_line(g->chip, off);
        if (!line) {
            lr_err_set(e, LR_ENODEV, "%s: line offset %u (%s) does not exist (chip has %u lines)",
                       chip, off, l->what, gpiod_chip_num_lines(g->chip));
            return -1;
        }
    } else {
        line = gpiod_chip_find_line(g->chip, l->spec);
        if (!line) {
            lr_err_set(e, LR_ENODEV, "%s: line '%s' (%s) not found%s%s", chip, l->spec, l->what,
                       errno && errno != ENOENT ? ": " : "",
                       errno && errno != ENOENT ? strerror(errno) : "");
            return -1;
        }
    }
    if (gpiod_line_request_both_edges_events_flags(line, g->consumer, g->flags) < 0) {
        int err = errno;
        const char *user = gpiod_line_consumer(line);
        lr_err_set(e, LR_EIO, "%s: line %s (%s): request failed: %s%s%s%s",
                   chip, l->spec, l->what, strerror(err), user ? " (used by '" : "",
                   user ? user : "", user ? "')" : "");
        return -1;
    }
    l->line = line;
    l->fd = gpiod_line_event_get_fd(line);
    int fl = l->fd >= 0 ? fcntl(l->fd, F_GETFL) : -1;
    if (fl < 0 || fcntl(l->fd, F_SETFL, fl | O_NONBLOCK) < 0) {
        lr_err_set(e, LR_EIO, "%s: line %s (%s): no usable event fd: %s", chip, l->spec, l->what,
                   strerror(errno));
        return -1;
    }
    int v = gpiod_line_get_value(line);
    if (v < 0) {
        lr_err_set(e, LR_EIO, "%s: line %s (%s): cannot read value: %s", chip, l->spec, l->what,
                   strerror(errno));
        return -1;
    }
    return v;
}

static int gpio_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    lr_gpio *g = (lr_gpio *)d;
    (void)now_ns;
    errno = 0;
    g->chip = gpiod_chip_open_lookup(g->chip_name);
    if (!g->chip) {
        int err = errno ? errno : ENOENT;
        return lr_err_set(e, err == ENOENT || err == ENODEV ? LR_ENODEV : LR_EIO,
                          "%s: cannot open chip: %s", g->chip_name, strerror(err));
    }
    for (int i = 0; i < g->n_enc; i++) {
        encoder *en = &g->enc[i];
        int a = request_line(g, &en->l[0], e);
        int b = a < 0 ? -1 : request_line(g, &en->l[1], e);
        if (a < 0 || b < 0) {
            gpio_close(d);
            return e->code;
        }
        lr_quad_init(&en->q, en->steps, (unsigned)(a << 1 | b), en->reverse);
    }
    for (int i = 0; i < g->n_btn; i++) {
        button *bt = &g->btn[i];
        int v = request_line(g, &bt->l, e);
        if (v < 0) {
            gpio_close(d);
            return e->code;
        }
        lr_debounce_init(&bt->db, bt->window_ns, bt->active_high ? v : !v);
    }
    return LR_OK;
}

static int gpio_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    lr_gpio *g = (lr_gpio *)d;
    int n = 0;
    for (int i = 0; i < g->n_enc; i++)
        for (int k = 0; k < 2; k++) {
            if (n < max)
                fds[n] = (struct pollfd){.fd = g->enc[i].l[k].fd, .events = POLLIN};
            n++;
        }
    for (int i = 0; i < g->n_btn; i++) {
        if (n < max)
            fds[n] = (struct pollfd){.fd = g->btn[i].l.fd, .events = POLLIN};
        n++;
    }
    return n;
}

/* Reads up to max events from fd. Returns the count, or -1 (errno set) on a real error. */
static int read_events(int fd, struct gpiod_line_event *ev, int max)
{
    int n = gpiod_line_event_read_fd_multiple(fd, ev, (unsigned)max);
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
        return 0;
    return n;
}

typedef struct tagged {
    int64_t t;
    int line;
    int level;
} tagged;

#define BATCH 64

static bool dispatch_encoder(lr_gpio *g, encoder *en, int64_t now_ns)
{
    struct gpiod_line_event raw[BATCH];
    tagged ev[2 * BATCH];
    int n = 0;
    for (int k = 0; k < 2; k++) {
        int got = read_events(en->l[k].fd, raw, BATCH);
        if (got < 0) {
            int err = errno;
            lr_dev_lost(&g->base, err == ENODEV ? LR_ENODEV : LR_EIO, now_ns,
                        "%s: line %s (%s): read failed: %s", g->chip_name, en->l[k].spec,
                        en->l[k].what, strerror(err));
            return false;
        }
        for (int i = 0; i < got; i++)
            ev[n++] = (tagged){event_time(&raw[i], now_ns), k,
                               raw[i].event_type == GPIOD_LINE_EVENT_RISING_EDGE};
    }
    /* The two contacts come on two fds: restore their order by timestamp (insertion sort is
     * stable, so same-time edges keep their per-line order). */
    for (int i = 1; i < n; i++) {
        tagged x = ev[i];
        int j = i - 1;
        while (j >= 0 && ev[j].t > x.t) {
            ev[j + 1] = ev[j];
            j--;
        }
        ev[j + 1] = x;
    }
    for (int i = 0; i < n; i++) {
        int step = lr_quad_edge(&en->q, ev[i].line, ev[i].level);
        if (step)
            lr_dev_emit(&g->base, NULL, en->name, LR_EV_DELTA, step, ev[i].t);
    }
    return true;
}

static void button_change(lr_gpio *g, button *bt, int change, int64_t t)
{
    if (change > 0)
        lr_dev_emit(&g->base, NULL, bt->name, LR_EV_PRESS, 1, t);
    else if (change < 0)
        lr_dev_emit(&g->base, NULL, bt->name, LR_EV_RELEASE, 0, t);
}

static bool dispatch_button(lr_gpio *g, button *bt, int64_t now_ns)
{
    struct gpiod_line_event raw[BATCH];
    int got = read_events(bt->l.fd, raw, BATCH);
    if (got < 0) {
        int err = errno;
        lr_dev_lost(&g->base, err == ENODEV ? LR_ENODEV : LR_EIO, now_ns,
                    "%s: line %s (%s): read failed: %s", g->chip_name, bt->l.spec, bt->l.what,
                    strerror(err));
        return false;
    }
    for (int i = 0; i < got; i++) {
        int level = raw[i].event_type == GPIOD_LINE_EVENT_RISING_EDGE;
        int64_t t;
        int c = lr_debounce_edge(&bt->db, bt->active_high ? level : !level,
                                 event_time(&raw[i], now_ns), &t);
        button_change(g, bt, c, t);
    }
    if (lr_debounce_deadline(&bt->db) <= now_ns) {
        int64_t t;
        int c = lr_debounce_tick(&bt->db, now_ns, &t);
        button_change(g, bt, c, t);
    }
    return true;
}

static void gpio_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_gpio *g = (lr_gpio *)d;
    for (int i = 0; i < g->n_enc; i++)
        if (!dispatch_encoder(g, &g->enc[i], now_ns))
            return;
    for (int i = 0; i < g->n_btn; i++)
        if (!dispatch_button(g, &g->btn[i], now_ns))
            return;
}

static int64_t gpio_next_deadline(lr_dev *d)
{
    lr_gpio *g = (lr_gpio *)d;
    int64_t t = LR_NO_DEADLINE;
    for (int i = 0; i < g->n_btn; i++) {
        int64_t b = lr_debounce_deadline(&g->btn[i].db);
        if (b < t)
            t = b;
    }
    return t;
}

static void gpio_destroy(lr_dev *d)
{
    lr_gpio *g = (lr_gpio *)d;
    free(g->enc);
    free(g->btn);
    free(g);
}

static const lr_dev_ops GPIO_OPS = {
    .kind = "gpio",
    .open = gpio_open,
    .close = gpio_close,
    .pollfds = gpio_pollfds,
    .dispatch = gpio_dispatch,
    .next_deadline = gpio_next_deadline,
    .destroy = gpio_destroy,
};

static int set_line(lr_gpio *g, gline *l, const char *spec, const char *ctl, const char *suffix,
                    const char *field, lr_err *e)
{
    if (!spec || !spec[0])
        return lr_err_set(e, LR_EINVAL, "%s: %s: no line given", g->base.prefix, field);
    if (strlen(spec) >= sizeof l->spec)
        return lr_err_set(e, LR_EINVAL, "%s: %s: line name '%s' too long", g->base.prefix, field,
                          spec);
    strcpy(l->spec, spec);
    snprintf(l->what, sizeof l->what, "%s%s", ctl, suffix);
    l->fd = -1;
    return LR_OK;
}

static int set_name(lr_gpio *g, char dst[LR_EVENT_NAME_MAX], const char *name, const char *field,
                    lr_err *e)
{
    if (!name || !name[0])
        return lr_err_set(e, LR_EINVAL, "%s: %s: no control name", g->base.prefix, field);
    if (strlen(name) >= LR_EVENT_NAME_MAX)
        return lr_err_set(e, LR_EINVAL, "%s: %s: name '%s' longer than %d characters",
                          g->base.prefix, field, name, LR_EVENT_NAME_MAX - 1);
    for (int i = 0; i < g->n_enc; i++)
        if (g->enc[i].name != dst && strcmp(g->enc[i].name, name) == 0)
            return lr_err_set(e, LR_EINVAL, "%s: %s: control name '%s' used twice",
                              g->base.prefix, field, name);
    for (int i = 0; i < g->n_btn; i++)
        if (g->btn[i].name != dst && strcmp(g->btn[i].name, name) == 0)
            return lr_err_set(e, LR_EINVAL, "%s: %s: control name '%s' used twice",
                              g->base.prefix, field, name);
    strcpy(dst, name);
    return LR_OK;
}

static int configure(lr_gpio *g, const lr_gpio_desc *desc, lr_err *e)
{
    const char *pf = g->base.prefix;
    if (desc->n_encoders < 0 || desc->n_buttons < 0 ||
        2 * desc->n_encoders + desc->n_buttons > LR_GPIO_MAX_LINES)
        return lr_err_set(e, LR_EINVAL, "%s: %d encoders and %d buttons: 0..%d lines allowed", pf,
                          desc->n_encoders, desc->n_buttons, LR_GPIO_MAX_LINES);
    if (desc->n_encoders + desc->n_buttons == 0)
        return lr_err_set(e, LR_EINVAL, "%s: no encoders or buttons configured", pf);
    if ((desc->n_encoders && !desc->encoders) || (desc->n_buttons && !desc->buttons))
        return lr_err_set(e, LR_EINVAL, "%s: encoder/button array is NULL", pf);
    const char *chip =
        desc->chip && desc->chip[0] ? desc->chip : lr_gpio_opts[LR_GPIO_OPT_CHIP].dflt_text;
    if (strlen(chip) >= sizeof g->chip_name)
        return lr_err_set(e, LR_EINVAL, "%s: chip name too long", pf);
    strcpy(g->chip_name, chip);
    snprintf(g->base.ident, sizeof g->base.ident, "%s", chip);
    snprintf(g->consumer, sizeof g->consumer, "%s",
             desc->consumer && desc->consumer[0] ? desc->consumer : "lamprig");
    switch (desc->bias) {
    case LR_GPIO_BIAS_PULL_UP: g->flags = GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP; break;
    case LR_GPIO_BIAS_AS_IS: g->flags = 0; break;
    case LR_GPIO_BIAS_DISABLE: g->flags = GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE; break;
    case LR_GPIO_BIAS_PULL_DOWN: g->flags = GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN; break;
    default: return lr_err_set(e, LR_EINVAL, "%s: bias %d unknown", pf, (int)desc->bias);
    }
    g->enc = calloc((size_t)desc->n_encoders + 1, sizeof *g->enc);
    g->btn = calloc((size_t)desc->n_buttons + 1, sizeof *g->btn);
    if (!g->enc || !g->btn)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", pf);
    char field[48];
    for (int i = 0; i < desc->n_encoders; i++) {
        const lr_gpio_encoder *c = &desc->encoders[i];
        encoder *en = &g->enc[i];
        g->n_enc = i + 1;
        snprintf(field, sizeof field, "encoders[%d]", i);
        int rc = set_name(g, en->name, c->name, field, e);
        if (rc == LR_OK)
            rc = set_line(g, &en->l[0], c->line_a, en->name, ".a", field, e);
        if (rc == LR_OK)
            rc = set_line(g, &en->l[1], c->line_b, en->name, ".b", field, e);
        if (rc != LR_OK)
            return rc;
        if (strcmp(en->l[0].spec, en->l[1].spec) == 0)
            return lr_err_set(e, LR_EINVAL, "%s: %s.line_a and line_b are both '%s'", pf, field,
                              en->l[0].spec);
        int s = (int)lr_opt_or_default(&lr_gpio_encoder_opts[LR_GPIO_ENC_STEPS_PER_DETENT],
                                       c->steps_per_detent);
        if (s != 1 && s != 2 && s != 4)
            return lr_err_set(e, LR_EINVAL, "%s: %s.steps_per_detent %d is not 1, 2 or 4", pf,
                              field, c->steps_per_detent);
        en->steps = s;
        en->reverse = c->reverse;
    }
    for (int i = 0; i < desc->n_buttons; i++) {
        const lr_gpio_button *c = &desc->buttons[i];
        button *bt = &g->btn[i];
        g->n_btn = i + 1;
        snprintf(field, sizeof field, "buttons[%d]", i);
        int rc = set_name(g, bt->name, c->name, field, e);
        if (rc == LR_OK)
            rc = set_line(g, &bt->l, c->line, bt->name, "", field, e);
        if (rc != LR_OK)
            return rc;
        const lr_opt *db = &lr_gpio_button_opts[LR_GPIO_BTN_DEBOUNCE_MS];
        if (!lr_opt_in_range(db, c->debounce_ms))
            return lr_err_set(e, LR_EINVAL, "%s: %s.debounce_ms %d is not %ld..%ld", pf, field,
                              c->debounce_ms, db->lo, db->hi);
        bt->window_ns = (int64_t)lr_opt_or_default(db, c->debounce_ms) * 1000000;
        bt->active_high = c->active_high;
    }
    /* One line serves one control. */
    for (int i = 0; i < 2 * g->n_enc + g->n_btn; i++)
        for (int j = i + 1; j < 2 * g->n_enc + g->n_btn; j++) {
            const gline *a = i < 2 * g->n_enc ? &g->enc[i / 2].l[i % 2] : &g->btn[i - 2 * g->n_enc].l;
            const gline *b = j < 2 * g->n_enc ? &g->enc[j / 2].l[j % 2] : &g->btn[j - 2 * g->n_enc].l;
            if (strcmp(a->spec, b->spec) == 0)
                return lr_err_set(e, LR_EINVAL, "%s: line '%s' used by both %s and %s", pf,
                                  a->spec, a->what, b->what);
        }
    return LR_OK;
}

int lr_gpio_create(const lr_gpio_desc *desc, lr_gpio **out, lr_err *e)
{
    *out = NULL;
    lr_gpio *g = calloc(1, sizeof *g);
    if (!g)
        return lr_err_set(e, LR_ENOMEM, "gpio: out of memory");
    int rc = lr_dev_init(&g->base, &GPIO_OPS, &desc->dev, e);
    if (rc == LR_OK)
        rc = configure(g, desc, e);
    if (rc == LR_OK)
        rc = lr_dev_start(&g->base, desc->dev.required, lr_now_ns(), e);
    if (rc != LR_OK) {
        gpio_close(&g->base);
        gpio_destroy(&g->base);
        return rc;
    }
    *out = g;
    return LR_OK;
}

void lr_gpio_destroy(lr_gpio *g)
{
    if (g)
        lr_dev_destroy(&g->base);
}

lr_dev *lr_gpio_dev(lr_gpio *g) { return &g->base; }

unsigned lr_gpio_encoder_invalid(const lr_gpio *g, int i)
{
    if (i < 0 || i >= g->n_enc)
        return 0;
    return g->enc[i].invalid_before + g->enc[i].q.invalid;
}
