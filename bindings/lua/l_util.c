/*
** l_util.c — checking the named-field tables that constructors take.
**
** Messages follow one pattern so scripts get the same help everywhere:
**   scene.lua:3: outcrop.point: 'radius' must be a positive number (got -1)
**   scene.lua:4: outcrop.sphere: unknown field 'radus' (did you mean 'radius'?)
*/
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "l_util.h"

/* Like luaL_where(L, 1), but when the binding was called from C (pcall,
** a string metamethod forwarding `"x" + node`) it names the nearest Lua
** caller rather than nothing. */
static void where(lua_State *L) {
  lua_Debug ar;
  for (int level = 1; lua_getstack(L, level, &ar); level++) {
    lua_getinfo(L, "Sl", &ar);
    if (ar.currentline > 0) {
      lua_pushfstring(L, "%s:%d: ", ar.short_src, ar.currentline);
      return;
    }
  }
  lua_pushliteral(L, "");
}

/* Pushes "file:line: fname: message" (where() gives the position). */
static void push_message(lua_State *L, const char *fname, const char *fmt,
                         va_list ap) {
  luaL_checkstack(L, 4, NULL);
  where(L);
  lua_pushstring(L, fname);
  lua_pushliteral(L, ": ");
  lua_pushvfstring(L, fmt, ap);
  lua_concat(L, 4);
}

int oclua_error(lua_State *L, const char *fname, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  push_message(L, fname, fmt, ap);
  va_end(ap);
  return lua_error(L);
}

/* Warnings go to stderr at once, whatever lua_setwarnf does (stock
** lua5.4 shows none until warn("@on")): a script that made an empty mesh
** should hear why. */
void oclua_warn(lua_State *L, const char *fname, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  push_message(L, fname, fmt, ap);
  va_end(ap);
  fprintf(stderr, "outcrop: warning: %s\n", lua_tostring(L, -1));
  fflush(stderr);
  lua_pop(L, 1);
}

int oclua_liberror(lua_State *L, const char *fname, const oc_error *err) {
  if (err->msg[0] != '\0') return oclua_error(L, fname, "%s", err->msg);
  return oclua_error(L, fname, "failed (error code %d)", (int)err->code);
}

const char *oclua_got(lua_State *L, int idx) {
  idx = lua_absindex(L, idx);
  switch (lua_type(L, idx)) {
  case LUA_TNUMBER:
    if (lua_isinteger(L, idx))
      return lua_pushfstring(L, "%I", (LUAI_UACINT)lua_tointeger(L, idx));
    return lua_pushfstring(L, "%f", (LUAI_UACNUMBER)lua_tonumber(L, idx));
  case LUA_TUSERDATA: {
    int t = luaL_getmetafield(L, idx, "__name");
    if (t == LUA_TSTRING) return lua_tostring(L, -1);
    if (t != LUA_TNIL) lua_pop(L, 1);
    return lua_pushstring(L, luaL_typename(L, idx));
  }
  default:
    return lua_pushstring(L, luaL_typename(L, idx));
  }
}

/* ---- unknown names ------------------------------------------------- */

/* Edit distance, capped: names are short and only near misses matter. */
static size_t distance(const char *a, const char *b) {
  size_t la = strlen(a), lb = strlen(b);
  size_t row[33];
  if (la > 32 || lb > 32) return (size_t)-1;
  for (size_t j = 0; j <= lb; j++)
    row[j] = j;
  for (size_t i = 1; i <= la; i++) {
    size_t diag = row[0];
    row[0] = i;
    for (size_t j = 1; j <= lb; j++) {
      size_t up = row[j];
      size_t best = diag + (a[i - 1] != b[j - 1]);
      if (row[j] + 1 < best) best = row[j] + 1;
      if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
      row[j] = best;
      diag = up;
    }
  }
  return row[lb];
}

