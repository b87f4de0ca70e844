/* PLY reader (ascii and binary little-endian). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "render/mesh/mesh_internal.h"
#include "render/mesh/mesh_io.h"

#define MAX_PROPS 64
#define MAX_ELEMS 16
#define MAX_POLY 1024 /* vertices in one face: more is garbage, not a lamp */

enum ptype { P_NONE, P_I8, P_U8, P_I16, P_U16, P_I32, P_U32, P_F32, P_F64 };

typedef struct prop {
    char name[32];
    enum ptype type;  /* value type (list items for a list) */
    enum ptype count; /* list length type; P_NONE for a scalar */
} prop;

typedef struct elem {
    char name[32];
    size_t count;
    prop props[MAX_PROPS];
    int nprops;
    int line;
} elem;

static enum ptype parse_type(const char *s)
{
    static const struct { const char *n; enum ptype t; } T[] = {
        {"char", P_I8},    {"int8", P_I8},     {"uchar", P_U8},   {"uint8", P_U8},
        {"short", P_I16},  {"int16", P_I16},   {"ushort", P_U16}, {"uint16", P_U16},
        {"int", P_I32},    {"int32", P_I32},   {"uint", P_U32},   {"uint32", P_U32},
        {"float", P_F32},  {"float32", P_F32}, {"double", P_F64}, {"float64", P_F64}};
    for (size_t i = 0; i < sizeof T / sizeof T[0]; i++)
        if (strcmp(s, T[i].n) == 0)
            return T[i].t;
    return P_NONE;
}

