/*
** l_terrain.c — outcrop.terrain(hf or e, {falloff=, transition=, mask=,
** invert=, ...}): a heightfield or an elevation tree implicitized into a
*terrain node (Paris et al. 2019
** section 5.1; docs/fields.md has the field).
**
**   field      | default
**   -----------+-----------------------------------------------------------
**   falloff    | 4 cells of the heightfield: the prism's falloff R
**   transition | 1 (metre): the half-width W of sigma
**   mask       | none: a heightfield (Omega where it is >= 0.5), or the
**              | path of a grey image stretched over the heightfield's
**              | width (Omega where it is >= half its brightest pixel)
**   thickness  | 0: how much farther than the elevations the prism reaches
**              | on the solid side (below; above when inverted)
**   invert     | false: solid above the surface instead of below
**   edges      | "open" (no mask): the solid is cut at the grid's vertical
**              | sides, the surface the grid's up to its border samples;
**              | "slab": the paper's prism, falling off over 'falloff'
**              | inside the grid's sides (a mask always gives a slab)
**
** The table is optional. Everything is checked before anything is made;
** the node keeps the grid alive.
**
** outcrop.terrain(e, {...}) with an elevation tree e (Génevaux et al. 2015)
** takes the same fields but a path 'mask', and `domain` = {x0, y0, x1, y1}
** (default: the box of its terrain, oc_enode_terrain_box); falloff
** defaults to 1/100 of the domain's longer side. The solid is below f
** where alpha >= 1/2 and nothing where alpha < 1/2 (lib/terrain/terrain.c).
*/
#include <string.h>

#include "l_elevation.h"
#include "l_field.h"
#include "l_heightfield.h"
#include "l_terrain.h"

/* outcrop.terrain(e [, {...}]) for an elevation tree e at 1. */
static int tree_terrain(lua_State *L, oc_enode *e, const char *fname) {
  static const char *const known[] = {"falloff", "transition", "thickness",
                                      "mask",    "invert",     "edges",
                                      "domain",  NULL};
  static const char *const edges[] = {"open", "slab", NULL};
  oc_terrain_params tp;
  oc_terrain_defaults_source(NULL, &tp);
  double dom[4], falloff = 0;
  int hasdom = 0;
  oc_heightfield *mask = NULL;
  if (!lua_isnoneornil(L, 2)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    falloff = oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, 0);
    tp.transition =
        oclua_field_optnumber(&f, "transition", OCLUA_POSITIVE, tp.transition);
    tp.thickness = oclua_field_optnumber(&f, "thickness", OCLUA_FINITE, 0);
    if (tp.thickness < 0)
      oclua_error(L, fname, "'thickness' must be >= 0 (got %f)", tp.thickness);
    tp.invert = oclua_field_optbool(&f, "invert", 0);
    int given = oclua_field_push(&f, "edges") != LUA_TNIL;
    lua_pop(L, 1);
    int ed = oclua_field_optoption(&f, "edges", edges, 0);
    if (given) tp.edges = ed == 0 ? OC_TERRAIN_OPEN : OC_TERRAIN_SLAB;
    hasdom = oclua_field_numbers(&f, "domain", 4, dom,
                                 "must be {x0, y0, x1, y1} with finite "
                                 "numbers");
    if (hasdom && !(dom[0] < dom[2] && dom[1] < dom[3]))
      oclua_error(L, fname,
                  "'domain' = {x0, y0, x1, y1} needs x0 < x1 and y0 < y1 "
                  "(got {%f, %f, %f, %f})",
                  (LUAI_UACNUMBER)dom[0], (LUAI_UACNUMBER)dom[1],
                  (LUAI_UACNUMBER)dom[2], (LUAI_UACNUMBER)dom[3]);
    /* a grid stays on the stack, pinned until the node has its distance
    ** grid (the node keeps no reference to it) */
    int t = oclua_field_push(&f, "mask");
    if (t != LUA_TNIL && !oclua_isheightfield(L, -1))
      oclua_field_error(&f, "mask", -1,
                        "must be a heightfield for an elevation tree");
    else if (t != LUA_TNIL)
      mask = oclua_pinheightfield(L, -1, fname);
  }
  tp.mask = mask;
  oclua_node *u = oclua_newnode(L);
  oc_error err = {OC_OK, ""};
  oc_elevation src;
  if (oc_enode_elevation(e, hasdom ? dom : NULL, &src, &err) != OC_OK)
    return oclua_liberror(L, fname, &err);
  if (falloff == 0) {
    oc_terrain_params d;
    oc_terrain_defaults_source(&src, &d);
    falloff = d.falloff;
  }
  tp.falloff = falloff;
  oc_node *n = oc_terrain(&src, &tp, &err);
  src.release(src.ud); /* the node holds its own reference */
  return oclua_setnode(L, u, n, &err, fname);
}

