/*
** l_blocks.h — outcrop.blocks: fracture tiles and their blocks
** (l_blocks.c).
*/
#ifndef L_BLOCKS_H
#define L_BLOCKS_H

#include "l_util.h"

/* Adds outcrop.blocks to the module table at the stack top. */
void oclua_open_blocks(lua_State *L);

#endif
