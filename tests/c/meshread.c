/*
** meshread.c — the tests' own mesh reader and checker (see meshread.h):
** a JSON parser, PLY / OBJ / GLB readers working on the whole file in
** memory, and the topological and geometric checks. It shares no code
** with lib/, so a writer bug cannot hide behind the same bug here.
*/
#include "meshread.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* Formats into `why` (when there is room) and returns 0, so that a
** failing step can `return say(...)`. */
static int say(char *why, size_t size, const char *fmt, ...) {
  if (why && size) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, size, fmt, ap);
    va_end(ap);
  }
  return 0;
}

/* ======================================================================
** JSON
** ====================================================================== */

#define JSON_DEPTH 64

typedef struct jp {
  const char *s, *end;
  char *why;
  size_t whysize;
} jp;

static int jerr(jp *p, const char *what) {
  return say(p->why, p->whysize, "JSON: %s (%ld bytes before the end)", what,
             (long)(p->end - p->s));
}

static void jws(jp *p) {
  while (p->s < p->end &&
         (*p->s == ' ' || *p->s == '\t' || *p->s == '\n' || *p->s == '\r'))
    p->s++;
}

static void jclear(mr_json *v) {
  if (!v) return;
  for (size_t i = 0; i < v->n; i++) {
    jclear(&v->items[i]);
    if (v->keys) free(v->keys[i]);
  }
  free(v->items);
  free(v->keys);
  free(v->string);
  memset(v, 0, sizeof *v);
}

void mr_json_free(mr_json *v) {
  jclear(v);
  free(v);
}

static int hex4(jp *p, unsigned *out) {
  if (p->end - p->s < 4) return jerr(p, "truncated \\u escape");
  unsigned v = 0;
  for (int i = 0; i < 4; i++) {
    char c = *p->s++;
    v <<= 4;
    if (c >= '0' && c <= '9')
      v |= (unsigned)(c - '0');
    else if (c >= 'a' && c <= 'f')
      v |= (unsigned)(c - 'a' + 10);
    else if (c >= 'A' && c <= 'F')
      v |= (unsigned)(c - 'A' + 10);
    else
      return jerr(p, "bad hex digit in \\u escape");
  }
  *out = v;
  return 1;
}

/* Appends code point cp as UTF-8 (buf has room for 4 more bytes). */
static size_t utf8(char *buf, unsigned cp) {
  if (cp < 0x80) {
    buf[0] = (char)cp;
    return 1;
  }
  if (cp < 0x800) {
    buf[0] = (char)(0xC0 | cp >> 6);
    buf[1] = (char)(0x80 | (cp & 0x3F));
    return 2;
  }
  if (cp < 0x10000) {
    buf[0] = (char)(0xE0 | cp >> 12);
    buf[1] = (char)(0x80 | (cp >> 6 & 0x3F));
    buf[2] = (char)(0x80 | (cp & 0x3F));
    return 3;
  }
  buf[0] = (char)(0xF0 | cp >> 18);
  buf[1] = (char)(0x80 | (cp >> 12 & 0x3F));
  buf[2] = (char)(0x80 | (cp >> 6 & 0x3F));
  buf[3] = (char)(0x80 | (cp & 0x3F));
  return 4;
}

/* At the opening quote; the string's bytes go to a malloc'ed *out. The
** decoded text is never longer than the source, so one allocation of the
** source's remaining length bounds it. */
static int jstring(jp *p, char **out) {
  p->s++; /* '"' */
  const char *q = p->s;
  while (q < p->end && *q != '"')
    q += *q == '\\' ? 2 : 1;
  if (q >= p->end) return jerr(p, "unterminated string");
  char *buf = malloc((size_t)(q - p->s) + 1);
  if (!buf) return jerr(p, "out of memory");
  size_t n = 0;
  while (*p->s != '"') {
    unsigned char c = (unsigned char)*p->s++;
    if (c < 0x20) {
      free(buf);
      return jerr(p, "control character in string");
    }
    if (c != '\\') {
      buf[n++] = (char)c;
      continue;
    }
    char e = *p->s++;
    unsigned cp;
    switch (e) {
    case '"':
      buf[n++] = '"';
      break;
    case '\\':
      buf[n++] = '\\';
      break;
    case '/':
      buf[n++] = '/';
      break;
    case 'b':
      buf[n++] = '\b';
      break;
    case 'f':
      buf[n++] = '\f';
      break;
    case 'n':
      buf[n++] = '\n';
      break;
    case 'r':
      buf[n++] = '\r';
      break;
    case 't':
      buf[n++] = '\t';
      break;
    case 'u':
      if (!hex4(p, &cp)) {
        free(buf);
        return 0;
      }
      if (cp >= 0xD800 && cp < 0xDC00) { /* needs its low surrogate */
        unsigned lo;
        if (p->end - p->s < 6 || p->s[0] != '\\' || p->s[1] != 'u') {
          free(buf);
          return jerr(p, "lone high surrogate");
        }
        p->s += 2;
        if (!hex4(p, &lo)) {
          free(buf);
          return 0;
        }
        if (lo < 0xDC00 || lo > 0xDFFF) {
          free(buf);
          return jerr(p, "bad low surrogate");
        }
        cp = 0x10000 + ((cp - 0xD800) << 10) + (lo - 0xDC00);
      } else if (cp >= 0xDC00 && cp <= 0xDFFF) {
        free(buf);
        return jerr(p, "lone low surrogate");
      } else if (cp == 0) {
        free(buf);
        return jerr(p, "\\u0000 in string");
      }
      n += utf8(buf + n, cp); /* at most 4 bytes for 6 or 12 source bytes */
      break;
    default:
      free(buf);
      return jerr(p, "bad escape in string");
    }
  }
  p->s++; /* '"' */
  buf[n] = '\0';
  *out = buf;
  return 1;
}

static int digits(jp *p) {
  const char *s = p->s;
  while (p->s < p->end && *p->s >= '0' && *p->s <= '9')
    p->s++;
  return p->s > s;
}

/* The strict JSON number grammar, then strtod on a bounded copy. */
static int jnumber(jp *p, double *out) {
  const char *start = p->s;
  if (*p->s == '-') p->s++;
  if (p->s < p->end && *p->s == '0')
    p->s++;
  else if (!digits(p))
    return jerr(p, "bad number");
  if (p->s < p->end && *p->s == '.') {
    p->s++;
    if (!digits(p)) return jerr(p, "no digit after the decimal point");
  }
  if (p->s < p->end && (*p->s == 'e' || *p->s == 'E')) {
    p->s++;
    if (p->s < p->end && (*p->s == '+' || *p->s == '-')) p->s++;
    if (!digits(p)) return jerr(p, "no digit in the exponent");
  }
  char tmp[128];
  size_t n = (size_t)(p->s - start);
  if (n >= sizeof tmp) return jerr(p, "number too long");
  memcpy(tmp, start, n);
  tmp[n] = '\0';
  *out = strtod(tmp, NULL);
  return 1;
}

static int jliteral(jp *p, const char *word, mr_jtype t, mr_json *v) {
  size_t n = strlen(word);
  if ((size_t)(p->end - p->s) < n || memcmp(p->s, word, n) != 0)
    return jerr(p, "unexpected character");
  p->s += n;
  v->type = t;
  return 1;
}

static int jvalue(jp *p, mr_json *v, int depth);

