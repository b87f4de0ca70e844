/* lamprig tests — generated reference blocks in the READMEs. */
#ifndef LR_TEST_DOC_BLOCK_H
#define LR_TEST_DOC_BLOCK_H

#include <stdio.h>

/* Fails the test unless the README at path quotes exactly what write(f) produces between
 * "<!-- BEGIN name -->\n" and "<!-- END name -->". On a difference the expected block is
 * written to build/test/name.md (paste it into the README) and the first differing line is
 * named. */
void lr_test_doc_block(const char *path, const char *name, void (*write)(FILE *f));

#endif
