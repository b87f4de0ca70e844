/* lamprig tests — the include graph between the tree's folders, checked against the layers
 * that docs/layers.txt declares.
 *
 * docs/layers.txt lists the layers from the bottom up, one per line: a name, then the folders
 * in it ("render/core"; "tools/" followed by a star stands for every folder below tools/). A
 * source file (.c, .h, .cpp, .hpp) may include a header of its own folder, of a folder in its
 * own layer or of any layer below, never of a layer above; and the graph of includes between
 * folders has no cycle, inside a layer either. A folder that holds sources but is in no layer is a problem too,
 * so a new folder has to be placed before it builds into the tree. */
#ifndef LR_TEST_INCLUDE_GRAPH_H
#define LR_TEST_INCLUDE_GRAPH_H

#include <stddef.h>

/* Scans the sources below root (build/ and dot-folders skipped), resolving each
 * `#include "X"` from root, then from the including file's folder (an include that resolves
 * to no file of the tree, a system header, is not an edge). Writes one line per problem to
 * report (at most cap bytes, always terminated), each naming the file and line:
 *   render/core/x.c:12: includes render/cpu/frame.h: layer "shared" includes "estimators" above it
 *   render/foo: holds sources but is in no layer of docs/layers.txt
 *   cycle: render/a -> render/b -> render/a (render/a/x.h:3, render/b/y.h:5)
 * Returns the number of problems, or -1 when root or the layers file cannot be read (the
 * reason in report). */
int lr_test_check_layers(const char *root, const char *layers_path, char *report, size_t cap);

#endif
