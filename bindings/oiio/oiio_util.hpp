/*
** oiio_util.hpp — what both OpenImageIO readers (oiio.cpp: images,
** oiio_hf.cpp: heightfields) need alike: one-line error messages and
** attributes as text (internal).
*/
#ifndef OC_OIIO_UTIL_HPP
#define OC_OIIO_UTIL_HPP

#include <OpenImageIO/imageio.h>

#include <string>

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

#endif
