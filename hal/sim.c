#include "hal/sim.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hal/dev_impl.h"
#include "render/base/file.h"

const lr_opt lr_sim_opts[] = {
    [LR_SIM_OPT_SCRIPT] = {"script", LR_OPT_STRING, .help = "script file (hal/README.md)"},
    [LR_SIM_OPT_TEXT] = {"text", LR_OPT_STRING, .help = "the script itself"},
    [LR_SIM_OPT_LOOP] = {"loop", LR_OPT_BOOL, .dflt = 0, .help = "start over after the end"},
    LR_OPT_END,
};

struct lr_sim_script {
    lr_event *ev;
    int n, cap;
    int64_t end_ns; /* -1: no `end` line */
};

static bool valid_name(const char *s, size_t n)
{
    if (n == 0 || n >= LR_EVENT_NAME_MAX)
        return false;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        if (!isalnum(c) && c != '_' && c != '.' && c != '-')
            return false;
    }
    return true;
}

static bool parse_number(const char *tok, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(tok, &end);
    if (end == tok || *end || errno == ERANGE || !isfinite(v))
        return false;
    *out = v;
    return true;
}

/* Splits line (modified in place) into at most max whitespace-separated tokens, stopping at
 * '#'. Returns the count, or max + 1 when there are more. */
static int tokenize(char *line, char **tok, int max)
{
    char *hash = strchr(line, '#');
    if (hash)
        *hash = '\0';
    int n = 0;
    char *p = line;
    for (;;) {
        while (*p && isspace((unsigned char)*p))
            p++;
        if (!*p)
            return n;
        if (n == max)
            return max + 1;
        tok[n++] = p;
        while (*p && !isspace((unsigned char)*p))
            p++;
        if (*p)
            *p++ = '\0';
    }
}

static int push(lr_sim_script *s, const lr_event *ev, lr_err *e)
{
    if (s->n == s->cap) {
        int cap = s->cap ? 2 * s->cap : 64;
        lr_event *nv = realloc(s->ev, (size_t)cap * sizeof *nv);
        if (!nv)
            return lr_err_set(e, LR_ENOMEM, "sim: out of memory at %d events", s->n);
        s->ev = nv;
        s->cap = cap;
    }
    s->ev[s->n++] = *ev;
    return LR_OK;
}

static int parse_line(lr_sim_script *s, char *line, const char *fn, int ln, int64_t *last_t,
                      lr_err *e)
{
    char *tok[5];
    int nt = tokenize(line, tok, 4);
    if (nt == 0)
        return LR_OK;
    if (nt > 4)
        return lr_err_set(e, LR_EPARSE, "%s:%d: too many fields (time control kind [value])", fn,
                          ln);
    if (s->end_ns >= 0)
        return lr_err_set(e, LR_EPARSE, "%s:%d: event after the 'end' line", fn, ln);
    double t;
    if (!parse_number(tok[0], &t) || t < 0 || t > 1e7)
        return lr_err_set(e, LR_EPARSE, "%s:%d: time '%s' is not a number of seconds >= 0", fn,
                          ln, tok[0]);
    int64_t t_ns = llround(t * 1e9);
    if (t_ns < *last_t)
        return lr_err_set(e, LR_EPARSE, "%s:%d: time %s goes back (previous event at %.9g s)", fn,
                          ln, tok[0], (double)*last_t / 1e9);
    *last_t = t_ns;
    if (nt >= 2 && strcmp(tok[1], "end") == 0) {
        if (nt > 2)
            return lr_err_set(e, LR_EPARSE, "%s:%d: 'end' takes no value", fn, ln);
        s->end_ns = t_ns;
        return LR_OK;
    }
    if (nt < 3)
        return lr_err_set(e, LR_EPARSE, "%s:%d: expected 'time control kind [value]'", fn, ln);

    const char *source = "", *control = tok[1];
    char *slash = strchr(tok[1], '/');
    if (slash) {
        *slash = '\0';
        source = tok[1];
        control = slash + 1;
        if (!valid_name(source, strlen(source)))
            return lr_err_set(e, LR_EPARSE,
                              "%s:%d: source '%s' is not 1..%d characters of [A-Za-z0-9_.-]", fn,
                              ln, source, LR_EVENT_NAME_MAX - 1);
    }
    if (!valid_name(control, strlen(control)))
        return lr_err_set(e, LR_EPARSE,
                          "%s:%d: control '%s' is not 1..%d characters of [A-Za-z0-9_.-]", fn, ln,
                          control, LR_EVENT_NAME_MAX - 1);
    lr_event_kind kind;
    if (lr_event_kind_parse(tok[2], &kind) != LR_OK)
        return lr_err_set(e, LR_EPARSE,
                          "%s:%d: unknown kind '%s' (expected delta, absolute, press or release)",
                          fn, ln, tok[2]);
    double value = kind == LR_EV_PRESS ? 1 : 0;
    if (nt == 4) {
        if (!parse_number(tok[3], &value))
            return lr_err_set(e, LR_EPARSE, "%s:%d: value '%s' is not a finite number", fn, ln,
                              tok[3]);
    } else if (kind == LR_EV_DELTA || kind == LR_EV_ABSOLUTE) {
        return lr_err_set(e, LR_EPARSE, "%s:%d: %s needs a value", fn, ln,
                          lr_event_kind_name(kind));
    }
    lr_event ev;
    lr_event_set(&ev, source, control, kind, value, t_ns);
    return push(s, &ev, e);
}

