/*
** oiio_hf.cpp — exact heightfield reads through OpenImageIO: the first
** channel of an image as stored (see lib/io/oiio_hf.h); part of
** liboutcrop_oiio.so (io/oiio_glue.h).
**
** Every entry point catches every exception: C callers get a status and
** a message, never an unwinding stack.
*/
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "oiio_util.hpp"
#include "io/oiio_hf.h"

extern "C" {
#include "core/error.h"
}

using OIIO::ImageInput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

/* Integer samples are read as they are stored into the front of the float
** buffer, then widened in place from the last one down: sample k's float
** occupies bytes [4k, 4k + 4), past every narrower sample still unread. */
template <typename T> void widen(float *dst, size_t n) {
  const T *src = reinterpret_cast<const T *>(dst);
  for (size_t k = n; k-- > 0;) {
    T v;
    std::memcpy(&v, src + k, sizeof v);
    dst[k] = static_cast<float>(v);
  }
}

/* Rows read between two polls of the progress callback. */
const int STRIP = 64;

int read_raw(const char *path, const oc_oiio_raw *r, oc_error *err) {
  ImageSpec config;
  /* Values as stored: never multiplied by an alpha channel. */
  config.attribute("oiio:UnassociatedAlpha", 1);
  oc_oiio_input input;
  if (!oc_oiio_open_input(input, path, config, err))
    return err ? err->code : OC_EIO;
  ImageInput *in = input.in.get();
  const ImageSpec &spec = in->spec();
  if (spec.deep || spec.depth > 1 || spec.nchannels < 1)
    return oc_seterr(err, OC_EUNSUPPORTED,
                     "cannot read '%s': deep, volume and channel-less "
                     "images are not heightfields",
                     path);
  if (spec.width < 1 || spec.height < 1)
    return oc_seterr(err, OC_EIO,
                     "cannot read '%s': it declares %d x %d pixels", path,
                     spec.width, spec.height);
  for (const auto &p : spec.extra_attribs) {
    std::string v = oc_oiio_attr_text(p);
    if (r->attr) r->attr(r->ud, p.name().c_str(), v.c_str());
  }
  TypeDesc type = spec.channelformat(0);
  /* `begin` refuses sizes over the grid limit before anything is
  ** allocated; the file's declared size is not trusted further. */
  float *dst = r->begin(r->ud, spec.width, spec.height, spec.nchannels,
                        type.c_str(), err);
  if (!dst) return err ? err->code : OC_EINVAL;
  size_t n = (size_t)spec.width * (size_t)spec.height;
  TypeDesc mem = TypeDesc::FLOAT;
  switch (type.basetype) {
  case TypeDesc::UINT8:
  case TypeDesc::INT8:
  case TypeDesc::UINT16:
  case TypeDesc::INT16:
  case TypeDesc::UINT32:
  case TypeDesc::INT32:
    mem = type; /* no normalization: widened below */
    break;
  default: /* half, float exactly; the rest converted by OpenImageIO */
    break;
  }
  const oc_progress *pr = &r->progress;
  /* Scanline files are read in strips, polling for cancellation between
  ** them; tiled ones whole. Row y's samples go to (T *)dst + y * width. */
  bool ok = true;
  int strip = spec.tile_width ? spec.height : STRIP;
  for (int y = spec.y; ok && y < spec.y + spec.height; y += strip) {
    if (pr->fn && pr->fn(pr->ud, (double)(y - spec.y) / spec.height))
      return oc_seterr(err, OC_ECANCEL, "loading '%s' cancelled", path);
    int end = std::min(y + strip, spec.y + spec.height);
    char *at = (char *)dst + (size_t)(y - spec.y) * spec.width * mem.size();
    ok = spec.tile_width ? in->read_image(0, 0, 0, 1, mem, at)
                         : in->read_scanlines(0, 0, y, end, 0, 0, 1, mem, at);
  }
  if (!ok)
    return oc_seterr(err, OC_EIO, "cannot read '%s': %s", path,
                     oc_oiio_oneline(in->geterror()).c_str());
  switch (mem.basetype) {
  case TypeDesc::UINT8:
    widen<uint8_t>(dst, n);
    break;
  case TypeDesc::INT8:
    widen<int8_t>(dst, n);
    break;
  case TypeDesc::UINT16:
    widen<uint16_t>(dst, n);
    break;
  case TypeDesc::INT16:
    widen<int16_t>(dst, n);
    break;
  case TypeDesc::UINT32:
    widen<uint32_t>(dst, n);
    break;
  case TypeDesc::INT32:
    widen<int32_t>(dst, n);
    break;
  default:
    break;
  }
  return OC_OK;
}

} // namespace

extern "C" int oc_glue_read_raw(const char *path, const oc_oiio_raw *r,
                                oc_error *err) {
  try {
    return read_raw(path, r, err);
  } catch (const std::bad_alloc &) {
    return oc_seterr(err, OC_ENOMEM, "cannot read '%s': out of memory", path);
  } catch (const std::exception &e) {
    return oc_seterr(err, OC_EIO, "cannot read '%s': OpenImageIO failed: %s",
                     path, e.what());
  } catch (...) {
    return oc_seterr(err, OC_EIO, "cannot read '%s': OpenImageIO failed", path);
  }
}