/* Grows the containers of v to hold one more member. */
static int jgrow(jp *p, mr_json *v, size_t *cap) {
  if (v->n < *cap) return 1;
  size_t nc = *cap ? 2 * *cap : 8;
  mr_json *items = realloc(v->items, nc * sizeof *items);
  if (!items) return jerr(p, "out of memory");
  v->items = items;
  if (v->type == MR_JOBJECT) {
    char **keys = realloc(v->keys, nc * sizeof *keys);
    if (!keys) return jerr(p, "out of memory");
    v->keys = keys;
  }
  *cap = nc;
  return 1;
}

/* At '[' or '{'; on failure v holds nothing. */
static int jcontainer(jp *p, mr_json *v, int depth) {
  int object = *p->s == '{';
  char close = object ? '}' : ']';
  v->type = object ? MR_JOBJECT : MR_JARRAY;
  size_t cap = 0;
  p->s++;
  jws(p);
  if (p->s < p->end && *p->s == close) {
    p->s++;
    return 1;
  }
  for (;;) {
    if (!jgrow(p, v, &cap)) goto fail;
    char *key = NULL;
    if (object) {
      jws(p);
      if (p->s >= p->end || *p->s != '"') {
        jerr(p, "object key expected");
        goto fail;
      }
      if (!jstring(p, &key)) goto fail;
      for (size_t i = 0; i < v->n; i++)
        if (strcmp(v->keys[i], key) == 0) {
          free(key);
          jerr(p, "duplicate key");
          goto fail;
        }
      jws(p);
      if (p->s >= p->end || *p->s != ':') {
        free(key);
        jerr(p, "':' expected");
        goto fail;
      }
      p->s++;
    }
    memset(&v->items[v->n], 0, sizeof *v->items);
    if (!jvalue(p, &v->items[v->n], depth + 1)) {
      free(key);
      goto fail;
    }
    if (object) v->keys[v->n] = key;
    v->n++;
    jws(p);
    if (p->s < p->end && *p->s == ',') {
      p->s++;
      continue;
    }
    if (p->s < p->end && *p->s == close) {
      p->s++;
      return 1;
    }
    jerr(p, object ? "',' or '}' expected" : "',' or ']' expected");
    goto fail;
  }
fail:
  jclear(v);
  return 0;
}

static int jvalue(jp *p, mr_json *v, int depth) {
  if (depth > JSON_DEPTH) return jerr(p, "nested too deeply");
  jws(p);
  if (p->s >= p->end) return jerr(p, "value expected");
  switch (*p->s) {
  case '{':
  case '[':
    return jcontainer(p, v, depth);
  case '"':
    v->type = MR_JSTRING;
    return jstring(p, &v->string);
  case 't':
    return jliteral(p, "true", MR_JTRUE, v);
  case 'f':
    return jliteral(p, "false", MR_JFALSE, v);
  case 'n':
    return jliteral(p, "null", MR_JNULL, v);
  default:
    if (*p->s == '-' || (*p->s >= '0' && *p->s <= '9')) {
      v->type = MR_JNUMBER;
      return jnumber(p, &v->number);
    }
    return jerr(p, "unexpected character");
  }
}

mr_json *mr_json_parse(const char *text, size_t len, char *why,
                       size_t whysize) {
  jp p = {text, text + len, why, whysize};
  mr_json *v = calloc(1, sizeof *v);
  if (!v) {
    say(why, whysize, "JSON: out of memory");
    return NULL;
  }
  if (!jvalue(&p, v, 0)) {
    free(v);
    return NULL;
  }
  jws(&p);
  if (p.s != p.end) {
    jerr(&p, "text after the value");
    mr_json_free(v);
    return NULL;
  }
  return v;
}

const mr_json *mr_json_get(const mr_json *v, const char *key) {
  if (!v || v->type != MR_JOBJECT) return NULL;
  for (size_t i = 0; i < v->n; i++)
    if (strcmp(v->keys[i], key) == 0) return &v->items[i];
  return NULL;
}

const mr_json *mr_json_at(const mr_json *v, size_t i) {
  if (!v || v->type != MR_JARRAY || i >= v->n) return NULL;
  return &v->items[i];
}

const char *mr_json_str(const mr_json *v) {
  return v && v->type == MR_JSTRING ? v->string : NULL;
}

/* ======================================================================
** Files and little-endian
** ====================================================================== */

unsigned char *mr_slurp(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 1 << 16, n = 0;
  unsigned char *buf = malloc(cap);
  while (buf) {
    n += fread(buf + n, 1, cap - n, f);
    if (n < cap) break;
    unsigned char *b = realloc(buf, 2 * cap);
    if (!b) {
      free(buf);
      buf = NULL;
      break;
    }
    buf = b;
    cap *= 2;
  }
  if (buf && ferror(f)) {
    free(buf);
    buf = NULL;
  }
  fclose(f);
  if (buf) *len = n;
  return buf;
}

int mr_same_bytes(const char *a, const char *b) {
  size_t na = 0, nb = 0;
  unsigned char *da = mr_slurp(a, &na), *db = mr_slurp(b, &nb);
  int same = da && db && na == nb && memcmp(da, db, na) == 0;
  free(da);
  free(db);
  return same;
}

static uint32_t le32(const unsigned char *p) {
  return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 |
         (uint32_t)p[3] << 24;
}

static float lef32(const unsigned char *p) {
  uint32_t u = le32(p);
  float f;
  memcpy(&f, &u, sizeof f);
  return f;
}

static mr_mesh *new_mesh(mr_format fmt, size_t nv, size_t nt, int normals,
                         int colours, char *why, size_t ws) {
  mr_mesh *m = calloc(1, sizeof *m);
  if (!m) return say(why, ws, "out of memory"), NULL;
  m->format = fmt;
  m->nv = nv;
  m->nt = nt;
  /* At least one element, so that an empty mesh still has arrays. */
  m->pos = malloc((3 * nv + 1) * sizeof(float));
  m->nrm = normals ? malloc((3 * nv + 1) * sizeof(float)) : NULL;
  m->col = colours ? malloc((3 * nv + 1) * sizeof(float)) : NULL;
  m->tri = malloc((3 * nt + 1) * sizeof(uint32_t));
  if (!m->pos || !m->tri || (normals && !m->nrm) || (colours && !m->col)) {
    mr_free(m);
    say(why, ws, "out of memory for %zu vertices, %zu triangles", nv, nt);
    return NULL;
  }
  return m;
}

void mr_free(mr_mesh *m) {
  if (!m) return;
  free(m->pos);
  free(m->nrm);
  free(m->col);
  free(m->tri);
  mr_json_free(m->gltf);
  free(m);
}

/* ======================================================================
** PLY (binary little-endian)
** ====================================================================== */

enum { MAXPROP = 16, MAXELEM = 8 };

typedef struct ply_prop {
  char name[64];
  int type;       /* byte size of a scalar, negative for list */
  int kind;       /* 'i' signed, 'u' unsigned, 'f' float */
  int count_size; /* list: size of the uchar/ushort/uint count */
  int count_kind;
} ply_prop;

typedef struct ply_elem {
  char name[64];
  size_t count;
  int nprop;
  ply_prop prop[MAXPROP];
} ply_elem;

/* Size and kind of a PLY scalar type name; 0 when unknown. */
static int ply_type(const char *t, int *kind) {
  static const struct {
    const char *name;
    int size, kind;
  } types[] = {{"char", 1, 'i'},   {"int8", 1, 'i'},    {"uchar", 1, 'u'},
               {"uint8", 1, 'u'},  {"short", 2, 'i'},   {"int16", 2, 'i'},
               {"ushort", 2, 'u'}, {"uint16", 2, 'u'},  {"int", 4, 'i'},
               {"int32", 4, 'i'},  {"uint", 4, 'u'},    {"uint32", 4, 'u'},
               {"float", 4, 'f'},  {"float32", 4, 'f'}, {"double", 8, 'f'},
               {"float64", 8, 'f'}};
  for (size_t i = 0; i < sizeof types / sizeof *types; i++)
    if (strcmp(t, types[i].name) == 0) {
      *kind = types[i].kind;
      return types[i].size;
    }
  return 0;
}

