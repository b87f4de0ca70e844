/* Shared by the passes: meshes on the GPU, material coefficients, the light G-buffer and
 * Algorithm 1 bindings, small uniform helpers. */
#include <math.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/passes/passes.h"

static int upload(lr_gpu_mesh *g, const lr_mesh *m, lr_err *e)
{
    size_t nv = lr_mesh_vertex_count(m), nt = lr_mesh_triangle_count(m);
    if (nt * 3 > 0x7fffffff)
        return lr_err_set(e, LR_EINVAL, "mesh %s: too many triangles for the GPU", lr_mesh_name(m));
    glGenVertexArrays(1, &g->vao);
    glGenBuffers(2, g->vbo);
    glGenBuffers(1, &g->ebo);
    glBindVertexArray(g->vao);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo[0]);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 3 * sizeof(float)), lr_mesh_positions(m),
                 GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, 0);
    glEnableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo[1]);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nv * 3 * sizeof(float)), lr_mesh_normals(m),
                 GL_STATIC_DRAW);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, 0);
    glEnableVertexAttribArray(1);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(nt * 3 * sizeof(uint32_t)),
                 lr_mesh_indices(m), GL_STATIC_DRAW);
    glBindVertexArray(0);
    g->count = (GLsizei)(nt * 3);
    return lr_gl_check("mesh upload", e);
}

static void release(lr_gpu_mesh *g)
{
    if (g->vao) {
        glDeleteVertexArrays(1, &g->vao);
        glDeleteBuffers(2, g->vbo);
        glDeleteBuffers(1, &g->ebo);
    }
    memset(g, 0, sizeof *g);
}

void lr_passes_free_meshes(lr_renderer *r)
{
    for (int i = 0; i < LR_MAX_OBJECTS; i++)
        release(&r->obj[i]);
    for (int i = 0; i < LR_MAX_RECEIVERS; i++)
        release(&r->recv[i]);
    r->n_objects = r->n_receivers = 0;
}

