/* lamprig — shader files: assembly with header, defines and includes; compile errors mapped
 * back to the file and line they came from. */
#include "render/gl/shader.h"

#include <ctype.h>
#include <limits.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/base/file.h"

#define MAX_INCLUDE_DEPTH 16

struct lr_shader_source {
    char *text;
    size_t len, cap;
    /* line i (0-based) of text came from files[line_file[i]], 1-based line line_no[i];
     * line_file -1 marks the prelude. */
    int *line_file, *line_no;
    int nlines, lines_cap;
    char **files;     /* display path, as composed from the caller's path */
    char **realpaths; /* for "paste each file once" */
    int nfiles, files_cap;
    int prelude;
};

/* Every precision a pass could trip over: float/int default to highp only in vertex and
 * compute shaders, and sampler3D/2DArray/shadow samplers have no default in fragment shaders
 * at all (GLSL ES 3.10, "Default Precision Qualifiers"). highp samplers also keep float
 * textures at full precision on GPUs that default sampler2D to lowp. */
static const char *const precision_lines[] = {
    "precision highp float;",
    "precision highp int;",
    "precision highp sampler2D;",
    "precision highp sampler3D;",
    "precision highp samplerCube;",
    "precision highp sampler2DArray;",
    "precision highp sampler2DShadow;",
    "precision highp samplerCubeShadow;",
    "precision highp isampler2D;",
    "precision highp usampler2D;",
};

static const char *const stage_define[] = {
    [LR_STAGE_VERTEX] = "#define LR_VERTEX_SHADER 1",
    [LR_STAGE_FRAGMENT] = "#define LR_FRAGMENT_SHADER 1",
    [LR_STAGE_COMPUTE] = "#define LR_COMPUTE_SHADER 1",
};

static int append_line(lr_shader_source *s, const char *str, size_t n, int file, int line,
                       lr_err *e)
{
    if (s->len + n + 2 > s->cap) {
        size_t cap = s->cap ? s->cap : 4096;
        while (s->len + n + 2 > cap)
            cap *= 2;
        char *t = realloc(s->text, cap);
        if (!t)
            return lr_err_set(e, LR_ENOMEM, "shader source");
        s->text = t;
        s->cap = cap;
    }
    if (s->nlines == s->lines_cap) {
        int cap = s->lines_cap ? 2 * s->lines_cap : 256;
        int *f = realloc(s->line_file, (size_t)cap * sizeof *f);
        if (!f)
            return lr_err_set(e, LR_ENOMEM, "shader line map");
        s->line_file = f;
        int *l = realloc(s->line_no, (size_t)cap * sizeof *l);
        if (!l)
            return lr_err_set(e, LR_ENOMEM, "shader line map");
        s->line_no = l;
        s->lines_cap = cap;
    }
    memcpy(s->text + s->len, str, n);
    s->len += n;
    s->text[s->len++] = '\n';
    s->text[s->len] = '\0';
    s->line_file[s->nlines] = file;
    s->line_no[s->nlines] = line;
    s->nlines++;
    return LR_OK;
}

static int prelude_line(lr_shader_source *s, const char *str, lr_err *e)
{
    return append_line(s, str, strlen(str), -1, s->nlines + 1, e);
}

/* Registers path; returns its index, or -2 when the same file (by realpath) was pasted
 * already, or -1 on allocation failure. */
static int add_file(lr_shader_source *s, const char *path, const char *real)
{
    for (int i = 0; i < s->nfiles; i++)
        if (strcmp(s->realpaths[i], real) == 0)
            return -2;
    if (s->nfiles == s->files_cap) {
        int cap = s->files_cap ? 2 * s->files_cap : 8;
        char **f = realloc(s->files, (size_t)cap * sizeof *f);
        if (!f)
            return -1;
        s->files = f;
        char **r = realloc(s->realpaths, (size_t)cap * sizeof *r);
        if (!r)
            return -1;
        s->realpaths = r;
        s->files_cap = cap;
    }
    s->files[s->nfiles] = strdup(path);
    s->realpaths[s->nfiles] = strdup(real);
    if (!s->files[s->nfiles] || !s->realpaths[s->nfiles]) {
        free(s->files[s->nfiles]);
        free(s->realpaths[s->nfiles]);
        return -1;
    }
    return s->nfiles++;
}