static double ply_scalar(const unsigned char *p, int size, int kind) {
  switch (size) {
  case 1:
    return kind == 'i' ? (double)(int8_t)p[0] : (double)p[0];
  case 2: {
    uint16_t u = (uint16_t)(p[0] | p[1] << 8);
    return kind == 'i' ? (double)(int16_t)u : (double)u;
  }
  case 4: {
    uint32_t u = le32(p);
    if (kind == 'f') return lef32(p);
    return kind == 'i' ? (double)(int32_t)u : (double)u;
  }
  default: {
    uint64_t u = (uint64_t)le32(p) | (uint64_t)le32(p + 4) << 32;
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
  }
  }
}

/* Parses the header up to and including "end_header\n"; *body gets the
** offset of the data. */
static int ply_header(const unsigned char *d, size_t len, ply_elem *elems,
                      int *nelem, char *gen, size_t gensize, size_t *body,
                      char *why, size_t ws) {
  size_t pos = 0;
  int line_no = 0, format_seen = 0;
  *nelem = 0;
  for (;;) {
    const unsigned char *nl = memchr(d + pos, '\n', len - pos);
    if (!nl) return say(why, ws, "PLY: no end_header");
    char line[256];
    size_t n = (size_t)(nl - (d + pos));
    /* Comments may be long (provenance): only the first is kept. */
    if (n >= 8 && memcmp(d + pos, "comment ", 8) == 0 && line_no > 0) {
      size_t k = n - 8 < gensize - 1 ? n - 8 : gensize - 1;
      if (!gen[0]) {
        memcpy(gen, d + pos + 8, k);
        gen[k] = '\0';
      }
      pos = (size_t)(nl - d) + 1;
      line_no++;
      continue;
    }
    if (n && d[pos + n - 1] == '\r') n--;
    if (n >= sizeof line) return say(why, ws, "PLY: header line too long");
    memcpy(line, d + pos, n);
    line[n] = '\0';
    pos = (size_t)(nl - d) + 1;
    line_no++;
    char a[64] = "", b[64] = "", c[64] = "", e[64] = "";
    int k = sscanf(line, "%63s %63s %63s %63s", a, b, c, e);
    if (line_no == 1) {
      if (strcmp(line, "ply") != 0) return say(why, ws, "PLY: no magic");
      continue;
    }
    if (k <= 0) return say(why, ws, "PLY: empty header line %d", line_no);
    if (strcmp(a, "format") == 0) {
      if (k != 3 || strcmp(b, "binary_little_endian") != 0 ||
          strcmp(c, "1.0") != 0)
        return say(why, ws, "PLY: unsupported format line '%s'", line);
      format_seen = 1;
    } else if (strcmp(a, "comment") == 0) {
      if (!gen[0]) snprintf(gen, gensize, "%s", line + (n > 8 ? 8 : n));
    } else if (strcmp(a, "obj_info") == 0) {
    } else if (strcmp(a, "element") == 0) {
      if (k != 3 || *nelem == MAXELEM)
        return say(why, ws, "PLY: bad element line '%s'", line);
      char *end;
      errno = 0;
      unsigned long long cnt = strtoull(c, &end, 10);
      if (*end || errno || c[0] == '-')
        return say(why, ws, "PLY: bad element count '%s'", c);
      ply_elem *el = &elems[(*nelem)++];
      memset(el, 0, sizeof *el);
      snprintf(el->name, sizeof el->name, "%s", b);
      el->count = (size_t)cnt;
    } else if (strcmp(a, "property") == 0) {
      if (*nelem == 0) return say(why, ws, "PLY: property before element");
      ply_elem *el = &elems[*nelem - 1];
      if (el->nprop == MAXPROP) return say(why, ws, "PLY: too many properties");
      ply_prop *pr = &el->prop[el->nprop++];
      memset(pr, 0, sizeof *pr);
      if (strcmp(b, "list") == 0) {
        int ik;
        if (k != 4) return say(why, ws, "PLY: bad list property '%s'", line);
        pr->count_size = ply_type(c, &pr->count_kind);
        int isz = ply_type(e, &ik);
        char name[64] = "";
        sscanf(line, "%*s %*s %*s %*s %63s", name);
        if (!pr->count_size || pr->count_kind == 'f' || !isz || ik == 'f' ||
            !name[0])
          return say(why, ws, "PLY: bad list property '%s'", line);
        pr->type = -isz;
        pr->kind = ik;
        snprintf(pr->name, sizeof pr->name, "%s", name);
      } else {
        if (k != 3) return say(why, ws, "PLY: bad property '%s'", line);
        pr->type = ply_type(b, &pr->kind);
        if (!pr->type) return say(why, ws, "PLY: unknown type '%s'", b);
        snprintf(pr->name, sizeof pr->name, "%s", c);
      }
    } else if (strcmp(a, "end_header") == 0 && k == 1) {
      break;
    } else {
      return say(why, ws, "PLY: unknown header line '%s'", line);
    }
  }
  if (!format_seen) return say(why, ws, "PLY: no format line");
  *body = pos;
  return 1;
}

static int find_prop(const ply_elem *el, const char *name) {
  for (int i = 0; i < el->nprop; i++)
    if (strcmp(el->prop[i].name, name) == 0) return i;
  return -1;
}