static const char *closest(const char *name, const char *const *known) {
  const char *best = NULL;
  size_t bestd = (size_t)-1;
  for (; *known; known++) {
    size_t d = distance(name, *known);
    if (d < bestd) bestd = d, best = *known;
  }
  /* A suggestion must be nearer than a rewrite of most of the name. */
  if (best && bestd <= 2 && bestd < strlen(best)) return best;
  return NULL;
}

static int known_name(const char *name, const char *const *known) {
  for (; *known; known++)
    if (strcmp(name, *known) == 0) return 1;
  return 0;
}

/* " of 'name'" for a nested table (prefix "name."), else "". Pushed. */
static const char *in_field(const oclua_fields *f) {
  size_t n = strlen(f->prefix);
  if (n == 0) return "";
  return lua_pushfstring(f->L, " of '%s'",
                         lua_pushlstring(f->L, f->prefix, n - 1));
}

void oclua_fields_open_args(oclua_fields *f, lua_State *L, const char *fname,
                            const char *const *known) {
  oclua_checkargs(L, 1, fname, "a table of named fields");
  if (lua_isnoneornil(L, 1)) {
    lua_settop(L, 0);
    lua_newtable(L);
  }
  oclua_fields_open(f, L, 1, fname, NULL, known, 0);
}

void oclua_fields_open(oclua_fields *f, lua_State *L, int idx,
                       const char *fname, const char *prefix,
                       const char *const *known, int array) {
  lua_Integer count = 0, maxkey = 0;
  idx = lua_absindex(L, idx);
  f->L = L;
  f->fname = fname;
  f->prefix = prefix ? prefix : "";
  f->t = idx;
  f->narray = 0;
  if (!lua_istable(L, idx)) {
    if (*f->prefix) {
      /* the prefix is "name." */
      const char *name = lua_pushlstring(L, f->prefix, strlen(f->prefix) - 1);
      oclua_error(L, fname, "'%s' must be a table (got %s)", name,
                  oclua_got(L, idx));
    }
    oclua_error(L, fname, "expected a table of named fields (got %s)",
                oclua_got(L, idx));
  }
  luaL_checkstack(L, 4, NULL);
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    lua_pop(L, 1);
    if (lua_type(L, -1) == LUA_TSTRING) {
      const char *key = lua_tostring(L, -1);
      const char *hint;
      if (known_name(key, known)) continue;
      hint = closest(key, known);
      if (hint)
        oclua_error(L, fname, "unknown field '%s%s' (did you mean '%s%s'?)",
                    f->prefix, key, f->prefix, hint);
      oclua_error(L, fname, "unknown field '%s%s'", f->prefix, key);
    } else if (array && lua_isinteger(L, -1) && lua_tointeger(L, -1) >= 1) {
      lua_Integer k = lua_tointeger(L, -1);
      count++;
      if (k > maxkey) maxkey = k;
    } else if (lua_isinteger(L, -1)) {
      lua_Integer k = lua_tointeger(L, -1);
      oclua_error(L, fname,
                  "unexpected array item [%I]%s (fields are named, "
                  "e.g. %s%s = ...)",
                  (LUAI_UACINT)k, in_field(f), f->prefix,
                  known[0] ? known[0] : "name");
    } else {
      const char *type = luaL_typename(L, -1);
      oclua_error(L, fname, "unexpected key of type %s%s (fields are named)",
                  type, in_field(f));
    }
  }
  if (count != maxkey)
    oclua_error(L, fname,
                "the array part%s must be a sequence 1..n without "
                "holes (%I items, largest index %I)",
                in_field(f), (LUAI_UACINT)count, (LUAI_UACINT)maxkey);
  f->narray = count;
}

/* ---- scalar fields --------------------------------------------------- */

int oclua_field_push(const oclua_fields *f, const char *name) {
  return lua_getfield(f->L, f->t, name);
}

int oclua_field_error(const oclua_fields *f, const char *name, int idx,
                      const char *what) {
  lua_State *L = f->L;
  const char *got = oclua_got(L, idx);
  return oclua_error(L, f->fname, "'%s%s' %s (got %s)", f->prefix, name, what,
                     got);
}

