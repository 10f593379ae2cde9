/* cmd_stars.c - `navcam stars`: write NavCam's star index from a catalogue,
 * and describe an index (docs/stars.md). */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/cli.h"
#include "core/clock.h"
#include "core/error.h"
#include "render/stars.h"

static const char stars_help[] =
    "Usage: navcam stars index STARS.DAT -o INDEX [--max-mag V]\n"
    "       navcam stars info INDEX\n"
    "\n"
    "index  read a star catalogue and write NavCam's star index (brightest\n"
    "       first, so that stars to a limiting magnitude load and cost nothing\n"
    "       beyond them). STARS.DAT is KStars' stars.dat: Hipparcos and Tycho\n"
    "       stars to V 8.99 with J2000 positions, proper motions, V and B-V\n"
    "       (Debian package kstars-data: /usr/share/kstars/stars.dat;\n"
    "       scripts/install-deps.sh --stars extracts it without installing KStars).\n"
    "  -o, --output INDEX   the index to write\n"
    "      --max-mag V      keep only stars of magnitude V or brighter (V included)\n"
    "info   count the stars of an index by magnitude, and time its loading.\n"
    "  -h, --help           this help\n"
    "\n"
    "Use the index in a scene: stars: {catalogue: INDEX} (docs/stars.md).\n";

static double now_ms(void) { return (double)nc_mono_ns() * 1e-6; }

static int info(const char *path)
{
    struct nc_star_cat c;
    double t0 = now_ms();
    if (nc_star_cat_load(path, &c) < 0)
        return nc_cli_fail();
    double ms = now_ms() - t0;
    printf("%s: %zu stars, V %.2f to %.2f, positions at epoch J%.2f; loaded in %.1f ms\n", path, c.n,
           c.star[0].v_mag, c.star[c.n - 1].v_mag, c.epoch_jyear, ms);
    for (int v = (int)floor(c.star[0].v_mag); v <= (int)floor(c.star[c.n - 1].v_mag); v++)
        printf("  V < %2d: %zu\n", v + 1, nc_star_cat_count_to(&c, nextafterf((float)(v + 1), -INFINITY)));
    nc_star_cat_free(&c);
    return 0;
}

int main(int argc, char **argv)
{
    nc_cli_init("stars");
    const char *verb = argc > 1 ? argv[1] : "";
    if (!strcmp(verb, "-h") || !strcmp(verb, "--help")) {
        fputs(stars_help, stdout);
        return 0;
    }
    if (!strcmp(verb, "info") && argc == 3 && (!strcmp(argv[2], "-h") || !strcmp(argv[2], "--help"))) {
        fputs(stars_help, stdout);
        return 0;
    }
    if (!strcmp(verb, "info") && argc == 3)
        return info(argv[2]);
    if (strcmp(verb, "index") != 0) {
        fputs("Usage: navcam stars index STARS.DAT -o INDEX | navcam stars info INDEX (navcam stars --help)\n", stderr);
        return 2;
    }
    static const struct option opts[] = {{"output", required_argument, NULL, 'o'},
                                         {"max-mag", required_argument, NULL, 'm'},
                                         {"help", no_argument, NULL, 'h'},
                                         {NULL, 0, NULL, 0}};
    const char *out = NULL;
    double max_mag = INFINITY;
    int ch;
    optind = 2;
    while ((ch = nc_cli_getopt(argc, argv, "o:h", opts)) != -1) {
        const char *end;
        switch (ch) {
        case 'o': out = optarg; break;
        case 'm':
            if (nc_cli_decimal(optarg, &end, &max_mag) < 0 || *end) {
                fprintf(stderr, "navcam stars: --max-mag: expected a magnitude, got '%s'\n", optarg);
                return 2;
            }
            break;
        case 'h': fputs(stars_help, stdout); return 0;
        default: fputs("Try 'navcam stars --help'.\n", stderr); return 2;
        }
    }
    if (!out || optind != argc - 1) {
        fputs("navcam stars index: give one catalogue and -o INDEX (navcam stars --help)\n", stderr);
        return 2;
    }
    struct nc_star_cat c;
    double t0 = now_ms();
    if (nc_star_cat_read_kstars(argv[optind], &c) < 0)
        return nc_cli_fail();
    size_t all = c.n;
    c.n = nc_star_cat_count_to(&c, max_mag);
    if (c.n == 0) {
        fprintf(stderr, "navcam stars: no star of V %g or brighter in %s\n", max_mag, argv[optind]);
        nc_star_cat_free(&c);
        return 1;
    }
    int rc = nc_star_cat_write(&c, out);
    if (rc == 0)
        printf("wrote %s: %zu of %zu stars, V %.2f to %.2f, J%.1f, %zu bytes (%.0f ms)\n", out, c.n, all,
               c.star[0].v_mag, c.star[c.n - 1].v_mag, c.epoch_jyear, 24 + 32 * c.n, now_ms() - t0);
    nc_star_cat_free(&c);
    return rc < 0 ? nc_cli_fail() : 0;
}
