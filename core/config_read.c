/* config_read.c - the typed readers of the configuration tree (config.h):
 * each checks kind, syntax and range and names file, line and key on error,
 * and marks what it read, so unread keys can be reported as unknown; the
 * errors themselves, with the likely misspelling of a missing key. */
#include "core/config.h"

#include <errno.h>
#include <libgen.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"
#include "core/lines.h"

/* ---- readers ---------------------------------------------------------- */

/* key, remembered as one map's readers asked for it (once; a failure to
 * allocate only leaves the unknown-key message shorter). */
static void note_asked(struct nc_cfg_node *map, const char *key)
{
    for (size_t i = 0; i < map->nasked; i++)
        if (!strcmp(map->asked[i], key))
            return;
    char **a = realloc(map->asked, (map->nasked + 1) * sizeof *a), *k = strdup(key);
    if (a)
        map->asked = a;
    if (a && k)
        a[map->nasked++] = k;
    else
        free(k);
}

struct nc_cfg_node *nc_cfg_get(struct nc_cfg_node *map, const char *key)
{
    if (!map || map->kind != NC_CFG_MAP)
        return NULL;
    note_asked(map, key);
    struct nc_cfg_node *n = nc__cfg_find(map, key);
    if (n)
        n->used = 1;
    return n;
}

static const char *kind_name(enum nc_cfg_kind k)
{
    return k == NC_CFG_MAP ? "a map" : k == NC_CFG_SEQ ? "a list" : "a single value";
}

int nc_cfg_map(struct nc_cfg_node *parent, const char *key, struct nc_cfg_node **out)
{
    struct nc_cfg_node *n = nc_cfg_get(parent, key);
    if (!n)
        return 0;
    if (n->kind != NC_CFG_MAP)
        return nc_cfg_error(n, "expected a map of keys, got %s", kind_name(n->kind));
    *out = n;
    return 1;
}

int nc_cfg_seq(struct nc_cfg_node *parent, const char *key, struct nc_cfg_node **out)
{
    struct nc_cfg_node *n = nc_cfg_get(parent, key);
    if (!n)
        return 0;
    if (n->kind != NC_CFG_SEQ)
        return nc_cfg_error(n, "expected a list, got %s", kind_name(n->kind));
    *out = n;
    return 1;
}

static int scalar_double(struct nc_cfg_node *n, double *out)
{
    if (n->kind != NC_CFG_SCALAR)
        return nc_cfg_error(n, "expected a number, got %s", kind_name(n->kind));
    char *end;
    errno = 0;
    /* YAML spells non-finite floats .nan and .inf: name them as such. */
    const char *t = n->value + (n->value[0] == '-' || n->value[0] == '+');
    if (!strcasecmp(t, ".nan") || !strcasecmp(t, ".inf"))
        return nc_cfg_error(n, "expected a finite number, got \"%s\"", n->value);
    double v = nc_strtod_decimal(n->value, &end); /* not 0x1p1, inf, nan */
    while (*end == ' ')
        end++;
    if (end == n->value || *end)
        return nc_cfg_error(n, "expected a number, got \"%s\"%s", n->value,
                            strpbrk(n->value, "xX") ? " (decimal digits: no hexadecimal)" : "");
    if (errno == ERANGE)
        return nc_cfg_error(n, "expected a number, got \"%s\", beyond a double's range (%s)", n->value,
                            fabs(v) > 1 ? "at most 1.8e308" : "at least 2.2e-308 in magnitude, or 0");
    if (!isfinite(v))
        return nc_cfg_error(n, "expected a finite number, got \"%s\"", n->value);
    n->used = 1;
    *out = v;
    return 1;
}

int nc_cfg_double(struct nc_cfg_node *parent, const char *key, double min, double max, double *out)
{
    struct nc_cfg_node *n = nc_cfg_get(parent, key);
    if (!n)
        return 0;
    double v;
    int rc = scalar_double(n, &v);
    if (rc < 0)
        return rc;
    if (v < min || v > max)
        return nc_cfg_error(n, "expected a number in [%g, %g], got %s", min, max, n->value);
    *out = v;
    return 1;
}

