/* The folder include graph against docs/layers.txt: see include_graph.h. */
#include "tests/support/include_graph.h"

#include <dirent.h>
#include <limits.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define MAX_FOLDERS 128
#define MAX_LAYERS 32
#define MAX_PATTERNS 256
#define WITNESS_MAX 320

typedef struct pattern {
    char text[PATH_MAX];
    bool below; /* written "x/" and a star: every folder below x */
    int layer;
} pattern;

typedef struct graph {
    char root[PATH_MAX];     /* realpath of the tree */
    char layer_name[MAX_LAYERS][64];
    int nlayers;
    pattern pat[MAX_PATTERNS];
    int npat;
    char folder[MAX_FOLDERS][PATH_MAX];
    int nfolders;
    /* edge[a][b]: the first include from folder a into folder b, as "file:line", or "". */
    char (*edge)[MAX_FOLDERS][WITNESS_MAX];
    char *report;
    size_t cap, used;
    int problems;
    bool overflow; /* more folders than MAX_FOLDERS */
} graph;

static void vadd(graph *g, const char *fmt, va_list ap)
{
    if (g->used + 1 >= g->cap)
        return;
    int n = vsnprintf(g->report + g->used, g->cap - g->used, fmt, ap);
    if (n > 0)
        g->used = g->used + (size_t)n < g->cap ? g->used + (size_t)n : g->cap - 1;
}

/* More text for the problem being reported. */
static void add(graph *g, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vadd(g, fmt, ap);
    va_end(ap);
}

/* A new problem. */
static void say(graph *g, const char *fmt, ...)
{
    g->problems++;
    va_list ap;
    va_start(ap, fmt);
    vadd(g, fmt, ap);
    va_end(ap);
}

static int read_layers(graph *g, const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        snprintf(g->report, g->cap, "%s: cannot be read", path);
        return -1;
    }
    char line[4096];
    int lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *save = NULL, *tok = strtok_r(line, " \t\r\n", &save);
        if (!tok)
            continue;
        if (g->nlayers == MAX_LAYERS) {
            fclose(f);
            snprintf(g->report, g->cap, "%s:%d: more than %d layers", path, lineno, MAX_LAYERS);
            return -1;
        }
        int L = g->nlayers++;
        snprintf(g->layer_name[L], sizeof g->layer_name[L], "%s", tok);
        while ((tok = strtok_r(NULL, " \t\r\n", &save))) {
            if (g->npat == MAX_PATTERNS) {
                fclose(f);
                snprintf(g->report, g->cap, "%s:%d: more than %d folders", path, lineno,
                         MAX_PATTERNS);
                return -1;
            }
            pattern *p = &g->pat[g->npat++];
            size_t n = strlen(tok);
            p->below = n >= 2 && strcmp(tok + n - 2, "/*") == 0;
            snprintf(p->text, sizeof p->text, "%.*s", (int)(p->below ? n - 2 : n), tok);
            p->layer = L;
        }
    }
    fclose(f);
    if (g->nlayers == 0) {
        snprintf(g->report, g->cap, "%s: declares no layer", path);
        return -1;
    }
    return 0;
}

/* The layer of a folder: an exact entry wins over a "below" one; -1 when none. */
static int layer_of(const graph *g, const char *folder)
{
    int below = -1;
    for (int i = 0; i < g->npat; i++) {
        const pattern *p = &g->pat[i];
        size_t n = strlen(p->text);
        if (!p->below && strcmp(folder, p->text) == 0)
            return p->layer;
        if (p->below && strncmp(folder, p->text, n) == 0 && folder[n] == '/')
            below = p->layer;
    }
    return below;
}

static int folder_index(graph *g, const char *folder)
{
    for (int i = 0; i < g->nfolders; i++)
        if (strcmp(g->folder[i], folder) == 0)
            return i;
    if (g->nfolders == MAX_FOLDERS) {
        g->overflow = true;
        return -1;
    }
    snprintf(g->folder[g->nfolders], PATH_MAX, "%s", folder);
    return g->nfolders++;
}

static void dir_of(const char *rel, char *out, size_t cap)
{
    const char *slash = strrchr(rel, '/');
    snprintf(out, cap, "%.*s", slash ? (int)(slash - rel) : 1, slash ? rel : ".");
}

static bool is_source(const char *name)
{
    const char *dot = strrchr(name, '.');
    return dot && (!strcmp(dot, ".c") || !strcmp(dot, ".h") || !strcmp(dot, ".cpp") ||
                   !strcmp(dot, ".hpp"));
}

