/* cmd_batch.c - `navcam batch TRAJ.csv -o DIR`: a trajectory rendered to a
 * dataset, one frame per row with its ground truth; deterministic per
 * frame, resumable, and shardable over processes (Slurm job arrays,
 * docs/batch.md). Argument parsing and files; the frame is camera/shot.h's. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/cli.h"
#include "camera/load.h"
#include "camera/shot.h"
#include "core/clock.h"
#include "core/error.h"
#include "core/fs.h"
#include "core/traj.h"
#include "render/image_io.h"
#include "render/rt.h"

static const char batch_help[] =
    "Usage: navcam batch TRAJ.csv|builtin:approach -o DIR [--scene SCENE.yaml] [--set KEY=VALUE]...\n"
    "                    [options]\n"
    "\n"
    "Render every row of TRAJ.csv (the layouts of `navcam replay --help`: pose rows,\n"
    "or SPC SUM-like rows; builtin:approach is replay's built-in approach of 8 poses)\n"
    "with SCENE.yaml (default: the built-in scene) into DIR.\n"
    "Row i (0-based, counting data rows; rows with capture 0 are skipped) gives:\n"
    "  DIR/frame_NNNNNN.EXT            the frame (--quantity, --format); the camera\n"
    "                                  model's noise is keyed by i, so a frame's\n"
    "                                  bytes depend only on the scene and its row\n"
    "  DIR/frame_NNNNNN_geometry.fits  ground-truth planes at pixel centres: range_m,\n"
    "                                  x_m y_m z_m (the point seen, body-fixed), nx ny nz\n"
    "                                  (its normal), incidence_deg emission_deg\n"
    "                                  phase_deg, body (-1: sky; other planes 0 there)\n"
    "  DIR/frame_NNNNNN_boulders.csv   the boulders seen (bodies with boulders)\n"
    "  DIR/frame_NNNNNN_craters.csv    the craters whose centre is seen (bodies with\n"
    "                                  craters)\n"
    "  DIR/frame_NNNNNN.json           the row's pose, Sun, bodies, camera and render\n"
    "                                  settings and the files above; written last\n"
    "A row whose .json exists is done and skipped: rerun the same command after a\n"
    "crash to finish. Files are written under temporary names, flushed and\n"
    "renamed; a row another process is rendering (its lock held) is passed over.\n"
    "\n"
    "  -o, --output DIR      the dataset directory (made with its missing parents)\n"
    "      --scene FILE      the scene (default: the built-in default scene)\n"
    "  -s, --set KEY=VALUE   override a scene key (as navcam render); repeatable\n"
    "  -q, --quantity Q      dn (default), electrons, radiance, iof, range or rock_id\n"
    "  -F, --format EXT      fits (default), tif, exr or png\n"
    "  -e, --exposure T      exposure time, s, 0..3600 (default: exposure.time_s)\n"
    "      --shard K/N       render only rows i with i mod N = K (0 <= K < N): N\n"
    "                        processes, e.g. a Slurm job array with\n"
    "                        --shard $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT,\n"
    "                        write the same files as one\n"
    "      --no-geometry     skip the geometry planes and the lists\n"
    "      --sumfile X.SUM   the camera of an SPC SUM file (size, intrinsics, mirroring;\n"
    "                        each row gives the pose and the Sun): replaces the camera\n"
    "                        section with {sumfile: X.SUM} and takes sun.direction out\n"
    "                        (docs/sumfiles.md)\n"
    "  -j, --threads N       render threads, 0..1024 (default: render.threads, else all\n"
    "                        cores; 0: all cores)\n"
    "  -h, --help            this help\n";

/* A text file DIR/NAME: opened as DIR/.NAME.tmp (tmp holds that path) ... */
static int begin(const char *dir, const char *name, char *tmp, size_t len, FILE **f)
{
    snprintf(tmp, len, "%s/.%s.tmp", dir, name);
    if (!(*f = fopen(tmp, "w")))
        return nc_error(-errno, "%s: %s", tmp, strerror(errno));
    return 0;
}