int oclua_field_missing(const oclua_fields *f, const char *name,
                        const char *what) {
  return oclua_error(f->L, f->fname, "missing field '%s%s' (%s)", f->prefix,
                     name, what);
}

static const char *rule_text(int rule) {
  switch (rule) {
  case OCLUA_POSITIVE:
    return "must be a positive number";
  case OCLUA_NONZERO:
    return "must be a non-zero finite number";
  default:
    return "must be a finite number";
  }
}

static double check_number(const oclua_fields *f, const char *name, int rule) {
  lua_State *L = f->L;
  double x;
  int ok;
  if (lua_type(L, -1) != LUA_TNUMBER)
    oclua_field_error(f, name, -1, rule_text(rule));
  x = lua_tonumber(L, -1);
  ok = isfinite(x);
  if (rule == OCLUA_POSITIVE) ok = ok && x > 0;
  if (rule == OCLUA_NONZERO) ok = ok && x != 0;
  if (!ok) oclua_field_error(f, name, -1, rule_text(rule));
  lua_pop(L, 1);
  return x;
}

double oclua_field_number(const oclua_fields *f, const char *name, int rule) {
  if (oclua_field_push(f, name) == LUA_TNIL)
    oclua_field_missing(f, name, rule_text(rule) + strlen("must be "));
  return check_number(f, name, rule);
}

double oclua_field_optnumber(const oclua_fields *f, const char *name, int rule,
                             double def) {
  if (oclua_field_push(f, name) == LUA_TNIL) {
    lua_pop(f->L, 1);
    return def;
  }
  return check_number(f, name, rule);
}

lua_Integer oclua_field_optint(const oclua_fields *f, const char *name,
                               lua_Integer lo, lua_Integer hi,
                               lua_Integer def) {
  lua_State *L = f->L;
  lua_Integer v;
  int isint;
  if (oclua_field_push(f, name) == LUA_TNIL) {
    lua_pop(L, 1);
    return def;
  }
  v = lua_tointegerx(L, -1, &isint);
  if (lua_type(L, -1) != LUA_TNUMBER || !isint || v < lo || v > hi) {
    const char *what = lua_pushfstring(L, "must be an integer in %I..%I",
                                       (LUAI_UACINT)lo, (LUAI_UACINT)hi);
    oclua_field_error(f, name, -2, what);
  }
  lua_pop(L, 1);
  return v;
}

int oclua_field_optbool(const oclua_fields *f, const char *name, int def) {
  lua_State *L = f->L;
  int t = oclua_field_push(f, name), v = def;
  if (t == LUA_TBOOLEAN)
    v = lua_toboolean(L, -1);
  else if (t != LUA_TNIL)
    oclua_field_error(f, name, -1, "must be a boolean");
  lua_pop(L, 1);
  return v;
}

int oclua_field_optoption(const oclua_fields *f, const char *name,
                          const char *const *options, int def) {
  lua_State *L = f->L;
  int t = oclua_field_push(f, name);
  if (t == LUA_TNIL) {
    lua_pop(L, 1);
    return def;
  }
  if (t == LUA_TSTRING) {
    const char *s = lua_tostring(L, -1);
    for (int i = 0; options[i]; i++)
      if (strcmp(s, options[i]) == 0) {
        lua_pop(L, 1);
        return i;
      }
  }
  {
    luaL_Buffer b;
    luaL_buffinit(L, &b);
    luaL_addstring(&b, "must be one of ");
    for (int i = 0; options[i]; i++) {
      if (i > 0) luaL_addstring(&b, ", ");
      luaL_addchar(&b, '"');
      luaL_addstring(&b, options[i]);
      luaL_addchar(&b, '"');
    }
    luaL_pushresult(&b);
    if (t == LUA_TSTRING)
      return oclua_error(L, f->fname, "'%s%s' %s (got \"%s\")", f->prefix, name,
                         lua_tostring(L, -1), lua_tostring(L, -2));
    return oclua_field_error(f, name, -2, lua_tostring(L, -1));
  }
}

