/*
** l_relief.h — outcrop.relief_warp, the gradient-based warp (l_relief.c).
*/
#ifndef L_RELIEF_H
#define L_RELIEF_H

#include "l_util.h"

/* Adds outcrop.relief_warp to the module table at the stack top. */
void oclua_open_relief(lua_State *L);

#endif
