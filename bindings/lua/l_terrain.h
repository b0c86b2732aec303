/*
** l_terrain.h — outcrop.terrain: a heightfield implicitized into a 3D
** field node (l_terrain.c).
*/
#ifndef L_TERRAIN_H
#define L_TERRAIN_H

#include "l_util.h"

/* Adds outcrop.terrain to the module table at the stack top. */
void oclua_open_terrain(lua_State *L);

#endif
