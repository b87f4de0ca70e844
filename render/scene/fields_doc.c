/* The scene field reference (lr_scene_fields_markdown) written from the field tables, so that
 * configs/scenes/README.md cannot drift from what the loader accepts. */
#include <string.h>

#include "render/scene/fields.h"
#include "render/scene/scene_internal.h"

static const char *type_text(const lr_field *f, char *buf, size_t cap)
{
    switch (f->type) {
    case LR_FT_NUM: return "number";
    case LR_FT_INT:
    case LR_FT_UINT: return "integer";
    case LR_FT_VEC3:
    case LR_FT_SIZE3: return "[x, y, z]";
    case LR_FT_RGB: return "[r, g, b]";
    case LR_FT_PAIR: return "[w, h]";
    case LR_FT_SCALE: return "number or [x, y, z]";
    case LR_FT_BOOL: return "true, false";
    case LR_FT_PATH: return "path";
    case LR_FT_NAME: return "name";
    case LR_FT_OBJECT: return "object";
    case LR_FT_ENUM:
    case LR_FT_ENUMB:
    case LR_FT_TYPE: break;
    }
    buf[0] = '\0';
    for (int i = 0; f->names[i]; i++)
        snprintf(buf + strlen(buf), cap - strlen(buf), "%s`%s`", i ? ", " : "", f->names[i]);
    return buf;
}

static void range_cell(const lr_field *f, char *buf, size_t cap)
{
    char r[96];
    lr_field_range_text(f, r, sizeof r);
    const char *each = f->type == LR_FT_RGB ? "each band "
                       : f->type == LR_FT_SIZE3 || f->type == LR_FT_PAIR ? "each side " : "";
    snprintf(buf, cap, "%s%s%s%s%s%s", r[0] ? each : "", r,
             f->flags & LR_FF_COORD ? "within 1e6 mm of the origin" : "",
             f->flags & LR_FF_UNIT ? "non-zero (normalised)" : "",
             f->flags & LR_FF_ANGLES ? "finite" : "", "");
    if (f->unit && !(f->flags & LR_FF_COORD))
        snprintf(buf + strlen(buf), cap - strlen(buf), "%s%s", buf[0] ? " " : "", f->unit);
}

/* rec: a record of the kind with its defaults (resolved where a generator fills them in). */
static void default_cell(const lr_field *f, const void *rec, char *buf, size_t cap)
{
    if (f->flags & LR_FF_REQUIRED) {
        snprintf(buf, cap, "required");
        return;
    }
    if (f->dflt_text || f->type >= LR_FT_NAME) {
        snprintf(buf, cap, "%s", f->dflt_text ? f->dflt_text : "");
        return;
    }
    const char *p = (const char *)rec + f->off;
    const double *v = (const double *)p;
    switch (f->type) {
    case LR_FT_NUM: snprintf(buf, cap, "%g", *v); break;
    case LR_FT_INT: snprintf(buf, cap, "%d", *(const int *)p); break;
    case LR_FT_UINT: snprintf(buf, cap, "%u", *(const unsigned *)p); break;
    case LR_FT_VEC3:
    case LR_FT_SCALE: {
        const lr_vec3 *x = (const lr_vec3 *)p;
        if (f->type == LR_FT_SCALE && x->x == x->y && x->y == x->z)
            snprintf(buf, cap, "%g", x->x);
        else
            snprintf(buf, cap, "[%g, %g, %g]", x->x, x->y, x->z);
        break;
    }
    case LR_FT_RGB:
    case LR_FT_SIZE3: snprintf(buf, cap, "[%g, %g, %g]", v[0], v[1], v[2]); break;
    case LR_FT_PAIR: snprintf(buf, cap, "[%g, %g]", v[0], v[1]); break;
    case LR_FT_BOOL:
        snprintf(buf, cap, "%s", *(const bool *)p != !!(f->flags & LR_FF_INVERT) ? "true"
                                                                                 : "false");
        break;
    case LR_FT_ENUM: snprintf(buf, cap, "`%s`", f->names[*(const int *)p]); break;
    case LR_FT_ENUMB: snprintf(buf, cap, "`%s`", f->names[*(const bool *)p ? 1 : 0]); break;
    default: buf[0] = '\0'; break;
    }
    if (f->flags & LR_FF_ZERO_DEFAULT)
        snprintf(buf + strlen(buf), cap - strlen(buf), " (also 0)");
}

