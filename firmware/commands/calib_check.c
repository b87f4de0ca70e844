/* `lamprig calib check FILE...`: load and validate calibration files of any kind. */
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calib/albedo.h"
#include "calib/calfile.h"
#include "calib/camcal.h"
#include "calib/camresp.h"
#include "calib/colormatrix.h"
#include "calib/graycode.h"
#include "calib/pose.h"
#include "calib/procam.h"
#include "calib/projresp.h"
#include "firmware/commands/calib_cli.h"
#include "render/base/json.h"

enum { CHECK_VALID, CHECK_INVALID, CHECK_SKIPPED };

/* Whether path is a calibration file at all: a JSON object with a top-level "kind" (every
 * calibration file has one; rig configs, scenes and materials have none). 1 yes, 0 no, -1 it
 * cannot be read or is not JSON (message in e). */
static int has_kind(const char *path, lr_err *e)
{
    lr_json *j;
    if (lr_json_load(path, &j, e))
        return -1;
    lr_jnode root = lr_json_root(j);
    int yes = lr_json_type(j, root) == LR_JSON_OBJECT && lr_json_get(j, root, "kind") != LR_JNONE;
    lr_json_destroy(j);
    return yes;
}

static bool known_kind(const char *kind)
{
    static const char *const kinds[] = {LR_CAMCAL_KIND,      LR_PROCAM_KIND,  LR_CAMRESP_KIND,
                                        LR_PROJRESP_KIND,    LR_COLORMATRIX_KIND, LR_POSE_KIND,
                                        LR_ALBEDO_KIND,      LR_GC_SEQUENCE_KIND};
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++)
        if (!strcmp(kind, kinds[k]))
            return true;
    return false;
}

/* Checks one file: CHECK_VALID (summary on stdout), CHECK_INVALID (the error on stderr) or
 * CHECK_SKIPPED (valid JSON but not a calibration file: one line on stdout). */
