/* params.c - parameter tables: checking, reading and describing (params.h). */
#include "core/params.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

static const struct nc_param *find(const struct nc_param *table, const char *key)
{
    for (const struct nc_param *p = table; p && p->key; p++)
        if (!strcmp(p->key, key))
            return p;
    return NULL;
}

static void key_list(const struct nc_param *const *tables, int ntables, char *buf, size_t len)
{
    size_t pos = 0;
    buf[0] = '\0';
    for (int t = 0; t < ntables; t++)
        for (const struct nc_param *p = tables[t]; p && p->key && pos < len; p++)
            pos += (size_t)snprintf(buf + pos, len - pos, "%s%s", pos ? ", " : "", p->key);
}

int nc_params_check(const struct nc_cfg_node *map, const struct nc_param *const *tables, int ntables, const char *what)
{
    if (!map)
        return 0;
    if (map->kind != NC_CFG_MAP)
        return nc_cfg_error(map, "expected a map of keys for %s", what);
    for (size_t i = 0; i < map->nchild; i++) {
        const struct nc_cfg_node *c = map->child[i];
        const struct nc_param *p = NULL;
        for (int t = 0; t < ntables && !p; t++)
            p = find(tables[t], c->key);
        if (!p) { /* the nearest key within a third of its letters' edits, as for any section */
            char keys[512], hint[96] = "";
            key_list(tables, ntables, keys, sizeof keys);
            const char *names[64];
            size_t n = 0;
            for (int t = 0; t < ntables; t++)
                for (const struct nc_param *q = tables[t]; q && q->key && n < 64; q++)
                    names[n++] = q->key;
            const char *best = nc__cfg_nearest(c->key, names, n);
            if (best)
                snprintf(hint, sizeof hint, "; did you mean '%s'?", best);
            return nc_cfg_error(c, "unknown key for %s%s (it takes: %s)", what, hint, keys);
        }
        if (p->type == NC_PARAM_MAP && c->kind == NC_CFG_MAP) {
            const struct nc_param *sub[1] = {p->sub};
            int rc = nc_params_check(c, sub, 1, what);
            if (rc < 0)
                return rc;
        }
    }
    return 0;
}

/* The table entry of key with the expected type; a mismatch is a
 * programming error in the caller, reported as such. */
static const struct nc_param *entry(const struct nc_param *table, const char *key, enum nc_param_type type, int *rc)
{
    const struct nc_param *p = find(table, key);
    if (!p || p->type != type) {
        *rc = nc_error(NC_EUNSUPPORTED, "internal: parameter '%s' is not in the table as read", key);
        return NULL;
    }
    *rc = 0;
    return p;
}

int nc_param_bool(struct nc_cfg_node *map, const struct nc_param *table, const char *key, int *out)
{
    static const char *const names[] = {"false", "true", NULL};
    int rc;
    const struct nc_param *p = entry(table, key, NC_PARAM_BOOL, &rc);
    if (!p)
        return rc;
    if (p->def)
        *out = !strcmp(p->def, "true");
    return nc_cfg_enum(map, key, names, out);
}

int nc_param_int(struct nc_cfg_node *map, const struct nc_param *table, const char *key, long *out)
{
    int rc;
    const struct nc_param *p = entry(table, key, NC_PARAM_INT, &rc);
    if (!p)
        return rc;
    if (p->def)
        *out = strtol(p->def, NULL, 10);
    return nc_cfg_int(map, key, (long)p->min, (long)p->max, out);
}

int nc_param_double(struct nc_cfg_node *map, const struct nc_param *table, const char *key, double *out)
{
    int rc;
    const struct nc_param *p = entry(table, key, NC_PARAM_DOUBLE, &rc);
    if (!p)
        return rc;
    if (p->def)
        *out = strtod(p->def, NULL);
    return nc_cfg_double(map, key, p->min, p->max, out);
}

int nc_param_string(struct nc_cfg_node *map, const struct nc_param *table, const char *key, const char **out)
{
    int rc;
    const struct nc_param *p = entry(table, key, NC_PARAM_STRING, &rc);
    if (!p)
        return rc;
    if (p->def)
        *out = p->def;
    struct nc_cfg_node *n = nc_cfg_get(map, key);
    if (!n && (p->flags & NC_PARAM_REQUIRED))
        return nc_cfg_missing(map, key, p->doc);
    if (n && (p->flags & NC_PARAM_EMPTY_OK) && n->kind == NC_CFG_SCALAR && !n->value[0]) {
        *out = n->value;
        return 1;
    }
    char why[256];
    if ((rc = nc_cfg_string(map, key, out)) > 0 && p->check && p->check(*out, why, sizeof why) < 0)
        return nc_cfg_key_error(map, key, "%s", why);
    return rc;
}

int nc_param_enum(struct nc_cfg_node *map, const struct nc_param *table, const char *key, int *out)
{
    int rc;
    const struct nc_param *p = entry(table, key, NC_PARAM_ENUM, &rc);
    if (!p)
        return rc;
    for (int i = 0; p->def && p->names[i]; i++)
        if (!strcmp(p->names[i], p->def))
            *out = i;
    return nc_cfg_enum(map, key, p->names, out);
}

int nc_param_map(struct nc_cfg_node *map, const struct nc_param *table, const char *key, struct nc_cfg_node **out)
{
    int rc;
    const struct nc_param *p = entry(table, key, NC_PARAM_MAP, &rc);
    if (!p)
        return rc;
    *out = NULL;
    return nc_cfg_map(map, key, out);
}