int lr_passes_upload_meshes(lr_renderer *r, lr_err *e)
{
    lr_passes_free_meshes(r);
    int no = lr_scene_object_count(r->scene), nr = lr_scene_receiver_count(r->scene);
    if (no > LR_MAX_OBJECTS)
        return lr_err_set(e, LR_EUNSUPPORTED, "renderer: %d objects; at most %d", no, LR_MAX_OBJECTS);
    if (nr > LR_MAX_RECEIVERS)
        return lr_err_set(e, LR_EUNSUPPORTED, "renderer: %d receivers; at most %d", nr,
                          LR_MAX_RECEIVERS);
    for (int i = 0; i < no; i++) {
        const lr_scene_object *o = lr_scene_object_at(r->scene, i);
        int rc = upload(&r->obj[i], o->mesh, e);
        if (rc)
            return rc;
        r->two_sided[i] = !o->closed;
    }
    for (int i = 0; i < nr; i++) {
        int rc = upload(&r->recv[i], lr_scene_receiver_at(r->scene, i)->mesh, e);
        if (rc)
            return rc;
    }
    r->n_objects = no;
    r->n_receivers = nr;
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

void lr_passes_update_coeffs(lr_renderer *r)
{
    memset(r->coef, 0, sizeof r->coef);
    memset(r->sss, 0, sizeof r->sss);
    int no = lr_scene_object_count(r->scene);
    for (int i = 0; i < no && i < LR_MAX_OBJECTS; i++) {
        const lr_scene_object *o = lr_scene_object_at(r->scene, i);
        lr_passes_pack_coeffs(&o->coeffs, r->coef + 20 * i);
        lr_passes_pack_sss(&o->coeffs, o->sss_model, r->sss + 12 * i);
    }
}

void lr_passes_set_coeffs(lr_renderer *r, const lr_program *p)
{
    GLint loc = lr_program_uniform(p, "u_coef");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_coef[0]");
    if (loc >= 0)
        glUniform4fv(loc, 5 * LR_MAX_OBJECTS, r->coef);
    loc = lr_program_uniform(p, "u_sss");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_sss[0]");
    if (loc >= 0)
        glUniform4fv(loc, 3 * LR_MAX_OBJECTS, r->sss);
}

void lr_passes_uniform_mat4(const lr_program *p, const char *name, const double m[16])
{
    float f[16];
    lr_mat4_to_float(m, f);
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniformMatrix4fv(loc, 1, GL_FALSE, f);
}

void lr_passes_uniform_v3(const lr_program *p, const char *name, lr_vec3 v)
{
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniform3f(loc, (float)v.x, (float)v.y, (float)v.z);
}

void lr_passes_uniform_i(const lr_program *p, const char *name, int v)
{
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniform1i(loc, v);
}

void lr_passes_uniform_f(const lr_program *p, const char *name, float v)
{
    GLint loc = lr_program_uniform(p, name);
    if (loc >= 0)
        glUniform1f(loc, v);
}

void lr_passes_bind_tex(const lr_program *p, const char *name, int unit, const lr_tex *t)
{
    glActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    if (t)
        glBindTexture(lr_tex_target(t), lr_tex_id(t));
    lr_passes_uniform_i(p, name, unit);
}

void lr_passes_bind_gbuffer(lr_renderer *r, const lr_program *p)
{
    if (r->gb.mode == LR_GB_CUBE) {
        lr_passes_bind_tex(p, "u_gb_cube_pos", 0, r->gb.pos_cube);
        lr_passes_bind_tex(p, "u_gb_cube_nrm", 1, r->gb.nrm_cube);
        /* Units of the unused sampler type must differ from the used ones. */
        lr_passes_uniform_i(p, "u_gb_pos", 2);
        lr_passes_uniform_i(p, "u_gb_nrm", 3);
    } else {
        lr_passes_uniform_i(p, "u_gb_cube_pos", 0);
        lr_passes_uniform_i(p, "u_gb_cube_nrm", 1);
        lr_passes_bind_tex(p, "u_gb_pos", 2, r->gb.pos_2d);
        lr_passes_bind_tex(p, "u_gb_nrm", 3, r->gb.nrm_2d);
    }
    lr_passes_uniform_i(p, "u_gb_mode", r->gb.mode);
    GLint loc = lr_program_uniform(p, "u_gb_vp");
    if (loc >= 0)
        glUniformMatrix4fv(loc, 1, GL_FALSE, r->gb.vp);
    lr_passes_uniform_v3(p, "u_light_pos", r->gb.pos);
    lr_passes_uniform_v3(p, "u_light_dir", r->gb.dir);
    lr_passes_uniform_i(p, "u_light_type", r->gb.type);
    loc = lr_program_uniform(p, "u_spot_cos");
    if (loc >= 0)
        glUniform2f(loc, r->gb.spot_cos[0], r->gb.spot_cos[1]);
}

void lr_passes_bind_gather(lr_renderer *r, const lr_program *p)
{
    lr_passes_bind_tex(p, "u_map_B", 4, r->rad.B);
    lr_passes_bind_tex(p, "u_map_nrm", 5, r->rad.nrm);
    lr_passes_bind_tex(p, "u_map_depth", 6, r->rad.depth);
    GLint loc = lr_program_uniform(p, "u_map_P");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_map_P[0]");
    if (loc >= 0)
        glUniformMatrix4fv(loc, r->rad.K, GL_FALSE, r->rad.Pf);
    loc = lr_program_uniform(p, "u_map_d");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_map_d[0]");
    if (loc >= 0)
        glUniform3fv(loc, r->rad.K, r->rad.df);
    lr_passes_uniform_i(p, "u_K", r->rad.K);
    lr_passes_uniform_f(p, "u_eps_bias", r->rad.eps_bias);
    lr_passes_uniform_f(p, "u_eps_comb", r->rad.eps_comb);
    lr_passes_uniform_f(p, "u_map_scale", r->rad.scale);
}

void lr_passes_cube_face_vp(lr_vec3 at, int f, double znear, double zfar, double out[16])
{
    static const double dir[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const double up[6][3] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    double view[16], proj[16];
    lr_vec3 target = lr_v3_add(at, lr_v3(dir[f][0], dir[f][1], dir[f][2]));
    lr_mat4_look_at(at, target, lr_v3(up[f][0], up[f][1], up[f][2]), view);
    lr_mat4_perspective(M_PI / 2.0, 1.0, znear, zfar, proj);
    lr_mat4_mul(proj, view, out);
}

const lr_light *lr_passes_light(const lr_renderer *r)
{
    return lr_scene_light_at(r->scene, 0);
}
