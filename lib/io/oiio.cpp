/*
** oiio.cpp — the bridge from lib/io to OpenImageIO: plain C functions
** (as lib/io/oiio.h describes them) that read and write image files,
** part of liboutcrop_oiio.so (io/oiio_glue.h), loaded on first use.
**
** With oiio_hf.cpp the only C++ in the project. Every entry point catches
** every exception: C callers get a status code and a message, never an
** unwinding stack.
*/
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include <strings.h>

#include "oiio_util.hpp"
#include "io/metatext.h"
#include "io/oiio.h"

extern "C" {
#include "core/error.h"
}

using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

namespace {

int say(char *why, size_t n, int code, const char *fmt, ...) {
  if (why && n) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, n, fmt, ap);
    va_end(ap);
  }
  return code;
}

/* String attributes the TIFF and JPEG writers store in a tag of their
** own; any other key would be silently dropped by those writers. */
bool native_text(const char *format, const char *key) {
  /* OpenImageIO's own attributes (the writer's colour space tag) are
  ** settings every writer understands, not text to fold */
  if (strncasecmp(key, "oiio:", 5) == 0) return true;
  static const char *const tiff[] = {
      "Artist",       "Copyright",    "DateTime",
      "DocumentName", "HostComputer", "ImageDescription",
      "Make",         "Model",        "Software"};
  static const char *const jpeg[] = {"ImageDescription", "Software", "Artist",
                                     "Copyright", "DateTime"};
  if (std::strcmp(format, "tiff") == 0) {
    for (const char *k : tiff)
      if (strcasecmp(k, key) == 0) return true;
    return false;
  }
  if (std::strcmp(format, "jpeg") == 0) {
    for (const char *k : jpeg)
      if (strcasecmp(k, key) == 0) return true;
    return false;
  }
  return true;
}

/* The formats whose only free text is the ImageDescription. */
bool folds(const char *format) {
  return std::strcmp(format, "tiff") == 0 || std::strcmp(format, "jpeg") == 0;
}

/* A key that can start a "key=value" line. */
bool line_key(const char *k) {
  if (!*k) return false;
  for (; *k; k++)
    if ((unsigned char)*k < ' ' || *k == '=' || *k == 0x7f) return false;
  return true;
}

/* Keys the format cannot hold become lines of the ImageDescription, each
** value quoted (io/metatext.h) so that none can forge another line; a
** description given by the caller becomes a line too, so that the whole
** text is lines we wrote. */
void describe(const char *format, const oc_oiio_out *im, ImageSpec &spec) {
  std::string folded;
  for (size_t i = 0; i < im->nmeta; i++) {
    const char *k = im->meta[2 * i], *v = im->meta[2 * i + 1];
    bool own_line = folds(format) && strcasecmp(k, "ImageDescription") == 0;
    if (native_text(format, k) && !own_line) {
      spec.attribute(k, v);
    } else if (line_key(k)) {
      std::string q(oc_meta_quoted_size(v), '\0');
      q.resize(oc_meta_quote(v, &q[0]));
      folded += k;
      folded += '=';
      folded += q;
      folded += '\n';
    }
  }
  if (!folded.empty()) {
    folded.pop_back();
    spec.attribute("ImageDescription", folded);
  }
  /* The TIFF and EXR writers stamp the current time unless a DateTime is
  ** present; an empty one is written as nothing (TIFF) or an empty
  ** capDate (EXR), which keeps repeated writes byte-identical. */
  if (!spec.find_attribute("DateTime")) spec.attribute("DateTime", "");
}

