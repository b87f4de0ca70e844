/* lamprig tests — model-id comparisons outside render/models/.
 *
 * render/models/model.h: code outside a model's folder asks the model's ops table and never
 * compares an id. This scans the sources below root (.c, .h, .cpp, .hpp and the GLSL files
 * .glsl, .vert, .frag, .comp; build/, tests/, dot-folders and render/models/ skipped) for a
 * comparison with an LR_SSS_ id, across line breaks too: `== LR_SSS_X`, `!= LR_SSS_X`,
 * `LR_SSS_X ==`, `LR_SSS_X !=` and `case LR_SSS_X`. */
#ifndef LR_TEST_MODEL_IDS_H
#define LR_TEST_MODEL_IDS_H

#include <stddef.h>

/* Writes one line per comparison ("render/x/y.c:12: compares a model id: == LR_SSS_MULTIPOLE")
 * to report (at most cap bytes, always terminated). Returns their number, or -1 when root
 * cannot be read. */
int lr_test_check_model_ids(const char *root, char *report, size_t cap);

#endif