int lr_sim_script_parse(const char *text, const char *filename, lr_sim_script **out, lr_err *e)
{
    *out = NULL;
    const char *fn = filename ? filename : "<script>";
    lr_sim_script *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", fn);
    s->end_ns = -1;
    int64_t last_t = 0;
    int ln = 0, rc = LR_OK;
    const char *p = text;
    char line[1024];
    while (*p && rc == LR_OK) {
        ln++;
        size_t n = strcspn(p, "\n");
        if (n >= sizeof line) {
            rc = lr_err_set(e, LR_EPARSE, "%s:%d: line longer than %zu characters", fn, ln,
                            sizeof line - 1);
            break;
        }
        memcpy(line, p, n);
        line[n] = '\0';
        if (n && line[n - 1] == '\r')
            line[n - 1] = '\0';
        rc = parse_line(s, line, fn, ln, &last_t, e);
        p += n;
        if (*p == '\n')
            p++;
    }
    if (rc != LR_OK) {
        lr_sim_script_destroy(s);
        return rc;
    }
    *out = s;
    return LR_OK;
}

int lr_sim_script_load(const char *path, lr_sim_script **out, lr_err *e)
{
    *out = NULL;
    /* A regular file only: a FIFO would block the open for ever, a device read for ever. */
    FILE *f;
    int rc = lr_file_fopen_regular(path, &f, e);
    if (rc)
        return rc;
    size_t cap = 4096, len = 0;
    char *buf = malloc(cap);
    rc = LR_OK;
    while (buf) {
        if (len + 1 >= cap) {
            if (cap >= (16u << 20)) {
                rc = lr_err_set(e, LR_EPARSE, "%s: larger than 16 MiB", path);
                break;
            }
            char *nb = realloc(buf, cap * 2);
            if (!nb)
                break;
            buf = nb;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - 1 - len, f);
        len += got;
        if (got == 0)
            break;
    }
    if (!buf)
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
    else if (rc == LR_OK && ferror(f))
        rc = lr_err_set(e, LR_EIO, "%s: read error: %s", path, strerror(errno));
    fclose(f);
    if (rc == LR_OK) {
        buf[len] = '\0';
        if (strlen(buf) != len)
            rc = lr_err_set(e, LR_EPARSE, "%s: contains a NUL byte (not a text file)", path);
        else
            rc = lr_sim_script_parse(buf, path, out, e);
    }
    free(buf);
    return rc;
}

void lr_sim_script_destroy(lr_sim_script *s)
{
    if (!s)
        return;
    free(s->ev);
    free(s);
}

int lr_sim_script_count(const lr_sim_script *s) { return s->n; }

bool lr_sim_script_get(const lr_sim_script *s, int i, lr_event *out)
{
    if (i < 0 || i >= s->n)
        return false;
    *out = s->ev[i];
    return true;
}