/* If the line's first token is the preprocessor directive `word` ("# include" allowed, as in
 * C), returns a pointer just past it, else NULL. */
static const char *directive(const char *p, const char *end, const char *word)
{
    while (p < end && (*p == ' ' || *p == '\t'))
        p++;
    if (p == end || *p != '#')
        return NULL;
    p++;
    while (p < end && (*p == ' ' || *p == '\t'))
        p++;
    size_t n = strlen(word);
    if ((size_t)(end - p) < n || memcmp(p, word, n) != 0)
        return NULL;
    p += n;
    if (p < end && (isalnum((unsigned char)*p) || *p == '_'))
        return NULL;
    return p;
}

static int load_file(lr_shader_source *s, const char *path, const char *from, int from_line,
                     int depth, lr_err *e);

/* `#include "name"` at line `line` of files[file]: name is relative to that file. */
static int include(lr_shader_source *s, int file, int line, const char *p, const char *end,
                   int depth, lr_err *e)
{
    const char *from = s->files[file];
    while (p < end && (*p == ' ' || *p == '\t'))
        p++;
    const char *q = p < end && *p == '"' ? memchr(p + 1, '"', (size_t)(end - p - 1)) : NULL;
    if (!q || q == p + 1)
        return lr_err_set(e, LR_EPARSE, "%s:%d: malformed #include (expected #include \"file\")",
                          from, line);
    for (const char *t = q + 1; t < end && !(t[0] == '/' && t + 1 < end && t[1] == '/'); t++)
        if (*t != ' ' && *t != '\t')
            return lr_err_set(e, LR_EPARSE, "%s:%d: unexpected text after #include", from, line);
    int name_len = (int)(q - p - 1);
    const char *slash = strrchr(from, '/');
    int dir_len = (p[1] == '/' || !slash) ? 0 : (int)(slash - from + 1);
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%.*s%.*s", dir_len, from, name_len, p + 1) >= (int)sizeof path)
        return lr_err_set(e, LR_EINVAL, "%s:%d: include path too long", from, line);
    return load_file(s, path, from, line, depth + 1, e);
}

static int load_file(lr_shader_source *s, const char *path, const char *from, int from_line,
                     int depth, lr_err *e)
{
    char *data;
    size_t len;
    char real[PATH_MAX];
    int rc = lr_file_read(path, LR_FILE_MAX_TEXT, &data, &len, e);
    if (rc)
        return from ? lr_err_prefix(e, "%s:%d: include", from, from_line) : rc;
    if (!realpath(path, real))
        snprintf(real, sizeof real, "%s", path);
    int file = add_file(s, path, real);
    if (file == -2) {
        free(data);
        return LR_OK;
    }
    if (file < 0) {
        free(data);
        return lr_err_set(e, LR_ENOMEM, "%s: shader file list", path);
    }
    if (depth > MAX_INCLUDE_DEPTH) {
        free(data);
        return lr_err_set(e, LR_EPARSE, "%s:%d: includes nested deeper than %d", from, from_line,
                          MAX_INCLUDE_DEPTH);
    }
    const char *p = data, *end = data + len;
    for (int line = 1; rc == LR_OK && p < end; line++) {
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        const char *eol = nl ? nl : end;
        const char *stop = eol > p && eol[-1] == '\r' ? eol - 1 : eol;
        const char *rest;
        if (directive(p, stop, "version"))
            rc = lr_err_set(e, LR_EPARSE,
                            "%s:%d: #version is added by the shader loader; remove it", path, line);
        else if ((rest = directive(p, stop, "include")) != NULL)
            rc = include(s, file, line, rest, stop, depth, e);
        else
            rc = append_line(s, p, (size_t)(stop - p), file, line, e);
        p = nl ? nl + 1 : end;
    }
    free(data);
    return rc;
}

