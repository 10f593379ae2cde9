/* config.c - the configuration tree: libyaml documents -> nodes with origins,
 * dotted-path overrides, typed readers and the unknown-key check. */
#include "core/config.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <yaml.h>

#include "core/error.h"

static void node_free(struct nc_cfg_node *n)
{
    if (!n)
        return;
    for (size_t i = 0; i < n->nchild; i++)
        node_free(n->child[i]);
    free(n->child);
    for (size_t i = 0; i < n->nasked; i++)
        free(n->asked[i]);
    free(n->asked);
    free(n->key);
    free(n->value);
    free(n);
}

static struct nc_cfg_node *node_new(enum nc_cfg_kind kind, const char *origin, int line)
{
    struct nc_cfg_node *n = calloc(1, sizeof *n);
    if (n) {
        n->kind = kind;
        n->origin = origin;
        n->line = line;
    }
    return n;
}

static int node_append(struct nc_cfg_node *parent, struct nc_cfg_node *child)
{
    struct nc_cfg_node **c = realloc(parent->child, (parent->nchild + 1) * sizeof *c);
    if (!c)
        return -ENOMEM;
    parent->child = c;
    c[parent->nchild++] = child;
    child->parent = parent;
    return 0;
}

void nc_cfg_init(struct nc_cfg *cfg) { memset(cfg, 0, sizeof *cfg); }

void nc_cfg_free(struct nc_cfg *cfg)
{
    node_free(cfg->root);
    for (size_t i = 0; i < cfg->norigins; i++)
        free(cfg->origins[i]);
    free(cfg->origins);
    memset(cfg, 0, sizeof *cfg);
}

static const char *intern_origin(struct nc_cfg *cfg, const char *origin)
{
    char **o = realloc(cfg->origins, (cfg->norigins + 1) * sizeof *o);
    if (!o)
        return NULL;
    cfg->origins = o;
    o[cfg->norigins] = strdup(origin);
    return o[cfg->norigins] ? o[cfg->norigins++] : NULL;
}

void nc_cfg_path(const struct nc_cfg_node *node, char *buf, size_t len)
{
    const struct nc_cfg_node *chain[64];
    size_t depth = 0;
    for (const struct nc_cfg_node *n = node; n && n->parent && depth < 64; n = n->parent)
        chain[depth++] = n;
    size_t pos = 0;
    buf[0] = '\0';
    while (depth-- > 0 && pos < len) {
        const struct nc_cfg_node *n = chain[depth];
        int w;
        if (n->key)
            w = snprintf(buf + pos, len - pos, "%s%s", pos ? "." : "", n->key);
        else {
            size_t idx = 0;
            while (n->parent->child[idx] != n)
                idx++;
            w = snprintf(buf + pos, len - pos, "[%zu]", idx);
        }
        if (w < 0)
            break;
        pos += (size_t)w;
    }
    if (pos == 0)
        snprintf(buf, len, "(top level)");
}

void nc_cfg_where(const struct nc_cfg_node *node, char *buf, size_t len)
{
    char path[256];
    nc_cfg_path(node, path, sizeof path);
    const char *origin = node->origin ? node->origin : "config";
    if (node->line > 0)
        snprintf(buf, len, "%s:%d: %s", origin, node->line, path);
    else
        snprintf(buf, len, "%s: %s", origin, path);
}

/* ---- loading ---------------------------------------------------------- */

/* The most values a configuration may expand to: a YAML alias repeats a
 * subtree, and aliases of aliases grow it ninefold a level (a file of a few
 * lines would take gigabytes). */
#define NC_CFG_MAX_VALUES 200000

/* ":LINE" of a text with lines (a file), "" for one without (a --set value) */
static const char *at_line(char buf[16], int line)
{
    if (line > 0)
        snprintf(buf, 16, ":%d", line);
    else
        buf[0] = '\0';
    return buf;
}

