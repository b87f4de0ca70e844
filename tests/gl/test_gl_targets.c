/* Float render targets, cube and array faces, readback, the fullscreen triangle and pass
 * timers, on the real driver (llvmpipe here). Images are tiny: llvmpipe under ASan is slow. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <GLES3/gl31.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/gl/gl.h"
#include "render/gl/shader.h"
#include "render/gl/tex.h"
#include "render/gl/timer.h"
#include "render/image/image.h"
#include "tests/support/fs.h"
#include "tests/support/gl.h"

typedef struct fixture {
    char *dir;
    lr_gl *gl;
    lr_program *constant; /* writes uniform u_value */
} fixture;

#define CHECK(call)                                                                                \
    do {                                                                                           \
        lr_err e_ = {0};                                                                           \
        lr_err *e = &e_;                                                                           \
        if ((call) != LR_OK)                                                                       \
            fail_msg("%s: %s", #call, e_.msg);                                                     \
    } while (0)

static lr_program *program(fixture *f, const char *name, const char *frag_src)
{
    char *fs = lr_test_write(f->dir, name, frag_src, (size_t)-1);
    lr_program *p = NULL;
    lr_err e = {0};
    if (lr_program_create(&(lr_program_desc){.vertex = "render/shaders/fullscreen.vert", .fragment = fs},
                          &p, &e))
        fail_msg("%s", e.msg);
    free(fs);
    return p;
}

static int setup(void **state)
{
    fixture *f = calloc(1, sizeof *f);
    f->dir = lr_test_tmpdir();
    if (lr_test_gl_create(&f->gl))
        return -1;
    f->constant = program(f, "const.frag", "uniform vec4 u_value;\nout vec4 o;\n"
                                           "void main() { o = u_value; }\n");
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = *state;
    lr_program_destroy(f->constant);
    lr_gl_destroy(f->gl);
    lr_test_rmtree(f->dir);
    free(f);
    return 0;
}

static void fill(fixture *f, lr_fb *fb, const float v[4])
{
    lr_fb_bind(fb);
    glUseProgram(lr_program_id(f->constant));
    glUniform4fv(lr_program_uniform(f->constant, "u_value"), 1, v);
    lr_gl_draw_fullscreen(f->gl);
}

static lr_tex *tex(fixture *f, lr_tex_desc d)
{
    lr_tex *t = NULL;
    CHECK(lr_tex_create(f->gl, &d, &t, e));
    return t;
}

static lr_fb *fb1(fixture *f, lr_tex *t, int layer)
{
    lr_fb *fb = NULL;
    CHECK(lr_fb_create(f->gl, &(lr_fb_desc){.color = {{t, layer}}}, &fb, e));
    return fb;
}

/* Values that 16-bit floats cannot hold exactly, across magnitudes, negative included. */
static const float probe[4] = {0.1f, 1.0f / 3.0f, -12345.678f, 3.0e-3f};

static void rgba32f_target_reads_back_exactly(void **state)
{
    fixture *f = *state;
    lr_tex *t = tex(f, (lr_tex_desc){.width = 5, .height = 3});
    lr_fb *fb = fb1(f, t, 0);
    fill(f, fb, probe);
    float px[5 * 3 * 4];
    CHECK(lr_fb_read(fb, 0, 0, 0, 5, 3, px, e));
    for (int i = 0; i < 15; i++)
        assert_memory_equal(&px[4 * i], probe, sizeof probe); /* bit-exact: fp32 end to end */
    lr_fb_destroy(fb);
    lr_tex_destroy(t);
}

static void rgba16f_target_rounds_to_half(void **state)
{
    fixture *f = *state;
    lr_tex *t = tex(f, (lr_tex_desc){.format = LR_TEX_RGBA16F, .width = 2, .height = 2});
    lr_fb *fb = fb1(f, t, 0);
    fill(f, fb, probe);
    float px[4 * 4];
    CHECK(lr_fb_read(fb, 0, 0, 0, 2, 2, px, e));
    for (int c = 0; c < 4; c++) {
        float v = probe[c], r = px[c];
        /* A half has a 10-bit stored mantissa: in the binade [2^k, 2^(k+1)) its spacing (one
         * ulp) is 2^(k-10). Conversion rounds to nearest (error <= ulp/2) or, as GLES also
         * allows, toward zero (error < ulp); one ulp covers both. All probes are normal
         * halves (6.1e-5 < |v| < 65504), so k is v's own exponent. */
        double ulp = ldexp(1.0, ilogb(v) - 10);
        if (fabs((double)r - (double)v) > ulp)
            fail_msg("channel %d: %.9g read back as %.9g, more than one half ulp (%.3g)", c, v, r, ulp);
        /* And it really was stored as a half: r is a multiple of its own ulp. */
        double m = (double)r / ldexp(1.0, ilogb(r) - 10);
        assert_true(m == floor(m));
        assert_true(r != v); /* none of the probes is a half */
        for (int i = 1; i < 4; i++)
            assert_true(px[4 * i + c] == r);
    }
    /* Exactly representable values survive unchanged. */
    const float exact[4] = {0.5f, -3.25f, 1024.0f, 0.0f};
    fill(f, fb, exact);
    CHECK(lr_fb_read(fb, 0, 1, 1, 1, 1, px, e));
    assert_memory_equal(px, exact, sizeof exact);
    lr_fb_destroy(fb);
    lr_tex_destroy(t);
}

static void r32f_target_and_mrt(void **state)
{
    fixture *f = *state;
    lr_tex *r = tex(f, (lr_tex_desc){.format = LR_TEX_R32F, .width = 3, .height = 2});
    lr_tex *rgba = tex(f, (lr_tex_desc){.width = 3, .height = 2});
    lr_program *p = program(f, "mrt.frag",
                            "uniform vec4 u_a, u_b;\n"
                            "layout(location = 0) out float o0;\n"
                            "layout(location = 1) out vec4 o1;\n"
                            "void main() { o0 = u_a.x; o1 = u_b; }\n");
    lr_fb *fb = NULL;
    CHECK(lr_fb_create(f->gl, &(lr_fb_desc){.color = {{r, 0}, {rgba, 0}}, .depth_buffer = true},
                       &fb, e));
    lr_fb_bind(fb);
    glUseProgram(lr_program_id(p));
    glUniform4f(lr_program_uniform(p, "u_a"), 0.7f, 9.0f, 9.0f, 9.0f);
    glUniform4f(lr_program_uniform(p, "u_b"), 1.5f, -2.5f, 1e-3f, 42.0f);
    lr_gl_draw_fullscreen(f->gl);
    float px[4];
    CHECK(lr_fb_read(fb, 0, 2, 1, 1, 1, px, e));
    const float want0[4] = {0.7f, 0.0f, 0.0f, 1.0f}; /* missing channels read as (0, 0, 1) */
    assert_memory_equal(px, want0, sizeof want0);
    CHECK(lr_fb_read(fb, 1, 0, 0, 1, 1, px, e));
    const float want1[4] = {1.5f, -2.5f, 1e-3f, 42.0f};
    assert_memory_equal(px, want1, sizeof want1);
    lr_fb_destroy(fb);
    lr_program_destroy(p);
    lr_tex_destroy(r);
    lr_tex_destroy(rgba);
}

static void fullscreen_triangle_covers_every_texel(void **state)
{
    fixture *f = *state;
    lr_program *p = program(f, "uv.frag", "in vec2 v_uv;\nout vec4 o;\n"
                                          "void main() { o = vec4(v_uv, 1.0, 1.0); }\n");
    lr_tex *t = tex(f, (lr_tex_desc){.width = 4, .height = 2});
    lr_fb *fb = fb1(f, t, 0);
    lr_fb_bind(fb);
    glClearColor(-1.0f, -1.0f, -1.0f, -1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glUseProgram(lr_program_id(p));
    lr_gl_draw_fullscreen(f->gl);
    float px[4 * 2 * 4];
    CHECK(lr_fb_read(fb, 0, 0, 0, 4, 2, px, e));
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 4; x++) {
            const float *q = &px[4 * (y * 4 + x)];
            /* v_uv at texel centres, row 0 at the bottom; interpolation error ~1 float ulp. */
            assert_float_equal(q[0], (x + 0.5f) / 4.0f, 1e-6f);
            assert_float_equal(q[1], (y + 0.5f) / 2.0f, 1e-6f);
            assert_true(q[3] == 1.0f); /* nothing left at the clear value */
        }
    lr_fb_destroy(fb);
    lr_tex_destroy(t);
    lr_program_destroy(p);
}

static void cube_faces_render_and_sample_independently(void **state)
{
    fixture *f = *state;
    lr_tex *cube = tex(f, (lr_tex_desc){.type = LR_TEX_CUBE, .width = 4});
    int w, h, layers;
    lr_tex_size(cube, &w, &h, &layers);
    assert_int_equal(h, 4);
    assert_int_equal(layers, 6);
    assert_int_equal(lr_tex_target(cube), GL_TEXTURE_CUBE_MAP);
    lr_fb *faces[6];
    for (int i = 0; i < 6; i++) {
        faces[i] = fb1(f, cube, i);
        fill(f, faces[i], (const float[4]){(float)i + 1.0f, 10.0f * (float)i, -0.25f * (float)i, 1.0f});
    }
    for (int i = 0; i < 6; i++) {
        float px[4 * 16];
        CHECK(lr_fb_read(faces[i], 0, 0, 0, 4, 4, px, e));
        const float want[4] = {(float)i + 1.0f, 10.0f * (float)i, -0.25f * (float)i, 1.0f};
        for (int k = 0; k < 16; k++)
            assert_memory_equal(&px[4 * k], want, sizeof want);
        lr_fb_destroy(faces[i]);
    }

    /* Sampling along +X, -X, +Y, -Y, +Z, -Z finds face 0..5: the face numbering is GL's. */
    lr_program *p = program(f, "cube.frag",
                            "uniform samplerCube u_cube;\nout vec4 o;\n"
                            "const vec3 dirs[6] = vec3[6](vec3(1, 0, 0), vec3(-1, 0, 0), vec3(0, 1, 0),\n"
                            "                             vec3(0, -1, 0), vec3(0, 0, 1), vec3(0, 0, -1));\n"
                            "void main() { o = texture(u_cube, dirs[int(gl_FragCoord.x)]); }\n");
    lr_tex *out = tex(f, (lr_tex_desc){.width = 6, .height = 1});
    lr_fb *fb = fb1(f, out, 0);
    lr_fb_bind(fb);
    glUseProgram(lr_program_id(p));
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_CUBE_MAP, lr_tex_id(cube));
    glUniform1i(lr_program_uniform(p, "u_cube"), 0);
    lr_gl_draw_fullscreen(f->gl);
    float px[6 * 4];
    CHECK(lr_fb_read(fb, 0, 0, 0, 6, 1, px, e));
    for (int i = 0; i < 6; i++)
        assert_true(px[4 * i] == (float)i + 1.0f);
    lr_fb_destroy(fb);
    lr_tex_destroy(out);
    lr_program_destroy(p);
    lr_tex_destroy(cube);
}

