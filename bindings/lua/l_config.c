/*
** l_config.c — outcrop.configure and outcrop.param, and what a run read.
**
** One configuration per Lua state, set through oclua_configure whichever
** the front end: the interpreter passes --seed, --set and --out to it,
** an embedder under stock lua5.4 calls outcrop.configure. Each of seed,
** every parameter name and out is set at most once: a later call may
** repeat a value or fill one not set yet, never change one (nor change
** anything once an output was written, nor a parameter already read, nor
** the seed once something used it), so what a file records is what the
** whole run used.
**
** OCLUA_STATE holds:
**   seed_set, out_set  configure fixed the seed, the output folder
**   seed_used          the scene seed was read (l_util.c)
**   written            an output was written (oclua_mark_written)
**   reads              name -> {default}: what outcrop.param read first
**   order              names in the order of their first read
**   inputs, inputset   "name=sha256" pairs of the input files, in read
**                      order, and the set of them
**   scene_sha256       scene file -> its hash (l_provenance.c's cache)
*/
#define _XOPEN_SOURCE 700 /* realpath */

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "l_config.h"

/* Names longer than this get no "did you mean" (the distance is
** quadratic). */
#define MAX_SUGGEST 256

static int state_flag(lua_State *L, int st, const char *name) {
  int v = (lua_getfield(L, st, name), lua_toboolean(L, -1));
  lua_pop(L, 1);
  return v;
}

static void state_set(lua_State *L, int st, const char *name) {
  lua_pushboolean(L, 1);
  lua_setfield(L, st, name);
}

void oclua_mark_written(lua_State *L) {
  oclua_state(L);
  state_set(L, lua_gettop(L), "written");
  lua_pop(L, 1);
}

const char *oclua_param_text(lua_State *L, int idx) {
  idx = lua_absindex(L, idx);
  switch (lua_type(L, idx)) {
  case LUA_TSTRING:
    lua_pushvalue(L, idx);
    break;
  case LUA_TBOOLEAN:
    lua_pushstring(L, lua_toboolean(L, idx) ? "true" : "false");
    break;
  case LUA_TNUMBER:
    if (lua_isinteger(L, idx)) {
      lua_pushfstring(L, "%I", (LUAI_UACINT)lua_tointeger(L, idx));
    } else {
      char buf[64];
      double v = (double)lua_tonumber(L, idx);
      snprintf(buf, sizeof buf, "%.14g", v);
      if (strtod(buf, NULL) != v) snprintf(buf, sizeof buf, "%.17g", v);
      if (buf[strspn(buf, "-0123456789")] == '\0') strcat(buf, ".0");
      lua_pushstring(L, buf);
    }
    break;
  default:
    luaL_tolstring(L, idx, NULL);
    break;
  }
  return lua_tostring(L, -1);
}

/* ---- outcrop.configure ---------------------------------------------------
 */

static int written_error(lua_State *L, const char *fname) {
  return oclua_error(L, fname,
                     "outputs were already written (configure before the "
                     "first write)");
}

/* Checks the params table at t: non-empty string names without '=', and
** string, finite number or boolean values. */
static void check_params(lua_State *L, int t, const char *fname) {
  lua_pushnil(L);
  while (lua_next(L, t)) {
    if (lua_type(L, -2) != LUA_TSTRING)
      oclua_error(L, fname, "'params' keys must be parameter names (got %s)",
                  oclua_got(L, -2));
    const char *name = lua_tostring(L, -2);
    if (name[0] == '\0' || strchr(name, '='))
      oclua_error(L, fname,
                  "'params' names must be non-empty and hold no '=' (got "
                  "\"%s\")",
                  name);
    int vt = lua_type(L, -1);
    if (vt == LUA_TNUMBER && !isfinite((double)lua_tonumber(L, -1)))
      oclua_error(L, fname, "'params.%s' must be a finite number (got %s)",
                  name, oclua_got(L, -1));
    if (vt != LUA_TSTRING && vt != LUA_TNUMBER && vt != LUA_TBOOLEAN)
      oclua_error(L, fname,
                  "'params.%s' must be a string, a number or a boolean (got "
                  "%s)",
                  name, oclua_got(L, -1));
    lua_pop(L, 1);
  }
}

