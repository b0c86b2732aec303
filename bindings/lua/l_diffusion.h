/*
** l_diffusion.h — feature curves and diffusion (l_diffusion.c).
*/
#ifndef L_DIFFUSION_H
#define L_DIFFUSION_H

#include "l_util.h"

/* Adds outcrop.feature_curve and outcrop.diffusion to the module table at
** the stack top. */
void oclua_open_diffusion(lua_State *L);

#endif
