/* The scene file's fields (fields.h): one table per record, in the order the file reference
 * lists them and run-time errors name them. A range here is the only statement of it; the
 * relations between fields are in check.c. */
#include <stddef.h>

#include "render/photometry/photometry.h"
#include "render/scene/fields.h"
#include "render/scene/scene_internal.h"

#define NB LR_FNONE
#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

/* ---- lights ---------------------------------------------------------------------------------- */

#define P (1u << LR_LIGHT_POINT)
#define S (1u << LR_LIGHT_SPOT)
#define D (1u << LR_LIGHT_DIRECTIONAL)
#define Q (1u << LR_LIGHT_QUAD)
#define K (1u << LR_LIGHT_DISK)
#define L(m) offsetof(lr_light, m)

static const char *const light_types[] = {"point", "spot", "directional", "quad", "disk", NULL};
static const char *const light_what[] = {"a point light", "a spot light", "a directional light",
                                         "a quad light", "a disk light"};
static const char *const light_objects[] = {"flicker", NULL};

static const lr_field light_fields[] = {
    {"type", LR_FT_TYPE, .names = light_types, .flags = LR_FF_REQUIRED | LR_FF_NO_SET,
     .help = "point, spot, directional, quad or disk"},
    {"name", LR_FT_NAME, .dflt_text = "light0, light1, ...", .flags = LR_FF_NO_SET,
     .help = "unique; letters, digits, _ and - (not only digits)"},
    /* One of intensity, intensity_cd and flux_lm (radiance and flux_lm for area lights) is
     * given: load.c; the record check derives the others (lr_light_resolve_units), so a get
     * reads the present value in each unit and a set of any of them is the dimmer. */
    {"intensity", LR_FT_NUM, P | S, L(intensity), 0, 1e12, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .dflt_text = "one of intensity, intensity_cd, flux_lm", .unit = "(W/sr)",
     .dirty = LR_DIRTY_INTENSITY, .help = "radiant intensity (on axis for a spot): the dimmer"},
    {"intensity_cd", LR_FT_NUM, P | S, L(intensity_cd), 0, 1e15, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .dflt_text = "one of intensity, intensity_cd, flux_lm", .unit = "(cd)",
     .dirty = LR_DIRTY_INTENSITY,
     .help = "luminous intensity (on axis for a spot): intensity = intensity_cd / (683 lm/W "
             "x Y(color)); a candle flame ~1 cd"},
    {"flux_lm", LR_FT_NUM, P | S | Q | K, L(flux_lm), 0, 1e15, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .dflt_text = "one of the strengths", .unit = "(lm)", .dirty = LR_DIRTY_INTENSITY,
     .help = "luminous flux: over 4 pi sr (point), the cone's distribution (spot), pi x area "
             "per side (quad, disk: a Lambertian emitter)"},
    {"radiance", LR_FT_NUM, D, L(intensity), 0, 1e12, LR_FF_REQUIRED | LR_FF_HI_OPEN |
     LR_FF_HI_QUIET, .unit = "(W/mm^2)", .dirty = LR_DIRTY_INTENSITY,
     .help = "irradiance on a surface facing the light (seed 003 Eq. 6)"},
    {"radiance", LR_FT_NUM, Q | K, L(intensity), 0, 1e12, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .dflt_text = "one of radiance, flux_lm", .unit = "(W/(mm^2 sr))",
     .dirty = LR_DIRTY_INTENSITY,
     .help = "emitted radiance of the Lambertian area light: the dimmer"},
    {"color", LR_FT_RGB, 0, L(color), 0, 1e6, LR_FF_HI_OPEN | LR_FF_HI_QUIET, .dflt = {1, 1, 1},
     .dirty = LR_DIRTY_INTENSITY, .help = "per-band factor: band b gets intensity * color[b]"},
    {"color_temperature_k", LR_FT_NUM, 0, L(color_temperature_k), LR_CCT_MIN_K, LR_CCT_MAX_K,
     LR_FF_ZERO_ABSENT, .dflt_text = "none (color)", .unit = "K", .dirty = LR_DIRTY_INTENSITY,
     .help = "instead of color: a Planckian radiator's colour (CIE 1931, linear sRGB), "
             "intensity its visible watts (candle ~1900 K, warm lamp 2700 K)"},
    {"position", LR_FT_VEC3, P | S, L(position), NB, NB, LR_FF_REQUIRED | LR_FF_COORD,
     .unit = "mm", .dirty = LR_DIRTY_LIGHT_GEOMETRY, .help = "where the light is"},
    {"position", LR_FT_VEC3, Q | K, L(position), NB, NB, LR_FF_REQUIRED | LR_FF_COORD,
     .unit = "mm", .dirty = LR_DIRTY_LIGHT_GEOMETRY, .help = "the emitter's centre"},
    /* Not parallel to each other: check.c. */
    {"edge_u", LR_FT_VEC3, Q, L(edge_u), -1e6, 1e6, LR_FF_REQUIRED, .unit = "mm",
     .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "half-edge vector from the centre (the quad spans -edge_u..edge_u)"},
    {"edge_v", LR_FT_VEC3, Q, L(edge_v), -1e6, 1e6, LR_FF_REQUIRED, .unit = "mm",
     .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "second half-edge vector; emits on the side of edge_u x edge_v"},
    {"normal", LR_FT_VEC3, K, L(direction), NB, NB, LR_FF_REQUIRED | LR_FF_UNIT,
     .dflt = {0, 0, -1}, .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "the emitting side (normalised)"},
    {"radius", LR_FT_NUM, K, L(radius), 0, 1e6, LR_FF_REQUIRED | LR_FF_LO_OPEN | LR_FF_HI_QUIET,
     .unit = "mm", .dirty = LR_DIRTY_LIGHT_GEOMETRY, .help = "disk radius"},
    {"two_sided", LR_FT_BOOL, Q | K, L(two_sided), .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "emit on both sides (an LED strip seen from both faces)"},
    {"direction", LR_FT_VEC3, S | D, L(direction), NB, NB, LR_FF_REQUIRED | LR_FF_UNIT,
     .dflt = {0, 0, -1}, .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "the way the light travels (normalised)"},
    {"direction", LR_FT_VEC3, P, L(direction), NB, NB, LR_FF_UNIT, .dflt = {0, 0, -1},
     .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "with a profile: the luminaire's nadir (gamma 0; normalised)"},
    /* Loaded with the scene (load.c), so not settable at run time. */
    {"profile", LR_FT_PATH, P | S | Q | K, L(profile_path), .flags = LR_FF_NO_SET,
     .dflt_text = "none",
     .help = "photometric file (.ies LM-63, .ldt EULUMDAT), relative to the scene: the "
             "intensity per direction (render/photometry/profile.h); without a strength, the "
             "file's flux (or its candela)"},
    {"profile_c0", LR_FT_VEC3, P | S | Q | K, L(profile_c0), -1e6, 1e6, 0,
     .dflt_text = "a quad's edge_u, else +x", .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "with a profile: the direction of its C0 plane (the luminaire's length)"},
    /* inner_deg's upper bound is outer_deg: check.c. */
    {"inner_deg", LR_FT_NUM, S, L(inner_deg), NB, NB, 0, .dflt = {20}, .unit = "degrees",
     .dirty = LR_DIRTY_LIGHT_GEOMETRY, .help = "half-angle of full intensity, (0, outer_deg]"},
    {"outer_deg", LR_FT_NUM, S, L(outer_deg), 0, 90, LR_FF_LO_OPEN | LR_FF_HI_OPEN,
     .dflt = {30}, .unit = "degrees", .dirty = LR_DIRTY_LIGHT_GEOMETRY,
     .help = "half-angle of zero intensity"},
    /* Flicker is applied by the renderer at composition on its clock (render/renderer.h
     * lr_renderer_set_time), the sway included: the transport stays at the light's mean
     * position (jitter << 1/sigma_tr), so every flicker field is composition-only. */
    {"flicker.amplitude", LR_FT_NUM, P | S, L(flicker.amplitude), 0, 1, 0,
     .dirty = LR_DIRTY_INTENSITY, .help = "relative intensity swing; 0: steady"},
    {"flicker.frequency_hz", LR_FT_NUM, P | S, L(flicker.frequency_hz), 0, 1000,
     LR_FF_LO_OPEN, .dflt = {8}, .unit = "Hz", .dirty = LR_DIRTY_INTENSITY,
     .help = "dominant frequency (candle flames: a few Hz to ~10 Hz)"},
    {"flicker.jitter_mm", LR_FT_NUM, P | S, L(flicker.jitter_mm), 0, 1000, 0, .unit = "mm",
     .dirty = LR_DIRTY_INTENSITY, .help = "position sway amplitude; 0: the flame stays put"},
    {"flicker.seed", LR_FT_UINT, P | S, L(flicker.seed), 0, NB, 0, .dflt = {1},
     .dirty = LR_DIRTY_INTENSITY, .help = "phases (replays see the same flame)"},
};

