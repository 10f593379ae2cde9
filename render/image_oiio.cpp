// image_oiio.cpp - the OpenImageIO back-end of image_io (EXR, TIFF, PNG):
// the module navcam-oiio.so, loaded on first use (image_io_impl.h). The
// only file that touches OpenImageIO; no physics and no policy here. It
// links nothing of NavCam's: its errors go back as text.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h" // the codes only
#include "core/le.h"
#include "render/image_io_impl.h"

using namespace OIIO;

namespace {

__attribute__((format(printf, 4, 5))) int fail(int code, char *err, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    std::vsnprintf(err, len, fmt, ap);
    va_end(ap);
    // One line: OpenImageIO's error text has a line per error it met.
    std::string one(err);
    while (!one.empty() && one.back() == '\n')
        one.pop_back();
    for (size_t at; (at = one.find('\n')) != std::string::npos;)
        one.replace(at, 1, "; ");
    std::snprintf(err, len, "%s", one.c_str());
    return code;
}

// TIFF's DateTime (tag 306) is "YYYY:MM:DD HH:MM:SS" or absent. OpenImageIO
// stamps the time of writing unless given a value, and writes "" as an
// empty tag, which strict TIFF validators call malformed: the empty entry is
// taken out of the first directory (the entries after it and the next
// directory's offset move up 12 bytes; nothing points into a directory).
// libtiff writes the host's byte order: a little-endian file is mended, a
// big-endian host's keeps the empty tag.
void drop_empty_datetime(std::vector<unsigned char> &v)
{
    uint8_t *b = v.data();
    if (v.size() < 8 || b[0] != 'I' || b[1] != 'I' || nc_le_get_u16(b + 2) != 42) // 43: BigTIFF, not written here
        return;
    const size_t ifd = nc_le_get_u32(b + 4);
    if (ifd < 8 || ifd > v.size() - 6)
        return;
    const size_t n = nc_le_get_u16(b + ifd);
    if (n == 0 || (v.size() - ifd - 6) / 12 < n)
        return;
    for (size_t i = 0; i < n; i++) {
        uint8_t *e = b + ifd + 2 + 12 * i;
        if (nc_le_get_u16(e) != 306)
            continue;
        if (nc_le_get_u16(e + 2) != 2 || nc_le_get_u32(e + 4) > 1) // ASCII, at most its NUL: empty
            return;
        std::memmove(e, e + 12, 12 * (n - 1 - i) + 4);
        std::memset(b + ifd + 2 + 12 * (n - 1) + 4, 0, 12);
        nc_le_put_u16(b + ifd, (uint16_t)(n - 1));
        return;
    }
}

int write_image(const char *path, const void *px, int w, int h, enum nc__pixel type, const struct nc_image_attr *attrs,
                int nattrs, const char *description, char *err, size_t elen)
{
    TypeDesc td = type == NC__PX_FLOAT ? TypeDesc::FLOAT : type == NC__PX_U16 ? TypeDesc::UINT16 : TypeDesc::UINT8;
    ImageSpec spec(w, h, 1, td);
    spec.channelnames = {"Y"};
    spec.attribute("oiio:ColorSpace", "linear");
    // No write time unless the caller gives one: OpenImageIO would stamp
    // the time of writing (TIFF DateTime, EXR capDate), and a file must be
    // the same bytes whenever it is written (docs/batch.md).
    spec.attribute("DateTime", "");
    for (int i = 0; i < nattrs; i++)
        if (std::strncmp(attrs[i].name, "fits:", 5)) // FITS keywords of their own (the WCS): FITS files only
            spec.attribute(attrs[i].name, attrs[i].value);
    if (description)
        spec.attribute("ImageDescription", description);
    // The file is encoded in memory and written here: OpenImageIO's PNG and
    // EXR writers do not report a failed write (a full disk, a file size
    // limit), and the caller must know that the file is whole. (The buffer
    // outlives the writer, whose destructor may still write to it.)
    std::vector<unsigned char> bytes;
    Filesystem::IOVecOutput mem(bytes);
    auto out = ImageOutput::create(path);
    if (!out)
        return fail(NC_EIMAGE, err, elen, "%s: %s", path, OIIO::geterror().c_str());
    if (!out->set_ioproxy(&mem))
        return fail(NC_EIMAGE, err, elen, "%s: %s cannot encode to memory", path, out->format_name());
    // OpenImageIO deflates a float TIFF with the floating-point predictor
    // (3), which some readers cannot undo (Python's tifffile without
    // imagecodecs), and an integer one with horizontal differencing (2);
    // deflate alone is read everywhere, by zlib alone.
    if (!std::strcmp(out->format_name(), "tiff"))
        spec.attribute("tiff:Predictor", 1);
    if (!out->open(path, spec))
        return fail(NC_EIMAGE, err, elen, "%s: open for writing: %s", path, out->geterror().c_str());
    if (!out->write_image(td, px)) {
        std::string e = out->geterror();
        out->close();
        return fail(NC_EIMAGE, err, elen, "%s: write: %s", path, e.c_str());
    }
    if (!out->close())
        return fail(NC_EIMAGE, err, elen, "%s: close: %s", path, out->geterror().c_str());
    if (!std::strcmp(out->format_name(), "tiff"))
        drop_empty_datetime(bytes);
    FILE *f = std::fopen(path, "wb");
    if (!f)
        return fail(-errno, err, elen, "%s: %s", path, std::strerror(errno));
    const bool whole = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size() && std::fflush(f) == 0;
    const int e = errno;
    if (std::fclose(f) != 0 || !whole)
        return fail(-(whole ? errno : e), err, elen, "%s: write: %s", path, std::strerror(whole ? errno : e));
    return 0;
}

int read_image(const char *path, float **px, int *w, int *h, char *err, size_t elen)
{
    auto in = ImageInput::open(path);
    if (!in)
        return fail(NC_EIMAGE, err, elen, "%s: %s", path, OIIO::geterror().c_str());
    const ImageSpec &spec = in->spec();
    size_t n = (size_t)spec.width * (size_t)spec.height;
    float *buf = (float *)std::malloc(n * sizeof(float));
    if (!buf)
        return fail(-ENOMEM, err, elen, "%s: out of memory", path);
    // A file cut short reads "successfully" with its missing rows left as they
    // were (OpenImageIO's TIFF reader says so only in its error text).
    bool ok = in->read_image(0, 0, 0, 1, TypeDesc::FLOAT, buf);
    std::string e = in->geterror();
    if (!ok || !e.empty()) {
        std::free(buf);
        return fail(NC_EIMAGE, err, elen, "%s: read: %s", path, e.empty() ? "failed" : e.c_str());
    }
    *w = spec.width;
    *h = spec.height;
    *px = buf;
    return 0;
}

int read_attr(const char *path, const char *name, char *buf, size_t len, char *err, size_t elen)
{
    auto in = ImageInput::open(path);
    if (!in)
        return fail(NC_EIMAGE, err, elen, "%s: %s", path, OIIO::geterror().c_str());
    const ParamValue *p = in->spec().find_attribute(name, TypeDesc::STRING);
    if (!p)
        return fail(NC_EIMAGE, err, elen, "%s: no attribute '%s'", path, name);
    std::snprintf(buf, len, "%s", p->get_string().c_str());
    return 0;
}

const struct nc__oiio_api api = {NC__OIIO_ABI, write_image, read_image, read_attr};

} // namespace

extern "C" __attribute__((visibility("default"))) const struct nc__oiio_api *nc__oiio_module(void) { return &api; }
