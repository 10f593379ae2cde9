/* shot.c - one frame of a scene to an image file (shot.h). */
#include "camera/shot.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "camera/load.h"
#include "camera/quality.h"
#include "core/clock.h"
#include "core/error.h"
#include "render/image_io.h"
#include "render/rt.h"

static double now_ms(void) { return (double)nc_mono_ns() * 1e-6; }

int nc_shot_setup(const char *path, const char *const *sets, int nsets, struct nc_scene *scene,
                  struct nc_camsys *cs, struct nc_sky *sky)
{
    /* The stars first: a mistake in their section comes before the scene is built. */
    int rc = nc_sky_load(path, sets, nsets, sky);
    if (rc < 0)
        return rc;
    if ((rc = nc_setup_load(path, sets, nsets, scene, cs)) < 0) {
        nc_sky_free(sky);
        return rc;
    }
    if ((rc = nc_sky_prepare(sky, cs, &scene->camera)) < 0) {
        nc_sky_free(sky);
        nc_scene_free(scene);
        nc_camsys_free(cs);
    }
    return rc;
}

void nc_frame_flip(struct nc_frame *f, int rows, int cols)
{
    if (!rows && !cols)
        return;
    float *planes[] = {f->radiance, f->iof, f->range_m, f->coverage};
    for (int i = 0; i < 4; i++)
        if (planes[i])
            nc_image_flip(planes[i], sizeof(float), f->width_px, f->height_px, rows, cols);
    if (f->rock_id)
        nc_image_flip(f->rock_id, sizeof *f->rock_id, f->width_px, f->height_px, rows, cols);
    for (int k = 0; f->geom && k < NC_GEOM_PLANES; k++)
        nc_image_flip(f->geom + (size_t)k * (size_t)f->width_px * (size_t)f->height_px, sizeof(float), f->width_px,
                   f->height_px, rows, cols);
}

/* A celestial WCS (FITS WCS paper II, gnomonic: RA---TAN, DEC--TAN, ICRS)
 * for the stored image of pinhole camera c whose scene frame is the ICRS
 * (a scene with stars), as attributes "fits:KEY" (the FITS writer writes
 * them as bare keywords and turns them for bottom-up rows; the other
 * formats leave them out) into out, their values in val: how many (0 for a
 * camera with distortion, which a TAN WCS cannot describe). For pixel
 * (x, y) the camera sees u = (x - cx) / fx, v = (y - cy) / fy, the scene
 * direction R (u, v, 1); the standard coordinates east and north of the
 * boresight b are u R_x . e + v R_y . e (e east) and the same with north:
 * linear in (u, v), so the CD matrix is exact. */
void nc_shot_detail_of(const struct nc_renderer *r, int nbodies, struct nc_shot_detail *d)
{
    d->lod_error_m = nc_rt_lod_error_m(r->rt);
    d->boulder_min_m = nc_rt_boulder_min_m(r->rt);
    d->boulder_mesh_px = nc_rt_boulder_mesh_px(r->rt);
    for (int i = 0; i < NC_MAX_BODIES; i++)
        d->fold_theta_bar_deg[i] = i < nbodies ? r->fold_theta_bar_deg[i] : -1;
    d->fold_max_deg = nc_render_fold_theta_bar_deg(r, nbodies);
}

int nc_shot_detail_attrs(const struct nc_scene *scene, const struct nc_shot_detail *d, struct nc_shot_detail_text *t,
                         struct nc_image_attr *out)
{
    static const char *const names[3] = {"navcam:lod_error_m", "navcam:boulder_min_m", "navcam:boulder_mesh_px"};
    const double v[3] = {d->lod_error_m, d->boulder_min_m, d->boulder_mesh_px};
    int n = 0;
    for (int k = 0; k < 3; k++) {
        snprintf(t->num[k], sizeof t->num[k], "%.17g", v[k]);
        out[n++] = (struct nc_image_attr){names[k], t->num[k]};
    }
    /* how each mesh is shaded (name=flat or name=smooth), and the roughness each body's rocks not traced were
     * folded into (name=deg), comma-separated */
    t->normals[0] = t->fold[0] = 0;
    for (int i = 0, o = 0, p = 0; i < scene->nbodies; i++) {
        const struct nc_body *b = &scene->body[i];
        if (nc_body_is_mesh(b))
            o += snprintf(t->normals + o, sizeof t->normals - (size_t)o, "%s%s=%s", o ? "," : "", b->name,
                          b->smooth_normals ? "smooth" : "flat");
        if (d->fold_theta_bar_deg[i] >= 0)
            p += snprintf(t->fold + p, sizeof t->fold - (size_t)p, "%s%s=%.6g", p ? "," : "", b->name,
                          d->fold_theta_bar_deg[i]);
    }
    if (t->normals[0])
        out[n++] = (struct nc_image_attr){"navcam:normals", t->normals};
    if (t->fold[0])
        out[n++] = (struct nc_image_attr){"navcam:rock_fold_theta_bar_deg", t->fold};
    return n;
}

