#include "firmware/version.h"

/* The Makefile passes VERSION's line as LR_VERSION (and rebuilds this file when it changes). */
#ifndef LR_VERSION
#error "LR_VERSION is defined by the Makefile from the VERSION file"
#endif

const char *lr_version(void) { return LR_VERSION; }
