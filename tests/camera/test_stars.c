/* test_stars.c - stars in the frame (camera/sky.h, render/stars.h):
 *  1. the KStars stars.dat reader and NavCam's index (round trip, order,
 *     errors that name the line);
 *  2. proper motion and aberration against their formulas;
 *  3. photometry through the camera model: a star's electrons, summed over
 *     the PSF, against the zero point integrated here independently
 *     (Simpson's rule over the 500-700 nm band); V + 5 gives 1/100;
 *  4. the aberration of a 30 km/s observer moves the star's centroid by
 *     atan(beta gamma) = 20.64 arcsec in the rendered frame;
 *  5. a body in front hides the star; 1 and 2 threads give the same frame;
 *  6. the Sun: its disk drawn in the field carries its whole irradiance, a
 *     body in front hides it, and the warnings say in or near the field. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "camera/load.h"
#include "camera/sky.h"
#include "core/error.h"
#include "testutil.h"

#define AS (M_PI / 180 / 3600) /* one arcsecond, rad */

/* A noise-free camera, 2.06 arcsec pixels (5 um at 0.5 m), looking at the
 * direction of the synthetic index's first star; a small sphere elsewhere. */
static const char scene_fmt[] = "bodies:\n"
                                "  - name: rock\n"
                                "    shape: {type: sphere, radius_m: 100}\n"
                                "    position_m: [%.17g, %.17g, %.17g]\n"
                                "    material: {model: lambert, A: 0.1}\n"
                                "sun: {direction: [%.17g, %.17g, %.17g]}\n"
                                "camera: {width_px: 96, height_px: 96, focal_length_m: 0.5, pixel_pitch_m: 5.0e-6,\n"
                                "         position_m: [0, 0, 0], look_at_m: [%.17g, %.17g, %.17g], up: [0, 0, 1]}\n"
                                "render: {samples_per_pixel: 1}\n"
                                "optics: {f_number: 8, transmission: 0.9, passband: {from_m: 5.0e-7, to_m: 7.0e-7},\n"
                                "         vignetting: none, psf: {type: gaussian, sigma_px: 1.0}}\n"
                                "sensor: {qe: 0.6, read_noise_e: 0, dark_current_e_s: 0, shot_noise: false,\n"
                                "         full_well_e: 1.0e9, gain_e_per_dn: 1000, adc_bits: 16}\n"
                                "exposure: {time_s: 1.0}\n"
                                "stars: {catalogue: '%s', limit_mag: 12, observer_velocity_m_s: [%.17g, %.17g, %.17g]}\n";

struct shot {
    double sum, cx, cy; /* electrons in the frame, centroid (px) */
    struct nc_sky_stats st;
};

/* Render the scene (body at rock, stars) and take the electrons. */
static struct shot shoot(struct nc_vec3 look, struct nc_vec3 rock, struct nc_vec3 v, int threads, float **keep)
{
    char yaml[4096], idx[1024];
    snprintf(idx, sizeof idx, "%s", nc_test_path("stars.ncs"));
    struct nc_vec3 sun = nc_v3_unit(look); /* behind anything in front of the camera: its side to us is dark */
    snprintf(yaml, sizeof yaml, scene_fmt, rock.x, rock.y, rock.z, sun.x, sun.y, sun.z, look.x, look.y, look.z, idx,
             v.x, v.y, v.z);
    const char *path = nc_test_path("scene.yaml");
    nc_test_write(path, yaml);
    struct nc_scene s;
    struct nc_camsys cs;
    struct nc_sky sky;
    struct shot out = {0};
    int rc = nc_setup_load(path, NULL, 0, &s, &cs);
    CHECK(rc >= 0 && nc_sky_load(path, NULL, 0, &sky) >= 0 && sky.on && nc_sky_prepare(&sky, &cs, &s.camera) >= 0,
          "set-up: %s", nc_errmsg());
    if (rc < 0 || !sky.on) {
        fprintf(stderr, "test_stars: cannot go on without the scene\n");
        exit(nc_test_end() ? 1 : 1);
    }
    struct nc_scene drawn = s;
    nc_camsys_render_camera(&cs, &s.camera, &drawn.camera);
    struct nc_renderer r;
    struct nc_frame f;
    nc_renderer_init(&r, &drawn, threads);
    nc_frame_alloc(&f, drawn.camera.width_px, drawn.camera.height_px);
    struct nc_exposure ex = {.exposure_s = 1.0};
    float *e = malloc(sizeof(float) * 96 * 96);
    CHECK(nc_render_exposure(&r, &drawn, &ex, &f, NULL) == 0 && nc_sky_draw(&sky, &r, &cs, &drawn, 0, 1.0, &f, &out.st) == 0 &&
              nc_camsys_electrons(&cs, f.radiance, 1.0, e) == 0,
          "render: %s", nc_errmsg());
    double mx = 0, my = 0;
    for (int y = 0; y < 96; y++)
        for (int x = 0; x < 96; x++) {
            out.sum += e[y * 96 + x];
            mx += x * (double)e[y * 96 + x];
            my += y * (double)e[y * 96 + x];
        }
    out.cx = out.sum > 0 ? mx / out.sum : NAN;
    out.cy = out.sum > 0 ? my / out.sum : NAN;
    if (keep)
        *keep = e;
    else
        free(e);
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_sky_free(&sky);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
    return out;
}

