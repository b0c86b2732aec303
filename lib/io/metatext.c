/*
** metatext.c — quoting metadata values into "key=value" lines and reading
** them back (see metatext.h).
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/metatext.h"

static int needs_quotes(const char *s) {
  for (; *s; s++) {
    unsigned char c = (unsigned char)*s;
    if (c <= ' ' || c == 0x7f || c == '"' || c == '\\') return 1;
  }
  return 0;
}

/* The escape of c, or NULL when c stands for itself. */
static const char *escape(unsigned char c, char tmp[5]) {
  switch (c) {
  case '"':
    return "\\\"";
  case '\\':
    return "\\\\";
  case '\n':
    return "\\n";
  case '\t':
    return "\\t";
  case '\r':
    return "\\r";
  }
  if (c < ' ' || c == 0x7f) {
    snprintf(tmp, 5, "\\%03u", (unsigned)c);
    return tmp;
  }
  return NULL;
}

size_t oc_meta_quoted_size(const char *value) {
  if (!needs_quotes(value)) return strlen(value) + 1;
  size_t n = 3; /* quotes and NUL */
  for (const char *s = value; *s; s++) {
    char tmp[5];
    const char *e = escape((unsigned char)*s, tmp);
    n += e ? strlen(e) : 1;
  }
  return n;
}

size_t oc_meta_quote(const char *value, char *out) {
  if (!needs_quotes(value)) {
    size_t n = strlen(value);
    memcpy(out, value, n + 1);
    return n;
  }
  char *o = out;
  *o++ = '"';
  for (const char *s = value; *s; s++) {
    char tmp[5];
    const char *e = escape((unsigned char)*s, tmp);
    if (!e) {
      *o++ = *s;
      continue;
    }
    size_t k = strlen(e);
    memcpy(o, e, k);
    o += k;
  }
  *o++ = '"';
  *o = '\0';
  return (size_t)(o - out);
}

/* Unquotes the quoted value s[0..n) in place (s[0] is '"'); 0, or -1 when
** it is not one well-formed quoted string. */
static int unquote(char *s, size_t n) {
  char *o = s;
  size_t i = 1;
  while (i < n && s[i] != '"') {
    char c = s[i++];
    if (c != '\\') {
      *o++ = c;
      continue;
    }
    if (i >= n) return -1;
    c = s[i++];
    if (c == 'n')
      *o++ = '\n';
    else if (c == 't')
      *o++ = '\t';
    else if (c == 'r')
      *o++ = '\r';
    else if (c == '"' || c == '\\')
      *o++ = c;
    else if (c >= '0' && c <= '3' && i + 1 < n && s[i] >= '0' && s[i] <= '7' &&
             s[i + 1] >= '0' && s[i + 1] <= '7') {
      int v = (c - '0') * 64 + (s[i] - '0') * 8 + (s[i + 1] - '0');
      if (v == 0) return -1; /* would cut the string */
      *o++ = (char)v;
      i += 2;
    } else {
      return -1;
    }
  }
  if (i != n - 1) return -1; /* the closing quote ends the line */
  *o = '\0';
  return 0;
}

int oc_meta_unfold(const char *text,
                   void (*take)(void *ud, const char *key, const char *value),
                   void *ud) {
  size_t len = strlen(text);
  char *buf = malloc(len + 1);
  if (!buf) return -1;
  memcpy(buf, text, len + 1);
  char *line = buf;
  while (*line) {
    size_t n = strcspn(line, "\n");
    char *next = line[n] ? line + n + 1 : line + n;
    line[n] = '\0';
    char *eq = strchr(line, '=');
    if (eq && eq != line) {
      char *v = eq + 1;
      size_t vn = strlen(v);
      *eq = '\0';
      if (v[0] != '"' || unquote(v, vn) == 0) take(ud, line, v);
    }
    line = next;
  }
  free(buf);
  return 0;
}
