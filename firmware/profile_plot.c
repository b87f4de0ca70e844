#include "firmware/profile_plot.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>

#include "render/image/cairo_png.h"

const double lr_profile_plot_colour[3][3] = {
    {0.85, 0.10, 0.10},
    {0.10, 0.60, 0.10},
    {0.10, 0.25, 0.90},
};

/* Plot area inside the image, pixels. */
enum { PX0 = 100, PX1 = LR_PROFILE_PLOT_WIDTH - 30, PY0 = 50, PY1 = LR_PROFILE_PLOT_HEIGHT - 70 };
/* Decades of y kept below the largest value. */
#define Y_DECADES_MAX 12

typedef struct axes {
    double lx0, lx1, ly0, ly1; /* decade bounds, log10 */
} axes;

static double map_x(const axes *a, double x)
{
    return PX0 + (log10(x) - a->lx0) / (a->lx1 - a->lx0) * (PX1 - PX0);
}

static double map_y(const axes *a, double y)
{
    return PY1 - (log10(y) - a->ly0) / (a->ly1 - a->ly0) * (PY1 - PY0);
}

static int usable(double v) { return isfinite(v) && v > 0.0; }

/* "10" with a superscript exponent, anchored by (ax, ay): ax 0 left .. 1 right of the text,
 * ay the baseline. */
static void decade_label(cairo_t *cr, int k, double x, double y, double ax)
{
    char exp[16];
    snprintf(exp, sizeof exp, "%d", k);
    cairo_text_extents_t base, sup;
    cairo_set_font_size(cr, 14);
    cairo_text_extents(cr, "10", &base);
    cairo_set_font_size(cr, 10);
    cairo_text_extents(cr, exp, &sup);
    double w = base.x_advance + sup.x_advance;
    double left = x - ax * w;
    cairo_set_font_size(cr, 14);
    cairo_move_to(cr, left, y);
    cairo_show_text(cr, "10");
    cairo_set_font_size(cr, 10);
    cairo_move_to(cr, left + base.x_advance, y - 7);
    cairo_show_text(cr, exp);
}

static void draw_axes(cairo_t *cr, const axes *a, const char *x_label, const char *y_label)
{
    /* Decade grid lines, then the frame. */
    cairo_set_line_width(cr, 1.0);
    cairo_set_source_rgb(cr, 0.88, 0.88, 0.88);
    for (int k = (int)a->lx0; k <= (int)a->lx1; k++) {
        double px = map_x(a, pow(10.0, k));
        cairo_move_to(cr, px, PY0);
        cairo_line_to(cr, px, PY1);
    }
    for (int k = (int)a->ly0; k <= (int)a->ly1; k++) {
        double py = map_y(a, pow(10.0, k));
        cairo_move_to(cr, PX0, py);
        cairo_line_to(cr, PX1, py);
    }
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, PX0, PY0, PX1 - PX0, PY1 - PY0);
    cairo_stroke(cr);

    /* Ticks: long at decades, short at 2..9 times a decade; labels at decades (every other
     * decade when there are many, so that they do not collide). */
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    int xstep = (a->lx1 - a->lx0) > 10 ? 2 : 1;
    int ystep = (a->ly1 - a->ly0) > 10 ? 2 : 1;
    for (int k = (int)a->lx0; k <= (int)a->lx1; k++) {
        for (int m = 1; m <= 9; m++) {
            if (k == (int)a->lx1 && m > 1)
                break;
            double px = map_x(a, m * pow(10.0, k));
            double len = m == 1 ? 8 : 4;
            cairo_move_to(cr, px, PY1);
            cairo_line_to(cr, px, PY1 - len);
            cairo_move_to(cr, px, PY0);
            cairo_line_to(cr, px, PY0 + len);
        }
        if ((k - (int)a->lx0) % xstep == 0)
            decade_label(cr, k, map_x(a, pow(10.0, k)), PY1 + 22, 0.5);
    }
    for (int k = (int)a->ly0; k <= (int)a->ly1; k++) {
        for (int m = 1; m <= 9; m++) {
            if (k == (int)a->ly1 && m > 1)
                break;
            double py = map_y(a, m * pow(10.0, k));
            double len = m == 1 ? 8 : 4;
            cairo_move_to(cr, PX0, py);
            cairo_line_to(cr, PX0 + len, py);
            cairo_move_to(cr, PX1, py);
            cairo_line_to(cr, PX1 - len, py);
        }
        if ((k - (int)a->ly0) % ystep == 0)
            decade_label(cr, k, PX0 - 8, map_y(a, pow(10.0, k)) + 5, 1.0);
    }
    cairo_stroke(cr);

    cairo_text_extents_t t;
    cairo_set_font_size(cr, 14);
    cairo_text_extents(cr, x_label, &t);
    cairo_move_to(cr, (PX0 + PX1) / 2.0 - t.x_advance / 2, LR_PROFILE_PLOT_HEIGHT - 18);
    cairo_show_text(cr, x_label);
    cairo_text_extents(cr, y_label, &t);
    cairo_save(cr);
    cairo_move_to(cr, 24, (PY0 + PY1) / 2.0 + t.x_advance / 2);
    cairo_rotate(cr, -M_PI / 2);
    cairo_show_text(cr, y_label);
    cairo_restore(cr);
}

