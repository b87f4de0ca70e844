/* Wavefront OBJ reader: positions, normals and polygon faces. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/mesh/mesh_internal.h"
#include "render/mesh/mesh_io.h"

typedef struct dvec {
    double *v;
    size_t n, cap; /* in doubles */
} dvec;

typedef struct uvec {
    uint32_t *v;
    size_t n, cap;
} uvec;

typedef struct ivec {
    long long *v;
    size_t n, cap;
} ivec;

static int dpush(dvec *a, double x)
{
    if (a->n == a->cap) {
        size_t c = a->cap ? 2 * a->cap : 1024;
        double *nv = realloc(a->v, c * sizeof *nv);
        if (!nv)
            return -1;
        a->v = nv;
        a->cap = c;
    }
    a->v[a->n++] = x;
    return 0;
}

static int upush(uvec *a, uint32_t x)
{
    if (a->n == a->cap) {
        size_t c = a->cap ? 2 * a->cap : 1024;
        uint32_t *nv = realloc(a->v, c * sizeof *nv);
        if (!nv)
            return -1;
        a->v = nv;
        a->cap = c;
    }
    a->v[a->n++] = x;
    return 0;
}

static int ipush(ivec *a, long long x)
{
    if (a->n == a->cap) {
        size_t c = a->cap ? 2 * a->cap : 1024;
        long long *nv = realloc(a->v, c * sizeof *nv);
        if (!nv)
            return -1;
        a->v = nv;
        a->cap = c;
    }
    a->v[a->n++] = x;
    return 0;
}

/* Face corners as parsed: position and normal references (1-based after resolving negative
 * ones; 0 for "no normal"), and the line of each corner's face. */
typedef struct corners {
    ivec v, n;
    uvec line;
} corners;

typedef struct corner_key {
    long long key;
    size_t corner;
} corner_key;

static int cmp_corner(const void *pa, const void *pb)
{
    const corner_key *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->corner > b->corner) - (a->corner < b->corner);
}

/* Parses "i", "i/j", "i//k" or "i/j/k"; *vi and *ni receive the raw (possibly negative) indices,
 * *ni = 0 when absent. */
static bool parse_ref(const char *s, long long *vi, long long *ni)
{
    char *end;
    errno = 0;
    *vi = strtoll(s, &end, 10);
    *ni = 0;
    if (end == s || errno)
        return false;
    if (*end == '\0')
        return true;
    if (*end != '/')
        return false;
    s = end + 1;
    if (*s != '/') { /* texture index: parsed and ignored */
        if (*s == '\0')
            return false;
        strtoll(s, &end, 10);
        if (end == s)
            return false;
        s = end;
        if (*s == '\0')
            return true;
        if (*s != '/')
            return false;
    }
    s++;
    if (*s == '\0')
        return true; /* "i/j/" is tolerated as "i/j" */
    *ni = strtoll(s, &end, 10);
    /* 0 is no index in OBJ (they start at 1); absent is written as nothing, not 0. */
    return end != s && *end == '\0' && !errno && *ni != 0;
}

