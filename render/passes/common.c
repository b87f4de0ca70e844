/* Shared by the passes (render/passes/passes.h): meshes on the GPU, material coefficients
 * and cavity gains, the shaders' defines, small uniform helpers. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/models/twin/cavity_gains.h"
#include "render/passes/passes.h"

int lr_passes_upload_arrays(lr_gpu_mesh *g, const float *pos, const float *nrm, size_t nv,
                            const uint32_t *idx, size_t nt, const char *name, lr_err *e)
{
    if (nt * 3 > 0x7fffffff)
        return lr_err_set(e, LR_EINVAL, "mesh %s: too many triangles for the GPU", name);
    glGenVertexArrays(1, &g->vao);
    glGenBuffers(2, g->vbo);
    glGenBuffers(1, &g->ebo);
    glBindVertexArray(g->vao);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo[0]);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 3 * sizeof(float)), pos, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, 0);
    glEnableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo[1]);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 3 * sizeof(float)), nrm, GL_STATIC_DRAW);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, 0);
    glEnableVertexAttribArray(1);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(nt * 3 * sizeof(uint32_t)), idx,
                 GL_STATIC_DRAW);
    glBindVertexArray(0);
    g->count = (GLsizei)(nt * 3);
    return lr_gl_check("mesh upload", e);
}

static int upload(lr_gpu_mesh *g, const lr_mesh *m, lr_err *e)
{
    return lr_passes_upload_arrays(g, lr_mesh_positions(m), lr_mesh_normals(m),
                                   lr_mesh_vertex_count(m), lr_mesh_indices(m),
                                   lr_mesh_triangle_count(m), lr_mesh_name(m), e);
}

void lr_passes_release_mesh(lr_gpu_mesh *g)
{
    if (g->vao) {
        glDeleteVertexArrays(1, &g->vao);
        glDeleteBuffers(2, g->vbo);
        glDeleteBuffers(1, &g->ebo);
    }
    memset(g, 0, sizeof *g);
}

void lr_pass_objects_free(lr_pass_objects *o)
{
    for (int i = 0; i < LR_MAX_OBJECTS; i++) {
        lr_passes_release_mesh(&o->obj[i]);
        lr_passes_release_mesh(&o->built[i]);
    }
    for (int i = 0; i < LR_MAX_RECEIVERS; i++)
        lr_passes_release_mesh(&o->recv[i]);
    o->n_objects = o->n_receivers = 0;
}

int lr_pass_objects_upload(lr_pass_objects *objs, const lr_scene *s, lr_err *e)
{
    lr_pass_objects_free(objs);
    int no = lr_scene_object_count(s), nr = lr_scene_receiver_count(s);
    if (no > LR_MAX_OBJECTS)
        return lr_err_set(e, LR_EUNSUPPORTED, "renderer: %d objects; at most %d", no, LR_MAX_OBJECTS);
    if (nr > LR_MAX_RECEIVERS)
        return lr_err_set(e, LR_EUNSUPPORTED, "renderer: %d receivers; at most %d", nr,
                          LR_MAX_RECEIVERS);
    for (int i = 0; i < no; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        int rc = upload(&objs->obj[i], o->mesh, e);
        if (!rc && o->built_mesh && o->built_mesh != o->mesh)
            rc = upload(&objs->built[i], o->built_mesh, e);
        if (rc)
            return rc;
        objs->two_sided[i] = !o->closed;
    }
    for (int i = 0; i < nr; i++) {
        int rc = upload(&objs->recv[i], lr_scene_receiver_at(s, i)->mesh, e);
        if (rc)
            return rc;
    }
    objs->n_objects = no;
    objs->n_receivers = nr;
    return LR_OK;
}

void lr_passes_draw(const lr_gpu_mesh *m)
{
    glBindVertexArray(m->vao);
    glDrawElements(GL_TRIANGLES, m->count, GL_UNSIGNED_INT, 0);
    glBindVertexArray(0);
}

void lr_passes_pack_coeffs(const lr_coeffs *c, float b[20])
{
    for (int j = 0; j < 3; j++) {
        b[0 + j] = (float)c->sigma_tr[j];
        b[4 + j] = (float)c->D[j];
        b[8 + j] = isinf(c->de[j]) || c->de[j] > 1e30 ? -1.0f : (float)c->de[j];
        b[12 + j] = (float)c->sigma_t[j];
        b[16 + j] = (float)c->mfp[j];
    }
    b[3] = (float)c->eta;
    b[7] = (float)c->C_phi_norm;
    b[11] = (float)c->C_phi;
    b[15] = (float)c->C_E;
    b[19] = (float)c->A_dir;
}

void lr_passes_pack_sss(const lr_coeffs *c, enum lr_sss_model model, float b[12])
{
    for (int j = 0; j < 3; j++) {
        b[0 + j] = (float)c->albedo_prime[j];
        b[4 + j] = (float)c->z_r[j];
        b[8 + j] = (float)c->z_v[j];
    }
    b[3] = (float)model;
    b[7] = b[11] = 0.0f;
}

void lr_pass_objects_update_coeffs(lr_pass_objects *objs, const lr_scene *s)
{
    memset(objs->coef, 0, sizeof objs->coef);
    memset(objs->sss, 0, sizeof objs->sss);
    int no = lr_scene_object_count(s);
    for (int i = 0; i < no && i < LR_MAX_OBJECTS; i++) {
        const lr_scene_object *o = lr_scene_object_at(s, i);
        lr_passes_pack_coeffs(&o->coeffs, objs->coef + 20 * i);
        lr_passes_pack_sss(&o->coeffs, o->sss_model, objs->sss + 12 * i);
        lr_passes_pack_multipole(&o->coeffs, o->sss_model, o->thickness_mm, objs->sss + 12 * i);
    }
    for (int i = 0; i < LR_MAX_OBJECTS; i++)
        for (int c = 0; c < 3; c++)
            objs->sd_norm[3 * i + c] =
                i < no ? (float)lr_scene_object_sd_norm(lr_scene_object_at(s, i), c) : 1.0f;
}

int lr_pass_objects_update_cavity(lr_pass_objects *objs, const lr_scene *s, lr_err *e)
{
    /* One measurement per light (the closure depends on where the light sits in the cavity),
     * the same numbers lr_cpu_render applies per light (render/cpu/frame.c). */
    for (int k = 0; k < 3 * LR_MAX_LIGHTS * LR_MAX_OBJECTS; k++)
        objs->cavity_gain[k] = 1.0f;
    int no = lr_scene_object_count(s), nl = lr_scene_light_count(s);
    if (no > LR_MAX_OBJECTS)
        no = LR_MAX_OBJECTS;
    if (nl > LR_MAX_LIGHTS)
        nl = LR_MAX_LIGHTS;
    for (int l = 0; l < nl; l++) {
        double g[LR_MAX_OBJECTS][3];
        int rc = lr_cavity_scene_gains(s, l, 0, g, no, e);
        if (rc)
            return rc;
        for (int i = 0; i < no; i++)
            for (int c = 0; c < 3; c++)
                objs->cavity_gain[3 * (l * LR_MAX_OBJECTS + i) + c] = (float)g[i][c];
    }
    return LR_OK;
}