static int light_kind(const void *rec)
{
    return (int)((const lr_light *)rec)->type;
}

const lr_record_desc lr_scene_light_desc = {"lights[i]", "a light", light_types, light_what,
                                            light_kind, light_objects, light_fields,
                                            COUNT(light_fields)};
#undef P
#undef S
#undef D
#undef Q
#undef K

/* ---- camera ---------------------------------------------------------------------------------- */

#define PERSP (1u << 0)
#define ORTHO (1u << 1)
#define C(m) offsetof(lr_camera, m)

static const char *const camera_types[] = {"perspective", "orthographic", NULL};

static const lr_field camera_fields[] = {
    {"type", LR_FT_ENUMB, 0, C(orthographic), .names = camera_types, .dirty = LR_DIRTY_CAMERA,
     .help = "perspective or orthographic"},
    {"position", LR_FT_VEC3, 0, C(position), NB, NB, LR_FF_REQUIRED | LR_FF_COORD,
     .dflt = {0, -600, 300}, .unit = "mm", .dirty = LR_DIRTY_CAMERA, .help = "eye"},
    {"target", LR_FT_VEC3, 0, C(target), NB, NB, LR_FF_REQUIRED | LR_FF_COORD,
     .dflt = {0, 0, 60}, .unit = "mm", .dirty = LR_DIRTY_CAMERA,
     .help = "the point looked at (not the position)"},
    {"up", LR_FT_VEC3, 0, C(up), NB, NB, LR_FF_UNIT, .dflt = {0, 0, 1}, .dirty = LR_DIRTY_CAMERA,
     .help = "not along the view"},
    {"fov_deg", LR_FT_NUM, 0, C(fov_deg), 0, 180, LR_FF_LO_OPEN | LR_FF_HI_OPEN, PERSP,
     .dflt = {40}, .unit = "degrees", .dirty = LR_DIRTY_CAMERA,
     .help = "vertical field of view (perspective)"},
    {"height_mm", LR_FT_NUM, 0, C(height_mm), 0, 2e6, LR_FF_LO_OPEN | LR_FF_HI_QUIET, ORTHO,
     .dflt = {300}, .unit = "mm", .dirty = LR_DIRTY_CAMERA,
     .help = "view height (orthographic)"},
    {"near", LR_FT_NUM, 0, C(near_mm), 0, 1e7, LR_FF_LO_OPEN | LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .dflt = {10}, .unit = "mm", .dirty = LR_DIRTY_CAMERA, .help = "near clipping distance"},
    /* far's lower bound is near: check.c. */
    {"far", LR_FT_NUM, 0, C(far_mm), NB, NB, 0, .dflt = {10000}, .unit = "mm",
     .dirty = LR_DIRTY_CAMERA, .help = "far clipping distance, (near, 1e7]"},
};