static int l_terrain(lua_State *L) {
  static const char *const known[] = {
      "falloff", "transition", "thickness", "mask", "invert", "edges", NULL};
  static const char *const edges[] = {"open", "slab", NULL};
  const char *fname = "outcrop.terrain";
  oclua_checkargs(L, 2, fname,
                  "(heightfield or elevation tree [, {falloff=, "
                  "transition=, thickness=, mask=, invert=, edges=, "
                  "domain=}])");
  lua_settop(L, 2);
  oc_enode *tree = oclua_testenode(L, 1);
  if (tree) return tree_terrain(L, tree, fname); /* immutable: on the stack */
  if (!oclua_isheightfield(L, 1))
    oclua_error(L, fname,
                "expected a heightfield or an elevation tree (got %s)",
                oclua_got(L, 1));
  oclua_checkheightfield(L, 1, fname);
  /* pinned: the options' metamethods and finalizers may close it */
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  oc_terrain_params tp;
  oc_terrain_defaults(hf, &tp); /* the lib's: falloff 4 cells, W 1 */
  const char *mask_path = NULL;
  oc_heightfield *mask = NULL;
  if (!lua_isnoneornil(L, 2)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    tp.falloff =
        oclua_field_optnumber(&f, "falloff", OCLUA_POSITIVE, tp.falloff);
    tp.transition =
        oclua_field_optnumber(&f, "transition", OCLUA_POSITIVE, tp.transition);
    tp.thickness = oclua_field_optnumber(&f, "thickness", OCLUA_FINITE, 0);
    if (tp.thickness < 0)
      oclua_error(L, fname, "'thickness' must be >= 0 (got %f)", tp.thickness);
    tp.invert = oclua_field_optbool(&f, "invert", 0);
    int given = oclua_field_push(&f, "edges") != LUA_TNIL;
    lua_pop(L, 1);
    int e = oclua_field_optoption(&f, "edges", edges, 0);
    if (given) tp.edges = e == 0 ? OC_TERRAIN_OPEN : OC_TERRAIN_SLAB;
    /* The value stays on the stack (an __index may have made it) and a
    ** grid is pinned until the node has retained it. */
    int t = oclua_field_push(&f, "mask");
    if (t == LUA_TSTRING)
      mask_path = lua_tostring(L, -1);
    else if (t != LUA_TNIL && !oclua_isheightfield(L, -1))
      oclua_field_error(&f, "mask", -1, "must be a heightfield or a path");
    else if (t != LUA_TNIL)
      mask = oclua_pinheightfield(L, -1, fname);
  }
  oclua_node *u = oclua_newnode(L);
  oc_error err = {OC_OK, ""};
  oc_heightfield *own = NULL;
  if (mask_path) {
    /* the image stretched over hf and normalised (the lib's), raising
    ** with nothing to release */
    own = oc_heightfield_load_mask(mask_path, hf, &err);
    if (!own) oclua_liberror(L, fname, &err);
  }
  tp.mask = own ? own : mask;
  oc_node *n = oc_heightfield_terrain(hf, &tp, &err);
  oc_heightfield_release(own);
  return oclua_setnode(L, u, n, &err, fname);
}

void oclua_open_terrain(lua_State *L) {
  lua_pushcfunction(L, l_terrain);
  lua_setfield(L, -2, "terrain");
}
