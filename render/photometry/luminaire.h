/* lamprig — a luminaire's measured intensity distribution (photometric files: IES LM-63,
 * EULUMDAT), parsed to one form.
 *
 * Angles are type C (the photometric type of interior and LED luminaires): the vertical angle
 * gamma from nadir (0: straight down the luminaire's axis, 180: straight up), the C plane
 * (horizontal) angle around that axis, C0 along the luminaire's length, C90 across. A file
 * stores only the planes its symmetry needs (one plane, a quadrant, a half); lr_luminaire_cd
 * folds any plane onto them. Parsers check every count, angle and value and refuse a file with
 * "FILE:LINE: what" (the line of the offending number).
 */
#ifndef LR_LUMINAIRE_H
#define LR_LUMINAIRE_H

#include <stddef.h>

#include "render/base/err.h"

enum lr_lum_symmetry {
    LR_LUM_SYM_ROTATIONAL, /* one plane, the same all round */
    LR_LUM_SYM_QUADRANT,   /* C0..C90: mirror in the C0-C180 and the C90-C270 planes */
    LR_LUM_SYM_BILATERAL,  /* C0..C180: mirror in the C0-C180 plane */
    LR_LUM_SYM_BILATERAL90,/* C90..C270: mirror in the C90-C270 plane */
    LR_LUM_SYM_NONE        /* C0..C360 (a last plane at 360 repeats 0) */
};

/* Bounds a parser accepts (a real file has at most 361 vertical, 721 horizontal angles): they
 * keep a hostile file's allocation small. */
#define LR_LUM_MAX_ANGLES 1801
#define LR_LUM_MAX_VALUES 400000

typedef struct lr_luminaire {
    int n_v, n_h;
    double *v_deg; /* ascending, in [0, 180] */
    double *h_deg; /* ascending, the planes the symmetry keeps */
    double *cd;    /* n_h x n_v (plane-major): candela with the file's multipliers applied */
    enum lr_lum_symmetry sym;
    /* The flux the file states (lm): IES lamps x lumens per lamp (the lamp's flux; with
     * photometry measured on the luminaire this is its flux too when the file says so, and
     * for files made here), EULUMDAT the luminaire's: lamp flux x light output ratio. 0: the
     * file states none (IES absolute photometry, -1 lumens). */
    double lumens;
    /* IES TILT=INCLUDE: the multiplying factor per lamp tilt (kept, not applied: the files'
     * intensities are for the luminaire as measured); 0 angles: TILT=NONE or EULUMDAT. */
    int n_tilt;
    double *tilt_deg, *tilt_factor;
    char format[24]; /* "LM-63-2002", "LM-63-1995", "LM-63-1991", "LM-63-1986", "EULUMDAT" */
} lr_luminaire;

/* Parse a file's text (name for messages). Out is zeroed first and owns its arrays on success;
 * on failure it holds nothing. */
int lr_ies_parse(const char *text, size_t len, const char *name, lr_luminaire *out, lr_err *e);
int lr_ldt_parse(const char *text, size_t len, const char *name, lr_luminaire *out, lr_err *e);
/* Reads path and parses it by its extension (.ies, .ldt; any case). */
int lr_luminaire_load(const char *path, lr_luminaire *out, lr_err *e);
void lr_luminaire_free(lr_luminaire *l);

/* Intensity (cd) in C plane h_deg (any angle: folded by the symmetry) at gamma v_deg,
 * bilinear between the stored angles; 0 beyond the vertical range the file covers. */
double lr_luminaire_cd(const lr_luminaire *l, double h_deg, double v_deg);
/* The luminous flux (lm): the intensity integrated over the sphere (midpoint rule, 0.25 deg in
 * gamma, 1 deg in C, on the bilinear interpolant: ~1e-5 relative for 5-degree data). */
double lr_luminaire_flux(const lr_luminaire *l);
/* The largest intensity (cd), for normalising a shape factor. */
double lr_luminaire_max_cd(const lr_luminaire *l);

/* Parser internals shared by ies.c and ldt.c: a number reader that knows its line. */
typedef struct lr_lum_text {
    const char *p, *end, *name;
    int line;
} lr_lum_text;
/* The next whitespace- or comma-separated number; fails "NAME:LINE: expected WHAT" at the end
 * of text or on a token that is not a finite number. */
int lr_lum_number(lr_lum_text *t, const char *what, double *v, lr_err *e);
/* Skips separators to the next token; returns its line. */
int lr_lum_skip(lr_lum_text *t);
/* Checks angles ascending within [lo, hi]; line: where the list starts. */
int lr_lum_angles(const lr_lum_text *t, int line, const char *what, const double *a, int n,
                  double lo, double hi, lr_err *e);
/* Allocates l's arrays (n_v, n_h set); LR_ENOMEM. */
int lr_lum_alloc(lr_luminaire *l, lr_err *e);

#endif