static void dirty_cell(unsigned dirty, char *buf, size_t cap)
{
    buf[0] = '\0';
    for (unsigned bit = 1; bit && dirty; bit <<= 1)
        if (dirty & bit) {
            char up[32];
            snprintf(up, sizeof up, "%s", lr_dirty_name(bit));
            for (char *c = up; *c; c++)
                *c = (char)(*c >= 'a' && *c <= 'z' ? *c - 'a' + 'A' : *c);
            snprintf(buf + strlen(buf), cap - strlen(buf), "%s`%s`", buf[0] ? ", " : "", up);
            dirty &= ~bit;
        }
}

/* A mesh of the kind with the generator's defaults resolved (render/mesh/shapes.h). */
static void mesh_defaults(int kind, mesh_spec *m)
{
    memset(m, 0, sizeof *m);
    m->kind = (enum lr_mesh_kind)kind;
    lr_fields_defaults(&lr_scene_mesh_desc, m);
    mesh_spec z = *m;
    const char *bad;
    lr_err ignore = {0};
    lr_candle_check(&z.candle, &m->candle, &bad, &ignore);
    lr_shade_check(&z.shade, &m->shade, &bad, &ignore);
    lr_sphere_check(&z.sphere, &m->sphere, &bad, &ignore);
    lr_box_check(&z.box, &m->box, &bad, &ignore);
}

static void table(FILE *out, const lr_record_desc *d)
{
    fprintf(out, "\n#### `%s`\n\n", d->section);
    bool kinds = d->kind_names != NULL;
    fprintf(out, "| field |%s value | range | default | a change sets | what |\n",
            kinds ? " for |" : "");
    fprintf(out, "|---|%s---|---|---|---|---|\n", kinds ? "---|" : "");
    union {
        lr_light light;
        lr_camera camera;
        lr_receiver receiver;
        obj_rec object;
        mesh_spec mesh;
        xform_spec xform;
        lr_render_settings render;
        lr_quality quality;
    } rec;
    for (int i = 0; i < d->n; i++) {
        const lr_field *f = &d->fields[i];
        memset(&rec, 0, sizeof rec);
        int kind = 0;
        while (kinds && !lr_field_has(f, kind))
            kind++;
        if (d == &lr_scene_mesh_desc)
            mesh_defaults(kind, &rec.mesh);
        else
            lr_fields_defaults(d, &rec);
        char type[160], range[160], dflt[96], dirty[96], forw[96] = "";
        for (int k = 0; kinds && d->kind_names[k]; k++)
            if (f->kinds && lr_field_has(f, k))
                snprintf(forw + strlen(forw), sizeof forw - strlen(forw), "%s%s",
                         forw[0] ? ", " : "", d->kind_names[k]);
        range_cell(f, range, sizeof range);
        default_cell(f, &rec, dflt, sizeof dflt);
        dirty_cell(f->flags & LR_FF_NO_SET ? 0 : f->dirty, dirty, sizeof dirty);
        fprintf(out, "| `%s` |", f->key);
        if (kinds)
            fprintf(out, " %s |", f->kinds ? forw : "all");
        fprintf(out, " %s | %s | %s | %s | %s |\n", type_text(f, type, sizeof type), range, dflt,
                f->flags & LR_FF_NO_SET ? "(fixed)" : dirty, f->help);
    }
}

void lr_scene_fields_markdown(FILE *out)
{
    const lr_record_desc *all[] = {&lr_scene_object_desc,   &lr_scene_mesh_desc,
                                   &lr_scene_transform_desc, &lr_scene_light_desc,
                                   &lr_scene_camera_desc,   &lr_scene_receiver_desc,
                                   &lr_scene_render_desc,   &lr_scene_quality_desc};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++)
        table(out, all[i]);
}
