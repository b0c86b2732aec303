/*
** l_mesh.h — the mesh userdata made by outcrop.polygonize.
*/
#ifndef L_MESH_H
#define L_MESH_H

#include "l_util.h"

#define OCLUA_MESH "outcrop.mesh"

typedef struct oclua_mesh {
  oc_mesh *mesh; /* NULL while being made, or once closed */
} oclua_mesh;

/* Adds outcrop.polygonize to the module table at the stack top and sets
** up the mesh metatable. */
void oclua_open_mesh(lua_State *L);

#endif
