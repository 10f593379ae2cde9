/* cmd_population.c - `navcam population`: every boulder and crater a
 * scene's bodies are given, as CSV files, to check a population against its
 * size-frequency distribution or to use as ground truth (docs/terrain.md). */
#include <errno.h>
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/cli.h"
#include "camera/load.h"
#include "core/error.h"
#include "core/fs.h"

static const char population_help[] =
    "Usage: navcam population [SCENE.yaml] [--set KEY=VALUE]... [-b BOULDERS.csv] [-c CRATERS.csv]\n"
    "\n"
    "The boulders and craters the scene's bodies are given (SCENE.yaml, or the\n"
    "built-in default scene, with --set overrides as for `navcam render`): every one\n"
    "drawn, whatever a camera would trace or see. A line per body on standard output\n"
    "(its surface, the populations' counts and parameters) and, with -b and -c, the\n"
    "lists as CSV, each after comment lines (#) giving every body's surface area and\n"
    "parameters (or saying that no body has any), so that N(>D) = C D^-b per km^2\n"
    "can be fitted on the list:\n"
    "  BOULDERS.csv  body,index,x_m,y_m,z_m,diameter_m,shape,q_w,q_x,q_y,q_z\n"
    "                index: in the body's list (largest octave first), as rock_id\n"
    "                shows it; the centre in the body-fixed frame, m; diameter_m the\n"
    "                rock's longest dimension, m; shape its shape's number; q the\n"
    "                rotation rock frame -> body frame (scalar first)\n"
    "  CRATERS.csv   body,index,x_m,y_m,z_m,diameter_m,age\n"
    "                index: oldest first; the centre on the surface before carving,\n"
    "                body-fixed, m; diameter_m rim to rim, m; age 0 (fresh) to 1\n"
    "A file is written whole or not at all (a temporary renamed).\n"
    "\n"
    "  -s, --set KEY=VALUE    override a configuration key (repeatable)\n"
    "  -b, --boulders FILE    every boulder, CSV\n"
    "  -c, --craters FILE     every crater, CSV\n"
    "  -h, --help             this help\n"
    "\n"
    "Example: navcam population --set 'bodies.0.boulders={preset: bennu, min_diameter_m: 1}' -b rocks.csv\n";

/* Each body's surface and parameters, as comment lines (a line saying so
 * where no body has any). */
static void comments(FILE *f, const struct nc_scene *s, int rocks)
{
    int any = 0;
    for (int b = 0; b < s->nbodies; b++)
        any |= rocks ? s->body[b].boulders.n > 0 : s->body[b].craters.n > 0;
    if (!any)
        fprintf(f, "# no body has %s\n", rocks ? "boulders" : "craters");
    for (int b = 0; b < s->nbodies; b++) {
        const struct nc_body *y = &s->body[b];
        if (rocks && y->boulders.n) {
            const struct nc_boulder_params *p = &y->boulders.params;
            fprintf(f, "# body %d '%s': %zu boulders on %.9g km^2, N(>D) = C D^-b per km^2 with C %.9g, b %.9g, "
                    "D from %.9g to %.9g m, seed %llu\n", b, y->name, y->boulders.n, y->boulders.area_m2 * 1e-6,
                    p->c_per_km2, p->slope, p->d_min_m, p->d_max_m, (unsigned long long)p->seed);
        } else if (!rocks && y->craters.n) {
            const struct nc_crater_params *p = &y->craters.params;
            fprintf(f, "# body %d '%s': %zu craters on %.9g km^2, N(>D) = C D^-b per km^2 with C %.9g, b %.9g, "
                    "D from %.9g to %.9g m, seed %llu\n", b, y->name, y->craters.n, y->craters.area_km2,
                    p->c_per_km2, p->slope, p->d_min_m, p->d_max_m, (unsigned long long)p->seed);
        }
    }
}

/* The boulders (rocks 1) or craters (0) of every body into path: a
 * temporary beside it, renamed when whole. */
