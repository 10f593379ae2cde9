/* material.c - the reflectance model registry, presets, and materials from
 * configuration. The models themselves are in brdf.c. */
#include "render/material.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "render/albedo_map.h"
#include "core/error.h"
#include "core/log.h"

extern const struct nc_brdf_model nc_brdf_lambert, nc_brdf_lommel_seeliger, nc_brdf_hapke, nc_brdf_mcewen;

const struct nc_brdf_model *const nc_brdf_models[] = {&nc_brdf_lambert, &nc_brdf_lommel_seeliger, &nc_brdf_hapke,
                                                      &nc_brdf_mcewen, NULL};

/* Parameter sets from shared/notes/reflectance.md. */
const struct nc_brdf_preset nc_brdf_presets[] = {
    {"comet_67p", "hapke", "w=0.055 b=0.456 c=1 B_S0=1 h_S=0.035 B_C0=0 theta_bar=16 phi=0",
     "Davidsson, Buratti & Hicks 2022 (seed paper Table 1; b as a backward lobe)"},
    {"moon", "hapke", "w=0.3854 b=0.2375 c=0.3253 B_S0=1.686 h_S=0.0672 B_C0=0 theta_bar=23.657 phi=0",
     "Sato et al. 2014, median of the 643 nm parameter maps"},
    {NULL, NULL, NULL, NULL},
};

const struct nc_brdf_model *nc_brdf_find(const char *name)
{
    for (int i = 0; nc_brdf_models[i]; i++)
        if (strcmp(nc_brdf_models[i]->name, name) == 0)
            return nc_brdf_models[i];
    return NULL;
}

const struct nc_brdf_preset *nc_brdf_preset_find(const char *name)
{
    for (int i = 0; nc_brdf_presets[i].name; i++)
        if (strcmp(nc_brdf_presets[i].name, name) == 0)
            return &nc_brdf_presets[i];
    return NULL;
}