static void array_layer_and_upload_orientation(void **state)
{
    fixture *f = *state;
    lr_tex *arr = tex(f, (lr_tex_desc){.type = LR_TEX_2D_ARRAY, .width = 2, .height = 2, .layers = 3});
    /* Upload to layer 2, read it back through a framebuffer: row 0 is the bottom both ways. */
    const float data[16] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16};
    CHECK(lr_tex_upload(arr, 2, data, e));
    lr_fb *fb = fb1(f, arr, 2);
    float px[16];
    CHECK(lr_fb_read(fb, 0, 0, 0, 2, 2, px, e));
    assert_memory_equal(px, data, sizeof data);
    CHECK(lr_fb_read(fb, 0, 1, 1, 1, 1, px, e)); /* top right */
    assert_memory_equal(px, &data[12], 4 * sizeof(float));
    /* Rendering into layer 0 leaves layer 2 alone. */
    lr_fb *fb0 = fb1(f, arr, 0);
    fill(f, fb0, (const float[4]){7, 7, 7, 7});
    CHECK(lr_fb_read(fb, 0, 0, 0, 2, 2, px, e));
    assert_memory_equal(px, data, sizeof data);
    CHECK(lr_fb_read(fb0, 0, 0, 0, 1, 1, px, e));
    assert_true(px[0] == 7.0f);
    lr_fb_destroy(fb0);
    lr_fb_destroy(fb);
    lr_tex_destroy(arr);
}

