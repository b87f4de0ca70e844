/* lamprig — heterogeneous material volumes for the diffusion grid (format in README.md).
 *
 *   # comment (anywhere; blank lines are ignored)
 *   lamprig-volume 1
 *   box X0 Y0 Z0 X1 Y1 Z1          mm, the object's frame; cells split it evenly
 *   dims NX NY NZ                  1..256 each
 *   region C sigma_a R G B sigma_s_prime R G B     C one printable character, >= 1 region
 *   data
 *   NZ slices (z ascending) of NY rows (y ascending) of NX region characters (x ascending)
 *
 * Errors: LR_EPARSE / LR_EINVAL "FILE:LINE: what is wrong".
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/file.h"
#include "render/diffusion/dgrid.h"
#include "render/optics/optics.h"

#define LR_DVOLUME_MAX_DIM 256
#define LR_DVOLUME_MAX_REGIONS 64

typedef struct region {
    char id;
    double sigma_a[3], sigma_s_prime[3];
} region;

struct lr_dvolume {
    lr_vec3 lo, hi;
    int n[3];
    int n_regions;
    region regions[LR_DVOLUME_MAX_REGIONS];
    unsigned char *cells; /* region index per cell, x fastest */
};

void lr_dvolume_destroy(lr_dvolume *v)
{
    if (!v)
        return;
    free(v->cells);
    free(v);
}

int lr_dvolume_region_count(const lr_dvolume *v) { return v->n_regions; }

/* Next non-blank, non-comment line; trailing whitespace (and \r) stripped. */
static char *next_line(char **cursor, int *lineno)
{
    while (**cursor) {
        char *line = *cursor;
        char *end = strchr(line, '\n');
        if (end) {
            *end = '\0';
            *cursor = end + 1;
        } else {
            *cursor = line + strlen(line);
        }
        (*lineno)++;
        size_t len = strlen(line);
        while (len && isspace((unsigned char)line[len - 1]))
            line[--len] = '\0';
        while (isspace((unsigned char)*line))
            line++;
        if (*line && *line != '#')
            return line;
    }
    return NULL;
}

static int parse_triple(char **s, double out[3], bool positive_sum_ok)
{
    for (int c = 0; c < 3; c++) {
        char *end;
        out[c] = strtod(*s, &end);
        if (end == *s || !isfinite(out[c]) || out[c] < 0.0)
            return -1;
        *s = end;
    }
    (void)positive_sum_ok;
    return 0;
}

