/*
** l_handle.h — lifetimes of the module's userdata while bindings use them.
**
** Lua code can run in the middle of a binding: metamethods of option
** tables, callbacks, and finalizers of script objects, which run at any
** allocation. Such code may close an object (`local x <close>`) or drop
** the last reference to it. So every userdata that owns a C object starts
** with an oclua_handle, and a call that keeps the C pointer across Lua
** code (or across an allocation) pins the object first: while pinned,
** closing it only marks it closed, and the C object is freed when the last
** pin goes. A pin is a to-be-closed guard slot on the caller's stack: it
** goes when the binding returns or raises, or, for a coroutine abandoned
** in an error, when the collector finalizes the guard.
**
** A call that reads a pointer and uses it with no Lua code and no
** allocation in between (a getter) needs no pin: only a check.
*/
#ifndef L_HANDLE_H
#define L_HANDLE_H

#include "l_util.h"

typedef struct oclua_handle oclua_handle;

struct oclua_handle {
  /* frees the C object (and clears the pointer to it); called once */
  void (*release)(oclua_handle *h);
  const char *what; /* "heightfield": names the kind in messages */
  unsigned busy;    /* pins held by calls running now */
  int closed;       /* closed or collected: unusable by new calls */
};

/* Call right after creating the userdata, before anything can raise. */
void oclua_handle_init(oclua_handle *h, const char *what,
                       void (*release)(oclua_handle *));
/* For __gc and __close: frees now, or when the last pin goes. Safe when
** run twice and on a resurrected object. */
void oclua_handle_close(oclua_handle *h);
/* Raises "fname: the <what> was closed" when h is closed. */
void oclua_handle_check(lua_State *L, const oclua_handle *h, const char *fname);
/* Pins the object at idx (a userdata starting with h) for the rest of the
** running binding: pushes a to-be-closed guard slot, so the caller must
** never pop below it (return or raise instead). Raises, as above, when
** the object is or gets closed before it is pinned. */
void oclua_pin(lua_State *L, int idx, oclua_handle *h, const char *fname);

/* Makes the metatable named tname with the functions of meta, a method
** table (methods, may be NULL) as __index, and __metatable set so that
** scripts can neither read it nor call or remove __gc/__close. Leaves the
** metatable on the stack. */
void oclua_newmeta(lua_State *L, const char *tname, const luaL_Reg *meta,
                   const luaL_Reg *methods);

/* Sets up the guard's metatable; called once when the module opens. */
void oclua_open_handle(lua_State *L);

#endif