static void depth_texture_attachment(void **state)
{
    fixture *f = *state;
    lr_tex *c = tex(f, (lr_tex_desc){.type = LR_TEX_CUBE, .width = 2});
    lr_tex *d = tex(f, (lr_tex_desc){.type = LR_TEX_CUBE, .format = LR_TEX_DEPTH32F, .width = 2});
    lr_fb *fb = NULL;
    CHECK(lr_fb_create(f->gl, &(lr_fb_desc){.color = {{c, 3}}, .depth = {d, 3}}, &fb, e));
    /* Depth test against a cleared far plane keeps the triangle (z = 0 maps to depth 0.5). */
    lr_fb_bind(fb);
    glEnable(GL_DEPTH_TEST);
    glClearDepthf(1.0f);
    glClear(GL_DEPTH_BUFFER_BIT);
    fill(f, fb, (const float[4]){1, 2, 3, 4});
    /* A second draw with GL_LESS at equal depth fails the test and changes nothing. */
    glDepthFunc(GL_LESS);
    fill(f, fb, (const float[4]){9, 9, 9, 9});
    glDisable(GL_DEPTH_TEST);
    float px[4];
    CHECK(lr_fb_read(fb, 0, 1, 0, 1, 1, px, e));
    assert_memory_equal(px, ((const float[4]){1, 2, 3, 4}), 4 * sizeof(float));
    lr_fb_destroy(fb);
    lr_tex_destroy(d);
    lr_tex_destroy(c);
}