static int add_define(lr_shader_source *s, const char *def, lr_err *e)
{
    if (strpbrk(def, "\r\n"))
        return lr_err_set(e, LR_EPARSE, "shader define \"%s\" contains a line break", def);
    size_t n = strcspn(def, " =");
    if (n == 0)
        return lr_err_set(e, LR_EPARSE, "shader define \"%s\" has no name", def);
    char line[512];
    /* "NAME=VALUE" is accepted as well as "NAME VALUE". */
    int k = def[n] ? snprintf(line, sizeof line, "#define %.*s %s", (int)n, def, def + n + 1)
                   : snprintf(line, sizeof line, "#define %s", def);
    if (k >= (int)sizeof line)
        return lr_err_set(e, LR_EINVAL, "shader define \"%.40s...\" too long", def);
    return prelude_line(s, line, e);
}

int lr_shader_source_load(const char *path, lr_shader_stage stage, const char *const *defines,
                          lr_shader_source **out, lr_err *e)
{
    *out = NULL;
    if ((unsigned)stage > LR_STAGE_COMPUTE)
        return lr_err_set(e, LR_EINVAL, "%s: unknown shader stage %d", path, (int)stage);
    lr_shader_source *s = calloc(1, sizeof *s);
    if (!s)
        return lr_err_set(e, LR_ENOMEM, "shader source");
    int rc = prelude_line(s, "#version 310 es", e);
    if (rc == LR_OK)
        rc = prelude_line(s, stage_define[stage], e);
    for (size_t i = 0; rc == LR_OK && i < sizeof precision_lines / sizeof *precision_lines; i++)
        rc = prelude_line(s, precision_lines[i], e);
    for (size_t i = 0; rc == LR_OK && defines && defines[i]; i++)
        rc = add_define(s, defines[i], e);
    s->prelude = s->nlines;
    if (rc == LR_OK)
        rc = load_file(s, path, NULL, 0, 0, e);
    if (rc) {
        lr_shader_source_free(s);
        return rc;
    }
    *out = s;
    return LR_OK;
}

void lr_shader_source_free(lr_shader_source *s)
{
    if (!s)
        return;
    for (int i = 0; i < s->nfiles; i++) {
        free(s->files[i]);
        free(s->realpaths[i]);
    }
    free(s->files);
    free(s->realpaths);
    free(s->line_file);
    free(s->line_no);
    free(s->text);
    free(s);
}

const char *lr_shader_source_text(const lr_shader_source *s) { return s->text ? s->text : ""; }
int lr_shader_source_prelude_lines(const lr_shader_source *s) { return s->prelude; }

int lr_shader_source_locate(const lr_shader_source *s, int line, const char **file, int *file_line)
{
    if (line < 1 || line > s->nlines)
        return -1;
    int f = s->line_file[line - 1];
    *file = f < 0 ? "<prelude>" : s->files[f];
    *file_line = s->line_no[line - 1];
    return 0;
}

/* Appends printf output to out[*len..cap), truncating silently. */
__attribute__((format(printf, 4, 5))) static void put(char *out, size_t cap, size_t *len,
                                                      const char *fmt, ...)
{
    if (*len + 1 >= cap)
        return;
    va_list ap;
    va_start(ap, fmt);
    int k = vsnprintf(out + *len, cap - *len, fmt, ap);
    va_end(ap);
    if (k > 0)
        *len = *len + (size_t)k < cap ? *len + (size_t)k : cap - 1;
}

/* Recognises a location at the start of one log line. Sets *line (assembled-source line),
 * *col (0 when absent), *sev (a severity word to print, may be "") and *msg (the text after
 * the location). Returns false when the line carries no location. */