int nc_cfg_int(struct nc_cfg_node *parent, const char *key, long min, long max, long *out)
{
    struct nc_cfg_node *n = nc_cfg_get(parent, key);
    if (!n)
        return 0;
    if (n->kind != NC_CFG_SCALAR)
        return nc_cfg_error(n, "expected a whole number, got %s", kind_name(n->kind));
    char *end;
    errno = 0;
    long v = strtol(n->value, &end, 10);
    if (end != n->value && (*end == '.' || *end == 'e' || *end == 'E') && !errno) {
        /* a whole number written as a decimal (1e3, 64.0): taken when it is one exactly */
        errno = 0;
        const double d = nc_strtod_decimal(n->value, &end);
        if (!*end && !errno && d == floor(d) && fabs(d) <= 9007199254740992.0)
            v = (long)d;
        else
            end = n->value;
    }
    if (end == n->value || *end || errno)
        return nc_cfg_error(n, "expected a whole number, got \"%s\"", n->value);
    if (v < min || v > max)
        return nc_cfg_error(n, "expected a whole number in [%ld, %ld], got %ld", min, max, v);
    *out = v;
    return 1;
}

int nc_cfg_seed(struct nc_cfg_node *parent, const char *key, uint64_t *out)
{
    long v = 0;
    int rc = nc_cfg_int(parent, key, 0, 0x7fffffffL, &v);
    if (rc > 0)
        *out = (uint64_t)v;
    return rc;
}

int nc_cfg_string(struct nc_cfg_node *parent, const char *key, const char **out)
{
    struct nc_cfg_node *n = nc_cfg_get(parent, key);
    if (!n)
        return 0;
    if (n->kind != NC_CFG_SCALAR || !n->value[0])
        return nc_cfg_error(n, "expected a non-empty text value, got %s", n->kind == NC_CFG_SCALAR ? "nothing" : kind_name(n->kind));
    *out = n->value;
    return 1;
}

int nc_cfg_enum(struct nc_cfg_node *parent, const char *key, const char *const *names, int *out)
{
    const char *s = "";
    int rc = nc_cfg_string(parent, key, &s);
    if (rc <= 0)
        return rc;
    char list[256] = "";
    for (int i = 0; names[i]; i++) {
        if (strcmp(names[i], s) == 0) {
            *out = i;
            return 1;
        }
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", i ? ", " : "", names[i]);
    }
    return nc_cfg_key_error(parent, key, "expected one of: %s; got \"%s\"", list, s);
}

int nc_cfg_doubles(struct nc_cfg_node *parent, const char *key, double *out, size_t n)
{
    struct nc_cfg_node *s = nc_cfg_get(parent, key);
    if (!s)
        return 0;
    if (s->kind != NC_CFG_SEQ || s->nchild != n) {
        /* an item past the length another layer added (--set KEY.3=...) is where the length went wrong */
        const struct nc_cfg_node *at = s;
        for (size_t i = n; s->kind == NC_CFG_SEQ && i < s->nchild; i++)
            at = s->child[i]->origin != s->origin ? s->child[i] : at;
        return nc_cfg_error(at, "expected a list of %zu numbers, got %s", n,
                            s->kind == NC_CFG_SEQ ? "a list of another length" : kind_name(s->kind));
    }
    double tmp[16];
    for (size_t i = 0; i < n && i < 16; i++) {
        int rc = scalar_double(s->child[i], &tmp[i]);
        if (rc < 0)
            return rc;
    }
    memcpy(out, tmp, n * sizeof *out);
    return 1;
}

int nc_cfg_vec3(struct nc_cfg_node *parent, const char *key, struct nc_vec3 *out)
{
    double v[3] = {0};
    int rc = nc_cfg_doubles(parent, key, v, 3);
    if (rc == 1)
        *out = nc_v3(v[0], v[1], v[2]);
    return rc;
}

int nc_cfg_vec3_max(struct nc_cfg_node *parent, const char *key, double max, const char *what, const char *limit,
                    struct nc_vec3 *out)
{
    const int rc = nc_cfg_vec3(parent, key, out);
    const double len = rc == 1 ? hypot(hypot(out->x, out->y), out->z) : 0; /* 1e300 is not inf */
    int digits = 6; /* as few as show it beyond the limit, nearer it than the limit (not "1e+15 m" for 1e15 + 1) */
    char text[32];
    while (snprintf(text, sizeof text, "%.*g", digits, len) > 0 && digits < 17 &&
           !(strtod(text, NULL) > max && fabs(strtod(text, NULL) - len) < len - max))
        digits++;
    if (!(len <= max))
        return nc_cfg_key_error(parent, key, "%s %s, beyond %s", text, what, limit);
    return rc;
}