static int camera_kind(const void *rec)
{
    return ((const lr_camera *)rec)->orthographic ? 1 : 0;
}

const lr_record_desc lr_scene_camera_desc = {"camera", "camera", NULL, NULL, camera_kind, NULL,
                                             camera_fields, COUNT(camera_fields)};

/* ---- receivers ------------------------------------------------------------------------------- */

#define PLANE (1u << LR_RECEIVER_PLANE)
#define BOX (1u << LR_RECEIVER_BOX)
#define R(m) offsetof(lr_receiver, m)

static const char *const receiver_types[] = {"plane", "box", NULL};
static const char *const receiver_what[] = {"a plane receiver", "a box receiver"};

static const lr_field receiver_fields[] = {
    {"type", LR_FT_TYPE, .names = receiver_types, .flags = LR_FF_REQUIRED | LR_FF_NO_SET,
     .help = "plane or box"},
    {"name", LR_FT_NAME, .dflt_text = "receiver0, ...", .flags = LR_FF_NO_SET,
     .help = "unique; letters, digits, _ and -"},
    {"albedo", LR_FT_RGB, 0, R(albedo), 0, 1, LR_FF_REQUIRED,
     .unit = "(a diffuse surface reflects at most what it receives)",
     .dirty = LR_DIRTY_RECEIVERS, .help = "diffuse reflectance per band"},
    {"center", LR_FT_VEC3, 0, R(center), NB, NB, LR_FF_REQUIRED, .unit = "mm",
     .dirty = LR_DIRTY_RECEIVERS, .help = "centre of the plane or box"},
    {"normal", LR_FT_VEC3, PLANE, R(normal), NB, NB, LR_FF_REQUIRED | LR_FF_UNIT,
     .dirty = LR_DIRTY_RECEIVERS, .help = "front normal, toward the scene"},
    {"u_dir", LR_FT_VEC3, PLANE, R(u_dir), NB, NB, 0, .dflt_text = "x, or y for a normal along x",
     .dirty = LR_DIRTY_RECEIVERS, .help = "direction of size[0], projected into the plane"},
    {"size", LR_FT_PAIR, PLANE, R(size), 0, NB, LR_FF_REQUIRED | LR_FF_LO_OPEN, .unit = "mm",
     .dirty = LR_DIRTY_RECEIVERS, .help = "w, h"},
    {"size", LR_FT_SIZE3, BOX, R(size), 0, NB, LR_FF_REQUIRED | LR_FF_LO_OPEN, .unit = "mm",
     .dirty = LR_DIRTY_RECEIVERS, .help = "x, y, z"},
    {"subdivisions", LR_FT_INT, PLANE, R(subdivisions), NB, NB, 0, .dflt_text = "1",
     .dirty = LR_DIRTY_RECEIVERS, .help = "grid cells per side (render/mesh/shapes.h)"},
};