int nc_shot_wcs_attrs(const struct nc_camera *c, char (*val)[32], struct nc_image_attr *out)
{
    if (c->distorted)
        return 0;
    const struct nc_mat3 R = nc_quat_to_mat(c->attitude_q);
    const struct nc_vec3 x = nc_v3(R.m[0][0], R.m[1][0], R.m[2][0]), y = nc_v3(R.m[0][1], R.m[1][1], R.m[2][1]),
                         b = nc_v3(R.m[0][2], R.m[1][2], R.m[2][2]);
    const double ra = atan2(b.y, b.x), dec = asin(fmax(-1.0, fmin(1.0, b.z))), deg = 180 / M_PI;
    const struct nc_vec3 east = nc_v3(-sin(ra), cos(ra), 0),
                         north = nc_v3(-sin(dec) * cos(ra), -sin(dec) * sin(ra), cos(dec));
    /* the stored image: mirrored columns x = W - p1, rows y = H - p2 (FITS
     * p 1-based); else x = p1 - 1, y = p2 - 1 */
    const double sx = c->flip_cols ? -1 : 1, sy = c->flip_rows ? -1 : 1;
    const double crpix1 = c->flip_cols ? c->width_px - c->cx_px : c->cx_px + 1,
                 crpix2 = c->flip_rows ? c->height_px - c->cy_px : c->cy_px + 1;
    const double num[8] = {fmod(ra * deg + 360, 360), dec * deg, crpix1, crpix2,
                           sx * deg * nc_v3_dot(x, east) / c->fx_px, sy * deg * nc_v3_dot(y, east) / c->fy_px,
                           sx * deg * nc_v3_dot(x, north) / c->fx_px, sy * deg * nc_v3_dot(y, north) / c->fy_px};
    static const char *const nkeys[8] = {"fits:CRVAL1", "fits:CRVAL2", "fits:CRPIX1", "fits:CRPIX2",
                                         "fits:CD1_1",  "fits:CD1_2",  "fits:CD2_1",  "fits:CD2_2"};
    /* LONPOLE 180, the default everywhere but at a boresight on the north pole (Dec +90 exactly, the identity
     * attitude), where FITS's default of 0 turned the frame by 180 deg in every reader */
    static const char *const skeys[7][2] = {{"fits:WCSAXES", "2"},        {"fits:CTYPE1", "RA---TAN"},
                                            {"fits:CTYPE2", "DEC--TAN"}, {"fits:CUNIT1", "deg"},
                                            {"fits:CUNIT2", "deg"},      {"fits:RADESYS", "ICRS"},
                                            {"fits:LONPOLE", "180"}};
    int n = 0;
    for (int k = 0; k < 7; k++)
        out[n++] = (struct nc_image_attr){skeys[k][0], skeys[k][1]};
    for (int k = 0; k < 8; k++) {
        snprintf(val[k], sizeof val[k], "%.17g", num[k]);
        out[n++] = (struct nc_image_attr){nkeys[k], val[k]};
    }
    return n;
}

int nc_shot_electrons(const struct nc_camsys *cs, const struct nc_camera *c, const float *radiance,
                      double exposure_s, float *electrons)
{
    const int rc = nc_camsys_electrons(cs, radiance, exposure_s, electrons);
    if (rc >= 0 && (c->flip_rows || c->flip_cols))
        nc_image_flip(electrons, sizeof *electrons, cs->width_px, cs->height_px, c->flip_rows, c->flip_cols);
    return rc;
}

int nc_shot_mirrored_attr(const struct nc_camera *c, char val[32], struct nc_image_attr *out)
{
    if (!c->flip_rows && !c->flip_cols)
        return 0;
    snprintf(val, 32, "rows=%d columns=%d", c->flip_rows, c->flip_cols);
    *out = (struct nc_image_attr){"navcam:image_mirrored", val};
    return 1;
}

