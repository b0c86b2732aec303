/*
** l_provenance.c — oclua_stamp_provenance: where an image came from,
** written into its metadata so that a picture found later can be made
** again (same scene, parameters, seed and inputs give the same bytes),
** and checked (the hashes of the scene and of the files it read).
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "l_config.h"
#include "l_provenance.h"

#define FNAME "outcrop (provenance)"
/* oc_image_set_meta takes values up to 65535 bytes; parameters beyond
** this are cut with a marker rather than failing the write. */
#define MAX_PARAMS_TEXT 65000
/* Not "": OpenImageIO's EXR reader drops empty attributes, and a reader
** should see "no parameters" rather than no record. No pair looks like
** this: every pair holds a '='. */
#define NO_PARAMS "(none)"

static void set(lua_State *L, oc_image *img, const char *key,
                const char *value) {
  oc_error err = {OC_OK, ""};
  if (oc_image_set_meta(img, key, value, &err) != OC_OK)
    oclua_liberror(L, FNAME, &err);
}

/* Pushes the scene's name (see l_provenance.h). */
static void push_scene(lua_State *L) {
  lua_Debug ar;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_SCENE) == LUA_TSTRING) return;
  lua_pop(L, 1);
  /* Stock lua5.4: the nearest chunk run as a file is the best guess. */
  for (int level = 1; lua_getstack(L, level, &ar); level++) {
    lua_getinfo(L, "S", &ar);
    if (strcmp(ar.what, "main") == 0 && ar.source[0] == '@') {
      lua_pushstring(L, ar.source + 1);
      return;
    }
  }
  lua_pushliteral(L, "(none)");
}

/* Pushes the SHA-256 of the scene named at the top: the interpreter's
** (of the bytes it loaded), else that of the file by that name, hashed
** once per name and run. */
static void push_scene_sha256(lua_State *L) {
  const char *scene = lua_tostring(L, -1);
  char hex[OC_SHA256_HEX];
  oc_error err = {OC_OK, ""};
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_SCENE_SHA256) == LUA_TSTRING)
    return;
  lua_pop(L, 1);
  if (strcmp(scene, "(none)") == 0 || strcmp(scene, "-") == 0) {
    lua_pushliteral(L, "(none)");
    return;
  }
  oclua_state(L);
  luaL_getsubtable(L, -1, "scene_sha256");
  if (lua_getfield(L, -1, scene) != LUA_TSTRING) {
    lua_pop(L, 1);
    if (oc_infile_sha256(scene, hex, &err) != OC_OK)
      strcpy(hex, "(unreadable)");
    lua_pushstring(L, hex);
    lua_pushvalue(L, -1);
    lua_setfield(L, -3, scene);
  }
  lua_replace(L, -3);
  lua_pop(L, 1);
}

/* A bounded text buffer owned by a Lua userdata, so that an error raised
** meanwhile leaks nothing. Appends past the end are dropped and noted. */
typedef struct text {
  char *p;
  size_t n, cap;
  int cut;
} text;

static void add(text *t, const char *s, size_t n) {
  if (t->cut || n > t->cap - t->n) {
    t->cut = 1;
    return;
  }
  memcpy(t->p + t->n, s, n);
  t->n += n;
}

static int needs_quotes(const char *s, size_t n) {
  for (size_t i = 0; i < n; i++) {
    unsigned char c = (unsigned char)s[i];
    if (c <= ' ' || c == 0x7f || c == '"' || c == '\\') return 1;
  }
  return 0;
}

/* A quoted pair is added whole or not at all. */
static void add_pair(text *t, const char *s, size_t n) {
  char tmp[8];
  size_t mark = t->n;
  if (!needs_quotes(s, n)) {
    add(t, s, n);
    return;
  }
  add(t, "\"", 1);
  for (size_t i = 0; i < n; i++) {
    unsigned char c = (unsigned char)s[i];
    if (c == '"' || c == '\\') {
      tmp[0] = '\\', tmp[1] = (char)c;
      add(t, tmp, 2);
    } else if (c == '\n') {
      add(t, "\\n", 2);
    } else if (c == '\t') {
      add(t, "\\t", 2);
    } else if (c == '\r') {
      add(t, "\\r", 2);
    } else if (c < ' ' || c == 0x7f) {
      snprintf(tmp, sizeof tmp, "\\%03u", (unsigned)c);
      add(t, tmp, 4);
    } else {
      add(t, s + i, 1); /* UTF-8 bytes stay as they are */
    }
  }
  add(t, "\"", 1);
  if (t->cut) t->n = mark;
}