static void bad_targets_are_rejected_with_field_names(void **state)
{
    fixture *f = *state;
    lr_tex *a = tex(f, (lr_tex_desc){.width = 4, .height = 4, .label = "radiance"});
    lr_tex *b = tex(f, (lr_tex_desc){.width = 4, .height = 2});
    lr_tex *d = tex(f, (lr_tex_desc){.format = LR_TEX_DEPTH24, .width = 4, .height = 4});
    lr_fb *fb = (lr_fb *)1;
    lr_err e = {0};
    assert_int_equal(lr_fb_create(f->gl, &(lr_fb_desc){.color = {{a, 0}, {b, 0}}, .label = "gbuf"},
                                  &fb, &e),
                     LR_EINVAL);
    assert_null(fb);
    assert_string_equal(e.msg, "gbuf: color[1] is 4x2, the others 4x4");
    assert_int_equal(lr_fb_create(f->gl, &(lr_fb_desc){.color = {{d, 0}}}, &fb, &e), LR_EINVAL);
    assert_string_equal(e.msg, "framebuffer: color[0]: DEPTH24 is not a colour format");
    assert_int_equal(lr_fb_create(f->gl, &(lr_fb_desc){.color = {{a, 1}}}, &fb, &e), LR_EINVAL);
    assert_string_equal(e.msg, "framebuffer: color[0]: radiance: layer 1 outside 0..0");
    assert_int_equal(lr_fb_create(f->gl, &(lr_fb_desc){0}, &fb, &e), LR_EINVAL);

    lr_tex *t = (lr_tex *)1;
    assert_int_equal(lr_tex_create(f->gl, &(lr_tex_desc){.type = LR_TEX_CUBE, .width = 4, .height = 2},
                                   &t, &e),
                     LR_EINVAL);
    assert_null(t);
    assert_int_equal(lr_tex_create(f->gl, &(lr_tex_desc){.width = 0, .height = 2}, &t, &e), LR_EINVAL);
    assert_int_equal(lr_tex_create(f->gl, &(lr_tex_desc){.format = LR_TEX_DEPTH32F, .width = 2,
                                                         .height = 2, .linear = true},
                                   &t, &e),
                     LR_EUNSUPPORTED);
    lr_fb *ok = fb1(f, a, 0);
    float px[4];
    assert_int_equal(lr_fb_read(ok, 1, 0, 0, 1, 1, px, &e), LR_EINVAL);
    assert_int_equal(lr_fb_read(ok, 0, 3, 3, 2, 1, px, &e), LR_EINVAL);
    assert_int_equal(lr_tex_upload(a, 1, px, &e), LR_EINVAL);
    lr_fb_destroy(ok);
    lr_tex_destroy(a);
    lr_tex_destroy(b);
    lr_tex_destroy(d);
}