static int write_list(const char *path, const struct nc_scene *s, int rocks)
{
    char tmp[4200];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", path, (long)getpid());
    FILE *f = fopen(tmp, "w");
    if (!f)
        return nc_error(-errno, "%s: cannot write a file there: %s", path, strerror(errno));
    comments(f, s, rocks);
    fputs(rocks ? "body,index,x_m,y_m,z_m,diameter_m,shape,q_w,q_x,q_y,q_z\n"
                : "body,index,x_m,y_m,z_m,diameter_m,age\n",
          f);
    for (int b = 0; b < s->nbodies; b++) {
        if (rocks) {
            const struct nc_boulder_field *bf = &s->body[b].boulders;
            for (size_t k = 0; k < bf->n; k++) {
                const struct nc_boulder *r = &bf->rock[k];
                fprintf(f, "%d,%zu,%.9g,%.9g,%.9g,%.9g,%u,%.9g,%.9g,%.9g,%.9g\n", b, k, r->centre_m[0], r->centre_m[1],
                        r->centre_m[2], 2.0 * r->half_m, (unsigned)r->shape, r->q[0], r->q[1], r->q[2], r->q[3]);
            }
        } else {
            const struct nc_crater_field *cf = &s->body[b].craters;
            for (size_t k = 0; k < cf->n; k++) {
                const struct nc_crater *c = &cf->crater[k];
                fprintf(f, "%d,%zu,%.9g,%.9g,%.9g,%.9g,%.6g\n", b, k, c->centre_m[0], c->centre_m[1], c->centre_m[2],
                        c->d_m, c->age);
            }
        }
    }
    const int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        const int err = errno ? errno : EIO;
        unlink(tmp);
        return nc_error(-err, "%s: write failed: %s", path, strerror(err));
    }
    int rc = nc_commit_file(tmp, path);
    if (rc < 0) {
        char why[512];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        unlink(tmp);
        return nc_error(rc, "%s: not written (%s)", path, why);
    }
    return 0;
}

int main(int argc, char **argv)
{
    nc_cli_init("population");
    static const struct option opts[] = {
        {"set", required_argument, NULL, 's'},    {"boulders", required_argument, NULL, 'b'},
        {"craters", required_argument, NULL, 'c'}, {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    const char **sets = calloc((size_t)argc + 1, sizeof *sets);
    const char *rocks_out = NULL, *craters_out = NULL, *scene_path = NULL;
    int nsets = 0, c;
    if (!sets)
        return 1;
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "s:b:c:h", opts)) != -1) {
        switch (c) {
        case 's': sets[nsets++] = optarg; break;
        case 'b': rocks_out = optarg; break;
        case 'c': craters_out = optarg; break;
        case 'h': fputs(population_help, stdout); free(sets); return 0;
        default: fputs("Try 'navcam population --help'.\n", stderr); free(sets); return 2;
        }
    }
    if (optind < argc)
        scene_path = argv[optind++];
    if (optind < argc) {
        fprintf(stderr, "navcam population: more than one scene file given\nTry 'navcam population --help'.\n");
        free(sets);
        return 2;
    }
    /* Fail before the build (seconds for a large population), not after,
     * when an output cannot be written. */
    if ((rocks_out && nc_cli_dir_writable(rocks_out) < 0) || (craters_out && nc_cli_dir_writable(craters_out) < 0)) {
        free(sets);
        return 1;
    }
    struct nc_scene s;
    struct nc_camsys cs;
    int rc = nc_setup_load(scene_path, sets, nsets, &s, &cs);
    free(sets);
    if (rc < 0)
        return nc_cli_fail();
    nc_camsys_free(&cs);
    for (int b = 0; b < s.nbodies; b++) {
        const struct nc_body *y = &s.body[b];
        printf("body %d '%s':", b, y->name);
        if (y->boulders.n)
            printf(" %zu boulders of %.9g to %.9g m on %.9g km^2 (C %.9g per km^2, b %.9g, seed %llu);", y->boulders.n,
                   y->boulders.params.d_min_m, y->boulders.params.d_max_m, y->boulders.area_m2 * 1e-6,
                   y->boulders.params.c_per_km2, y->boulders.params.slope,
                   (unsigned long long)y->boulders.params.seed);
        else
            printf(" no boulders;");
        if (y->craters.n)
            printf(" %zu craters of %.9g to %.9g m on %.9g km^2 (C %.9g per km^2, b %.9g, seed %llu)\n", y->craters.n,
                   y->craters.params.d_min_m, y->craters.params.d_max_m, y->craters.area_km2,
                   y->craters.params.c_per_km2, y->craters.params.slope, (unsigned long long)y->craters.params.seed);
        else
            printf(" no craters\n");
    }
    if ((rocks_out && (rc = write_list(rocks_out, &s, 1)) < 0) ||
        (craters_out && (rc = write_list(craters_out, &s, 0)) < 0)) {
        nc_scene_free(&s);
        return nc_cli_fail();
    }
    nc_scene_free(&s);
    return 0;
}
