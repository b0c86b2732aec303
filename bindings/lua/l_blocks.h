/*
** l_blocks.h — outcrop.blocks: fracture tiles and their blocks
** (l_blocks.c).
*/
#ifndef L_BLOCKS_H
#define L_BLOCKS_H

#include "l_util.h"

/* Adds outcrop.blocks to the module table at the stack top. */
void oclua_open_blocks(lua_State *L);
/* A new, empty tile userdata pushed; set the returned slot to the tile
** (its __gc frees it). */
oc_btile **oclua_newtile(lua_State *L);
/* The tile at idx (an error naming `what` otherwise). */
oc_btile *oclua_checktile(lua_State *L, int idx, const char *fname,
                          const char *what);

/* Reads field `blocks` of a tile's options (authored blocks: box, points
** or planes each, l_blocks_shapes.c) into Lua-owned memory held by one
** value left on the stack (nil when absent); the count in *n. */
const oc_block_shape *oclua_read_block_shapes(const oclua_fields *f, size_t *n);

#endif
