/* cli.c - the commands' shared start-up, error reporting and JSON members (cli.h). */
#include "app/cli.h"

#include <arpa/inet.h>
#include <ctype.h>
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/error.h"
#include "core/lines.h"
#include "core/log.h"
#include "core/texture.h"

static char name[64] = "navcam";

void nc_cli_init(const char *command)
{
    snprintf(name, sizeof name, "navcam %s", command);
    nc_log_set_program(name);
}

int nc_cli_fail(void)
{
    fprintf(stderr, "%s: %s\n", name, nc_errmsg());
    return 1;
}

int nc_cli_getopt(int argc, char *const argv[], const char *shortopts, const struct option *opts)
{
    const int c = getopt_long(argc, argv, shortopts, opts, NULL);
    /* a value of its own argument (not --output=--x or -o--x, which say what they mean) that is a long option,
     * or one of this command's short ones (-q; a negative number, -1, stays a value) */
    if (c == -1 || c == '?' || !optarg || optind < 2 || optarg != argv[optind - 1])
        return c;
    const int is_long = !strncmp(optarg, "--", 2) && optarg[2],
              is_short = optarg[0] == '-' && isalpha((unsigned char)optarg[1]) && !optarg[2] &&
                         strchr(shortopts, optarg[1]);
    if (!is_long && !is_short)
        return c;
    fprintf(stderr, "%s: %s needs a value, got the option '%s'\n", name, argv[optind - 2], optarg);
    return '?';
}

int nc_cli_dir_writable(const char *path)
{
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", path);
    const char *dir = dirname(buf); /* "." for a bare file name: not a pointer into buf */
    if (access(dir, W_OK) == 0)
        return 0;
    fprintf(stderr, "%s: %s: cannot write into directory '%s': %s\n", name, path, dir, strerror(errno));
    return -1;
}

int nc_cli_long(const char *opt, const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    const long v = strtol(s, &end, 10);
    if (end == s || *end || errno || v < lo || v > hi) {
        fprintf(stderr, "%s: --%s expects %ld..%ld, got '%s'\n", name, opt, lo, hi, s);
        return -1;
    }
    *out = v;
    return 0;
}

int nc_cli_threads(const char *s, int *out)
{
    long v;
    if (nc_cli_long("threads", s, 0, 1024, &v) < 0)
        return -1;
    if (v == 0) {
        const long n = sysconf(_SC_NPROCESSORS_ONLN);
        v = n > 0 ? n : 1;
    }
    *out = (int)v;
    return 0;
}

void nc_cli_sumfile(const char **sets, int *nsets, char *buf, size_t len, const char *path)
{
    size_t n = (size_t)snprintf(buf, len, "camera={sumfile: '");
    for (const char *c = path; *c && n + 4 < len; c++) { /* a quote doubled: YAML's single-quoted scalar */
        if (*c == '\'')
            buf[n++] = '\'';
        buf[n++] = *c;
    }
    snprintf(buf + n, len > n ? len - n : 0, "'}");
    memmove(sets + 2, sets, (size_t)*nsets * sizeof *sets);
    sets[0] = buf;
    sets[1] = "sun.direction=null"; /* the SUM file's SZ gives it */
    *nsets += 2;
}

int nc_cli_decimal(const char *s, const char **end, double *out)
{
    char *e;
    *out = nc_strtod_decimal(s, &e);
    *end = e;
    return e != s && isfinite(*out) ? 0 : -1;
}

int nc_cli_whole(const char *s, unsigned long long *out)
{
    char *end;
    errno = 0;
    *out = strtoull(s, &end, 10);
    return *s >= '0' && *s <= '9' && !*end && !errno ? 0 : -1;
}

int nc_cli_double(const char *opt, const char *s, double lo, double hi, double *out)
{
    const char *end;
    double v;
    if (nc_cli_decimal(s, &end, &v) < 0 || *end || !(v >= lo && v <= hi)) {
        fprintf(stderr, "%s: --%s expects %g..%g, got '%s'\n", name, opt, lo, hi, s);
        return -1;
    }
    *out = v;
    return 0;
}

int nc_cli_host(const char *s)
{
    struct in_addr a;
    if (inet_pton(AF_INET, s, &a) == 1)
        return 0;
    fprintf(stderr, "%s: --host expects a numeric IPv4 address such as 127.0.0.1 (names are not looked up), got '%s'\n",
            name, s);
    return -1;
}

int nc_cli_gnuplot(const char *dir, const char *script)
{
    fflush(stdout);
    const pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        if (dup2(STDERR_FILENO, STDOUT_FILENO) < 0 || chdir(dir) < 0)
            _exit(127);
        execlp("gnuplot", "gnuplot", script, (char *)NULL);
        _exit(127);
    }
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            return -1;
    return WIFEXITED(status) && WEXITSTATUS(status) == 0 ? 0 : -1;
}

int nc_cli_out_open(const char *path, FILE **f)
{
    *f = path ? fopen(path, "w") : stdout;
    return *f ? 0 : nc_error(-errno, "%s: %s", path, strerror(errno));
}

int nc_cli_out_close(FILE *f, const char *path)
{
    if (!path)
        return fflush(f) != 0 ? nc_error(-errno, "standard output: %s", strerror(errno)) : 0;
    return fclose(f) != 0 ? nc_error(-errno, "%s: %s", path, strerror(errno)) : 0;
}

void nc_cli_json_num(FILE *f, const char *key, double v, const char *sep)
{
    if (isfinite(v))
        fprintf(f, "\"%s\": %.9g%s", key, v, sep);
    else
        fprintf(f, "\"%s\": null%s", key, sep);
}

void nc_cli_json_vec(FILE *f, const char *key, const double *v, int n, const char *sep)
{
    fprintf(f, "\"%s\": [", key);
    for (int i = 0; i < n; i++)
        fprintf(f, "%.17g%s", v[i], i + 1 < n ? ", " : "");
    fprintf(f, "]%s", sep);
}

void nc_cli_json_str(FILE *f, const char *key, const char *v)
{
    fprintf(f, "\"%s\": \"", key);
    for (; *v; v++)
        fprintf(f, *v == '"' || *v == '\\' ? "\\%c" : (unsigned char)*v < 32 ? "?" : "%c", *v);
    fprintf(f, "\", ");
}

void nc_cli_json_texture(FILE *f, const struct nc_texture *t)
{
    fprintf(f, "\"region_px\": %zu, \"scale\": [%.9g, %.9g], \"corners\": %zu, ", t->region_px, t->lo, t->hi,
            t->corners);
    nc_cli_json_num(f, "corners_per_mpx", t->corners_per_mpx, ", ");
    nc_cli_json_num(f, "psd_beta", t->psd_beta, ", ");
    nc_cli_json_num(f, "psd_r2", t->psd_r2, ", ");
    nc_cli_json_num(f, "grad_mean", t->grad_mean, ", ");
    nc_cli_json_num(f, "grad_rms", t->grad_rms, ", ");
    nc_cli_json_num(f, "grad_kurtosis", t->grad_kurtosis, "");
}