static mr_mesh *read_ply(const unsigned char *d, size_t len, char *why,
                         size_t ws) {
  ply_elem elems[MAXELEM];
  int nelem;
  char gen[128] = "";
  size_t pos = 0;
  if (!ply_header(d, len, elems, &nelem, gen, sizeof gen, &pos, why, ws))
    return NULL;
  const ply_elem *ev = NULL, *ef = NULL;
  for (int i = 0; i < nelem; i++) {
    if (strcmp(elems[i].name, "vertex") == 0) ev = &elems[i];
    if (strcmp(elems[i].name, "face") == 0) ef = &elems[i];
  }
  if (!ev) return say(why, ws, "PLY: no vertex element"), NULL;
  static const char *const names[9] = {"x",  "y",   "z",     "nx",  "ny",
                                       "nz", "red", "green", "blue"};
  int at[9];
  for (int i = 0; i < 9; i++) {
    at[i] = find_prop(ev, names[i]);
    if (at[i] >= 0 && ev->prop[at[i]].type < 0)
      return say(why, ws, "PLY: vertex property %s is a list", names[i]), NULL;
  }
  if (at[0] < 0 || at[1] < 0 || at[2] < 0)
    return say(why, ws, "PLY: vertex without x, y, z"), NULL;
  int normals = at[3] >= 0 && at[4] >= 0 && at[5] >= 0;
  int colours = at[6] >= 0 && at[7] >= 0 && at[8] >= 0;
  if (!normals && (at[3] >= 0 || at[4] >= 0 || at[5] >= 0))
    return say(why, ws, "PLY: incomplete normals"), NULL;
  if (!colours && (at[6] >= 0 || at[7] >= 0 || at[8] >= 0))
    return say(why, ws, "PLY: incomplete colours"), NULL;
  int fl = ef ? find_prop(ef, "vertex_indices") : -1;
  if (ef && fl < 0) fl = find_prop(ef, "vertex_index");
  if (ef && (fl < 0 || ef->prop[fl].type >= 0))
    return say(why, ws, "PLY: face without a vertex_indices list"), NULL;
  /* Guard the allocation against absurd counts before trusting them. */
  if (ev->count > len || (ef && ef->count > len))
    return say(why, ws, "PLY: element counts larger than the file"), NULL;
  mr_mesh *m = new_mesh(MR_PLY, ev->count, ef ? ef->count : 0, normals, colours,
                        why, ws);
  if (!m) return NULL;
  snprintf(m->generator, sizeof m->generator, "%s", gen);

  for (int e = 0; e < nelem; e++) {
    const ply_elem *el = &elems[e];
    for (size_t i = 0; i < el->count; i++) {
      for (int k = 0; k < el->nprop; k++) {
        const ply_prop *pr = &el->prop[k];
        if (pr->type > 0) {
          if (len - pos < (size_t)pr->type) goto truncated;
          double v = ply_scalar(d + pos, pr->type, pr->kind);
          pos += (size_t)pr->type;
          if (el != ev) continue;
          for (int c = 0; c < 9; c++) {
            if (at[c] != k) continue;
            if (c < 3)
              m->pos[3 * i + c] = (float)v;
            else if (c < 6)
              m->nrm[3 * i + c - 3] = (float)v;
            else
              m->col[3 * i + c - 6] =
                  pr->kind == 'f' ? (float)v
                                  : (float)(v / ((1u << (8 * pr->type)) - 1));
          }
          continue;
        }
        if (len - pos < (size_t)pr->count_size) goto truncated;
        double cnt = ply_scalar(d + pos, pr->count_size, pr->count_kind);
        pos += (size_t)pr->count_size;
        int isz = -pr->type;
        if (el == ef && k == fl && cnt != 3) {
          mr_free(m);
          say(why, ws, "PLY: face %zu has %g vertices (only triangles)", i,
              cnt);
          return NULL;
        }
        if (cnt < 0 || (len - pos) / (size_t)isz < (size_t)cnt) goto truncated;
        for (int j = 0; j < (int)cnt; j++) {
          double v = ply_scalar(d + pos, isz, pr->kind);
          pos += (size_t)isz;
          if (el == ef && k == fl) {
            if (v < 0 || v >= (double)m->nv) {
              mr_free(m);
              say(why, ws, "PLY: face %zu uses vertex %g of %zu", i, v, m->nv);
              return NULL;
            }
            m->tri[3 * i + j] = (uint32_t)v;
          }
        }
      }
    }
  }
  if (pos != len) {
    mr_free(m);
    say(why, ws, "PLY: %zu bytes after the last element", len - pos);
    return NULL;
  }
  return m;
truncated:
  mr_free(m);
  say(why, ws, "PLY: file truncated");
  return NULL;
}

/* ======================================================================
** OBJ
** ====================================================================== */

typedef struct fvec {
  float *v;
  size_t n, cap; /* in floats */
} fvec;

static int fpush(fvec *f, const float *x, int k) {
  if (f->n + (size_t)k > f->cap) {
    size_t nc = f->cap ? 2 * f->cap : 96;
    float *v = realloc(f->v, nc * sizeof *v);
    if (!v) return 0;
    f->v = v;
    f->cap = nc;
  }
  memcpy(f->v + f->n, x, (size_t)k * sizeof *x);
  f->n += (size_t)k;
  return 1;
}

/* Up to `max` floats from s; returns how many, or -1 on a malformed
** token. */
static int obj_floats(const char *s, float *out, int max) {
  int k = 0;
  for (;;) {
    while (*s == ' ' || *s == '\t')
      s++;
    if (!*s) return k;
    if (k == max) return -1;
    char *end;
    out[k++] = strtof(s, &end);
    if (end == s || (*end && *end != ' ' && *end != '\t')) return -1;
    s = end;
  }
}

/* One face corner "v", "v/t", "v//n" or "v/t/n"; indices resolved to
** 0-based (negative ones count back from the end). *n = -1 without. */
static int obj_corner(const char *tok, long nv, long nn, long *v, long *n) {
  char *end;
  long a = strtol(tok, &end, 10), c = 0;
  if (end == tok) return 0;
  *n = -1;
  if (*end == '/') {
    const char *t = end + 1;
    if (*t != '/')
      strtol(t, &end, 10); /* texture index, ignored */
    else
      end = (char *)t;
    if (*end == '/') {
      const char *u = end + 1;
      c = strtol(u, &end, 10);
      if (end == u) return 0;
      *n = c > 0 ? c - 1 : nn + c;
      if (*n < 0 || *n >= nn) return 0;
    }
  }
  if (*end) return 0;
  *v = a > 0 ? a - 1 : nv + a;
  return a != 0 && *v >= 0 && *v < nv;
}

static mr_mesh *read_obj(const unsigned char *d, size_t len, char *why,
                         size_t ws) {
  fvec P = {0}, N = {0}, C = {0};
  uint32_t *tri = NULL;
  size_t nt = 0, tcap = 0;
  char gen[128] = "";
  int normal_refs = 0;
  mr_mesh *m = NULL;
  char line[1024];
  size_t pos = 0, line_no = 0;
  while (pos < len) {
    const unsigned char *nl = memchr(d + pos, '\n', len - pos);
    size_t n = nl ? (size_t)(nl - (d + pos)) : len - pos;
    line_no++;
    /* Comments may be long (provenance): skipped unless first. */
    if (n >= sizeof line && d[pos] == '#' && gen[0]) {
      pos += n + 1;
      continue;
    }
    if (n >= sizeof line) {
      say(why, ws, "OBJ: line %zu too long", line_no);
      goto done;
    }
    if (memchr(d + pos, '\0', n)) {
      say(why, ws, "OBJ: NUL byte on line %zu", line_no);
      goto done;
    }
    memcpy(line, d + pos, n);
    line[n] = '\0';
    if (n && line[n - 1] == '\r') line[n - 1] = '\0';
    pos += n + 1;
    char *s = line;
    while (*s == ' ' || *s == '\t')
      s++;
    if (*s == '#') {
      if (!gen[0]) {
        s++;
        while (*s == ' ')
          s++;
        snprintf(gen, sizeof gen, "%s", s);
      }
      continue;
    }
    if (!*s) continue;
    char *rest = s + strcspn(s, " \t");
    if (*rest) *rest++ = '\0';
    float x[6];
    if (strcmp(s, "v") == 0) {
      int k = obj_floats(rest, x, 6);
      if (k != 3 && k != 6) {
        say(why, ws, "OBJ: bad vertex on line %zu", line_no);
        goto done;
      }
      if (k == 6 && P.n != C.n) {
        say(why, ws, "OBJ: colours on some vertices only (line %zu)", line_no);
        goto done;
      }
      if (!fpush(&P, x, 3) || (k == 6 && !fpush(&C, x + 3, 3))) goto oom;
    } else if (strcmp(s, "vn") == 0) {
      if (obj_floats(rest, x, 3) != 3) {
        say(why, ws, "OBJ: bad normal on line %zu", line_no);
        goto done;
      }
      if (!fpush(&N, x, 3)) goto oom;
    } else if (strcmp(s, "f") == 0) {
      long v[4], nn[4];
      int k = 0;
      for (char *tok = strtok(rest, " \t"); tok; tok = strtok(NULL, " \t")) {
        if (k == 4 ||
            !obj_corner(tok, (long)(P.n / 3), (long)(N.n / 3), &v[k], &nn[k])) {
          say(why, ws, "OBJ: bad face corner '%s' on line %zu", tok, line_no);
          goto done;
        }
        k++;
      }
      if (k != 3) {
        say(why, ws, "OBJ: face with %d corners on line %zu (only triangles)",
            k, line_no);
        goto done;
      }
      for (int j = 0; j < 3; j++) {
        if (nn[j] >= 0) {
          normal_refs = 1;
          if (nn[j] != v[j]) {
            say(why, ws,
                "OBJ: line %zu pairs vertex %ld with normal %ld (the reader "
                "keeps one normal per vertex)",
                line_no, v[j] + 1, nn[j] + 1);
            goto done;
          }
        }
      }
      if (nt == tcap) {
        tcap = tcap ? 2 * tcap : 64;
        uint32_t *t = realloc(tri, 3 * tcap * sizeof *t);
        if (!t) goto oom;
        tri = t;
      }
      for (int j = 0; j < 3; j++)
        tri[3 * nt + j] = (uint32_t)v[j];
      nt++;
    } else if (strcmp(s, "o") && strcmp(s, "g") && strcmp(s, "s") &&
               strcmp(s, "vt") && strcmp(s, "mtllib") && strcmp(s, "usemtl")) {
      say(why, ws, "OBJ: unsupported statement '%s' on line %zu", s, line_no);
      goto done;
    }
  }
  (void)normal_refs;
  if (N.n && N.n != P.n) {
    say(why, ws, "OBJ: %zu normals for %zu vertices", N.n / 3, P.n / 3);
    goto done;
  }
  if (C.n && C.n != P.n) {
    say(why, ws, "OBJ: colours on some vertices only");
    goto done;
  }
  m = new_mesh(MR_OBJ, P.n / 3, nt, N.n > 0, C.n > 0, why, ws);
  if (!m) goto done;
  if (P.n) memcpy(m->pos, P.v, P.n * sizeof(float));
  if (N.n) memcpy(m->nrm, N.v, N.n * sizeof(float));
  if (C.n) memcpy(m->col, C.v, C.n * sizeof(float));
  if (nt) memcpy(m->tri, tri, 3 * nt * sizeof(uint32_t));
  snprintf(m->generator, sizeof m->generator, "%s", gen);
  goto done;
oom:
  say(why, ws, "OBJ: out of memory");
done:
  free(P.v);
  free(N.v);
  free(C.v);
  free(tri);
  return m;
}

