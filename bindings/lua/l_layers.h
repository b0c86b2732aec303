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

#endif
