/* image_oiio_load.c - the OpenImageIO module (image_io_impl.h) found and
 * loaded on first use, once per process, and its functions behind the
 * back-end's C interface. It is looked for where the commands are: beside
 * this program (libexec/navcam), in libexec/navcam beside it (a build tree)
 * or in ../libexec/navcam (an installed tree), then at the install and
 * build paths this library was configured with (a test program or tool
 * elsewhere in the build tree). */
#include <dlfcn.h>
#include <limits.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "render/image_io_impl.h"

#define MODULE "navcam-oiio.so"

static pthread_once_t once = PTHREAD_ONCE_INIT;
static const struct nc__oiio_api *api;
static char why[3 * PATH_MAX]; /* why api is NULL */

static void load(void)
{
    char self[PATH_MAX] = "", dir[PATH_MAX] = ".", path[PATH_MAX + 64];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    if (n > 0) {
        self[n] = '\0';
        char *slash = strrchr(self, '/');
        if (slash && slash > self) {
            *slash = '\0';
            snprintf(dir, sizeof dir, "%s", self);
        }
    }
    const char *const rel[] = {"%s/" MODULE, "%s/libexec/navcam/" MODULE, "%s/../libexec/navcam/" MODULE};
    const char *const fixed[] = {NC_OIIO_MODULE_INSTALLED, NC_OIIO_MODULE_BUILD};
    for (int i = 0; i < 5; i++) {
        if (i < 3)
            snprintf(path, sizeof path, rel[i], dir);
        else
            snprintf(path, sizeof path, "%s", fixed[i - 3]);
        if (access(path, F_OK) != 0)
            continue;
        void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!h) {
            snprintf(why, sizeof why, "%s", dlerror());
            return;
        }
        const struct nc__oiio_api *(*entry)(void) = (const struct nc__oiio_api *(*)(void))dlsym(h, "nc__oiio_module");
        const struct nc__oiio_api *a = entry ? entry() : NULL;
        if (!a || a->abi != NC__OIIO_ABI) {
            snprintf(why, sizeof why, "%s is not this NavCam's module (%s)", path,
                     a ? "another interface version" : "no nc__oiio_module");
            return;
        }
        api = a;
        return;
    }
    snprintf(why, sizeof why,
             "%s not found beside this program (%s), in its libexec/navcam or ../libexec/navcam, nor at %s or %s",
             MODULE, dir, fixed[0], fixed[1]);
}

int nc__oiio_load(void)
{
    pthread_once(&once, load);
    return api ? 0 : nc_error(NC_EUNSUPPORTED, "EXR, TIFF and PNG files need NavCam's OpenImageIO module: %s", why);
}

int nc__oiio_write(const char *path, const void *px, int w, int h, enum nc__pixel type,
                   const struct nc_image_attr *attrs, int nattrs, const char *description)
{
    char err[1024];
    int rc = nc__oiio_load();
    if (rc == 0 && (rc = api->write(path, px, w, h, type, attrs, nattrs, description, err, sizeof err)) < 0)
        nc_error(rc, "%s", err);
    return rc;
}

int nc__oiio_read(const char *path, float **px, int *w, int *h)
{
    char err[1024];
    int rc = nc__oiio_load();
    if (rc == 0 && (rc = api->read(path, px, w, h, err, sizeof err)) < 0)
        nc_error(rc, "%s", err);
    return rc;
}

int nc__oiio_read_attr(const char *path, const char *name, char *buf, size_t len)
{
    char err[1024];
    int rc = nc__oiio_load();
    if (rc == 0 && (rc = api->read_attr(path, name, buf, len, err, sizeof err)) < 0)
        nc_error(rc, "%s", err);
    return rc;
}
