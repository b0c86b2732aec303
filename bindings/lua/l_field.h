/*
** l_field.h — the node userdata, shared by every binding file that takes
** or returns field nodes.
**
** A node userdata owns one reference to an immutable oc_node; the C node
** retains its children, so the order in which Lua collects userdata never
** frees a node still in a tree. Queries compile the node lazily with the
** current outcrop.threshold and keep the program until the threshold
** changes or the userdata is collected.
**
** A node cannot be closed, only collected: a call keeps the nodes it uses
** reachable from its stack (the argument, or a field value it leaves
** pushed) until the library has retained them. A program lives in its own
** userdata (a "program box", the node's user value while it is the
** cache), which every caller of oclua_program_at keeps on its stack: a
** callback or a finalizer that changes outcrop.threshold and recompiles
** the node only replaces the cache, and the program in use is freed by
** the collector once the call is over.
*/
#ifndef L_FIELD_H
#define L_FIELD_H

#include "l_util.h"

#define OCLUA_NODE "outcrop.node"

typedef struct oclua_node {
  oc_node *node;    /* NULL while a constructor runs, and once collected */
  oc_program *prog; /* the cached program (owned by its box), or NULL */
  double threshold; /* T that prog was compiled with */
} oclua_node;

/* Pushes a node userdata that owns nothing yet. Create it BEFORE calling
** the lib constructor, so that a raised error cannot leak the node. */
oclua_node *oclua_newnode(lua_State *L);
/* Stores the constructor's result in u, or raises with err's message
** when it is NULL. Returns 1 (the userdata on the stack top). */
int oclua_setnode(lua_State *L, oclua_node *u, oc_node *node,
                  const oc_error *err, const char *fname);

oclua_node *oclua_testnode(lua_State *L, int idx);
/* Raises "<fname>: <what> must be an outcrop node (got ...)". */
oc_node *oclua_checknode(lua_State *L, int idx, const char *fname,
                         const char *what);

/* The current outcrop.threshold, checked to be a positive number. */
double oclua_threshold(lua_State *L, const char *fname);
/* The node at idx compiled with the current threshold (cached). Pushes
** the program's box, which keeps the program alive while it is on the
** stack. */
const oc_program *oclua_program(lua_State *L, int idx, const char *fname);
/* The same with threshold t (t > 0); the cache then holds that program
** until a query with another threshold replaces it. */
const oc_program *oclua_program_at(lua_State *L, int idx, const char *fname,
                                   double t);

/* Each adds its functions to the module table at the stack top. */
void oclua_open_field(lua_State *L);
void oclua_open_prim(lua_State *L);

/* The curve of the table f (points, radius, bezier) with its energy read
** from field `energy` (default 1 when optional), pushed as a new node
** userdata; returns 1. Shared by outcrop.curve and outcrop.geology.curve. */
int oclua_make_curve(oclua_fields *f, const char *energy, int optional);
void oclua_open_ops(lua_State *L);
/* Operator metamethods (__add, __sub, __unm, __bor, __band). */
extern const luaL_Reg oclua_node_operators[];

#endif