static int receiver_kind(const void *rec)
{
    return (int)((const lr_receiver *)rec)->type;
}

const lr_record_desc lr_scene_receiver_desc = {"receivers[i]", "a receiver", receiver_types,
                                               receiver_what, receiver_kind, NULL,
                                               receiver_fields, COUNT(receiver_fields)};

/* ---- objects --------------------------------------------------------------------------------- */

#define O(m) offsetof(obj_rec, m)

static const char *const sss_models[] = {"directional_dipole", "standard_dipole", "multipole",
                                         "translucent_radiosity",
                                         "diffusion_grid", "sh_translucency", NULL};

static const lr_field object_fields[] = {
    {"name", LR_FT_NAME, .dflt_text = "object0, ...", .flags = LR_FF_NO_SET,
     .help = "unique; letters, digits, _ and -"},
    {"material", LR_FT_OBJECT, .flags = LR_FF_REQUIRED, .dirty = LR_DIRTY_MATERIAL,
     .help = "a preset name (configs/materials) or a material object (render/material)"},
    {"mesh", LR_FT_OBJECT, .flags = LR_FF_REQUIRED, .dirty = LR_DIRTY_GEOMETRY,
     .help = "the shape: objects[i].mesh below"},
    {"transform", LR_FT_OBJECT, .dirty = LR_DIRTY_GEOMETRY,
     .help = "placement: objects[i].transform below"},
    /* The lr_sss_model order. */
    {"model", LR_FT_ENUM, 0, O(pub.sss_model), .names = sss_models, .dirty = LR_DIRTY_MATERIAL,
     .help = "the S_d of the radiosity maps (seed 003; standard: Jensen 2001; multipole: "
             "Donner & Jensen 2005 slab, T across the wall, R on the same face; "
             "translucent_radiosity: seed 000's patch solve with the receivers, for materials "
             "of sigma_tr = sqrt(3 sigma_a (sigma_a + sigma_s_prime)) <= 500 /mm in every band "
             "(its properties' max_sigma_tr, render/models/translucent_radiosity/; a material beyond is refused); "
             "diffusion_grid: seed 001's grid solve, closed meshes; sh_translucency: seed 002, SH "
             "of the entering light times a thickness attenuation, the cheapest)"},
    /* The range is lr_multipole_thickness_validate's (LR_MULTIPOLE_D_MIN..MAX). */
    {"thickness_mm", LR_FT_NUM, 0, O(pub.thickness_mm), 1e-3, 1e4, .flags = LR_FF_ZERO_ABSENT,
     .unit = "mm", .dirty = LR_DIRTY_MATERIAL, .dflt_text = "none",
     .help = "the wall the multipole models; required with model multipole"},
    {"dgrid_h_mm", LR_FT_NUM, 0, O(pub.dgrid_h_mm), 0.05, 100.0, .flags = LR_FF_ZERO_ABSENT,
     .unit = "mm", .dirty = LR_DIRTY_MATERIAL, .dflt_text = "auto",
     .help = "diffusion_grid: grid spacing (auto: bounding radius / 20)"},
    {"dgrid_volume", LR_FT_PATH, 0, O(pub.dgrid_volume), .dirty = LR_DIRTY_MATERIAL,
     .dflt_text = "none",
     .help = "diffusion_grid: heterogeneous sigma_a, sigma_s' volume file (render/diffusion)"},
    {"normalize", LR_FT_BOOL, 0, O(pub.sd_raw), .flags = LR_FF_INVERT, .dflt = {1},
     .dirty = LR_DIRTY_MATERIAL,
     .help = "false: the profile as published (the directional dipole without its energy "
             "normalisation; the standard dipole and multipole without the exit's 1 / T_hem)"},
};

