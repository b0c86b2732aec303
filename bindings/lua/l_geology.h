/*
** l_geology.h — outcrop.geology (resistance trees) and outcrop.erosion
** (l_geology.c).
*/
#ifndef L_GEOLOGY_H
#define L_GEOLOGY_H

#include "l_util.h"

/* Adds outcrop.geology and outcrop.erosion to the module table at the
** stack top. */
void oclua_open_geology(lua_State *L);

#endif
