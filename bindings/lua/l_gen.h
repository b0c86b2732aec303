/*
** l_gen.h — outcrop.poisson2d, outcrop.poisson3d and the point-set
** userdata they return with flat = true.
*/
#ifndef L_GEN_H
#define L_GEN_H

#include "l_util.h"

#define OCLUA_POINTS "outcrop.points"

/* Adds outcrop.poisson2d and outcrop.poisson3d to the module table at the
** stack top and sets up the point-set metatable. */
void oclua_open_gen(lua_State *L);

#endif