const lr_record_desc lr_scene_object_desc = {"objects[i]", "an object", NULL, NULL, NULL, NULL,
                                             object_fields, COUNT(object_fields)};

/* ---- meshes: the generators' descriptors (render/mesh/shapes.h), whose own checks hold the
 * ranges; 0 is "the generator's default" -------------------------------------------------- */

#define CANDLE (1u << LR_MESH_CANDLE)
#define SHADE (1u << LR_MESH_SHADE)
#define SPHERE (1u << LR_MESH_SPHERE)
#define MBOX (1u << LR_MESH_BOX)
#define MFILE (1u << LR_MESH_FILE)
#define M(m) offsetof(mesh_spec, m)
#define G LR_DIRTY_GEOMETRY

static const char *const mesh_types[] = {"candle", "shade", "sphere", "box", "file", NULL};
static const char *const mesh_what[] = {"a candle mesh", "a shade mesh", "a sphere mesh",
                                        "a box mesh", "a file mesh"};

static const lr_field mesh_fields[] = {
    {"type", LR_FT_TYPE, .names = mesh_types, .flags = LR_FF_REQUIRED | LR_FF_NO_SET,
     .help = "candle, shade, sphere, box or file (fixed at run time)"},
    {"radius", LR_FT_NUM, CANDLE, M(candle.radius), .unit = "mm", .dirty = G, .help = "pillar radius"},
    {"height", LR_FT_NUM, CANDLE, M(candle.height), .unit = "mm", .dirty = G, .help = "pillar height"},
    {"pool_depth", LR_FT_NUM, CANDLE, M(candle.pool_depth), .flags = LR_FF_ZERO_FLAG,
     .aux = M(candle.flat_top), .unit = "mm", .dirty = G,
     .help = "melt pool depth, < height; 0: a flat top"},
    {"pool_radius", LR_FT_NUM, CANDLE, M(candle.pool_radius), .dflt_text = "radius - 3",
     .unit = "mm", .dirty = G,
     .help = "melt pool radius, <= radius"},
    {"segments", LR_FT_INT, CANDLE, M(candle.segments), .dirty = G, .help = "around the axis"},
    {"pool_rings", LR_FT_INT, CANDLE, M(candle.pool_rings), .dirty = G,
     .help = "rings from the pool's centre to its edge"},
    {"side_rings", LR_FT_INT, CANDLE, M(candle.side_rings), .dflt_text = "auto", .dirty = G,
     .help = "along the height (auto: square-ish quads)"},
    {"radius_bottom", LR_FT_NUM, SHADE, M(shade.radius_bottom), .unit = "mm", .dirty = G,
     .help = "outer radius at z = 0"},
    {"radius_top", LR_FT_NUM, SHADE, M(shade.radius_top), .unit = "mm", .dirty = G,
     .help = "outer radius at the top"},
    {"height", LR_FT_NUM, SHADE, M(shade.height), .unit = "mm", .dirty = G, .help = "shade height"},
    {"thickness", LR_FT_NUM, SHADE, M(shade.thickness), .flags = LR_FF_ZERO_FLAG,
     .aux = M(shade.single_surface), .unit = "mm", .dirty = G,
     .help = "wall thickness; 0: a single surface"},
    {"rims", LR_FT_BOOL, SHADE, M(shade.no_rims), .flags = LR_FF_INVERT, .dflt = {1}, .dirty = G,
     .help = "close the shell at top and bottom"},
    {"segments", LR_FT_INT, SHADE, M(shade.segments), .dirty = G, .help = "around the axis"},
    {"rings", LR_FT_INT, SHADE, M(shade.rings), .dflt_text = "auto", .dirty = G,
     .help = "along the wall (auto: square-ish quads)"},
    {"radius", LR_FT_NUM, SPHERE, M(sphere.radius), .unit = "mm", .dirty = G, .help = "radius"},
    {"subdivisions", LR_FT_INT, SPHERE, M(sphere.subdivisions), .dirty = G,
     .help = "0..7: 20 * 4^n triangles"},
    {"size", LR_FT_VEC3, MBOX, M(box.size), .unit = "mm", .dirty = G, .help = "x, y, z"},
    {"path", LR_FT_PATH, MFILE, M(path), .flags = LR_FF_REQUIRED, .dirty = G,
     .help = ".ply or .obj, relative to the scene file"},
    {"scale", LR_FT_NUM, MFILE, M(file_scale), 0, 1e6, LR_FF_LO_OPEN | LR_FF_HI_OPEN |
     LR_FF_HI_QUIET, .dflt = {1}, .dirty = G, .help = "e.g. 1000 for a file in metres"},
};

