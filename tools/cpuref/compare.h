/* lamprig-cpuref's --compare (compare.c). */
#ifndef LR_CPUREF_COMPARE_H
#define LR_CPUREF_COMPARE_H

#include <stdio.h>

#include "render/image/image.h"
#include "render/scene/scene.h"

int lr_cpuref_compare(const lr_scene *s, const lr_image *img, const char *ref_path, FILE *out,
                      lr_err *e);

#endif
