/* config.h - NavCam configuration tree: YAML files read with libyaml, plus
 * command-line overrides (--set a.b.c=VALUE), with typed readers.
 *
 * Every node remembers the file and line it came from, and whether a reader
 * consumed it, so that errors name file, line, key and what was expected, and
 * keys nobody read are reported as unknown. This module knows nothing about
 * scenes: it must not grow scene-specific logic.
 */
#ifndef NC_CONFIG_H
#define NC_CONFIG_H

#include <stddef.h>
#include <stdint.h>

#include "core/vec.h"

enum nc_cfg_kind { NC_CFG_SCALAR, NC_CFG_MAP, NC_CFG_SEQ };

struct nc_cfg_node {
    enum nc_cfg_kind kind;
    char *key;   /* key within the parent map, NULL for sequence items and root */
    char *value; /* scalar text; NULL otherwise */
    int quoted;  /* a scalar written in quotes (or as a block): never YAML's null */
    const char *origin; /* file name or "--set ..." (owned by struct nc_cfg) */
    int line;           /* 1-based; 0 when not from a file */
    int used;
    char **asked; /* a map: the keys readers asked of it, for the unknown-key message */
    size_t nasked;
    struct nc_cfg_node *parent;
    struct nc_cfg_node **child;
    size_t nchild;
};

struct nc_cfg {
    struct nc_cfg_node *root;
    char **origins;
    size_t norigins;
};

void nc_cfg_init(struct nc_cfg *cfg);
void nc_cfg_free(struct nc_cfg *cfg);
/* Load a whole document; it replaces what was loaded before. */
int nc_cfg_load_file(struct nc_cfg *cfg, const char *path);
int nc_cfg_load_string(struct nc_cfg *cfg, const char *text, const char *origin);
/* Apply "dotted.key=VALUE"; VALUE is YAML (a scalar or a flow list/map).
 * Sequence items are addressed by index: bodies.0.shape or bodies[0].shape. */
int nc_cfg_set(struct nc_cfg *cfg, const char *assignment);
/* Lay top over base: maps merge key by key, scalars and sequences replace.
 * top's nodes (with their file and line) move into base; top is freed. */
int nc_cfg_overlay(struct nc_cfg *base, struct nc_cfg *top);

/* Child of a map by key without marking it used (internal to config*.c). */
struct nc_cfg_node *nc__cfg_find(struct nc_cfg_node *map, const char *key);
/* --set's KEY (len bytes) as a dotted path in out ("a[0].b": "a.0.b"); an
 * error naming origin if it is none (an empty name, a stray bracket). */
int nc__cfg_key_path(const char *key, size_t len, char *out, size_t cap, const char *origin);
/* Whether a scalar is YAML's null (null, Null, NULL, ~ unquoted), which --set and a
 * file laid over another take as "leave this key out" (config.c). */
int nc__cfg_is_null(const struct nc_cfg_node *v);
/* ... or a key with nothing after it (an unquoted empty scalar: YAML's null in a file). */
int nc__cfg_is_null_or_empty(const struct nc_cfg_node *v);
/* Edit distance of two keys, two swapped neighbours counting one (config_read.c). */
size_t nc__cfg_edits(const char *a, const char *b);
/* The one of names[0..n-1] nearest key within a third of its letters'
 * edits (a typo; none for one- or two-letter keys), else NULL. */
const char *nc__cfg_nearest(const char *key, const char *const *names, size_t n);
/* Child of a map by key, or NULL. Marks it used. */
struct nc_cfg_node *nc_cfg_get(struct nc_cfg_node *map, const char *key);
/* Readers: return 1 when the key was present and valid, 0 when absent
 * (*out untouched), negative with a message when present but invalid. */
int nc_cfg_map(struct nc_cfg_node *parent, const char *key, struct nc_cfg_node **out);
int nc_cfg_seq(struct nc_cfg_node *parent, const char *key, struct nc_cfg_node **out);
int nc_cfg_double(struct nc_cfg_node *parent, const char *key, double min, double max, double *out);
int nc_cfg_int(struct nc_cfg_node *parent, const char *key, long min, long max, long *out);
/* A random seed: a whole number in [0, 2^31 - 1]. */
int nc_cfg_seed(struct nc_cfg_node *parent, const char *key, uint64_t *out);
int nc_cfg_string(struct nc_cfg_node *parent, const char *key, const char **out);
int nc_cfg_enum(struct nc_cfg_node *parent, const char *key, const char *const *names, int *out);
int nc_cfg_doubles(struct nc_cfg_node *parent, const char *key, double *out, size_t n);
int nc_cfg_vec3(struct nc_cfg_node *parent, const char *key, struct nc_vec3 *out);
/* nc_cfg_vec3 with a length of at most max, else the error "LENGTH WHAT,
 * beyond LIMIT" (what: "m from the scene's origin"; limit: "1e+15 m"). */
int nc_cfg_vec3_max(struct nc_cfg_node *parent, const char *key, double max, const char *what, const char *limit,
                    struct nc_vec3 *out);
/* A unit quaternion [w, x, y, z]; within 1e-3 of unit length it is normalised. */
int nc_cfg_quat(struct nc_cfg_node *parent, const char *key, struct nc_quat *out);

/* A file named by node n resolved against the directory of the config file
 * n came from (absolute paths, and nodes from strings or --set, unchanged). */
void nc_cfg_resolve_path(const struct nc_cfg_node *n, const char *file, char *out, size_t len);

/* Error helpers that prefix "origin:line: path:" for a node (or the place a
 * missing key should have been). */
int nc_cfg_error(const struct nc_cfg_node *node, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* The error about key of map, at the key's line when it is there, else at the
 * map's (a default that failed): "FILE:LINE: outputs[0].path: ..." either way. */
int nc_cfg_key_error(struct nc_cfg_node *map, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
int nc_cfg_missing(const struct nc_cfg_node *parent, const char *key, const char *expected);
/* map lacks every one of keys (NULL-terminated): the error msg on map, with
 * the key no reader took that most likely misspells one of them. */
int nc_cfg_missing_any(const struct nc_cfg_node *map, const char *const *keys, const char *msg);
/* Dotted path of a node, e.g. "bodies[0].shape.radius_m". */
void nc_cfg_path(const struct nc_cfg_node *node, char *buf, size_t len);
/* Where node came from and its path, as errors name it: "FILE:LINE: path",
 * or "--set ARG: path" for a value set on the command line (no line). */
void nc_cfg_where(const struct nc_cfg_node *node, char *buf, size_t len);
/* Mark a node and everything below it as consumed (sections a reader
 * deliberately ignores). */
void nc_cfg_mark_used(struct nc_cfg_node *node);
/* First node (depth-first, in file order) that no reader consumed: an error. */
int nc_cfg_check_unused(struct nc_cfg *cfg);
/* The same within node n (NULL: none), once its readers have run. */
int nc_cfg_check_unused_in(struct nc_cfg *cfg, struct nc_cfg_node *n);
/* The same for map's own keys alone, not what lies below them: a section no
 * reader takes, before the readers of the others have run. */
int nc_cfg_check_unused_keys(struct nc_cfg *cfg, struct nc_cfg_node *map);

#endif