void oclua_state(lua_State *L) {
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_STATE) == LUA_TTABLE) return;
  lua_pop(L, 1);
  lua_newtable(L);
  lua_pushvalue(L, -1);
  lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_STATE);
}

lua_Integer oclua_scene_seed(lua_State *L) {
  lua_Integer seed = OCLUA_DEFAULT_SEED;
  int isint;
  lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_SEED);
  if (lua_type(L, -1) == LUA_TNUMBER) {
    lua_Integer v = lua_tointegerx(L, -1, &isint);
    if (isint && v >= 0) seed = v;
  }
  lua_pop(L, 1);
  oclua_state(L);
  lua_pushboolean(L, 1);
  lua_setfield(L, -2, "seed_used");
  lua_pop(L, 1);
  return seed;
}

uint64_t oclua_field_seed(const oclua_fields *f, const char *name) {
  lua_State *L = f->L;
  lua_Integer v;
  int isint;
  if (oclua_field_push(f, name) == LUA_TNIL) {
    lua_pop(L, 1);
    return (uint64_t)oclua_scene_seed(L);
  }
  v = lua_tointegerx(L, -1, &isint);
  if (lua_type(L, -1) != LUA_TNUMBER || !isint || v < 0)
    oclua_field_error(f, name, -1, "must be an integer >= 0");
  lua_pop(L, 1);
  return (uint64_t)v;
}

void oclua_field_noise(const oclua_fields *f, oc_noise *nz, double amp,
                       int octaves, int offset) {
  nz->wavelength = oclua_field_number(f, "wavelength", OCLUA_POSITIVE);
  nz->amplitude =
      isnan(amp) ? oclua_field_number(f, "amplitude", OCLUA_FINITE)
                 : oclua_field_optnumber(f, "amplitude", OCLUA_FINITE, amp);
  nz->octaves = (int)oclua_field_optint(f, "octaves", 1, 16, octaves);
  nz->offset =
      offset ? oclua_field_optnumber(f, "offset", OCLUA_FINITE, 0.0) : 0;
  nz->seed = oclua_field_seed(f, "seed");
}

/* ---- vectors --------------------------------------------------------- */

enum { VEC_OK, VEC_NOTTABLE, VEC_ELEMENT, VEC_LONG, VEC_NAN };

static const char *const axis_names[3] = {"x", "y", "z"};

/* Reads a vector without raising, so the caller can word the message. */
static int read_vec(lua_State *L, int idx, oc_vec3 *v, int *bad) {
  double c[3];
  int array;
  if (!lua_istable(L, idx)) return VEC_NOTTABLE;
  array = lua_geti(L, idx, 1) != LUA_TNIL;
  lua_pop(L, 1);
  for (int i = 0; i < 3; i++) {
    int t =
        array ? lua_geti(L, idx, i + 1) : lua_getfield(L, idx, axis_names[i]);
    if (t != LUA_TNUMBER) {
      *bad = i;
      lua_pop(L, 1);
      return VEC_ELEMENT;
    }
    c[i] = lua_tonumber(L, -1);
    lua_pop(L, 1);
  }
  if (array) {
    int t = lua_geti(L, idx, 4);
    lua_pop(L, 1);
    if (t != LUA_TNIL) return VEC_LONG;
  }
  *v = (oc_vec3){c[0], c[1], c[2]};
  for (int i = 0; i < 3; i++)
    if (!isfinite(c[i])) {
      *bad = i;
      return VEC_NAN;
    }
  return VEC_OK;
}