/* ======================================================================
** GLB (glTF 2.0 binary)
** ====================================================================== */

typedef struct glb {
  const mr_json *root;
  const unsigned char *bin;
  size_t binlen; /* BIN chunk length */
  size_t buflen; /* buffers[0].byteLength (0 without a buffer) */
  char *why;
  size_t ws;
} glb;

/* A resolved accessor. */
typedef struct acc {
  const unsigned char *data; /* first element, or NULL when absent */
  size_t count, ncomp, csize, stride;
  long ctype;
  const mr_json *view; /* its bufferView */
} acc;

#define BAD(g, ...) say((g)->why, (g)->ws, "GLB: " __VA_ARGS__)

/* Member `key` of obj as a non-negative integer (below 2^53) in *out;
** `dflt` when absent, or an error when absent and dflt < 0 (required).
** Returns 1, or 0 with the reason. */
static int jint(glb *g, const mr_json *obj, const char *key, long long dflt,
                const char *where, long long *out) {
  const mr_json *v = mr_json_get(obj, key);
  if (!v) {
    *out = dflt;
    return dflt >= 0 ? 1 : BAD(g, "%s has no %s", where, key);
  }
  if (v->type != MR_JNUMBER || v->number < 0 ||
      v->number > 9007199254740992.0 || v->number != floor(v->number))
    return BAD(g, "%s.%s must be a non-negative integer", where, key);
  *out = (long long)v->number;
  return 1;
}

static int component_size(long long t) {
  switch (t) {
  case 5120:
  case 5121:
    return 1;
  case 5122:
  case 5123:
    return 2;
  case 5125:
  case 5126:
    return 4;
  default:
    return 0;
  }
}

static int components(const char *type) {
  static const struct {
    const char *name;
    int n;
  } t[] = {{"SCALAR", 1}, {"VEC2", 2}, {"VEC3", 3}, {"VEC4", 4},
           {"MAT2", 4},   {"MAT3", 9}, {"MAT4", 16}};
  for (size_t i = 0; type && i < sizeof t / sizeof *t; i++)
    if (strcmp(type, t[i].name) == 0) return t[i].n;
  return 0;
}

static double acc_value(const acc *a, size_t i, size_t c) {
  const unsigned char *p = a->data + i * a->stride + c * a->csize;
  switch (a->ctype) {
  case 5120:
    return (int8_t)p[0];
  case 5121:
    return p[0];
  case 5122:
    return (int16_t)(p[0] | p[1] << 8);
  case 5123:
    return (uint16_t)(p[0] | p[1] << 8);
  case 5125:
    return le32(p);
  default:
    return lef32(p);
  }
}

static int check_view(glb *g, size_t i) {
  const mr_json *v = mr_json_at(mr_json_get(g->root, "bufferViews"), i);
  char where[48];
  snprintf(where, sizeof where, "bufferViews[%zu]", i);
  if (!v || v->type != MR_JOBJECT) return BAD(g, "%s is not an object", where);
  long long buf, off, len, stride, target;
  if (!jint(g, v, "buffer", -1, where, &buf) ||
      !jint(g, v, "byteOffset", 0, where, &off) ||
      !jint(g, v, "byteLength", -1, where, &len) ||
      !jint(g, v, "byteStride", 0, where, &stride) ||
      !jint(g, v, "target", 0, where, &target))
    return 0;
  if (buf != 0) return BAD(g, "%s.buffer %lld does not exist", where, buf);
  if (len < 1) return BAD(g, "%s.byteLength must be >= 1", where);
  if ((unsigned long long)off + (unsigned long long)len > g->buflen)
    return BAD(g, "%s [%lld, +%lld) is outside the buffer of %zu bytes", where,
               off, len, g->buflen);
  if (mr_json_get(v, "byteStride") &&
      (stride < 4 || stride > 252 || stride % 4))
    return BAD(g, "%s.byteStride %lld invalid", where, stride);
  if (target && target != 34962 && target != 34963)
    return BAD(g, "%s.target %lld invalid", where, target);
  return 1;
}

