/* material.h - surface reflectance models behind one interface.
 *
 * A model is one constant struct: a name, its parameter table (key, default,
 * physical range, unit), optional derived constants and cross-checks, and an
 * evaluator of the bidirectional reflectance r (1/sr) over arrays of
 * photometric geometries. Radiance = r * J, where J is the solar irradiance
 * on a surface facing the Sun (W m^-2). Conventions are those of
 * shared/notes/reflectance.md: BRDF = r / mu0, RADF = I/F = pi r,
 * REFF = pi r / mu0. The renderer and `navcam brdf` reach models only through
 * this interface; a new model is a new registry entry and nothing else.
 */
#ifndef NC_MATERIAL_H
#define NC_MATERIAL_H

#include <stddef.h>

#include "core/config.h"

#define NC_BRDF_MAX_PARAMS 12
#define NC_BRDF_MAX_DERIVED 12

struct nc_albedo_map;

struct nc_brdf_param {
    const char *key;
    double def; /* NAN: required, no default */
    double min, max;
    const char *unit;
    const char *doc;
};

/* One photometric geometry: cosines of incidence, emission and phase angles
 * (the caller guarantees 0 < mu0 <= 1 and 0 < mu <= 1), and the local factor on
 * the model's albedo parameter (1 unless an albedo map says otherwise). */
struct nc_photometry {
    double mu0, mu, cos_g;
    double albedo_factor;
};

struct nc_brdf_model {
    const char *name;
    const char *description;
    const struct nc_brdf_param *params;
    int nparams;
    int albedo_param; /* the parameter an albedo map scales */
    int ncderived;
    /* Derived constants from the parameters (may be NULL). */
    void (*prepare)(const double *p, double *c);
    /* Checks across parameters; fills why and returns < 0 (may be NULL). */
    int (*check)(const double *p, char *why, size_t len);
    /* r (1/sr) for n geometries; p in table order, c from prepare(). */
    void (*eval)(const double *p, const double *c, size_t n, const struct nc_photometry *geo, double *r);
};

struct nc_material {
    const struct nc_brdf_model *model;
    double p[NC_BRDF_MAX_PARAMS];
    double c[NC_BRDF_MAX_DERIVED];
    struct nc_albedo_map *albedo_map; /* owned; NULL for none */
};

/* A named parameter set from the literature. */
struct nc_brdf_preset {
    const char *name;
    const char *model;
    const char *keys; /* "w=0.055 b=0.456 ..." */
    const char *source;
};

extern const struct nc_brdf_model *const nc_brdf_models[];
extern const struct nc_brdf_preset nc_brdf_presets[];

const struct nc_brdf_model *nc_brdf_find(const char *name);
const struct nc_brdf_preset *nc_brdf_preset_find(const char *name);
/* Material with every parameter at its default (required ones NAN). */
int nc_material_init(struct nc_material *m, const char *model);
/* Apply a preset's model and parameters. */
int nc_material_preset(struct nc_material *m, const char *preset);
/* Set one parameter by key, checked against its range. */
int nc_material_set(struct nc_material *m, const char *key, double value);
/* All required parameters set, cross-checks pass; computes derived constants. */
int nc_material_finish(struct nc_material *m);
/* Read a material map: model or preset, the model's parameter keys, and an
 * optional albedo_map's keys (its image is read by
 * nc_material_load_albedo_map, with the body's build). */
int nc_material_from_config(struct nc_cfg_node *map, struct nc_material *m);
int nc_material_load_albedo_map(struct nc_cfg_node *map, struct nc_material *m);
void nc_material_free(struct nc_material *m);

/* Rocks too small to trace, folded into the reflectance as macroscopic
 * roughness (docs/terrain.md). Rocks covering a fraction `cover` of the
 * surface (nc_boulders_cover) add to the mean square slope:
 *   tan^2 theta_bar' = tan^2 theta_bar + (A + B cover) cover,
 * at most the parameter's upper bound: for a small cover linear in the area,
 * as a slope variance is, and faster as the cover grows. A and B were fitted
 * to the roughness that makes rendered rocks left out as bright as traced
 * ones, at 40 and 75 deg phase and covers 0.13 to 0.69 (docs/terrain.md);
 * test_boulders checks them on other scenes.
 * Only models with a roughness parameter named theta_bar (degrees) can fold:
 * the index of that parameter, or -1. */
#define NC_ROCK_FOLD_A 0.6
#define NC_ROCK_FOLD_B 0.35
int nc_material_roughness_param(const struct nc_material *m);
/* out = m with the rocks folded in (sharing m's albedo map: never free
 * out); returns the theta_bar used, degrees, or -1 (out = m) where m cannot fold. */
double nc_material_fold_rocks(const struct nc_material *m, double cover, struct nc_material *out);

/* Photometric quantities of one geometry given in degrees: out = {r, BRDF,
 * RADF, REFF}. i >= 90 or e >= 90 gives zeros. Returns < 0 (message naming
 * the problem) for a geometry that cannot exist: any angle outside 0..180, or
 * g outside |i - e| .. min(i + e, 360 - i - e) (1e-6 deg tolerance). */
int nc_material_eval_deg(const struct nc_material *m, double i_deg, double e_deg, double g_deg, double out[4]);

/* Geometric albedo: the zero-phase I/F of a sphere of this material seen
 * from afar over that of a Lambert disk, p = 2 int_0^1 RADF(mu, mu, 0) mu dmu
 * (disk area 2 mu dmu where i = e = acos mu); 4000-point midpoint rule.
 * Lambert A gives 2A/3, Lommel-Seeliger w gives w/8. */
double nc_material_geometric_albedo(const struct nc_material *m);
/* Lommel-Seeliger w below this gives a geometric albedo w/8 darker than any
 * measured small body (the darkest comet nuclei and asteroids, ~0.02): a
 * sign that a single-scattering albedo was given (docs/reflectance.md). */
#define NC_LS_W_SUSPECT 0.16

/* r (1/sr) of the material for n geometries. */
static inline void nc_material_eval(const struct nc_material *m, size_t n, const struct nc_photometry *geo, double *r)
{
    m->model->eval(m->p, m->c, n, geo, r);
}

#endif
