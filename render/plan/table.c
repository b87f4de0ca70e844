/* lamprig planner — the measured speed/error table (CSV from the bench sweep).
 *
 * Header-driven: the first non-comment line names the columns, each row is looked up by
 * name, so a bench that adds or reorders columns does not break the planner. Cells are plain
 * (the bench writes no quotes or commas inside a field); a quoted cell is an error rather
 * than something half-understood. */
#include "render/plan/plan.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render/base/file.h"
#include "render/base/paths.h"

struct lr_plan_table {
    char name[256];
    lr_plan_row *rows;
    int n, cap;
};

enum col {
    C_SCENE, C_MODEL, C_PARAMS, C_FRAME_MS, C_RMSE, C_RMSE_OBJ, C_RMSE_REC, C_K, C_N, C_NVPL,
    C_MAP, C_GBUF, C_FRAMES, C_VPL, C_MS_G, C_MS_R, C_MS_V, C_MS_C, C_W, C_H, C_BIAS_O, C_BIAS_R,
    C_NOISE_O, C_NOISE_R, C_SS, C_LPV, C_MS_LPV, C_MAL, C_MAL_FLOOR, C_BAND, C_COUNT
};

static const struct {
    const char *name;
    bool required;
    bool inf_ok; /* "inf" is a value: band_excess of a row that leaves a region dark */
    /* "<FLOOR" is a value: a debiased error under the reference's noise (the bench writes the
     * floor, lr_eval_row's floor_*): the field gets the floor, lr_plan_row.under_floor this
     * bit. */
    unsigned floor_bit;
} cols[C_COUNT] = {
    [C_SCENE] = {"scene", true},          [C_MODEL] = {"model", true},
    [C_PARAMS] = {"params", false},       [C_FRAME_MS] = {"frame_ms", true},
    [C_RMSE] = {"rel_rmse", true, false, LR_PLAN_UNDER_REL_RMSE},
    [C_RMSE_OBJ] = {"rel_rmse_object", false, false, LR_PLAN_UNDER_REL_RMSE_OBJECT},
    [C_RMSE_REC] = {"rel_rmse_receivers", false, false, LR_PLAN_UNDER_REL_RMSE_RECEIVERS},
    [C_K] = {"K", true},                  [C_N] = {"N", true},
    [C_NVPL] = {"N_vpl", true},           [C_MAP] = {"map_size", true},
    [C_GBUF] = {"gbuffer_size", true},    [C_FRAMES] = {"frames", true},
    [C_VPL] = {"vpl", true},              [C_MS_G] = {"ms_gbuffer", false},
    [C_MS_R] = {"ms_radiosity", false},   [C_MS_V] = {"ms_vpl", false},
    [C_MS_C] = {"ms_compose", false},     [C_W] = {"width", false},
    [C_H] = {"height", false},
    [C_BIAS_O] = {"bias_object", false, false, LR_PLAN_UNDER_BIAS_OBJECT},
    [C_BIAS_R] = {"bias_receivers", false, false, LR_PLAN_UNDER_BIAS_RECEIVERS},
    [C_NOISE_O] = {"noise_object", false},
    [C_NOISE_R] = {"noise_receivers", false}, [C_SS] = {"supersample", false},
    [C_LPV] = {"lpv", false},             [C_MS_LPV] = {"ms_lpv", false},
    [C_MAL] = {"median_ln_object", false}, [C_MAL_FLOOR] = {"median_ln_floor", false},
    [C_BAND] = {"band_excess", false, true},
};

#define MAX_FIELDS 64

/* Splits line (modified in place) at commas; trims spaces and a trailing '\r'. */
static int split(char *line, char **f, int max)
{
    int n = 0;
    char *p = line;
    for (;;) {
        char *c = strchr(p, ',');
        if (c)
            *c = '\0';
        while (*p == ' ' || *p == '\t')
            p++;
        char *end = p + strlen(p);
        while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r'))
            *--end = '\0';
        if (n < max)
            f[n] = p;
        n++;
        if (!c)
            break;
        p = c + 1;
    }
    return n;
}

static int cell_err(const char *name, int line, const char *col, lr_err *e, const char *what,
                    const char *text)
{
    return lr_err_set(e, LR_EPARSE, "%s:%d: column '%s': %s, got '%.40s'", name, line, col, what,
                      text);
}

