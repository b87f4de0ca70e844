#include "tests/support/doc_block.h"

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "tests/support/fs.h"

void lr_test_doc_block(const char *path, const char *name, void (*write)(FILE *f))
{
    char *want = NULL;
    size_t want_len = 0;
    FILE *m = open_memstream(&want, &want_len);
    assert_non_null(m);
    write(m);
    fclose(m);

    size_t len;
    char *text = (char *)lr_test_read(path, &len);
    char begin[128], end[128];
    snprintf(begin, sizeof begin, "<!-- BEGIN %s -->\n", name);
    snprintf(end, sizeof end, "<!-- END %s -->", name);
    char *b = strstr(text, begin), *e = b ? strstr(b, end) : NULL;
    if (!b || !e)
        fail_msg("%s: no '%s' ... '%s' block", path, begin, end);
    b += strlen(begin);
    *e = '\0';
    if (strcmp(b, want) != 0) {
        char out[256];
        snprintf(out, sizeof out, "build/test/%s.md", name);
        FILE *f = fopen(out, "w");
        if (f) {
            fputs(want, f);
            fclose(f);
        }
        int line = 1;
        size_t i = 0;
        for (; b[i] && b[i] == want[i]; i++)
            line += b[i] == '\n';
        fail_msg("%s: block '%s' differs from the tables at its line %d; the generated block is "
                 "in %s", path, name, line, out);
    }
    free(text);
    free(want);
}
