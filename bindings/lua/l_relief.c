/*
** l_relief.c — outcrop.relief_warp (Paris et al. 2020, section 4.2): the
** gradient-based warp of any node by a relief.
**
** outcrop.relief_warp(node, {relief =, amplitude =, step =})
**   relief: "turbulence" (the default), or {kind = "turbulence",
**     wavelength = 1, octaves = 4, seed = scene seed}, or {kind = "image",
**     path =, wavelength = 1} (the image repeats every wavelength metres)
**   amplitude: the relief's largest displacement, metres (required)
**   step: the gradient's step (default 4 |amplitude|)
*/
#include <math.h>
#include <string.h>

#include "l_config.h"
#include "l_field.h"
#include "l_relief.h"

/* Reads `relief` into rp and pushes one value: the image's path (rp->path
** points into it, so it lives while it is on the stack) or nil. */
static void read_relief(const oclua_fields *f, oc_relief_params *rp) {
  static const char *const known[] = {"kind", "wavelength", "octaves",
                                      "seed", "path",       NULL};
  static const char *const kinds[] = {"turbulence", "image", NULL};
  lua_State *L = f->L;
  int t = oclua_field_push(f, "relief");
  if (t == LUA_TNIL || t == LUA_TSTRING) {
    if (t == LUA_TSTRING && strcmp(lua_tostring(L, -1), "turbulence") != 0)
      oclua_field_error(f, "relief", -1,
                        "must be \"turbulence\" or a table {kind =, ...}");
    lua_pop(L, 1);
    rp->seed = oclua_scene_seed(L);
    lua_pushnil(L);
    return;
  }
  if (t != LUA_TTABLE)
    oclua_field_error(f, "relief", -1,
                      "must be \"turbulence\" or a table {kind =, ...}");
  oclua_fields r;
  oclua_fields_open(&r, L, -1, f->fname, "relief.", known, 0);
  rp->kind = (oc_relief_kind)oclua_field_optoption(&r, "kind", kinds, 0);
  rp->wavelength =
      oclua_field_optnumber(&r, "wavelength", OCLUA_POSITIVE, rp->wavelength);
  if (rp->kind == OC_RELIEF_TURBULENCE) {
    rp->octaves = (int)oclua_field_optint(&r, "octaves", 1, 16, rp->octaves);
    rp->seed = oclua_field_seed(&r, "seed");
    if (oclua_field_push(&r, "path") != LUA_TNIL)
      oclua_field_error(&r, "path", -1, "is for kind = \"image\" only");
    lua_remove(L, -2); /* the relief table; nil stays */
  } else {
    if (oclua_field_push(&r, "octaves") != LUA_TNIL ||
        oclua_field_push(&r, "seed") != LUA_TNIL)
      oclua_error(L, f->fname,
                  "'relief.octaves' and 'relief.seed' are for kind = "
                  "\"turbulence\" only");
    lua_pop(L, 2);
    if (oclua_field_push(&r, "path") != LUA_TSTRING)
      oclua_field_error(&r, "path", -1, "must be the path of an image file");
    rp->path = lua_tostring(L, -1);
    lua_remove(L, -2); /* the relief table; the path stays */
  }
}

static int l_relief_warp(lua_State *L) {
  static const char *const known[] = {"relief", "amplitude", "step", NULL};
  const char *fname = "outcrop.relief_warp";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_relief_params rp;
  oclua_checkargs(L, 2, fname, "(node, {relief =, amplitude =, step =})");
  oclua_checknode(L, 1, fname, "argument #1");
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oc_relief_defaults(&rp);
  read_relief(&f, &rp);
  rp.amplitude = oclua_field_number(&f, "amplitude", OCLUA_FINITE);
  rp.step = oclua_field_optnumber(&f, "step", OCLUA_POSITIVE, 0);
  /* the node again: a metamethod of the options may have changed nothing
  ** at index 1, but its userdata is checked after any Lua code ran */
  oc_node *child = oclua_checknode(L, 1, fname, "argument #1");
  oclua_node *u = oclua_newnode(L);
  int n = oclua_setnode(L, u, oc_relief_warp(child, &rp, &err), &err, fname);
  if (rp.path) oclua_record_input(L, rp.path, fname);
  return n;
}

void oclua_open_relief(lua_State *L) {
  lua_pushcfunction(L, l_relief_warp);
  lua_setfield(L, -2, "relief_warp");
}