static int cell_number(const char *name, int line, const char *col, const char *text,
                       bool required, double *out, lr_err *e)
{
    /* An optional measurement the bench did not take (ms_vpl of a row without VPLs) is
     * written "nan" by the bench's CSV writer, or left empty. */
    if (!*text || (!required && !strcmp(text, "nan"))) {
        if (required)
            return lr_err_set(e, LR_EPARSE, "%s:%d: column '%s': empty", name, line, col);
        *out = NAN;
        return LR_OK;
    }
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    /* strtod reads "nan", "inf" and hex: a measured value is a finite decimal. */
    bool decimal = strspn(text, "0123456789+-.eE") == strlen(text);
    if (*end || errno || !decimal || !isfinite(v))
        return cell_err(name, line, col, e, "expected a finite number", text);
    if (v < 0)
        return cell_err(name, line, col, e, "must be >= 0", text);
    *out = v;
    return LR_OK;
}

static int cell_int(const char *name, int line, const char *col, const char *text, bool required,
                    int min, int *out, lr_err *e)
{
    double v;
    int rc = cell_number(name, line, col, text, required, &v, e);
    if (rc)
        return rc;
    if (isnan(v)) {
        *out = 0;
        return LR_OK;
    }
    if (v != floor(v) || v < min || v > 1e7)
        return lr_err_set(e, LR_EPARSE, "%s:%d: column '%s': expected a whole number >= %d, got '%.40s'",
                          name, line, col, min, text);
    *out = (int)v;
    return LR_OK;
}

static int cell_text(const char *name, int line, const char *col, const char *text, char *buf,
                     size_t cap, bool required, lr_err *e)
{
    if (required && !*text)
        return lr_err_set(e, LR_EPARSE, "%s:%d: column '%s': empty", name, line, col);
    if (strchr(text, '"'))
        return cell_err(name, line, col, e, "quoted cells are not supported", text);
    if (strlen(text) >= cap)
        return cell_err(name, line, col, e, "too long", text);
    strcpy(buf, text);
    return LR_OK;
}

static int parse_row(const char *name, int line, char **f, const int *at, lr_plan_row *r,
                     lr_err *e)
{
    memset(r, 0, sizeof *r);
    r->line = line;
    r->ms_change = NAN; /* from models.csv, merged after the parse */
#define TXT(c, field, req) \
    if ((rc = cell_text(name, line, cols[c].name, at[c] >= 0 ? f[at[c]] : "", r->field, \
                        sizeof r->field, req, e))) \
        return rc
#define NUM(c, field) \
    if (cols[c].inf_ok && at[c] >= 0 && !strcmp(f[at[c]], "inf")) \
        r->field = INFINITY; \
    else if (cols[c].floor_bit && at[c] >= 0 && f[at[c]][0] == '<') { \
        if (cell_number(name, line, cols[c].name, f[at[c]] + 1, true, &r->field, e)) \
            return cell_err(name, line, cols[c].name, e, "expected '<' and a finite number " \
                            ">= 0 (an error under its noise floor)", f[at[c]]); \
        r->under_floor |= cols[c].floor_bit; \
    } else if ((rc = cell_number(name, line, cols[c].name, at[c] >= 0 ? f[at[c]] : "", \
                                 cols[c].required, &r->field, e))) \
        return rc
#define INT(c, field, min) \
    if ((rc = cell_int(name, line, cols[c].name, at[c] >= 0 ? f[at[c]] : "", cols[c].required, \
                       min, &r->field, e))) \
        return rc
    int rc;
    TXT(C_SCENE, scene, true);
    TXT(C_MODEL, model, true);
    TXT(C_PARAMS, params, false);
    enum lr_sss_model m;
    if (!lr_sss_model_parse(r->model, &m))
        return cell_err(name, line, "model", e, "expected a diffusion model name "
                        "(directional_dipole, standard_dipole, multipole, ...)", r->model);
    NUM(C_FRAME_MS, frame_ms);
    NUM(C_RMSE, rel_rmse);
    NUM(C_RMSE_OBJ, rel_rmse_object);
    NUM(C_RMSE_REC, rel_rmse_receivers);
    INT(C_K, K, 1);
    INT(C_N, N, 1);
    INT(C_NVPL, N_vpl, 0);
    INT(C_MAP, map_size, 1);
    INT(C_GBUF, gbuffer_size, 1);
    INT(C_FRAMES, frames, 1);
    NUM(C_MS_G, ms_gbuffer);
    NUM(C_MS_R, ms_radiosity);
    NUM(C_MS_V, ms_vpl);
    NUM(C_MS_C, ms_compose);
    INT(C_W, width, 0);
    INT(C_H, height, 0);
    NUM(C_BIAS_O, bias_object);
    NUM(C_BIAS_R, bias_receivers);
    NUM(C_NOISE_O, noise_object);
    NUM(C_NOISE_R, noise_receivers);
    INT(C_SS, supersample, 0);
    INT(C_LPV, lpv, 0);
    NUM(C_MS_LPV, ms_lpv);
    NUM(C_MAL, median_ln_object);
    NUM(C_MAL_FLOOR, median_ln_floor);
    NUM(C_BAND, band_excess); /* "inf": a region the setting leaves dark */
#undef TXT
#undef NUM
#undef INT
    const char *v = f[at[C_VPL]];
    if (!strcmp(v, "on"))
        r->vpl = true;
    else if (strcmp(v, "off"))
        return cell_err(name, line, "vpl", e, "expected on or off", v);
    if (r->frame_ms <= 0)
        return cell_err(name, line, "frame_ms", e, "must be > 0", f[at[C_FRAME_MS]]);
    return LR_OK;
}