/* Electrons (float) or a digitised frame of a rendered radiance image (the
 * camera model's render size: the sensor plus the PSF's margin), in the
 * rendered orientation: the optics (vignetting, PSF) act there, and the
 * electrons are then mirrored as s's camera stores its image, so that the
 * sensor's fixed patterns (PRNU, DSNU, hot pixels) and its noise are keyed
 * to stored pixels. */
static int write_sensor_frame(const char *out, const struct nc_frame *f, enum nc_quantity q, const struct nc_scene *s,
                              const struct nc_camsys *cs, double exposure, unsigned long long frame_no,
                              const struct nc_image_attr *extra, int nextra, double *scale)
{
    const int W = cs->width_px, H = cs->height_px;
    size_t n = (size_t)W * (size_t)H;
    float *e = malloc(n * sizeof *e);
    uint16_t *dn = malloc(n * sizeof *dn);
    struct nc_image_attr attrs[64];
    char text[32][200];
    int rc = e && dn ? nc_shot_electrons(cs, &s->camera, f->radiance, exposure, e) : nc_error(-ENOMEM, "out of memory");
    int na = nc_frame_meta(s, q, attrs, text, 32);
    na += nc_camsys_meta(cs, exposure, frame_no, attrs + na, text + na, 31 - na);
    for (int i = 0; i < nextra && na < 64; i++)
        attrs[na++] = extra[i];
    if (rc >= 0 && q == NC_Q_ELECTRONS)
        rc = nc_image_write(out, e, W, H, attrs, na, scale);
    else if (rc >= 0 && (rc = nc_camsys_digitise(cs, e, exposure, frame_no, dn)) >= 0)
        rc = nc_image_write_dn(out, dn, W, H, cs->sensor.adc_bits, attrs, na);
    free(e);
    free(dn);
    return rc;
}

