/* lamprig — GLSL ES programs loaded from files under render/shaders/.
 *
 * A shader file holds GLSL ES 3.10 without a #version line. The loader builds the source the
 * driver sees as
 *
 *     #version 310 es
 *     #define LR_VERTEX_SHADER 1        (or LR_FRAGMENT_SHADER / LR_COMPUTE_SHADER)
 *     precision highp float; ...        (highp everywhere: the passes accumulate radiometry in
 *                                        float, and Mali/V3D default samplers to lowp)
 *     #define NAME VALUE                (each of the caller's defines, in order)
 *     <the file, with every  #include "other.glsl"  line replaced by that file>
 *
 * Includes are resolved relative to the including file, and each file is pasted at most once
 * per shader (so shared GLSL such as the optics functions needs no include guards and a cycle
 * cannot recurse). The directive is recognised on any line whose first token is #include,
 * including inside comments or #if 0 blocks.
 *
 * The loader keeps a map from every line of the assembled source back to (file, line), and
 * rewrites the driver's log through it: Mesa's "0:12(5): error: ...", the "ERROR: 0:12: ..."
 * of ANGLE/Mali/Adreno/PowerVR and NVIDIA's "0(12) : error ..." all become
 * "render/shaders/compose.frag:7:5: error: ..." naming the file (an included one if the
 * error is there) and its own line. The error message of a failed build is the mapped log on
 * one line ("; " between entries), starting with the first error's file and line.
 */
#ifndef LR_SHADER_H
#define LR_SHADER_H

#include <GLES3/gl31.h>
#include <stdbool.h>
#include <stddef.h>

#include "render/base/err.h"

typedef enum lr_shader_stage {
    LR_STAGE_VERTEX = 0,
    LR_STAGE_FRAGMENT,
    LR_STAGE_COMPUTE,
} lr_shader_stage;

/* ---- source assembly (no GL needed) ------------------------------------------------------ */

typedef struct lr_shader_source lr_shader_source;

/* Reads `path`, resolves its includes and prepends the header and `defines` (NULL-terminated
 * list of "NAME" or "NAME VALUE"; NULL for none). Errors: LR_EIO (file or include cannot be
 * read: "dir/a.frag:3: cannot open include: dir/b.glsl: No such file or directory"),
 * LR_EPARSE (a #version line in a file, a malformed #include, a newline in a define). */
int lr_shader_source_load(const char *path, lr_shader_stage stage, const char *const *defines,
                          lr_shader_source **out, lr_err *e);
void lr_shader_source_free(lr_shader_source *src);

/* The text handed to glShaderSource. */
const char *lr_shader_source_text(const lr_shader_source *src);
/* Number of lines the loader put in front of the file's first line. */
int lr_shader_source_prelude_lines(const lr_shader_source *src);
/* Maps line `line` (1-based) of the assembled text to the file it came from and that file's
 * own 1-based line; the prelude maps to "<prelude>". Returns 0 on success, -1 when `line` is
 * outside the text. */
int lr_shader_source_locate(const lr_shader_source *src, int line, const char **file,
                            int *file_line);
/* Rewrites a driver info log through the line map into out (always NUL-terminated; lines that
 * carry no recognised location are kept, prefixed with the main file's path). Entries are
 * separated by `sep` (e.g. "\n" or "; "). Returns the file line of the first located entry,
 * or 0 when none was located. */
int lr_shader_source_map_log(const lr_shader_source *src, const char *log, const char *sep,
                             char *out, size_t cap);

/* ---- programs ---------------------------------------------------------------------------- */

typedef struct lr_program lr_program;

typedef struct lr_program_desc {
    /* Either vertex + fragment, or compute alone. */
    const char *vertex;
    const char *fragment;
    const char *compute;
    /* Directory the three paths are relative to (e.g. "render/shaders"); NULL: as given. */
    const char *dir;
    /* NULL-terminated "NAME" / "NAME VALUE" list, the same for every stage; NULL: none. */
    const char *const *defines;
} lr_program_desc;

/* Loads, compiles and links (needs a current GL context). Errors: those of
 * lr_shader_source_load, and LR_EGL for compile ("render/shaders/x.frag:12:3: error: ...")
 * and link failures ("link x.vert + x.frag: ..."). */
int lr_program_create(const lr_program_desc *desc, lr_program **out, lr_err *e);
/* Deletes the GL program (context current); NULL is a no-op. */
void lr_program_destroy(lr_program *p);

GLuint lr_program_id(const lr_program *p);
/* glGetUniformLocation of "u_x" or "u_x[i]"; -1 when the compiler dropped it (declared but
 * unused: legitimate, nothing to set). A name the program's sources do not declare (found
 * at creation from the assembled source: compilers drop unused uniforms, so the active ones
 * cannot tell a misspelling from an unused uniform) also gives -1 and is remembered for
 * lr_program_check: setting a uniform the shader lacks is an error, not a silent no-op. */
GLint lr_program_uniform(lr_program *p, const char *name);
/* Whether the program's sources declare uniform `name` (an array index is ignored). */
bool lr_program_declares(const lr_program *p, const char *name);
/* LR_EINVAL "program mesh.vert + radiosity.frag: sets uniform u_foo, which its shaders do not
 * declare" for the first undeclared name asked of lr_program_uniform since the last check
 * (then forgotten); LR_OK when there was none. Callers check after each draw's set-up. */
int lr_program_check(lr_program *p, lr_err *e);

#endif