int nc_cfg_quat(struct nc_cfg_node *parent, const char *key, struct nc_quat *out)
{
    double v[4] = {0};
    int rc = nc_cfg_doubles(parent, key, v, 4);
    if (rc <= 0)
        return rc;
    struct nc_quat q = {v[0], v[1], v[2], v[3]};
    double n = nc_quat_norm(q);
    if (fabs(n - 1.0) > 1e-3)
        return nc_cfg_key_error(parent, key,
                                "expected a unit quaternion [w, x, y, z] (scalar first), got norm %.9g", n);
    *out = (struct nc_quat){q.w / n, q.x / n, q.y / n, q.z / n};
    return 1;
}

static struct nc_cfg_node *first_unused(struct nc_cfg_node *n)
{
    if (!n->used)
        return n;
    if (n->kind == NC_CFG_SCALAR)
        return NULL;
    for (size_t i = 0; i < n->nchild; i++) {
        struct nc_cfg_node *u = first_unused(n->child[i]);
        if (u)
            return u;
    }
    return NULL;
}

/* ---- errors --------------------------------------------------------- */

static int vcfg_error(const struct nc_cfg_node *node, const char *key, const char *fmt, va_list ap)
{
    char path[256], msg[512];
    vsnprintf(msg, sizeof msg, fmt, ap);
    if (!node) /* no place to name (a caller's nc_cfg_get of an absent key) */
        return key ? nc_error(NC_ECONFIG, "config: %s: %s", key, msg) : nc_error(NC_ECONFIG, "config: %s", msg);
    /* A plain file's key: null (or nothing, or ~) is a value, not the default. */
    if (!key && nc__cfg_is_null_or_empty(node))
        snprintf(msg + strlen(msg), sizeof msg - strlen(msg), " (%s: give a value, or leave the key out for its "
                 "default)", node->value[0] ? "YAML's null" : "no value");
    nc_cfg_path(node, path, sizeof path);
    const char *sep = key ? (node->parent ? "." : "") : "";
    if (key && !node->parent)
        path[0] = '\0';
    if (node->line > 0)
        return nc_error(NC_ECONFIG, "%s:%d: %s%s%s: %s", node->origin, node->line, path, sep, key ? key : "", msg);
    return nc_error(NC_ECONFIG, "%s: %s%s%s: %s", node->origin ? node->origin : "config", path, sep, key ? key : "", msg);
}

int nc_cfg_error(const struct nc_cfg_node *node, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = vcfg_error(node, NULL, fmt, ap);
    va_end(ap);
    return rc;
}

int nc_cfg_key_error(struct nc_cfg_node *map, const char *key, const char *fmt, ...)
{
    const struct nc_cfg_node *n = map && map->kind == NC_CFG_MAP ? nc__cfg_find(map, key) : NULL;
    va_list ap;
    va_start(ap, fmt);
    int rc = n ? vcfg_error(n, NULL, fmt, ap) : vcfg_error(map, key, fmt, ap);
    va_end(ap);
    return rc;
}

static int cfg_error_key(const struct nc_cfg_node *parent, const char *key, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = vcfg_error(parent, key, fmt, ap);
    va_end(ap);
    return rc;
}

/* The key of map parent that no reader took and that most likely misspells
 * key: key cut short (3 letters or more: 'lat' for 'lat_deg'), else one
 * within a third of key's letters in edits; *score says how close (lower is
 * closer). NULL if none. */
static const struct nc_cfg_node *typo_of(const struct nc_cfg_node *parent, const char *key, size_t *score)
{
    const struct nc_cfg_node *best = NULL;
    size_t bs = strlen(key) / 3 + 1;
    for (size_t i = 0; parent && parent->kind == NC_CFG_MAP && i < parent->nchild; i++) {
        const struct nc_cfg_node *c = parent->child[i];
        if (c->used || !c->key)
            continue;
        const size_t lc = strlen(c->key), sc = lc >= 3 && lc < strlen(key) && !strncmp(key, c->key, lc)
                                                   ? 0
                                                   : nc__cfg_edits(c->key, key);
        if (sc < bs)
            best = c, bs = sc;
    }
    *score = bs;
    return best;
}