static size_t type_size(enum ptype t)
{
    static const size_t S[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return S[t];
}

static bool is_int_type(enum ptype t) { return t != P_F32 && t != P_F64; }

/* Reader state over the whole file. */
typedef struct reader {
    const char *path;
    char *buf;
    size_t len, pos;
    int line; /* ascii: line of the current position */
    lr_err *e;
} reader;

static void skip_space(reader *r)
{
    while (r->pos < r->len && strchr(" \t\r\n", r->buf[r->pos])) {
        if (r->buf[r->pos] == '\n')
            r->line++;
        r->pos++;
    }
}

/* Next whitespace-separated token of an ascii body; NULL at the end. Counts lines. */
static const char *next_token(reader *r, char *tok, size_t cap, int *tok_line)
{
    skip_space(r);
    if (r->pos >= r->len)
        return NULL;
    size_t n = 0;
    *tok_line = r->line;
    while (r->pos < r->len && !strchr(" \t\r\n", r->buf[r->pos])) {
        if (n + 1 < cap)
            tok[n++] = r->buf[r->pos];
        r->pos++;
    }
    tok[n] = '\0';
    return tok;
}

/* One ascii value as a double (integers are exact up to 2^53, far beyond any index here). */
static int ascii_value(reader *r, enum ptype t, const char *what, size_t index, double *out)
{
    char tok[64];
    int line = r->line;
    if (!next_token(r, tok, sizeof tok, &line))
        return lr_err_set(r->e, LR_EPARSE, "%s:%d: file ends inside %s %zu", r->path, r->line,
                          what, index);
    char *end;
    errno = 0;
    double v;
    if (is_int_type(t)) {
        long long x = strtoll(tok, &end, 10);
        v = (double)x;
    } else {
        v = strtod(tok, &end);
    }
    if (end == tok || *end != '\0' || errno == ERANGE)
        return lr_err_set(r->e, LR_EPARSE, "%s:%d: %s %zu: '%s' is not a valid %s", r->path,
                          line, what, index, tok, is_int_type(t) ? "integer" : "number");
    *out = v;
    return LR_OK;
}

static uint64_t le_bits(const unsigned char *p, size_t n)
{
    uint64_t v = 0;
    for (size_t i = 0; i < n; i++)
        v |= (uint64_t)p[i] << (8 * i);
    return v;
}

static int binary_value(reader *r, enum ptype t, const char *what, size_t index, double *out)
{
    size_t n = type_size(t);
    if (r->len - r->pos < n)
        return lr_err_set(r->e, LR_EPARSE,
                          "%s: truncated binary data in %s %zu (byte offset %zu of %zu)",
                          r->path, what, index, r->pos, r->len);
    uint64_t b = le_bits((const unsigned char *)r->buf + r->pos, n);
    r->pos += n;
    switch (t) {
    case P_I8: *out = (int8_t)b; break;
    case P_U8: *out = (uint8_t)b; break;
    case P_I16: *out = (int16_t)b; break;
    case P_U16: *out = (uint16_t)b; break;
    case P_I32: *out = (int32_t)b; break;
    case P_U32: *out = (uint32_t)b; break;
    case P_F32: {
        uint32_t u = (uint32_t)b;
        float f;
        memcpy(&f, &u, sizeof f);
        *out = f;
        break;
    }
    default: {
        double d;
        memcpy(&d, &b, sizeof d);
        *out = d;
        break;
    }
    }
    return LR_OK;
}

/* Reads one header line into buf (without the newline); returns false at the end. */
static bool header_line(reader *r, char *buf, size_t cap)
{
    if (r->pos >= r->len)
        return false;
    size_t n = 0;
    while (r->pos < r->len && r->buf[r->pos] != '\n') {
        if (n + 1 < cap)
            buf[n++] = r->buf[r->pos];
        r->pos++;
    }
    if (r->pos < r->len)
        r->pos++; /* the newline */
    if (n > 0 && buf[n - 1] == '\r')
        n--;
    buf[n] = '\0';
    r->line++;
    return true;
}

typedef struct growing {
    double *pos, *nrm;
    uint32_t *idx, *origin;
    size_t nt, cap_t;
} growing;

static int add_triangle(growing *g, uint32_t a, uint32_t b, uint32_t c, uint32_t origin)
{
    if (g->nt == g->cap_t) {
        size_t cap = g->cap_t ? 2 * g->cap_t : 1024;
        uint32_t *ni = realloc(g->idx, 3 * cap * sizeof *ni);
        if (!ni)
            return -1;
        g->idx = ni;
        uint32_t *no = realloc(g->origin, cap * sizeof *no);
        if (!no)
            return -1;
        g->origin = no;
        g->cap_t = cap;
    }
    g->idx[3 * g->nt] = a;
    g->idx[3 * g->nt + 1] = b;
    g->idx[3 * g->nt + 2] = c;
    g->origin[g->nt++] = origin;
    return 0;
}

int lr_mesh_load_ply(const char *path, const lr_mesh_checks *checks, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    reader r = {.path = path, .e = e};
    int rc = lr_mesh_read_file(path, &r.buf, &r.len, e);
    if (rc)
        return rc;
    elem *el = calloc(MAX_ELEMS, sizeof *el);
    growing g = {0};
    if (!el) {
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    char line[256];
    int nel = 0;
    bool binary = false, have_format = false;
    if (!header_line(&r, line, sizeof line) || strcmp(line, "ply") != 0) {
        rc = lr_err_set(e, LR_EPARSE, "%s:1: not a PLY file (first line must be 'ply')", path);
        goto done;
    }
    for (;;) {
        if (!header_line(&r, line, sizeof line)) {
            rc = lr_err_set(e, LR_EPARSE, "%s:%d: header has no 'end_header'", path, r.line);
            goto done;
        }
        char kw[32] = "", a[32] = "", b[32] = "", c[32] = "", d[32] = "";
        int n = sscanf(line, "%31s %31s %31s %31s %31s", kw, a, b, c, d);
        if (n <= 0 || strcmp(kw, "comment") == 0 || strcmp(kw, "obj_info") == 0)
            continue;
        if (strcmp(kw, "end_header") == 0)
            break;
        if (strcmp(kw, "format") == 0) {
            if (n < 3 || strcmp(b, "1.0") != 0) {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: malformed format line", path, r.line);
                goto done;
            }
            if (strcmp(a, "ascii") == 0) {
                binary = false;
            } else if (strcmp(a, "binary_little_endian") == 0) {
                binary = true;
            } else if (strcmp(a, "binary_big_endian") == 0) {
                rc = lr_err_set(e, LR_EUNSUPPORTED, "%s:%d: binary_big_endian PLY is not "
                                "supported; save as ascii or binary_little_endian", path, r.line);
                goto done;
            } else {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: unknown format '%s'", path, r.line, a);
                goto done;
            }
            have_format = true;
        } else if (strcmp(kw, "element") == 0) {
            char *end;
            errno = 0;
            unsigned long long cnt = n == 3 ? strtoull(b, &end, 10) : 0;
            if (n != 3 || *end != '\0' || errno || b[0] == '-') {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: malformed element line", path, r.line);
                goto done;
            }
            if (nel == MAX_ELEMS) {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: more than %d elements", path, r.line,
                                MAX_ELEMS);
                goto done;
            }
            /* Every element takes at least one byte of the file: a larger count is a lie that
             * must not turn into a huge allocation. */
            if (cnt > r.len) {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: element '%s' claims %llu items in a "
                                "%zu-byte file", path, r.line, a, cnt, r.len);
                goto done;
            }
            elem *x = &el[nel++];
            snprintf(x->name, sizeof x->name, "%s", a);
            x->count = (size_t)cnt;
            x->line = r.line;
        } else if (strcmp(kw, "property") == 0) {
            if (nel == 0) {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: property before any element", path,
                                r.line);
                goto done;
            }
            elem *x = &el[nel - 1];
            if (x->nprops == MAX_PROPS) {
                rc = lr_err_set(e, LR_EPARSE, "%s:%d: too many properties", path, r.line);
                goto done;
            }
            prop *p = &x->props[x->nprops];
            if (strcmp(a, "list") == 0) {
                p->count = parse_type(b);
                p->type = parse_type(c);
                snprintf(p->name, sizeof p->name, "%s", d);
                if (n != 5 || p->count == P_NONE || p->type == P_NONE ||
                    !is_int_type(p->count)) {
                    rc = lr_err_set(e, LR_EPARSE, "%s:%d: malformed list property", path,
                                    r.line);
                    goto done;
                }
            } else {
                p->count = P_NONE;
                p->type = parse_type(a);
                snprintf(p->name, sizeof p->name, "%s", b);
                if (n != 3 || p->type == P_NONE) {
                    rc = lr_err_set(e, LR_EPARSE, "%s:%d: malformed property (type '%s')",
                                    path, r.line, a);
                    goto done;
                }
            }
            x->nprops++;
        } else {
            rc = lr_err_set(e, LR_EPARSE, "%s:%d: unknown header keyword '%s'", path, r.line, kw);
            goto done;
        }
    }
    r.line++; /* the body starts on the line after end_header */
    if (!have_format) {
        rc = lr_err_set(e, LR_EPARSE, "%s: header has no format line", path);
        goto done;
    }
    int iv = -1, ifc = -1;
    for (int i = 0; i < nel; i++) {
        if (strcmp(el[i].name, "vertex") == 0)
            iv = i;
        if (strcmp(el[i].name, "face") == 0)
            ifc = i;
    }
    if (iv < 0 || ifc < 0) {
        rc = lr_err_set(e, LR_EPARSE, "%s: needs a 'vertex' and a 'face' element", path);
        goto done;
    }
    int px = -1, py = -1, pz = -1, pnx = -1, pny = -1, pnz = -1, plist = -1;
    for (int i = 0; i < el[iv].nprops; i++) {
        const prop *p = &el[iv].props[i];
        if (p->count != P_NONE)
            continue;
        if (!strcmp(p->name, "x")) px = i;
        if (!strcmp(p->name, "y")) py = i;
        if (!strcmp(p->name, "z")) pz = i;
        if (!strcmp(p->name, "nx")) pnx = i;
        if (!strcmp(p->name, "ny")) pny = i;
        if (!strcmp(p->name, "nz")) pnz = i;
    }
    for (int i = 0; i < el[ifc].nprops; i++) {
        const prop *p = &el[ifc].props[i];
        if (p->count != P_NONE &&
            (!strcmp(p->name, "vertex_indices") || !strcmp(p->name, "vertex_index")) &&
            is_int_type(p->type))
            plist = i;
    }
    if (px < 0 || py < 0 || pz < 0) {
        rc = lr_err_set(e, LR_EPARSE, "%s:%d: element 'vertex' lacks x, y or z", path,
                        el[iv].line);
        goto done;
    }
    if (plist < 0) {
        rc = lr_err_set(e, LR_EPARSE, "%s:%d: element 'face' lacks an integer "
                        "'vertex_indices' list", path, el[ifc].line);
        goto done;
    }
    bool normals = pnx >= 0 && pny >= 0 && pnz >= 0;
    size_t nv = el[iv].count;
    g.pos = malloc(3 * (nv ? nv : 1) * sizeof *g.pos);
    g.nrm = normals ? malloc(3 * (nv ? nv : 1) * sizeof *g.nrm) : NULL;
    if (!g.pos || (normals && !g.nrm)) {
        rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
        goto done;
    }
    int (*value)(reader *, enum ptype, const char *, size_t, double *) =
        binary ? binary_value : ascii_value;
    for (int ei = 0; ei < nel; ei++) {
        elem *x = &el[ei];
        for (size_t k = 0; k < x->count; k++) {
            if (!binary)
                skip_space(&r);
            int item_line = r.line; /* ascii: the line the item starts on */
            for (int pi = 0; pi < x->nprops; pi++) {
                const prop *p = &x->props[pi];
                if (p->count == P_NONE) {
                    double v;
                    if ((rc = value(&r, p->type, x->name, k, &v)))
                        goto done;
                    if (ei != iv)
                        continue;
                    int axis = pi == px ? 0 : pi == py ? 1 : pi == pz ? 2 : -1;
                    int naxis = pi == pnx ? 0 : pi == pny ? 1 : pi == pnz ? 2 : -1;
                    if (axis >= 0 && !isfinite(v)) {
                        rc = binary ? lr_err_set(e, LR_EINVAL, "%s: vertex %zu: coordinate %c "
                                                 "is %g", path, k, "xyz"[axis], v)
                                    : lr_err_set(e, LR_EINVAL, "%s:%d: vertex %zu: coordinate "
                                                 "%c is %g", path, r.line, k, "xyz"[axis], v);
                        goto done;
                    }
                    if (axis >= 0)
                        g.pos[3 * k + axis] = v;
                    if (naxis >= 0 && normals)
                        g.nrm[3 * k + naxis] = v;
                    continue;
                }
                double cnt;
                if ((rc = value(&r, p->count, x->name, k, &cnt)))
                    goto done;
                if (cnt < 0 || cnt > MAX_POLY) {
                    if (binary)
                        rc = lr_err_set(e, LR_EPARSE, "%s: %s %zu: list of %g items (at most "
                                        "%d)", path, x->name, k, cnt, MAX_POLY);
                    else
                        rc = lr_err_set(e, LR_EPARSE, "%s:%d: %s %zu: list of %g items (at "
                                        "most %d)", path, r.line, x->name, k, cnt, MAX_POLY);
                    goto done;
                }
                uint32_t poly[MAX_POLY];
                for (int q = 0; q < (int)cnt; q++) {
                    double v;
                    if ((rc = value(&r, p->type, x->name, k, &v)))
                        goto done;
                    if (ei == ifc && pi == plist) {
                        if (v < 0 || v > 4294967294.0) {
                            if (binary)
                                rc = lr_err_set(e, LR_EINVAL, "%s: face %zu: vertex index %g "
                                                "out of range (%zu vertices)", path, k, v, nv);
                            else
                                rc = lr_err_set(e, LR_EINVAL, "%s:%d: face %zu: vertex index %g "
                                                "out of range (%zu vertices)", path, r.line, k,
                                                v, nv);
                            goto done;
                        }
                        poly[q] = (uint32_t)v;
                    }
                }
                if (ei == ifc && pi == plist) {
                    if (cnt < 3) {
                        if (binary)
                            rc = lr_err_set(e, LR_EPARSE, "%s: face %zu has %g vertices "
                                            "(at least 3)", path, k, cnt);
                        else
                            rc = lr_err_set(e, LR_EPARSE, "%s:%d: face %zu has %g vertices "
                                            "(at least 3)", path, item_line, k, cnt);
                        goto done;
                    }
                    uint32_t origin = binary ? (uint32_t)k : (uint32_t)item_line;
                    for (int q = 1; q + 1 < (int)cnt; q++)
                        if (add_triangle(&g, poly[0], poly[q], poly[q + 1], origin)) {
                            rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
                            goto done;
                        }
                }
            }
        }
    }
    /* No normals in the file: computed here, split along sharp edges (crease.c). */
    double *cpos = NULL, *cnrm = NULL;
    if (!normals) {
        size_t ncr = 0;
        int cr_rc = lr_mesh_crease_normals(g.pos, nv, g.idx, g.nt,
                                           cos(LR_MESH_CREASE_DEG * M_PI / 180.0), &cpos, &cnrm,
                                           &ncr);
        if (cr_rc < 0) {
            rc = lr_err_set(e, LR_ENOMEM, "%s: out of memory", path);
            goto done;
        }
        if (cr_rc == 0) {
            free(g.pos);
            g.pos = cpos;
            g.nrm = cnrm;
            nv = ncr;
        }
    }
    lr_mesh_desc d = {
        .name = path,
        .vertex_count = nv,
        .positions = g.pos,
        .normals = g.nrm,
        .triangle_count = g.nt,
        .indices = g.idx,
        .origin = g.origin,
        .origin_is_line = !binary,
    };
    if (checks)
        d.checks = *checks;
    rc = lr_mesh_create(&d, out, e);
    if (!rc && !normals && checks && checks->report)
        checks->report->normals_computed = true; /* by the loader, not read from the file */
done:
    free(r.buf);
    free(el);
    free(g.pos);
    free(g.nrm);
    free(g.idx);
    free(g.origin);
    return rc;
}

int lr_mesh_load(const char *path, const lr_mesh_checks *checks, lr_mesh **out, lr_err *e)
{
    *out = NULL;
    const char *dot = strrchr(path, '.');
    if (dot && strcasecmp(dot, ".ply") == 0)
        return lr_mesh_load_ply(path, checks, out, e);
    if (dot && strcasecmp(dot, ".obj") == 0)
        return lr_mesh_load_obj(path, checks, out, e);
    return lr_err_set(e, LR_EUNSUPPORTED, "%s: unknown mesh format (expected .ply or .obj)",
                      path);
}
