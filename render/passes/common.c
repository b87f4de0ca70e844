/* Shared by the passes: meshes on the GPU, material coefficients, the light G-buffer and
 * Algorithm 1 bindings, small uniform helpers. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render/base/mat4.h"
#include "render/cpu/cavity.h"
#include "render/passes/passes.h"

#define STR_(x) #x
#define STR(x) STR_(x)

const char *const *lr_passes_defines(void)
{
    static const char *const defines[] = {"LR_MAX_OBJECTS " STR(LR_MAX_OBJECTS),
                                          "LR_MAX_K " STR(LR_MAX_K),
                                          "LR_MAX_LIGHTS " STR(LR_MAX_LIGHTS), NULL};
    return defines;
}

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
        lr_passes_pack_multipole(&o->coeffs, o->sss_model, o->thickness_mm, r->sss + 12 * i);
    }
    for (int i = 0; i < LR_MAX_OBJECTS; i++)
        for (int c = 0; c < 3; c++)
            r->sd_norm[3 * i + c] =
                i < no ? (float)lr_scene_object_sd_norm(lr_scene_object_at(r->scene, i), c) : 1.0f;
}

int lr_passes_update_cavity(lr_renderer *r, lr_err *e)
{
    /* One measurement per light (the closure depends on where the light sits in the cavity),
     * the same numbers lr_cpu_render applies per light (render/cpu/frame.c). */
    for (int k = 0; k < 3 * LR_MAX_LIGHTS * LR_MAX_OBJECTS; k++)
        r->cavity_gain[k] = 1.0f;
    int no = lr_scene_object_count(r->scene), nl = lr_scene_light_count(r->scene);
    if (no > LR_MAX_OBJECTS)
        no = LR_MAX_OBJECTS;
    if (nl > LR_MAX_LIGHTS)
        nl = LR_MAX_LIGHTS;
    for (int l = 0; l < nl; l++) {
        double g[LR_MAX_OBJECTS][3];
        int rc = lr_cpu_cavity_scene_gains(r->scene, l, 0, g, no, e);
        if (rc)
            return rc;
        for (int i = 0; i < no; i++)
            for (int c = 0; c < 3; c++)
                r->cavity_gain[3 * (l * LR_MAX_OBJECTS + i) + c] = (float)g[i][c];
    }
    return LR_OK;
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
    loc = lr_program_uniform(p, "u_sd_norm");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_sd_norm[0]");
    if (loc >= 0)
        glUniform3fv(loc, LR_MAX_OBJECTS, r->sd_norm);
    loc = lr_program_uniform(p, "u_cavity_gain");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_cavity_gain[0]");
    if (loc >= 0)
        glUniform3fv(loc, LR_MAX_LIGHTS * LR_MAX_OBJECTS, r->cavity_gain);
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

void lr_passes_bind_gbuffer(lr_renderer *r, const lr_program *p, int l)
{
    const struct lr_light_gbuffer *g = &r->gb[l];
    if (g->mode == LR_GB_CUBE) {
        lr_passes_bind_tex(p, "u_gb_cube_pos", 0, g->pos_cube);
        lr_passes_bind_tex(p, "u_gb_cube_nrm", 1, g->nrm_cube);
        /* Units of the unused sampler type must differ from the used ones. */
        lr_passes_uniform_i(p, "u_gb_pos", 2);
        lr_passes_uniform_i(p, "u_gb_nrm", 3);
    } else {
        lr_passes_uniform_i(p, "u_gb_cube_pos", 0);
        lr_passes_uniform_i(p, "u_gb_cube_nrm", 1);
        lr_passes_bind_tex(p, "u_gb_pos", 2, g->pos_2d);
        lr_passes_bind_tex(p, "u_gb_nrm", 3, g->nrm_2d);
    }
    lr_passes_uniform_i(p, "u_gb_mode", g->mode);
    GLint loc = lr_program_uniform(p, "u_gb_vp");
    if (loc >= 0)
        glUniformMatrix4fv(loc, 1, GL_FALSE, g->vp);
    lr_passes_uniform_v3(p, "u_light_pos", g->pos);
    lr_passes_uniform_v3(p, "u_light_dir", g->dir);
    lr_passes_uniform_i(p, "u_light_type", g->type);
    loc = lr_program_uniform(p, "u_spot_cos");
    if (loc >= 0)
        glUniform2f(loc, g->spot_cos[0], g->spot_cos[1]);
}

