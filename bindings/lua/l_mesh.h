/*
** l_mesh.h — the mesh userdata made by outcrop.polygonize.
*/
#ifndef L_MESH_H
#define L_MESH_H

#include "l_handle.h"

#define OCLUA_MESH "outcrop.mesh"

typedef struct oclua_mesh {
  oclua_handle h; /* first: pins and closing (l_handle.h) */
  oc_mesh *mesh;  /* NULL while being made, or once freed */
} oclua_mesh;

/* Pushes a new mesh userdata holding no mesh yet (set u->mesh at once:
** the userdata frees it). */
oclua_mesh *oclua_newmesh(lua_State *L);

/* Adds outcrop.polygonize to the module table at the stack top and sets
** up the mesh metatable. */
void oclua_open_mesh(lua_State *L);

#endif
