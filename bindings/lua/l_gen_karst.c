/*
** l_gen_karst.c — karst networks by invasion percolation: outcrop.generate.karst.
*/
#include "l_gen.h"

const luaL_Reg oclua_gen_karst[] = {{NULL, NULL}};