/* The scene file of the last shoot with sets, its sky drawn at the times
 * t[0..nt-1] (s) in turn with one nc_sky, exposures of expo s; the
 * electrons of the last. */
static float *draw_at(const char **sets, int nsets, const double *t, int nt, double expo)
{
    const char *path = nc_test_path("scene.yaml");
    struct nc_scene s;
    struct nc_camsys cs;
    struct nc_sky sky;
    CHECK(nc_setup_load(path, sets, nsets, &s, &cs) >= 0 && nc_sky_load(path, sets, nsets, &sky) >= 0 &&
              nc_sky_prepare(&sky, &cs, &s.camera) >= 0,
          "set-up: %s", nc_errmsg());
    struct nc_scene drawn = s;
    nc_camsys_render_camera(&cs, &s.camera, &drawn.camera);
    struct nc_renderer r;
    struct nc_frame f;
    struct nc_sky_stats st;
    nc_renderer_init(&r, &drawn, 2);
    nc_frame_alloc(&f, drawn.camera.width_px, drawn.camera.height_px);
    struct nc_exposure ex = {.exposure_s = expo};
    float *e = malloc(sizeof(float) * 96 * 96);
    for (int k = 0; k < nt; k++)
        CHECK(nc_render_exposure(&r, &drawn, &ex, &f, NULL) == 0 &&
                  nc_sky_draw(&sky, &r, &cs, &drawn, t[k], expo, &f, &st) == 0 &&
                  nc_camsys_electrons(&cs, f.radiance, expo, e) == 0,
              "render: %s", nc_errmsg());
    nc_frame_free(&f);
    nc_renderer_free(&r);
    nc_sky_free(&sky);
    nc_camsys_free(&cs);
    nc_scene_free(&s);
    return e;
}

static double centroid_x(const float *e)
{
    double m = 0, mx = 0;
    for (int i = 0; i < 96 * 96; i++)
        m += e[i], mx += (i % 96) * (double)e[i];
    return mx / m;
}

/* Planck photon spectral radiance shape, lambda in m (any constant factor). */
static double photons(double l, double t)
{
    const double h = 6.62607015e-34, c = 299792458.0, k = 1.380649e-23;
    return 1.0 / (pow(l, 4) * expm1(h * c / (l * k * t)));
}