int nc_shot(struct nc_renderer *r, struct nc_scene *scene, const struct nc_camsys *cs, struct nc_sky *sky,
            enum nc_quantity q, double exposure, double t_sim_s, uint64_t frame_no, const char *out,
            const struct nc_image_attr *extra_in, int nextra_in, struct nc_shot_info *info)
{
    memset(info, 0, sizeof *info);
    struct nc_frame f = {0};
    double t1 = now_ms();
    /* Electrons and DN go through the camera model, whose PSF needs the
     * light from a margin around the field: render that larger image. */
    struct nc_scene drawn = *scene;
    if (q > NC_Q_ROCK_ID)
        nc_camsys_render_camera(cs, &scene->camera, &drawn.camera);
    int rc = nc_frame_alloc(&f, drawn.camera.width_px, drawn.camera.height_px);
    if (rc >= 0 && q == NC_Q_ROCK_ID &&
        !(f.rock_id = malloc((size_t)f.width_px * (size_t)f.height_px * sizeof *f.rock_id)))
        rc = nc_error(-ENOMEM, "out of memory");
    /* Motion during the exposure (camera and body rates) and a rolling
     * shutter are integrated over the exposure window. */
    struct nc_exposure ex = {.exposure_s = exposure, .rolling = cs->sensor.shutter == NC_SHUTTER_ROLLING,
                             .line_time_s = cs->sensor.line_time_s};
    info->time_samples = 1;
    /* render.quality: auto picks the settings from the camera's noise, for
     * the sensor's own render camera whatever the quantity */
    if (rc >= 0 && scene->render.quality_auto) {
        struct nc_scene sensor = drawn;
        struct nc_quality_choice qc;
        nc_camsys_render_camera(cs, &scene->camera, &sensor.camera);
        if ((rc = nc_quality_auto(r, &sensor, cs, exposure, &qc)) >= 0) {
            drawn.render = sensor.render;
            scene->render = sensor.render; /* recorded in the file */
            nc_quality_describe(&qc, 0, info->quality, sizeof info->quality);
            info->quality_ms = qc.pilot_ms;
        }
    }
    struct nc_rt_stats st0, st1;
    nc_rt_get_stats(r->rt, &st0);
    if (rc >= 0)
        rc = nc_render_exposure(r, &drawn, &ex, &f, &info->time_samples);
    nc_rt_get_stats(r->rt, &st1);
    const unsigned long hits = st1.camera_hits - st0.camera_hits, back = st1.camera_back_hits - st0.camera_back_hits;
    int rock_body = 0;
    const long rock = nc_rt_camera_in_rock(&st1, drawn.nbodies, &rock_body);
    if (rc >= 0 && nc_rt_mostly_back(hits, back))
        snprintf(info->inside_warning, sizeof info->inside_warning,
                 "%lu of the %lu camera-ray samples that met a surface met its back, inner side: is the camera "
                 "inside a body (or a mesh wound inward)?", back, hits);
    else if (rc >= 0 && rock >= 0)
        snprintf(info->inside_warning, sizeof info->inside_warning,
                 "the camera is inside boulder %ld of body %d: rocks are one-sided, so it sees out of the rock as if "
                 "it were not there", rock, rock_body);
    /* Stars (the `stars` section), drawn before the camera model's PSF. */
    char starinfo[120] = "";
    double ts0 = now_ms();
    if (rc >= 0 && sky->on && (rc = nc_sky_draw(sky, r, cs, &drawn, t_sim_s, exposure, &f, &info->stars)) >= 0)
        snprintf(starinfo, sizeof starinfo, "limit_mag=%.2f drawn=%ld hidden=%ld", info->stars.limit_mag,
                 info->stars.drawn, info->stars.hidden);
    /* The Sun: drawn when its disk reaches the frame; a warning in or near it. */
    char suninfo[200] = "";
    struct nc_sun_view *sv = &info->sun;
    if (rc >= 0 && (rc = nc_render_sun(r, &drawn, NC_SUN_NEAR_DEG, &f, sv)) >= 0) {
        nc_sun_view_warning(sv, info->sun_warning, sizeof info->sun_warning);
        nc_sun_view_text(sv, suninfo, sizeof suninfo); /* "" when the Sun is neither in nor near the field */
    }
    double t2 = now_ms();
    info->render_ms = ts0 - t1;
    info->stars_ms = t2 - ts0;
    if (q <= NC_Q_ROCK_ID) /* the sensor's quantities are mirrored after the optics (write_sensor_frame) */
        nc_frame_flip(&f, scene->camera.flip_rows, scene->camera.flip_cols);
    char flip[32];
    struct nc_image_attr extra[48];
    struct nc_shot_detail detail;
    struct nc_shot_detail_text detail_text;
    nc_shot_detail_of(r, scene->nbodies, &detail);
    int nextra = nc_shot_detail_attrs(scene, &detail, &detail_text, extra);
    if (suninfo[0])
        extra[nextra++] = (struct nc_image_attr){"navcam:sun_view", suninfo};
    if (starinfo[0])
        extra[nextra++] = (struct nc_image_attr){"navcam:stars", starinfo};
    nextra += nc_shot_mirrored_attr(&scene->camera, flip, extra + nextra);
    if (scene->camera.from_sumfile)
        extra[nextra++] = (struct nc_image_attr){"navcam:sumfile_utc", scene->camera.sumfile_utc};
    char wcsval[8][32];
    if (sky->on)
        nextra += nc_shot_wcs_attrs(&scene->camera, wcsval, extra + nextra);
    for (int i = 0; i < nextra_in && nextra < 48; i++)
        extra[nextra++] = extra_in[i];
    if (rc >= 0 && q <= NC_Q_ROCK_ID)
        rc = nc_frame_write(out, &f, q, scene, extra, nextra, &info->preview_scale);
    else if (rc >= 0)
        rc = write_sensor_frame(out, &f, q, scene, cs, exposure, frame_no, extra, nextra, &info->preview_scale);
    nc_frame_free(&f);
    return rc;
}

int nc_shot_geometry(struct nc_renderer *r, const struct nc_scene *scene, float *geom, int32_t *rock_id)
{
    struct nc_scene s = *scene;
    s.render.samples_per_pixel = 1;
    s.render.bounces = 0;
    s.render.soft_shadows = 0;
    struct nc_frame f = {0};
    int rc = nc_frame_alloc(&f, s.camera.width_px, s.camera.height_px);
    if (rc < 0)
        return rc;
    f.geom = geom;
    f.rock_id = rock_id;
    rc = nc_render_frame(r, &s, &f);
    nc_frame_flip(&f, s.camera.flip_rows, s.camera.flip_cols);
    f.geom = NULL; /* the caller's */
    f.rock_id = NULL;
    nc_frame_free(&f);
    return rc;
}
