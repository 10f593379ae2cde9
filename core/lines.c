/* lines.c - a text file read a line at a time (lines.h). */
#include "core/lines.h"

#include <ctype.h>
#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>

#include "core/error.h"

void nc_lines_init(struct nc_lines *l, FILE *f, const char *path, int code)
{
    *l = (struct nc_lines){.f = f, .path = path, .code = code};
}

int nc_lines_next(struct nc_lines *l)
{
    errno = 0;
    const ssize_t n = getline(&l->line, &l->cap, l->f);
    if (n <= 0) {
        if (ferror(l->f))
            return nc_error(-EIO, "%s:%zu: cannot read: %s", l->path, l->no + 1, strerror(errno ? errno : EIO));
        return 0;
    }
    l->no++;
    l->len = (size_t)n;
    const size_t c = strlen(l->line);
    if (c != l->len)
        return nc_error(l->code, "%s:%zu: a NUL byte at column %zu (a binary or damaged file?)", l->path, l->no, c + 1);
    if (l->no == 1 && l->len >= 3 && !memcmp(l->line, "\xef\xbb\xbf", 3)) { /* a UTF-8 byte-order mark */
        l->len -= 3;
        memmove(l->line, l->line + 3, l->len + 1);
    }
    /* CRs ending the line (CR LF, or CR CR LF converted twice) are fine; memchr: the length is known */
    const char *cr = memchr(l->line, '\r', l->len);
    if (cr && strcmp(cr + strspn(cr, "\r"), "\n") != 0 && cr[strspn(cr, "\r")] != '\0')
        return nc_error(l->code, "%s:%zu: a carriage return at column %zu inside the line (classic Mac line ends? "
                        "end lines with LF or CR LF)", l->path, l->no, (size_t)(cr - l->line) + 1);
    return 1;
}

void nc_lines_free(struct nc_lines *l)
{
    free(l->line);
    l->line = NULL;
    l->cap = 0;
}

double nc_strtod_fortran(const char *s, char **end)
{
    const size_t lead = strspn(s, " \t\r\n\v\f"), len = strcspn(s + lead, " \t\r\n\v\f,");
    char num[64], *e;
    if (len >= sizeof num)
        return strtod(s, end);
    memcpy(num, s + lead, len);
    num[len] = '\0';
    if (!strpbrk(num, "xX")) /* not in a hexadecimal number's digits */
        for (size_t i = 1; i < len; i++) /* within the token (an empty one has nothing past its end to read) */
            if ((num[i] == 'D' || num[i] == 'd') && (isdigit((unsigned char)num[i - 1]) || num[i - 1] == '.'))
                num[i] = 'E';
    const double v = strtod(num, &e);
    if (end)
        *end = (char *)s + (e == num ? 0 : lead + (size_t)(e - num));
    return v;
}

double nc_strtod_decimal(const char *s, char **end)
{
    char *e;
    const double v = strtod(s, &e);
    const char *digits = s + strspn(s, " \t");
    const int decimal = e != s && strspn(digits, "0123456789+-.eE") >= (size_t)(e - digits);
    if (end)
        *end = decimal ? e : (char *)s;
    return decimal ? v : 0;
}
