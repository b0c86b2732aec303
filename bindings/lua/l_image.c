/*
** l_image.c — the image userdata (write, size, get, channels) and
** outcrop.slice, which samples a node on an axis-aligned plane.
**
** slice defaults: plane = "xz", at = 0, size = {256, 256}, box = the
** node's bounds on the plane's two axes (an error when they are infinite
** or empty). write: bits = 0 (the format's default: 8 for PNG/JPEG, 16
** for TIFF, half floats for EXR; 32 is float for TIFF and EXR); every
** write stamps the provenance of l_provenance.h, and `meta = {k = v}`
** adds the caller's own keys (both stay on the image for later writes).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "l_field.h"
#include "l_image.h"
#include "l_provenance.h"

#define DEFAULT_SLICE_SIZE 256
#define MAX_SLICE_SIZE 16384

static void image_release(oclua_handle *h) {
  oclua_image *u = (oclua_image *)h;
  if (u->img) oc_image_free(u->img);
  u->img = NULL;
}

oclua_image *oclua_newimage(lua_State *L) {
  oclua_image *u = lua_newuserdatauv(L, sizeof *u, 0);
  oclua_handle_init(&u->h, "image", image_release);
  u->img = NULL;
  luaL_setmetatable(L, OCLUA_IMAGE);
  return u;
}

oc_image *oclua_checkimage(lua_State *L, int idx, const char *fname, int pin) {
  oclua_image *u = luaL_checkudata(L, idx, OCLUA_IMAGE);
  oclua_handle_check(L, &u->h, fname);
  if (u->img == NULL) oclua_error(L, fname, "the image is not made");
  if (pin) oclua_pin(L, idx, &u->h, fname);
  return u->img;
}

/* ---- image:write options: meta ------------------------ */

static int by_key(const void *a, const void *b) {
  return strcmp(*(const char *const *)a, *(const char *const *)b);
}

/* Reads `meta = {key = "value", ...}` of the write options at f and sets
** it on img, keys sorted so that the file's bytes do not follow the
** table's traversal order. Provenance keys are the engine's to write. */
static void set_user_meta(const oclua_fields *f, oc_image *img) {
  lua_State *L = f->L;
  oc_error err = {OC_OK, ""};
  size_t n = 0, k = 0;
  int m = lua_gettop(L) + 1;
  int t = oclua_field_push(f, "meta");
  if (t == LUA_TNIL) {
    lua_pop(L, 1);
    return;
  }
  if (t != LUA_TTABLE)
    oclua_field_error(f, "meta", m, "must be a table {key = \"value\", ...}");
  lua_pushnil(L);
  while (lua_next(L, m)) {
    int vt = lua_type(L, -1);
    if (lua_type(L, -2) != LUA_TSTRING)
      oclua_error(L, f->fname, "'meta' keys must be strings (got %s)",
                  oclua_got(L, -2));
    const char *key = lua_tostring(L, -2);
    if (vt != LUA_TSTRING && vt != LUA_TNUMBER)
      oclua_error(L, f->fname,
                  "'meta.%s' must be a string or a number (got %s)", key,
                  oclua_got(L, -1));
    if (strncmp(key, "outcrop:", 8) == 0 ||
        strcmp(key, OCLUA_META_SOFTWARE) == 0)
      oclua_error(L, f->fname,
                  "'meta.%s' is provenance, written by outcrop itself", key);
    n++;
    lua_pop(L, 1);
  }
  const char **keys = lua_newuserdatauv(L, (n ? n : 1) * sizeof *keys, 0);
  lua_pushnil(L);
  while (lua_next(L, m)) {
    if (k < n) keys[k++] = lua_tostring(L, -2);
    lua_pop(L, 1);
  }
  qsort(keys, k, sizeof *keys, by_key);
  for (size_t i = 0; i < k; i++) {
    lua_getfield(L, m, keys[i]);
    const char *v = luaL_tolstring(L, -1, NULL);
    if (oc_image_set_meta(img, keys[i], v, &err) != OC_OK)
      oclua_error(L, f->fname, "'meta.%s': %s", keys[i], err.msg);
    lua_pop(L, 2);
  }
  lua_settop(L, m - 1);
}

