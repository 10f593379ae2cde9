/* lines.h - a text file read a line at a time, refusing what a C string
 * would lose: a NUL byte ends the string where the line goes on, so the rest
 * of the line would be dropped unseen. Lines have no length limit. */
#ifndef NC_LINES_H
#define NC_LINES_H

#include <stddef.h>
#include <stdio.h>

struct nc_lines {
    FILE *f;
    const char *path; /* named in errors */
    int code;         /* the error code of a line refused */
    size_t no;        /* the number of the line last read, from 1 */
    char *line;       /* that line, its end of line kept */
    size_t len, cap;
};

/* Lines of f (opened and closed by the caller), errors naming path and
 * returning code. */
void nc_lines_init(struct nc_lines *l, FILE *f, const char *path, int code);

/* The next line into l->line: 1; 0 at the end of the file; code with
 * "PATH:NO: a NUL byte at column C (a binary or damaged file?)", or for a
 * carriage return not ending the line (LF, CR LF or CR CR LF end lines; a
 * lone CR, classic Mac's, would run lines together); -EIO when the file cannot be
 * read. A UTF-8 byte-order mark opening the file is dropped. */
int nc_lines_next(struct nc_lines *l);

void nc_lines_free(struct nc_lines *l);

/* strtod, and a Fortran D exponent (1.5D+03, as SPC's files and FITS
 * headers write them) read as E. */
double nc_strtod_fortran(const char *s, char **end);

/* strtod of a decimal number only (digits, sign, point, exponent, after
 * blanks): hexadecimal (0x1p1), inf and nan read nothing (*end = s). */
double nc_strtod_decimal(const char *s, char **end);

#endif
