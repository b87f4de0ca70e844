/* lamprig — the scene file's fields, described once (render/scene internals).
 *
 * One table per record kind (light, camera, receiver, object, mesh, transform, render
 * settings, quality budget) gives each field its key, value type, range, default, the
 * lr_dirty bit a change sets and a one-line description. The loader (load.c) reads JSON
 * through it, lr_scene_set/get (set.c) parse and print values through it, the record checks
 * (check.c) test its ranges, and the field reference in configs/scenes/README.md is written
 * from it (lr_scene_fields_markdown; tests/base/test_scene.c compares the two). What a table cannot
 * say -- relations between fields (inner_deg <= outer_deg, far > near, a camera that can see),
 * the generators' own mesh checks (render/mesh/shapes.h), materials (render/material) -- is
 * explicit code after the table-driven part.
 */
#ifndef LR_SCENE_FIELDS_H
#define LR_SCENE_FIELDS_H

#include <stdbool.h>
#include <stddef.h>
#include <math.h>
#include <stdio.h>

#include "render/base/err.h"
#include "render/base/json.h"

enum lr_ftype {
    LR_FT_NUM,   /* double */
    LR_FT_INT,   /* int (a JSON integer) */
    LR_FT_UINT,  /* unsigned (a JSON integer >= 0) */
    LR_FT_VEC3,  /* lr_vec3, "x,y,z" */
    LR_FT_RGB,   /* double[3], "r,g,b" (per band) */
    LR_FT_SIZE3, /* double[3], "x,y,z" (per side) */
    LR_FT_PAIR,  /* double[2], "w,h" (per side) */
    LR_FT_SCALE, /* lr_vec3 from a number (all axes) or "x,y,z" */
    LR_FT_BOOL,  /* bool */
    LR_FT_ENUM,  /* int (an enum), one of names[] */
    LR_FT_ENUMB, /* bool, one of two names[] (false, true) */
    LR_FT_PATH,  /* char[LR_SCENE_PATH_MAX] */
    LR_FT_NAME,  /* a record's name: loaded by its own code (unique, defaulted) */
    LR_FT_TYPE,  /* a record's "type": selects the kind; loaded by its own code */
    LR_FT_OBJECT /* a nested object with its own code (material, mesh, transform) */
};

enum {
    LR_FF_REQUIRED = 1u << 0,
    LR_FF_LO_OPEN = 1u << 1,    /* lo itself is out of range */
    LR_FF_HI_OPEN = 1u << 2,
    LR_FF_HI_QUIET = 1u << 3,   /* hi is a sanity bound, named only when it is exceeded */
    LR_FF_ZERO_DEFAULT = 1u << 4, /* 0 means the default, in the file and in a change */
    LR_FF_COORD = 1u << 5,      /* a position: finite, within 1e6 mm of the origin */
    LR_FF_UNIT = 1u << 6,       /* a direction: non-zero, normalised by the check */
    LR_FF_ANGLES = 1u << 7,     /* angles: finite (within 1e6 degrees) */
    LR_FF_INVERT = 1u << 8,     /* a bool stored negated (normalize -> sd_raw) */
    LR_FF_ZERO_FLAG = 1u << 9,  /* 0 is a shape, not the default: sets the bool at aux */
    LR_FF_NO_SET = 1u << 10,    /* not a run-time parameter (names, types, mesh type) */
    LR_FF_ZERO_ABSENT = 1u << 11, /* 0 means "not given": outside the range's check */
};

/* No bound. */
#define LR_FNONE NAN

typedef struct lr_field {
    const char *key;        /* as in the file: "intensity", "flicker.amplitude" */
    enum lr_ftype type;
    unsigned kinds;         /* bit (1 << kind) of each record kind that has it; 0: every kind */
    size_t off;             /* of the value in the record */
    double lo, hi;          /* range (LR_FNONE: no bound; both 0: none); per component */
    unsigned flags;         /* LR_FF_* */
    unsigned check_kinds;   /* the range applies to these kinds only; 0: to every kind */
    double dflt[3];         /* default, set before reading; components for vectors */
    const char *dflt_text;  /* the default in words when the number is not it ("auto") */
    const char *unit;       /* after the range in messages and the reference: "(W/sr)", "mm" */
    unsigned dirty;         /* lr_dirty bits of a change */
    const char *const *names; /* ENUM, ENUMB: NULL-terminated */
    size_t aux;             /* ZERO_FLAG: offset of its bool */
    const char *help;       /* one line */
} lr_field;

