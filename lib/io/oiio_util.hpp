/*
** oiio_util.hpp — what both OpenImageIO readers (oiio.cpp: images,
** oiio_hf.cpp: heightfields) need alike: one-line error messages,
** attributes as text, and opening a file that may be hostile (internal).
*/
#ifndef OC_OIIO_UTIL_HPP
#define OC_OIIO_UTIL_HPP

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <memory>
#include <string>

extern "C" {
#include "core/error.h"
#include "io/infile.h"
#include "io/oiio.h"
#include "io/oiio_hf.h"

/* The bridge's entry points, gathered by oiio_host.cpp into its table. */
int oc_glue_encode(const oc_oiio_out *im, oc_oiio_sink sink, void *ud,
                   char *why, size_t whysize);
oc_image *oc_glue_read(const char *path, oc_error *err);
int oc_glue_read_raw(const char *path, const oc_oiio_raw *r, oc_error *err);
}

/* OpenImageIO messages may span lines; ours are one line. */
inline std::string oc_oiio_oneline(std::string s) {
  for (char &c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ')
    s.pop_back();
  return s.empty() ? std::string("unknown OpenImageIO error") : s;
}

/* An attribute's value as text: strings whole; numbers and arrays of them
** capped, they are not provenance. */
inline std::string oc_oiio_attr_text(const OIIO::ParamValue &p) {
  if (p.type() == OIIO::TypeDesc::STRING) {
    const char *s = *(const char *const *)p.data();
    return s ? s : "";
  }
  return p.get_string(64);
}

/* An image reader over a file we opened and checked ourselves. Members
** are destroyed in reverse order: the reader, its proxy, then the file. */
struct oc_oiio_input {
  struct closer {
    void operator()(FILE *f) const { std::fclose(f); }
  };
  std::unique_ptr<FILE, closer> file;
  std::unique_ptr<OIIO::Filesystem::IOFile> proxy;
  std::unique_ptr<OIIO::ImageInput> in;
};

/* Opens `path` through oc_infile_open (a regular file, the reader chosen
** by its signature: no other reader probes it) and reads its header.
** Returns false with `err` set (OC_EIO naming the path). */
inline bool oc_oiio_open_input(oc_oiio_input &x, const char *path,
                               const OIIO::ImageSpec &config, oc_error *err) {
  FILE *fp;
  const char *format;
  if (oc_infile_open(path, &fp, &format, err) != OC_OK) return false;
  x.file.reset(fp);
  x.proxy.reset(
      new OIIO::Filesystem::IOFile(fp, OIIO::Filesystem::IOProxy::Read));
  x.in = OIIO::ImageInput::create(format);
  OIIO::ImageSpec spec;
  if (!x.in || !x.in->supports("ioproxy") ||
      !x.in->set_ioproxy(x.proxy.get()) || !x.in->open(path, spec, config)) {
    std::string e = x.in ? x.in->geterror() : OIIO::geterror();
    oc_seterr(err, OC_EIO, "cannot read '%s': %s", path,
              oc_oiio_oneline(e).c_str());
    return false;
  }
  return true;
}

#endif