static int check_one(const char *path)
{
    char kind[64];
    lr_err e = {0};
    int k = has_kind(path, &e);
    if (k < 0) {
        fprintf(stderr, "%s\n", e.msg);
        return CHECK_INVALID;
    }
    if (k == 0) {
        printf("%s: not a calibration file (no \"kind\"), skipped\n", path);
        return CHECK_SKIPPED;
    }
    if (lr_calfile_peek_kind(path, kind, sizeof kind, &e)) {
        fprintf(stderr, "%s\n", e.msg);
        return CHECK_INVALID;
    }
    if (!known_kind(kind)) {
        printf("%s: not a calibration file (kind '%s'), skipped\n", path, kind);
        return CHECK_SKIPPED;
    }
    int rc = LR_OK;
    if (!strcmp(kind, LR_CAMCAL_KIND)) {
        lr_camcal c;
        if (!(rc = lr_camcal_load(path, &c, &e))) {
            printf("%s: camera %dx%d, fx %.3f fy %.3f cx %.3f cy %.3f, rms %.4f px, %d views\n",
                   path, c.k.width, c.k.height, c.k.fx, c.k.fy, c.k.cx, c.k.cy, c.rms, c.nviews);
            lr_camcal_free(&c);
        }
    } else if (!strcmp(kind, LR_PROCAM_KIND)) {
        lr_procam p;
        if (!(rc = lr_procam_load(path, &p, &e))) {
            printf("%s: projector %dx%d fx %.3f fy %.3f cx %.3f cy %.3f; camera %dx%d; "
                   "T (%.2f, %.2f, %.2f) mm; stereo rms %.4f px\n",
                   path, p.proj.width, p.proj.height, p.proj.fx, p.proj.fy, p.proj.cx, p.proj.cy,
                   p.cam.width, p.cam.height, p.T[0], p.T[1], p.T[2], p.rms);
            lr_procam_free(&p);
        }
    } else if (!strcmp(kind, LR_CAMRESP_KIND)) {
        lr_camresp r;
        if (!(rc = lr_camresp_load(path, &r, &e)))
            printf("%s: camera response, %d exposures\n", path, r.images);
    } else if (!strcmp(kind, LR_PROJRESP_KIND)) {
        lr_projresp *r = malloc(sizeof *r);
        if (!r)
            rc = lr_err_set(&e, LR_ENOMEM, "out of memory");
        else if (!(rc = lr_projresp_load(path, r, &e)))
            printf("%s: projector response, %d levels, gamma %.3f %.3f %.3f\n", path, r->nlevels,
                   r->gamma[0], r->gamma[1], r->gamma[2]);
        free(r);
    } else if (!strcmp(kind, LR_COLORMATRIX_KIND)) {
        lr_colormatrix m;
        if (!(rc = lr_colormatrix_load(path, &m, &e)))
            printf("%s: colour matrix from %d patches, rms %.4f\n", path, m.patches, m.rms);
    } else if (!strcmp(kind, LR_POSE_KIND)) {
        lr_rig_pose p;
        if (!(rc = lr_rig_pose_load(path, &p, &e))) {
            lr_vec3 c = lr_pose_center(&p.camera);
            printf("%s: pose from %s, camera at (%.2f, %.2f, %.2f) mm, rms %.4f px%s\n", path,
                   p.source, c.x, c.y, c.z, p.rms, p.has_projector ? ", with projector" : "");
        }
    } else if (!strcmp(kind, LR_ALBEDO_KIND)) {
        lr_albedo a;
        if (!(rc = lr_albedo_load(path, &a, &e))) {
            printf("%s: mockup response %dx%d, %ld pixels measured, %ld filled\n", path,
                   a.response.width, a.response.height, a.measured_pixels, a.filled_pixels);
            lr_albedo_free(&a);
        }
    } else if (!strcmp(kind, LR_GC_SEQUENCE_KIND)) {
        char dir[4096];
        snprintf(dir, sizeof dir, "%s", path);
        char *slash = strrchr(dir, '/');
        if (slash)
            *slash = '\0';
        else
            snprintf(dir, sizeof dir, ".");
        int pw, ph;
        if (!(rc = lr_gc_read_sequence(dir, &pw, &ph, &e)))
            printf("%s: Gray-code sequence for a %dx%d projector\n", path, pw, ph);
    }
    if (rc) {
        fprintf(stderr, "%s\n", e.msg);
        return CHECK_INVALID;
    }
    return CHECK_VALID;
}

static int run(const lr_cli *c)
{
    const lr_args *a = &c->args;
    if (a->npos < 1)
        return lr_cli_usage(c->path, "expected one or more calibration files");
    int count[3] = {0};
    for (int i = 0; i < a->npos; i++)
        count[check_one(a->pos[i])]++;
    if (a->npos > 1)
        printf("%d valid, %d invalid, %d not calibration files\n", count[CHECK_VALID],
               count[CHECK_INVALID], count[CHECK_SKIPPED]);
    /* Files that are not calibration files (a glob over a folder that also holds rig configs)
     * do not fail the check; one that is, or claims to be, and does not load does. */
    return count[CHECK_INVALID] ? LR_EXIT_FAIL : LR_EXIT_OK;
}

static const lr_argspec opts[] = {{0}};

const lr_command lr_calib_check = {
    .name = "check",
    .summary = "load and validate calibration files of any kind, print a summary; a JSON file\n"
               "that is not a calibration file (no \"kind\", e.g. a rig config) is named and\n"
               "skipped; exit status 1 only when a file cannot be read, is not JSON or is a\n"
               "calibration file that does not load",
    .opts = opts,
    .operands = "FILE...",
    .max_operands = LR_ARGS_POS,
    .notes = "Exit status: 0 every calibration file loads, 1 one does not, 2 bad arguments.",
    .run = run,
};