/* ... and closed and renamed to DIR/NAME when complete (rc < 0: only closed). */
static int commit(FILE *f, int rc, const char *tmp, const char *dir, const char *name)
{
    char path[4200];
    if (fclose(f) != 0 && rc >= 0)
        rc = nc_error(-EIO, "%s: write failed", tmp);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return rc < 0 ? rc : nc_commit_file(tmp, path);
}

/* The boulders and craters seen in a geometry render, as CSV files. */
static int lists(const char *dir, const char *stem, const struct nc_scene *s, const float *geom,
                 const int32_t *rock, int *nrocks, int *ncraters)
{
    const struct nc_camera *c = &s->camera;
    const size_t plane = (size_t)c->width_px * (size_t)c->height_px;
    char tmp[4200], name[80];
    int rc = 0;
    *nrocks = *ncraters = -1;
    int any_rocks = 0, any_craters = 0;
    for (int b = 0; b < s->nbodies; b++) {
        any_rocks |= s->body[b].boulders.n > 0;
        any_craters |= s->body[b].craters.n > 0;
    }
    if (any_rocks) {
        snprintf(name, sizeof name, "%s_boulders.csv", stem);
        FILE *f;
        if ((rc = begin(dir, name, tmp, sizeof tmp, &f)) < 0)
            return rc;
        fprintf(f, "body,index,x_m,y_m,z_m,diameter_m,pixels\n");
        *nrocks = 0;
        for (int b = 0; b < s->nbodies && rc == 0; b++) {
            const struct nc_boulder_field *bf = &s->body[b].boulders;
            if (!bf->n)
                continue;
            uint32_t *px = calloc(bf->n, sizeof *px);
            if (!px) {
                rc = nc_error(-ENOMEM, "out of memory");
                break;
            }
            for (size_t i = 0; i < plane; i++)
                if (rock[i] >= 0 && geom[NC_GEOM_BODY * plane + i] == b && (size_t)rock[i] < bf->n)
                    px[rock[i]]++;
            for (size_t k = 0; k < bf->n; k++)
                if (px[k]) {
                    const struct nc_boulder *r = &bf->rock[k];
                    fprintf(f, "%d,%zu,%.9g,%.9g,%.9g,%.9g,%u\n", b, k, r->centre_m[0], r->centre_m[1], r->centre_m[2],
                            2.0 * r->half_m, px[k]);
                    (*nrocks)++;
                }
            free(px);
        }
        if ((rc = commit(f, rc, tmp, dir, name)) < 0)
            return rc;
    }
    if (any_craters) {
        snprintf(name, sizeof name, "%s_craters.csv", stem);
        FILE *f;
        if ((rc = begin(dir, name, tmp, sizeof tmp, &f)) < 0)
            return rc;
        fprintf(f, "body,index,x_m,y_m,z_m,diameter_m,age,sample_px,line_px\n");
        *ncraters = 0;
        struct nc_mat3 cam = nc_quat_to_mat(c->attitude_q);
        for (int b = 0; b < s->nbodies; b++) {
            const struct nc_body *body = &s->body[b];
            struct nc_mat3 R = nc_quat_to_mat(body->attitude_q);
            for (size_t k = 0; k < body->craters.n; k++) {
                const struct nc_crater *cr = &body->craters.crater[k];
                struct nc_vec3 cb = nc_v3(cr->centre_m[0], cr->centre_m[1], cr->centre_m[2]);
                struct nc_vec3 w = nc_v3_add(body->position_m, nc_mat_mul_v(&R, cb));
                struct nc_vec3 v = nc_mat_tmul_v(&cam, nc_v3_sub(w, c->position_m));
                double x, y;
                if (!(v.z > 0) || nc_camera_project(c, v, &x, &y) < 0)
                    continue;
                if (c->flip_cols)
                    x = c->width_px - 1 - x;
                if (c->flip_rows)
                    y = c->height_px - 1 - y;
                long ix = lround(x), iy = lround(y);
                if (ix < 0 || iy < 0 || ix >= c->width_px || iy >= c->height_px)
                    continue;
                size_t o = (size_t)iy * (size_t)c->width_px + (size_t)ix;
                /* seen: the surface at that pixel is this body, within half a diameter of the centre */
                double dx = geom[NC_GEOM_X * plane + o] - cb.x, dy = geom[NC_GEOM_Y * plane + o] - cb.y,
                       dz = geom[NC_GEOM_Z * plane + o] - cb.z;
                if (geom[NC_GEOM_BODY * plane + o] != b || sqrt(dx * dx + dy * dy + dz * dz) > 0.5 * cr->d_m)
                    continue;
                fprintf(f, "%d,%zu,%.9g,%.9g,%.9g,%.9g,%.6g,%.3f,%.3f\n", b, k, cb.x, cb.y, cb.z, cr->d_m, cr->age, x,
                        y);
                (*ncraters)++;
            }
        }
        if ((rc = commit(f, 0, tmp, dir, name)) < 0)
            return rc;
    }
    return 0;
}

