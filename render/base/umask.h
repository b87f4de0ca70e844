/* lamprig — the process's file mode creation mask, read without changing it.
 *
 * umask(2) can only be read by setting it (umask(x) then umask(old)), and a file another
 * thread creates in between gets the wrong mode. Linux (4.7 and later) reports the mask in
 * /proc/self/status ("Umask:\t0022"); that is read instead, each time (the mask may change
 * while the process runs, and holding it would be global state). */
#ifndef LR_UMASK_H
#define LR_UMASK_H

#include <sys/types.h>

/* The current umask; 0077 when /proc/self/status cannot be read or has no Umask line (then
 * files are made for their owner only, as mkstemp makes them). */
mode_t lr_umask_get(void);

#endif