/* What the seed field asks: 0 nothing to do, 1 set it. Raises on a
** conflict. */
static int check_seed(lua_State *L, int st, lua_Integer seed,
                      const char *fname) {
  lua_Integer cur = OCLUA_DEFAULT_SEED;
  int isint;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_SEED) == LUA_TNUMBER) {
    lua_Integer v = lua_tointegerx(L, -1, &isint);
    if (isint && v >= 0) cur = v;
  }
  lua_pop(L, 1);
  if (state_flag(L, st, "seed_set")) {
    if (cur != seed)
      oclua_error(L, fname, "'seed' is already configured as %I (got %I)",
                  (LUAI_UACINT)cur, (LUAI_UACINT)seed);
    return 0;
  }
  if (cur != seed && state_flag(L, st, "seed_used"))
    oclua_error(L, fname,
                "'seed' comes too late: the scene seed %I was already used "
                "(by outcrop.seed or a constructor without seed)",
                (LUAI_UACINT)cur);
  if (cur != seed && state_flag(L, st, "written")) written_error(L, fname);
  return 1;
}

/* Raises when parameter `name` (value at v) conflicts with the
** configuration; returns 1 when it is to be set. */
static int check_param(lua_State *L, int st, int v, const char *name,
                       const char *fname) {
  int top = lua_gettop(L), set = 1;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS) == LUA_TTABLE &&
      lua_getfield(L, -1, name) != LUA_TNIL) {
    const char *was = oclua_param_text(L, -1);
    const char *now = oclua_param_text(L, v);
    if (strcmp(was, now) != 0)
      oclua_error(L, fname,
                  "'params.%s' is already configured as \"%s\" (got \"%s\")",
                  name, was, now);
    set = 0;
  } else {
    lua_getfield(L, st, "reads");
    if (lua_istable(L, -1) && lua_getfield(L, -1, name) != LUA_TNIL)
      oclua_error(L, fname,
                  "'params.%s' comes too late: outcrop.param already read it",
                  name);
    if (state_flag(L, st, "written")) written_error(L, fname);
  }
  lua_settop(L, top);
  return set;
}

/* Resolves `out` into real (PATH_MAX bytes); raises on a conflict.
** Returns 1 when OCLUA_OUTDIR is to be set. */
static int check_out(lua_State *L, int st, const char *out, char *real,
                     const char *fname) {
  struct stat sb;
  lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_SANDBOX);
  if (lua_toboolean(L, -1))
    oclua_error(L, fname,
                "'out' cannot be set in the sandbox (outputs go to the "
                "interpreter's --out folder)");
  lua_pop(L, 1);
  if (stat(out, &sb) != 0 || realpath(out, real) == NULL)
    oclua_error(L, fname, "'out' must name an existing folder ('%s': %s)", out,
                strerror(errno));
  if (!S_ISDIR(sb.st_mode))
    oclua_error(L, fname,
                "'out' must name an existing folder ('%s' is not "
                "a folder)",
                out);
  lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_OUTDIR);
  const char *cur = lua_tostring(L, -1);
  int same = cur && strcmp(cur, real) == 0;
  if (!same && state_flag(L, st, "out_set"))
    oclua_error(L, fname, "'out' is already configured as '%s' (got '%s')",
                cur ? cur : ".", real);
  if (!same && state_flag(L, st, "written")) written_error(L, fname);
  lua_pop(L, 1);
  state_set(L, st, "out_set");
  return !same;
}

