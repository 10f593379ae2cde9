/* output_file.c - the file output: numbered DN image files through
 * OpenImageIO/cfitsio (image_io.h) and a JSON-lines sidecar with every
 * frame's metadata (options: file_params below). */
#include <errno.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/fs.h"
#include "render/image_io.h"
#include "emulator/output.h"

struct file_out {
    char dir[2048];
    char pattern[256];
    FILE *sidecar;
    char sidecar_path[2300];
    int bottom_up; /* FITS rows in the archive order */
};

static const char *const fits_orders[] = {"top_down", "bottom_up", NULL};

static const struct nc_param file_params[] = {
    NC_P_STRING("directory", "out", "where the files go (relative to the working directory; made if missing, with its parents)"),
    NC_P_STRING("pattern", "frame_%06llu.png", "file name with one conversion %llu, %06llu or the like (flags - and 0, width up to 99) for the frame number, no other %; the extension picks the format "
     "(.png, .tif, .fits, .exr)"),
    NC_P_ENUM("fits_row_order", "top_down", fits_orders,
              "for .fits patterns: top_down (row 1 is the top image row) or bottom_up (row 1 at the bottom, as FITS "
              "viewers and mission archives show it); the keyword ROWORDER records which"),
    NC_P_STRING_OR_EMPTY("sidecar", "frames.jsonl",
                         "JSON-lines file with every frame's metadata, in the directory: a file name (no '/', not an "
                         "image format's extension), or empty: none"),
    NC_P_END,
};

/* 1 when pattern holds exactly one conversion, %[-0][width]llu, and no
 * other '%': it is handed to snprintf with the frame number, so any other
 * conversion (%s, %n) would read or write what is not there. */
static int pattern_ok(const char *pattern)
{
    const char *pc = strchr(pattern, '%');
    if (!pc || strchr(pc + 1, '%'))
        return 0;
    const char *p = pc + 1;
    p += strspn(p, "-0");
    const size_t width = strspn(p, "0123456789");
    return width <= 2 && !strncmp(p + width, "llu", 3);
}

/* The pattern must format exactly one unsigned long long, into a name a
 * directory can hold for every frame number, of a format this build
 * writes (its library loaded now, not at the first frame); the FITS row
 * order only with FITS. Before the scene is built (nc_output_check). */
static int file_check(struct nc_cfg_node *opts)
{
    const char *pattern = NULL, *sidecar = NULL;
    int rc, bottom_up = 0;
    if ((rc = nc_param_string(opts, file_params, "pattern", &pattern)) < 0 ||
        (rc = nc_param_string(opts, file_params, "sidecar", &sidecar)) < 0 ||
        (rc = nc_param_enum(opts, file_params, "fits_row_order", &bottom_up)) < 0)
        return rc;
    /* in the directory, and never a frame's name (a frame written over it lost every record before) */
    if (sidecar[0] && (strchr(sidecar, '/') || !strcmp(sidecar, ".") || !strcmp(sidecar, "..") ||
                       nc_image_format_ok(sidecar, NULL)))
        return nc_cfg_key_error(opts, "sidecar", "expected a file name in the directory: no '/', not an image "
                                "format's extension (frames have those), e.g. frames.jsonl");
    if (!pattern_ok(pattern) || strchr(pattern, '/'))
        return nc_cfg_key_error(opts, "pattern",
                                "expected a file name with one %%llu conversion (flags - or 0, a width of at most 99), "
                                "no other %% and no '/', e.g. frame_%%06llu.png");
    char probe[512];
    if (snprintf(probe, sizeof probe, pattern, ~0ULL) > NAME_MAX)
        return nc_cfg_key_error(opts, "pattern", "makes file names longer than %d bytes", NAME_MAX);
    snprintf(probe, sizeof probe, pattern, 0ULL);
    if (!nc_image_format_ok(probe, NULL))
        return nc_cfg_key_error(opts, "pattern", "unsupported image format (use .png, .tif, .fits or .exr)");
    if (bottom_up && !nc_image_is_fits(probe))
        return nc_cfg_key_error(opts, "fits_row_order", "applies to .fits patterns only (the pattern writes %s)",
                                probe);
    if (nc_image_prepare(probe) < 0) {
        char why[4096];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_cfg_key_error(opts, "pattern", "%s", why);
    }
    return 0;
}