int lr_mesh_load_obj(const char *path, const lr_mesh_checks *checks, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    char *buf = NULL;
    size_t len = 0;
    int rc = lr_mesh_read_file(path, &buf, &len, e);
    if (rc)
        return rc;
    const lr_warn_sink *warn = checks ? &checks->warn : NULL;
    dvec pos = {0}, nrm = {0};
    corners cr = {0};
    uvec fstart = {0}; /* first corner of each face */
    double *outpos = NULL, *outnrm = NULL;
    uint32_t *idx = NULL, *origin = NULL, *corner_vertex = NULL;
    size_t ntri = 0;
    char warned[8][16];
    int nwarned = 0;
    int lineno = 0;
    char *p = buf;
    while (p < buf + len) {
        char *eol = memchr(p, '\n', (size_t)(buf + len - p));
        if (!eol)
            eol = buf + len;
        *eol = '\0';
        lineno++;
        char *hash = strchr(p, '#');
        if (hash)
            *hash = '\0';
        char *save = NULL;
        char *kw = strtok_r(p, " \t\r", &save);
        p = eol + 1;
        if (!kw)
            continue;
        if (strcmp(kw, "v") == 0 || strcmp(kw, "vn") == 0) {
            bool is_v = kw[1] == '\0';
            double x[3];
            int k = 0;
            char *tok;
            while ((tok = strtok_r(NULL, " \t\r", &save)) && k < 3) {
                char *end;
                x[k] = strtod(tok, &end);
                if (end == tok || *end != '\0') {
                    rc = lr_err_set(e, LR_EPARSE, "%s:%d: '%s' is not a number", path, lineno,
                                    tok);
                    goto done;
                }
                if (!isfinite(x[k])) {
                    rc = lr_err_set(e, LR_EINVAL, "%s:%d: %s: coordinate %c is %s", path,
                                    lineno, is_v ? "vertex" : "normal", "xyz"[k], tok);
                    goto done;
                }
                k++;
            }
            if (k < 3) {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: '%s' needs 3 numbers", path, lineno, kw);
                goto done;
            }
            /* Extra numbers (w, or the r g b of the vertex-colour extension) are ignored. */
            for (int i = 0; i < 3; i++)
                if (dpush(is_v ? &pos : &nrm, x[i])) {
                    rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
                    goto done;
                }
        } else if (strcmp(kw, "f") == 0) {
            size_t first = cr.v.n;
            char *tok;
            while ((tok = strtok_r(NULL, " \t\r", &save))) {
                long long vi, ni;
                if (!parse_ref(tok, &vi, &ni)) {
                    rc = lr_err_set(e, LR_EPARSE, "%s:%d: malformed face corner '%s'", path,
                                    lineno, tok);
                    goto done;
                }
                long long nv = (long long)(pos.n / 3), nn = (long long)(nrm.n / 3);
                if (vi == 0 || (vi < 0 && vi + nv < 0)) {
                    rc = lr_err_set(e, LR_EINVAL, "%s:%d: vertex index %lld out of range "
                                    "(%lld vertices so far)", path, lineno, vi, nv);
                    goto done;
                }
                if (ni < 0 && ni + nn < 0) {
                    rc = lr_err_set(e, LR_EINVAL, "%s:%d: normal index %lld out of range "
                                    "(%lld normals so far)", path, lineno, ni, nn);
                    goto done;
                }
                /* Negative indices count back from the latest: -1 is the last one. */
                if (vi < 0)
                    vi += nv + 1;
                if (ni < 0)
                    ni += nn + 1;
                if (ipush(&cr.v, vi) || ipush(&cr.n, ni) || upush(&cr.line, (uint32_t)lineno)) {
                    rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
                    goto done;
                }
            }
            if (cr.v.n - first < 3) {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: face with %zu corners (at least 3)", path,
                                lineno, cr.v.n - first);
                goto done;
            }
            if (upush(&fstart, (uint32_t)first)) {
                rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
                goto done;
            }
        } else if (strcmp(kw, "vt") == 0 || strcmp(kw, "o") == 0 || strcmp(kw, "g") == 0 ||
                   strcmp(kw, "s") == 0 || strcmp(kw, "usemtl") == 0 ||
                   strcmp(kw, "mtllib") == 0) {
            continue;
        } else {
            bool seen = false;
            for (int i = 0; i < nwarned; i++)
                seen = seen || strncmp(warned[i], kw, sizeof warned[i] - 1) == 0;
            if (!seen && nwarned < 8) {
                snprintf(warned[nwarned++], sizeof warned[0], "%s", kw);
                lr_warn(warn, "%s:%d: '%s' statements are ignored", path, lineno, kw);
            }
        }
    }
    size_t nv = pos.n / 3, nn = nrm.n / 3, nc = cr.v.n;
    if (fstart.n == 0) {
        rc = lr_err_set(e, LR_EPARSE, "%s: no faces", path);
        goto done;
    }
    /* Forward references are legal in OBJ: positive indices are checked once all is read. */
    bool all_normals = nn > 0, any_normal = false;
    for (size_t c = 0; c < nc; c++) {
        if (cr.v.v[c] > (long long)nv) {
            rc = lr_err_set(e, LR_EINVAL, "%s:%u: vertex index %lld out of range (%zu vertices)",
                            path, cr.line.v[c], cr.v.v[c], nv);
            goto done;
        }
        if (cr.n.v[c] > (long long)nn) {
            rc = lr_err_set(e, LR_EINVAL, "%s:%u: normal index %lld out of range (%zu normals)",
                            path, cr.line.v[c], cr.n.v[c], nn);
            goto done;
        }
        all_normals = all_normals && cr.n.v[c] > 0;
        any_normal = any_normal || cr.n.v[c] > 0;
    }
    if (any_normal && !all_normals)
        lr_warn(warn, "%s: some face corners have no normal; computing all normals", path);
    /* One output vertex per distinct (position, normal) pair when normals are used, else the
     * positions as they are. */
    corner_vertex = malloc(nc * sizeof *corner_vertex);
    if (!corner_vertex) {
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    size_t nout = nv;
    if (all_normals) {
        corner_key *key = malloc(nc * sizeof *key);
        if (!key) {
            rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
            goto done;
        }
        for (size_t c = 0; c < nc; c++)
            key[c] = (corner_key){(cr.v.v[c] - 1) * (long long)(nn + 1) + cr.n.v[c], c};
        qsort(key, nc, sizeof *key, cmp_corner);
        nout = 0;
        for (size_t i = 0; i < nc; i++) {
            if (i > 0 && key[i].key != key[i - 1].key)
                nout++;
            corner_vertex[key[i].corner] = (uint32_t)nout;
        }
        nout++;
        free(key);
        outpos = malloc(3 * nout * sizeof *outpos);
        outnrm = malloc(3 * nout * sizeof *outnrm);
        if (!outpos || !outnrm) {
            rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
            goto done;
        }
        for (size_t c = 0; c < nc; c++) {
            uint32_t o = corner_vertex[c];
            memcpy(&outpos[3 * o], &pos.v[3 * (cr.v.v[c] - 1)], 3 * sizeof(double));
            memcpy(&outnrm[3 * o], &nrm.v[3 * (cr.n.v[c] - 1)], 3 * sizeof(double));
        }
    } else {
        for (size_t c = 0; c < nc; c++)
            corner_vertex[c] = (uint32_t)(cr.v.v[c] - 1);
    }
    size_t nf = fstart.n;
    for (size_t f = 0; f < nf; f++) {
        size_t a = fstart.v[f], b = f + 1 < nf ? fstart.v[f + 1] : nc;
        ntri += b - a - 2;
    }
    idx = malloc(3 * ntri * sizeof *idx);
    origin = malloc(ntri * sizeof *origin);
    if (!idx || !origin) {
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    size_t t = 0;
    for (size_t f = 0; f < nf; f++) {
        size_t a = fstart.v[f], b = f + 1 < nf ? fstart.v[f + 1] : nc;
        for (size_t q = a + 1; q + 1 < b; q++) {
            idx[3 * t] = corner_vertex[a];
            idx[3 * t + 1] = corner_vertex[q];
            idx[3 * t + 2] = corner_vertex[q + 1];
            origin[t++] = cr.line.v[a];
        }
    }
    /* No normals in the file: computed here, split along sharp edges (crease.c). */
    if (!all_normals) {
        size_t ncr = 0;
        int cr_rc = lr_mesh_crease_normals(pos.v, nv, idx, ntri,
                                           cos(LR_MESH_CREASE_DEG * M_PI / 180.0), &outpos,
                                           &outnrm, &ncr);
        if (cr_rc < 0) {
            rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
            goto done;
        }
        nout = cr_rc ? nv : ncr;
    }
    lr_mesh_desc d = {
        .name = path,
        .vertex_count = nout,
        .positions = outpos ? outpos : pos.v,
        .normals = outnrm,
        .triangle_count = ntri,
        .indices = idx,
        .origin = origin,
        .origin_is_line = true,
    };
    if (checks)
        d.checks = *checks;
    rc = lr_mesh_create(&d, out, e);
    if (!rc && !all_normals && checks && checks->report)
        checks->report->normals_computed = true; /* by the loader, not read from the file */
done:
    free(buf);
    free(pos.v);
    free(nrm.v);
    free(cr.v.v);
    free(cr.n.v);
    free(cr.line.v);
    free(fstart.v);
    free(outpos);
    free(outnrm);
    free(idx);
    free(origin);
    free(corner_vertex);
    return rc;
}
