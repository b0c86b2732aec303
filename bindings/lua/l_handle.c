/*
** l_handle.c — pins: the busy count of a userdata while a binding uses it,
** and the to-be-closed guard that gives the pin back however the binding
** ends. See l_handle.h.
*/
#include "l_handle.h"

#define GUARD "outcrop.pin"

typedef struct guard {
  oclua_handle *h; /* NULL until pinned, and once unpinned */
} guard;

void oclua_handle_init(oclua_handle *h, const char *what,
                       void (*release)(oclua_handle *)) {
  h->release = release;
  h->what = what;
  h->busy = 0;
  h->closed = 0;
}

void oclua_handle_close(oclua_handle *h) {
  int was = h->closed;
  h->closed = 1;
  if (!was && h->busy == 0 && h->release) h->release(h);
}

void oclua_handle_check(lua_State *L, const oclua_handle *h,
                        const char *fname) {
  if (h->closed) oclua_error(L, fname, "the %s was closed", h->what);
}

/* __close of the guard, and its __gc as a backstop: the object (kept alive
** by the guard's user value) is still in memory here even when both are
** being finalized, since the collector frees neither before both ran. */
static int guard_close(lua_State *L) {
  guard *g = luaL_checkudata(L, 1, GUARD);
  oclua_handle *h = g->h;
  g->h = NULL;
  if (h && --h->busy == 0 && h->closed && h->release) h->release(h);
  return 0;
}

void oclua_pin(lua_State *L, int idx, oclua_handle *h, const char *fname) {
  idx = lua_absindex(L, idx);
  oclua_handle_check(L, h, fname);
  /* Allocating the guard may run finalizers, which may close h: it is
  ** checked again once nothing else can run. */
  guard *g = lua_newuserdatauv(L, sizeof *g, 1);
  g->h = NULL;
  luaL_setmetatable(L, GUARD);
  lua_pushvalue(L, idx);
  lua_setiuservalue(L, -2, 1);
  lua_toclose(L, -1);
  oclua_handle_check(L, h, fname);
  h->busy++;
  g->h = h;
}

void oclua_newmeta(lua_State *L, const char *tname, const luaL_Reg *meta,
                   const luaL_Reg *methods) {
  luaL_newmetatable(L, tname);
  luaL_setfuncs(L, meta, 0);
  if (methods) {
    lua_newtable(L);
    luaL_setfuncs(L, methods, 0);
    lua_setfield(L, -2, "__index");
  }
  lua_pushliteral(L, "protected");
  lua_setfield(L, -2, "__metatable");
}

void oclua_open_handle(lua_State *L) {
  static const luaL_Reg guard_meta[] = {
      {"__close", guard_close}, {"__gc", guard_close}, {NULL, NULL}};
  oclua_newmeta(L, GUARD, guard_meta, NULL);
  lua_pop(L, 1);
}