int encode(const oc_oiio_out *im, oc_oiio_sink sink, void *ud, char *why,
           size_t n) {
  TypeDesc file, mem;
  switch (im->type) {
  case OC_OIIO_U8:
    file = mem = TypeDesc::UINT8;
    break;
  case OC_OIIO_U16:
    file = mem = TypeDesc::UINT16;
    break;
  case OC_OIIO_HALF:
    file = TypeDesc::HALF;
    mem = TypeDesc::FLOAT;
    break;
  case OC_OIIO_F32:
    file = mem = TypeDesc::FLOAT;
    break;
  default:
    return say(why, n, OC_EIO, "unknown sample type %d", (int)im->type);
  }
  auto out = ImageOutput::create(im->format);
  if (!out)
    return say(why, n, OC_EIO, "%s", oc_oiio_oneline(OIIO::geterror()).c_str());
  ImageSpec spec(im->width, im->height, im->channels, file);
  for (int c = 0; c < im->channels; c++)
    spec.channelnames[c] = im->channel_names[c];
  spec.alpha_channel = im->alpha;
  /* Values are written as given: no division by alpha on the way out. */
  if (im->alpha >= 0) spec.attribute("oiio:UnassociatedAlpha", 1);
  describe(im->format, im, spec);
  /* Encoded into memory: the disk is written by the caller, through one
  ** path that checks every write (libjpeg, for one, would otherwise exit
  ** the process on a failed write). The formats we write all take a
  ** proxy; one that did not would write a file named "-", never ours. */
  OIIO::Filesystem::IOVecOutput vec;
  void *proxy = &vec;
  if (!out->supports("ioproxy"))
    return say(why, n, OC_EIO, "OpenImageIO cannot encode %s into memory",
               im->format);
  spec.attribute("oiio:ioproxy", TypeDesc::PTR, &proxy);
  if (!out->open("-", spec))
    return say(why, n, OC_EIO, "%s", oc_oiio_oneline(out->geterror()).c_str());
  bool ok = out->write_image(mem, im->pixels);
  std::string e = ok ? std::string() : out->geterror();
  ok = out->close() && ok;
  if (!ok) {
    if (e.empty()) e = out->geterror();
    return say(why, n, OC_EIO, "%s", oc_oiio_oneline(e).c_str());
  }
  const std::vector<unsigned char> &bytes = vec.buffer();
  return sink(ud, bytes.data(), bytes.size(), why, n);
}

void set_meta(void *img, const char *key, const char *value) {
  oc_image_set_meta(static_cast<oc_image *>(img), key, value, nullptr);
}

struct image_deleter {
  void operator()(oc_image *img) const { oc_image_free(img); }
};

oc_image *read_file(const char *path, oc_error *err) {
  ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  oc_oiio_input input;
  if (!oc_oiio_open_input(input, path, config, err)) return nullptr;
  ImageInput *in = input.in.get();
  const ImageSpec &spec = in->spec();
  if (spec.deep || spec.depth > 1) {
    oc_seterr(err, OC_EUNSUPPORTED,
              "cannot read '%s': deep and volume images "
              "are not supported",
              path);
    return nullptr;
  }
  oc_error sub;
  std::unique_ptr<oc_image, image_deleter> img(
      oc_image_new(spec.width, spec.height, spec.nchannels, &sub));
  if (!img) {
    oc_seterr(err, sub.code, "cannot read '%s': %s", path, sub.msg);
    return nullptr;
  }
  if (!in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT,
                      oc_image_data(img.get()))) {
    oc_seterr(err, OC_EIO, "cannot read '%s': %s", path,
              oc_oiio_oneline(in->geterror()).c_str());
    return nullptr;
  }
  /* Names and attributes the image model refuses (odd characters,
  ** encoding settings such as "compression") are left out. */
  for (int c = 0; c < spec.nchannels && c < (int)spec.channelnames.size(); c++)
    oc_image_set_channel_name(img.get(), c, spec.channelnames[c].c_str(),
                              nullptr);
  for (const auto &p : spec.extra_attribs) {
    std::string v = oc_oiio_attr_text(p);
    oc_image_set_meta(img.get(), p.name().c_str(), v.c_str(), nullptr);
  }
  /* The lines the writer folded into a TIFF or JPEG description come back
  ** as the keys they were (only there: in other formats a description is
  ** free text, not ours to parse). */
  if (folds(in->format_name())) {
    std::string d = spec.get_string_attribute("ImageDescription");
    if (oc_meta_unfold(d.c_str(), set_meta, img.get()) != 0)
      throw std::bad_alloc();
  }
  return img.release();
}

} // namespace

extern "C" int oc_glue_encode(const oc_oiio_out *im, oc_oiio_sink sink,
                              void *ud, char *why, size_t whysize) {
  try {
    return encode(im, sink, ud, why, whysize);
  } catch (const std::bad_alloc &) {
    return say(why, whysize, OC_EIO, "out of memory");
  } catch (const std::exception &e) {
    return say(why, whysize, OC_EIO, "OpenImageIO failed: %s", e.what());
  } catch (...) {
    return say(why, whysize, OC_EIO, "OpenImageIO failed");
  }
}

extern "C" oc_image *oc_glue_read(const char *path, oc_error *err) {
  try {
    return read_file(path, err);
  } catch (const std::bad_alloc &) {
    oc_seterr(err, OC_ENOMEM, "cannot read '%s': out of memory", path);
  } catch (const std::exception &e) {
    oc_seterr(err, OC_EIO, "cannot read '%s': OpenImageIO failed: %s", path,
              e.what());
  } catch (...) {
    oc_seterr(err, OC_EIO, "cannot read '%s': OpenImageIO failed", path);
  }
  return nullptr;
}
