/* cli.c - the commands' shared start-up, error reporting and JSON members (cli.h). */
#include "app/cli.h"

#include <math.h>
#include <stdio.h>

#include "core/error.h"
#include "core/log.h"

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

void nc_cli_json_num(FILE *f, const char *key, double v, const char *sep)
{
    if (isfinite(v))
        fprintf(f, "\"%s\": %.9g%s", key, v, sep);
    else
        fprintf(f, "\"%s\": null%s", key, sep);
}

void nc_cli_json_str(FILE *f, const char *key, const char *v)
{
    fprintf(f, "\"%s\": \"", key);
    for (; *v; v++)
        fprintf(f, *v == '"' || *v == '\\' ? "\\%c" : (unsigned char)*v < 32 ? "?" : "%c", *v);
    fprintf(f, "\", ");
}