int lr_plan_table_parse(const char *text, size_t len, const char *name, lr_plan_table **out,
                        lr_err *e)
{
    *out = NULL;
    if (!name)
        name = "table";
    lr_plan_table *t = calloc(1, sizeof *t);
    char *buf = malloc(len + 1);
    if (!t || !buf) {
        free(t);
        free(buf);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    }
    snprintf(t->name, sizeof t->name, "%s", name);
    memcpy(buf, text, len);
    buf[len] = '\0';
    int at[C_COUNT], nheader = 0, rc = LR_OK, line = 0;
    char *f[MAX_FIELDS], empty[1] = {0};
    char *p = buf;
    while (p && !rc) {
        char *nl = strchr(p, '\n');
        if (nl)
            *nl = '\0';
        line++;
        char *s = p;
        p = nl ? nl + 1 : NULL;
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (!*s || *s == '#')
            continue;
        int n = split(s, f, MAX_FIELDS);
        if (n > MAX_FIELDS) {
            rc = lr_err_set(e, LR_EPARSE, "%s:%d: more than %d columns", name, line, MAX_FIELDS);
            break;
        }
        if (!nheader) {
            for (int c = 0; c < C_COUNT; c++) {
                at[c] = -1;
                for (int i = 0; i < n; i++)
                    if (!strcmp(f[i], cols[c].name)) {
                        if (at[c] >= 0) {
                            rc = lr_err_set(e, LR_EPARSE, "%s:%d: column '%s': given twice", name,
                                            line, cols[c].name);
                            break;
                        }
                        at[c] = i;
                    }
                if (!rc && at[c] < 0 && cols[c].required)
                    rc = lr_err_set(e, LR_EPARSE, "%s:%d: column '%s': missing from the header",
                                    name, line, cols[c].name);
                if (rc)
                    break;
            }
            nheader = n;
            continue;
        }
        /* A row may stop before optional trailing columns (rows written before a column was
         * appended to the header, e.g. lpv and ms_lpv): they read empty. */
        bool short_ok = n < nheader;
        for (int c = 0; c < C_COUNT && short_ok; c++)
            short_ok = !(at[c] >= n && cols[c].required);
        if (n != nheader && !short_ok) {
            rc = lr_err_set(e, LR_EPARSE, "%s:%d: %d cells, the header has %d", name, line, n,
                            nheader);
            break;
        }
        for (int i = n; i < nheader; i++)
            f[i] = empty;
        if (t->n == t->cap) {
            int cap = t->cap ? 2 * t->cap : 32;
            lr_plan_row *r = realloc(t->rows, (size_t)cap * sizeof *r);
            if (!r) {
                rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
                break;
            }
            t->rows = r;
            t->cap = cap;
        }
        if (!(rc = parse_row(name, line, f, at, &t->rows[t->n], e)))
            t->n++;
    }
    free(buf);
    if (!rc && !nheader)
        rc = lr_err_set(e, LR_EPARSE, "%s:1: no header line", name);
    if (!rc && !t->n)
        rc = lr_err_set(e, LR_EPARSE, "%s:%d: no rows", name, line);
    if (rc) {
        lr_plan_table_destroy(t);
        return rc;
    }
    *out = t;
    return LR_OK;
}

/* Rows still without a change cost, of scene and model: ms. */
static int set_change(lr_plan_table *t, const char *scene, const char *model, double ms)
{
    int n = 0;
    for (int i = 0; i < t->n; i++)
        if (isnan(t->rows[i].ms_change) && !strcmp(t->rows[i].scene, scene) &&
            !strcmp(t->rows[i].model, model)) {
            t->rows[i].ms_change = ms;
            n++;
        }
    return n;
}