/* Resolves and validates accessor i (its bufferView already checked):
** alignment, extent, and min/max against the data when given. */
static int get_acc(glb *g, size_t i, acc *a) {
  const mr_json *x = mr_json_at(mr_json_get(g->root, "accessors"), i);
  char where[48];
  snprintf(where, sizeof where, "accessors[%zu]", i);
  if (!x || x->type != MR_JOBJECT) return BAD(g, "%s does not exist", where);
  if (mr_json_get(x, "sparse")) return BAD(g, "%s is sparse", where);
  long long vi, off, ct, count;
  if (!jint(g, x, "bufferView", -1, where, &vi) ||
      !jint(g, x, "byteOffset", 0, where, &off) ||
      !jint(g, x, "componentType", -1, where, &ct) ||
      !jint(g, x, "count", -1, where, &count))
    return 0;
  int csize = component_size(ct);
  int ncomp = components(mr_json_str(mr_json_get(x, "type")));
  if (!csize) return BAD(g, "%s.componentType %lld invalid", where, ct);
  if (!ncomp) return BAD(g, "%s.type invalid", where);
  if (count < 1) return BAD(g, "%s.count must be >= 1", where);
  const mr_json *norm = mr_json_get(x, "normalized");
  if (norm && (norm->type == MR_JTRUE ? ct == 5126 || ct == 5125
                                      : norm->type != MR_JFALSE))
    return BAD(g, "%s.normalized invalid", where);
  const mr_json *view =
      mr_json_at(mr_json_get(g->root, "bufferViews"), (size_t)vi);
  if (!view) return BAD(g, "%s.bufferView %lld does not exist", where, vi);
  long long voff, vlen, vstride;
  if (!jint(g, view, "byteOffset", 0, where, &voff) ||
      !jint(g, view, "byteLength", -1, where, &vlen) ||
      !jint(g, view, "byteStride", 0, where, &vstride))
    return 0;
  size_t elem = (size_t)csize * (size_t)ncomp;
  size_t stride = vstride ? (size_t)vstride : elem;
  if (off % csize || (voff + off) % csize)
    return BAD(g, "%s is not aligned to its component size", where);
  if (stride < elem) return BAD(g, "%s: byteStride below the element", where);
  if ((unsigned long long)off + stride * ((size_t)count - 1) + elem >
      (unsigned long long)vlen)
    return BAD(g, "%s: %lld elements of %zu bytes overrun bufferView %lld",
               where, count, elem, vi);
  a->data = g->bin + voff + off;
  a->count = (size_t)count;
  a->ncomp = (size_t)ncomp;
  a->csize = (size_t)csize;
  a->stride = stride;
  a->ctype = (long)ct;
  a->view = view;
  /* min/max compared as glTF does: in the component type's precision. */
  static const char *const bound[2] = {"min", "max"};
  for (int b = 0; b < 2; b++) {
    const mr_json *arr = mr_json_get(x, bound[b]);
    if (!arr) continue;
    if (arr->type != MR_JARRAY || arr->n != (size_t)ncomp)
      return BAD(g, "%s.%s must hold %d numbers", where, bound[b], ncomp);
    for (size_t c = 0; c < (size_t)ncomp; c++) {
      if (arr->items[c].type != MR_JNUMBER)
        return BAD(g, "%s.%s[%zu] is not a number", where, bound[b], c);
      double want = acc_value(a, 0, c);
      for (size_t k = 1; k < a->count; k++) {
        double v = acc_value(a, k, c);
        if (b ? v > want : v < want) want = v;
      }
      double got = arr->items[c].number;
      if (ct == 5126) got = (float)got;
      if (got != want)
        return BAD(g, "%s.%s[%zu] is %.9g, the data's is %.9g", where, bound[b],
                   c, arr->items[c].number, want);
    }
  }
  return 1;
}

/* An attribute: float VEC3, 4-byte aligned, in a vertex-buffer view. */
static int vec3_attr(glb *g, const mr_json *attrs, const char *name,
                     int required, acc *a) {
  a->data = NULL;
  if (!mr_json_get(attrs, name))
    return required ? BAD(g, "primitive has no %s", name) : 1;
  long long i, target;
  if (!jint(g, attrs, name, -1, "attributes", &i) || !get_acc(g, (size_t)i, a))
    return 0;
  const mr_json *ax = mr_json_at(mr_json_get(g->root, "accessors"), (size_t)i);
  if (a->ctype != 5126 || a->ncomp != 3 ||
      strcmp(mr_json_str(mr_json_get(ax, "type")), "VEC3") != 0)
    return BAD(g, "%s must be a float VEC3 accessor", name);
  if ((a->data - g->bin) % 4 || a->stride % 4)
    return BAD(g, "%s is not 4-byte aligned", name);
  if (!jint(g, a->view, "target", 34962, "bufferView", &target)) return 0;
  if (target != 34962)
    return BAD(g, "%s's bufferView target is %lld", name, target);
  if (!strcmp(name, "POSITION") &&
      (!mr_json_get(ax, "min") || !mr_json_get(ax, "max")))
    return BAD(g, "POSITION accessor without min and max");
  return 1;
}

/* The index of the one mesh the scene shows in *mesh (-1: none). Nodes
** with transforms are refused: the reader would misplace their mesh. */
static int scene_mesh(glb *g, long long *mesh) {
  const mr_json *nodes = mr_json_get(g->root, "nodes");
  long long si;
  if (!jint(g, g->root, "scene", 0, "root", &si)) return 0;
  const mr_json *scene = mr_json_at(mr_json_get(g->root, "scenes"), (size_t)si);
  if (!scene) return BAD(g, "scene %lld does not exist", si);
  const mr_json *roots = mr_json_get(scene, "nodes");
  *mesh = -1;
  size_t stack[64], top = 0, visited = 0;
  for (size_t i = 0; roots && i < roots->n; i++) {
    const mr_json *r = &roots->items[i];
    if (r->type != MR_JNUMBER || r->number < 0 || top == 64)
      return BAD(g, "bad scene node list");
    stack[top++] = (size_t)r->number;
  }
  while (top) {
    size_t ni = stack[--top];
    const mr_json *node = mr_json_at(nodes, ni);
    if (!node || node->type != MR_JOBJECT)
      return BAD(g, "node %zu does not exist", ni);
    if (++visited > 1000) return BAD(g, "node hierarchy has a cycle");
    static const char *const xf[] = {"matrix", "translation", "rotation",
                                     "scale"};
    for (int k = 0; k < 4; k++)
      if (mr_json_get(node, xf[k]))
        return BAD(g, "node %zu has a transform the reader ignores", ni);
    long long mi;
    if (!jint(g, node, "mesh", 0, "node", &mi)) return 0;
    if (mr_json_get(node, "mesh")) {
      if (*mesh >= 0) return BAD(g, "more than one mesh node");
      *mesh = mi;
    }
    const mr_json *ch = mr_json_get(node, "children");
    for (size_t i = 0; ch && i < ch->n; i++) {
      if (ch->items[i].type != MR_JNUMBER || top == 64)
        return BAD(g, "bad children of node %zu", ni);
      stack[top++] = (size_t)ch->items[i].number;
    }
  }
  return 1;
}

static int glb_buffer(glb *g) {
  const mr_json *bufs = mr_json_get(g->root, "buffers");
  if (!bufs) return g->bin ? BAD(g, "BIN chunk without a buffer") : 1;
  if (bufs->type != MR_JARRAY || bufs->n != 1)
    return BAD(g, "the reader expects exactly one buffer");
  const mr_json *b = &bufs->items[0];
  if (mr_json_get(b, "uri")) return BAD(g, "buffer has a uri");
  long long bl;
  if (!jint(g, b, "byteLength", -1, "buffers[0]", &bl)) return 0;
  if (bl < 1) return BAD(g, "buffers[0].byteLength must be >= 1");
  if (!g->bin) return BAD(g, "buffer without a BIN chunk");
  /* The BIN chunk may exceed the buffer by its padding, up to 3 bytes. */
  if ((size_t)bl > g->binlen || g->binlen - (size_t)bl > 3)
    return BAD(g, "buffer of %lld bytes in a BIN chunk of %zu", bl, g->binlen);
  for (size_t i = (size_t)bl; i < g->binlen; i++)
    if (g->bin[i]) return BAD(g, "BIN padding is not zero");
  g->buflen = (size_t)bl;
  return 1;
}