/* The detail a frame was rendered with, as the emulator's frame records
 * give it (docs/emulator.md). */
struct detail {
    struct nc_shot_detail shot; /* levels of detail, boulder cut, fold */
    double line_time_s;
    int rolling, time_samples;
};

static int truth(const char *dir, const char *stem, const char *ext, int geometry, long row,
                 const struct nc_traj_row *tr, const struct nc_scene *s, enum nc_quantity q, double exposure,
                 const char *quality, const struct detail *d, int nrocks, int ncraters)
{
    char tmp[4200], name[80];
    snprintf(name, sizeof name, "%s.json", stem);
    FILE *f;
    int rc = begin(dir, name, tmp, sizeof tmp, &f);
    if (rc < 0)
        return rc;
    const struct nc_camera *c = &s->camera;
    fprintf(f, "{\"row\": %ld, \"line\": %d, \"t_s\": %.17g,\n", row, tr->line, tr->t_s);
    fprintf(f, " \"image\": \"%s.%s\", \"quantity\": \"%s\", \"units\": \"%s\", \"exposure_s\": %.17g, "
               "\"frame_number\": %ld,\n",
            stem, ext, nc_quantity_names[q], nc_quantity_units(q), exposure, row);
    if (geometry) {
        fprintf(f, " \"geometry\": \"%s_geometry.fits\", \"geometry_planes\": [", stem);
        for (int k = 0; k < NC_GEOM_PLANES; k++)
            fprintf(f, "\"%s\"%s", nc_geom_plane_names[k], k + 1 < NC_GEOM_PLANES ? ", " : "],\n");
        if (nrocks >= 0)
            fprintf(f, " \"boulders\": \"%s_boulders.csv\", \"boulders_in_view\": %d,\n", stem, nrocks);
        if (ncraters >= 0)
            fprintf(f, " \"craters\": \"%s_craters.csv\", \"craters_in_view\": %d,\n", stem, ncraters);
    }
    double v[4];
    fprintf(f, " \"camera\": {");
    v[0] = c->position_m.x, v[1] = c->position_m.y, v[2] = c->position_m.z;
    nc_cli_json_vec(f, "position_m", v, 3, ", ");
    v[0] = c->attitude_q.w, v[1] = c->attitude_q.x, v[2] = c->attitude_q.y, v[3] = c->attitude_q.z;
    nc_cli_json_vec(f, "attitude_q", v, 4, ", ");
    fprintf(f, "\"width_px\": %d, \"height_px\": %d, ", c->width_px, c->height_px);
    v[0] = c->fx_px, v[1] = c->fy_px, v[2] = c->cx_px, v[3] = c->cy_px;
    nc_cli_json_vec(f, "fx_fy_cx_cy_px", v, 4, ", ");
    const double k[5] = {c->k1, c->k2, c->k3, c->p1, c->p2}; /* Brown-Conrady, OpenCV's order; 0 without */
    nc_cli_json_vec(f, "distortion_k1_k2_k3_p1_p2", k, 5, ", ");
    fprintf(f, "\"mirrored_rows\": %d, \"mirrored_columns\": %d, ", c->flip_rows, c->flip_cols);
    const double m[6] = {c->velocity_m_s.x, c->velocity_m_s.y, c->velocity_m_s.z, c->angular_velocity_rad_s.x,
                         c->angular_velocity_rad_s.y, c->angular_velocity_rad_s.z}; /* motion in the exposure */
    nc_cli_json_vec(f, "velocity_m_s", m, 3, ", ");
    nc_cli_json_vec(f, "angular_velocity_rad_s", m + 3, 3, ", ");
    fprintf(f, "\"shutter\": \"%s\", \"line_time_s\": %.17g, \"time_samples\": %d},\n",
            d->rolling ? "rolling" : "global", d->rolling ? d->line_time_s : 0, d->time_samples);
    struct nc_vec3 sd;
    double irr;
    nc_scene_sun_at(s, s->body[0].position_m, &sd, &irr);
    fprintf(f, " \"sun\": {");
    v[0] = s->sun.direction.x, v[1] = s->sun.direction.y, v[2] = s->sun.direction.z;
    if (!s->sun.has_position)
        nc_cli_json_vec(f, "direction_body0", v, 3, ", ");
    v[0] = sd.x, v[1] = sd.y, v[2] = sd.z;
    nc_cli_json_vec(f, "direction_scene", v, 3, ", ");
    fprintf(f, "\"distance_m\": %.17g, \"irradiance_w_m2\": %.17g},\n \"bodies\": [", s->sun.distance_m, irr);
    for (int b = 0; b < s->nbodies; b++) {
        const struct nc_body *bd = &s->body[b];
        fputc('{', f);
        nc_cli_json_str(f, "name", bd->name); /* a quote or backslash in it escaped */
        v[0] = bd->position_m.x, v[1] = bd->position_m.y, v[2] = bd->position_m.z;
        nc_cli_json_vec(f, "position_m", v, 3, ", ");
        v[0] = bd->attitude_q.w, v[1] = bd->attitude_q.x, v[2] = bd->attitude_q.y, v[3] = bd->attitude_q.z;
        nc_cli_json_vec(f, "attitude_q", v, 4, "}");
        fprintf(f, "%s", b + 1 < s->nbodies ? ", " : "],\n");
    }
    /* the keys and types of the emulator's frame records (docs/emulator.md) */
    fprintf(f, " \"render\": {\"quality\": \"%s\", \"samples_per_pixel\": %d, \"bounces\": %d, \"soft_shadows\": %s, "
               "\"seed\": %llu",
            quality[0] ? "auto" : "manual", s->render.samples_per_pixel, s->render.bounces,
            s->render.soft_shadows ? "true" : "false", (unsigned long long)s->render.seed);
    if (quality[0])
        fprintf(f, ", \"quality_choice\": \"%s\"", quality);
    fprintf(f, "},\n \"lod_error_m\": %.17g, \"boulder_min_m\": %.17g, \"boulder_mesh_px\": %.17g, "
               "\"rock_fold_theta_bar_deg\": %.17g}\n",
            d->shot.lod_error_m, d->shot.boulder_min_m, d->shot.boulder_mesh_px, d->shot.fold_max_deg);
    return commit(f, 0, tmp, dir, name);
}