int lr_plan_table_merge_changes(lr_plan_table *t, const char *text, size_t len, const char *name,
                                lr_err *e)
{
    if (!name)
        name = "models table";
    char *buf = malloc(len + 1);
    if (!buf)
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    memcpy(buf, text, len);
    buf[len] = '\0';
    static const char *const need[3] = {"scene", "model", "material_ms"};
    int at[3] = {-1, -1, -1}, nheader = 0, line = 0, rc = LR_OK;
    char *f[MAX_FIELDS];
    for (char *p = buf, *nl; p && !rc; p = nl ? nl + 1 : NULL) {
        if ((nl = strchr(p, '\n')))
            *nl = '\0';
        line++;
        p += strspn(p, " \t\r");
        if (!*p || *p == '#')
            continue;
        int n = split(p, f, MAX_FIELDS);
        if (n > MAX_FIELDS) {
            rc = lr_err_set(e, LR_EPARSE, "%s:%d: more than %d columns", name, line, MAX_FIELDS);
        } else if (!nheader) {
            for (int c = 0; c < 3; c++) {
                for (int i = 0; i < n; i++)
                    if (!strcmp(f[i], need[c]))
                        at[c] = i;
                if (at[c] < 0 && !rc)
                    rc = lr_err_set(e, LR_EPARSE, "%s:%d: column '%s': missing from the header",
                                    name, line, need[c]);
            }
            nheader = n;
        } else if (n != nheader) {
            rc = lr_err_set(e, LR_EPARSE, "%s:%d: %d cells, the header has %d", name, line, n,
                            nheader);
        } else {
            char scene[LR_PLAN_TEXT_MAX], model[LR_PLAN_TEXT_MAX];
            double ms;
            enum lr_sss_model m;
            if (!(rc = cell_text(name, line, "scene", f[at[0]], scene, sizeof scene, true, e)) &&
                !(rc = cell_text(name, line, "model", f[at[1]], model, sizeof model, true, e)) &&
                !(rc = cell_number(name, line, "material_ms", f[at[2]], true, &ms, e)) &&
                !lr_sss_model_parse(model, &m))
                rc = cell_err(name, line, "model", e, "expected a diffusion model name", model);
            if (!rc)
                set_change(t, scene, model, ms);
        }
    }
    free(buf);
    return rc;
}

/* Merges the models table at path when it exists (a missing one is not an error: the rows
 * keep no change cost). */
static int merge_changes_file(lr_plan_table *t, const char *path, lr_err *e)
{
    if (access(path, R_OK) != 0)
        return LR_OK;
    char *data;
    size_t len;
    int rc = lr_file_read(path, LR_FILE_MAX_TEXT, &data, &len, e);
    if (rc)
        return rc;
    rc = lr_plan_table_merge_changes(t, data, len, path, e);
    free(data);
    return rc;
}

int lr_plan_table_load(const char *path, lr_plan_table **out, lr_err *e)
{
    char *data;
    size_t len;
    *out = NULL;
    int rc = lr_file_read(path, LR_FILE_MAX_TEXT, &data, &len, e);
    if (rc)
        return rc;
    rc = lr_plan_table_parse(data, len, path, out, e);
    free(data);
    if (rc)
        return rc;
    /* The change costs: the models table beside this one (a bench run's build/bench, or the
     * committed configs/bench), then the committed one for the pairs it lacks. */
    char sib[1024];
    const char *slash = strrchr(path, '/');
    int w = slash ? snprintf(sib, sizeof sib, "%.*s/models.csv", (int)(slash - path), path)
                  : snprintf(sib, sizeof sib, "models.csv");
    if (w > 0 && (size_t)w < sizeof sib)
        rc = merge_changes_file(*out, sib, e);
    w = snprintf(sib, sizeof sib, "%s/bench/models.csv", lr_configs_dir());
    if (!rc && w > 0 && (size_t)w < sizeof sib)
        rc = merge_changes_file(*out, sib, e);
    if (rc) {
        lr_plan_table_destroy(*out);
        *out = NULL;
    }
    return rc;
}

void lr_plan_table_destroy(lr_plan_table *t)
{
    if (!t)
        return;
    free(t->rows);
    free(t);
}

