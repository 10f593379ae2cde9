/* test_params.c - the core pieces every layer leans on: parameter tables
 * (unknown keys rejected with file:line, defaults and ranges from the table,
 * nested maps, help and Markdown from the same rows), error names for every
 * errno the C library knows, and the logger's one-line, prefixed output. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/config.h"
#include "core/error.h"
#include "core/log.h"
#include "core/params.h"
#include "testutil.h"

static const char *const modes[] = {"slow", "fast", NULL};
static const struct nc_param sub[] = {
    NC_P_STRING("line", NULL, "a line"),
    NC_P_ENUM("level", "fast", modes, "its mode"),
    NC_P_END,
};
static const struct nc_param table[] = {
    NC_P_DOUBLE("rate_hz", "10", 0.5, 100, "Hz", "how often"),
    NC_P_INT("count", "3", 1, 9, "", "how many"),
    NC_P_STRING("name", "cam", "what it is called"),
    NC_P_STRING_OR_EMPTY("note", "x.txt", "a file, empty for none"),
    NC_P_ENUM("mode", "fast", modes, "speed"),
    NC_P_BOOL("on", "true", "switch"),
    NC_P_MAP("strobe", sub, "a nested map"),
    NC_P_END,
};

/* A form: "AB" followed by digits. */
static int ab_form(const char *v, char *why, size_t len)
{
    if (!strncmp(v, "AB", 2) && v[2] && strspn(v + 2, "0123456789") == strlen(v + 2))
        return 0;
    snprintf(why, len, "'%s' is not AB and digits", v);
    return -1;
}
static const struct nc_param must[] = {
    NC_P_STRING_REQUIRED("port", "the port to use"),
    NC_P_STRING_CHECKED("id", "AB1", ab_form, "an id"),
    NC_P_MAP("strobe", sub, "a nested map"),
    NC_P_END,
};
static const struct nc_param sub_must[] = {NC_P_STRING_REQUIRED("line", "its line"), NC_P_END};
static const struct nc_param must_nested[] = {NC_P_MAP("strobe", sub_must, "a nested map"), NC_P_END};

static int load(struct nc_cfg *cfg, const char *yaml)
{
    nc_cfg_init(cfg);
    return nc_cfg_load_string(cfg, yaml, "t.yaml");
}