static int by_name(const void *a, const void *b) {
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Pushes the text of the string array of `n` items at names, each
** quoted as add_pair does, separated by spaces, sorted when `sort`, cut
** with a marker past MAX_PARAMS_TEXT; NO_PARAMS when n is 0. */
static void push_list(lua_State *L, const char **names, size_t n, int t,
                      int sort) {
  if (sort) qsort(names, n, sizeof *names, by_name);
  text out = {lua_newuserdatauv(L, MAX_PARAMS_TEXT, 0), 0, MAX_PARAMS_TEXT - 4,
              0};
  for (size_t i = 0; i < n && !out.cut; i++) {
    size_t len;
    const char *pair;
    if (t) { /* a table of name -> text */
      lua_getfield(L, t, names[i]);
      pair = lua_pushfstring(L, "%s=%s", names[i], lua_tostring(L, -1));
    } else {
      pair = lua_pushstring(L, names[i]);
    }
    len = lua_rawlen(L, -1);
    if (i) add(&out, " ", 1);
    add_pair(&out, pair, len);
    lua_pop(L, t ? 2 : 1);
  }
  if (out.cut) { /* room was kept for the marker */
    out.cut = 0;
    out.cap += 4;
    add(&out, "...", 3);
  }
  if (n == 0)
    lua_pushliteral(L, NO_PARAMS);
  else
    lua_pushlstring(L, out.p, out.n);
  lua_remove(L, -2);
}

/* Copies the text of every value of table `from` with a string key into
** table `to` (as name -> text). */
static void merge(lua_State *L, int to, int from, int records) {
  lua_pushnil(L);
  while (lua_next(L, from)) {
    if (lua_type(L, -2) == LUA_TSTRING) {
      if (records) lua_rawgeti(L, -1, 1); /* {default} */
      if (!lua_isnil(L, -1)) {
        lua_pushvalue(L, -2 - records);
        oclua_param_text(L, -2);
        lua_rawset(L, to);
      }
      if (records) lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
}

/* Pushes the parameters as one line, sorted by name: every parameter
** outcrop.param read, with the configured value or else its default
** (those read without a default and not configured are left out: no
** --set value gives nil), and the configured ones no call read (yet).
** Sorted because the tables' traversal order changes from run to run,
** the bytes of a file must not. */
static void push_params(lua_State *L) {
  size_t n = 0, k = 0;
  int base = lua_gettop(L);
  lua_newtable(L); /* name -> text */
  int t = base + 1;
  oclua_state(L);
  if (lua_getfield(L, -1, "reads") == LUA_TTABLE) merge(L, t, base + 3, 1);
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS) == LUA_TTABLE)
    merge(L, t, base + 4, 0);
  lua_settop(L, t);
  lua_pushnil(L);
  while (lua_next(L, t)) {
    n++;
    lua_pop(L, 1);
  }
  /* The names stay alive as keys of the table at t. */
  const char **names = lua_newuserdatauv(L, (n ? n : 1) * sizeof *names, 0);
  lua_pushnil(L);
  while (lua_next(L, t)) {
    if (k < n) names[k++] = lua_tostring(L, -2);
    lua_pop(L, 1);
  }
  push_list(L, names, k, t, 1);
  lua_replace(L, t);
  lua_settop(L, t);
}

/* Pushes the input files as "name=sha256" pairs in read order. */
static void push_inputs(lua_State *L) {
  int base = lua_gettop(L);
  oclua_state(L);
  luaL_getsubtable(L, -1, "inputs");
  size_t n = lua_rawlen(L, -1);
  const char **names = lua_newuserdatauv(L, (n ? n : 1) * sizeof *names, 0);
  for (size_t i = 0; i < n; i++) {
    lua_rawgeti(L, base + 2, (lua_Integer)i + 1);
    names[i] = lua_tostring(L, -1); /* alive in the array */
    lua_pop(L, 1);
  }
  push_list(L, names, n, 0, 0);
  lua_replace(L, base + 1);
  lua_settop(L, base + 1);
}

void oclua_push_provenance(lua_State *L,
                           const char *kv[2 * OCLUA_PROVENANCE_PAIRS]) {
  static const char *const keys[OCLUA_PROVENANCE_PAIRS] = {
      OCLUA_META_SOFTWARE,     OCLUA_META_VERSION, OCLUA_META_SCENE,
      OCLUA_META_SCENE_SHA256, OCLUA_META_SEED,    OCLUA_META_PARAMS,
      OCLUA_META_INPUTS};
  luaL_checkstack(L, OCLUA_PROVENANCE_PAIRS + 8, NULL);
  /* whatever follows, configure may not change what this records */
  oclua_mark_written(L);
  lua_pushliteral(L, "outcrop " OC_VERSION);
  lua_pushliteral(L, OC_VERSION);
  push_scene(L);
  push_scene_sha256(L);
  lua_pushfstring(L, "%I", (LUAI_UACINT)oclua_scene_seed(L));
  push_params(L);
  push_inputs(L);
  for (int i = 0; i < OCLUA_PROVENANCE_PAIRS; i++) {
    kv[2 * i] = keys[i];
    kv[2 * i + 1] = lua_tostring(L, i - OCLUA_PROVENANCE_PAIRS);
  }
}

void oclua_stamp_provenance(lua_State *L, oc_image *img) {
  const char *kv[2 * OCLUA_PROVENANCE_PAIRS];
  oclua_push_provenance(L, kv);
  for (int i = 0; i < OCLUA_PROVENANCE_PAIRS; i++)
    set(L, img, kv[2 * i], kv[2 * i + 1]);
  lua_pop(L, OCLUA_PROVENANCE_PAIRS);
}