static bool parse_location(const char *l, int *line, int *col, const char **sev, const char **msg)
{
    int src, n = 0;
    *col = 0;
    *sev = "";
    /* ANGLE, Mali, Adreno, PowerVR: "ERROR: 0:12: 'x' : undeclared identifier" */
    static const char *const sevs[][2] = {{"ERROR: ", "error: "}, {"WARNING: ", "warning: "}};
    for (size_t i = 0; i < 2; i++) {
        size_t k = strlen(sevs[i][0]);
        if (strncmp(l, sevs[i][0], k) == 0 && sscanf(l + k, "%d:%d:%n", &src, line, &n) == 2 && n) {
            *sev = sevs[i][1];
            *msg = l + k + n;
            return true;
        }
    }
    /* Mesa: "0:12(5): error: `x' undeclared" */
    n = 0;
    if (sscanf(l, "%d:%d(%d):%n", &src, line, col, &n) == 3 && n) {
        *msg = l + n;
        return true;
    }
    /* NVIDIA: "0(12) : error C1008: undefined variable" */
    n = 0;
    if (sscanf(l, "%d(%d) :%n", &src, line, &n) == 2 && n) {
        *msg = l + n;
        return true;
    }
    return false;
}

int lr_shader_source_map_log(const lr_shader_source *s, const char *log, const char *sep,
                             char *out, size_t cap)
{
    size_t len = 0;
    int first = 0;
    if (cap)
        out[0] = '\0';
    const char *main_file = s->nfiles ? s->files[0] : "shader";
    for (const char *p = log; p && *p;) {
        const char *nl = strchr(p, '\n');
        size_t n = nl ? (size_t)(nl - p) : strlen(p);
        char l[1024];
        snprintf(l, sizeof l, "%.*s", (int)n, p);
        p = nl ? nl + 1 : p + n;
        size_t m = strlen(l);
        while (m && isspace((unsigned char)l[m - 1]))
            l[--m] = '\0';
        if (m == 0)
            continue;
        int line, col, fline;
        const char *sev, *msg, *file;
        if (len)
            put(out, cap, &len, "%s", sep);
        if (parse_location(l, &line, &col, &sev, &msg) &&
            lr_shader_source_locate(s, line, &file, &fline) == 0) {
            while (*msg == ' ')
                msg++;
            if (!first)
                first = fline;
            if (col)
                put(out, cap, &len, "%s:%d:%d: %s%s", file, fline, col, sev, msg);
            else
                put(out, cap, &len, "%s:%d: %s%s", file, fline, sev, msg);
        } else {
            put(out, cap, &len, "%s: %s", main_file, l);
        }
    }
    return first;
}

/* ---- programs ------------------------------------------------------------------------------ */

/* Uniform names a program's sources declare (array names without their index). */
typedef struct name_list {
    char **v;
    int n, cap;
} name_list;

struct lr_program {
    GLuint id;
    char label[192];       /* "fullscreen.vert + blend.frag", for messages */
    name_list uniforms;    /* declared in the sources (scan_uniforms) */
    char undeclared[64];   /* the first name lr_program_uniform was asked for and the sources
                            * do not declare, until lr_program_check reports it */
};

static void names_free(name_list *l)
{
    for (int i = 0; i < l->n; i++)
        free(l->v[i]);
    free(l->v);
    memset(l, 0, sizeof *l);
}

static bool names_has(const name_list *l, const char *name, size_t len)
{
    for (int i = 0; i < l->n; i++)
        if (strlen(l->v[i]) == len && !memcmp(l->v[i], name, len))
            return true;
    return false;
}

static int names_add(name_list *l, const char *name, size_t len)
{
    if (names_has(l, name, len))
        return 0;
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 32;
        char **v = realloc(l->v, (size_t)cap * sizeof *v);
        if (!v)
            return -1;
        l->v = v;
        l->cap = cap;
    }
    char *c = malloc(len + 1);
    if (!c)
        return -1;
    memcpy(c, name, len);
    c[len] = '\0';
    l->v[l->n++] = c;
    return 0;
}

static bool ident_char(char c)
{
    return isalnum((unsigned char)c) || c == '_';
}

/* Copies text without its comments (each replaced by a space). */
static char *strip_comments(const char *text)
{
    size_t n = strlen(text);
    char *out = malloc(n + 1), *o = out;
    if (!out)
        return NULL;
    for (const char *t = text; *t;) {
        if (t[0] == '/' && t[1] == '/') {
            while (*t && *t != '\n')
                t++;
            *o++ = ' ';
        } else if (t[0] == '/' && t[1] == '*') {
            const char *end = strstr(t + 2, "*/");
            t = end ? end + 2 : t + strlen(t);
            *o++ = ' ';
        } else {
            *o++ = *t++;
        }
    }
    *o = '\0';
    return out;
}