static int mesh_kind(const void *rec)
{
    return (int)((const mesh_spec *)rec)->kind;
}

const lr_record_desc lr_scene_mesh_desc = {"objects[i].mesh", "a mesh", mesh_types, mesh_what,
                                           mesh_kind, NULL, mesh_fields, COUNT(mesh_fields)};

/* ---- transform ------------------------------------------------------------------------------- */

#define X(m) offsetof(xform_spec, m)

static const lr_field transform_fields[] = {
    {"translate", LR_FT_VEC3, 0, X(translate), NB, NB, LR_FF_COORD, .unit = "mm", .dirty = G,
     .help = "applied last"},
    {"rotate_deg", LR_FT_VEC3, 0, X(rotate_deg), NB, NB, LR_FF_ANGLES, .unit = "degrees",
     .dirty = G, .help = "about x, then y, then z"},
    {"scale", LR_FT_SCALE, 0, X(scale), 0, 1e6, LR_FF_LO_OPEN | LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .dflt = {1, 1, 1}, .unit = "(no mirroring)", .dirty = G,
     .help = "a number or per axis, applied first"},
};

const lr_record_desc lr_scene_transform_desc = {"objects[i].transform", "a transform", NULL,
                                                NULL, NULL, NULL, transform_fields,
                                                COUNT(transform_fields)};