int lr_dvolume_parse(const char *text, const char *name, lr_dvolume **out, lr_err *e)
{
    *out = NULL;
    if (!name)
        name = "volume";
    char *buf = strdup(text ? text : "");
    lr_dvolume *v = calloc(1, sizeof *v);
    if (!buf || !v) {
        free(buf), free(v);
        return lr_err_set(e, LR_ENOMEM, "%s: out of memory", name);
    }
    char *cur = buf, *line;
    int ln = 0, rc = LR_OK;
    bool have_box = false, have_dims = false;
#define FAIL(code, ...)                                                                      \
    do {                                                                                     \
        char msg_[256];                                                                      \
        snprintf(msg_, sizeof msg_, __VA_ARGS__);                                            \
        rc = lr_err_set(e, code, "%s:%d: %s", name, ln, msg_);                               \
        goto done;                                                                           \
    } while (0)
    line = next_line(&cur, &ln);
    if (!line || strcmp(line, "lamprig-volume 1") != 0)
        FAIL(LR_EPARSE, "expected the header 'lamprig-volume 1'");
    while ((line = next_line(&cur, &ln))) {
        if (strcmp(line, "data") == 0)
            break;
        if (strncmp(line, "box", 3) == 0 && isspace((unsigned char)line[3])) {
            double b[6];
            char *s = line + 3;
            for (int k = 0; k < 6; k++) {
                char *end;
                b[k] = strtod(s, &end);
                if (end == s || !isfinite(b[k]))
                    FAIL(LR_EPARSE, "field 'box': six finite numbers (mm) expected");
                s = end;
            }
            if (*s)
                FAIL(LR_EPARSE, "field 'box': trailing text '%s'", s);
            if (!(b[3] > b[0] && b[4] > b[1] && b[5] > b[2]))
                FAIL(LR_EINVAL, "field 'box': the upper corner must exceed the lower one");
            v->lo = lr_v3(b[0], b[1], b[2]);
            v->hi = lr_v3(b[3], b[4], b[5]);
            have_box = true;
        } else if (strncmp(line, "dims", 4) == 0 && isspace((unsigned char)line[4])) {
            char *s = line + 4;
            for (int k = 0; k < 3; k++) {
                char *end;
                long d = strtol(s, &end, 10);
                if (end == s || d < 1 || d > LR_DVOLUME_MAX_DIM)
                    FAIL(LR_EINVAL, "field 'dims': three integers in 1..%d expected",
                         LR_DVOLUME_MAX_DIM);
                v->n[k] = (int)d;
                s = end;
            }
            if (*s)
                FAIL(LR_EPARSE, "field 'dims': trailing text '%s'", s);
            have_dims = true;
        } else if (strncmp(line, "region", 6) == 0 && isspace((unsigned char)line[6])) {
            if (v->n_regions == LR_DVOLUME_MAX_REGIONS)
                FAIL(LR_EINVAL, "field 'region': at most %d regions", LR_DVOLUME_MAX_REGIONS);
            char *s = line + 6;
            while (isspace((unsigned char)*s))
                s++;
            if (!isgraph((unsigned char)*s) || !(s[1] == ' ' || s[1] == '\t'))
                FAIL(LR_EPARSE, "field 'region': one printable character names a region");
            region *r = &v->regions[v->n_regions];
            r->id = *s++;
            for (int k = 0; k < v->n_regions; k++)
                if (v->regions[k].id == r->id)
                    FAIL(LR_EINVAL, "field 'region': '%c' defined twice", r->id);
            while (isspace((unsigned char)*s))
                s++;
            if (strncmp(s, "sigma_a", 7) != 0 || parse_triple((s += 7, &s), r->sigma_a, true))
                FAIL(LR_EPARSE, "region '%c': 'sigma_a R G B' (mm^-1, >= 0) expected", r->id);
            while (isspace((unsigned char)*s))
                s++;
            if (strncmp(s, "sigma_s_prime", 13) != 0 ||
                parse_triple((s += 13, &s), r->sigma_s_prime, true))
                FAIL(LR_EPARSE, "region '%c': 'sigma_s_prime R G B' (mm^-1, >= 0) expected",
                     r->id);
            if (*s)
                FAIL(LR_EPARSE, "region '%c': trailing text '%s'", r->id, s);
            for (int c = 0; c < 3; c++)
                if (!(r->sigma_a[c] + r->sigma_s_prime[c] >= LR_SIGMA_T_PRIME_MIN))
                    FAIL(LR_EINVAL, "region '%c': band %d: sigma_a + sigma_s_prime must be > 0",
                         r->id, c);
            v->n_regions++;
        } else {
            FAIL(LR_EPARSE, "unknown line '%.40s' (box, dims, region or data expected)", line);
        }
    }
    if (!line)
        FAIL(LR_EPARSE, "missing 'data' line");
    if (!have_box || !have_dims || v->n_regions == 0)
        FAIL(LR_EPARSE, "'box', 'dims' and at least one 'region' must come before 'data'");
    size_t cells = (size_t)v->n[0] * (size_t)v->n[1] * (size_t)v->n[2];
    v->cells = malloc(cells);
    if (!v->cells)
        FAIL(LR_ENOMEM, "out of memory");
    for (int k = 0; k < v->n[2]; k++)
        for (int j = 0; j < v->n[1]; j++) {
            line = next_line(&cur, &ln);
            if (!line)
                FAIL(LR_EPARSE, "data ends at slice z %d row y %d (expected %d slices of %d rows)",
                     k, j, v->n[2], v->n[1]);
            if ((int)strlen(line) != v->n[0])
                FAIL(LR_EPARSE, "data row has %zu cells, dims says %d", strlen(line), v->n[0]);
            for (int i = 0; i < v->n[0]; i++) {
                int r = -1;
                for (int q = 0; q < v->n_regions; q++)
                    if (v->regions[q].id == line[i])
                        r = q;
                if (r < 0)
                    FAIL(LR_EINVAL, "column %d: '%c' is not a region", i + 1, line[i]);
                v->cells[((size_t)k * (size_t)v->n[1] + (size_t)j) * (size_t)v->n[0] + (size_t)i] =
                    (unsigned char)r;
            }
        }
    if ((line = next_line(&cur, &ln)))
        FAIL(LR_EPARSE, "text after the last slice");
#undef FAIL
done:
    free(buf);
    if (rc) {
        lr_dvolume_destroy(v);
        return rc;
    }
    *out = v;
    return LR_OK;
}

int lr_dvolume_load(const char *path, lr_dvolume **out, lr_err *e)
{
    *out = NULL;
    char *text;
    size_t len;
    int rc = lr_file_read(path, LR_FILE_MAX_DATA, &text, &len, e);
    if (rc)
        return rc;
    if (strlen(text) != len) {
        free(text);
        return lr_err_set(e, LR_EPARSE, "%s: contains a NUL byte", path);
    }
    rc = lr_dvolume_parse(text, path, out, e);
    free(text);
    return rc;
}

void lr_dvolume_at(const lr_dvolume *v, lr_vec3 p, double sigma_a[3], double sigma_s_prime[3])
{
    double f[3] = {(p.x - v->lo.x) / (v->hi.x - v->lo.x), (p.y - v->lo.y) / (v->hi.y - v->lo.y),
                   (p.z - v->lo.z) / (v->hi.z - v->lo.z)};
    int c[3];
    for (int a = 0; a < 3; a++) {
        double x = isfinite(f[a]) ? floor(f[a] * v->n[a]) : 0.0;
        c[a] = (int)fmax(0.0, fmin((double)(v->n[a] - 1), x));
    }
    const region *r =
        &v->regions[v->cells[((size_t)c[2] * (size_t)v->n[1] + (size_t)c[1]) * (size_t)v->n[0] +
                             (size_t)c[0]]];
    memcpy(sigma_a, r->sigma_a, 3 * sizeof *sigma_a);
    memcpy(sigma_s_prime, r->sigma_s_prime, 3 * sizeof *sigma_s_prime);
}