oc_vec3 oclua_tovec(lua_State *L, int idx, const char *fname, const char *label,
                    lua_Integer elem) {
  oc_vec3 v = {0, 0, 0};
  int bad = 0, status;
  const char *name;
  idx = lua_absindex(L, idx);
  status = read_vec(L, idx, &v, &bad);
  if (status == VEC_OK) return v;
  name = elem > 0 ? lua_pushfstring(L, "%s[%I]", label, (LUAI_UACINT)elem)
                  : lua_pushstring(L, label);
  switch (status) {
  case VEC_NOTTABLE:
    oclua_error(L, fname, "'%s' must be a table of 3 numbers (got %s)", name,
                oclua_got(L, idx));
    break;
  case VEC_ELEMENT:
    if (lua_geti(L, idx, 1) != LUA_TNIL) {
      lua_geti(L, idx, bad + 1);
      oclua_error(L, fname, "'%s' must be a table of 3 numbers (item %d is %s)",
                  name, bad + 1, oclua_got(L, -1));
    }
    lua_getfield(L, idx, axis_names[bad]);
    oclua_error(L, fname, "'%s' must be a table of 3 numbers ('%s' is %s)",
                name, axis_names[bad], oclua_got(L, -1));
    break;
  case VEC_LONG:
    oclua_error(L, fname, "'%s' must be a table of 3 numbers (got more than 3)",
                name);
    break;
  default: {
    double c = bad == 0 ? v.x : bad == 1 ? v.y : v.z;
    oclua_error(L, fname, "'%s' must have finite coordinates (got %f)", name,
                (LUAI_UACNUMBER)c);
  }
  }
  return v;
}

oc_vec3 oclua_field_vec(const oclua_fields *f, const char *name) {
  oc_vec3 v;
  if (!oclua_field_optvec(f, name, &v))
    oclua_field_missing(f, name, "a table of 3 numbers");
  return v;
}

int oclua_field_optvec(const oclua_fields *f, const char *name, oc_vec3 *v) {
  lua_State *L = f->L;
  if (oclua_field_push(f, name) == LUA_TNIL) {
    lua_pop(L, 1);
    return 0;
  }
  if (*f->prefix) {
    const char *label = lua_pushfstring(L, "%s%s", f->prefix, name);
    *v = oclua_tovec(L, -2, f->fname, label, 0);
    lua_pop(L, 2);
  } else {
    *v = oclua_tovec(L, -1, f->fname, name, 0);
    lua_pop(L, 1);
  }
  return 1;
}

void oclua_checkargs(lua_State *L, int n, const char *fname,
                     const char *usage) {
  int top = lua_gettop(L);
  if (top > n)
    oclua_error(L, fname, "too many arguments (%d; usage: %s)", top, usage);
}

void oclua_pushstats(lua_State *L, size_t nodes, size_t primitives,
                     size_t bytes) {
  lua_createtable(L, 0, 3);
  lua_pushinteger(L, (lua_Integer)nodes);
  lua_setfield(L, -2, "nodes");
  lua_pushinteger(L, (lua_Integer)primitives);
  lua_setfield(L, -2, "primitives");
  lua_pushinteger(L, (lua_Integer)bytes);
  lua_setfield(L, -2, "bytes");
}

