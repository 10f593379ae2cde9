// image_oiio.cpp - the OpenImageIO back-end of image_io (EXR, TIFF, PNG).
// The only file that touches OpenImageIO; no physics and no policy here.
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <string>

extern "C" {
#include "core/error.h"
}
#include "render/image_io_impl.h"

using namespace OIIO;

extern "C" int nc__oiio_write(const char *path, const void *px, int w, int h, enum nc__pixel type,
                              const struct nc_image_attr *attrs, int nattrs, const char *description)
{
    TypeDesc td = type == NC__PX_FLOAT ? TypeDesc::FLOAT : type == NC__PX_U16 ? TypeDesc::UINT16 : TypeDesc::UINT8;
    ImageSpec spec(w, h, 1, td);
    spec.channelnames = {"Y"};
    spec.attribute("oiio:ColorSpace", "linear");
    for (int i = 0; i < nattrs; i++)
        spec.attribute(attrs[i].name, attrs[i].value);
    if (description)
        spec.attribute("ImageDescription", description);
    auto out = ImageOutput::create(path);
    if (!out)
        return nc_error(NC_EIMAGE, "%s: %s", path, OIIO::geterror().c_str());
    if (!out->open(path, spec))
        return nc_error(NC_EIMAGE, "%s: open for writing: %s", path, out->geterror().c_str());
    if (!out->write_image(td, px)) {
        std::string e = out->geterror();
        out->close();
        return nc_error(NC_EIMAGE, "%s: write: %s", path, e.c_str());
    }
    if (!out->close())
        return nc_error(NC_EIMAGE, "%s: close: %s", path, out->geterror().c_str());
    return 0;
}

extern "C" int nc__oiio_read(const char *path, float **px, int *w, int *h)
{
    auto in = ImageInput::open(path);
    if (!in)
        return nc_error(NC_EIMAGE, "%s: %s", path, OIIO::geterror().c_str());
    const ImageSpec &spec = in->spec();
    size_t n = (size_t)spec.width * (size_t)spec.height;
    float *buf = (float *)std::malloc(n * sizeof(float));
    if (!buf)
        return nc_error(-ENOMEM, "%s: out of memory", path);
    if (!in->read_image(0, 0, 0, 1, TypeDesc::FLOAT, buf)) {
        std::free(buf);
        return nc_error(NC_EIMAGE, "%s: read: %s", path, in->geterror().c_str());
    }
    *w = spec.width;
    *h = spec.height;
    *px = buf;
    return 0;
}

extern "C" int nc__oiio_read_attr(const char *path, const char *name, char *buf, size_t len)
{
    auto in = ImageInput::open(path);
    if (!in)
        return nc_error(NC_EIMAGE, "%s: %s", path, OIIO::geterror().c_str());
    const ParamValue *p = in->spec().find_attribute(name, TypeDesc::STRING);
    if (!p)
        return nc_error(NC_EIMAGE, "%s: no attribute '%s'", path, name);
    std::snprintf(buf, len, "%s", p->get_string().c_str());
    return 0;
}