static double now_s(void) { return (double)nc_mono_ns() * 1e-9; }

/* ", N being rendered by another process" (a static buffer), or "" */
static const char *busy_txt(long busy)
{
    static char t[64];
    if (!busy)
        return "";
    snprintf(t, sizeof t, ", %ld being rendered by another process", busy);
    return t;
}

/* Row i of the trajectory into DIR/STEM.*: the frame, the geometry and its
 * lists (unless geometry is 0), then the JSON. */
static int batch_row(struct nc_renderer *r, const struct nc_scene *base, const struct nc_camsys *cs,
                     struct nc_sky *sky, const struct nc_traj_row *row, long i, const char *dir,
                     const char *stem, const char *ext, enum nc_quantity q, double exposure, int geometry, float *geom,
                     int32_t *rock)
{
    const double t0 = now_s();
    struct nc_scene s = *base; /* shares the meshes; render settings fresh per row */
    struct nc_pose pose;
    nc_scene_pose(base, 0, &pose);
    pose.cam_position_m = row->p;
    pose.cam_attitude_q = row->q;
    if (row->body_frame) { /* SUM-like: moved with bodies[0], as camera.sumfile is */
        const struct nc_body *b0 = &base->body[0];
        pose.cam_position_m = nc_v3_add(b0->position_m, nc_quat_rotate(b0->attitude_q, row->p));
        pose.cam_attitude_q = nc_quat_mul(b0->attitude_q, row->q);
    }
    pose.sun = nc_v3_unit(row->sun);
    pose.sun_is_position = 0;
    nc_scene_apply_pose(&s, &pose);
    struct nc_shot_info info;
    char tmp[4200], path[4200], rowtxt[32];
    snprintf(tmp, sizeof tmp, "%s/.%s.tmp.%s", dir, stem, ext);
    snprintf(path, sizeof path, "%s/%s.%s", dir, stem, ext);
    snprintf(rowtxt, sizeof rowtxt, "%ld", i);
    const struct nc_image_attr extra[] = {{"navcam:batch_row", rowtxt}};
    int rc;
    if ((rc = nc_shot(r, &s, cs, sky, q, exposure, row->t_s, (uint64_t)i, tmp, extra, 1, &info)) < 0 ||
        (rc = nc_commit_file(tmp, path)) < 0)
        return rc;
    struct detail det = {.line_time_s = cs->sensor.line_time_s, .rolling = cs->sensor.shutter == NC_SHUTTER_ROLLING,
                         .time_samples = info.time_samples};
    nc_shot_detail_of(r, s.nbodies, &det.shot);
    int nrocks = -1, ncraters = -1;
    if (geometry) {
        snprintf(tmp, sizeof tmp, "%s/.%s_geometry.tmp.fits", dir, stem);
        snprintf(path, sizeof path, "%s/%s_geometry.fits", dir, stem);
        if ((rc = nc_shot_geometry(r, &s, geom, rock)) < 0 ||
            (rc = nc_image_write_planes(tmp, geom, s.camera.width_px, s.camera.height_px, NC_GEOM_PLANES,
                                        nc_geom_plane_names, extra, 1)) < 0 ||
            (rc = nc_commit_file(tmp, path)) < 0 || (rc = lists(dir, stem, &s, geom, rock, &nrocks, &ncraters)) < 0)
            return rc;
    }
    if ((rc = truth(dir, stem, ext, geometry, i, row, &s, q, exposure, info.quality, &det, nrocks, ncraters)) < 0)
        return rc;
    printf("%s (row %ld, t = %.6g s): %.0f ms\n", stem, i, row->t_s, 1e3 * (now_s() - t0));
    if (info.sun_warning[0])
        printf("  WARNING: row %ld (line %d): %s\n", i, row->line, info.sun_warning);
    if (info.inside_warning[0])
        printf("  WARNING: row %ld (line %d): %s (columns in the wrong order?)\n", i, row->line, info.inside_warning);
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv)
{
    nc_cli_init("batch");
    static const struct option opts[] = {
        {"output", required_argument, NULL, 'o'},  {"scene", required_argument, NULL, 'S'},
        {"set", required_argument, NULL, 's'},     {"quantity", required_argument, NULL, 'q'},
        {"format", required_argument, NULL, 'F'},  {"exposure", required_argument, NULL, 'e'},
        {"shard", required_argument, NULL, 'K'},   {"no-geometry", no_argument, NULL, 'G'},
        {"threads", required_argument, NULL, 'j'}, {"help", no_argument, NULL, 'h'},
        {"sumfile", required_argument, NULL, 'U'},  {NULL, 0, NULL, 0},
    };
    const char *dir = NULL, *scene_path = NULL, *ext = "fits";
    const char **sets = calloc(2 * (size_t)argc + 2, sizeof *sets); /* --sumfile=X adds two */
    char sumset[4200];
    int nsets = 0, threads = 0, geometry = 1, c;
    long shard_k = 0, shard_n = 1;
    double exposure = -1;
    enum nc_quantity q = NC_Q_DN;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "o:s:q:F:e:j:h", opts)) != -1) {
        char *end;
        switch (c) {
        case 'o': dir = optarg; break;
        case 'S': scene_path = optarg; break;
        case 's': sets[nsets++] = optarg; break;
        case 'G': geometry = 0; break;
        case 'U': /* the rows give the pose and the Sun: the file's SZ and the scene's direction are not used */
            nc_cli_sumfile(sets, &nsets, sumset, sizeof sumset, optarg);
            break;
        case 'F':
            ext = optarg;
            if (strcmp(ext, "fits") && strcmp(ext, "tif") && strcmp(ext, "exr") && strcmp(ext, "png")) {
                fprintf(stderr, "navcam batch: --format expects fits, tif, exr or png, got '%s'\n", optarg);
                goto usage;
            }
            break;
        case 'q':
            if (nc_quantity_parse(optarg, &q) < 0) {
                fprintf(stderr, "navcam batch: --quantity: %s\n", nc_errmsg());
                goto usage;
            }
            break;
        case 'e':
            if (nc_cli_double("exposure", optarg, 0, 3600, &exposure) < 0)
                goto usage;
            break;
        case 'K':
            shard_k = strtol(optarg, &end, 10);
            if (*end == '/')
                shard_n = strtol(end + 1, &end, 10);
            if (*end || optarg[0] == '/' || !strchr(optarg, '/') || shard_n < 1 || shard_n > 1000000 ||
                shard_k < 0 || shard_k >= shard_n) {
                fprintf(stderr, "navcam batch: --shard expects K/N with 0 <= K < N, got '%s'\n", optarg);
                goto usage;
            }
            break;
        case 'j':
            if (nc_cli_threads(optarg, &threads) < 0)
                goto usage;
            break;
        case 'h': fputs(batch_help, stdout); free(sets); return 0;
        default: fputs("Try 'navcam batch --help'.\n", stderr); goto usage;
        }
    }
    if (argc - optind != 1 || !dir) {
        fprintf(stderr, "navcam batch: %s\nTry 'navcam batch --help'.\n",
                !dir ? "missing -o DIR" : "give one trajectory (TRAJ.csv or builtin:approach)");
        goto usage;
    }
    char dotext[16];
    snprintf(dotext, sizeof dotext, "x.%s", ext);
    if (nc_quantity_format_check(q, dotext) < 0) {
        fprintf(stderr, "navcam batch: --format %s: %s\n", ext, nc_errmsg());
        goto usage;
    }
    struct nc_traj_row *rows = NULL;
    int nrows = nc_traj_read(argv[optind], &rows);
    if (nrows < 0) {
        free(sets);
        return nc_cli_fail();
    }
    struct nc_scene base;
    struct nc_camsys cs;
    struct nc_sky sky;
    int rc = nc_shot_setup(scene_path, sets, nsets, &base, &cs, &sky);
    free(sets);
    if (rc < 0) {
        free(rows);
        return nc_cli_fail();
    }
    if (exposure < 0)
        exposure = cs.exposure_s;
    struct nc_renderer r;
    if ((rc = nc_renderer_init(&r, &base, threads)) < 0) {
        nc_scene_free(&base);
        nc_sky_free(&sky);
        free(rows);
        return nc_cli_fail();
    }
    const size_t plane = (size_t)base.camera.width_px * (size_t)base.camera.height_px;
    float *geom = geometry ? malloc(NC_GEOM_PLANES * plane * sizeof *geom) : NULL;
    int32_t *rock = geometry ? malloc(plane * sizeof *rock) : NULL;
    if (geometry && (!geom || !rock))
        rc = nc_error(-ENOMEM, "out of memory for the geometry planes");
    if (rc >= 0) /* the image library now, not at the first frame; after the configuration */
        rc = nc_image_prepare(dotext);
    if (rc >= 0) /* once the configuration is known good: no empty directory left by a mistake in it */
        rc = nc_mkdirs(dir);
    long done = 0, skipped = 0, busy = 0, mine = 0, no_capture = 0, failed = 0, failed_run = 0;
    double t_all = now_s();
    for (long i = 0; i < nrows && rc >= 0; i++) {
        if (i % shard_n != shard_k)
            continue;
        if (!rows[i].capture) {
            no_capture++;
            continue;
        }
        mine++;
        char stem[32], path[4200];
        snprintf(stem, sizeof stem, "frame_%06ld", i);
        snprintf(path, sizeof path, "%s/%s.json", dir, stem);
        char lock[4200];
        int fd;
        if (access(path, F_OK) == 0) {
            skipped++;
            continue;
        }
        /* held while the row is rendered (DIR/.STEM.lock), so that two processes given the same rows (a shard
         * submitted again while it still runs) never write the same temporary files; the other skips the row */
        snprintf(lock, sizeof lock, "%s/.%s.lock", dir, stem);
        if ((rc = nc_fs_lock(lock, &fd)) <= 0) {
            busy += rc == 0;
            if (rc < 0)
                break;
            continue;
        }
        if (access(path, F_OK) == 0) { /* finished by another process while we took the lock: done */
            nc_fs_unlock(lock, fd, 1);
            skipped++;
            continue;
        }
        if (rc == 2) /* what a crash or a failure left of the row, some named by its process's id */
            nc_fs_drop_temporaries(dir, stem);
        rc = batch_row(&r, &base, &cs, &sky, &rows[i], i, dir, stem, ext, q, exposure, geometry, geom, rock);
        nc_fs_unlock(lock, fd, rc >= 0); /* the file removed once the row is done: nobody renders it again */
        if (rc < 0) { /* named, and the other rows go on: ten failures in a row stop the shard */
            fprintf(stderr, "navcam batch: row %ld (line %d): %s\n", i, rows[i].line, nc_errmsg());
            rc = ++failed_run < 10 ? 0 : nc_error(rc, "stopped: ten rows in a row failed");
            failed++;
        } else
            done++, failed_run = 0;
    }
    double el = now_s() - t_all;
    char off[64] = "";
    if (no_capture)
        snprintf(off, sizeof off, " (and %ld with capture 0, not rendered)", no_capture);
    if (rc >= 0)
        printf("navcam batch: shard %ld/%ld: %ld of %d rows are this shard's%s; %ld rendered, %ld failed, %ld already "
               "done%s; %.1f s (%.0f frames per hour)\n", shard_k, shard_n, mine, nrows, off, done, failed, skipped,
               busy_txt(busy), el, el > 0 ? done * 3600 / el : 0.0);
    free(geom);
    free(rock);
    free(rows);
    nc_renderer_free(&r);
    nc_scene_free(&base);
    nc_camsys_free(&cs);
    nc_sky_free(&sky);
    return rc < 0 ? nc_cli_fail() : failed > 0;
usage:
    free(sets);
    return 2;
}