/* A YAML node of a text with lines (with_line) or of a --set value. */
static int convert(struct nc_cfg *cfg, yaml_document_t *doc, yaml_node_t *yn, const char *origin, int with_line,
                   int depth, long *left, struct nc_cfg_node **out)
{
    int line = with_line ? (int)yn->start_mark.line + 1 : 0;
    char at[16];
    if (depth > 32)
        return nc_error(NC_ECONFIG, "%s%s: nesting deeper than 32 levels", origin, at_line(at, line));
    if (--*left < 0)
        return nc_error(NC_ECONFIG, "%s%s: the configuration expands to more than %d values (YAML aliases that "
                        "repeat large parts?)", origin, at_line(at, line), NC_CFG_MAX_VALUES);
    struct nc_cfg_node *n = NULL;
    int rc = 0;
    switch (yn->type) {
    case YAML_SCALAR_NODE:
        n = node_new(NC_CFG_SCALAR, origin, line);
        if (!n || !(n->value = strndup((const char *)yn->data.scalar.value, yn->data.scalar.length)))
            goto nomem;
        n->quoted = yn->data.scalar.style != YAML_PLAIN_SCALAR_STYLE;
        break;
    case YAML_SEQUENCE_NODE:
        n = node_new(NC_CFG_SEQ, origin, line);
        if (!n)
            goto nomem;
        for (yaml_node_item_t *it = yn->data.sequence.items.start; it < yn->data.sequence.items.top; it++) {
            struct nc_cfg_node *c;
            if ((rc = convert(cfg, doc, yaml_document_get_node(doc, *it), origin, with_line, depth + 1, left, &c)) < 0)
                goto fail;
            if ((rc = node_append(n, c)) < 0) {
                node_free(c);
                goto nomem;
            }
        }
        break;
    case YAML_MAPPING_NODE:
        n = node_new(NC_CFG_MAP, origin, line);
        if (!n)
            goto nomem;
        for (yaml_node_pair_t *p = yn->data.mapping.pairs.start; p < yn->data.mapping.pairs.top; p++) {
            yaml_node_t *k = yaml_document_get_node(doc, p->key);
            int kline = with_line ? (int)k->start_mark.line + 1 : 0;
            if (k->type != YAML_SCALAR_NODE) {
                rc = nc_error(NC_ECONFIG, "%s%s: map keys must be plain words", origin, at_line(at, kline));
                goto fail;
            }
            const char *ks = (const char *)k->data.scalar.value;
            for (size_t i = 0; i < n->nchild; i++) {
                if (strcmp(n->child[i]->key, ks) == 0) {
                    char path[256];
                    nc_cfg_path(n->child[i], path, sizeof path);
                    rc = with_line ? nc_error(NC_ECONFIG, "%s:%d: key '%s' appears twice in the same map (first at "
                                              "line %d)", origin, kline, ks, n->child[i]->line)
                                   : nc_error(NC_ECONFIG, "%s: key '%s' appears twice in the same map", origin, ks);
                    goto fail;
                }
            }
            struct nc_cfg_node *c;
            if ((rc = convert(cfg, doc, yaml_document_get_node(doc, p->value), origin, with_line, depth + 1, left,
                              &c)) < 0)
                goto fail;
            c->line = kline;
            if (!(c->key = strdup(ks)) || node_append(n, c) < 0) {
                node_free(c);
                goto nomem;
            }
        }
        break;
    default:
        rc = nc_error(NC_ECONFIG, "%s%s: empty YAML node", origin, at_line(at, line));
        goto fail;
    }
    *out = n;
    return 0;
nomem:
    rc = nc_error(-ENOMEM, "%s: out of memory", origin);
fail:
    node_free(n);
    return rc;
}

/* Whether text nests deeper than convert() takes, found from the parser's
 * events before the document is loaded: libyaml's scanner takes time
 * quadratic in the nesting (100 000 brackets: half a minute), so it is
 * stopped at the first level too deep. 0 also for a syntax error (the
 * loader reports it). */