int nc_params_values(struct nc_cfg_node *map, const struct nc_param *const *tables, int ntables)
{
    if (map && map->kind != NC_CFG_MAP)
        return 0;
    int rc = 0;
    for (size_t i = 0; map && i < map->nchild && rc >= 0; i++) {
        const char *key = map->child[i]->key;
        const struct nc_param *t = NULL, *p = NULL;
        for (int k = 0; k < ntables && !p; k++)
            if ((p = find(tables[k], key)))
                t = tables[k];
        if (!p)
            continue;
        int b;
        long l;
        double d;
        const char *str;
        struct nc_cfg_node *sub;
        switch (p->type) {
        case NC_PARAM_BOOL: rc = nc_param_bool(map, t, key, &b); break;
        case NC_PARAM_INT: rc = nc_param_int(map, t, key, &l); break;
        case NC_PARAM_DOUBLE: rc = nc_param_double(map, t, key, &d); break;
        case NC_PARAM_STRING: rc = nc_param_string(map, t, key, &str); break;
        case NC_PARAM_ENUM: rc = nc_param_enum(map, t, key, &b); break;
        case NC_PARAM_MAP: {
            const struct nc_param *inner[1] = {p->sub};
            if ((rc = nc_param_map(map, t, key, &sub)) >= 0)
                rc = nc_params_values(sub, inner, 1);
            break;
        }
        }
    }
    for (int k = 0; k < ntables && rc >= 0; k++) /* the keys that must be given */
        for (const struct nc_param *p = tables[k]; p->key && rc >= 0; p++)
            if ((p->flags & NC_PARAM_REQUIRED) && !(map && nc__cfg_find(map, p->key))) /* map NULL: none given */
                rc = nc_cfg_missing(map, p->key, p->doc);
    return rc < 0 ? rc : 0;
}

/* "[default] range unit" of an entry. */
static void describe(const struct nc_param *p, char *buf, size_t len)
{
    size_t pos = 0;
    if (p->def)
        pos += (size_t)snprintf(buf + pos, len - pos, "default %s; ", p->def);
    else if (p->flags & NC_PARAM_REQUIRED)
        pos += (size_t)snprintf(buf + pos, len - pos, "required; ");
    switch (p->type) {
    case NC_PARAM_BOOL: snprintf(buf + pos, len - pos, "true or false"); break;
    case NC_PARAM_INT: snprintf(buf + pos, len - pos, "whole number %.0f..%.0f", p->min, p->max); break;
    case NC_PARAM_DOUBLE: snprintf(buf + pos, len - pos, "%g..%g", p->min, p->max); break;
    case NC_PARAM_STRING: snprintf(buf + pos, len - pos, "text"); break;
    case NC_PARAM_MAP: snprintf(buf + pos, len - pos, "a map"); break;
    case NC_PARAM_ENUM:
        for (int i = 0; p->names[i] && pos < len; i++)
            pos += (size_t)snprintf(buf + pos, len - pos, "%s%s", i ? " | " : "", p->names[i]);
        break;
    }
}

static void help_rows(FILE *f, const struct nc_param *table, int indent, const char *prefix)
{
    for (const struct nc_param *p = table; p && p->key; p++) {
        char key[160], what[256];
        snprintf(key, sizeof key, "%s%s", prefix, p->key);
        describe(p, what, sizeof what);
        fprintf(f, "%*s%-22s %s%s%s: %s\n", indent, "", key, what, p->unit && p->unit[0] ? " " : "",
                p->unit ? p->unit : "", p->doc);
        if (p->type == NC_PARAM_MAP) {
            char sub[176];
            snprintf(sub, sizeof sub, "%s.", key);
            help_rows(f, p->sub, indent, sub);
        }
    }
}

void nc_params_print_help(FILE *f, const struct nc_param *table, int indent) { help_rows(f, table, indent, ""); }

static const char *const type_names[] = {"bool", "int", "number", "text", "enum", "map"};

static void md_rows(FILE *f, const struct nc_param *table, const char *prefix)
{
    for (const struct nc_param *p = table; p && p->key; p++) {
        char key[160], range[256] = "";
        snprintf(key, sizeof key, "%s%s", prefix, p->key);
        if (p->type == NC_PARAM_INT || p->type == NC_PARAM_DOUBLE)
            snprintf(range, sizeof range, "%g .. %g", p->min, p->max);
        else if (p->type == NC_PARAM_ENUM)
            for (size_t i = 0, pos = 0; p->names[i] && pos < sizeof range; i++)
                pos += (size_t)snprintf(range + pos, sizeof range - pos, "%s`%s`", i ? ", " : "", p->names[i]);
        fprintf(f, "| `%s` | %s | %s%s%s | %s | %s | %s |\n", key, type_names[p->type], p->def ? "`" : "",
                p->def ? p->def : (p->flags & NC_PARAM_REQUIRED) ? "(required)" : "", p->def ? "`" : "", range,
                p->unit ? p->unit : "", p->doc);
        if (p->type == NC_PARAM_MAP) {
            char sub[176];
            snprintf(sub, sizeof sub, "%s.", key);
            md_rows(f, p->sub, sub);
        }
    }
}

void nc_params_print_markdown(FILE *f, const struct nc_param *table)
{
    fputs("| key | type | default | range | unit | meaning |\n|---|---|---|---|---|---|\n", f);
    md_rows(f, table, "");
}
