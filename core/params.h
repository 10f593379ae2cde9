/* params.h - parameter tables: what a configurable part (a driver, later any
 * module) takes, in one constant array of {key, type, default, range, unit,
 * description}. The table is the single source of truth: the part reads its
 * options through it (defaults and ranges are never written twice), unknown
 * keys are rejected with file and line before any hardware is touched, and
 * `--help` text and the docs' tables are printed from it.
 * Knows the configuration tree (config.h), nothing about drivers.
 */
#ifndef NC_PARAMS_H
#define NC_PARAMS_H

#include <stdio.h>

#include "core/config.h"

enum nc_param_type {
    NC_PARAM_BOOL,   /* true/false */
    NC_PARAM_INT,    /* whole number in [min, max] */
    NC_PARAM_DOUBLE, /* finite number in [min, max] */
    NC_PARAM_STRING, /* non-empty text */
    NC_PARAM_ENUM,   /* one of names[] */
    NC_PARAM_MAP,    /* a nested map whose keys are the table sub[] */
};

struct nc_param {
    const char *key;
    enum nc_param_type type;
    const char *def;           /* the default as written in a config; NULL: none (optional, or see doc) */
    double min, max;           /* INT and DOUBLE */
    const char *unit;          /* SI unit, "" for none */
    const char *const *names;  /* ENUM: NULL-terminated */
    const struct nc_param *sub;/* MAP: its table */
    const char *doc;           /* one sentence */
    unsigned flags;            /* NC_PARAM_EMPTY_OK, NC_PARAM_REQUIRED */
    /* STRING: the form a value must have (NULL: any), checked with the table's other checks, before any part is
     * opened: < 0 with a reason in why when value is not of it. */
    int (*check)(const char *value, char *why, size_t len);
};
enum {
    NC_PARAM_EMPTY_OK = 1u << 0, /* STRING: an empty value is allowed (it means "none") */
    NC_PARAM_REQUIRED = 1u << 1, /* STRING: the key must be given (no default) */
};
/* Table rows, one macro per type; a table ends with NC_P_END. */
#define NC_P_DOUBLE(k, d, lo, hi, u, text) \
    {.key = (k), .type = NC_PARAM_DOUBLE, .def = (d), .min = (lo), .max = (hi), .unit = (u), .doc = (text)}
#define NC_P_INT(k, d, lo, hi, u, text) \
    {.key = (k), .type = NC_PARAM_INT, .def = (d), .min = (lo), .max = (hi), .unit = (u), .doc = (text)}
#define NC_P_STRING(k, d, text) {.key = (k), .type = NC_PARAM_STRING, .def = (d), .unit = "", .doc = (text)}
#define NC_P_STRING_OR_EMPTY(k, d, text) \
    {.key = (k), .type = NC_PARAM_STRING, .def = (d), .unit = "", .doc = (text), .flags = NC_PARAM_EMPTY_OK}
#define NC_P_STRING_REQUIRED(k, text) \
    {.key = (k), .type = NC_PARAM_STRING, .unit = "", .doc = (text), .flags = NC_PARAM_REQUIRED}
#define NC_P_STRING_CHECKED(k, d, fn, text) \
    {.key = (k), .type = NC_PARAM_STRING, .def = (d), .unit = "", .doc = (text), .check = (fn)}
#define NC_P_ENUM(k, d, list, text) {.key = (k), .type = NC_PARAM_ENUM, .def = (d), .unit = "", .names = (list), .doc = (text)}
#define NC_P_BOOL(k, d, text) {.key = (k), .type = NC_PARAM_BOOL, .def = (d), .unit = "", .doc = (text)}
#define NC_P_MAP(k, table, text) {.key = (k), .type = NC_PARAM_MAP, .unit = "", .sub = (table), .doc = (text)}
#define NC_P_END {.key = NULL}

/* Rejects a key of map that none of the tables names (recursing into MAP
 * entries): "file:line: outputs[0].pixel_fromat: unknown key for <what>
 * (it takes: ...)". Reads nothing, marks nothing. */
int nc_params_check(const struct nc_cfg_node *map, const struct nc_param *const *tables, int ntables, const char *what);

/* Every configured key of map read through its table entry (type, range,
 * names, form; recursing into MAP entries), as the part will read it, and
 * every required key present: so a part's options can be checked whole
 * before it is opened. Keys no table names are left to nc_params_check. */
int nc_params_values(struct nc_cfg_node *map, const struct nc_param *const *tables, int ntables);

/* Typed readers through a table entry: *out gets the table's default (when
 * it has one), then the configured value checked against the table's range.
 * map may be NULL (everything at its default). Return 1 when the key was
 * configured, 0 when not, negative with a message naming file:line:key. */
int nc_param_bool(struct nc_cfg_node *map, const struct nc_param *table, const char *key, int *out);
int nc_param_int(struct nc_cfg_node *map, const struct nc_param *table, const char *key, long *out);
int nc_param_double(struct nc_cfg_node *map, const struct nc_param *table, const char *key, double *out);
int nc_param_string(struct nc_cfg_node *map, const struct nc_param *table, const char *key, const char **out);
int nc_param_enum(struct nc_cfg_node *map, const struct nc_param *table, const char *key, int *out);
/* A MAP entry: *out is the node (NULL when absent; a map has no default);
 * its keys are read with the entry's own table (struct nc_param.sub). */
int nc_param_map(struct nc_cfg_node *map, const struct nc_param *table, const char *key, struct nc_cfg_node **out);

/* The table as help text: one line a key, "  key  [default] range unit: doc",
 * nested maps as "strobe.line". indent: leading spaces. */
void nc_params_print_help(FILE *f, const struct nc_param *table, int indent);
/* The table as a Markdown table (docs/drivers.md is made of these). */
void nc_params_print_markdown(FILE *f, const struct nc_param *table);

#endif
