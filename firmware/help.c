/* The --help text of a command, generated from its table (firmware/cli.h): the synopsis from
 * the options (required ones bare, optional ones in brackets, groups as one word), the option
 * list from their metavars and help lines, a group's subcommands with their synopses; the
 * prose (about, else the summary; notes) as written. */
#include <string.h>

#include "firmware/cli.h"

/* Lines are wrapped before this column. */
#define WIDTH 92
/* The option list's help column, at most. */
#define LABEL_MAX 24

/* Words written at column col, wrapped to lines indented by indent; fresh: the next word
 * starts its line (no space before it). */
typedef struct wrap {
    FILE *f;
    int col, indent, fresh;
} wrap;

static void put_word(wrap *w, const char *word)
{
    int len = (int)strlen(word);
    if (!w->fresh && w->col + 1 + len > WIDTH) {
        fprintf(w->f, "\n%*s", w->indent, "");
        w->col = w->indent;
    } else if (!w->fresh) {
        fputc(' ', w->f);
        w->col++;
    }
    fputs(word, w->f);
    w->col += len;
    w->fresh = 0;
}

/* One synopsis word per option: "--out F.png" or "[--hdr F.pfm]", "[--set key=value ...]",
 * "--capture IMG [IMG...]"; options of a group once, as the group's name. */
static void synopsis(wrap *w, const lr_command *c)
{
    const lr_argspec *o = c->opts;
    for (int i = 0; o && o[i].name; i++) {
        char word[256];
        if (o[i].group) {
            int seen = 0;
            for (int j = 0; j < i && !seen; j++)
                seen = o[j].group && !strcmp(o[j].group, o[i].group);
            if (!seen)
                put_word(w, o[i].group);
            continue;
        }
        const char *mv = lr_args_metavar(&o[i]);
        int req = (o[i].flags & LR_ARG_REQUIRED) != 0;
        if (o[i].flags & LR_ARG_LIST)
            snprintf(word, sizeof word, "%s%s %s [%s...]%s", req ? "" : "[", o[i].name, mv, mv,
                     req ? "" : "]");
        else
            snprintf(word, sizeof word, "%s%s%s%s%s%s", req ? "" : "[", o[i].name, *mv ? " " : "",
                     mv, o[i].repeat > 1 ? " ..." : "", req ? "" : "]");
        put_word(w, word);
    }
    if (c->operands)
        put_word(w, c->operands);
}

/* Text with embedded newlines, every line after the first indented. */
static void indented(FILE *f, const char *text, int indent)
{
    for (const char *p = text; *p;) {
        size_t len = strcspn(p, "\n");
        fprintf(f, "%.*s\n", (int)len, p);
        p += len;
        if (*p == '\n' && *++p)
            fprintf(f, "%*s", indent, "");
    }
}

static void options(FILE *f, const lr_argspec *o)
{
    int col = 0;
    for (int i = 0; o && o[i].name; i++) {
        int len = (int)(strlen(o[i].name) + 1 + strlen(lr_args_metavar(&o[i])));
        if (len > col && len <= LABEL_MAX)
            col = len;
    }
    for (int i = 0; o && o[i].name; i++) {
        char label[128];
        const char *mv = lr_args_metavar(&o[i]);
        snprintf(label, sizeof label, "%s%s%s", o[i].name, *mv ? " " : "", mv);
        if (!o[i].help) {
            fprintf(f, "  %s\n", label);
            continue;
        }
        if ((int)strlen(label) > col)
            fprintf(f, "  %s\n  %*s  ", label, col, "");
        else
            fprintf(f, "  %-*s  ", col, label);
        indented(f, o[i].help, col + 4);
    }
}

/* A group's leaves, flattened: "projector patterns --proj WxH --out DIR", then its summary. */
static void list_subs(FILE *f, const lr_command *g, const char *prefix)
{
    for (const lr_command *const *s = g->subs; *s; s++) {
        char name[128];
        snprintf(name, sizeof name, "%s%s%s", prefix, *prefix ? " " : "", (*s)->name);
        if ((*s)->subs) {
            list_subs(f, *s, name);
            continue;
        }
        int indent = 2 + (int)strlen(name) + 1;
        fprintf(f, "  %s", name);
        wrap w = {f, indent - 1, indent > LABEL_MAX ? 8 : indent, 0};
        synopsis(&w, *s);
        fprintf(f, "\n      ");
        indented(f, (*s)->summary, 6);
    }
}

/* head: the usage line's program and command words ("lamprig calib projector",
 * "lamprig-cpuref"); path: the command's path for `lamprig help PATH` (groups only). */
static void print_help(FILE *f, const lr_command *c, const char *program, const char *path)
{
    char head[300];
    snprintf(head, sizeof head, "usage: %s", program);
    fputs(head, f);
    wrap w = {f, (int)strlen(head), (int)strlen(head) + 1, 0};
    if (c->subs) {
        put_word(&w, "SUBCOMMAND");
        put_word(&w, "[OPTIONS]");
    } else {
        synopsis(&w, c);
    }
    fputc('\n', f);
    /* A subcommand's summary is its description when it has no longer one. */
    const char *about = c->about ? c->about : c->summary;
    if (about)
        fprintf(f, "\n%s\n", about);
    if (c->subs) {
        fprintf(f, "\nSubcommands (`lamprig help %s SUBCOMMAND` shows one in full):\n", path);
        list_subs(f, c, "");
    } else if (c->opts && c->opts[0].name) {
        fputc('\n', f);
        options(f, c->opts);
    }
    if (c->notes)
        fprintf(f, "\n%s\n", c->notes);
}

void lr_help_print(FILE *f, const lr_command *c, const char *path)
{
    char program[280];
    snprintf(program, sizeof program, "lamprig %s", path);
    print_help(f, c, program, path);
}

void lr_help_print_tool(FILE *f, const lr_command *c)
{
    print_help(f, c, c->name, c->name);
}
