/* material.h - surface reflectance models behind one interface.
 *
 * A model is one constant struct: a name, its parameter table (key, default,
 * physical range, unit) and an evaluator of the bidirectional reflectance
 * r (1/sr) over arrays of photometric geometries. Radiance = r * J, where J is
 * the solar irradiance on a surface facing the Sun (W m^-2). Conventions are
 * those of shared/notes/reflectance.md: BRDF = r / mu0, I/F = pi r.
 * The renderer calls models only through this interface; a new model is a new
 * entry in the registry and nothing else changes.
 */
#ifndef NC_MATERIAL_H
#define NC_MATERIAL_H

#include <stddef.h>

#include "config.h"

#define NC_BRDF_MAX_PARAMS 12

struct nc_brdf_param {
    const char *key;
    double def, min, max;
    const char *unit;
    const char *doc;
};

/* One photometric geometry: cosines of incidence, emission and phase angles
 * (mu0 > 0 and mu > 0 are guaranteed by the caller), and the local factor on
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
    /* r (1/sr) for n geometries; p holds the parameters in table order. */
    void (*eval)(const double *p, size_t n, const struct nc_photometry *geo, double *r);
};

struct nc_material {
    const struct nc_brdf_model *model;
    double p[NC_BRDF_MAX_PARAMS];
};

extern const struct nc_brdf_model *const nc_brdf_models[];

const struct nc_brdf_model *nc_brdf_find(const char *name);
/* Material with every parameter at its default. */
int nc_material_init(struct nc_material *m, const char *model);
/* Set one parameter by key, checked against its range. */
int nc_material_set(struct nc_material *m, const char *key, double value);
/* Read "model: NAME" and the model's parameter keys from a config map. */
int nc_material_from_config(struct nc_cfg_node *map, struct nc_material *m);
/* r (1/sr) of the material for n geometries. */
static inline void nc_material_eval(const struct nc_material *m, size_t n, const struct nc_photometry *geo, double *r)
{
    m->model->eval(m->p, n, geo, r);
}

#endif
