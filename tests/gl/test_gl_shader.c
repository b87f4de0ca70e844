/* Shader files: assembly (header, defines, includes), the line map, and compile/link errors
 * that name the file and line — checked with deliberately broken shaders in a temp dir. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl/gl.h"
#include "render/gl/shader.h"
#include "tests/support/fs.h"
#include "tests/support/gl.h"

typedef struct fixture {
    char *dir;
    lr_gl *gl;
} fixture;

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    f->dir = lr_test_tmpdir();
    if (lr_test_gl_create(&f->gl))
        return -1;
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    lr_gl_destroy(f->gl);
    lr_test_rmtree(f->dir);
    free(f);
    return 0;
}

static int count(const char *hay, const char *needle)
{
    int n = 0;
    for (const char *p = hay; (p = strstr(p, needle)) != NULL; p++)
        n++;
    return n;
}

/* ---- assembly ---------------------------------------------------------------------------- */

static void source_has_header_defines_and_line_map(void **state)
{
    fixture *f = *state;
    free(lr_test_write(f->dir, "lib/optics.glsl", "float f1(float x) { return x; }\n"
                                                  "float f2(float x) { return x * x; }\n", (size_t)-1));
    char *main_path = lr_test_write(f->dir, "a.frag",
                                    "out vec4 o;\n"             /* 1 */
                                    "#include \"lib/optics.glsl\"\n" /* 2 */
                                    "void main() { o = vec4(N); }\n", /* 3 */
                                    (size_t)-1);
    const char *defines[] = {"N 4.0", "FLAG", "K=8", NULL};
    lr_shader_source *src = NULL;
    lr_err e = {0};
    if (lr_shader_source_load(main_path, LR_STAGE_FRAGMENT, defines, &src, &e))
        fail_msg("%s", e.msg);
    const char *text = lr_shader_source_text(src);
    assert_int_equal(strncmp(text, "#version 310 es\n#define LR_FRAGMENT_SHADER 1\n", 45), 0);
    assert_non_null(strstr(text, "\n#define N 4.0\n#define FLAG\n#define K 8\n"));
    assert_non_null(strstr(text, "precision highp float;\n"));
    assert_non_null(strstr(text, "precision highp sampler2DArray;\n"));
    assert_null(strstr(text, "#include"));

    /* Prelude: version, stage, 10 precision lines, 3 defines. */
    int pre = lr_shader_source_prelude_lines(src);
    assert_int_equal(pre, 2 + 10 + 3);
    const char *file;
    int line;
    assert_int_equal(lr_shader_source_locate(src, 1, &file, &line), 0);
    assert_string_equal(file, "<prelude>");
    assert_int_equal(line, 1);
    assert_int_equal(lr_shader_source_locate(src, pre + 1, &file, &line), 0);
    assert_string_equal(file, main_path);
    assert_int_equal(line, 1);
    char *inc_path = lr_test_path(f->dir, "lib/optics.glsl");
    assert_int_equal(lr_shader_source_locate(src, pre + 3, &file, &line), 0);
    assert_string_equal(file, inc_path);
    assert_int_equal(line, 2);
    assert_int_equal(lr_shader_source_locate(src, pre + 4, &file, &line), 0);
    assert_string_equal(file, main_path);
    assert_int_equal(line, 3);
    assert_int_equal(lr_shader_source_locate(src, pre + 5, &file, &line), -1);
    assert_int_equal(lr_shader_source_locate(src, 0, &file, &line), -1);
    lr_shader_source_free(src);
    free(inc_path);
    free(main_path);
}

