/* material.c - the reflectance model registry and the models themselves.
 * Hot path: eval() runs on every lit hit; keep it branch-light and finite. */
#include "material.h"

#include <math.h>
#include <string.h>

#include "error.h"

/* Lambert: r = A mu0 / pi (notes/reflectance.md). */
static const struct nc_brdf_param lambert_params[] = {
    {"A", 0.1, 0.0, 1.0, "1", "Lambert albedo (bihemispherical reflectance)"},
};

static void lambert_eval(const double *p, size_t n, const struct nc_photometry *geo, double *r)
{
    const double k = p[0] / M_PI;
    for (size_t i = 0; i < n; i++)
        r[i] = k * geo[i].albedo_factor * geo[i].mu0;
}

static const struct nc_brdf_model lambert = {
    .name = "lambert",
    .description = "Lambertian surface, r = A mu0 / pi",
    .params = lambert_params,
    .nparams = 1,
    .eval = lambert_eval,
};

const struct nc_brdf_model *const nc_brdf_models[] = {&lambert, NULL};

const struct nc_brdf_model *nc_brdf_find(const char *name)
{
    for (int i = 0; nc_brdf_models[i]; i++)
        if (strcmp(nc_brdf_models[i]->name, name) == 0)
            return nc_brdf_models[i];
    return NULL;
}

int nc_material_init(struct nc_material *m, const char *model)
{
    const struct nc_brdf_model *md = nc_brdf_find(model);
    if (!md)
        return nc_error(NC_ERANGE, "unknown reflectance model '%s'", model);
    memset(m, 0, sizeof *m);
    m->model = md;
    for (int i = 0; i < md->nparams; i++)
        m->p[i] = md->params[i].def;
    return 0;
}

int nc_material_set(struct nc_material *m, const char *key, double value)
{
    for (int i = 0; i < m->model->nparams; i++) {
        const struct nc_brdf_param *p = &m->model->params[i];
        if (strcmp(p->key, key) != 0)
            continue;
        if (!(value >= p->min && value <= p->max))
            return nc_error(NC_ERANGE, "%s: parameter %s must be in [%g, %g], got %g", m->model->name, key, p->min,
                            p->max, value);
        m->p[i] = value;
        return 0;
    }
    return nc_error(NC_ERANGE, "%s: no parameter named '%s'", m->model->name, key);
}

int nc_material_from_config(struct nc_cfg_node *map, struct nc_material *m)
{
    static const char *names[8];
    int n = 0;
    for (; nc_brdf_models[n] && n < 7; n++)
        names[n] = nc_brdf_models[n]->name;
    names[n] = NULL;
    int which = 0, rc;
    if ((rc = nc_cfg_enum(map, "model", names, &which)) < 0)
        return rc;
    if (rc == 0)
        return nc_cfg_missing(map, "model", "a reflectance model name, e.g. lambert");
    nc_material_init(m, names[which]);
    for (int i = 0; i < m->model->nparams; i++) {
        const struct nc_brdf_param *p = &m->model->params[i];
        if ((rc = nc_cfg_double(map, p->key, p->min, p->max, &m->p[i])) < 0)
            return rc;
    }
    return 0;
}
