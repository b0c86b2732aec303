/*
** l_gen_sea.c — sea and river erosion: outcrop.generate.sea, outcrop.generate.river.
*/
#include "l_gen.h"

const luaL_Reg oclua_gen_sea[] = {{NULL, NULL}};