static int too_deep(const char *text, size_t len, const char *origin, int with_line)
{
    char at[16];
    yaml_parser_t parser;
    if (!yaml_parser_initialize(&parser))
        return 0;
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
    int depth = 0, rc = 0, done = 0;
    while (!done && !rc) {
        yaml_event_t ev;
        if (!yaml_parser_parse(&parser, &ev))
            break;
        if ((ev.type == YAML_SEQUENCE_START_EVENT || ev.type == YAML_MAPPING_START_EVENT) && ++depth > 33)
            rc = nc_error(NC_ECONFIG, "%s%s: nesting deeper than 32 levels", origin,
                          at_line(at, with_line ? (int)ev.start_mark.line + 1 : 0));
        depth -= ev.type == YAML_SEQUENCE_END_EVENT || ev.type == YAML_MAPPING_END_EVENT;
        done = ev.type == YAML_STREAM_END_EVENT;
        yaml_event_delete(&ev);
    }
    yaml_parser_delete(&parser);
    return rc;
}

/* The parser's syntax error, with its line; after: it came after the
 * first document. */
static int syntax_error(const yaml_parser_t *parser, const char *origin, int with_line, int after)
{
    char at[16];
    return nc_error(NC_ECONFIG, "%s%s: YAML syntax error: %s%s%s%s", origin,
                    at_line(at, with_line ? (int)parser->problem_mark.line + 1 : 0),
                    parser->problem ? parser->problem : "unknown", parser->context ? " " : "",
                    parser->context ? parser->context : "",
                    after ? " (text after the end of the value: one value, one document)" : "");
}

/* Parse one YAML document from memory into a node tree. */
static int parse_yaml(struct nc_cfg *cfg, const char *text, size_t len, const char *origin, int with_line,
                      struct nc_cfg_node **out)
{
    yaml_parser_t parser;
    yaml_document_t doc;
    int rc = too_deep(text, len, origin, with_line);
    if (rc < 0)
        return rc;
    if (!yaml_parser_initialize(&parser))
        return nc_error(-ENOMEM, "%s: cannot initialise the YAML parser", origin);
    yaml_parser_set_input_string(&parser, (const unsigned char *)text, len);
    if (!yaml_parser_load(&parser, &doc)) {
        rc = syntax_error(&parser, origin, with_line, 0);
        yaml_parser_delete(&parser);
        return rc;
    }
    yaml_node_t *root = yaml_document_get_root_node(&doc);
    long left = NC_CFG_MAX_VALUES;
    if (!root)
        *out = NULL;
    else
        rc = convert(cfg, &doc, root, origin, with_line, 0, &left, out);
    yaml_document_delete(&doc);
    /* One document: a second one ('---', after a '...' or not) would be
     * dropped unseen, its keys neither read nor refused; so would text that
     * does not parse after the first (`[1, 2] [3]`, `{a: 1}]`, keys after
     * a '...'). */
    yaml_document_t more;
    if (rc >= 0 && !yaml_parser_load(&parser, &more)) {
        rc = syntax_error(&parser, origin, with_line, 1);
        node_free(*out);
        *out = NULL;
    } else if (rc >= 0) { /* (also after an empty first one) */
        yaml_node_t *r2 = yaml_document_get_root_node(&more);
        if (r2) {
            char at[16];
            rc = nc_error(NC_ECONFIG, "%s%s: a second YAML document ('---'): one document a file (merge its keys "
                          "into the first)", origin, at_line(at, with_line ? (int)r2->start_mark.line + 1 : 0));
            node_free(*out);
            *out = NULL;
        }
        yaml_document_delete(&more);
    }
    yaml_parser_delete(&parser);
    return rc;
}