static void each_file_is_included_once(void **state)
{
    fixture *f = *state;
    /* Diamond (a -> b, a -> c, b -> d, c -> d) and a cycle (d -> a). */
    free(lr_test_write(f->dir, "d.glsl", "#include \"a.frag\"\nfloat d_marker;\n", (size_t)-1));
    free(lr_test_write(f->dir, "b.glsl", "# include \"d.glsl\"\n", (size_t)-1));
    free(lr_test_write(f->dir, "sub/c.glsl", "#include \"../d.glsl\" // shared\n", (size_t)-1));
    char *a = lr_test_write(f->dir, "a.frag", "#include \"b.glsl\"\n#include \"sub/c.glsl\"\n",
                            (size_t)-1);
    lr_shader_source *src = NULL;
    lr_err e = {0};
    if (lr_shader_source_load(a, LR_STAGE_FRAGMENT, NULL, &src, &e))
        fail_msg("%s", e.msg);
    assert_int_equal(count(lr_shader_source_text(src), "float d_marker;"), 1);
    lr_shader_source_free(src);
    free(a);
}

static void loader_errors_name_file_and_line(void **state)
{
    fixture *f = *state;
    lr_shader_source *src = NULL;
    lr_err e = {0};
    char *v = lr_test_write(f->dir, "v.frag", "// comment\n#version 300 es\n", (size_t)-1);
    assert_int_equal(lr_shader_source_load(v, LR_STAGE_FRAGMENT, NULL, &src, &e), LR_EPARSE);
    assert_null(src);
    char want[512];
    snprintf(want, sizeof want, "%s:2: #version is added by the shader loader; remove it", v);
    assert_string_equal(e.msg, want);

    char *m = lr_test_write(f->dir, "m.frag", "\n\n#include \"nope.glsl\"\n", (size_t)-1);
    assert_int_equal(lr_shader_source_load(m, LR_STAGE_FRAGMENT, NULL, &src, &e), LR_EIO);
    snprintf(want, sizeof want, "%s:3: include: %s/nope.glsl: cannot open: No such file or directory",
             m, f->dir);
    assert_string_equal(e.msg, want);

    char *b = lr_test_write(f->dir, "b.frag", "#include <x.glsl>\n", (size_t)-1);
    assert_int_equal(lr_shader_source_load(b, LR_STAGE_FRAGMENT, NULL, &src, &e), LR_EPARSE);
    snprintf(want, sizeof want, "%s:1: malformed #include (expected #include \"file\")", b);
    assert_string_equal(e.msg, want);

    const char *bad_define[] = {"A 1\nvoid x;", NULL};
    assert_int_equal(lr_shader_source_load(b, LR_STAGE_FRAGMENT, bad_define, &src, &e), LR_EPARSE);
    assert_non_null(strstr(e.msg, "contains a line break"));

    assert_int_equal(lr_shader_source_load("/nonexistent/x.frag", LR_STAGE_FRAGMENT, NULL, &src, &e),
                     LR_EIO);
    assert_string_equal(e.msg, "/nonexistent/x.frag: cannot open: No such file or directory");
    free(v);
    free(m);
    free(b);
}

static void driver_log_formats_are_mapped(void **state)
{
    fixture *f = *state;
    free(lr_test_write(f->dir, "inc.glsl", "x\ny\nz\n", (size_t)-1));
    char *p = lr_test_write(f->dir, "s.frag", "a\n#include \"inc.glsl\"\nb\n", (size_t)-1);
    lr_shader_source *src = NULL;
    lr_err e = {0};
    if (lr_shader_source_load(p, LR_STAGE_FRAGMENT, NULL, &src, &e))
        fail_msg("%s", e.msg);
    int pre = lr_shader_source_prelude_lines(src);
    char *inc = lr_test_path(f->dir, "inc.glsl");
    char log[512], out[1024], want[1024];

    /* Mesa: assembled line pre+3 is inc.glsl line 2. */
    snprintf(log, sizeof log, "0:%d(7): error: `q' undeclared\n0:%d(1): error: syntax error\n",
             pre + 3, pre + 5);
    assert_int_equal(lr_shader_source_map_log(src, log, "\n", out, sizeof out), 2);
    snprintf(want, sizeof want, "%s:2:7: error: `q' undeclared\n%s:3:1: error: syntax error", inc, p);
    assert_string_equal(out, want);

    /* ANGLE / Mali / Adreno. */
    snprintf(log, sizeof log, "ERROR: 0:%d: 'q' : undeclared identifier\nERROR: 1 compilation errors.  No code generated.\n",
             pre + 1);
    assert_int_equal(lr_shader_source_map_log(src, log, "; ", out, sizeof out), 1);
    snprintf(want, sizeof want, "%s:1: error: 'q' : undeclared identifier; %s: ERROR: 1 compilation errors.  No code generated.", p, p);
    assert_string_equal(out, want);

    /* NVIDIA. */
    snprintf(log, sizeof log, "0(%d) : error C1008: undefined variable \"q\"", pre + 4);
    assert_int_equal(lr_shader_source_map_log(src, log, "\n", out, sizeof out), 3);
    snprintf(want, sizeof want, "%s:3: error C1008: undefined variable \"q\"", inc);
    assert_string_equal(out, want);

    /* Output always fits and stays terminated. */
    char tiny[16];
    lr_shader_source_map_log(src, log, "\n", tiny, sizeof tiny);
    assert_int_equal(strlen(tiny), sizeof tiny - 1);
    lr_shader_source_free(src);
    free(inc);
    free(p);
}