void oclua_configure(lua_State *L, int idx, const char *fname) {
  static const char *const known[] = {"seed", "params", "out", NULL};
  oclua_fields f;
  char real[PATH_MAX];
  int top = lua_gettop(L), isint;
  idx = lua_absindex(L, idx);
  oclua_fields_open(&f, L, idx, fname, NULL, known, 0);
  oclua_state(L);
  int st = lua_gettop(L);

  /* every field is checked before anything is stored */
  int has_seed = oclua_field_push(&f, "seed") != LUA_TNIL;
  lua_Integer seed = lua_tointegerx(L, -1, &isint);
  if (has_seed && (lua_type(L, -1) != LUA_TNUMBER || !isint || seed < 0))
    oclua_field_error(&f, "seed", -1, "must be an integer >= 0");
  lua_pop(L, 1);

  int pt = oclua_field_push(&f, "params"), params = lua_gettop(L);
  if (pt != LUA_TNIL && pt != LUA_TTABLE)
    oclua_field_error(&f, "params", -1, "must be a table {name = value}");
  if (pt == LUA_TTABLE) check_params(L, params, fname);

  int ot = oclua_field_push(&f, "out"), set_out = 0;
  if (ot != LUA_TNIL) {
    if (ot != LUA_TSTRING)
      oclua_field_error(&f, "out", -1, "must be a string (a folder)");
    set_out = check_out(L, st, lua_tostring(L, -1), real, fname);
  }
  lua_pop(L, 1);

  has_seed = has_seed && check_seed(L, st, seed, fname);
  if (pt == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, params)) {
      if (!check_param(L, st, lua_gettop(L), lua_tostring(L, -2), fname)) {
        lua_pushvalue(L, -2);
        lua_pushnil(L);
        lua_rawset(L, params); /* nothing to store (allowed during next) */
      }
      lua_pop(L, 1);
    }
  }

  /* store */
  if (has_seed) {
    lua_pushinteger(L, seed);
    lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_SEED);
    state_set(L, st, "seed_set");
  }
  if (pt == LUA_TTABLE) {
    luaL_getsubtable(L, LUA_REGISTRYINDEX, OCLUA_PARAMS);
    lua_pushnil(L);
    while (lua_next(L, params)) {
      lua_pushvalue(L, -2);
      lua_insert(L, -2);
      lua_rawset(L, -4);
    }
    lua_pop(L, 1);
  }
  if (set_out) {
    lua_pushstring(L, real);
    lua_setfield(L, LUA_REGISTRYINDEX, OCLUA_OUTDIR);
    state_set(L, st, "out_set");
  }
  lua_settop(L, top);
}

/* Pushes a shallow raw copy of the table at idx. */
static void copy_table(lua_State *L, int idx) {
  lua_newtable(L);
  lua_pushnil(L);
  while (lua_next(L, idx)) {
    lua_pushvalue(L, -2);
    lua_insert(L, -2);
    lua_rawset(L, -4);
  }
}

static int l_configure(lua_State *L) {
  const char *fname = "outcrop.configure";
  if (lua_type(L, 1) != LUA_TTABLE)
    oclua_error(L, fname, "expects a table {seed =, params =, out =} (got %s)",
                oclua_got(L, 1));
  oclua_checkargs(L, 1, fname, "{seed =, params =, out =}");
  /* a copy of params: the caller's table is not changed */
  if (lua_getfield(L, 1, "params") == LUA_TTABLE) {
    copy_table(L, lua_gettop(L));
    copy_table(L, 1); /* the other fields as they are */
    lua_insert(L, -2);
    lua_setfield(L, -2, "params");
    oclua_configure(L, -1, fname);
    return 0;
  }
  lua_pop(L, 1);
  oclua_configure(L, 1, fname);
  return 0;
}

/* ---- outcrop.param ---------------------------------------------------------
 */

/* Notes the first read of parameter (name at 1, default at 2). */
static void record_read(lua_State *L) {
  oclua_state(L);                  /* 3 */
  luaL_getsubtable(L, 3, "reads"); /* 4 */
  lua_pushvalue(L, 1);
  if (lua_rawget(L, 4) == LUA_TNIL) {
    lua_pushvalue(L, 1);
    lua_createtable(L, 1, 0);
    lua_pushvalue(L, 2);
    lua_rawseti(L, -2, 1);
    lua_rawset(L, 4);                /* reads[name] = {default} */
    luaL_getsubtable(L, 3, "order"); /* 6 */
    lua_pushvalue(L, 1);
    lua_rawseti(L, 6, (lua_Integer)lua_rawlen(L, 6) + 1);
  }
  lua_settop(L, 2);
}