static mr_mesh *glb_mesh(glb *g) {
  const char *version =
      mr_json_str(mr_json_get(mr_json_get(g->root, "asset"), "version"));
  if (!version || strcmp(version, "2.0") != 0)
    return BAD(g, "asset.version is not \"2.0\""), NULL;
  if (mr_json_get(g->root, "extensionsRequired"))
    return BAD(g, "requires extensions"), NULL;
  if (!glb_buffer(g)) return NULL;
  const mr_json *views = mr_json_get(g->root, "bufferViews");
  for (size_t i = 0; views && i < views->n; i++)
    if (!check_view(g, i)) return NULL;
  const mr_json *accs = mr_json_get(g->root, "accessors");
  for (size_t i = 0; accs && i < accs->n; i++) {
    acc a;
    if (!get_acc(g, i, &a)) return NULL;
  }

  long long mi = -1;
  if (!scene_mesh(g, &mi)) return NULL;
  if (mi < 0) return new_mesh(MR_GLB, 0, 0, 0, 0, g->why, g->ws);
  const mr_json *mesh = mr_json_at(mr_json_get(g->root, "meshes"), (size_t)mi);
  const mr_json *prims = mr_json_get(mesh, "primitives");
  if (!prims || prims->type != MR_JARRAY || prims->n != 1)
    return BAD(g, "the reader expects one mesh with one primitive"), NULL;
  const mr_json *prim = &prims->items[0];
  long long mode, ii;
  if (!jint(g, prim, "mode", 4, "primitive", &mode)) return NULL;
  if (mode != 4) return BAD(g, "primitive mode is not TRIANGLES"), NULL;
  const mr_json *attrs = mr_json_get(prim, "attributes");
  if (!attrs || attrs->type != MR_JOBJECT)
    return BAD(g, "primitive without attributes"), NULL;
  for (size_t i = 0; i < attrs->n; i++)
    if (strcmp(attrs->keys[i], "POSITION") &&
        strcmp(attrs->keys[i], "NORMAL") && strcmp(attrs->keys[i], "COLOR_0"))
      return BAD(g, "unsupported attribute %s", attrs->keys[i]), NULL;
  acc P, N, C, I;
  if (!vec3_attr(g, attrs, "POSITION", 1, &P) ||
      !vec3_attr(g, attrs, "NORMAL", 0, &N) ||
      !vec3_attr(g, attrs, "COLOR_0", 0, &C))
    return NULL;
  if ((N.data && N.count != P.count) || (C.data && C.count != P.count))
    return BAD(g, "attribute counts differ"), NULL;
  if (!jint(g, prim, "indices", -1, "primitive", &ii) ||
      !get_acc(g, (size_t)ii, &I))
    return NULL;
  long long target;
  if (I.ncomp != 1 || (I.ctype != 5121 && I.ctype != 5123 && I.ctype != 5125))
    return BAD(g, "indices must be an unsigned SCALAR accessor"), NULL;
  if (mr_json_get(I.view, "byteStride"))
    return BAD(g, "indices bufferView has a byteStride"), NULL;
  if (!jint(g, I.view, "target", 34963, "bufferView", &target)) return NULL;
  if (target != 34963)
    return BAD(g, "indices bufferView target is %lld", target), NULL;
  if (I.count % 3) return BAD(g, "%zu indices", I.count), NULL;

  mr_mesh *m = new_mesh(MR_GLB, P.count, I.count / 3, N.data != NULL,
                        C.data != NULL, g->why, g->ws);
  if (!m) return NULL;
  for (size_t i = 0; i < P.count; i++)
    for (size_t c = 0; c < 3; c++) {
      m->pos[3 * i + c] = (float)acc_value(&P, i, c);
      if (N.data) m->nrm[3 * i + c] = (float)acc_value(&N, i, c);
      if (C.data) m->col[3 * i + c] = (float)acc_value(&C, i, c);
    }
  for (size_t i = 0; i < I.count; i++) {
    double v = acc_value(&I, i, 0);
    if (v >= (double)P.count) {
      mr_free(m);
      return BAD(g, "index %zu is %.0f, past %zu vertices", i, v, P.count),
             NULL;
    }
    m->tri[i] = (uint32_t)v;
  }
  return m;
}

static mr_mesh *read_glb(const unsigned char *d, size_t len, char *why,
                         size_t ws) {
  glb g = {NULL, NULL, 0, 0, why, ws};
  if (len < 20 || le32(d) != 0x46546C67u) return BAD(&g, "no magic"), NULL;
  if (le32(d + 4) != 2) return BAD(&g, "version %u", le32(d + 4)), NULL;
  if (le32(d + 8) != len || len % 4)
    return BAD(&g, "header length %u, file %zu bytes", le32(d + 8), len), NULL;
  size_t jlen = le32(d + 12);
  if (le32(d + 16) != 0x4E4F534Au)
    return BAD(&g, "first chunk is not JSON"), NULL;
  if (jlen % 4 || jlen > len - 20)
    return BAD(&g, "JSON chunk length %zu", jlen), NULL;
  const char *js = (const char *)d + 20;
  /* Padding is spaces only, and only as many as reach a multiple of 4. */
  size_t pad = 0;
  while (pad < jlen && strchr(" \t\r\n", js[jlen - 1 - pad]))
    pad++;
  for (size_t i = jlen - pad; i < jlen; i++)
    if (js[i] != ' ') return BAD(&g, "JSON padding is not spaces"), NULL;
  if (pad > 3) return BAD(&g, "JSON padded with %zu spaces", pad), NULL;
  size_t at = 20 + jlen;
  if (at < len) {
    if (len - at < 8 || le32(d + at + 4) != 0x004E4942u)
      return BAD(&g, "second chunk is not BIN"), NULL;
    g.binlen = le32(d + at);
    if (g.binlen % 4 || g.binlen != len - at - 8)
      return BAD(&g, "BIN chunk of %zu bytes must end the file", g.binlen),
             NULL;
    g.bin = d + at + 8;
  }
  char jwhy[200] = "";
  mr_json *root = mr_json_parse(js, jlen, jwhy, sizeof jwhy);
  if (!root) return BAD(&g, "%s", jwhy), NULL;
  if (root->type != MR_JOBJECT) {
    mr_json_free(root);
    return BAD(&g, "JSON is not an object"), NULL;
  }
  g.root = root;
  mr_mesh *m = glb_mesh(&g);
  if (!m) {
    mr_json_free(root);
    return NULL;
  }
  m->gltf = root;
  m->json_length = jlen;
  m->bin_length = g.binlen;
  const char *gen =
      mr_json_str(mr_json_get(mr_json_get(root, "asset"), "generator"));
  snprintf(m->generator, sizeof m->generator, "%s", gen ? gen : "");
  return m;
}

/* ======================================================================
** Dispatch
** ====================================================================== */

void mr_gltf_to_engine(mr_mesh *m) {
  for (size_t i = 0; i < m->nv; i++) {
    float *v[2] = {m->pos + 3 * i, m->nrm ? m->nrm + 3 * i : NULL};
    for (int k = 0; k < 2; k++) {
      if (!v[k]) continue;
      float Y = v[k][1], Z = v[k][2];
      v[k][1] = -Z;
      v[k][2] = Y;
    }
  }
}

mr_mesh *mr_read(const char *path, char *why, size_t whysize) {
  const char *dot = strrchr(path, '.');
  int fmt = !dot                       ? -1
            : !strcasecmp(dot, ".ply") ? MR_PLY
            : !strcasecmp(dot, ".obj") ? MR_OBJ
            : !strcasecmp(dot, ".glb") ? MR_GLB
                                       : -1;
  if (fmt < 0) return say(why, whysize, "%s: unknown extension", path), NULL;
  size_t len = 0;
  unsigned char *d = mr_slurp(path, &len);
  if (!d)
    return say(why, whysize, "%s: cannot read: %s", path, strerror(errno)),
           NULL;
  char sub[200] = "";
  mr_mesh *m = fmt == MR_PLY   ? read_ply(d, len, sub, sizeof sub)
               : fmt == MR_OBJ ? read_obj(d, len, sub, sizeof sub)
                               : read_glb(d, len, sub, sizeof sub);
  free(d);
  if (!m) say(why, whysize, "%s: %s", path, sub);
  return m;
}