/* Element i of uniform array `name` ("u_x[2]"). */
static GLint array_loc(const lr_program *p, const char *name, int i)
{
    char n[64];
    snprintf(n, sizeof n, "%s[%d]", name, i);
    return lr_program_uniform(p, n);
}

void lr_passes_bind_lights(lr_renderer *r, const lr_program *p)
{
    /* Every array element gets its own unit, used or not: a cube and a 2D sampler must never
     * share one (units 4..10 belong to the gather and the VPLs). */
    for (int l = 0; l < LR_MAX_LIGHTS; l++) {
        const struct lr_light_gbuffer *g = &r->gb[l];
        bool on = l < r->n_lights;
        glActiveTexture(GL_TEXTURE0 + (GLenum)l);
        glBindTexture(GL_TEXTURE_CUBE_MAP, on && g->mode == LR_GB_CUBE ? lr_tex_id(g->pos_cube) : 0);
        glActiveTexture(GL_TEXTURE11 + (GLenum)l);
        glBindTexture(GL_TEXTURE_2D, on && g->mode != LR_GB_CUBE ? lr_tex_id(g->pos_2d) : 0);
        GLint loc;
        if ((loc = array_loc(p, "u_lights_cube", l)) >= 0)
            glUniform1i(loc, l);
        if ((loc = array_loc(p, "u_lights_2d", l)) >= 0)
            glUniform1i(loc, 11 + l);
        if (!on)
            continue;
        if ((loc = array_loc(p, "u_lights_mode", l)) >= 0)
            glUniform1i(loc, g->mode);
        if ((loc = array_loc(p, "u_lights_type", l)) >= 0)
            glUniform1i(loc, g->type);
        if ((loc = array_loc(p, "u_lights_vp", l)) >= 0)
            glUniformMatrix4fv(loc, 1, GL_FALSE, g->vp);
        if ((loc = array_loc(p, "u_lights_pos", l)) >= 0)
            glUniform3f(loc, (float)g->pos.x, (float)g->pos.y, (float)g->pos.z);
        if ((loc = array_loc(p, "u_lights_dir", l)) >= 0)
            glUniform3f(loc, (float)g->dir.x, (float)g->dir.y, (float)g->dir.z);
        if ((loc = array_loc(p, "u_lights_spot_cos", l)) >= 0)
            glUniform2f(loc, g->spot_cos[0], g->spot_cos[1]);
        double I[3];
        lr_passes_light_rgb(r, l, I);
        if ((loc = array_loc(p, "u_lights_I", l)) >= 0)
            glUniform3f(loc, (float)I[0], (float)I[1], (float)I[2]);
    }
    lr_passes_uniform_i(p, "u_n_lights", r->n_lights);
}

void lr_passes_bind_gather(lr_renderer *r, const lr_program *p, const double w[][3])
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
    lr_passes_set_light_w(r, p, w);
}

void lr_passes_set_light_w(lr_renderer *r, const lr_program *p, const double w[][3])
{
    /* The maps store B * scale[l]: the weight divides it out. */
    GLint loc;
    float wf[3 * LR_MAX_LIGHTS] = {0};
    for (int l = 0; l < r->n_lights; l++)
        for (int c = 0; c < 3; c++)
            wf[3 * l + c] = (float)(w[l][c] / r->rad.scale[l]);
    loc = lr_program_uniform(p, "u_light_w");
    if (loc < 0)
        loc = lr_program_uniform(p, "u_light_w[0]");
    if (loc >= 0)
        glUniform3fv(loc, LR_MAX_LIGHTS, wf);
    lr_passes_uniform_i(p, "u_n_lights", r->n_lights);
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

const lr_light *lr_passes_light(const lr_renderer *r, int l)
{
    return lr_scene_light_at(r->scene, l);
}

void lr_passes_light_rgb(const lr_renderer *r, int l, double out[3])
{
    lr_light_rgb(lr_passes_light(r, l), out);
    double f = lr_renderer_flicker(r, l);
    for (int c = 0; c < 3; c++)
        out[c] *= f;
}
