/* output.c - opening drivers by name, the frame record as JSON and as a binary block. */
#include "emulator/output.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "core/error.h"
#include "core/le.h"
#include "render/rt.h"

static const struct nc_param common_params[] = {
    NC_P_STRING("driver", NULL, "the output (`navcam serve --help` lists them)"),
    NC_P_END,
};

int nc_output_check(const struct nc_output_driver *drv, struct nc_cfg_node *opts)
{
    char what[96];
    snprintf(what, sizeof what, "output driver '%s'", drv->name);
    const struct nc_param *const tables[] = {common_params, drv->params};
    int rc = nc_params_check(opts, tables, 2, what);
    if (rc >= 0)
        rc = nc_params_values(opts, tables, 2);
    return rc < 0 || !drv->check ? rc : drv->check(opts);
}

int nc_output_open(struct nc_output *o, const struct nc_output_driver *drv, struct nc_cfg_node *opts,
                   const struct nc_output_ctx *ctx)
{
    memset(o, 0, sizeof *o);
    int rc = nc_output_check(drv, opts);
    if (rc < 0)
        return rc;
    o->drv = drv;
    o->priv = calloc(1, o->drv->priv_size ? o->drv->priv_size : 1);
    if (!o->priv)
        return nc_error(-ENOMEM, "out of memory");
    if ((rc = o->drv->open(o->priv, opts, ctx)) < 0) {
        free(o->priv);
        o->priv = NULL;
    }
    return rc;
}

int nc_output_submit(struct nc_output *o, const struct nc_frame_record *r)
{
    int rc = o->drv->submit(o->priv, r);
    if (rc < 0)
        o->failed++;
    else
        o->submitted++;
    return rc;
}

int nc_output_control(struct nc_output *o, const char *request, void *arg)
{
    if (!o->drv->control)
        return NC_EUNSUPPORTED;
    return o->drv->control(o->priv, request, arg);
}

void nc_output_close(struct nc_output *o)
{
    if (o->drv && o->priv)
        o->drv->close(o->priv);
    free(o->priv);
    memset(o, 0, sizeof *o);
}

static const char *const quality_names[] = {"interpolated", "extrapolated", "stale", "none", "scene"};

/* The Sun as the frame used it, as every writer of its record gives it: a
 * direction made a unit vector, a position as it is. */
static struct nc_vec3 record_sun(const struct nc_pose *p) { return p->sun_is_position ? p->sun : nc_v3_unit(p->sun); }