/* ======================================================================
** Checks
** ====================================================================== */

typedef struct hedge {
  uint32_t lo, hi;
  int forward; /* 1 when the triangle runs lo -> hi */
} hedge;

static int cmp_hedge(const void *a, const void *b) {
  const hedge *x = a, *y = b;
  if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
  if (x->hi != y->hi) return x->hi < y->hi ? -1 : 1;
  return 0;
}

/* Vertex order by position, for finding duplicates (qsort has no
** context argument, so the positions ride along with the index). */
typedef struct vkey {
  float p[3];
  size_t i;
} vkey;

static int cmp_vkey(const void *a, const void *b) {
  const vkey *x = a, *y = b;
  for (int c = 0; c < 3; c++) {
    if (x->p[c] < y->p[c]) return -1;
    if (x->p[c] > y->p[c]) return 1;
  }
  return x->i < y->i ? -1 : x->i > y->i;
}

static size_t find_root(size_t *parent, size_t i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

static void topology(const mr_mesh *m, mr_report *r) {
  hedge *h = malloc((3 * m->nt + 1) * sizeof *h);
  if (!h) {
    r->edges = (size_t)-1;
    return;
  }
  size_t nh = 0;
  for (size_t t = 0; t < m->nt; t++)
    for (int k = 0; k < 3; k++) {
      uint32_t a = m->tri[3 * t + k], b = m->tri[3 * t + (k + 1) % 3];
      if (a == b) continue; /* a degenerate triangle's collapsed edge */
      h[nh].lo = a < b ? a : b;
      h[nh].hi = a < b ? b : a;
      h[nh].forward = a < b;
      nh++;
    }
  qsort(h, nh, sizeof *h, cmp_hedge);
  for (size_t i = 0; i < nh;) {
    size_t j = i, fwd = 0;
    while (j < nh && h[j].lo == h[i].lo && h[j].hi == h[i].hi)
      fwd += (size_t)h[j++].forward;
    size_t uses = j - i;
    r->edges++;
    if (uses == 1)
      r->boundary_edges++;
    else if (uses > 2)
      r->nonmanifold_edges++;
    else if (fwd != 1)
      r->misoriented_edges++;
    i = j;
  }
  free(h);
}

static void duplicates(const mr_mesh *m, mr_report *r) {
  vkey *k = malloc((m->nv + 1) * sizeof *k);
  if (!k) return;
  for (size_t i = 0; i < m->nv; i++) {
    memcpy(k[i].p, m->pos + 3 * i, sizeof k[i].p);
    k[i].i = i;
  }
  qsort(k, m->nv, sizeof *k, cmp_vkey);
  for (size_t i = 1; i < m->nv; i++)
    if (k[i].p[0] == k[i - 1].p[0] && k[i].p[1] == k[i - 1].p[1] &&
        k[i].p[2] == k[i - 1].p[2])
      r->duplicate_vertices++;
  free(k);
}

static void cross(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

void mr_check(const mr_mesh *m, mr_report *r) {
  memset(r, 0, sizeof *r);
  r->vertices = m->nv;
  r->triangles = m->nt;
  char *used = calloc(m->nv + 1, 1);
  size_t *parent = malloc((m->nv + 1) * sizeof *parent);
  double *nsum = m->nrm ? calloc(3 * m->nv + 1, sizeof *nsum) : NULL;
  if (!used || !parent || (m->nrm && !nsum)) {
    free(used);
    free(parent);
    free(nsum);
    r->edges = (size_t)-1;
    return;
  }
  for (size_t i = 0; i < m->nv; i++)
    parent[i] = i;
  for (int c = 0; c < 3; c++) {
    r->lo[c] = INFINITY;
    r->hi[c] = -INFINITY;
  }
  for (size_t t = 0; t < m->nt; t++)
    for (int k = 0; k < 3; k++) {
      uint32_t v = m->tri[3 * t + k];
      used[v] = 1;
      for (int c = 0; c < 3; c++) {
        r->lo[c] = fmin(r->lo[c], m->pos[3 * v + c]);
        r->hi[c] = fmax(r->hi[c], m->pos[3 * v + c]);
      }
      size_t a = find_root(parent, m->tri[3 * t]), b = find_root(parent, v);
      if (a != b) parent[b] = a;
    }
  for (size_t i = 0; i < m->nv; i++)
    if (used[i]) {
      r->referenced++;
      if (find_root(parent, i) == i) r->components++;
    }

  /* Volume about the centre of the bounds: the sum does not depend on the
  ** origin for a closed mesh, and a near origin keeps rounding small. */
  double o[3];
  for (int c = 0; c < 3; c++)
    o[c] = m->nt ? 0.5 * (r->lo[c] + r->hi[c]) : 0.0;
  double vol = 0, area = 0;
  for (size_t t = 0; t < m->nt; t++) {
    const uint32_t *v = m->tri + 3 * t;
    double p[3][3];
    for (int k = 0; k < 3; k++)
      for (int c = 0; c < 3; c++)
        p[k][c] = m->pos[3 * v[k] + c] - o[c];
    double e1[3], e2[3], n[3], q[3];
    for (int c = 0; c < 3; c++) {
      e1[c] = p[1][c] - p[0][c];
      e2[c] = p[2][c] - p[0][c];
    }
    cross(e1, e2, n);
    cross(p[1], p[2], q);
    vol += (p[0][0] * q[0] + p[0][1] * q[1] + p[0][2] * q[2]) / 6.0;
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    area += 0.5 * len;
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2] || len == 0)
      r->degenerate_triangles++;
    if (nsum)
      for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++)
          nsum[3 * v[k] + c] += n[c];
  }
  r->volume = vol;
  r->area = area;
  if (m->nrm) {
    for (size_t i = 0; i < m->nv; i++) {
      const float *n = m->nrm + 3 * i;
      double l =
          sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
      if (!used[i]) continue;
      if (fabs(l - 1) > r->normal_length_error)
        r->normal_length_error = fabs(l - 1);
      double d =
          n[0] * nsum[3 * i] + n[1] * nsum[3 * i + 1] + n[2] * nsum[3 * i + 2];
      if (d < 0) r->normals_against++;
    }
  }
  free(used);
  free(parent);
  free(nsum);

  topology(m, r);
  duplicates(m, r);
  r->euler = (long)r->referenced - (long)r->edges + (long)r->triangles;
  r->closed = m->nt > 0 && r->boundary_edges == 0 && r->nonmanifold_edges == 0;
  r->consistent = r->misoriented_edges == 0 && r->nonmanifold_edges == 0;
  r->outward = r->closed && r->consistent && r->volume > 0;
}

const char *mr_report_str(const mr_report *r, char *buf, size_t size) {
  snprintf(buf, size,
           "V=%zu (referenced %zu, duplicates %zu) T=%zu (degenerate %zu) "
           "E=%zu (boundary %zu, non-manifold %zu, misoriented %zu) "
           "euler=%ld components=%zu volume=%.9g area=%.9g closed=%d "
           "consistent=%d outward=%d normals: length error %.3g, %zu against",
           r->vertices, r->referenced, r->duplicate_vertices, r->triangles,
           r->degenerate_triangles, r->edges, r->boundary_edges,
           r->nonmanifold_edges, r->misoriented_edges, r->euler, r->components,
           r->volume, r->area, r->closed, r->consistent, r->outward,
           r->normal_length_error, r->normals_against);
  return buf;
}
