/* Per-pixel error maps as PNG (lr_heatmap_png in calib/compare.h), drawn with cairo. */
#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "calib/compare.h"
#include "render/image/cairo_png.h"

enum { BAR_W = 90, TOP = 28 };

/* Dark blue -> purple -> red -> orange -> yellow, piecewise linear in t in [0, 1]. */
static void colormap(double t, double rgb[3])
{
    static const double stops[5][3] = {
        {0.05, 0.03, 0.25}, {0.45, 0.05, 0.55}, {0.85, 0.15, 0.25}, {0.98, 0.55, 0.05},
        {1.00, 0.95, 0.35}};
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    double f = t * 4;
    int i = f >= 4 ? 3 : (int)f;
    f -= i;
    for (int c = 0; c < 3; c++)
        rgb[c] = stops[i][c] * (1 - f) + stops[i + 1][c] * f;
}

int lr_heatmap_png(const char *path, const float *v, int w, int h, double vmax,
                   const char *title, lr_err *e)
{
    if (!(vmax > 0) || !isfinite(vmax))
        return lr_err_set(e, LR_EINVAL, "heatmap: scale %g must be > 0", vmax);
    int W = w + BAR_W, H = h + TOP;
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        return lr_err_set(e, LR_ENOMEM, "heatmap: cannot create a %dx%d image", W, H);
    }
    cairo_t *cr = cairo_create(s);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_surface_flush(s);
    unsigned char *data = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            double c[3] = {0.5, 0.5, 0.5}, t = v[(size_t)y * w + x];
            if (isfinite(t))
                colormap(t / vmax, c);
            uint32_t *p = (uint32_t *)(data + (size_t)(y + TOP) * stride) + x;
            *p = (uint32_t)lround(c[0] * 255) << 16 | (uint32_t)lround(c[1] * 255) << 8 |
                 (uint32_t)lround(c[2] * 255);
        }
    /* Colour bar: top = vmax, bottom = 0. */
    int bx = w + 12, by0 = TOP + 8, by1 = H - 8;
    for (int y = by0; y <= by1; y++)
        for (int x = bx; x < bx + 16; x++) {
            double c[3];
            colormap((double)(by1 - y) / (by1 - by0), c);
            uint32_t *p = (uint32_t *)(data + (size_t)y * stride) + x;
            *p = (uint32_t)lround(c[0] * 255) << 16 | (uint32_t)lround(c[1] * 255) << 8 |
                 (uint32_t)lround(c[2] * 255);
        }
    cairo_surface_mark_dirty(s);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 11);
    for (int i = 0; i <= 4; i++) {
        double y = by1 - (by1 - by0) * i / 4.0;
        char label[32];
        snprintf(label, sizeof label, "%s%.3g", i == 4 ? ">=" : "", vmax * i / 4.0);
        cairo_move_to(cr, bx + 16, y + 0.5);
        cairo_line_to(cr, bx + 20, y + 0.5);
        cairo_stroke(cr);
        cairo_move_to(cr, bx + 22, y + 4);
        cairo_show_text(cr, label);
    }
    cairo_set_font_size(cr, 13);
    cairo_move_to(cr, 4, 18);
    cairo_show_text(cr, title ? title : "");
    return lr_cairo_finish_png(cr, s, path, e);
}