/* ---- compile and link on the driver ---------------------------------------------------- */

static void compile_error_names_file_and_line(void **state)
{
    fixture *f = *state;
    char *vs = lr_test_write(f->dir, "ok.vert", "void main() { gl_Position = vec4(0.0); }\n",
                             (size_t)-1);
    char *fs = lr_test_write(f->dir, "broken.frag",
                             "out vec4 o;\n"
                             "\n"
                             "void main()\n"
                             "{\n"
                             "    o = vec4(undeclared_thing);\n" /* line 5 */
                             "}\n",
                             (size_t)-1);
    lr_program *prog = (lr_program *)1;
    lr_err e = {0};
    assert_int_equal(lr_program_create(&(lr_program_desc){.vertex = vs, .fragment = fs}, &prog, &e),
                     LR_EGL);
    assert_null(prog);
    char want[512];
    print_message("%s\n", e.msg);
    snprintf(want, sizeof want, "%s:5:", fs);
    if (strncmp(e.msg, want, strlen(want)) != 0)
        fail_msg("expected \"%s...\", got \"%s\"", want, e.msg);
    assert_non_null(strstr(e.msg, "undeclared_thing"));
    free(vs);
    free(fs);
}

static void compile_error_in_include_names_included_file(void **state)
{
    fixture *f = *state;
    free(lr_test_write(f->dir, "shaders/lib/optics.glsl",
                       "// optics\n"
                       "float fresnel(float c) { return c; }\n"
                       "float broken(float x) { return x +* 2.0; }\n", /* line 3 */
                       (size_t)-1));
    free(lr_test_write(f->dir, "shaders/pass.frag",
                       "#include \"lib/optics.glsl\"\n"
                       "out vec4 o;\n"
                       "void main() { o = vec4(fresnel(0.5)); }\n",
                       (size_t)-1));
    free(lr_test_write(f->dir, "shaders/pass.vert", "void main() { gl_Position = vec4(0.0); }\n",
                       (size_t)-1));
    char *dir = lr_test_path(f->dir, "shaders");
    lr_program *prog = NULL;
    lr_err e = {0};
    lr_program_desc d = {.vertex = "pass.vert", .fragment = "pass.frag", .dir = dir};
    assert_int_equal(lr_program_create(&d, &prog, &e), LR_EGL);
    char want[512];
    print_message("%s\n", e.msg);
    snprintf(want, sizeof want, "%s/lib/optics.glsl:3:", dir);
    if (strncmp(e.msg, want, strlen(want)) != 0)
        fail_msg("expected \"%s...\", got \"%s\"", want, e.msg);
    free(dir);
}

