/*
** l_heightfield.h — the heightfield userdata, shared by the binding files
** that make grids (l_heightfield.c: load, fbm, from, resample, crop),
** analyse them (l_hfanalysis.c) or consume them (terrain, sampling).
*/
#ifndef L_HEIGHTFIELD_H
#define L_HEIGHTFIELD_H

#include "l_handle.h"

#define OCLUA_HEIGHTFIELD "outcrop.heightfield"

typedef struct oclua_heightfield {
  oclua_handle h;     /* first: pins and closing (l_handle.h) */
  oc_heightfield *hf; /* one reference, or NULL while being made */
} oclua_heightfield;

/* Pushes a heightfield userdata holding nothing yet: create it BEFORE
** making the grid, then store the grid in it, so an error cannot leak. */
oclua_heightfield *oclua_newheightfield(lua_State *L);
/* Raises unless idx is an open heightfield (names fname in the message);
** for getters that run no Lua code while they use the grid. */
oc_heightfield *oclua_checkheightfield(lua_State *L, int idx,
                                       const char *fname);
/* The same, and pins the grid for the rest of the call (oclua_pin: pushes
** a guard slot the caller must not pop). */
oc_heightfield *oclua_pinheightfield(lua_State *L, int idx, const char *fname);
/* Stores hf, just made, in u (the userdata made before the work, so an
** error cannot leak) and returns 1; raises when hf is NULL ("interrupted"
** on cancel, else fname and err's message). */
int oclua_sethf(lua_State *L, oclua_heightfield *u, oc_heightfield *hf,
                const oc_error *err, const char *fname);
/* The grid to be made from the fields size = {nx, ny} (required), cell
** (> 0, default 1) and origin = {x0, y0} (default {0, 0}). */
oc_heightfield_grid oclua_field_grid(const oclua_fields *f);

/* Whether idx is a heightfield userdata, open or closed. */
int oclua_isheightfield(lua_State *L, int idx);

/* Sets up the metatable (methods of l_heightfield.c plus
** oclua_heightfield_analysis) and adds outcrop.heightfield to the module
** table at the stack top. */
void oclua_open_heightfield(lua_State *L);

/* Analysis methods (slope, filled, drainage, ...), from l_hfanalysis.c;
** NULL-terminated. */
extern const luaL_Reg oclua_heightfield_analysis[];

#endif
