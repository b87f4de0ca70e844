/* lamprig tests — a headless GL context for tests that need the driver. */
#ifndef LR_TEST_GL_H
#define LR_TEST_GL_H

#include "render/gl/gl.h"

/* Creates a surfaceless context (lr_gl_create with the defaults) and pins the driver
 * libraries in memory (lr_test_pin_libraries). On failure prints the message to stderr and
 * returns the error code; for cmocka setup functions. */
int lr_test_gl_create(lr_gl **out);

/* Marks every shared library loaded so far RTLD_NODELETE. Done after every eglInitialize in a
 * test binary (tests/support/gl.c defines it over libEGL's), so any context creation pins. Mesa dlcloses its driver at
 * eglTerminate; leaks inside the driver would then be reported from "<unknown module>" and
 * tests/lsan.supp could not name them. Pinned, they keep their library name and stay
 * suppressed, while leaks in our own code are reported as ever. */
void lr_test_pin_libraries(void);

/* The cmocka group fixture most GL tests share: declares the file's context VAR and defines
 * static setup() (lr_test_gl_create into VAR; -1 on failure) and teardown() (destroys it), for
 * cmocka_run_group_tests(tests, setup, teardown). One context per binary: creating one costs
 * far more than a test under ASan on llvmpipe. */
#define LR_TEST_GL_FIXTURE(var)                                                                \
    static lr_gl *var;                                                                         \
    static int setup(void **state)                                                             \
    {                                                                                          \
        (void)state;                                                                           \
        return lr_test_gl_create(&var) ? -1 : 0;                                               \
    }                                                                                          \
    static int teardown(void **state)                                                          \
    {                                                                                          \
        (void)state;                                                                           \
        lr_gl_destroy(var);                                                                    \
        var = NULL;                                                                            \
        return 0;                                                                              \
    }

#endif
