/* cli.c - the commands' shared start-up and error reporting (cli.h). */
#include "app/cli.h"

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
