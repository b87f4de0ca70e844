/* build/bench/pareto.png: per scene, the time to reach an error (frames x accumulation frame
 * time) against the error over object and receiver pixels, log-log, every row grey and the
 * Pareto front in colour, joined. */
#include "tools/bench/sweep.h"

#include <cairo.h>
#include <math.h>
#include <stdlib.h>

#include "render/image/cairo_png.h"

enum { PANEL_W = 520, PANEL_H = 400, COLS = 2 };
enum { ML = 70, MR = 20, MT = 40, MB = 50 }; /* panel margins */

double lrb_sweep_time_ms(const lr_eval_row *r)
{
    return r->frames * r->frame_ms;
}

static bool usable(double v)
{
    return isfinite(v) && v > 0.0;
}

typedef struct axes {
    double x0, y0;       /* panel origin */
    double lx0, lx1, ly0, ly1; /* decades */
} axes;

static double px(const axes *a, double v)
{
    return a->x0 + ML + (log10(v) - a->lx0) / (a->lx1 - a->lx0) * (PANEL_W - ML - MR);
}
static double py(const axes *a, double v)
{
    return a->y0 + PANEL_H - MB - (log10(v) - a->ly0) / (a->ly1 - a->ly0) * (PANEL_H - MT - MB);
}

static void text(cairo_t *cr, double x, double y, const char *s, double align)
{
    cairo_text_extents_t t;
    cairo_text_extents(cr, s, &t);
    cairo_move_to(cr, x - align * t.x_advance, y);
    cairo_show_text(cr, s);
}

static void panel(cairo_t *cr, double x0, double y0, const lrb_scene_result *sc,
                  const lr_eval_row *rows)
{
    int n = sc->nrows;
    double *c = malloc(sizeof(double) * (size_t)(n ? n : 1)), *er = malloc(sizeof(double) * (size_t)(n ? n : 1));
    bool *front = malloc(sizeof(bool) * (size_t)(n ? n : 1));
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_font_size(cr, 15);
    char title[160];
    snprintf(title, sizeof title, "%s%s: all settings (grey), Pareto front (red)", sc->name,
             sc->ok ? "" : " (failed)");
    text(cr, x0 + PANEL_W / 2.0, y0 + 22, title, 0.5);
    double xmin = INFINITY, xmax = 0, ymin = INFINITY, ymax = 0;
    for (int i = 0; c && er && i < n; i++) {
        c[i] = lrb_sweep_time_ms(&rows[i]);
        er[i] = rows[i].rel_rmse;
        if (usable(c[i]) && usable(er[i])) {
            xmin = fmin(xmin, c[i]), xmax = fmax(xmax, c[i]);
            ymin = fmin(ymin, er[i]), ymax = fmax(ymax, er[i]);
        }
    }
    if (!c || !er || !front || !(xmax > 0)) {
        free(c), free(er), free(front);
        return;
    }
    lr_eval_pareto(c, er, n, front);
    axes a = {x0, y0, floor(log10(xmin)), ceil(log10(xmax)), floor(log10(ymin)), ceil(log10(ymax))};
    if (a.lx1 <= a.lx0)
        a.lx1 = a.lx0 + 1;
    if (a.ly1 <= a.ly0)
        a.ly0 = a.ly1 - 1;
    /* Axes and decade grid. */
    cairo_set_line_width(cr, 1);
    cairo_set_font_size(cr, 11);
    for (double d = a.lx0; d <= a.lx1; d++) {
        cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
        cairo_move_to(cr, px(&a, pow(10, d)), y0 + MT);
        cairo_line_to(cr, px(&a, pow(10, d)), y0 + PANEL_H - MB);
        cairo_stroke(cr);
        char l[32];
        snprintf(l, sizeof l, "%g", pow(10, d));
        cairo_set_source_rgb(cr, 0, 0, 0);
        text(cr, px(&a, pow(10, d)), y0 + PANEL_H - MB + 15, l, 0.5);
    }
    for (double d = a.ly0; d <= a.ly1; d++) {
        cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
        cairo_move_to(cr, x0 + ML, py(&a, pow(10, d)));
        cairo_line_to(cr, x0 + PANEL_W - MR, py(&a, pow(10, d)));
        cairo_stroke(cr);
        char l[32];
        snprintf(l, sizeof l, "%g", pow(10, d));
        cairo_set_source_rgb(cr, 0, 0, 0);
        text(cr, x0 + ML - 5, py(&a, pow(10, d)) + 4, l, 1.0);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, x0 + ML, y0 + MT, PANEL_W - ML - MR, PANEL_H - MT - MB);
    cairo_stroke(cr);
    text(cr, x0 + (ML + PANEL_W - MR) / 2.0, y0 + PANEL_H - 12,
         "time to reach the error: frames x frame time (ms)", 0.5);
    cairo_save(cr);
    cairo_translate(cr, x0 + 16, y0 + PANEL_H / 2.0);
    cairo_rotate(cr, -M_PI / 2);
    text(cr, 0, 0, "relative RMSE vs physical reference", 0.5);
    cairo_restore(cr);
    /* All rows grey, then the front: sorted by cost, joined, red. */
    cairo_set_source_rgb(cr, 0.6, 0.6, 0.6);
    for (int i = 0; i < n; i++)
        if (usable(c[i]) && usable(er[i])) {
            cairo_arc(cr, px(&a, c[i]), py(&a, er[i]), 2.5, 0, 2 * M_PI);
            cairo_fill(cr);
        }
    cairo_set_source_rgb(cr, 0.85, 0.1, 0.1);
    cairo_set_line_width(cr, 1.5);
    double last = -1.0;
    for (int k = 0; k < n; k++) {
        int best = -1;
        for (int i = 0; i < n; i++)
            if (front[i] && c[i] > last && (best < 0 || c[i] < c[best]))
                best = i;
        if (best < 0)
            break;
        double X = px(&a, c[best]), Y = py(&a, er[best]);
        if (last < 0)
            cairo_move_to(cr, X, Y);
        else
            cairo_line_to(cr, X, Y);
        last = c[best];
    }
    cairo_stroke(cr);
    for (int i = 0; i < n; i++)
        if (front[i]) {
            cairo_arc(cr, px(&a, c[i]), py(&a, er[i]), 4, 0, 2 * M_PI);
            cairo_fill(cr);
        }
    free(c), free(er), free(front);
}

int lrb_sweep_plot(const char *path, const lr_eval_row *rows, int nrows,
                   const lrb_scene_result *scenes, int nscenes, lr_err *e)
{
    (void)nrows;
    int nr = (nscenes + COLS - 1) / COLS;
    if (nr < 1)
        return lr_err_set(e, LR_EINVAL, "%s: no scenes to plot", path);
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, COLS * PANEL_W, nr * PANEL_H);
    cairo_t *cr = cairo_create(s);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    for (int k = 0; k < nscenes; k++)
        panel(cr, (k % COLS) * PANEL_W, (k / COLS) * PANEL_H, &scenes[k], rows + scenes[k].row0);
    return lr_cairo_finish_png(cr, s, path, e);
}