void lr_passes_set_coeffs(const lr_pass_objects *o, lr_program *p)
{
    GLint loc = lr_program_uniform(p, "u_coef");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_coef[0]");
    if (loc >= 0)
        glUniform4fv(loc, 5 * LR_MAX_OBJECTS, o->coef);
    loc = lr_program_uniform(p, "u_sss");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_sss[0]");
    if (loc >= 0)
        glUniform4fv(loc, 3 * LR_MAX_OBJECTS, o->sss);
}

void lr_passes_uniform_v3_array(lr_program *p, const char *name, const float *v, int count)
{
    /* Drivers name an array "u_x" or "u_x[0]". */
    char first[64];
    snprintf(first, sizeof first, "%s[0]", name);
    GLint loc = lr_program_uniform(p, name);
    if (loc < 0)
        loc = lr_program_uniform(p, first);
    if (loc >= 0)
        glUniform3fv(loc, count, v);
}

void lr_passes_uniform_mat4(lr_program *p, const char *name, const double m[16])
{
    float f[16];
    lr_mat4_to_float(m, f);
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniformMatrix4fv(loc, 1, GL_FALSE, f);
}

void lr_passes_uniform_v3(lr_program *p, const char *name, lr_vec3 v)
{
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniform3f(loc, (float)v.x, (float)v.y, (float)v.z);
}

void lr_passes_uniform_i(lr_program *p, const char *name, int v)
{
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniform1i(loc, v);
}

void lr_passes_uniform_f(lr_program *p, const char *name, float v)
{
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniform1f(loc, v);
}

void lr_passes_bind_tex(lr_program *p, const char *name, int unit, const lr_tex *t)
{
    glActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    if (t)
        glBindTexture(lr_tex_target(t), lr_tex_id(t));
    lr_passes_uniform_i(p, name, unit);
}
