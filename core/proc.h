/* proc.h - the process's resident memory, as the kernel counts it (Linux
 * /proc/self/status VmRSS): what the memory figures of tests and
 * benchmarks measure. */
#ifndef NC_PROC_H
#define NC_PROC_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Resident memory in KiB; 0 if unknown. */
static inline long nc_resident_kb(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    long v = 0;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "VmRSS:", 6))
            v = atol(line + 6);
    if (f)
        fclose(f);
    return v;
}

#endif
