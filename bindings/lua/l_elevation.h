/*
** l_elevation.h — the elevation-tree userdata (l_elevation.c), for the
** binding files that take elevation trees (terrain, heightfield sampling,
** rendering).
*/
#ifndef L_ELEVATION_H
#define L_ELEVATION_H

#include "l_util.h"

#define OCLUA_ELEVATION "outcrop.elevation"

/* The tree at idx, or NULL when idx is not an elevation node. */
oc_enode *oclua_testenode(lua_State *L, int idx);
/* Raises "<fname>: <what> must be an elevation node (got ...)". */
oc_enode *oclua_checkenode(lua_State *L, int idx, const char *fname,
                           const char *what);
/* The elevation source of the tree at idx over domain (NULL: the box of
** its support); OC_OK, or an error code with err. The source holds its
** own reference to the tree (release it with src->release(src->ud)). */
int oclua_toelevation(lua_State *L, int idx, const double *domain,
                      oc_elevation *src, oc_error *err);

/* Adds outcrop.elevation to the module table at the stack top. */
void oclua_open_elevation(lua_State *L);

#endif