int nc_frame_record_json(const struct nc_frame_record *r, int wall_clock, char *buf, size_t len)
{
    const struct nc_pose *p = &r->pose;
    char mono[200] = "", ms[100] = "";
    if (wall_clock) {
        snprintf(mono, sizeof mono,
                 "\"trigger_mono_ns\": %lld, \"exposure_start_mono_ns\": %lld, \"exposure_end_mono_ns\": %lld, ",
                 (long long)r->trigger_mono_ns, (long long)r->exposure_start_mono_ns, (long long)r->exposure_end_mono_ns);
        snprintf(ms, sizeof ms, "\"render_ms\": %.3f, \"camera_ms\": %.3f, ", r->render_ms, r->camera_ms);
    }
    char stars[512] = "";
    if (r->stars_on)
        snprintf(stars, sizeof stars, "\"stars\": {\"limit_mag\": %.4g, \"drawn\": %ld, \"hidden\": %ld}, ",
                 r->star_limit_mag, r->stars_drawn, r->stars_hidden);
    if (r->sun_in_field || r->sun_near_field) { /* the Sun in or near the field: a warning */
        size_t k = strlen(stars);
        snprintf(stars + k, sizeof stars - k,
                 "\"sun\": {\"warning\": \"%s\", \"off_axis_deg\": %.6g, \"edge_deg\": %.6g, \"hidden\": %s}, ",
                 r->sun_in_field ? "sun in field" : "sun near field", r->sun_off_axis_deg, r->sun_edge_deg,
                 r->sun_hidden ? "true" : "false");
    }
    if (nc_rt_mostly_back(r->hit_samples, r->back_samples)) { /* a camera inside a body? */
        size_t k = strlen(stars);
        snprintf(stars + k, sizeof stars - k,
                 "\"inside\": {\"warning\": \"camera inside a body?\", \"back_samples\": %lu, "
                 "\"hit_samples\": %lu}, ",
                 r->back_samples, r->hit_samples);
    } else if (r->in_rock1 > 0) { /* rocks are one-sided: it sees out of the rock */
        size_t k = strlen(stars);
        snprintf(stars + k, sizeof stars - k,
                 "\"inside\": {\"warning\": \"camera inside a boulder\", \"body\": %d, \"boulder\": %ld}, ",
                 r->in_rock_body, r->in_rock1 - 1);
    }
    const struct nc_vec3 sun = record_sun(p);
    int n = snprintf(
        buf, len,
        "{\"frame\": %llu, \"request_sequence\": %u, \"trigger_source\": \"%s\", "
        "\"trigger_sim_ns\": %lld, \"exposure_start_sim_ns\": %lld, \"exposure_end_sim_ns\": %lld, %s"
        "\"pose\": {\"t_ns\": %lld, \"quality\": \"%s\", \"gap_ns\": %lld, "
        "\"camera_position_m\": [%.17g, %.17g, %.17g], \"camera_attitude_q\": [%.17g, %.17g, %.17g, %.17g], "
        "\"sun\": [%.17g, %.17g, %.17g], \"sun_is_position\": %s, \"body\": %s, "
        "\"body_position_m\": [%.17g, %.17g, %.17g], \"body_attitude_q\": [%.17g, %.17g, %.17g, %.17g]}, "
        "\"exposure_s\": %.17g, \"gain_db\": %.17g, \"time_samples\": %d, \"lod_error_m\": %.17g, "
        "\"boulder_min_m\": %.17g, \"boulder_mesh_px\": %.17g, \"rock_fold_theta_bar_deg\": %.17g, "
        "\"render\": {\"quality\": \"%s\", \"samples_per_pixel\": %d, \"bounces\": %d, \"soft_shadows\": %s}, %s%s"
        "\"width_px\": %d, \"height_px\": %d, \"adc_bits\": %d}",
        (unsigned long long)r->frame, r->request_sequence, r->trigger_source, (long long)r->trigger_sim_ns,
        (long long)r->exposure_start_sim_ns, (long long)r->exposure_end_sim_ns, mono, (long long)p->t_ns,
        quality_names[r->pose_quality], (long long)r->pose_gap_ns, p->cam_position_m.x, p->cam_position_m.y,
        p->cam_position_m.z, p->cam_attitude_q.w, p->cam_attitude_q.x, p->cam_attitude_q.y, p->cam_attitude_q.z,
        sun.x, sun.y, sun.z, p->sun_is_position ? "true" : "false", p->has_body ? "true" : "false",
        p->body_position_m.x, p->body_position_m.y, p->body_position_m.z, p->body_attitude_q.w, p->body_attitude_q.x,
        p->body_attitude_q.y, p->body_attitude_q.z, r->exposure_s, r->gain_db, r->time_samples, r->lod_error_m, r->boulder_min_m,
        r->boulder_mesh_px, r->rock_fold_theta_bar_deg, r->quality_auto ? "auto" : "manual", r->samples_per_pixel, r->bounces,
        r->soft_shadows ? "true" : "false", stars, ms, r->width_px,
        r->height_px, r->adc_bits);
    return n >= 0 && (size_t)n < len ? n : -1;
}

/* The metadata block (docs/gige.md gives the layout), little-endian: a
 * 48-byte core with its own CRC (fits a Mono8 row of 48 pixels), then the
 * pose, with a CRC over everything. */
static void metadata(const struct nc_frame_record *r, uint8_t m[NC_FRAME_META_BYTES])
{
    memset(m, 0, NC_FRAME_META_BYTES);
    memcpy(m, "NCMD", 4);
    nc_le_put_u16(m + 4, 1);
    nc_le_put_u16(m + 6, NC_FRAME_META_BYTES);
    nc_le_put_u64(m + 8, r->frame);
    nc_le_put_u64(m + 16, (uint64_t)r->exposure_start_sim_ns);
    nc_le_put_f64(m + 24, r->exposure_s);
    nc_le_put_f64(m + 32, r->gain_db);
    nc_le_put_u32(m + 40, r->request_sequence);
    nc_le_put_u32(m + 44, (uint32_t)crc32(0L, m, 44));
    nc_le_put_u64(m + 48, (uint64_t)r->trigger_sim_ns);
    nc_le_put_u64(m + 56, (uint64_t)r->exposure_end_sim_ns);
    nc_le_put_u64(m + 64, (uint64_t)r->exposure_start_mono_ns);
    const struct nc_pose *p = &r->pose;
    const struct nc_vec3 sun = record_sun(p);
    const double v[10] = {p->cam_position_m.x, p->cam_position_m.y, p->cam_position_m.z, p->cam_attitude_q.w,
                          p->cam_attitude_q.x, p->cam_attitude_q.y, p->cam_attitude_q.z, sun.x,
                          sun.y,               sun.z};
    for (int i = 0; i < 10; i++)
        nc_le_put_f64(m + 72 + 8 * i, v[i]);
    m[152] = (uint8_t)p->sun_is_position;
    m[153] = (uint8_t)r->pose_quality;
    nc_le_put_u16(m + 154, (uint16_t)r->adc_bits);
    nc_le_put_u32(m + 156, (uint32_t)crc32(0L, m, 156));
}

void nc_frame_metadata_row(const struct nc_frame_record *r, uint8_t *row, size_t len)
{
    uint8_t m[NC_FRAME_META_BYTES];
    metadata(r, m);
    memset(row, 0, len);
    memcpy(row, m, len < sizeof m ? len : sizeof m);
}
