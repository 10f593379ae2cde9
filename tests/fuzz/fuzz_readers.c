/* fuzz_readers.c - libFuzzer target: the readers of the text and binary
 * files a user hands NavCam (OBJ, PLY, SPC's ICQ shapes, SUM files,
 * trajectory CSVs, KStars' stars.dat, NavCam's star index), the first byte
 * picking which one reads the rest. They
 * must never crash, leak, hang or read out of bounds, whatever the file. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#include "core/sumfile.h"
#include "core/traj.h"
#include "render/mesh.h"
#include "render/stars.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const ext[] = {"obj", "ply", "icq", "SUM", "csv", "dat", "stars"};
    enum { NEXT = sizeof ext / sizeof ext[0] };
    if (size < 1)
        return 0;
    char path[64];
    snprintf(path, sizeof path, "/tmp/nc_fuzz_readers.%ld.%s", (long)getpid(), ext[data[0] % NEXT]);
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    fwrite(data + 1, 1, size - 1, f);
    fclose(f);
    switch (data[0] % NEXT) {
    case 3: {
        struct nc_sumfile s;
        nc_sumfile_read(path, &s);
        break;
    }
    case 4: {
        struct nc_traj_row *rows = NULL;
        if (nc_traj_read(path, &rows) >= 0)
            free(rows);
        break;
    }
    case 5:
    case 6: {
        struct nc_star_cat c;
        if ((data[0] % NEXT == 5 ? nc_star_cat_read_kstars(path, &c) : nc_star_cat_load(path, &c)) >= 0)
            nc_star_cat_free(&c);
        break;
    }
    default: {
        struct nc_mesh m;
        if (nc_mesh_load(path, 1.0, &m) == 0)
            nc_mesh_free(&m);
    }
    }
    unlink(path);
    return 0;
}