/* ---- render settings and quality budget ------------------------------------------------------ */

#define RS(m) offsetof(lr_render_settings, m)
#define SET LR_DIRTY_SETTINGS
#define Z LR_FF_ZERO_DEFAULT

/* Seed 003 renders with 31 maps of 512^2 on a desktop GPU; a Raspberry-Pi-class GPU gets half
 * the maps at a quarter of the texels by default. K: the radiosity pass's arrays
 * (LR_SCENE_MAX_K), well under the 256 layers GL_MAX_ARRAY_TEXTURE_LAYERS is on GLES 3.x;
 * 8192: the largest texture an SBC GPU offers. */
static const lr_field render_fields[] = {
    {"K", LR_FT_INT, 0, RS(K), 1, LR_SCENE_MAX_K, Z, .dflt = {16}, .dirty = SET,
     .help = "scattered-radiosity maps"},
    {"N", LR_FT_INT, 0, RS(N), 1, 65536, Z, .dflt = {16}, .dirty = SET,
     .help = "samples per texel, band and frame"},
    {"N_vpl", LR_FT_INT, 0, RS(N_vpl), 1, 65536, Z, .dflt = {64}, .dirty = SET,
     .help = "virtual point lights"},
    {"map_size", LR_FT_INT, 0, RS(map_size), 8, 8192, Z, .dflt = {256}, .dirty = SET,
     .help = "radiosity map side, texels"},
    {"gbuffer_size", LR_FT_INT, 0, RS(gbuffer_size), 8, 8192, Z, .dflt = {256}, .dirty = SET,
     .help = "light G-buffer side (each cube face when enclosed)"},
    {"vpl_map_size", LR_FT_INT, 0, RS(vpl_map_size), 4, 4096, Z, .dflt = {64}, .dirty = SET,
     .help = "cube map of the outer surface that places the VPLs"},
    {"frames", LR_FT_INT, 0, RS(frames), 1, 10000000, Z, .dflt = {64}, .dirty = SET,
     .help = "progressive frames until converged"},
    {"exposure", LR_FT_NUM, 0, RS(exposure), 0, 1e30, Z | LR_FF_LO_OPEN | LR_FF_HI_OPEN |
     LR_FF_HI_QUIET, .dflt = {1}, .dirty = LR_DIRTY_DISPLAY,
     .help = "multiplies radiance in W/(mm^2 sr) before tone mapping"},
    /* One of exposure and exposure_ev (load.c); the check derives the other. */
    {"exposure_ev", LR_FT_NUM, 0, RS(exposure_ev), -60, 100, LR_FF_HI_QUIET,
     .dflt_text = "from exposure", .dirty = LR_DIRTY_DISPLAY,
     .help = "instead of exposure: a camera's EV100 (meter K = 12.5 cd/m^2 at 18 % grey; "
             "exposure = 9.8352e8 / 2^EV; +1 EV halves the image)"},
    /* Only how composition gets B changes (render/passes/surface.h): a view-class change. Off
     * by default: its error is not yet shown to be under the converged noise (PIPELINE.md). */
    {"surface_cache", LR_FT_BOOL, 0, RS(surface_cache), .dflt = {0}, .dirty = LR_DIRTY_CAMERA,
     .help = "objects' B from the per-vertex surface cache (false: Algorithm 1 per pixel)"},
    /* Camera moves from the cache, the still image gathered (render/README.md "Camera
     * moves"): how composition gets B during a move, a view-class change. */
    {"surface_cache_moves", LR_FT_BOOL, 0, RS(surface_cache_moves), .dflt = {1},
     .dirty = LR_DIRTY_CAMERA,
     .help = "with surface_cache false: camera moves compose from the surface cache, the "
             "frame after a move with Algorithm 1 per pixel"},
    {"lpv", LR_FT_INT, 0, RS(lpv), 0, 128, Z, .dflt = {0}, .dirty = SET,
     .help = "light-propagation volume cells per axis for area, point and spot lights' "
             "indirect light on plane receivers (seed 004; 0: off, else 2-128, e.g. 32)"},
    /* Beyond seed 003 (its VPLs have no visibility): each VPL's light on the receivers is
     * shadowed by the objects (render/shaders/lib/vpl_irradiance.glsl). The VPL images and the
     * irradiance grids change, so a settings change (render/README.md "VPL visibility"). */
    {"vpl_visibility", LR_FT_BOOL, 0, RS(vpl_visibility), .dflt = {0}, .dirty = SET,
     .help = "shadow each VPL's light on the receivers by the objects (beyond seed 003)"},
    /* The receivers' own radiosity solve (render/bounce/README.md): their bounce joins the
     * receiver irradiance grid, so a settings change. */
    {"receiver_bounce", LR_FT_BOOL, 0, RS(receiver_bounce), .dflt = {0}, .dirty = SET,
     .help = "light bounced between the plane receivers (seed 000 radiosity, objects occlude)"},
    /* With receiver_bounce: the receivers' radiosity lights the objects too (render/bounce/
     * objlight.h); per vertex and light, read by composition, so a settings change. */
    {"receiver_light_on_objects", LR_FT_BOOL, 0, RS(receiver_light_on_objects), .dflt = {1},
     .dirty = SET,
     .help = "with receiver_bounce: the receivers' light (direct, VPL, bounced) lights the objects"},
    /* The objects' inner faces' light through their openings (render/openings/README.md): it
     * joins the receiver irradiance grid, so a settings change. */
    {"opening_light", LR_FT_BOOL, 0, RS(opening_light), .dflt = {0}, .dirty = SET,
     .help = "light a shade's or cup's inner face sends to the plane receivers through its "
             "openings (issue 12)"},
    /* Where composition reads the VPLs' light on the receivers from (render/passes/PIPELINE.md
     * "Receiver irradiance cache"): the grid's pass runs or not, so a settings change. */
    {"irradiance_grid", LR_FT_BOOL, 0, RS(irradiance_grid), .dflt = {1}, .dirty = SET,
     .help = "the VPLs' light on the plane receivers from the irradiance grid (false: gathered "
             "per pixel at composition; kept on while receiver_bounce, opening_light or "
             "translucent_radiosity needs the grid)"},
};