static void rgba8_target_reads_as_unit_floats(void **state)
{
    fixture *f = *state;
    lr_tex *t = tex(f, (lr_tex_desc){.format = LR_TEX_RGBA8, .width = 1, .height = 1});
    lr_fb *fb = fb1(f, t, 0);
    fill(f, fb, (const float[4]){0.0f, 1.0f, 2.0f, 128.0f / 255.0f}); /* 2.0 clamps to 1 */
    float px[4];
    CHECK(lr_fb_read(fb, 0, 0, 0, 1, 1, px, e));
    assert_true(px[0] == 0.0f && px[1] == 1.0f && px[2] == 1.0f);
    assert_true(px[3] == 128.0f / 255.0f);
    lr_fb_destroy(fb);
    lr_tex_destroy(t);
}

/* The tone-mapped output (render/passes/blend.h): the store clamps and sRGB-encodes the
 * colour (alpha stays linear), glReadPixels returns the stored bytes, and a sampler sees the
 * stored bytes too (SKIP_DECODE), as the RGBA8 target that the shader encoded gave them. */
static void srgb8_target_encodes_on_store_and_samples_as_stored(void **state)
{
    fixture *f = *state;
    if (!lr_gl_caps_get(f->gl)->srgb_decode)
        skip();
    lr_tex *t = tex(f, (lr_tex_desc){.format = LR_TEX_SRGB8_ALPHA8, .width = 1, .height = 1,
                                     .linear = true});
    lr_tex *t8 = tex(f, (lr_tex_desc){.format = LR_TEX_RGBA8, .width = 1, .height = 1});
    lr_fb *fb = fb1(f, t, 0), *fb8 = fb1(f, t8, 0);
    lr_program *copy = program(f, "copy.frag", "uniform highp sampler2D u_src;\nout vec4 o;\n"
                                               "void main() { o = texture(u_src, vec2(0.5)); }\n");
    /* Both sides of the linear segment's end (0.0031308), mid-tones, the clip at 1, below 0. */
    static const float lin[] = {0.0f, 1e-3f, 0.0031308f, 0.004f, 0.02f, 0.2140f, 0.5f,
                                0.9f, 1.0f, 1.5f, -0.25f};
    int off = 0;
    for (size_t i = 0; i < sizeof lin / sizeof lin[0]; i++) {
        fill(f, fb, (const float[4]){lin[i], 0.5f * lin[i], 1.0f - lin[i], 128.0f / 255.0f});
        float px[4], back[4];
        CHECK(lr_fb_read(fb, 0, 0, 0, 1, 1, px, e));
        for (int c = 0; c < 3; c++) {
            float v = c == 0 ? lin[i] : c == 1 ? 0.5f * lin[i] : 1.0f - lin[i];
            v = v < 0.0f ? 0.0f : v > 1.0f ? 1.0f : v;
            long want = lrintf(lr_srgb_encode(v) * 255.0f), got = lrintf(px[c] * 255.0f);
            /* The driver's encode: the exact curve's byte or, at a rounding boundary, one
             * step off (what test_render_blend allows the output). */
            if (labs(got - want) > 1)
                fail_msg("linear %.7g band %d: byte %ld, the exact curve %ld", (double)v, c, got,
                         want);
            off += got != want;
        }
        assert_true(lrintf(px[3] * 255.0f) == 128); /* alpha is not encoded */
        lr_fb_bind(fb8);
        glUseProgram(lr_program_id(copy));
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, lr_tex_id(t));
        glUniform1i(lr_program_uniform(copy, "u_src"), 0);
        lr_gl_draw_fullscreen(f->gl);
        CHECK(lr_fb_read(fb8, 0, 0, 0, 1, 1, back, e));
        for (int c = 0; c < 4; c++)
            assert_int_equal(lrintf(back[c] * 255.0f), lrintf(px[c] * 255.0f));
    }
    print_message("sRGB store: %d of %zu bytes one step from the exact curve\n", off,
                  3 * (sizeof lin / sizeof lin[0]));
    lr_program_destroy(copy);
    lr_fb_destroy(fb8);
    lr_fb_destroy(fb);
    lr_tex_destroy(t8);
    lr_tex_destroy(t);
}