typedef struct lr_record_desc {
    const char *section;            /* "lights[i]", for the reference */
    const char *what;               /* "a light", for messages when kinds are not named */
    const char *const *kind_names;  /* "point", "spot", ... (NULL-terminated); NULL: no kinds */
    const char *const *kind_what;   /* "a point light", ... for messages */
    int (*kind_of)(const void *rec);/* the kind of a record; NULL: 0 */
    const char *const *objects;     /* nested objects of dotted keys ("flicker"); NULL-terminated */
    const lr_field *fields;
    int n;
} lr_record_desc;

extern const lr_record_desc lr_scene_light_desc, lr_scene_camera_desc, lr_scene_receiver_desc,
    lr_scene_object_desc, lr_scene_mesh_desc, lr_scene_transform_desc, lr_scene_render_desc,
    lr_scene_quality_desc;

/* The value at offset off of a record. */
static inline void *lr_field_ptr(void *rec, size_t off)
{
    return (char *)rec + off;
}

/* "a, b or c" (last: " or ") of a NULL-terminated list. */
void lr_field_names_text(const char *const *names, const char *last, char *buf, size_t cap);

/* Whether f belongs to records of this kind. */
bool lr_field_has(const lr_field *f, int kind);
/* The field with this key for this kind, NULL when none. */
const lr_field *lr_field_find(const lr_record_desc *d, int kind, const char *key);

/* Sets every field of the table to its default, those of other kinds included (a point light
 * still has a valid direction); other memory is untouched. */
void lr_fields_defaults(const lr_record_desc *d, void *rec);

/* The keys a file object of this kind may hold (first components: "flicker" for
 * "flicker.amplitude"), plus "type" and "name" when the table has them; out has cap entries
 * and ends with NULL. */
void lr_fields_keys(const lr_record_desc *d, int kind, const char *prefix, const char **out,
                    int cap);

/* Reads the kind's fields from a JSON object (the ones of types the table can read; NAME,
 * TYPE and OBJECT fields are left to the caller): required ones must be present, the others
 * keep their value when absent. Fields "a.b" are read from the object "a" (whose keys are
 * checked). Messages are "FILE:LINE: field 'WHERE.KEY': ...". */
int lr_fields_read(const lr_json *j, lr_jnode obj, const char *where, const lr_record_desc *d,
                   int kind, void *rec, lr_err *e);

/* Checks the ranges (and COORD / UNIT / ANGLES) of the kind's fields in table order; on a
 * failure *field is the key and the message has no location. UNIT vectors are normalised. */
int lr_fields_check(const lr_record_desc *d, void *rec, const char **field, lr_err *e);

/* One run-time get or set of a field from or to text (lr_scene_set's value syntax): set
 * writes value into rec (no range check: the caller runs the record check), get writes the
 * value into buf. Errors are "KEY: what". */
typedef struct lr_field_op {
    bool get;
    const char *key;   /* the whole key, for messages */
    const char *value; /* set */
    char *buf;         /* get */
    size_t cap;
    lr_err *e;
} lr_field_op;
int lr_field_apply(lr_field_op *o, const lr_field *f, void *rec);
/* A set's error "KEY: message" (returns code); a get's value into o->buf (an error when it
 * does not fit). Shared by field_value.c and set.c's non-table fields. */
int lr_field_fail(lr_field_op *o, int code, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
int lr_field_out(lr_field_op *o, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* The "a point light has no parameter 'x' (known: ...)" error, the known list from the table
 * (settable fields of the kind; "flicker.{amplitude, ...}" groups one prefix). */
int lr_fields_unknown(lr_field_op *o, const lr_record_desc *d, int kind, const char *field);

/* The range as text: "in (0, 90)", ">= 0", "between 1 and 256"; "" when none. */
void lr_field_range_text(const lr_field *f, char *buf, size_t cap);

#endif