int lr_plan_table_count(const lr_plan_table *t) { return t->n; }
const lr_plan_row *lr_plan_table_row(const lr_plan_table *t, int i) { return &t->rows[i]; }
const char *lr_plan_table_name(const lr_plan_table *t) { return t->name; }

bool lr_plan_table_has_scene(const lr_plan_table *t, const char *scene)
{
    for (int i = 0; i < t->n; i++)
        if (!strcmp(t->rows[i].scene, scene))
            return true;
    return false;
}

int lr_plan_default_table(char *buf, size_t cap, const char **why, lr_err *e)
{
    /* The committed front sits in the configs directory; a bench run's results in the build
     * directory beside it (the source tree's layout). */
    const char *configs = lr_configs_dir();
    char root[1024], results[1200], front[1200];
    snprintf(root, sizeof root, "%s", configs);
    char *slash = strrchr(root, '/');
    if (slash && slash != root)
        *slash = '\0';
    else
        snprintf(root, sizeof root, "%s", slash ? "/" : ".");
    if (lr_path_join(results, sizeof results, root, "build/bench", "results.csv") ||
        lr_path_join(front, sizeof front, configs, "bench", "front.csv"))
        return lr_err_set(e, LR_EINVAL, "configs path too long");
    struct stat sr, sf;
    bool have_r = stat(results, &sr) == 0, have_f = stat(front, &sf) == 0;
    const char *pick = NULL;
    if (have_r && (!have_f || sr.st_mtime >= sf.st_mtime)) {
        pick = results;
        *why = "newest bench run";
    } else if (have_f) {
        pick = front;
        *why = "committed front";
    } else {
        return lr_err_set(e, LR_EIO, "no measured table: neither %s nor %s exists (run `make bench`)",
                          results, front);
    }
    if (strlen(pick) >= cap)
        return lr_err_set(e, LR_EINVAL, "%s: path too long", pick);
    strcpy(buf, pick);
    return LR_OK;
}

/* E[error^2] = bias^2 + noise^2 (the bench's split; issue 6): the error a render at this
 * setting has on average. One measured image is a single draw of a heavy-tailed noise, and
 * on the candle a 1-frame image often scores below the converged model's bias by luck; a
 * plan built on that draw would pick 1-frame settings for the wrong reason. The budget must
 * hold on the objects and on the receivers, so the larger of the two. Rows without the split
 * (hand-made tables) use the measured rel_rmse. */
static double region_error(double bias, double noise)
{
    return isfinite(bias) && isfinite(noise) ? sqrt(bias * bias + noise * noise) : NAN;
}

/* A bias under the reference's noise reads its floor (an upper bound): *at_most says so for
 * the region whose error is returned. */
static double rmse_part(const lr_plan_row *r, bool *at_most)
{
    double o = region_error(r->bias_object, r->noise_object);
    double v = region_error(r->bias_receivers, r->noise_receivers);
    bool ob = r->under_floor & LR_PLAN_UNDER_BIAS_OBJECT,
         vb = r->under_floor & LR_PLAN_UNDER_BIAS_RECEIVERS;
    if (isnan(o) && isnan(v)) {
        *at_most = r->under_floor & LR_PLAN_UNDER_REL_RMSE;
        return r->rel_rmse;
    }
    if (isnan(v) || (!isnan(o) && o > v) || (!isnan(o) && o == v && !ob)) {
        *at_most = ob;
        return o;
    }
    *at_most = vb;
    return v;
}

lr_plan_error_parts lr_plan_row_error_parts(const lr_plan_row *r)
{
    lr_plan_error_parts p = {.median = NAN, .band = r->band_excess};
    p.rmse = rmse_part(r, &p.rmse_at_most);
    /* Two references differ by the floor where both are noisy (the candle's dim sides: 0.44);
     * only what the model adds to it is the model's. */
    if (isfinite(r->median_ln_object))
        p.median = fmax(r->median_ln_object -
                            (isfinite(r->median_ln_floor) ? r->median_ln_floor : 0.0), 0.0);
    return p;
}

double lr_plan_row_error(const lr_plan_row *r)
{
    lr_plan_error_parts p = lr_plan_row_error_parts(r);
    double e = p.rmse;
    if (p.median > e || isnan(e))
        e = p.median;
    if (p.band > e || isnan(e))
        e = p.band;
    return e;
}

bool lr_plan_row_dark(const lr_plan_row *r)
{
    /* NaN (no band column) is not dark: hand-made tables predict the RMSE part alone. */
    return r->band_excess > LR_PLAN_DARK_LN;
}