const lr_record_desc lr_scene_render_desc = {"render", "render", NULL, NULL, NULL, NULL,
                                             render_fields, COUNT(render_fields)};

#define Q(m) offsetof(lr_quality, m)

static const lr_field quality_fields[] = {
    {"max_error", LR_FT_NUM, 0, Q(max_error), 0, 1e6, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .unit = "(0: no budget)", .dirty = SET,
     .help = "relative RMS error against the converged reference"},
    {"frame_ms", LR_FT_NUM, 0, Q(frame_ms), 0, 1e9, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .unit = "ms (0: no budget)", .dirty = SET, .help = "time budget per frame"},
    {"converge_ms", LR_FT_NUM, 0, Q(converge_ms), 0, 1e9, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .unit = "ms (0: no budget)", .dirty = SET,
     .help = "time budget from a change to the converged image (the light G-buffer and every "
             "accumulation frame, as measured): what a designer waits after turning a control"},
    {"change_ms", LR_FT_NUM, 0, Q(change_ms), 0, 1e9, LR_FF_HI_OPEN | LR_FF_HI_QUIET,
     .unit = "ms (0: none)", .dirty = SET,
     .help = "longest wait from a material change to the next frame: the planner leaves out "
             "models whose measured change cost is over it (configs/bench/models.csv)"},
};

const lr_record_desc lr_scene_quality_desc = {"quality", "quality", NULL, NULL, NULL, NULL,
                                              quality_fields, COUNT(quality_fields)};
