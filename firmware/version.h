/* lamprig — the program's version, from one place: the VERSION file at the top of the tree,
 * compiled into firmware/version.c by the Makefile. */
#ifndef LR_VERSION_H
#define LR_VERSION_H

/* "0.1.0" (the VERSION file's one line). */
const char *lr_version(void);

#endif
