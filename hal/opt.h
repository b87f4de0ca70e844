/* lamprig hal — option descriptors: every field a back end takes from its descriptor, with its
 * type, range and default, described once. The back ends validate with them (lr_opt_hal_ok),
 * the rig config (firmware/rig/config.c) reads its device objects through them, and
 * firmware/README.md's device table is generated from them (a test compares the two), so a
 * range is one number in one place.
 *
 * Integers: a descriptor field of 0 means "the default" to the back end (zero-initialised
 * descriptors work); any other value must lie in lo..hi. The rig config accepts lo..hi. */
#ifndef LR_HAL_OPT_H
#define LR_HAL_OPT_H

#include <stdbool.h>

typedef enum lr_opt_type {
    LR_OPT_INT = 0,
    LR_OPT_BOOL,
    LR_OPT_STRING, /* a name, a path, a URL */
    LR_OPT_ENUM,   /* one of names[], stored as its index */
    LR_OPT_HEX16,  /* a USB id as a hex string, "077d" */
    LR_OPT_LIST,   /* an array of objects with options of their own (documentation only) */
    LR_OPT_OBJECT, /* an object with options of its own (documentation only) */
} lr_opt_type;

typedef struct lr_opt {
    const char *key;
    lr_opt_type type;
    long lo, hi;              /* LR_OPT_INT: accepted range */
    long dflt;                /* int; bool 0/1; enum index */
    const char *dflt_text;    /* string default ("gpiochip0"); NULL: none */
    const char *const *names; /* LR_OPT_ENUM: NULL-terminated */
    bool required;
    const char *help;         /* one line, for the documentation */
} lr_opt;

/* An options table: a NULL key ends it. */
#define LR_OPT_END {0}

/* v in o->lo..o->hi. */
bool lr_opt_in_range(const lr_opt *o, long v);
/* What a back end accepts: 0 (the default) or lo..hi. */
bool lr_opt_hal_ok(const lr_opt *o, long v);
/* v, or the default when v is 0. */
long lr_opt_or_default(const lr_opt *o, long v);
/* Index of name in o->names, -1 when absent. */
int lr_opt_enum_index(const lr_opt *o, const char *name);
/* The entry with that key in a table, NULL when none. */
const lr_opt *lr_opt_find(const lr_opt *table, const char *key);

#endif
