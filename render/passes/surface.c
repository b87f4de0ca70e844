/* The objects' surface cache (render/passes/surface.h; PIPELINE.md "Surface cache"): a
 * lattice over every triangle of every object mesh, sub-triangle edges at most h
 * (render/mesh/lattice.h), and Algorithm 1 (lib/gather.glsl, lr_gather_each) evaluated once
 * per lattice point and light into a texture, one texel per entry, by a fullscreen draw. B
 * does not depend on the view (only F_t(w_o) / pi does), so composition
 * (compose_cached.vert/.frag) draws the original mesh and reads three entries per pixel
 * instead of K x 4 map taps, and a camera move costs no gather. */
#include "render/passes/surface.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>


static void free_entries(lr_surface *sc)
{
    for (int i = 0; i < LR_MAX_OBJECTS; i++)
        lr_passes_release_mesh(&sc->mesh[i]);
    lr_fb_destroy(sc->fb);
    lr_tex *t[] = {sc->pos, sc->nrm, sc->B};
    for (size_t i = 0; i < sizeof t / sizeof t[0]; i++)
        lr_tex_destroy(t[i]);
    sc->fb = NULL;
    sc->pos = sc->nrm = sc->B = NULL;
    sc->n_objects = sc->entries = sc->rows = sc->n_lights = 0;
    sc->built = sc->valid = false;
}

void lr_surface_free(lr_surface *sc) { free_entries(sc); }

void lr_surface_invalidate_geometry(lr_surface *sc)
{
    sc->built = false;
    sc->valid = false;
}

/* Object mesh m unindexed for compose_cached.vert: per corner its position and normal
 * (attributes 0, 1) and its triangle's lattice, (first cache entry, R) (attribute 2,
 * integer), render/mesh/lattice.h. */
static int upload_lattice_mesh(lr_gpu_mesh *g, const lr_mesh *m, const lr_refined *ref,
                               int base, lr_err *e)
{
    size_t nt = lr_mesh_triangle_count(m);
    if (nt * 3 > 0x7fffffff || !ref->lat_R || ref->n_parents != nt)
        return lr_err_set(e, LR_EINVAL, "surface cache: mesh %s: %zu triangles, no lattice for "
                          "them", lr_mesh_name(m), nt);
    const float *P = lr_mesh_positions(m), *N = lr_mesh_normals(m);
    const uint32_t *ix = lr_mesh_indices(m);
    float *pn = malloc(nt * 3 * 6 * sizeof *pn);
    GLint *lat = malloc(nt * 3 * 2 * sizeof *lat);
    if (!pn || !lat) {
        free(pn);
        free(lat);
        return lr_err_set(e, LR_ENOMEM, "surface cache: out of memory");
    }
    for (size_t t = 0; t < nt; t++)
        for (int c = 0; c < 3; c++) {
            size_t q = 3 * t + (size_t)c, v = ix[3 * t + (size_t)c];
            memcpy(pn + 6 * q, P + 3 * v, 3 * sizeof *pn);
            memcpy(pn + 6 * q + 3, N + 3 * v, 3 * sizeof *pn);
            lat[2 * q] = base + (GLint)ref->lat_base[t];
            lat[2 * q + 1] = (GLint)ref->lat_R[t];
        }
    glGenVertexArrays(1, &g->vao);
    glGenBuffers(2, g->vbo);
    glBindVertexArray(g->vao);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo[0]);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nt * 3 * 6 * sizeof *pn), pn, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), 0);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          (const void *)(3 * sizeof(float)));
    glEnableVertexAttribArray(1);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo[1]);
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(nt * 3 * 2 * sizeof *lat), lat, GL_STATIC_DRAW);
    glVertexAttribIPointer(2, 2, GL_INT, 0, 0);
    glEnableVertexAttribArray(2);
    glBindVertexArray(0);
    g->count = (GLsizei)(nt * 3);
    free(pn);
    free(lat);
    return lr_gl_check("surface cache mesh upload", e);
}