/* Its values checked by file_check (nc_output_open). */
static int file_open(void *priv, struct nc_cfg_node *opts, const struct nc_output_ctx *ctx)
{
    struct file_out *f = priv;
    const char *dir = NULL, *pattern = NULL, *sidecar = NULL;
    int rc;
    if ((rc = nc_param_string(opts, file_params, "directory", &dir)) < 0 ||
        (rc = nc_param_string(opts, file_params, "pattern", &pattern)) < 0 ||
        (rc = nc_param_string(opts, file_params, "sidecar", &sidecar)) < 0 ||
        (rc = nc_param_enum(opts, file_params, "fits_row_order", &f->bottom_up)) < 0)
        return rc;
    snprintf(f->dir, sizeof f->dir, "%s", dir);
    snprintf(f->pattern, sizeof f->pattern, "%s", pattern);
    if (nc_mkdirs(f->dir) < 0) { /* with every missing parent, as mkdir -p */
        char why[4200];
        snprintf(why, sizeof why, "%s", nc_errmsg());
        return nc_cfg_key_error(opts, "directory", "file output: %s", why);
    }
    if (sidecar[0]) {
        snprintf(f->sidecar_path, sizeof f->sidecar_path, "%s/%s", f->dir, sidecar);
        f->sidecar = fopen(f->sidecar_path, "w");
        if (!f->sidecar)
            return nc_error(-errno, "file output: %s: %s", f->sidecar_path, strerror(errno));
    }
    (void)ctx;
    return 0;
}

static int file_submit(void *priv, const struct nc_frame_record *r)
{
    struct file_out *f = priv;
    char name[512], path[2600], adc[16], fr[32], json[4096], meta[4096];
    snprintf(name, sizeof name, f->pattern, (unsigned long long)r->frame);
    snprintf(path, sizeof path, "%s/%s", f->dir, name);
    snprintf(adc, sizeof adc, "%d", r->adc_bits);
    snprintf(fr, sizeof fr, "%llu", (unsigned long long)r->frame);
    /* The sidecar has the wall-clock times; the image only what a rerun
     * reproduces, so that lock-step frame files are identical byte for byte. */
    int jl = nc_frame_record_json(r, 1, json, sizeof json), ml = nc_frame_record_json(r, 0, meta, sizeof meta);
    /* the record's metadata (navcam render's of a dn frame), else the least a reader needs */
    struct nc_image_attr attrs[72] = {
        {"navcam:quantity", "dn"}, {"navcam:units", "DN"}, {"navcam:adc_bits", adc}, {"navcam:frame", fr}};
    int n = 4;
    if (r->attrs && r->nattrs > 0 && r->nattrs <= 70)
        memcpy(attrs, r->attrs, sizeof *attrs * (size_t)r->nattrs), n = r->nattrs;
    attrs[n++] = (struct nc_image_attr){"navcam:frame_record", ml > 0 ? meta : ""};
    if (f->bottom_up)
        attrs[n++] = (struct nc_image_attr){"navcam:fits_row_order", "bottom_up"};
    int rc = nc_image_write_dn(path, r->dn, r->width_px, r->height_px, r->adc_bits, attrs, n);
    if (rc < 0)
        return rc;
    /* every line whole on disk when the frame is reported delivered: else the frame is not (a full disk) */
    if (f->sidecar && (jl < 0 || fprintf(f->sidecar, "%s\n", json) < 0 || fflush(f->sidecar) != 0)) {
        const int e = jl < 0 ? ENOSPC : errno;
        clearerr(f->sidecar);
        return nc_error(-e, "file output: %s: the frame's line not written: %s", f->sidecar_path,
                        jl < 0 ? "the record does not fit its buffer" : strerror(e));
    }
    return 0;
}

static int file_control(void *priv, const char *request, void *arg)
{
    struct file_out *f = priv;
    if (!strcmp(request, "flush"))
        return f->sidecar && fflush(f->sidecar) != 0 ? -errno : 0;
    return NC_EUNSUPPORTED;
}

static void file_close(void *priv)
{
    struct file_out *f = priv;
    if (f->sidecar)
        fclose(f->sidecar);
    f->sidecar = NULL;
}

const struct nc_output_driver nc_output_file = {
    .name = "file",
    .description = "numbered image files and a JSON-lines sidecar",
    .caps = NC_OUTPUT_CAP_DN16,
    .priv_size = sizeof(struct file_out),
    .params = file_params,
    .check = file_check,
    .open = file_open,
    .submit = file_submit,
    .control = file_control,
    .close = file_close,
};
