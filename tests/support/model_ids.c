/* Model-id comparisons outside render/models/ (model_ids.h). */
#include "tests/support/model_ids.h"

#include <dirent.h>
#include <regex.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct scan {
    regex_t re;
    char *report;
    size_t cap, used;
    int found;
    size_t root_len;
} scan;

static bool source_name(const char *name)
{
    static const char *const ext[] = {".c", ".h", ".cpp", ".hpp", ".glsl", ".vert", ".frag",
                                      ".comp"};
    const char *dot = strrchr(name, '.');
    for (size_t i = 0; dot && i < sizeof ext / sizeof ext[0]; i++)
        if (strcmp(dot, ext[i]) == 0)
            return true;
    return false;
}

static void say(scan *s, const char *fmt, const char *a, int line, const char *what, int len)
{
    if (s->used + 1 >= s->cap)
        return;
    int w = snprintf(s->report + s->used, s->cap - s->used, fmt, a, line, len, what);
    if (w > 0)
        s->used += (size_t)w < s->cap - s->used ? (size_t)w : s->cap - s->used - 1;
}

static void scan_file(scan *s, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return;
    char *text = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            char *t = realloc(text, cap = 2 * cap + 8192);
            if (!t)
                break;
            text = t;
        }
        size_t r = fread(text + n, 1, cap - n - 1, f);
        n += r;
        if (r == 0)
            break;
    }
    fclose(f);
    if (!text)
        return;
    text[n] = '\0';
    const char *p = text;
    regmatch_t m;
    while (regexec(&s->re, p, 1, &m, p == text ? 0 : REG_NOTBOL) == 0) {
        int line = 1;
        for (const char *q = text; q < p + m.rm_so; q++)
            line += *q == '\n';
        s->found++;
        say(s, "%s:%d: compares a model id: %.*s\n", path + s->root_len, line, p + m.rm_so,
            (int)(m.rm_eo - m.rm_so));
        p += m.rm_eo > 0 ? m.rm_eo : 1;
    }
    free(text);
}

static void walk(scan *s, const char *dir, int depth)
{
    DIR *d = opendir(dir);
    if (!d || depth > 16) {
        if (d)
            closedir(d);
        return;
    }
    struct dirent *de;
    while ((de = readdir(d))) {
        if (de->d_name[0] == '.')
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", dir, de->d_name);
        const char *rel = path + s->root_len;
        struct stat st;
        if (stat(path, &st) != 0)
            continue;
        if (S_ISDIR(st.st_mode)) {
            if (strcmp(rel, "build") == 0 || strcmp(rel, "tests") == 0 ||
                strcmp(rel, "render/models") == 0)
                continue;
            walk(s, path, depth + 1);
        } else if (S_ISREG(st.st_mode) && source_name(de->d_name)) {
            scan_file(s, path);
        }
    }
    closedir(d);
}

int lr_test_check_model_ids(const char *root, char *report, size_t cap)
{
    scan s = {.report = report, .cap = cap, .root_len = strlen(root) + 1};
    if (cap)
        report[0] = '\0';
    struct stat st;
    if (stat(root, &st) != 0 || !S_ISDIR(st.st_mode)) {
        snprintf(report, cap, "%s: cannot be read", root);
        return -1;
    }
    /* [[:space:]] spans line breaks: "==\n    LR_SSS_X" is caught too. */
    if (regcomp(&s.re,
                "[=!]=[[:space:]]*LR_SSS_[A-Z_]+|LR_SSS_[A-Z_]+[[:space:]]*[=!]=|"
                "case[[:space:]]+LR_SSS_[A-Z_]+",
                REG_EXTENDED) != 0) {
        snprintf(report, cap, "regcomp failed");
        return -1;
    }
    walk(&s, root, 0);
    regfree(&s.re);
    return s.found;
}
