/* cmd_brdf.c - `navcam brdf`: evaluate a reflectance model for one
 * geometry or a CSV stream. Links the reflectance models only. */
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "app/cli.h"
#include "core/error.h"
#include "render/material.h"

static const char brdf_help[] =
    "Usage: navcam brdf (--model NAME | --preset NAME) [--param KEY=VALUE]... [--geometry I,E,G]\n"
    "\n"
    "Evaluate a reflectance model. Angles in degrees: incidence i, emission e,\n"
    "phase g. With --geometry, print one row; otherwise read rows \"i,e,g\" from\n"
    "standard input (an optional header line first) and print one row each.\n"
    "Output columns, full double precision:\n"
    "  i_deg,e_deg,g_deg,r,brdf,radf,reff\n"
    "  r     bidirectional reflectance, 1/sr (radiance = r x solar irradiance)\n"
    "  brdf  r / cos i, 1/sr\n"
    "  radf  radiance factor I/F = pi r\n"
    "  reff  reflectance factor pi r / cos i\n"
    "i >= 90 or e >= 90 gives 0. Impossible geometries and out-of-range\n"
    "parameters are errors naming the input line or the key.\n"
    "\n"
    "  -m, --model NAME       lambert | lommel_seeliger | hapke | mcewen\n"
    "  -P, --preset NAME      a parameter set from the literature (comet_67p, moon)\n"
    "  -p, --param KEY=VALUE  a model parameter (repeatable; overrides the preset)\n"
    "  -g, --geometry I,E,G   one geometry instead of standard input\n"
    "      --no-header        do not print the column header\n"
    "  -l, --list             list models, their parameters and the presets\n"
    "  -h, --help             this help\n"
    "\n"
    "Parameters (defaults in brackets; 'required' has none):\n"
    "%s"
    "\n"
    "Examples:\n"
    "  navcam brdf --model hapke --param w=0.3 --param b=0.25 --param theta_bar=20 --geometry 30,0,30\n"
    "  printf 'i,e,g\\n30,30,0\\n60,0,60\\n' | navcam brdf --preset comet_67p\n"
    "\n"
    "Exit status: 0 done, 1 a bad line of standard input, 2 a bad option or option value.\n";

static void describe_models(char *buf, size_t len)
{
    size_t pos = 0;
    for (int i = 0; nc_brdf_models[i] && pos < len; i++) {
        const struct nc_brdf_model *md = nc_brdf_models[i];
        pos += (size_t)snprintf(buf + pos, len - pos, "  %s: %s\n", md->name, md->description);
        for (int k = 0; k < md->nparams && pos < len; k++) {
            const struct nc_brdf_param *p = &md->params[k];
            char def[32];
            if (isnan(p->def))
                snprintf(def, sizeof def, "required");
            else
                snprintf(def, sizeof def, "%g", p->def);
            pos += (size_t)snprintf(buf + pos, len - pos, "    %-10s [%s] %g..%g %s: %s\n", p->key, def, p->min,
                                    p->max, p->unit, p->doc);
        }
    }
    for (int i = 0; nc_brdf_presets[i].name && pos < len; i++)
        pos += (size_t)snprintf(buf + pos, len - pos, "  preset %s (%s): %s\n    source: %s\n", nc_brdf_presets[i].name,
                                nc_brdf_presets[i].model, nc_brdf_presets[i].keys, nc_brdf_presets[i].source);
}

/* The column header goes out with the first row, so that a run refused at
 * its first geometry prints nothing on stdout. */
static int header = 1;

static int print_brdf_row(const struct nc_material *m, double i, double e, double g, const char *where)
{
    double out[4];
    if (nc_material_eval_deg(m, i, e, g, out) < 0) {
        fprintf(stderr, "navcam brdf: %s: %s\n", where, nc_errmsg());
        return -1;
    }
    if (header)
        puts("i_deg,e_deg,g_deg,r,brdf,radf,reff");
    header = 0;
    printf("%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", i, e, g, out[0], out[1], out[2], out[3]);
    return 0;
}

/* Three comma-separated numbers, nothing else: 0, or -1 - k for the field
 * k (0 i, 1 e, 2 g) where it goes wrong. */
static int parse_geometry(const char *s, double v[3])
{
    const char *p = s;
    for (int k = 0; k < 3; k++) {
        char *end;
        while (*p == ' ' || *p == '\t')
            p++;
        v[k] = strtod(p, &end);
        if (end == p || !isfinite(v[k]))
            return -1 - k;
        p = end;
        while (*p == ' ' || *p == '\t')
            p++;
        if (k < 2) {
            if (*p != ',')
                return -1 - k;
            p++;
        }
    }
    while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\n')
        p++;
    return *p ? -3 : 0;
}

static const char *const field_names[] = {"i", "e", "g"};