int nc_cfg_load_string(struct nc_cfg *cfg, const char *text, const char *origin)
{
    const char *o = intern_origin(cfg, origin);
    if (!o)
        return nc_error(-ENOMEM, "out of memory");
    struct nc_cfg_node *root = NULL;
    int rc = parse_yaml(cfg, text, strlen(text), o, 1, &root);
    if (rc < 0)
        return rc;
    if (!root)
        root = node_new(NC_CFG_MAP, o, 1);
    if (!root)
        return nc_error(-ENOMEM, "out of memory");
    if (root->kind != NC_CFG_MAP) {
        node_free(root);
        return nc_error(NC_ECONFIG, "%s:1: the top level must be a map of keys (e.g. 'camera:')", o);
    }
    node_free(cfg->root);
    cfg->root = root;
    return 0;
}

/* ---- overrides -------------------------------------------------------- */

struct nc_cfg_node *nc__cfg_find(struct nc_cfg_node *map, const char *key)
{
    for (size_t i = 0; i < map->nchild; i++)
        if (strcmp(map->child[i]->key, key) == 0)
            return map->child[i];
    return NULL;
}

static void set_origin(struct nc_cfg_node *n, const char *origin)
{
    n->origin = origin;
    n->line = 0;
    for (size_t i = 0; i < n->nchild; i++)
        set_origin(n->child[i], origin);
}

/* Move top's node n over base's node b: maps merge key by key, anything
 * else replaces. Moved nodes are taken out of top. */
/* Child c (NULL: none) out of parent, freed; the others keep their order. */
static void node_remove(struct nc_cfg_node *parent, struct nc_cfg_node *c)
{
    if (!c)
        return;
    size_t k = 0;
    for (size_t i = 0; i < parent->nchild; i++)
        if (parent->child[i] != c)
            parent->child[k++] = parent->child[i];
    parent->nchild = k;
    node_free(c);
}

int nc__cfg_is_null(const struct nc_cfg_node *v)
{
    return v->kind == NC_CFG_SCALAR && v->value && !v->quoted &&
           (!strcmp(v->value, "null") || !strcmp(v->value, "Null") || !strcmp(v->value, "NULL") ||
            !strcmp(v->value, "~"));
}

int nc__cfg_is_null_or_empty(const struct nc_cfg_node *v)
{
    return nc__cfg_is_null(v) || (v->kind == NC_CFG_SCALAR && v->value && !v->value[0] && !v->quoted);
}

static int overlay_node(struct nc_cfg_node *b, struct nc_cfg_node *n)
{
    for (size_t i = 0; i < n->nchild; i++) {
        struct nc_cfg_node *c = n->child[i], *old = nc__cfg_find(b, c->key);
        if (old && old->kind == NC_CFG_MAP && c->kind == NC_CFG_MAP) {
            int rc = overlay_node(old, c);
            if (rc < 0)
                return rc;
            continue;
        }
        /* key: null (~, or nothing after the colon: YAML's null too) takes the base's key out */
        if (nc__cfg_is_null_or_empty(c)) {
            node_remove(b, old);
            continue;
        }
        if (old) { /* replace in place, keeping the base's key order */
            size_t k = 0;
            while (b->child[k] != old)
                k++;
            node_free(old);
            b->child[k] = c;
            c->parent = b;
        } else if (node_append(b, c) < 0) {
            return -ENOMEM;
        }
        n->child[i] = NULL;
    }
    return 0;
}

int nc_cfg_overlay(struct nc_cfg *base, struct nc_cfg *top)
{
    if (!top->root)
        return 0;
    if (!base->root || base->root->kind != NC_CFG_MAP || top->root->kind != NC_CFG_MAP)
        return nc_error(NC_ECONFIG, "configuration overlay: both documents must be maps");
    /* The origins move with their nodes. */
    char **o = realloc(base->origins, (base->norigins + top->norigins) * sizeof *o);
    if (!o)
        return nc_error(-ENOMEM, "out of memory");
    base->origins = o;
    memcpy(o + base->norigins, top->origins, top->norigins * sizeof *o);
    base->norigins += top->norigins;
    free(top->origins);
    top->origins = NULL;
    top->norigins = 0;
    int rc = overlay_node(base->root, top->root);
    nc_cfg_free(top); /* what was not moved (emptied maps) */
    return rc < 0 ? nc_error(rc, "out of memory") : 0;
}