static int missing(const struct nc_cfg_node *parent, const char *key, const char *msg, const struct nc_cfg_node *c,
                   const char *meant)
{
    if (!c)
        return key ? cfg_error_key(parent, key, "%s", msg) : nc_cfg_error(parent, "%s", msg);
    char at[32] = "";
    if (c->line > 0)
        snprintf(at, sizeof at, " (line %d)", c->line);
    return key ? cfg_error_key(parent, key, "%s; '%s'%s is not a key here: a misspelling of it?", msg, c->key, at)
               : nc_cfg_error(parent, "%s; '%s'%s is not a key here: a misspelling of '%s'?", msg, c->key, at,
                              meant ? meant : "?");
}

int nc_cfg_missing(const struct nc_cfg_node *parent, const char *key, const char *expected)
{
    char msg[1024];
    size_t score;
    snprintf(msg, sizeof msg, "missing required key (expected %s)", expected);
    const struct nc_cfg_node *typo = typo_of(parent, key, &score), *up = parent ? parent->parent : NULL;
    for (size_t i = 0; !typo && key && up && up->kind == NC_CFG_MAP && i < up->nchild; i++)
        if (up->child[i]->key && !strcmp(up->child[i]->key, key)) { /* the key one level too high */
            char where[256], here[256], at[32] = "";
            nc_cfg_path(up, where, sizeof where);
            nc_cfg_path(parent, here, sizeof here);
            if (up->child[i]->line > 0)
                snprintf(at, sizeof at, " (line %d)", up->child[i]->line);
            const size_t n = strlen(msg);
            snprintf(msg + n, sizeof msg - n, "; '%s'%s is given in %s instead: move it into %s", key, at,
                     where[0] ? where : "the top level", here);
        }
    return missing(parent, key, msg, typo, key);
}

int nc_cfg_missing_any(const struct nc_cfg_node *map, const char *const *keys, const char *msg)
{
    const struct nc_cfg_node *best = NULL;
    const char *meant = NULL;
    size_t bs = (size_t)-1, score;
    for (int i = 0; keys[i]; i++) {
        const struct nc_cfg_node *c = typo_of(map, keys[i], &score);
        if (c && score < bs)
            best = c, bs = score, meant = keys[i];
    }
    return missing(map, NULL, msg, best, meant);
}

/* The nearest of names within a third of key's letters' edits. */
const char *nc__cfg_nearest(const char *key, const char *const *names, size_t n)
{
    const char *best = NULL;
    size_t bd = strlen(key) / 3;
    for (size_t i = 0; i < n; i++) {
        const size_t d = nc__cfg_edits(key, names[i]);
        if (d <= bd && (!best || d < bd))
            best = names[i], bd = d;
    }
    return best;
}

/* Edit distance of two keys (a few dozen characters): insertions,
 * deletions, substitutions and swaps of two neighbours (hurts: hurst)
 * count one each, as optimal string alignment. */
size_t nc__cfg_edits(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b), r0[65], r1[65], r2[65], *prev = r0, *row = r1, *back = r2;
    if (la > 64 || lb > 64)
        return 99;
    for (size_t j = 0; j <= lb; j++)
        row[j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t *t = back;
        back = prev, prev = row, row = t; /* back: row i - 2, prev: row i - 1 */
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t d = prev[j - 1] + (a[i - 1] != b[j - 1]);
            if (prev[j] + 1 < d)
                d = prev[j] + 1;
            if (row[j - 1] + 1 < d)
                d = row[j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && back[j - 2] + 1 < d)
                d = back[j - 2] + 1;
            row[j] = d;
        }
    }
    return row[lb];
}

/* How many maps other than skip had their readers ask for key; *first the
 * first of them in file order. */