/* outcrop.param(name, default): the configured value for name, as a
** number when a string reads as one ("3", "1e-2", "0x10"), a boolean for
** "true" and "false", else the string (values configured as Lua values
** come back as they are); `default` when there is no such parameter. */
static int l_param(lua_State *L) {
  const char *fname = "outcrop.param";
  if (lua_type(L, 1) != LUA_TSTRING)
    oclua_error(L, fname, "the parameter name must be a string (got %s)",
                oclua_got(L, 1));
  oclua_checkargs(L, 2, fname, "(name [, default])");
  int dt = lua_type(L, 2);
  if (dt != LUA_TNONE && dt != LUA_TNIL && dt != LUA_TSTRING &&
      dt != LUA_TNUMBER && dt != LUA_TBOOLEAN)
    oclua_error(L, fname,
                "the default must be a string, a number or a boolean (got %s)",
                oclua_got(L, 2));
  lua_settop(L, 2);
  record_read(L);
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS) != LUA_TTABLE) {
    lua_settop(L, 2);
    return 1;
  }
  lua_pushvalue(L, 1);
  switch (lua_gettable(L, -2)) {
  case LUA_TNIL:
    lua_settop(L, 2);
    return 1;
  case LUA_TSTRING: {
    const char *s = lua_tostring(L, -1);
    if (strcmp(s, "true") == 0)
      lua_pushboolean(L, 1);
    else if (strcmp(s, "false") == 0)
      lua_pushboolean(L, 0);
    else
      lua_stringtonumber(L, s); /* on failure the string stays on top */
    return 1;
  }
  default: /* set by a host as a Lua value already */
    return 1;
  }
}

/* ---- what was read -------------------------------------------------------
 */

/* Optimal string alignment distance (edits, and swaps of neighbours:
** "stpes" is 1 from "steps"). */
static size_t distance(const char *a, size_t n, const char *b, size_t m) {
  size_t r0[MAX_SUGGEST + 1], r1[MAX_SUGGEST + 1], r2[MAX_SUGGEST + 1];
  size_t *pp = r0, *p = r1, *c = r2;
  for (size_t j = 0; j <= m; j++)
    p[j] = j;
  for (size_t i = 1; i <= n; i++) {
    c[0] = i;
    for (size_t j = 1; j <= m; j++) {
      size_t cost = a[i - 1] != b[j - 1];
      size_t d = p[j - 1] + cost;
      if (p[j] + 1 < d) d = p[j] + 1;
      if (c[j - 1] + 1 < d) d = c[j - 1] + 1;
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
          pp[j - 2] + 1 < d)
        d = pp[j - 2] + 1;
      c[j] = d;
    }
    size_t *t = pp;
    pp = p, p = c, c = t;
  }
  return p[m];
}