/* ---- methods --------------------------------------------------------- */

static int image_write(lua_State *L) {
  static const char *const known[] = {"bits", "meta", NULL};
  const char *fname = "image:write";
  oclua_checkimage(L, 1, fname, 0);
  oc_error err = {OC_OK, ""};
  int bits = 0;
  if (lua_type(L, 2) != LUA_TSTRING)
    oclua_error(L, fname, "the path must be a string (got %s)",
                oclua_got(L, 2));
  oclua_checkargs(L, 3, fname, "(path [, {bits = 8, 16 or 32, meta = {}}])");
  lua_settop(L, 3);
  oc_image *img = oclua_checkimage(L, 1, fname, 1);
  oclua_stamp_provenance(L, img);
  if (!lua_isnil(L, 3)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 3, fname, NULL, known, 0);
    bits = (int)oclua_field_optint(&f, "bits", -65536, 65536, 0);
    if (bits != 0 && bits != 8 && bits != 16 && bits != 32)
      oclua_error(L, fname,
                  "'bits' must be 8 or 16, or 32 for TIFF and EXR (got %d)",
                  bits);
    set_user_meta(&f, img);
  }
  oclua_target t;
  int e = oclua_output_target(L, fname, lua_tostring(L, 2), OCLUA_TARGET_CREATE,
                              &t);
  if (e) return oclua_output_fail(L, &t, strerror(e));
  int rc = oc_image_write_at(img, t.dir, t.name, bits, &err);
  oclua_target_close(L, &t);
  if (rc != OC_OK) {
    /* A file that cannot be written is an expected failure, as io.open. */
    if (err.code == OC_EIO)
      return oclua_output_fail(L, &t,
                               err.msg[0] ? err.msg : "cannot write the image");
    oclua_liberror(L, fname, &err);
  }
  lua_pushboolean(L, 1);
  return 1;
}

static int image_size(lua_State *L) {
  oc_image *img = oclua_checkimage(L, 1, "image:size", 0);
  lua_pushinteger(L, oc_image_width(img));
  lua_pushinteger(L, oc_image_height(img));
  return 2;
}

static int image_channels(lua_State *L) {
  lua_pushinteger(
      L, oc_image_channels(oclua_checkimage(L, 1, "image:channels", 0)));
  return 1;
}

/* get(i, j): column i from the left, row j from the top, both 1-based. */
static int image_get(lua_State *L) {
  const char *fname = "image:get";
  const oc_image *img = oclua_checkimage(L, 1, fname, 0);
  int w = oc_image_width(img), h = oc_image_height(img);
  int nc = oc_image_channels(img);
  lua_Integer ij[2];
  oclua_checkargs(L, 3, fname, "(i, j)");
  for (int k = 0; k < 2; k++) {
    int isint;
    lua_Integer lim = k == 0 ? w : h;
    ij[k] = lua_tointegerx(L, 2 + k, &isint);
    if (lua_type(L, 2 + k) != LUA_TNUMBER || !isint || ij[k] < 1 || ij[k] > lim)
      oclua_error(L, fname, "%s must be an integer in 1..%I (got %s)",
                  k == 0 ? "the column i" : "the row j", (LUAI_UACINT)lim,
                  oclua_got(L, 2 + k));
  }
  const float *px =
      oc_image_cdata(img) +
      ((size_t)(ij[1] - 1) * (size_t)w + (size_t)(ij[0] - 1)) * (size_t)nc;
  luaL_checkstack(L, nc, "too many channels");
  for (int c = 0; c < nc; c++)
    lua_pushnumber(L, px[c]);
  return nc;
}

static int image_gc(lua_State *L) {
  oclua_handle_close(luaL_checkudata(L, 1, OCLUA_IMAGE));
  return 0;
}

static int image_tostring(lua_State *L) {
  oclua_image *u = luaL_checkudata(L, 1, OCLUA_IMAGE);
  if (u->img == NULL || u->h.closed)
    lua_pushliteral(L, OCLUA_IMAGE ": (closed)");
  else
    lua_pushfstring(L, OCLUA_IMAGE ": %dx%d, %d channels",
                    oc_image_width(u->img), oc_image_height(u->img),
                    oc_image_channels(u->img));
  return 1;
}