static void draw_curves(cairo_t *cr, const axes *a, const double *x, const double (*y)[3], int n)
{
    cairo_save(cr);
    cairo_rectangle(cr, PX0, PY0, PX1 - PX0, PY1 - PY0);
    cairo_clip(cr);
    cairo_set_line_width(cr, 2.5);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    for (int b = 0; b < 3; b++) {
        int pen_down = 0;
        for (int i = 0; i < n; i++) {
            if (!usable(x[i]) || !usable(y[i][b])) {
                pen_down = 0;
                continue;
            }
            double px = map_x(a, x[i]), py = map_y(a, y[i][b]);
            if (pen_down)
                cairo_line_to(cr, px, py);
            else
                cairo_move_to(cr, px, py);
            pen_down = 1;
        }
        cairo_set_source_rgb(cr, lr_profile_plot_colour[b][0], lr_profile_plot_colour[b][1],
                             lr_profile_plot_colour[b][2]);
        cairo_stroke(cr);
    }
    cairo_restore(cr);

    /* Legend, top right inside the frame. */
    static const char *const names[3] = {"R", "G", "B"};
    cairo_set_font_size(cr, 13);
    cairo_set_line_width(cr, 2.5);
    for (int b = 0; b < 3; b++) {
        double ly = PY0 + 20 + 18 * b;
        cairo_set_source_rgb(cr, lr_profile_plot_colour[b][0], lr_profile_plot_colour[b][1],
                             lr_profile_plot_colour[b][2]);
        cairo_move_to(cr, PX1 - 60, ly - 4);
        cairo_line_to(cr, PX1 - 36, ly - 4);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, PX1 - 28, ly);
        cairo_show_text(cr, names[b]);
    }
}

int lr_profile_plot_png(const char *path, const char *title, const char *x_label,
                        const char *y_label, const double *x, const double (*y)[3], int n,
                        lr_err *e)
{
    double xmin = INFINITY, xmax = 0, ymax = 0;
    int nx = 0;
    for (int i = 0; i < n; i++) {
        if (!usable(x[i]))
            continue;
        nx++;
        xmin = fmin(xmin, x[i]);
        xmax = fmax(xmax, x[i]);
        for (int b = 0; b < 3; b++)
            if (usable(y[i][b]))
                ymax = fmax(ymax, y[i][b]);
    }
    if (nx < 2 || !(xmax > xmin))
        return lr_err_set(e, LR_EINVAL, "%s: a log-log plot needs at least two distinct r > 0",
                          path);
    if (!(ymax > 0))
        return lr_err_set(e, LR_EINVAL, "%s: nothing to plot: no value is > 0", path);
    double yfloor = ymax * pow(10.0, -Y_DECADES_MAX), ymin = ymax;
    for (int i = 0; i < n; i++)
        for (int b = 0; b < 3; b++)
            if (usable(x[i]) && usable(y[i][b]) && y[i][b] >= yfloor)
                ymin = fmin(ymin, y[i][b]);
    axes a = {floor(log10(xmin)), ceil(log10(xmax)), floor(log10(ymin)), ceil(log10(ymax))};
    if (a.lx1 <= a.lx0)
        a.lx1 = a.lx0 + 1;
    if (a.ly1 <= a.ly0)
        a.ly0 = a.ly1 - 1;

    cairo_surface_t *s =
        cairo_image_surface_create(CAIRO_FORMAT_RGB24, LR_PROFILE_PLOT_WIDTH, LR_PROFILE_PLOT_HEIGHT);
    cairo_t *cr = cairo_create(s);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    draw_axes(cr, &a, x_label, y_label);
    draw_curves(cr, &a, x, y, n);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
    cairo_set_font_size(cr, 18);
    cairo_text_extents_t t;
    cairo_text_extents(cr, title, &t);
    cairo_move_to(cr, (PX0 + PX1) / 2.0 - t.x_advance / 2, PY0 - 16);
    cairo_show_text(cr, title);
    return lr_cairo_finish_png(cr, s, path, e);
}
