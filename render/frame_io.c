/* frame_io.c - frame + scene -> image file with metadata. */
#include "render/frame_io.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/image_io.h"
#include "core/version.h"

const char *const nc_quantity_names[] = {"radiance", "iof", "range", "rock_id", "electrons", "dn", NULL};

const char *nc_quantity_units(enum nc_quantity q)
{
    static const char *const u[] = {"W m^-2 sr^-1", "1 (I/F)", "m", "1 (index in the body's boulder list, -1: none)", "e-", "DN"};
    return u[q];
}

int nc_quantity_parse(const char *name, enum nc_quantity *q)
{
    for (int i = 0; nc_quantity_names[i]; i++)
        if (strcmp(name, nc_quantity_names[i]) == 0) {
            *q = (enum nc_quantity)i;
            return 0;
        }
    return nc_error(NC_EUSAGE, "unknown quantity '%s' (expected radiance, iof, range, rock_id, electrons or dn)", name);
}

int nc_quantity_format_check(enum nc_quantity q, const char *path)
{
    int is_float = 1;
    if (q == NC_Q_ROCK_ID && nc_image_format_ok(path, &is_float) && !is_float)
        return nc_error(NC_EUSAGE, "rock_id needs FITS, TIFF or EXR: a PNG holds no -1 (ground, sky, no rock), "
                                   "nor every index exactly");
    return 0;
}

int nc_frame_meta(const struct nc_scene *s, enum nc_quantity q, struct nc_image_attr *attrs, char (*v)[200], int max)
{
    const struct nc_camera *c = &s->camera;
    const struct nc_body *b0 = &s->body[0];
    struct nc_vec3 sun_dir;
    double sun_irr;
    if (max < 16)
        return 0;
    nc_scene_sun_at(s, b0->position_m, &sun_dir, &sun_irr);
    snprintf(v[0], 200, "NavCam %s", NC_VERSION_STRING);
    snprintf(v[1], 200, "%s", nc_quantity_names[q]);
    snprintf(v[2], 200, "%s", nc_quantity_units(q));
    snprintf(v[3], 200, "[%.17g, %.17g, %.17g]", c->position_m.x, c->position_m.y, c->position_m.z);
    snprintf(v[4], 200, "[%.17g, %.17g, %.17g, %.17g]", c->attitude_q.w, c->attitude_q.x, c->attitude_q.y,
             c->attitude_q.z);
    snprintf(v[5], 200, "[%.17g, %.17g, %.17g]", sun_dir.x, sun_dir.y, sun_dir.z);
    snprintf(v[6], 200, "%.17g", sun_irr);
    snprintf(v[7], 200, "[%.17g, %.17g, %.17g, %.17g]", c->fx_px, c->fy_px, c->cx_px, c->cy_px);
    snprintf(v[8], 200, "%d", s->render.samples_per_pixel);
    snprintf(v[9], 200, "[%.17g, %.17g, %.17g]", b0->position_m.x, b0->position_m.y, b0->position_m.z);
    snprintf(v[10], 200, "[%.17g, %.17g, %.17g, %.17g]", b0->attitude_q.w, b0->attitude_q.x, b0->attitude_q.y,
             b0->attitude_q.z);
    snprintf(v[11], 200, "[%.17g, %.17g, %.17g, %.17g, %.17g]", c->k1, c->k2, c->k3, c->p1, c->p2);
    snprintf(v[12], 200, "shadows=%s bounces=%d roulette_after=%d quality=%s", s->render.soft_shadows ? "soft" : "hard",
             s->render.bounces, s->render.roulette_after, s->render.quality_auto ? "auto" : "manual");
    const struct nc_image_attr a[] = {
        {"Software", v[0]},
        {"navcam:version", NC_VERSION_STRING},
        {"navcam:quantity", v[1]},
        {"navcam:units", v[2]},
        {"navcam:camera_position_m", v[3]},
        {"navcam:camera_attitude_q", v[4]},
        {"navcam:quaternion_convention", "scalar-first [w,x,y,z], Hamilton; rotates camera-frame vectors into the scene frame"},
        {"navcam:camera_frame", "+Z boresight, +X right, +Y down"},
        {"navcam:sun_direction_scene", v[5]},
        {"navcam:sun_irradiance_w_m2", v[6]},
        {"navcam:intrinsics_fx_fy_cx_cy_px", v[7]},
        {"navcam:distortion_k1_k2_k3_p1_p2", v[11]},
        {"navcam:samples_per_pixel", v[8]},
        {"navcam:light", v[12]},
        {"navcam:body0_position_m", v[9]},
        {"navcam:body0_attitude_q", v[10]},
    };
    int n = (int)(sizeof a / sizeof a[0]);
    memcpy(attrs, a, (size_t)n * sizeof a[0]);
    return n;
}

int nc_frame_write(const char *path, const struct nc_frame *f, enum nc_quantity q, const struct nc_scene *s,
                   const struct nc_image_attr *extra, int nextra, double *preview_scale)
{
    if (q > NC_Q_ROCK_ID)
        return nc_error(NC_EUSAGE, "quantity %s needs the camera model", nc_quantity_names[q]);
    if (q == NC_Q_ROCK_ID && !f->rock_id)
        return nc_error(NC_EUSAGE, "quantity rock_id needs a frame with its rock-id plane");
    struct nc_image_attr attrs[64];
    char text[24][200];
    int n = nc_frame_meta(s, q, attrs, text, 24);
    for (int i = 0; i < nextra && n < 64; i++)
        attrs[n++] = extra[i];
    const float *px = q == NC_Q_RADIANCE ? f->radiance : q == NC_Q_IOF ? f->iof : f->range_m;
    float *ids = NULL;
    if (q == NC_Q_ROCK_ID) {
        size_t np = (size_t)f->width_px * (size_t)f->height_px;
        if (!(ids = malloc(np * sizeof *ids)))
            return nc_error(-ENOMEM, "out of memory");
        for (size_t i = 0; i < np; i++)
            ids[i] = (float)f->rock_id[i];
        px = ids;
    }
    int rc = nc_image_write(path, px, f->width_px, f->height_px, attrs, n, preview_scale);
    free(ids);
    return rc;
}