static void timers_report_sections(void **state)
{
    fixture *f = *state;
    lr_tex *t = tex(f, (lr_tex_desc){.width = 8, .height = 8});
    lr_fb *fb = fb1(f, t, 0);
    for (int cpu = 0; cpu < 2; cpu++) {
        lr_timer *tm = NULL;
        CHECK(lr_timer_create(f->gl, &(lr_timer_desc){.cpu = cpu, .max_sections = 2}, &tm, e));
        assert_int_equal(lr_timer_is_gpu(tm), !cpu && lr_gl_caps_get(f->gl)->timer_query);
        for (int frame = 0; frame < 2; frame++) {
            lr_timer_reset(tm);
            CHECK(lr_timer_begin(tm, "gbuffer", e));
            fill(f, fb, probe);
            CHECK(lr_timer_end(tm, e));
            CHECK(lr_timer_begin(tm, "compose", e));
            fill(f, fb, probe);
            CHECK(lr_timer_end(tm, e));
            CHECK(lr_timer_collect(tm, e));
            assert_int_equal(lr_timer_count(tm), 2);
            assert_string_equal(lr_timer_name(tm, 0), "gbuffer");
            assert_string_equal(lr_timer_name(tm, 1), "compose");
            for (int i = 0; i < 2; i++)
                assert_true(isfinite(lr_timer_ms(tm, i)) && lr_timer_ms(tm, i) >= 0.0);
        }
        lr_err e = {0};
        assert_int_equal(lr_timer_end(tm, &e), LR_EINVAL); /* nothing open */
        lr_timer_reset(tm);
        assert_int_equal(lr_timer_begin(tm, "a", &e), LR_OK);
        assert_int_equal(lr_timer_begin(tm, "b", &e), LR_EINVAL); /* no nesting */
        assert_string_equal(e.msg, "timer: \"b\" begun while \"a\" is open");
        assert_int_equal(lr_timer_end(tm, &e), LR_OK);
        assert_int_equal(lr_timer_begin(tm, "c", &e), LR_OK);
        assert_int_equal(lr_timer_end(tm, &e), LR_OK);
        assert_int_equal(lr_timer_begin(tm, "d", &e), LR_EINVAL); /* max_sections = 2 */
        assert_int_equal(lr_timer_collect(tm, &e), LR_OK);
        lr_timer_destroy(tm);
    }
    lr_fb_destroy(fb);
    lr_tex_destroy(t);
}

int main(void)
{
#define T(name) cmocka_unit_test_setup_teardown(name, setup, teardown)
    const struct CMUnitTest tests[] = {
        T(rgba32f_target_reads_back_exactly),
        T(rgba16f_target_rounds_to_half),
        T(r32f_target_and_mrt),
        T(fullscreen_triangle_covers_every_texel),
        T(cube_faces_render_and_sample_independently),
        T(array_layer_and_upload_orientation),
        T(depth_texture_attachment),
        T(bad_targets_are_rejected_with_field_names),
        T(rgba8_target_reads_as_unit_floats),
        T(srgb8_target_encodes_on_store_and_samples_as_stored),
        T(timers_report_sections),
    };
    if (getenv("LR_TEST_FILTER")) /* e.g. LR_TEST_FILTER='cube*' to run one test */
        cmocka_set_test_filter(getenv("LR_TEST_FILTER"));
    return cmocka_run_group_tests(tests, NULL, NULL);
}