static void vertex_error_and_defines(void **state)
{
    fixture *f = *state;
    /* The define decides whether the shader compiles: defines reach the source, and an error
     * past them is still counted from the file's first line. */
    char *vs = lr_test_write(f->dir, "d.vert",
                             "#ifndef GOOD\n"
                             "#error GOOD not defined\n" /* line 2 */
                             "#endif\n"
                             "void main() { gl_Position = vec4(GOOD); }\n",
                             (size_t)-1);
    char *fs = lr_test_write(f->dir, "d.frag", "out vec4 o;\nvoid main() { o = vec4(1.0); }\n",
                             (size_t)-1);
    lr_program *prog = NULL;
    lr_err e = {0};
    assert_int_equal(lr_program_create(&(lr_program_desc){.vertex = vs, .fragment = fs}, &prog, &e),
                     LR_EGL);
    char want[512];
    print_message("%s\n", e.msg);
    snprintf(want, sizeof want, "%s:2:", vs);
    if (strncmp(e.msg, want, strlen(want)) != 0)
        fail_msg("expected \"%s...\", got \"%s\"", want, e.msg);

    const char *defs[] = {"GOOD=0.5", NULL};
    if (lr_program_create(&(lr_program_desc){.vertex = vs, .fragment = fs, .defines = defs}, &prog, &e))
        fail_msg("%s", e.msg);
    assert_true(lr_program_id(prog) != 0);
    assert_int_equal(lr_program_uniform(prog, "no_such_uniform"), -1);
    lr_program_destroy(prog);
    free(vs);
    free(fs);
}

static void link_error_names_both_files(void **state)
{
    fixture *f = *state;
    /* The fragment shader reads a varying the vertex shader never writes. */
    char *vs = lr_test_write(f->dir, "l.vert", "void main() { gl_Position = vec4(0.0); }\n", (size_t)-1);
    char *fs = lr_test_write(f->dir, "l.frag", "in vec3 v_missing;\nout vec4 o;\n"
                                               "void main() { o = vec4(v_missing, 1.0); }\n",
                             (size_t)-1);
    lr_program *prog = NULL;
    lr_err e = {0};
    assert_int_equal(lr_program_create(&(lr_program_desc){.vertex = vs, .fragment = fs}, &prog, &e),
                     LR_EGL);
    char want[512];
    print_message("%s\n", e.msg);
    snprintf(want, sizeof want, "link %s + %s: ", vs, fs);
    if (strncmp(e.msg, want, strlen(want)) != 0)
        fail_msg("expected \"%s...\", got \"%s\"", want, e.msg);
    assert_non_null(strstr(e.msg, "v_missing"));
    assert_null(strchr(e.msg, '\n'));
    free(vs);
    free(fs);
}

static void compute_shader_and_bad_desc(void **state)
{
    fixture *f = *state;
    char *cs = lr_test_write(f->dir, "k.comp",
                             "layout(local_size_x = 8) in;\n"
                             "layout(std430, binding = 0) buffer B { float v[]; };\n"
                             "void main() { v[gl_GlobalInvocationID.x] = 2.0; }\n",
                             (size_t)-1);
    lr_program *prog = NULL;
    lr_err e = {0};
    if (lr_program_create(&(lr_program_desc){.compute = cs}, &prog, &e))
        fail_msg("%s", e.msg);
    lr_program_destroy(prog);
    assert_int_equal(lr_program_create(&(lr_program_desc){.compute = cs, .vertex = cs}, &prog, &e),
                     LR_EINVAL);
    assert_int_equal(lr_program_create(&(lr_program_desc){.fragment = cs}, &prog, &e), LR_EINVAL);
    free(cs);
}

static void project_shaders_compile(void **state)
{
    /* Every shader shipped under render/shaders/ that can stand alone. */
    lr_program *prog = NULL;
    lr_err e = {0};
    char *fs = lr_test_write(((fixture *)*state)->dir, "uv.frag",
                             "in vec2 v_uv;\nout vec4 o;\nvoid main() { o = vec4(v_uv, 0.0, 1.0); }\n",
                             (size_t)-1);
    lr_program_desc d = {.vertex = "render/shaders/fullscreen.vert", .fragment = fs};
    if (lr_program_create(&d, &prog, &e))
        fail_msg("%s", e.msg);
    lr_program_destroy(prog);
    free(fs);
}