int64_t lr_sim_script_length_ns(const lr_sim_script *s)
{
    if (s->end_ns >= 0)
        return s->end_ns;
    return s->n ? s->ev[s->n - 1].t_ns : 0;
}

/* ---- playback device ---- */

struct lr_sim {
    lr_dev base; /* first: lr_dev * <-> lr_sim * */
    lr_sim_script *script;
    int64_t start_ns;  /* time of script time 0 in the current loop */
    int next;          /* index of the next event to play */
    bool loop;
    uint64_t played;
};

static int sim_open(lr_dev *d, int64_t now_ns, lr_err *e)
{
    (void)d;
    (void)now_ns;
    (void)e;
    return LR_OK; /* nothing to open: the script was read at create */
}

static void sim_close(lr_dev *d) { (void)d; }

static int sim_pollfds(lr_dev *d, struct pollfd *fds, int max)
{
    (void)d;
    (void)fds;
    (void)max;
    return 0;
}

static int64_t sim_next_deadline(lr_dev *d)
{
    lr_sim *s = (lr_sim *)d;
    if (s->next >= s->script->n)
        return LR_NO_DEADLINE;
    return s->start_ns + s->script->ev[s->next].t_ns;
}

static void sim_dispatch(lr_dev *d, int64_t now_ns)
{
    lr_sim *s = (lr_sim *)d;
    const lr_sim_script *sc = s->script;
    int64_t period = lr_sim_script_length_ns(sc);
    /* Bounded so that a loop resumed after a long stall (suspend) cannot spin here. */
    for (int budget = 100000; budget > 0; budget--) {
        if (s->next >= sc->n) {
            if (s->loop && period > 0 && sc->n > 0) {
                s->start_ns += period;
                s->next = 0;
                continue;
            }
            lr_dev_done(d, "script finished (%llu events)", (unsigned long long)s->played);
            return;
        }
        const lr_event *ev = &sc->ev[s->next];
        int64_t t = s->start_ns + ev->t_ns;
        if (t > now_ns)
            return;
        lr_dev_emit(d, ev->source, ev->control, ev->kind, ev->value, t);
        s->next++;
        s->played++;
    }
}

static void sim_destroy(lr_dev *d)
{
    lr_sim *s = (lr_sim *)d;
    lr_sim_script_destroy(s->script);
    free(s);
}

static const lr_dev_ops SIM_OPS = {
    .kind = "sim",
    .open = sim_open,
    .close = sim_close,
    .pollfds = sim_pollfds,
    .dispatch = sim_dispatch,
    .next_deadline = sim_next_deadline,
    .destroy = sim_destroy,
};

int lr_sim_create(const lr_sim_desc *desc, lr_sim **out, lr_err *e)
{
    *out = NULL;
    lr_sim *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "sim: out of memory");
    int rc = lr_dev_init(&s->base, &SIM_OPS, &desc->dev, e);
    if (rc == LR_OK) {
        if (desc->text)
            rc = lr_sim_script_parse(desc->text, desc->path, &s->script, e);
        else if (desc->path)
            rc = lr_sim_script_load(desc->path, &s->script, e);
        else
            rc = lr_err_set(e, LR_EINVAL, "%s: neither path nor text given", s->base.prefix);
    }
    if (rc != LR_OK) {
        lr_sim_script_destroy(s->script);
        free(s);
        return rc;
    }
    snprintf(s->base.ident, sizeof s->base.ident, "%s (%d events%s)",
             desc->path ? desc->path : "script", s->script->n, desc->loop ? ", looping" : "");
    s->loop = desc->loop;
    s->start_ns = desc->start_ns ? desc->start_ns : lr_now_ns();
    lr_dev_start(&s->base, false, s->start_ns, e);
    *out = s;
    return LR_OK;
}

void lr_sim_destroy(lr_sim *s)
{
    if (s)
        lr_dev_destroy(&s->base);
}

lr_dev *lr_sim_dev(lr_sim *s) { return &s->base; }
uint64_t lr_sim_played(const lr_sim *s) { return s->played; }
