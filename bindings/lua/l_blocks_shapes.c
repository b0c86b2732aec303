/*
** l_blocks_shapes.c — the `blocks` field of outcrop.blocks.tile: authored
** blocks, each one of
**   {box = {x0, y0, z0, x1, y1, z1}}   an axis-aligned box (min, max);
**   {points = {{x, y, z}, ...}}        the convex hull of 4 or more points;
**   {planes = {{nx, ny, nz, d}, ...}}  the half-spaces n . p + d <= 0.
** Read into Lua-owned memory (one userdata per shape, all kept in one
** table left on the stack).
*/
#include <math.h>

#include "l_blocks.h"

#define MAX_SHAPES 1000
#define MAX_ITEMS 100000

/* Reads the array at the stack top as n rows of `width` numbers (points
** as vectors) into a new userdata left in anchor[slot]. */
static double *rows(lua_State *L, int anchor, int slot, const char *fname,
                    const char *label, int width, size_t *n) {
  lua_Integer m = lua_istable(L, -1) ? (lua_Integer)lua_rawlen(L, -1) : 0;
  if (m < 1 || m > MAX_ITEMS)
    oclua_error(L, fname, "'%s' must be an array of 1 .. %d %s (got %s)", label,
                MAX_ITEMS, width == 3 ? "points" : "{nx, ny, nz, d}",
                oclua_got(L, -1));
  double *x = lua_newuserdatauv(L, (size_t)m * (size_t)width * sizeof *x, 0);
  lua_rawseti(L, anchor, slot);
  for (lua_Integer i = 1; i <= m; i++) {
    lua_geti(L, -1, i);
    if (width == 3) {
      oc_vec3 v = oclua_tovec(L, -1, fname, label, i);
      x[3 * (i - 1)] = v.x, x[3 * (i - 1) + 1] = v.y, x[3 * (i - 1) + 2] = v.z;
    } else {
      if (!lua_istable(L, -1) || lua_rawlen(L, -1) != 4)
        oclua_error(L, fname, "'%s[%d]' must be {nx, ny, nz, d} (got %s)",
                    label, (int)i, oclua_got(L, -1));
      for (int k = 0; k < 4; k++) {
        if (lua_geti(L, -1, k + 1) != LUA_TNUMBER ||
            !isfinite(lua_tonumber(L, -1)))
          oclua_error(L, fname, "'%s[%d]' must be 4 finite numbers", label,
                      (int)i);
        x[4 * (i - 1) + k] = lua_tonumber(L, -1);
        lua_pop(L, 1);
      }
    }
    lua_pop(L, 1);
  }
  *n = (size_t)m;
  return x;
}

const oc_block_shape *oclua_read_block_shapes(const oclua_fields *f,
                                              size_t *n) {
  static const char *const none[] = {NULL};
  static const char *const known[] = {"box", "points", "planes", NULL};
  lua_State *L = f->L;
  *n = 0;
  if (oclua_field_push(f, "blocks") == LUA_TNIL) {
    lua_pop(L, 1);
    lua_pushnil(L); /* keeps the stack shape */
    return NULL;
  }
  oclua_fields a;
  oclua_fields_open(&a, L, -1, f->fname, "blocks.", none, 1);
  if (a.narray < 1 || a.narray > MAX_SHAPES)
    oclua_error(L, f->fname, "'blocks' must hold 1 .. %d blocks (got %d)",
                MAX_SHAPES, (int)a.narray);
  lua_createtable(L, (int)a.narray + 1, 0);
  int anchor = lua_gettop(L);
  oc_block_shape *sh = lua_newuserdatauv(L, (size_t)a.narray * sizeof *sh, 0);
  lua_rawseti(L, anchor, (lua_Integer)a.narray + 1);
  for (lua_Integer i = 1; i <= a.narray; i++) {
    oclua_fields e;
    oc_block_shape *s = &sh[i - 1];
    *s = (oc_block_shape){NULL, 0, NULL, 0};
    lua_geti(L, a.t, i);
    const char *pre = lua_pushfstring(L, "blocks[%d].", (int)i);
    oclua_fields_open(&e, L, -2, f->fname, pre, known, 0);
    int has[3], count = 0;
    for (int k = 0; k < 3; k++) {
      has[k] = oclua_field_push(&e, known[k]) != LUA_TNIL;
      lua_pop(L, 1);
      count += has[k];
    }
    if (count != 1)
      oclua_error(L, f->fname,
                  "'blocks[%d]' needs one of 'box', 'points', 'planes' (got "
                  "%d)",
                  (int)i, count);
    const char *label = lua_pushfstring(L, "blocks[%d].%s", (int)i,
                                        known[has[0]   ? 0
                                              : has[1] ? 1
                                                       : 2]);
    if (has[0]) {
      double b[6];
      oclua_field_numbers(&e, "box", 6, b, "must be {x0, y0, z0, x1, y1, z1}");
      if (!(b[0] < b[3] && b[1] < b[4] && b[2] < b[5]))
        oclua_error(L, f->fname, "'%s' must have min < max on each axis",
                    label);
      double *x = lua_newuserdatauv(L, 24 * sizeof *x, 0);
      lua_rawseti(L, anchor, i);
      for (int c = 0; c < 8; c++)
        for (int k = 0; k < 3; k++)
          x[3 * c + k] = (c >> k) & 1 ? b[3 + k] : b[k];
      s->points = x;
      s->npoints = 8;
    } else {
      oclua_field_push(&e, has[1] ? "points" : "planes");
      if (has[1])
        s->points = rows(L, anchor, (int)i, f->fname, label, 3, &s->npoints);
      else
        s->planes = rows(L, anchor, (int)i, f->fname, label, 4, &s->nplanes);
      lua_pop(L, 1);
    }
    lua_pop(L, 3); /* label, prefix, entry */
  }
  lua_remove(L, -2); /* the blocks table stays reachable from the options */
  *n = (size_t)a.narray;
  return sh;
}
