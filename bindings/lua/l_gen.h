/*
** l_gen.h — outcrop.poisson2d, outcrop.poisson3d and the point-set
** userdata they return with flat = true.
*/
#ifndef L_GEN_H
#define L_GEN_H

#include "l_util.h"

#define OCLUA_POINTS "outcrop.points"

/* Adds outcrop.poisson2d, outcrop.poisson3d and the outcrop.generate
** table to the module table at the stack top and sets up the point-set
** metatable. */
void oclua_open_gen(lua_State *L);

/* The landform generators (Paris et al. 2019, section 6), each from its own
** file,
** NULL-terminated: outcrop.generate.sea and .river (l_gen_sea.c),
** .karst (l_gen_karst.c), .hoodoos (l_gen_hoodoos.c). */
extern const luaL_Reg oclua_gen_sea[];
extern const luaL_Reg oclua_gen_karst[];
extern const luaL_Reg oclua_gen_hoodoos[];

#endif