/* ---- outcrop.slice --------------------------------------------------- */

int oclua_slice(lua_State *L, const char *fname, const double *stops,
                int nstops) {
  static const char *const known[] = {"plane", "at",      "box",
                                      "size",  "palette", NULL};
  static const char *const planes[] = {"xy", "xz", "yz", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_slice_params sp;
  double box[4], size[2] = {DEFAULT_SLICE_SIZE, DEFAULT_SLICE_SIZE};
  oclua_checkargs(L, 2, fname,
                  "(node, {plane =, at =, box =, size =, palette =})");
  oclua_checknode(L, 1, fname, "argument #1");
  if (lua_isnoneornil(L, 2)) { /* no options: an empty table at index 2 */
    lua_settop(L, 1);
    lua_newtable(L);
  }
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  int plane = oclua_field_optoption(&f, "plane", planes, 1);
  sp.plane = plane == 0 ? OC_PLANE_XY : plane == 1 ? OC_PLANE_XZ : OC_PLANE_YZ;
  sp.at = oclua_field_optnumber(&f, "at", OCLUA_FINITE, 0.0);
  oclua_field_numbers(&f, "size", 2, size, "must be {width, height}");
  for (int k = 0; k < 2; k++)
    if (size[k] != floor(size[k]) || size[k] < 1 || size[k] > MAX_SLICE_SIZE) {
      if (size[k] == floor(size[k]) && fabs(size[k]) < 1e18)
        lua_pushinteger(L, (lua_Integer)size[k]);
      else
        lua_pushnumber(L, size[k]);
      oclua_error(L, fname,
                  "'size' must be {width, height} with integers in "
                  "1..%d (got %s)",
                  MAX_SLICE_SIZE, oclua_got(L, -1));
    }
  sp.width = (int)size[0];
  sp.height = (int)size[1];
  int given =
      oclua_field_numbers(&f, "box", 4, box, "must be {u0, v0, u1, v1}");
  if (oclua_field_push(&f, "palette") != LUA_TNIL)
    stops = oclua_read_palette(L, -1, fname, "palette", &nstops);
  const oc_program *prog = oclua_program(L, 1, fname);
  if (!given) {
    if (oc_slice_default_window(prog, &sp, &err))
      oclua_liberror(L, fname, &err);
    box[0] = sp.u0, box[1] = sp.v0, box[2] = sp.u1, box[3] = sp.v1;
  }
  if (!(box[0] < box[2] && box[1] < box[3]))
    oclua_error(L, fname,
                "'box' = {u0, v0, u1, v1} needs u0 < u1 and v0 < v1 "
                "(got {%f, %f, %f, %f})%s",
                box[0], box[1], box[2], box[3],
                given ? "" : " (from the node's bounds)");
  sp.u0 = box[0], sp.v0 = box[1], sp.u1 = box[2], sp.v1 = box[3];
  oclua_image *u = oclua_newimage(L);
  u->img = oc_slice(prog, &sp, &err);
  if (u->img == NULL) oclua_liberror(L, fname, &err);
  /* the colours follow the palette; the "field" channel keeps the raw
  ** value */
  if (stops && oc_slice_apply_palette(u->img, stops, nstops, &err))
    oclua_liberror(L, fname, &err);
  return 1;
}

static int l_slice(lua_State *L) {
  return oclua_slice(L, "outcrop.slice", NULL, 0);
}

static const luaL_Reg image_methods[] = {{"write", image_write},
                                         {"size", image_size},
                                         {"get", image_get},
                                         {"channels", image_channels},
                                         {NULL, NULL}};

static const luaL_Reg image_meta[] = {
    {"__gc", image_gc},
    {"__close", image_gc}, /* `local img <close>` frees the pixels early */
    {"__tostring", image_tostring},
    {NULL, NULL}};

static const luaL_Reg image_funcs[] = {{"slice", l_slice}, {NULL, NULL}};

void oclua_open_image(lua_State *L) {
  oclua_newmeta(L, OCLUA_IMAGE, image_meta, image_methods);
  lua_pop(L, 1);
  luaL_setfuncs(L, image_funcs, 0);
}
