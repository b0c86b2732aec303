/*
** l_render.h — outcrop.render: sphere-traced images of a node.
*/
#ifndef L_RENDER_H
#define L_RENDER_H

#include "l_util.h"

/* Adds outcrop.render to the module table at the stack top. */
void oclua_open_render(lua_State *L);

#endif
