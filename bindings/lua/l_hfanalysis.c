/*
** l_hfanalysis.c — heightfield analysis methods: slope, filling, drainage,
** stream power, sinks, accessibility, distance to a level.
*/
#include "l_heightfield.h"

const luaL_Reg oclua_heightfield_analysis[] = {{NULL, NULL}};