static int askers(const struct nc_cfg_node *n, const char *key, const struct nc_cfg_node *skip,
                  const struct nc_cfg_node **first)
{
    int k = 0;
    if (n != skip)
        for (size_t i = 0; i < n->nasked; i++)
            if (!strcmp(n->asked[i], key)) {
                if (!k++ && !*first)
                    *first = n;
                break;
            }
    for (size_t i = 0; i < n->nchild; i++)
        k += askers(n->child[i], key, skip, first);
    return k;
}

int nc_cfg_check_unused(struct nc_cfg *cfg)
{
    if (!cfg->root)
        return 0;
    cfg->root->used = 1;
    return nc_cfg_check_unused_in(cfg, cfg->root);
}

int nc_cfg_check_unused_keys(struct nc_cfg *cfg, struct nc_cfg_node *map)
{
    for (size_t i = 0; map && map->kind == NC_CFG_MAP && i < map->nchild; i++)
        if (!map->child[i]->used)
            return nc_cfg_check_unused_in(cfg, map->child[i]);
    return 0;
}

/* The document that lists a section's keys: the emulator's serve and
 * outputs sections have theirs in docs/emulator.md, the rest config.md. */
static const char *doc_of(const struct nc_cfg_node *n)
{
    while (n->parent && n->parent->parent)
        n = n->parent;
    return n->key && (!strcmp(n->key, "serve") || !strcmp(n->key, "outputs")) ? "docs/emulator.md" : "docs/config.md";
}

int nc_cfg_check_unused_in(struct nc_cfg *cfg, struct nc_cfg_node *n)
{
    struct nc_cfg_node *u = n ? first_unused(n) : NULL;
    if (!u)
        return 0;
    const struct nc_cfg_node *p = u->parent;
    if (!u->key || !p || !p->nasked)
        return nc_cfg_error(u, "unknown key (see %s for the keys this section takes)", doc_of(u));
    /* The nearest key this section takes (a typo), else where the key is read
     * (a key in the wrong section), then every key this section takes. */
    char hint[1536] = "", where[512];
    const char *best = nc__cfg_nearest(u->key, (const char *const *)p->asked, p->nasked);
    for (size_t i = 0; i < p->nasked && !best; i++) { /* the key without its unit, or cut short */
        const char *a = p->asked[i], *k = u->key;
        const size_t la = strlen(a), lk = strlen(k);
        if ((la > lk && !strncmp(a, k, lk) && a[lk] == '_') || (lk > la && !strncmp(a, k, la) && k[la] == '_'))
            best = a;
    }
    /* the one section within this one that reads the key, else the one in
     * the whole file; a key that several read (a seed) names none of them */
    const struct nc_cfg_node *w = NULL;
    if (!best && askers(p, u->key, p, &w) != 1 && (w = NULL, askers(cfg->root, u->key, p, &w) != 1))
        w = NULL;
    if (best)
        snprintf(hint, sizeof hint, "; did you mean '%s'?", best);
    else if (w) {
        nc_cfg_path(w, where, sizeof where);
        snprintf(hint, sizeof hint, "; '%s' is read %s%s", u->key, w->parent ? "in " : "at the top level",
                 w->parent ? where : "");
    }
    size_t len = strlen(hint);
    snprintf(hint + len, sizeof hint - len, " (%s takes:", p->parent ? "this section" : "the top level");
    for (size_t i = 0; i < p->nasked && (len = strlen(hint)) < sizeof hint - 80; i++)
        snprintf(hint + len, sizeof hint - len, "%s %s", i ? "," : "", p->asked[i]);
    len = strlen(hint);
    snprintf(hint + len, sizeof hint - len, "%s; %s)", len >= sizeof hint - 80 ? ", ..." : "", doc_of(u));
    return nc_cfg_error(u, "unknown key%s", hint);
}

void nc_cfg_mark_used(struct nc_cfg_node *n)
{
    n->used = 1;
    for (size_t i = 0; i < n->nchild; i++)
        nc_cfg_mark_used(n->child[i]);
}

void nc_cfg_resolve_path(const struct nc_cfg_node *n, const char *file, char *out, size_t len)
{
    if (file[0] == '/' || !n || !n->origin || n->line == 0 || n->origin[0] == '<') {
        snprintf(out, len, "%s", file);
        return;
    }
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", n->origin);
    snprintf(out, len, "%s/%s", dirname(dir), file);
}