int nc_material_init(struct nc_material *m, const char *model)
{
    const struct nc_brdf_model *md = nc_brdf_find(model);
    if (!md) {
        char list[256] = "";
        for (int i = 0; nc_brdf_models[i]; i++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", nc_brdf_models[i]->name);
        return nc_error(NC_ERANGE, "unknown reflectance model '%s' (expected one of: %s)", model, list);
    }
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
    char list[256] = "";
    for (int i = 0; i < m->model->nparams; i++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", m->model->params[i].key);
    return nc_error(NC_ERANGE, "%s: no parameter named '%s' (it has: %s)", m->model->name, key, list);
}

int nc_material_preset(struct nc_material *m, const char *name)
{
    const struct nc_brdf_preset *ps = nc_brdf_preset_find(name);
    if (!ps) {
        char list[256] = "";
        for (int i = 0; nc_brdf_presets[i].name; i++)
            snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", nc_brdf_presets[i].name);
        return nc_error(NC_ERANGE, "unknown preset '%s' (expected one of: %s)", name, list);
    }
    int rc = nc_material_init(m, ps->model);
    char buf[512], *save = NULL;
    snprintf(buf, sizeof buf, "%s", ps->keys);
    for (char *tok = strtok_r(buf, " ", &save); tok && rc == 0; tok = strtok_r(NULL, " ", &save)) {
        char *eq = strchr(tok, '=');
        *eq = '\0';
        rc = nc_material_set(m, tok, strtod(eq + 1, NULL));
    }
    return rc;
}

int nc_material_finish(struct nc_material *m)
{
    for (int i = 0; i < m->model->nparams; i++)
        if (isnan(m->p[i]))
            return nc_error(NC_ERANGE, "%s: parameter %s is required (%s, %s)", m->model->name, m->model->params[i].key,
                            m->model->params[i].doc, m->model->params[i].unit);
    char why[256];
    if (m->model->check && m->model->check(m->p, why, sizeof why) < 0)
        return nc_error(NC_ERANGE, "%s: %s", m->model->name, why);
    if (m->model->prepare)
        m->model->prepare(m->p, m->c);
    return 0;
}

int nc_material_roughness_param(const struct nc_material *m)
{
    for (int i = 0; i < m->model->nparams; i++)
        if (!strcmp(m->model->params[i].key, "theta_bar"))
            return i;
    return -1;
}

double nc_material_fold_rocks(const struct nc_material *m, double cover, struct nc_material *out)
{
    *out = *m;
    int k = nc_material_roughness_param(m);
    if (k < 0)
        return -1;
    const double rad = M_PI / 180.0, t0 = tan(m->p[k] * rad);
    const double t1sq = (NC_ROCK_FOLD_A + NC_ROCK_FOLD_B * cover) * cover;
    double deg = atan(sqrt(t0 * t0 + t1sq)) / rad;
    out->p[k] = fmin(deg, m->model->params[k].max);
    if (m->model->prepare)
        m->model->prepare(out->p, out->c);
    return out->p[k];
}

int nc_material_from_config(struct nc_cfg_node *map, struct nc_material *m)
{
    static const char *names[8];
    int n = 0;
    for (; nc_brdf_models[n] && n < 7; n++)
        names[n] = nc_brdf_models[n]->name;
    names[n] = NULL;
    int which = 0, rc, hm, hp;
    const char *preset = NULL;
    char why[512];
    if ((hm = nc_cfg_enum(map, "model", names, &which)) < 0)
        return hm;
    if ((hp = nc_cfg_string(map, "preset", &preset)) < 0)
        return hp;
    if (hp) {
        if ((rc = nc_material_preset(m, preset)) < 0) {
            snprintf(why, sizeof why, "%s", nc_errmsg());
            return nc_cfg_key_error(map, "preset", "%s", why);
        }
        if (hm && strcmp(names[which], m->model->name) != 0)
            return nc_cfg_key_error(map, "model", "preset '%s' is a %s material, not %s", preset,
                                    m->model->name, names[which]);
    } else if (!hm) {
        return nc_cfg_missing(map, "model", "a reflectance model (lambert, lommel_seeliger, hapke, mcewen) or a preset");
    } else {
        nc_material_init(m, names[which]);
    }
    for (int i = 0; i < m->model->nparams; i++) {
        const struct nc_brdf_param *p = &m->model->params[i];
        if ((rc = nc_cfg_double(map, p->key, p->min, p->max, &m->p[i])) < 0)
            return rc;
    }
    struct nc_cfg_node *am;
    if ((rc = nc_cfg_map(map, "albedo_map", &am)) < 0)
        return rc;
    if (rc && (rc = nc_albedo_map_from_config(am, NULL)) < 0) /* the keys: the image comes with the build */
        return rc;
    if ((rc = nc_material_finish(m)) < 0) {
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_cfg_error(map, "%s", why);
    }
    if (!strcmp(m->model->name, "lommel_seeliger") && m->p[0] < NC_LS_W_SUSPECT) {
        const struct nc_cfg_node *w = nc_cfg_get(map, "w");
        char where[512];
        nc_cfg_where(w ? w : map, where, sizeof where);
        nc_log_warn("scene",
                    "%s = %g (lommel_seeliger) gives a geometric albedo of %.4f, darker than any measured "
                    "small body: Lommel-Seeliger's w is not a single-scattering albedo. For a body of geometric "
                    "albedo p use w = 8 p (Bennu, p = 0.044: w = 0.35), or Hapke with its w (docs/reflectance.md)",
                    where, m->p[0], m->p[0] / 8);
    }
    return 0;
}

int nc_material_load_albedo_map(struct nc_cfg_node *map, struct nc_material *m)
{
    struct nc_cfg_node *am = map ? nc_cfg_get(map, "albedo_map") : NULL;
    return am && !m->albedo_map ? nc_albedo_map_from_config(am, &m->albedo_map) : 0;
}

double nc_material_geometric_albedo(const struct nc_material *m)
{
    enum { N = 4000 };
    double sum = 0;
    for (int k = 0; k < N; k++) {
        double mu = (k + 0.5) / N, r;
        struct nc_photometry g = {mu, mu, 1.0, 1.0};
        nc_material_eval(m, 1, &g, &r);
        sum += M_PI * r * mu;
    }
    return 2 * sum / N;
}

void nc_material_free(struct nc_material *m)
{
    nc_albedo_map_free(m->albedo_map);
    m->albedo_map = NULL;
}

int nc_material_eval_deg(const struct nc_material *m, double i, double e, double g, double out[4])
{
    const double tol = 1e-6; /* deg: the rounding of a phase angle computed from vectors */
    if (!(i >= 0 && i <= 180) || !(e >= 0 && e <= 180) || !(g >= 0 && g <= 180))
        return nc_error(NC_ERANGE, "angles must be within 0..180 deg (got i = %g, e = %g, g = %g)", i, e, g);
    double gmin = fabs(i - e), gmax = fmin(i + e, 360.0 - i - e);
    if (g < gmin - tol || g > gmax + tol)
        return nc_error(NC_ERANGE,
                        "phase angle g = %.10g deg cannot occur with i = %.10g and e = %.10g (it must be within "
                        "%.10g..%.10g, give or take 1e-6 deg)",
                        g, i, e, gmin, gmax);
    out[0] = out[1] = out[2] = out[3] = 0.0;
    if (i >= 90 || e >= 90)
        return 0;
    const double d2r = M_PI / 180.0;
    struct nc_photometry geo = {cos(i * d2r), cos(e * d2r), cos(g * d2r), 1.0};
    double r;
    nc_material_eval(m, 1, &geo, &r);
    out[0] = r;
    out[1] = r / geo.mu0;
    out[2] = M_PI * r;
    out[3] = M_PI * r / geo.mu0;
    return 0;
}