/* Adds the names of the default-block uniforms that text (assembled GLSL) declares:
 * `uniform [precision] TYPE name[[N]] [, name2 ...];`. Declarations inside #if blocks count
 * whether or not the preprocessor keeps them (a name declared under some define is not a
 * misspelling); uniform blocks are skipped (the shaders have none). Why from the source: the
 * driver's active uniforms lack those the compiler dropped as unused, which are legitimate
 * to set (their location is -1). */
static int scan_uniforms(const char *text, name_list *out)
{
    char *src = strip_comments(text);
    if (!src)
        return -1;
    int rc = 0;
    for (const char *t = src; (t = strstr(t, "uniform")) != NULL && !rc;) {
        bool word = (t == src || !ident_char(t[-1])) && !ident_char(t[7]);
        t += 7;
        if (!word)
            continue;
        /* Tokens up to ';' or '{': qualifiers, the type, then the names. */
        const char *ids[64];
        size_t lens[64];
        int n = 0, depth = 0;
        bool block = false;
        for (; *t && *t != ';'; t++) {
            if (*t == '{') {
                block = true;
                break;
            }
            if (*t == '[')
                depth++;
            else if (*t == ']')
                depth--;
            else if (depth == 0 && (isalpha((unsigned char)*t) || *t == '_') && n < 64) {
                ids[n] = t;
                while (ident_char(t[1]))
                    t++;
                lens[n] = (size_t)(t - ids[n]) + 1;
                n++;
            }
        }
        if (block || n < 2)
            continue;
        /* ids: [precision] type name (, name)*: the names are every identifier after the
         * type (array sizes, inside brackets, are not collected). */
        int k = 1;
        static const char *const precision[] = {"highp", "mediump", "lowp"};
        for (int q = 0; q < 3; q++)
            if (lens[0] == strlen(precision[q]) && !memcmp(ids[0], precision[q], lens[0]))
                k = 2;
        for (int i = k; i < n && !rc; i++)
            rc = names_add(out, ids[i], lens[i]);
    }
    free(src);
    return rc;
}

static char *info_log(GLuint obj, bool program)
{
    GLint n = 0;
    if (program)
        glGetProgramiv(obj, GL_INFO_LOG_LENGTH, &n);
    else
        glGetShaderiv(obj, GL_INFO_LOG_LENGTH, &n);
    char *log = calloc(n > 0 ? (size_t)n + 1 : 1, 1);
    if (log && n > 0) {
        if (program)
            glGetProgramInfoLog(obj, n, NULL, log);
        else
            glGetShaderInfoLog(obj, n, NULL, log);
    }
    return log;
}

static int compile(const char *dir, const char *name, lr_shader_stage stage,
                   const char *const *defines, name_list *uniforms, GLuint *out, lr_err *e)
{
    static const GLenum gl_stage[] = {GL_VERTEX_SHADER, GL_FRAGMENT_SHADER, GL_COMPUTE_SHADER};
    char path[PATH_MAX];
    if (snprintf(path, sizeof path, "%s%s%s", dir ? dir : "", dir && *dir ? "/" : "", name) >=
        (int)sizeof path)
        return lr_err_set(e, LR_EINVAL, "%s: shader path too long", name);
    lr_shader_source *src;
    int rc = lr_shader_source_load(path, stage, defines, &src, e);
    if (rc)
        return rc;
    const char *text = lr_shader_source_text(src);
    if (scan_uniforms(text, uniforms) != 0) {
        lr_shader_source_free(src);
        return lr_err_set(e, LR_ENOMEM, "%s: uniform names: out of memory", path);
    }
    GLuint sh = glCreateShader(gl_stage[stage]);
    glShaderSource(sh, 1, &text, NULL);
    glCompileShader(sh);
    GLint ok = GL_FALSE;
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char *log = info_log(sh, false);
        char mapped[LR_ERR_MSG_MAX];
        lr_shader_source_map_log(src, log ? log : "", "; ", mapped, sizeof mapped);
        free(log);
        glDeleteShader(sh);
        rc = lr_err_set(e, LR_EGL, "%s", mapped[0] ? mapped : "compile failed without a log");
        if (!mapped[0])
            lr_err_prefix(e, "%s", path);
    }
    lr_shader_source_free(src);
    if (rc == LR_OK)
        *out = sh;
    return rc;
}