/* ---- uniforms the C side sets ------------------------------------------------------------- */

/* A uniform the shaders do not declare (a misspelling in C) is an error naming the program
 * and the uniform; one the compiler dropped as unused is not (location -1, nothing to set). */
static void undeclared_uniform_is_an_error(void **state)
{
    fixture *f = *state;
    char *vs = lr_test_write(f->dir, "u.vert",
                             "uniform mat4 u_vp;\n"
                             "void main() { gl_Position = u_vp * vec4(0.0, 0.0, 0.0, 1.0); }\n",
                             (size_t)-1);
    char *fs = lr_test_write(f->dir, "u.frag",
                             "uniform highp sampler2D u_src;\n"
                             "uniform vec3 u_w[4], u_unused;\n" /* u_unused: dropped */
                             "uniform float u_exposure; // uniform float u_in_comment;\n"
                             "/* uniform float u_in_block_comment; */\n"
                             "out vec4 o;\n"
                             "void main() { o = texture(u_src, vec2(0.5)) * u_exposure"
                             " + vec4(u_w[2], 0.0); }\n",
                             (size_t)-1);
    lr_program *prog = NULL;
    lr_err e = {0};
    if (lr_program_create(&(lr_program_desc){.vertex = vs, .fragment = fs}, &prog, &e))
        fail_msg("%s", e.msg);
    /* Declared and used: a location, no error. */
    assert_true(lr_program_uniform(prog, "u_exposure") >= 0);
    assert_true(lr_program_uniform(prog, "u_vp") >= 0);
    assert_true(lr_program_uniform(prog, "u_src") >= 0);
    assert_true(lr_program_uniform(prog, "u_w[2]") >= 0);
    /* Declared, unused: the driver may drop it; either way not an error. */
    lr_program_uniform(prog, "u_unused");
    assert_true(lr_program_declares(prog, "u_unused"));
    assert_int_equal(lr_program_check(prog, &e), LR_OK);
    /* Misspelt, or only in a comment: -1 and an error at the check, naming both. */
    assert_int_equal(lr_program_uniform(prog, "u_exposrue"), -1);
    assert_int_equal(lr_program_uniform(prog, "u_in_comment"), -1);
    assert_false(lr_program_declares(prog, "u_in_block_comment"));
    assert_int_equal(lr_program_check(prog, &e), LR_EINVAL);
    print_message("%s\n", e.msg);
    assert_non_null(strstr(e.msg, "u.vert + "));
    assert_non_null(strstr(e.msg, "u.frag"));
    assert_non_null(strstr(e.msg, "u_exposrue")); /* the first one asked for */
    /* Reported once. */
    assert_int_equal(lr_program_check(prog, &e), LR_OK);
    lr_program_destroy(prog);
    free(vs);
    free(fs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(source_has_header_defines_and_line_map, setup, teardown),
        cmocka_unit_test_setup_teardown(each_file_is_included_once, setup, teardown),
        cmocka_unit_test_setup_teardown(loader_errors_name_file_and_line, setup, teardown),
        cmocka_unit_test_setup_teardown(driver_log_formats_are_mapped, setup, teardown),
        cmocka_unit_test_setup_teardown(compile_error_names_file_and_line, setup, teardown),
        cmocka_unit_test_setup_teardown(compile_error_in_include_names_included_file, setup, teardown),
        cmocka_unit_test_setup_teardown(vertex_error_and_defines, setup, teardown),
        cmocka_unit_test_setup_teardown(link_error_names_both_files, setup, teardown),
        cmocka_unit_test_setup_teardown(compute_shader_and_bad_desc, setup, teardown),
        cmocka_unit_test_setup_teardown(project_shaders_compile, setup, teardown),
        cmocka_unit_test_setup_teardown(undeclared_uniform_is_an_error, setup, teardown),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='cube*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