int nc_cfg_set(struct nc_cfg *cfg, const char *assignment)
{
    char origin_buf[300];
    snprintf(origin_buf, sizeof origin_buf, "--set %s", assignment);
    const char *origin = intern_origin(cfg, origin_buf);
    if (!origin)
        return nc_error(-ENOMEM, "out of memory");
    const char *eq = strchr(assignment, '=');
    if (!eq || eq == assignment)
        return nc_error(NC_EUSAGE, "%s: expected KEY=VALUE, e.g. --set camera.position_m=[0,0,-5000]", origin);
    if (!cfg->root && !(cfg->root = node_new(NC_CFG_MAP, origin, 0)))
        return nc_error(-ENOMEM, "out of memory");

    struct nc_cfg_node *value = NULL;
    int rc = parse_yaml(cfg, eq + 1, strlen(eq + 1), origin, 0, &value);
    if (rc < 0)
        return rc;
    if (!value && !(value = node_new(NC_CFG_SCALAR, origin, 0)))
        return nc_error(-ENOMEM, "out of memory");
    if (!value->value && value->kind == NC_CFG_SCALAR && !(value->value = strdup("")))
        return nc_error(-ENOMEM, "out of memory");
    set_origin(value, origin);

    /* Walk the dotted path, creating maps as needed. "a[0]" == "a.0". */
    char path[256];
    if ((rc = nc__cfg_key_path(assignment, (size_t)(eq - assignment), path, sizeof path, origin)) < 0) {
        node_free(value);
        return rc;
    }
    struct nc_cfg_node *cur = cfg->root;
    char *save = NULL;
    char *tok = strtok_r(path, ".", &save);
    while (tok) {
        char *next = strtok_r(NULL, ".", &save);
        struct nc_cfg_node *child = NULL;
        size_t idx = 0;
        if (cur->kind == NC_CFG_SEQ) {
            char *end;
            errno = 0;
            unsigned long v = strtoul(tok, &end, 10);
            if (*end || errno || v > cur->nchild) {
                node_free(value);
                return nc_error(NC_EUSAGE, "%s: '%s' is not an index of a list with %zu items", origin, tok, cur->nchild);
            }
            idx = v;
            child = idx < cur->nchild ? cur->child[idx] : NULL;
        } else if (cur->kind == NC_CFG_MAP) {
            child = nc__cfg_find(cur, tok);
        } else {
            node_free(value);
            return nc_error(NC_EUSAGE, "%s: cannot descend into '%s': its parent is a single value", origin, tok);
        }
        if (!next && nc__cfg_is_null(value)) { /* KEY=null: the key (or list item) taken out */
            node_free(value);
            node_remove(cur, child);
            return 0;
        }
        if (!next) {
            if (child) {
                /* Replace in place, keeping the position and key. */
                value->key = child->key;
                child->key = NULL;
                value->parent = cur;
                for (size_t i = 0; i < cur->nchild; i++)
                    if (cur->child[i] == child)
                        cur->child[i] = value;
                node_free(child);
                return 0;
            }
            if (cur->kind == NC_CFG_MAP && !(value->key = strdup(tok))) {
                node_free(value);
                return nc_error(-ENOMEM, "out of memory");
            }
            if (node_append(cur, value) < 0) {
                node_free(value);
                return nc_error(-ENOMEM, "out of memory");
            }
            return 0;
        }
        if (!child && nc__cfg_is_null(value)) { /* nothing to take out: no parents made for it */
            node_free(value);
            return 0;
        }
        if (!child) {
            child = node_new(NC_CFG_MAP, origin, 0);
            if (!child || (cur->kind == NC_CFG_MAP && !(child->key = strdup(tok))) || node_append(cur, child) < 0) {
                node_free(child);
                node_free(value);
                return nc_error(-ENOMEM, "out of memory");
            }
        }
        cur = child;
        tok = next;
    }
    node_free(value);
    return nc_error(NC_EUSAGE, "%s: empty key path", origin);
}