int main(void)
{
    /* 1. stars.dat and the index. */
    const char *dat = nc_test_path("stars.dat");
    nc_test_write(dat, "# a test catalogue in KStars' columns\n"
                       "183656.34 +384701.3 +000201.0+000287.500128.9 00.03-0.00A0 0            , alp Lyr, Vega\n"
                       "064508.92 -164258.0 -000546.0-001223.100379.2 -1.4400.01A0 1            , alp CMa, Sirius\n"
                       "232339.92 +553760.0 -000013.5-000019.900006.4 08.7800.01A? 0\n");
    struct nc_star_cat c;
    CHECK(nc_star_cat_read_kstars(dat, &c) == 0 && c.n == 3, "read: %s", nc_errmsg());
    CHECK(c.star[0].v_mag == -1.44f && c.star[1].v_mag == 0.03f && c.star[2].v_mag == 8.78f, "brightest first");
    CHECK(fabs(c.star[0].ra_rad * 180 / M_PI - 101.287166667) < 1e-8 &&
              fabs(c.star[0].dec_rad * 180 / M_PI + 16.716111111) < 1e-8 && c.star[0].pm_dec_mas_yr == -1223.1f &&
              c.star[0].b_v == 0.01f,
          "Sirius: %.9f %.9f", c.star[0].ra_rad * 180 / M_PI, c.star[0].dec_rad * 180 / M_PI);
    CHECK(fabs(c.star[2].dec_rad * 180 / M_PI - (55 + 38 / 60.0)) < 1e-9, "60.00 seconds read as a number");
    const char *ix = nc_test_path("three.ncs");
    struct nc_star_cat d;
    CHECK(nc_star_cat_write(&c, ix) == 0 && nc_star_cat_load(ix, &d) == 0 && d.n == 3 && d.epoch_jyear == 2000 &&
              !memcmp(d.star, c.star, 3 * sizeof *c.star),
          "index round trip: %s", nc_errmsg());
    CHECK(nc_star_cat_count_to(&d, 0.0) == 1 && nc_star_cat_count_to(&d, 9) == 3, "prefix to a magnitude");
    /* V included: the limit as the catalogue's floats hold it (6.3 is 6.3000002 as a float: a star of 6.3 was
     * left out at --max-mag 6.3, where one of 8.78, 8.77999973 as a float, was kept) */
    d.star[2].v_mag = 6.3f;
    CHECK(nc_star_cat_count_to(&d, 6.3) == 3 && nc_star_cat_count_to(&d, 6.29) == 2,
          "a star at the limit: %zu of 3 to V 6.3", nc_star_cat_count_to(&d, 6.3));
    { /* a pipe (or, as root, /dev/null) at the index's path is not replaced; a symbolic link is, not its target */
        const char *fifo = nc_test_path("pipe.ncs"), *link = nc_test_path("link.ncs");
        struct stat st;
        unlink(fifo);
        CHECK(mkfifo(fifo, 0600) == 0 && nc_star_cat_write(&c, fifo) < 0 &&
                  nc_test_contains(nc_errmsg(), "pipe.ncs: exists and is not a regular file") && stat(fifo, &st) == 0 &&
                  S_ISFIFO(st.st_mode),
              "a pipe at the index's path: %s", nc_errmsg());
        unlink(fifo);
        unlink(link);
        CHECK(symlink(fifo, link) == 0 && nc_star_cat_write(&c, link) == 0 && lstat(link, &st) == 0 &&
                  S_ISREG(st.st_mode),
              "a symbolic link at the index's path: %s", nc_errmsg());
    }
    nc_star_cat_free(&d);
    { /* an index whose header epoch is no epoch (every star vanished), with bytes past its stars, with a
       * star's Dec beyond the pole, or out of magnitude order: each named */
        size_t len = 0;
        char *bytes = nc_test_read(ix, &len);
        const char *bad = nc_test_path("bad.ncs"),
                   *want[] = {"epoch Jnan is not a catalogue epoch", "bytes after the 3 stars",
                              "star 1 (from 0; byte 56): declination (rad) is not within +-pi/2",
                              "star 2 (from 0; byte 88): V magnitude is brighter than the star before",
                              "truncated (50000000 stars announced, 96 bytes of them)"};
        for (int k = 0; bytes && k < 5; k++) {
            char *b = malloc(len);
            FILE *f = b ? fopen(bad, "wb") : NULL;
            if (!f) {
                free(b);
                break;
            }
            memcpy(b, bytes, len);
            if (k == 0)
                memcpy(b + 16, &(double){NAN}, 8); /* the header's epoch (little-endian f64 at byte 16) */
            if (k == 2)
                memcpy(b + 24 + 32 + 8, &(double){2.0}, 8); /* star 1's Dec, rad */
            if (k == 3)
                memcpy(b + 24 + 2 * 32 + 24, &(float){-2.0f}, 4); /* star 2's V */
            if (k == 4) /* the header's count (u64 at byte 8), damaged: checked against the size first */
                memcpy(b + 8, (const unsigned char[8]){0x80, 0xf0, 0xfa, 0x02, 0, 0, 0, 0}, 8);
            fwrite(b, 1, len, f);
            if (k == 1)
                fputc(0, f);
            fclose(f);
            free(b);
            CHECK(nc_star_cat_load(bad, &d) < 0 && nc_test_contains(nc_errmsg(), want[k]), "a damaged index (%d): %s",
                  k, nc_errmsg());
        }
        free(bytes);
    }
    { /* a key the stars' reader does not take is an error, not a default */
        char set[1200];
        snprintf(set, sizeof set, "stars={catalogue: '%s', limit_magg: 5}", ix);
        const char *sets[] = {set};
        struct nc_sky sky;
        CHECK(nc_sky_load(NULL, sets, 1, &sky) < 0 &&
                  nc_test_contains(nc_errmsg(), "stars.limit_magg: unknown key; did you mean 'limit_mag'?"),
              "an unknown key under stars: %s", nc_errmsg());
    }
    nc_star_cat_free(&c);
    nc_test_write(dat, "064508.92 -164258.0 -000546.0-001223.100379.2 -1.4400.01A0 1\nnot a star\n");
    CHECK(nc_star_cat_read_kstars(dat, &c) < 0 &&
              nc_test_contains(nc_errmsg(), "stars.dat:2: RA hours (columns 1-2) 'no' is not a number in 0..23"),
          "a bad row names its line: %s", nc_errmsg());
    /* each number in its column's range, decimal: a Dec past the pole, 75 minutes, a hex V are named */
    static const char *const rows[][2] = {
        {"064508.92 +903000.0 -000546.0-001223.100379.2 -1.4400.01A0 1\n", "the Dec lies beyond 90 deg"},
        {"067508.92 -164258.0 -000546.0-001223.100379.2 -1.4400.01A0 1\n",
         "RA minutes (columns 3-4) '75' is not a number in 0..59"},
        {"064508.92 -164258.0 -000546.0-001223.100379.2  0x1A00.01A0 1\n",
         "V (columns 46-51) '  0x1A' is not a number"},
        {"064508.92 *164258.0 -000546.0-001223.100379.2 -1.4400.01A0 1\n", "the Dec's sign (column 11) is not + or -"},
        {"0645\n", "the row ends before RA seconds (columns 5-9)"},
    };
    for (size_t k = 0; k < sizeof rows / sizeof rows[0]; k++) {
        nc_test_write(dat, rows[k][0]);
        CHECK(nc_star_cat_read_kstars(dat, &c) < 0 && nc_test_contains(nc_errmsg(), "stars.dat:1: ") &&
                  nc_test_contains(nc_errmsg(), rows[k][1]),
              "row %zu: %s", k, nc_errmsg());
    }
    static const char nul[] = "064508.92 -164258.0 -000546.0-001223.100379.2 -1.4400.01A0 1\0\n";
    nc_test_write_bytes(dat, nul, sizeof nul - 1);
    CHECK(nc_star_cat_read_kstars(dat, &c) < 0 && nc_test_contains(nc_errmsg(), "stars.dat:1: a NUL byte at column 61"),
          "a NUL byte: %s", nc_errmsg());

    /* 2. Proper motion: 1000 mas/yr north for 10 years is 10 arcsec. */
    struct nc_star s0 = {.ra_rad = 0.3, .dec_rad = 0.2, .pm_dec_mas_yr = 1000, .v_mag = 5};
    struct nc_vec3 a = nc_star_direction(&s0, 2000, 2000), b = nc_star_direction(&s0, 2000, 2010);
    double moved = atan2(nc_v3_norm(nc_v3_cross(a, b)), nc_v3_dot(a, b)) / AS;
    printf("proper motion: %.9f arcsec in 10 years at 1000 mas/yr\n", moved);
    CHECK(fabs(moved - 10) < 1e-6 && b.z > a.z, "proper motion %.9f arcsec", moved);
    /* Aberration, perpendicular to the motion: atan(beta gamma). */
    const double beta = 3e4 / 299792458.0, want = atan(beta / sqrt(1 - beta * beta)) / AS;
    struct nc_vec3 p = nc_v3(1, 0, 0), q = nc_aberrate(p, nc_v3(0, 3e4, 0));
    double ab = atan2(nc_v3_norm(nc_v3_cross(p, q)), nc_v3_dot(p, q)) / AS;
    printf("aberration at 30 km/s: %.6f arcsec (expected %.6f)\n", ab, want);
    CHECK(fabs(ab - want) < 1e-6 && q.y > 0, "aberration %.6f arcsec", ab);

    /* A synthetic index: a V 5 star of B-V 0.65 and a V 10 twin 20 px away. */
    struct nc_star st[2] = {{.ra_rad = 1.0, .dec_rad = 0.4, .v_mag = 5.0f, .b_v = 0.65f},
                            {.ra_rad = 1.0 + 40 * 1e-5 / cos(0.4), .dec_rad = 0.4, .v_mag = 10.0f, .b_v = 0.65f}};
    struct nc_star_cat two = {.n = 2, .star = st, .epoch_jyear = 2000};
    CHECK(nc_star_cat_write(&two, nc_test_path("stars.ncs")) == 0, "write");
    struct nc_vec3 look = nc_star_direction(&st[0], 2000, 2000), away = nc_v3(0, 0, -1e4);

    /* 3. Photometry. */
    float *e1;
    struct shot s1 = shoot(look, away, nc_v3(0, 0, 0), 2, &e1);
    const double tk = 4600.0 * (1 / (0.92 * 0.65 + 1.7) + 1 / (0.92 * 0.65 + 0.62)), n = 2000;
    double g = 0; /* int over 500-700 nm of photons(l) / photons(545 nm), m */
    for (int i = 0; i <= n; i++) {
        double l = 500e-9 + 200e-9 * i / n;
        g += (i == 0 || i == n ? 1 : i % 2 ? 4 : 2) * photons(l, tk);
    }
    g *= 200e-9 / n / 3 / photons(545e-9, tk);
    const double area = M_PI * pow(0.5 / 8, 2) / 4; /* aperture diameter f / N */
    double e_v5 = 9.96e16 * pow(10, -0.4 * 5) * g * area * 0.9 * 0.6 * 1.0; /* e- in 1 s */
    /* The two stars separately: each one's 15 x 15 px window. */
    double w5 = 0, w10 = 0;
    int x5 = (int)lround(s1.cx), y5 = (int)lround(s1.cy);
    for (int y = -7; y <= 7; y++)
        for (int x = -7; x <= 7; x++) {
            w5 += e1[(y5 + y) * 96 + x5 + x];
            if (x5 + x - 40 >= 0)
                w10 += e1[(y5 + y) * 96 + x5 + x - 40];
        }
    printf("photometry: V 5, B-V 0.65 (T %.0f K): %.6g e- against %.6g predicted (%.4f); V 10: %.6g of V 5 "
           "(1/100 expected)\n",
           tk, w5, e_v5, w5 / e_v5, w10 / w5);
    CHECK(fabs(w5 / e_v5 - 1) < 0.02, "star electrons %.6g, zero point predicts %.6g", w5, e_v5);
    CHECK(fabs(w10 / w5 - 0.01) < 1e-4, "V + 5: ratio %.6g", w10 / w5);
    CHECK(s1.st.drawn == 2 && s1.st.hidden == 0 && s1.st.limit_mag == 12, "stats: drawn %ld hidden %ld limit %g",
          s1.st.drawn, s1.st.hidden, s1.st.limit_mag);

    /* 4. Aberration in the frame: 30 km/s along the camera's +x axis. */
    struct nc_vec3 right = nc_v3_unit(nc_v3_cross(look, nc_v3(0, 0, 1))); /* look x up: image +x */
    float *e2;
    shoot(look, away, nc_v3_scale(right, 3e4), 2, &e2);
    double c1 = 0, c2 = 0, m1 = 0, m2 = 0; /* centroids in a window that holds the V 5 star, not its twin */
    for (int y = -7; y <= 7; y++)
        for (int x = -7; x <= 20; x++) {
            double v1 = e1[(y5 + y) * 96 + x5 + x], v2 = e2[(y5 + y) * 96 + x5 + x];
            m1 += v1, c1 += (x5 + x) * v1, m2 += v2, c2 += (x5 + x) * v2;
        }
    double dx_px = c2 / m2 - c1 / m1, shift = atan(dx_px * 1e-5) / AS;
    printf("aberration in the frame: the star moved %.4f px = %.4f arcsec (expected %.4f)\n", dx_px, shift, want);
    CHECK(fabs(shift - want) < 0.1, "aberration in the frame %.4f arcsec, expected %.4f", shift, want);
    free(e2);

    /* 5. Occultation, and threads. */
    struct shot s3 = shoot(look, nc_v3_scale(look, 1e4), nc_v3(0, 0, 0), 2, NULL);
    printf("occultation: %ld hidden, %ld drawn, %.3g e- in the frame\n", s3.st.hidden, s3.st.drawn, s3.sum);
    CHECK(s3.st.hidden == 2 && s3.st.drawn == 0 && s3.sum < 1e-6 * s1.sum, "a body in front: hidden %ld, %g e-",
          s3.st.hidden, s3.sum);
    float *e4;
    shoot(look, away, nc_v3(0, 0, 0), 1, &e4);
    CHECK(!memcmp(e1, e4, sizeof(float) * 96 * 96), "1 and 2 threads: the same frame");
    free(e1);
    free(e4);

    /* 5a. A frame's stars depend on its own time, not on the frames drawn
     * before it: a star of 10 arcsec/yr along +RA (image -x) drawn at 3 days
     * after a frame at 0 gives the bytes of a sky drawn at 3 days first
     * (navcam batch's shards and resumed runs); it moved 10 * 3 / 365.25
     * arcsec, 0.04 px. */
    struct nc_star fast = {.ra_rad = 1.0, .dec_rad = 0.4, .pm_ra_mas_yr = 10000, .v_mag = 5.0f, .b_v = 0.65f};
    struct nc_star_cat one = {.n = 1, .star = &fast, .epoch_jyear = 2000};
    char fset[1100];
    snprintf(fset, sizeof fset, "stars.catalogue=%s", nc_test_path("fast.ncs"));
    const char *fsets[] = {fset};
    CHECK(nc_star_cat_write(&one, nc_test_path("fast.ncs")) == 0, "write");
    const double t0[] = {0}, t3[] = {3 * 86400.0}, t03[] = {0, 3 * 86400.0};
    float *f0 = draw_at(fsets, 1, t0, 1, 1.0), *f3 = draw_at(fsets, 1, t3, 1, 1.0),
          *f03 = draw_at(fsets, 1, t03, 2, 1.0);
    const double pm_as = (centroid_x(f0) - centroid_x(f3)) * 1e-5 / AS, want_as = 10 * 3 / 365.25;
    printf("proper motion in 3 days: %.4f arcsec (%.4f expected); drawn after a frame at 0: %s\n", pm_as, want_as,
           memcmp(f3, f03, sizeof(float) * 96 * 96) ? "differs" : "the same bytes");
    CHECK(!memcmp(f3, f03, sizeof(float) * 96 * 96), "a frame's stars depend on the frame drawn before it");
    CHECK(fabs(pm_as - want_as) < 0.01, "proper motion in 3 days: %.4f arcsec, expected %.4f", pm_as, want_as);
    free(f0);
    free(f3);
    free(f03);

    /* 5c. A rolling shutter: a star 30 rows below the middle one is exposed
     * 30 line times (1e-5 s each) after it; the camera turning at 0.02
     * rad/s about its y axis has moved it -0.02 * 3e-4 * 1e5 = -0.6 px along
     * x by then, against the global shutter's frame (an exposure of 1 ms: 2
     * px of smear about that place). */
    {
        const struct nc_vec3 north = nc_v3_unit(nc_v3_sub(nc_v3(0, 0, 1), nc_v3_scale(look, look.z)));
        const struct nc_vec3 up30 = nc_v3_unit(nc_v3_add(look, nc_v3_scale(north, 30e-5)));
        char at[200];
        snprintf(at, sizeof at, "camera.look_at_m=[%.17g, %.17g, %.17g]", up30.x, up30.y, up30.z);
        const char *glob[] = {at, "camera.angular_velocity_rad_s=[0, 0.02, 0]", "stars.limit_mag=6"};
        const char *roll[] = {at, "camera.angular_velocity_rad_s=[0, 0.02, 0]", "stars.limit_mag=6",
                              "sensor.shutter=rolling", "sensor.line_time_s=1e-5"};
        const double at0[] = {0};
        float *fg = draw_at(glob, 3, at0, 1, 1e-3), *fr = draw_at(roll, 5, at0, 1, 1e-3);
        const double dx = centroid_x(fr) - centroid_x(fg);
        printf("rolling shutter: a star 30 rows below the middle moved %.4f px along x (-0.6 expected)\n", dx);
        CHECK(fabs(dx + 0.6) < 0.02, "a star under a rolling shutter moved %.4f px, expected -0.6", dx);
        free(fg);
        free(fr);
    }

    /* 5b. limit_mag auto, by its definition: the faintest V whose star of
     * the most favourable colour (B-V within -0.4..2.0) gives 0.1 of the
     * noise of read noise and the dark current at the sensor's temperature
     * over the exposure. */
    for (int k = 0; k < 2; k++) {
        const double temp_k = k ? 303.15 : 273.15;
        char tset[64];
        snprintf(tset, sizeof tset, "sensor.temperature_k=%.17g", temp_k);
        const char *sets[] = {"sensor.read_noise_e=4", "sensor.dark_current_e_s=20", "sensor.dark_ref_temp_k=293.15",
                              "sensor.dark_doubling_k=6", tset, "stars.limit_mag=auto", "sensor.gain_e_per_dn=1"};
        const char *path = nc_test_path("scene.yaml"); /* the last shot's */
        struct nc_scene sc;
        struct nc_camsys cs;
        struct nc_sky sky;
        CHECK(nc_setup_load(path, sets, 7, &sc, &cs) >= 0 && nc_sky_load(path, sets, 7, &sky) >= 0 &&
                  nc_sky_prepare(&sky, &cs, &sc.camera) >= 0,
              "limit_mag auto: %s", nc_errmsg());
        double best = 0;
        for (int i = 0; i <= 24000; i++)
            best = fmax(best, nc_star_band_photons(&cs.optics, 0, -0.4 + 1e-4 * i));
        const double f_m = sc.camera.fx_px * cs.sensor.pixel_pitch_m, t = 0.5;
        const double e0 = best * M_PI * f_m * f_m / (4 * 8.0 * 8.0) * 0.9 * 0.6 * t;
        const double noise = sqrt(16 + 20 * exp2((temp_k - 293.15) / 6) * t);
        const double lim = 2.5 * log10(e0 / (0.1 * noise)), got = nc_sky_limit_mag(&sky, &cs, t);
        printf("limit_mag auto at %.2f K, 0.5 s: V %.4f (the definition: %.4f)\n", temp_k, got, lim);
        CHECK(fabs(got - lim) < 0.002, "limit_mag auto at %.2f K: %.4f, the definition gives %.4f", temp_k, got, lim);
        nc_sky_free(&sky);
        nc_camsys_free(&cs);
        nc_scene_free(&sc);
    }

    /* 6. The Sun, 1 deg off the boresight of a 3.7 deg field (its disk
     * about 9 px in radius), then 5 and 30 deg off, then behind a body; then
     * from 5 au on the boresight of a 73 deg field (fx 100 px: its disk
     * 0.093 px in radius, which 8 x 8 samples a pixel missed), in the open
     * and behind the body; then from 0.01 au (its disk 27.7 deg in radius,
     * 53 px: drawn (1 + cos theta) / 2 too dim with E over its solid angle). */
    const double offs[] = {1, 5, 30, 1, 0, 0, 0};
    for (int k = 0; k < 7; k++) {
        char sunset[160], rockset[160];
        double o = offs[k] * M_PI / 180;
        snprintf(sunset, sizeof sunset, "sun.direction=[%.17g, 0, %.17g]", sin(o), cos(o));
        snprintf(rockset, sizeof rockset, "bodies.0.position_m=[%.17g, 0, %.17g]", k == 3 ? 1e4 * sin(o) : 0.0,
                 k == 3 || k == 5 ? 1e4 * cos(o) : -1e4);
        const char *sets[] = {sunset, rockset, "camera.fx_px=100", "camera.fy_px=100",
                              k == 6 ? "sun.distance_au=0.01" : "sun.distance_au=5"};
        struct nc_scene sc;
        nc_test_scene("bodies:\n  - shape: {type: sphere, radius_m: 200}\n    material: {model: lambert, A: 0.1}\n"
                      "sun: {direction: [0, 0, 1]}\n"
                      "camera: {width_px: 128, height_px: 128, fx_px: 2000, fy_px: 2000, position_m: [0, 0, 0],\n"
                      "         attitude_q: [1, 0, 0, 0]}\n",
                      sets, k < 4 ? 2 : 5, &sc);
        struct nc_renderer rs;
        struct nc_frame fs;
        struct nc_sun_view sv;
        char warn[80];
        nc_renderer_init(&rs, &sc, 2);
        nc_frame_alloc(&fs, 128, 128);
        memset(fs.radiance, 0, 128 * 128 * sizeof *fs.radiance); /* the Sun is added to the body's light */
        CHECK(nc_render_sun(&rs, &sc, NC_SUN_NEAR_DEG, &fs, &sv) == 0, "sun: %s", nc_errmsg());
        nc_sun_view_warning(&sv, warn, sizeof warn);
        struct nc_vec3 sd;
        double irr;
        nc_scene_sun_at(&sc, sc.camera.position_m, &sd, &irr);
        printf("sun %g deg off axis: edge %.3f deg, in field %d, hidden %d, drawn %.6g of its irradiance, "
               "warning '%s'\n",
               offs[k], sv.edge_deg, sv.in_field, sv.hidden, sv.drawn_w_m2 / irr, warn);
        if (k == 0)
            CHECK(sv.in_field && !sv.hidden && fabs(sv.drawn_w_m2 / irr - 1) < 0.005 && !strcmp(warn, "sun in field"),
                  "the Sun in the field: drawn %.5f of its irradiance", sv.drawn_w_m2 / irr);
        if (k == 1) /* the edge 64 px from the centre (1.833 deg), the Sun's radius 0.267 deg */
            CHECK(!sv.in_field && sv.near_field && fabs(sv.edge_deg - (5 - atan(64.0 / 2000) * 180 / M_PI - 0.2666)) < 0.01 &&
                      sv.drawn_w_m2 == 0 && nc_test_contains(warn, "deg from the field"),
                  "the Sun near the field: edge %.4f deg", sv.edge_deg);
        if (k == 2)
            CHECK(!sv.in_field && !sv.near_field && !warn[0], "the Sun far from the field");
        if (k == 3 || k == 5)
            CHECK(sv.in_field && sv.hidden && sv.drawn_w_m2 == 0 && !strcmp(warn, "sun in field, hidden by a body"),
                  "the Sun behind a body (%d)", k);
        if (k == 4)
            CHECK(sv.in_field && !sv.hidden && fabs(sv.drawn_w_m2 / irr - 1) < 1e-9,
                  "the Sun's disk 0.093 px in radius: drawn %.9f of its irradiance", sv.drawn_w_m2 / irr);
        if (k == 6) { /* the disk's radiance E / (pi sin^2 theta), at its centre pixel */
            const double th = nc_scene_sun_radius_rad(&sc), disk = irr / (M_PI * sin(th) * sin(th));
            const double centre = fs.radiance[64 * 128 + 64];
            printf("the Sun from 0.01 au (radius %.2f deg): radiance %.6g (E / (pi sin^2 theta) %.6g), drawn %.5f of "
                   "its irradiance\n", th * 180 / M_PI, centre, disk, sv.drawn_w_m2 / irr);
            CHECK(fabs(centre / disk - 1) < 1e-6 && fabs(sv.drawn_w_m2 / irr - 1) < 0.005,
                  "the Sun from 0.01 au: radiance %.6g, want %.6g; drawn %.5f of its irradiance", centre, disk,
                  sv.drawn_w_m2 / irr);
        }
        nc_frame_free(&fs);
        nc_renderer_free(&rs);
        nc_scene_free(&sc);
    }
    /* A Sun given by its position (from bodies[0], in its frame: 1.8e9 m away) 0.02 au from the camera: its
     * disk as seen from the camera (13.4 deg in radius; it was sized from bodies[0], 22.7 deg, and too dim, as
     * an outside check found) */
    {
        const char *sets[] = {"sun={position_m: [-1e9, 0, 1.495978707e9]}", "camera.position_m=[0, 0, -1.495978707e9]",
                              "bodies.0.position_m=[1e9, 0, 0]", "camera.fx_px=100", "camera.fy_px=100"};
        struct nc_scene sc;
        nc_test_scene("bodies:\n  - shape: {type: sphere, radius_m: 200}\n    material: {model: lambert, A: 0.1}\n"
                      "sun: {direction: [0, 0, 1]}\n"
                      "camera: {width_px: 128, height_px: 128, fx_px: 2000, fy_px: 2000, position_m: [0, 0, 0],\n"
                      "         attitude_q: [1, 0, 0, 0]}\n",
                      sets, 5, &sc);
        struct nc_renderer rs;
        struct nc_frame fs;
        struct nc_sun_view sv;
        nc_renderer_init(&rs, &sc, 2);
        nc_frame_alloc(&fs, 128, 128);
        memset(fs.radiance, 0, 128 * 128 * sizeof *fs.radiance);
        CHECK(nc_render_sun(&rs, &sc, NC_SUN_NEAR_DEG, &fs, &sv) == 0, "sun: %s", nc_errmsg());
        struct nc_vec3 sd;
        double irr;
        nc_scene_sun_at(&sc, sc.camera.position_m, &sd, &irr);
        const double th = asin(6.957e8 / 2.991957414e9), disk = irr / (M_PI * sin(th) * sin(th));
        const double centre = fs.radiance[64 * 128 + 64];
        printf("a Sun 0.02 au from the camera, given by its position: radiance %.6g (E / (pi sin^2 theta) %.6g, "
               "theta %.4f deg), drawn %.5f of its irradiance\n", centre, disk, th * 180 / M_PI, sv.drawn_w_m2 / irr);
        CHECK(fabs(centre / disk - 1) < 1e-6 && fabs(sv.drawn_w_m2 / irr - 1) < 0.005,
              "a Sun given by its position: radiance %.6g, want %.6g", centre, disk);
        nc_frame_free(&fs);
        nc_renderer_free(&rs);
        nc_scene_free(&sc);
    }
    return nc_test_end();
}
