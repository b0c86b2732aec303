/*
** l_gen_hoodoos.c — hoodoos and goblins from a parameterized grammar: outcrop.generate.hoodoos.
*/
#include "l_gen.h"

const luaL_Reg oclua_gen_hoodoos[] = {{NULL, NULL}};