static void test_tables(void)
{
    const struct nc_param *const tables[] = {table};
    struct nc_cfg cfg;
    /* Unknown keys: file, line, path, and the keys that exist. */
    CHECK(load(&cfg, "rate_hz: 5\nrat_hz: 4\n") == 0, "load");
    int rc = nc_params_check(cfg.root, tables, 1, "driver 'x'");
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "t.yaml:2: rat_hz: unknown key for driver 'x'; did you mean 'rate_hz'?") &&
              nc_test_contains(nc_errmsg(), "rate_hz, count, name"),
          "unknown key: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    CHECK(load(&cfg, "strobe:\n  line: a\n  levle: slow\n") == 0, "load");
    rc = nc_params_check(cfg.root, tables, 1, "driver 'x'");
    CHECK(rc < 0 && nc_test_contains(nc_errmsg(), "t.yaml:3: strobe.levle: unknown key"), "nested: %s", nc_errmsg());
    nc_cfg_free(&cfg);

    /* No map at all: every default from the table. */
    double r = 0;
    long n = 0;
    const char *s = NULL, *note = NULL;
    int m = -1, on = -1;
    CHECK(nc_param_double(NULL, table, "rate_hz", &r) == 0 && r == 10, "default double %g", r);
    CHECK(nc_param_int(NULL, table, "count", &n) == 0 && n == 3, "default int %ld", n);
    CHECK(nc_param_string(NULL, table, "name", &s) == 0 && s && !strcmp(s, "cam"), "default string");
    CHECK(nc_param_enum(NULL, table, "mode", &m) == 0 && m == 1, "default enum %d", m);
    CHECK(nc_param_bool(NULL, table, "on", &on) == 0 && on == 1, "default bool %d", on);

    /* Configured values, and the table's ranges. */
    CHECK(load(&cfg, "rate_hz: 50\ncount: 9\nmode: slow\non: false\nnote: ''\nstrobe: {line: L}\n") == 0, "load");
    CHECK(nc_params_check(cfg.root, tables, 1, "x") == 0, "check: %s", nc_errmsg());
    CHECK(nc_param_double(cfg.root, table, "rate_hz", &r) == 1 && r == 50, "rate %g", r);
    CHECK(nc_param_int(cfg.root, table, "count", &n) == 1 && n == 9, "count %ld", n);
    CHECK(nc_param_enum(cfg.root, table, "mode", &m) == 1 && m == 0, "mode %d", m);
    CHECK(nc_param_bool(cfg.root, table, "on", &on) == 1 && on == 0, "on %d", on);
    CHECK(nc_param_string(cfg.root, table, "note", &note) == 1 && note && !note[0], "empty note allowed");
    struct nc_cfg_node *st = NULL;
    CHECK(nc_param_map(cfg.root, table, "strobe", &st) == 1 && st, "nested map");
    CHECK(nc_param_string(st, sub, "line", &s) == 1 && !strcmp(s, "L"), "nested string");
    CHECK(nc_param_enum(st, sub, "level", &m) == 0 && m == 1, "nested default");
    CHECK(nc_cfg_check_unused(&cfg) == 0, "everything read: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    CHECK(load(&cfg, "rate_hz: 0.1\n") == 0, "load");
    CHECK(nc_param_double(cfg.root, table, "rate_hz", &r) < 0 &&
              nc_test_contains(nc_errmsg(), "t.yaml:1: rate_hz: expected a number in [0.5, 100]"),
          "range: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    CHECK(load(&cfg, "name: ''\n") == 0, "load");
    CHECK(nc_param_string(cfg.root, table, "name", &s) < 0, "an empty name is refused");
    nc_cfg_free(&cfg);
    /* Reading a key the table lacks is the caller's bug, said as such. */
    CHECK(nc_param_double(NULL, table, "nope", &r) < 0 && nc_test_contains(nc_errmsg(), "not in the table"),
          "missing entry: %s", nc_errmsg());

    /* Required keys and forms are checked with the values, before any part opens; a required key only in
     * a map that is there. */
    const struct nc_param *const musts[] = {must}, *const nested[] = {must_nested};
    CHECK(load(&cfg, "id: AB7\n") == 0, "load");
    CHECK(nc_params_values(cfg.root, musts, 1) < 0 &&
              nc_test_contains(nc_errmsg(), "t.yaml:1: port: missing required key (expected the port to use)"),
          "required: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    /* no map at all (a trigger's options may be NULL): none given, so the required one is missing */
    CHECK(nc_params_values(NULL, musts, 1) < 0 && nc_test_contains(nc_errmsg(), "port: missing required key"),
          "required, no map: %s", nc_errmsg());
    CHECK(load(&cfg, "port: p\nid: AC7\n") == 0, "load");
    CHECK(nc_params_values(cfg.root, musts, 1) < 0 &&
              nc_test_contains(nc_errmsg(), "t.yaml:2: id: 'AC7' is not AB and digits"), "form: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    CHECK(load(&cfg, "port: p\nid: AB12\n") == 0 && nc_params_values(cfg.root, musts, 1) == 0 &&
              nc_param_string(cfg.root, must, "id", &s) == 1 && !strcmp(s, "AB12") &&
              nc_params_values(cfg.root, nested, 1) == 0, "valid: %s", nc_errmsg());
    nc_cfg_free(&cfg);
    CHECK(load(&cfg, "strobe: {level: slow}\n") == 0, "load");
    CHECK(nc_params_values(cfg.root, nested, 1) < 0 &&
              nc_test_contains(nc_errmsg(), "t.yaml:1: strobe.line: missing required key (expected its line)"),
          "nested required: %s", nc_errmsg());
    nc_cfg_free(&cfg);

    /* Help and Markdown come from the same rows. */
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    nc_params_print_help(f, table, 2);
    nc_params_print_markdown(f, table);
    nc_params_print_markdown(f, must);
    nc_params_print_help(f, must, 0);
    fclose(f);
    CHECK(nc_test_contains(text, "rate_hz") && nc_test_contains(text, "default 10; 0.5..100 Hz: how often") &&
              nc_test_contains(text, "strobe.level") && nc_test_contains(text, "| `rate_hz` | number | `10` | 0.5 .. 100 | Hz |") &&
              nc_test_contains(text, "| `strobe.line` | text |") &&
              nc_test_contains(text, "| `port` | text | (required) |") && nc_test_contains(text, "required; text: the port"),
          "help text:\n%s", text);
    free(text);
}

static void test_errno_names(void)
{
    /* Every errno value the C library describes has its symbolic name. */
    int unnamed = 0, named = 0;
    for (int e = 1; e < 134; e++) {
        if (!strncmp(strerror(e), "Unknown error", 13))
            continue; /* a hole in the numbering (41, 58) */
        const char *name = nc_err_name(-e);
        if (!strcmp(name, "E?")) {
            unnamed++;
            fprintf(stderr, "errno %d (%s) has no name\n", e, strerror(e));
        } else {
            named++;
        }
    }
    CHECK(unnamed == 0 && named > 120, "%d errno values without a name", unnamed);
    CHECK(!strcmp(nc_err_name(-ETIMEDOUT), "ETIMEDOUT") && !strcmp(nc_err_name(-EADDRINUSE), "EADDRINUSE") &&
              !strcmp(nc_err_name(-ENODEV), "ENODEV") && !strcmp(nc_err_name(NC_ECONFIG), "NC_ECONFIG"),
          "names");
}

static void test_log(void)
{
    /* Capture stderr in a file. */
    const char *path = nc_test_path("log.txt");
    fflush(stderr);
    int saved = dup(2), fd = open(path, O_CREAT | O_TRUNC | O_WRONLY, 0644);
    dup2(fd, 2);
    close(fd);
    nc_log_set_program("navcam test");
    nc_log_set_level(NC_LOG_INFO);
    nc_log_info("output/v4l2", "%s reopened after %d lost frames", "/dev/video42", 3);
    nc_log_warn("trigger/gpio", "late");
    nc_log_debug("emulator", "not shown at info level");
    nc_log_set_level(NC_LOG_ERROR);
    nc_log_info("emulator", "not shown at error level");
    dup2(saved, 2);
    close(saved);
    size_t got;
    char *buf = nc_test_read(path, &got);
    CHECK(buf && !strcmp(buf, "navcam test: output/v4l2: /dev/video42 reopened after 3 lost frames\n"
                              "navcam test: trigger/gpio: warning: late\n"),
          "log lines:\n%s", buf ? buf : "(none)");
    free(buf);
}

int main(void)
{
    test_tables();
    test_errno_names();
    test_log();
    return nc_test_end();
}
