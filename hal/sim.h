/* lamprig hal — sim: a timestamped script of control events, for headless demos and tests.
 *
 * Script (text, one event per line; '#' starts a comment; blank lines are skipped):
 *
 *     # time(s)  control          kind      value
 *     0.000      knob1            delta     +3
 *     0.250      dimmer           absolute  0.75
 *     1.0        button1          press            # value optional: press 1, release 0
 *     1.1        button1          release
 *     2.0        modbus/dimmer    absolute  0.5    # SOURCE/CONTROL speaks for another device
 *     4.0        end                               # optional: the script's length (for loop)
 *
 * Times are seconds from the start of playback, non-decreasing. Names are 1..31 characters of
 * [A-Za-z0-9_.-]. kind is delta | absolute | press | release; values are finite numbers.
 * Errors name the file and line: "configs/sim/demo.sim:7: unknown kind 'dleta' (...)".
 *
 * Playback needs no fd: lr_dev_next_deadline is the time of the next event, and dispatch emits
 * every event due by `now`, stamped with its scripted time (start + t), so timing does not
 * depend on how late the loop woke up. After the last event the device is DONE, or with `loop`
 * starts over (period: the `end` time if given, else the last event's time; a period of 0 does
 * not loop).
 */
#ifndef LR_HAL_SIM_H
#define LR_HAL_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "hal/dev.h"
#include "hal/event.h"
#include "hal/opt.h"
#include "render/base/err.h"

/* ---- the script, pure ---- */

typedef struct lr_sim_script lr_sim_script;

/* Parses text; `filename` only names the source in errors (NULL: "<script>"). */
int lr_sim_script_parse(const char *text, const char *filename, lr_sim_script **out, lr_err *e);
/* Reads and parses a file; LR_EIO naming the path when it cannot be read. */
int lr_sim_script_load(const char *path, lr_sim_script **out, lr_err *e);
void lr_sim_script_destroy(lr_sim_script *s);
int lr_sim_script_count(const lr_sim_script *s);
/* Event i (0-based); t_ns is its offset from the start of the script. source is "" when the
 * line did not name one. false when i is out of range. */
bool lr_sim_script_get(const lr_sim_script *s, int i, lr_event *out);
/* Script length: the `end` line's time, else the last event's time. */
int64_t lr_sim_script_length_ns(const lr_sim_script *s);

/* ---- the device ---- */

typedef struct lr_sim_desc {
    lr_dev_desc dev;     /* name default "sim": the source of events whose line names none */
    const char *path;    /* the script file, or */
    const char *text;    /* the script itself (path, if also given, only names it in errors) */
    int64_t start_ns;    /* CLOCK_MONOTONIC time of script time 0; 0 means the time of create */
    bool loop;           /* start over after the end */
} lr_sim_desc;

/* The options above as the rig config reads them (hal/opt.h); script and text: exactly one. */
enum { LR_SIM_OPT_SCRIPT = 0, LR_SIM_OPT_TEXT, LR_SIM_OPT_LOOP };
extern const lr_opt lr_sim_opts[];

typedef struct lr_sim lr_sim;

/* Fails (LR_EIO / LR_EPARSE naming file:line) on a bad script, whatever dev.required says:
 * a script is configuration, not hardware. */
int lr_sim_create(const lr_sim_desc *desc, lr_sim **out, lr_err *e);
void lr_sim_destroy(lr_sim *s);
lr_dev *lr_sim_dev(lr_sim *s);
/* Events played so far (all loops). */
uint64_t lr_sim_played(const lr_sim *s);

#endif