int lr_program_create(const lr_program_desc *d, lr_program **out, lr_err *e)
{
    *out = NULL;
    bool graphics = d->vertex || d->fragment;
    if (graphics == (d->compute != NULL) || (graphics && !(d->vertex && d->fragment)))
        return lr_err_set(e, LR_EINVAL, "program: give vertex + fragment, or compute alone");
    const char *names[2] = {d->compute ? d->compute : d->vertex, d->fragment};
    lr_shader_stage stages[2] = {d->compute ? LR_STAGE_COMPUTE : LR_STAGE_VERTEX, LR_STAGE_FRAGMENT};
    int count = d->compute ? 1 : 2;
    GLuint sh[2] = {0, 0};
    name_list uniforms = {0};
    int rc = LR_OK;
    for (int i = 0; i < count && rc == LR_OK; i++)
        rc = compile(d->dir, names[i], stages[i], d->defines, &uniforms, &sh[i], e);

    GLuint prog = 0;
    if (rc == LR_OK) {
        prog = glCreateProgram();
        for (int i = 0; i < count; i++)
            glAttachShader(prog, sh[i]);
        glLinkProgram(prog);
        GLint ok = GL_FALSE;
        glGetProgramiv(prog, GL_LINK_STATUS, &ok);
        if (!ok) {
            char *log = info_log(prog, true);
            /* One line: driver logs are multi-line. */
            size_t n = log ? strlen(log) : 0;
            for (size_t i = 0; i < n; i++)
                if (log[i] == '\n')
                    log[i] = ' ';
            while (n && log[n - 1] == ' ')
                log[--n] = '\0';
            rc = lr_err_set(e, LR_EGL, "link %s%s%s: %s", names[0], count > 1 ? " + " : "",
                            count > 1 ? names[1] : "", log ? log : "");
            free(log);
            glDeleteProgram(prog);
        }
    }
    for (int i = 0; i < count; i++)
        if (sh[i])
            glDeleteShader(sh[i]); /* the program keeps what it linked */
    lr_program *p = rc ? NULL : calloc(1, sizeof *p);
    if (!rc && !p) {
        glDeleteProgram(prog);
        rc = lr_err_set(e, LR_ENOMEM, "program");
    }
    if (rc) {
        names_free(&uniforms);
        return rc;
    }
    p->id = prog;
    p->uniforms = uniforms;
    snprintf(p->label, sizeof p->label, "%s%s%s", names[0], count > 1 ? " + " : "",
             count > 1 ? names[1] : "");
    *out = p;
    return LR_OK;
}

void lr_program_destroy(lr_program *p)
{
    if (!p)
        return;
    glDeleteProgram(p->id);
    names_free(&p->uniforms);
    free(p);
}

GLuint lr_program_id(const lr_program *p) { return p->id; }

/* The declared name of "u_x" or "u_x[3]" (or "u_x[3].y"): its length up to the index. */
static size_t base_len(const char *name)
{
    size_t n = 0;
    while (name[n] && name[n] != '[' && name[n] != '.')
        n++;
    return n;
}

bool lr_program_declares(const lr_program *p, const char *name)
{
    return names_has(&p->uniforms, name, base_len(name));
}

GLint lr_program_uniform(lr_program *p, const char *name)
{
    if (!lr_program_declares(p, name)) {
        if (!p->undeclared[0])
            snprintf(p->undeclared, sizeof p->undeclared, "%s", name);
        return -1;
    }
    return glGetUniformLocation(p->id, name);
}

int lr_program_check(lr_program *p, lr_err *e)
{
    if (!p->undeclared[0])
        return LR_OK;
    int rc = lr_err_set(e, LR_EINVAL,
                        "program %s: sets uniform %s, which its shaders do not declare",
                        p->label, p->undeclared);
    p->undeclared[0] = '\0';
    return rc;
}