/* The included file as a path relative to the root, or false when it is not in the tree. */
static bool resolve(const graph *g, const char *rel_dir, const char *inc, char *out, size_t cap)
{
    char cand[2 * PATH_MAX + 2], real[PATH_MAX];
    struct stat st;
    if (snprintf(cand, sizeof cand, "%s/%s", g->root, inc) >= (int)sizeof cand)
        return false;
    if (stat(cand, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (snprintf(cand, sizeof cand, "%s/%s/%s", g->root, rel_dir, inc) >= (int)sizeof cand)
            return false;
        if (stat(cand, &st) != 0 || !S_ISREG(st.st_mode))
            return false;
    }
    if (!realpath(cand, real))
        return false;
    size_t n = strlen(g->root);
    if (strncmp(real, g->root, n) != 0 || real[n] != '/')
        return false;
    snprintf(out, cap, "%s", real + n + 1);
    return true;
}

static void scan_file(graph *g, const char *rel)
{
    char path[2 * PATH_MAX], dir[PATH_MAX];
    if (snprintf(path, sizeof path, "%s/%s", g->root, rel) >= (int)sizeof path)
        return;
    dir_of(rel, dir, sizeof dir);
    int from = folder_index(g, dir);
    FILE *f = fopen(path, "r");
    if (!f || from < 0) {
        if (f)
            fclose(f);
        return;
    }
    char line[4096];
    int lineno = 0;
    while (fgets(line, sizeof line, f)) {
        lineno++;
        const char *s = line;
        while (*s == ' ' || *s == '\t')
            s++;
        if (*s++ != '#')
            continue;
        while (*s == ' ' || *s == '\t')
            s++;
        if (strncmp(s, "include", 7) != 0)
            continue;
        s += 7;
        while (*s == ' ' || *s == '\t')
            s++;
        if (*s != '"')
            continue;
        const char *end = strchr(s + 1, '"');
        if (!end)
            continue;
        char inc[PATH_MAX], target[PATH_MAX], tdir[PATH_MAX];
        snprintf(inc, sizeof inc, "%.*s", (int)(end - s - 1), s + 1);
        if (!resolve(g, dir, inc, target, sizeof target))
            continue;
        dir_of(target, tdir, sizeof tdir);
        if (strcmp(tdir, dir) == 0)
            continue;
        int to = folder_index(g, tdir);
        if (to < 0)
            continue;
        int lf = layer_of(g, dir), lt = layer_of(g, tdir);
        if (lf >= 0 && lt > lf)
            say(g, "%s:%d: includes %s: layer \"%s\" includes \"%s\" above it\n", rel, lineno,
                target, g->layer_name[lf], g->layer_name[lt]);
        if (!g->edge[from][to][0])
            if (snprintf(g->edge[from][to], WITNESS_MAX, "%s:%d includes %s", rel, lineno,
                         target) >= WITNESS_MAX)
                g->edge[from][to][WITNESS_MAX - 2] = '~'; /* cut short, still non-empty */
    }
    fclose(f);
}

static void scan_dir(graph *g, const char *rel)
{
    char path[2 * PATH_MAX];
    snprintf(path, sizeof path, "%s%s%s", g->root, *rel ? "/" : "", rel);
    DIR *d = opendir(path);
    if (!d)
        return;
    struct dirent *de;
    bool sources = false;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.' || (!*rel && strcmp(de->d_name, "build") == 0))
            continue;
        char child[PATH_MAX + 256];
        snprintf(child, sizeof child, "%s%s%s", rel, *rel ? "/" : "", de->d_name);
        char cpath[2 * PATH_MAX + 256];
        snprintf(cpath, sizeof cpath, "%s/%s", g->root, child);
        struct stat st;
        if (lstat(cpath, &st) != 0)
            continue;
        if (S_ISDIR(st.st_mode))
            scan_dir(g, child);
        else if (S_ISREG(st.st_mode) && is_source(de->d_name) && *rel) {
            sources = true;
            scan_file(g, child);
        }
    }
    closedir(d);
    if (sources && layer_of(g, rel) < 0)
        say(g, "%s: holds sources but is in no layer of the layers file\n", rel);
}

/* Tarjan's strongly connected components over the folder graph; every component of more than
 * one folder is a cycle, reported with the includes that close it. */
typedef struct tarjan {
    int index[MAX_FOLDERS], low[MAX_FOLDERS], stack[MAX_FOLDERS];
    bool on[MAX_FOLDERS];
    int sp, next;
} tarjan;

static void strong(graph *g, tarjan *t, int v)
{
    t->index[v] = t->low[v] = t->next++;
    t->stack[t->sp++] = v;
    t->on[v] = true;
    for (int w = 0; w < g->nfolders; w++) {
        if (!g->edge[v][w][0])
            continue;
        if (t->index[w] < 0) {
            strong(g, t, w);
            if (t->low[w] < t->low[v])
                t->low[v] = t->low[w];
        } else if (t->on[w] && t->index[w] < t->low[v]) {
            t->low[v] = t->index[w];
        }
    }
    if (t->low[v] != t->index[v])
        return;
    int members[MAX_FOLDERS], n = 0, w;
    do {
        w = t->stack[--t->sp];
        t->on[w] = false;
        members[n++] = w;
    } while (w != v);
    if (n < 2)
        return;
    say(g, "cycle among %d folders:", n);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            if (g->edge[members[i]][members[j]][0])
                add(g, " %s;", g->edge[members[i]][members[j]]);
    add(g, "\n");
}

int lr_test_check_layers(const char *root, const char *layers_path, char *report, size_t cap)
{
    if (!report || cap == 0)
        return -1;
    report[0] = '\0';
    graph *g = calloc(1, sizeof *g);
    if (!g || !(g->edge = calloc(MAX_FOLDERS, sizeof *g->edge))) {
        free(g);
        snprintf(report, cap, "out of memory");
        return -1;
    }
    g->report = report;
    g->cap = cap;
    int rc = -1;
    if (!realpath(root, g->root)) {
        snprintf(report, cap, "%s: no such folder", root);
        goto out;
    }
    if (read_layers(g, layers_path) != 0)
        goto out;
    scan_dir(g, "");
    if (g->overflow)
        say(g, "more than %d folders: raise MAX_FOLDERS\n", MAX_FOLDERS);
    tarjan *t = calloc(1, sizeof *t);
    if (!t) {
        snprintf(report, cap, "out of memory");
        goto out;
    }
    for (int i = 0; i < MAX_FOLDERS; i++)
        t->index[i] = -1;
    for (int v = 0; v < g->nfolders; v++)
        if (t->index[v] < 0)
            strong(g, t, v);
    free(t);
    rc = g->problems;
out:
    free(g->edge);
    free(g);
    return rc;
}