int main(int argc, char **argv)
{
    nc_cli_init("brdf");
    static const struct option opts[] = {
        {"model", required_argument, NULL, 'm'},    {"preset", required_argument, NULL, 'P'},
        {"param", required_argument, NULL, 'p'},    {"geometry", required_argument, NULL, 'g'},
        {"no-header", no_argument, NULL, 'H'},      {"list", no_argument, NULL, 'l'},
        {"help", no_argument, NULL, 'h'},           {NULL, 0, NULL, 0},
    };
    const char *model = NULL, *preset = NULL, *geometry = NULL;
    const char **params = calloc((size_t)argc + 1, sizeof *params);
    int nparams = 0, c, rc = 2;
    char models[4096];
    struct nc_material m;
    memset(&m, 0, sizeof m);
    if (!params)
        return 1;
    describe_models(models, sizeof models);
    optind = 1;
    while ((c = nc_cli_getopt(argc, argv, "m:P:p:g:lh", opts)) != -1) {
        switch (c) {
        case 'm': model = optarg; break;
        case 'P': preset = optarg; break;
        case 'p': params[nparams++] = optarg; break;
        case 'g': geometry = optarg; break;
        case 'H': header = 0; break;
        case 'l': fputs(models, stdout); rc = 0; goto out;
        case 'h': printf(brdf_help, models); rc = 0; goto out;
        default: fputs("Try 'navcam brdf --help'.\n", stderr); goto out;
        }
    }
    if (optind < argc) {
        fprintf(stderr, "navcam brdf: unexpected argument '%s'\nTry 'navcam brdf --help'.\n", argv[optind]);
        goto out;
    }
    if (!model && !preset) {
        fprintf(stderr, "navcam brdf: give --model NAME or --preset NAME\nTry 'navcam brdf --help'.\n");
        goto out;
    }
    /* a bad option value exits 2, naming the option; a bad line of standard input, 1 */
    const char *opt = preset ? "--preset" : "--model";
    if (preset) {
        if (nc_material_preset(&m, preset) < 0)
            goto fail;
        if (model && strcmp(model, m.model->name) != 0) {
            fprintf(stderr, "navcam brdf: --preset '%s' is a %s material, not --model %s\n", preset, m.model->name,
                    model);
            goto out;
        }
    } else if (nc_material_init(&m, model) < 0) {
        goto fail;
    }
    opt = "--param";
    for (int k = 0; k < nparams; k++) {
        const char *eq = strchr(params[k], '=');
        char key[64], *end;
        if (!eq || eq == params[k] || (size_t)(eq - params[k]) >= sizeof key) {
            fprintf(stderr, "navcam brdf: --param expects KEY=VALUE, got '%s'\n", params[k]);
            goto out;
        }
        snprintf(key, sizeof key, "%.*s", (int)(eq - params[k]), params[k]);
        double v = strtod(eq + 1, &end);
        if (end == eq + 1 || *end || !isfinite(v)) {
            fprintf(stderr, "navcam brdf: --param %s: expected a finite number, got '%s'\n", key, eq + 1);
            goto out;
        }
        if (nc_material_set(&m, key, v) < 0)
            goto fail;
    }
    if (nc_material_finish(&m) < 0)
        goto fail;
    opt = "--geometry";
    if (geometry) {
        double v[3];
        const int bad = parse_geometry(geometry, v);
        if (bad < 0) {
            fprintf(stderr, "navcam brdf: --geometry expects I,E,G in degrees, got '%s' (field %s)\n", geometry,
                    field_names[-1 - bad]);
            goto out;
        }
        rc = print_brdf_row(&m, v[0], v[1], v[2], "--geometry") < 0 ? 2 : 0;
        goto out;
    }
    char *line = NULL;
    size_t cap = 0;
    long lineno = 0;
    rc = 0;
    while (getline(&line, &cap, stdin) > 0) {
        lineno++;
        double v[3];
        char where[64];
        snprintf(where, sizeof where, "stdin:%ld", lineno);
        if (line[strspn(line, " \t\r\n")] == '\0')
            continue; /* blank */
        const int bad = parse_geometry(line, v);
        if (bad < 0) {
            if (lineno == 1 && strpbrk(line, "ieIE") && !strpbrk(line, "0123456789"))
                continue; /* the optional header */
            line[strcspn(line, "\r\n")] = '\0';
            fprintf(stderr, "navcam brdf: %s: expected \"i,e,g\" in degrees, got \"%s\" (field %s)\n", where, line,
                    field_names[-1 - bad]);
            rc = 1;
            break;
        }
        if (print_brdf_row(&m, v[0], v[1], v[2], where) < 0) {
            rc = 1;
            break;
        }
    }
    free(line);
    goto out;
fail:
    fprintf(stderr, "navcam brdf: %s: %s\n", opt, nc_errmsg());
out:
    free(params);
    return rc;
}
