/* log.h - the one way library code reports what it does: a line on stderr
 * prefixed with the program and the object it concerns,
 *     navcam serve: output/v4l2: /dev/video42 reopened after 3 lost frames
 * so a reader of a lab log knows at once who spoke. Libraries never print to
 * stderr themselves; the program names itself once (nc_log_set_program).
 * Each line is written with a single write(2), so lines of different threads
 * never interleave. Errors that a caller handles are not logged here: they
 * travel up as return codes with nc_error() (core/error.h).
 */
#ifndef NC_LOG_H
#define NC_LOG_H

enum nc_log_level { NC_LOG_ERROR, NC_LOG_WARN, NC_LOG_INFO, NC_LOG_DEBUG };

/* "navcam serve", "navcam render", ... (default "navcam"). Call before
 * starting threads; the string must outlive the program. */
void nc_log_set_program(const char *name);
/* Lines above this level are not written (default NC_LOG_INFO; the
 * environment variable NAVCAM_LOG=error|warn|info|debug sets it too). */
void nc_log_set_level(enum nc_log_level level);
int nc_log_enabled(enum nc_log_level level);

/* One line "<program>: <object>: <message>" (warnings and errors say so
 * after the object). object is "output/v4l2", "trigger/gpio", "serve", ... */
void nc_log(enum nc_log_level level, const char *object, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

#define nc_log_error(object, ...) nc_log(NC_LOG_ERROR, object, __VA_ARGS__)
#define nc_log_warn(object, ...) nc_log(NC_LOG_WARN, object, __VA_ARGS__)
#define nc_log_info(object, ...) nc_log(NC_LOG_INFO, object, __VA_ARGS__)
#define nc_log_debug(object, ...) nc_log(NC_LOG_DEBUG, object, __VA_ARGS__)

#endif
