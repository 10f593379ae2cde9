/* cli.h - what the `navcam` commands share: naming the program in log lines
 * and error messages, reporting the library's last error, and writing JSON
 * members. Each command is its own small executable (app/cmd_*.c) that
 * links only the layers it uses; app/navcam.c dispatches to them. */
#ifndef NC_APP_CLI_H
#define NC_APP_CLI_H

#include <stdio.h>

struct option;

/* "navcam render" etc.: the log prefix and the error prefix. */
void nc_cli_init(const char *command);
/* Prints "navcam CMD: <last error>" and returns 1 (the exit status). */
int nc_cli_fail(void);

/* getopt_long, but an option's value that is itself a long option, given
 * as the next argument ("--set --set k=v", "-o --json"), is refused:
 * "navcam CMD: --set needs a value, got the option '--set'" (the option as
 * typed) on stderr and '?', which every command answers with exit status 2
 * and a hint to its --help. --output=--x.png is taken as written. */
int nc_cli_getopt(int argc, char *const argv[], const char *shortopts, const struct option *opts);

/* A number option's value: the whole of s a number in [lo, hi], else
 * "navcam CMD: --opt expects lo..hi, got 's'" on stderr and -1. */
int nc_cli_long(const char *opt, const char *s, long lo, long hi, long *out);
int nc_cli_double(const char *opt, const char *s, double lo, double hi, double *out);
/* A decimal number at the start of s (strtod's, without hexadecimal, inf or
 * nan): 0 and *out, *end after it; -1 when s does not start with one. */
int nc_cli_decimal(const char *s, const char **end, double *out);
/* s whole a whole number 0 .. 2^64 - 1 in decimal digits: 0 and *out; -1
 * (a sign, an empty value, anything after the digits, too large). */
int nc_cli_whole(const char *s, unsigned long long *out);
/* --host: 0 for a numeric IPv4 address; -1 with the option named on stderr
 * for anything else (names are never looked up). */
int nc_cli_host(const char *s);
/* -j, --threads: 1 to 1024, or 0 for every online core (as render.threads:
 * 0), which then overrides render.threads; as nc_cli_long otherwise. */
int nc_cli_threads(const char *s, int *out);

/* --sumfile X.SUM: "camera={sumfile: 'X.SUM'}" and "sun.direction=null"
 * (the SUM file's SZ gives the Sun's direction) put before the other --set
 * arguments, so that a --set camera.KEY still adds to them; buf (len bytes)
 * holds the first. sets has room for two more. */
void nc_cli_sumfile(const char **sets, int *nsets, char *buf, size_t len, const char *path);

/* Where a command writes its results: *f is the file path (opened for
 * writing), or standard output when path is NULL; 0 or a negative error
 * code. Closing reports a failed write (0 or a negative error code);
 * standard output is flushed, not closed. */
int nc_cli_out_open(const char *path, FILE **f);
int nc_cli_out_close(FILE *f, const char *path);

/* Whether the directory path would be written into is writable: 0, or -1
 * after "navcam CMD: PATH: cannot write into directory 'DIR': why" on
 * stderr (a command checks before its work, not after). */
int nc_cli_dir_writable(const char *path);

/* gnuplot SCRIPT run in directory dir (no shell: any directory name is
 * safe), its output to stderr; 0 if it ran and succeeded. */
int nc_cli_gnuplot(const char *dir, const char *script);

/* JSON members: "key": v then sep (null when v is not finite), and
 * "key": "v", (the string escaped). */
void nc_cli_json_num(FILE *f, const char *key, double v, const char *sep);
void nc_cli_json_str(FILE *f, const char *key, const char *v);
/* "key": [v0, v1, ...] (n numbers to 17 digits) then sep. */
void nc_cli_json_vec(FILE *f, const char *key, const double *v, int n, const char *sep);

/* The members of a texture measurement (core/texture.h): region_px,
 * scale [lo, hi], corners, corners_per_mpx, psd_beta, psd_r2, grad_mean,
 * grad_rms, grad_kurtosis (no separator after the last). */
struct nc_texture;
void nc_cli_json_texture(FILE *f, const struct nc_texture *t);

#endif
