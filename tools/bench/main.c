/* lamprig-bench: `lamprig-bench` runs every section; `lamprig-bench NAME...` runs those;
 * `lamprig-bench --list` lists them. Output is markdown, ready for the README. */
#include "tools/bench/bench.h"

#include <string.h>

static const lrb_section *const sections[] = {
    &lrb_optics_section,
};
#define NSECTIONS (sizeof sections / sizeof sections[0])

static const lrb_section *find(const char *name)
{
    for (size_t k = 0; k < NSECTIONS; k++)
        if (strcmp(sections[k]->name, name) == 0)
            return sections[k];
    return NULL;
}

int main(int argc, char **argv)
{
    if (argc >= 2 && (!strcmp(argv[1], "--list") || !strcmp(argv[1], "--help") ||
                      !strcmp(argv[1], "-h"))) {
        printf("usage: lamprig-bench [SECTION...]\n\nsections:\n");
        for (size_t k = 0; k < NSECTIONS; k++)
            printf("  %-10s %s\n", sections[k]->name, sections[k]->summary);
        return 0;
    }
    for (int i = 1; i < argc; i++)
        if (!find(argv[i])) {
            fprintf(stderr, "lamprig-bench: unknown section '%s' (see --list)\n", argv[i]);
            return 2;
        }
    int status = 0;
    if (argc < 2) {
        for (size_t k = 0; k < NSECTIONS; k++)
            if (sections[k]->run(stdout))
                status = 1;
    } else {
        for (int i = 1; i < argc; i++)
            if (find(argv[i])->run(stdout))
                status = 1;
    }
    return status;
}
