/*
** l_blend.c — the blend tables of l_blend.h.
*/
#include "l_blend.h"

#include "l_field.h"

int oclua_read_blend(lua_State *L, int idx, const char *fname,
                     const char *label, const double **colors) {
  idx = lua_absindex(L, idx);
  if (!lua_istable(L, idx))
    oclua_error(L, fname, "'%s' must be an array of {node, {r, g, b}} (got %s)",
                label, oclua_got(L, idx));
  lua_Integer n = (lua_Integer)lua_rawlen(L, idx);
  if (n < 1 || n > OCLUA_MAX_BLEND)
    oclua_error(L, fname,
                "'%s' must hold 1 to %d pairs {node, {r, g, b}} "
                "(got %I)",
                label, OCLUA_MAX_BLEND, n);
  double *c = lua_newuserdatauv(L, 3 * (size_t)n * sizeof *c, 0);
  for (lua_Integer i = 1; i <= n; i++) {
    lua_rawgeti(L, idx, i);
    int ok = lua_istable(L, -1) && lua_rawlen(L, -1) == 2;
    if (ok) {
      lua_rawgeti(L, -1, 1);
      ok = oclua_testnode(L, -1) != NULL;
      lua_pop(L, 1);
    }
    if (ok) {
      lua_rawgeti(L, -1, 2);
      ok = lua_istable(L, -1) && lua_rawlen(L, -1) == 3;
      for (int k = 0; ok && k < 3; k++) {
        lua_rawgeti(L, -1, k + 1);
        double v = lua_tonumber(L, -1);
        ok = lua_type(L, -1) == LUA_TNUMBER && v >= 0 && v <= 1;
        c[3 * (i - 1) + k] = v;
        lua_pop(L, 1);
      }
      lua_pop(L, 1);
    }
    if (!ok)
      oclua_error(L, fname,
                  "'%s[%I]' must be {node, {r, g, b}} with r, g, b in [0, 1]",
                  label, i);
    lua_pop(L, 1);
  }
  *colors = c;
  return (int)n;
}

const oc_program *const *oclua_blend_programs(lua_State *L, int idx, int n,
                                              const char *fname, double t) {
  idx = lua_absindex(L, idx);
  const oc_program **p = lua_newuserdatauv(L, (size_t)n * sizeof *p, 0);
  luaL_checkstack(L, 2 * n + 4, NULL);
  for (int i = 0; i < n; i++) {
    lua_rawgeti(L, idx, i + 1);
    lua_rawgeti(L, -1, 1);
    p[i] = oclua_program_at(L, lua_gettop(L), fname, t);
    /* keep the box (pushed by oclua_program_at); drop the pair and node */
    lua_remove(L, -2);
    lua_remove(L, -2);
  }
  return p;
}
