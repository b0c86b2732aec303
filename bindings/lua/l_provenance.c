/*
** l_provenance.c — oclua_stamp_provenance: where an image came from,
** written into its metadata so that a picture found later can be made
** again (same scene, parameters and seed give the same bytes).
*/
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

/* Pushes the --set parameters as one line, sorted by name: the table's
** traversal order changes from run to run, the bytes of a file must
** not. */
static void push_params(lua_State *L) {
  size_t n = 0, k = 0;
  int t;
  if (lua_getfield(L, LUA_REGISTRYINDEX, OCLUA_PARAMS) != LUA_TTABLE) {
    lua_pop(L, 1);
    lua_pushliteral(L, NO_PARAMS);
    return;
  }
  t = lua_gettop(L);
  lua_pushnil(L);
  while (lua_next(L, t)) {
    if (lua_type(L, -2) == LUA_TSTRING) n++;
    lua_pop(L, 1);
  }
  /* The names stay alive as keys of the table at t. */
  const char **names = lua_newuserdatauv(L, (n ? n : 1) * sizeof *names, 0);
  lua_pushnil(L);
  while (lua_next(L, t)) {
    if (lua_type(L, -2) == LUA_TSTRING && k < n)
      names[k++] = lua_tostring(L, -2);
    lua_pop(L, 1);
  }
  qsort(names, k, sizeof *names, by_name);
  text out = {lua_newuserdatauv(L, MAX_PARAMS_TEXT, 0), 0, MAX_PARAMS_TEXT - 4,
              0};
  for (size_t i = 0; i < k && !out.cut; i++) {
    size_t len;
    lua_getfield(L, t, names[i]);
    /* A host may store Lua values rather than strings. */
    luaL_tolstring(L, -1, NULL);
    lua_pushfstring(L, "%s=%s", names[i], lua_tostring(L, -1));
    const char *pair = lua_tolstring(L, -1, &len);
    if (i) add(&out, " ", 1);
    add_pair(&out, pair, len);
    lua_pop(L, 3);
  }
  if (out.cut) { /* room was kept for the marker */
    out.cut = 0;
    out.cap += 4;
    add(&out, "...", 3);
  }
  if (k == 0)
    lua_pushliteral(L, NO_PARAMS);
  else
    lua_pushlstring(L, out.p, out.n);
  lua_replace(L, t);
  lua_settop(L, t);
}

void oclua_push_provenance(lua_State *L,
                           const char *kv[2 * OCLUA_PROVENANCE_PAIRS]) {
  static const char *const keys[OCLUA_PROVENANCE_PAIRS] = {
      OCLUA_META_SOFTWARE, OCLUA_META_VERSION, OCLUA_META_SCENE,
      OCLUA_META_SEED, OCLUA_META_PARAMS};
  luaL_checkstack(L, OCLUA_PROVENANCE_PAIRS + 4, NULL);
  lua_pushliteral(L, "outcrop " OC_VERSION);
  lua_pushliteral(L, OC_VERSION);
  push_scene(L);
  lua_pushfstring(L, "%I", (LUAI_UACINT)oclua_scene_seed(L));
  push_params(L);
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
