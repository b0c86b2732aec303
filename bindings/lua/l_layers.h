/*
** l_layers.h — the material-stack userdata (l_layers.c).
*/
#ifndef L_LAYERS_H
#define L_LAYERS_H

#include "l_util.h"

#define OCLUA_LAYERS "outcrop.layers"

/* Sets up the metatable and adds outcrop.layers to the module table at
** the stack top. */
void oclua_open_layers(lua_State *L);
/* The stacks at idx, pinned for the rest of the call. */
oc_stacks *oclua_pinlayers(lua_State *L, int idx, const char *fname);
/* Adds rocks to the layers table at the stack top and s:rocks to the
** stacks' methods (l_rocks.c). */
void oclua_open_rocks(lua_State *L);

#endif