/* Reads an array of exactly n finite numbers. Returns 0 when absent. */
int oclua_field_numbers(const oclua_fields *f, const char *name, int n,
                        double *out, const char *what) {
  lua_State *L = f->L;
  if (oclua_field_push(f, name) == LUA_TNIL) {
    lua_pop(L, 1);
    return 0;
  }
  if (!lua_istable(L, -1) || lua_rawlen(L, -1) != (size_t)n)
    oclua_field_error(f, name, -1, what);
  for (int i = 0; i < n; i++) {
    if (lua_geti(L, -1, i + 1) != LUA_TNUMBER || !isfinite(lua_tonumber(L, -1)))
      oclua_error(L, f->fname, "'%s%s' %s (item %d is %s)", f->prefix, name,
                  what, i + 1, oclua_got(L, -1));
    out[i] = lua_tonumber(L, -1);
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  return 1;
}

const double *oclua_read_palette(lua_State *L, int idx, const char *fname,
                                 const char *label, int *nstops) {
  static const char *const rgb[3] = {"r", "g", "b"};
  idx = lua_absindex(L, idx);
  lua_Integer n = lua_istable(L, idx) ? (lua_Integer)lua_rawlen(L, idx) : 0;
  if (n < 1 || n > OCLUA_MAX_STOPS)
    oclua_error(L, fname,
                "'%s' must be an array of 1..%d {value, {r, g, b}} (got %s)",
                label, OCLUA_MAX_STOPS, oclua_got(L, idx));
  double *stops = lua_newuserdatauv(L, (size_t)n * 4 * sizeof *stops, 0);
  for (lua_Integer k = 1; k <= n; k++) {
    double *s = stops + 4 * (k - 1);
    lua_geti(L, idx, k);
    if (!lua_istable(L, -1) || lua_rawlen(L, -1) != 2)
      oclua_error(L, fname, "'%s[%I]' must be {value, {r, g, b}} (got %s)",
                  label, (LUAI_UACINT)k, oclua_got(L, -1));
    if (lua_geti(L, -1, 1) != LUA_TNUMBER || !isfinite(lua_tonumber(L, -1)))
      oclua_error(L, fname, "'%s[%I]' value must be a finite number (got %s)",
                  label, (LUAI_UACINT)k, oclua_got(L, -1));
    s[0] = lua_tonumber(L, -1);
    lua_pop(L, 1);
    if (k > 1 && s[0] < s[-4])
      oclua_error(L, fname,
                  "'%s' values must be in ascending order (item %I: %f "
                  "after %f)",
                  label, (LUAI_UACINT)k, (LUAI_UACNUMBER)s[0],
                  (LUAI_UACNUMBER)s[-4]);
    if (lua_geti(L, -1, 2) != LUA_TTABLE || lua_rawlen(L, -1) != 3)
      oclua_error(L, fname, "'%s[%I]' colour must be {r, g, b} (got %s)", label,
                  (LUAI_UACINT)k, oclua_got(L, -1));
    for (int j = 0; j < 3; j++) {
      int t = lua_geti(L, -1, j + 1);
      double x = lua_tonumber(L, -1);
      if (t != LUA_TNUMBER || !(x >= 0 && x <= 1))
        oclua_error(L, fname,
                    "'%s[%I]' colour components must be in [0, 1] (got "
                    "%s = %s)",
                    label, (LUAI_UACINT)k, rgb[j], oclua_got(L, -1));
      s[1 + j] = x;
      lua_pop(L, 1);
    }
    lua_pop(L, 2);
  }
  *nstops = (int)n;
  return stops;
}

/* An array of {x, y} at stack index idx, n in [lo, hi] entries, into a
** Lua-owned array of 2 n doubles pushed on the stack (raw reads). */
double *oclua_read_xy(lua_State *L, int idx, const char *fname,
                      const char *label, lua_Integer lo, lua_Integer hi,
                      size_t *n) {
  if (!lua_istable(L, idx))
    oclua_error(L, fname, "'%s' must be an array of {x, y} (got %s)", label,
                oclua_got(L, idx));
  lua_Integer m = (lua_Integer)lua_rawlen(L, idx);
  if (m < lo || m > hi) {
    if (lo == hi)
      oclua_error(L, fname, "'%s' must hold %I points {x, y} (got %I)", label,
                  lo, m);
    oclua_error(L, fname, "'%s' must hold %I to %I points {x, y} (got %I)",
                label, lo, hi, m);
  }
  double *a = lua_newuserdatauv(L, 2 * (size_t)m * sizeof *a, 0);
  for (lua_Integer i = 1; i <= m; i++) {
    lua_rawgeti(L, idx, i);
    int ok = lua_istable(L, -1) && lua_rawlen(L, -1) == 2;
    for (int k = 1; ok && k <= 2; k++) {
      lua_rawgeti(L, -1, k);
      ok = lua_type(L, -1) == LUA_TNUMBER && isfinite(lua_tonumber(L, -1));
      if (ok) a[2 * (i - 1) + (k - 1)] = lua_tonumber(L, -1);
      lua_pop(L, 1);
    }
    if (!ok)
      oclua_error(L, fname, "'%s[%I]' must be {x, y} with finite numbers",
                  label, i);
    lua_pop(L, 1);
  }
  *n = (size_t)m;
  return a;
}