static int build(lr_surface *sc, const lr_pass_ctx *c, const lr_radiosity *rad, lr_err *e)
{
    free_entries(sc);
    int no = c->objs->n_objects, rc = LR_OK;
    lr_refined ref[LR_MAX_OBJECTS];
    memset(ref, 0, sizeof ref);
    size_t total = 0;
    for (int i = 0; i < no && !rc; i++) {
        size_t budget = LR_SURFACE_MAX_VERTICES > total ? LR_SURFACE_MAX_VERTICES - total : 1;
        rc = lr_surface_refine(c->scene, i, rad->size, budget, &ref[i], &sc->h[i], e);
        if (!rc) {
            sc->base[i] = (int)total;
            sc->nv[i] = (int)ref[i].nv;
            total += ref[i].nv * (c->objs->two_sided[i] ? 2 : 1);
        }
    }
    float *pos = NULL, *nrm = NULL;
    int rows = (int)((total + LR_SURFACE_ROW - 1) / LR_SURFACE_ROW);
    if (!rc && (rows < 1 || rows > c->caps->max_texture_size))
        rc = lr_err_set(e, LR_EUNSUPPORTED, "surface cache: %zu entries: beyond the driver's "
                        "%d rows of %d", total, c->caps->max_texture_size, LR_SURFACE_ROW);
    size_t texels = (size_t)rows * LR_SURFACE_ROW;
    if (!rc) {
        pos = calloc(texels * 4, sizeof *pos);
        nrm = calloc(texels * 4, sizeof *nrm);
        if (!pos || !nrm)
            rc = lr_err_set(e, LR_ENOMEM, "surface cache: out of memory");
    }
    for (int i = 0; i < no && !rc; i++) {
        int sides = c->objs->two_sided[i] ? 2 : 1;
        for (int side = 0; side < sides; side++)
            for (size_t v = 0; v < ref[i].nv; v++) {
                size_t k = (size_t)sc->base[i] + (size_t)side * ref[i].nv + v;
                float sgn = side ? -1.0f : 1.0f;
                for (int j = 0; j < 3; j++) {
                    pos[4 * k + j] = ref[i].pos[3 * v + j];
                    nrm[4 * k + j] = sgn * ref[i].nrm[3 * v + j];
                }
                pos[4 * k + 3] = 1.0f;
            }
        rc = upload_lattice_mesh(&sc->mesh[i], lr_scene_object_at(c->scene, i)->mesh, &ref[i],
                                 sc->base[i], e);
    }
    for (int i = 0; i < no; i++)
        lr_refined_free(&ref[i]);
    lr_tex_desc td = {.format = LR_TEX_RGBA32F, .width = LR_SURFACE_ROW, .height = rows,
                      .label = "surface cache entries"};
    if (!rc && !(rc = lr_tex_create(c->gl, &td, &sc->pos, e)) &&
        !(rc = lr_tex_create(c->gl, &td, &sc->nrm, e)) &&
        !(rc = lr_tex_upload(sc->pos, 0, pos, e)))
        rc = lr_tex_upload(sc->nrm, 0, nrm, e);
    free(pos);
    free(nrm);
    if (!rc) {
        lr_tex_desc bd = {.type = LR_TEX_2D_ARRAY, .format = LR_TEX_RGBA32F,
                          .width = LR_SURFACE_ROW, .height = rows, .layers = c->n_lights,
                          .label = "surface cache"};
        lr_fb_desc fd = {.label = "surface cache"};
        for (int l = 0; l < c->n_lights; l++)
            fd.color[l] = (lr_fb_attachment){NULL, l};
        if (!(rc = lr_tex_create(c->gl, &bd, &sc->B, e))) {
            for (int l = 0; l < c->n_lights; l++)
                fd.color[l].tex = sc->B;
            rc = lr_fb_create(c->gl, &fd, &sc->fb, e);
        }
    }
    if (rc) {
        free_entries(sc);
        return rc;
    }
    sc->n_objects = no;
    sc->entries = (int)total;
    sc->rows = rows;
    sc->n_lights = c->n_lights;
    sc->built = true;
    return LR_OK;
}

int lr_surface_run(lr_surface *sc, const lr_pass_ctx *c, const lr_radiosity *rad, lr_err *e)
{
    int rc;
    sc->valid = false;
    if ((!sc->built || sc->n_lights != c->n_lights || sc->n_objects != c->objs->n_objects) &&
        (rc = build(sc, c, rad, e)))
        return rc;
    lr_program *p = c->prog->cache;
    lr_fb_bind(sc->fb);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glUseProgram(lr_program_id(p));
    /* Unit intensity, no cavity gain: composition multiplies each object's gain per light. */
    double unit[LR_MAX_LIGHTS][3];
    for (int l = 0; l < LR_MAX_LIGHTS; l++)
        unit[l][0] = unit[l][1] = unit[l][2] = 1.0;
    lr_radiosity_bind_gather(rad, p, unit);
    lr_passes_bind_tex(p, "u_entry_pos", 0, sc->pos);
    lr_passes_bind_tex(p, "u_entry_nrm", 1, sc->nrm);
    lr_gl_draw_fullscreen(c->gl);
    if ((rc = lr_gl_check("surface cache pass", e)))
        return rc;
    sc->valid = true;
    return LR_OK;
}

void lr_surface_draw(const lr_surface *sc, int object)
{
    glBindVertexArray(sc->mesh[object].vao);
    glDrawArrays(GL_TRIANGLES, 0, sc->mesh[object].count);
    glBindVertexArray(0);
}

void lr_surface_bind(const lr_surface *sc, lr_program *p)
{
    lr_passes_bind_tex(p, "u_surface_B", 11, sc->B);
    lr_passes_uniform_i(p, "u_surface_row", LR_SURFACE_ROW);
}