static int by_name(const void *a, const void *b) {
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

int oclua_params_unread(lua_State *L) {
  int top = lua_gettop(L), count = 0;
  luaL_Buffer b;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS) != LUA_TTABLE) {
    lua_settop(L, top);
    lua_pushliteral(L, "");
    return 0;
  }
  int params = lua_gettop(L);
  oclua_state(L);
  luaL_getsubtable(L, -1, "reads");
  luaL_getsubtable(L, -2, "order");
  int reads = params + 2, order = params + 3;
  size_t n = 0, k = 0;
  lua_pushnil(L);
  while (lua_next(L, params)) {
    n += lua_type(L, -2) == LUA_TSTRING;
    lua_pop(L, 1);
  }
  /* the names stay alive as keys of params */
  const char **names = lua_newuserdatauv(L, (n ? n : 1) * sizeof *names, 0);
  lua_pushnil(L);
  while (lua_next(L, params)) {
    lua_pop(L, 1);
    if (lua_type(L, -1) != LUA_TSTRING || k == n) continue;
    lua_pushvalue(L, -1);
    if (lua_rawget(L, reads) == LUA_TNIL) names[k++] = lua_tostring(L, -2);
    lua_pop(L, 1);
  }
  qsort(names, k, sizeof *names, by_name);
  luaL_buffinit(L, &b);
  for (size_t i = 0; i < k; i++) {
    size_t len = strlen(names[i]), best = (size_t)-1;
    const char *near = NULL;
    lua_Integer nread = (lua_Integer)lua_rawlen(L, order);
    for (lua_Integer j = 1; j <= nread && len <= MAX_SUGGEST; j++) {
      size_t m;
      lua_rawgeti(L, order, j);
      const char *r = lua_tolstring(L, -1, &m);
      lua_pop(L, 1); /* r stays alive as a key of reads */
      if (m > MAX_SUGGEST) continue;
      size_t d = distance(names[i], len, r, m);
      if (d < best) best = d, near = r;
    }
    /* close: at most two edits, and fewer than half the name */
    if (near && best <= 2 && 2 * best <= len)
      lua_pushfstring(L,
                      "--set %s: no outcrop.param reads it (did you mean "
                      "'%s'?)\n",
                      names[i], near);
    else
      lua_pushfstring(L, "--set %s: no outcrop.param reads it\n", names[i]);
    luaL_addvalue(&b);
    count++;
  }
  luaL_pushresult(&b);
  lua_replace(L, top + 1);
  lua_settop(L, top + 1);
  return count;
}

void oclua_params_list(lua_State *L) {
  int top = lua_gettop(L);
  luaL_Buffer b;
  oclua_state(L);
  luaL_getsubtable(L, -1, "reads");
  luaL_getsubtable(L, -2, "order");
  int reads = top + 2, order = top + 3;
  lua_Integer n = (lua_Integer)lua_rawlen(L, order);
  luaL_buffinit(L, &b);
  for (lua_Integer i = 1; i <= n; i++) {
    lua_rawgeti(L, order, i); /* the name, then its record, its default */
    lua_pushvalue(L, -1);
    lua_rawget(L, reads);
    lua_rawgeti(L, -1, 1);
    int t = lua_type(L, -1);
    const char *type = t == LUA_TNUMBER
                           ? (lua_isinteger(L, -1) ? "integer" : "number")
                           : lua_typename(L, t);
    const char *def = t == LUA_TNIL ? "nil" : oclua_param_text(L, -1);
    if (t == LUA_TNIL) lua_pushnil(L); /* the same slots either way */
    lua_pushfstring(L, "%s\t%s\t%s\n", lua_tostring(L, -4), def, type);
    lua_replace(L, -5);
    lua_pop(L, 3);
    luaL_addvalue(&b);
  }
  luaL_pushresult(&b);
  lua_replace(L, top + 1);
  lua_settop(L, top + 1);
}

/* ---- inputs ----------------------------------------------------------------
 */

void oclua_record_input(lua_State *L, const char *path, const char *fname) {
  char hex[OC_SHA256_HEX];
  oc_error err = {OC_OK, ""};
  int top = lua_gettop(L);
  if (oc_infile_sha256(path, hex, &err) != OC_OK)
    oclua_error(L, fname, "%s (hashing it for provenance)", err.msg);
  oclua_state(L);
  luaL_getsubtable(L, -1, "inputset");
  lua_pushfstring(L, "%s=%s", path, hex);
  lua_pushvalue(L, -1);
  if (lua_rawget(L, -3) == LUA_TNIL) {
    lua_pop(L, 1);
    lua_pushvalue(L, -1);
    lua_pushboolean(L, 1);
    lua_rawset(L, -4);
    luaL_getsubtable(L, top + 1, "inputs");
    lua_pushvalue(L, -2);
    lua_rawseti(L, -2, (lua_Integer)lua_rawlen(L, -2) + 1);
  }
  lua_settop(L, top);
}

void oclua_open_config(lua_State *L) {
  static const luaL_Reg funcs[] = {
      {"param", l_param}, {"configure", l_configure}, {NULL, NULL}};
  luaL_setfuncs(L, funcs, 0);
}
