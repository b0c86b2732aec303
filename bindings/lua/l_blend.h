/*
** l_blend.h — colours blended by weight nodes (texturing by material,
** Peytavie et al. 2009 section 6), as render's `color = {blend = ...}`
** and a mesh's `colors = {blend = ...}` take them:
**   {{node, {r, g, b}}, ...}  (1 .. 16 pairs, components in [0, 1])
** stacks:colors{} makes one for material stacks.
*/
#ifndef L_BLEND_H
#define L_BLEND_H

#include "l_util.h"

#define OCLUA_MAX_BLEND 16

/* Checks the blend table at idx (`label` names it in messages) and pushes
** its colours (3 doubles a pair) in a userdata; returns the pair count. */
int oclua_read_blend(lua_State *L, int idx, const char *fname,
                     const char *label, const double **colors);
/* The blend table's nodes at idx compiled at threshold t, pushed in a
** userdata of n program pointers (and each program's box above it, which
** keep them alive while on the stack). */
const oc_program *const *oclua_blend_programs(lua_State *L, int idx, int n,
                                              const char *fname, double t);

#endif
