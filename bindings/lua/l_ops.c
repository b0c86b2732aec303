/*
** l_ops.c — operators: outcrop.blend, union, intersection, difference,
** smooth_union, smooth_intersection, warp, transform, perturb, and the
** node metamethods a + b (blend), a | b (union), a & b (intersection),
** a - b (difference), -a (energy times -1).
**
** Defaults: octaves = 3 for warp and perturb; seed = the scene seed;
** control = none (warp everywhere). transform fields are all optional
** (identity); rotate is {axis = {x, y, z}, angle = degrees} or Euler
** angles {rx, ry, rz} in degrees, applied about X, then Y, then Z.
*/
#include <math.h>
#include <string.h>

#include "l_field.h"

/* ---- n-ary operators ------------------------------------------------- */

typedef oc_node *(*nary_fn)(oc_node *const *, size_t, oc_error *);

/* Reads the children of {a, b, ...} into a Lua-owned scratch array,
** pushed with a table of their userdata: the table may lose them (a
** finalizer of the script's may run at the next allocation), the copy
** keeps them alive until the operator has retained them. */
static oc_node **children(lua_State *L, const oclua_fields *f, size_t *n) {
  oc_node **kids;
  *n = (size_t)f->narray;
  kids = lua_newuserdatauv(L, (*n ? *n : 1) * sizeof *kids, 0);
  lua_createtable(L, (int)(*n < 65536 ? *n : 65536), 0);
  for (lua_Integer i = 1; i <= f->narray; i++) {
    oclua_node *u;
    /* raw: no metamethod may run while kids is filled */
    lua_rawgeti(L, f->t, i);
    u = oclua_testnode(L, -1);
    if (u == NULL)
      oclua_error(L, f->fname, "child #%I must be an outcrop node (got %s)",
                  (LUAI_UACINT)i, oclua_got(L, -1));
    kids[i - 1] = u->node;
    lua_rawseti(L, -2, i);
  }
  return kids;
}

static int nary(lua_State *L, const char *fname, nary_fn fn) {
  static const char *const known[] = {NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  size_t n;
  oclua_checkargs(L, 1, fname, "a table {a, b, ...} of nodes");
  if (oclua_testnode(L, 1))
    oclua_error(L, fname,
                "expected a table {a, b, ...} of nodes (got a node; "
                "write %s{a, b})",
                fname);
  oclua_fields_open(&f, L, 1, fname, NULL, known, 1);
  if (f.narray < 1)
    oclua_error(L, fname, "needs at least one child node in {a, b, ...}");
  oc_node **kids = children(L, &f, &n);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, fn(kids, n, &err), &err, fname);
}

static int l_blend(lua_State *L) {
  return nary(L, "outcrop.blend", oc_blend);
}
static int l_union(lua_State *L) {
  return nary(L, "outcrop.union", oc_union);
}
static int l_intersection(lua_State *L) {
  return nary(L, "outcrop.intersection", oc_intersection);
}

static int l_difference(lua_State *L) {
  oc_error err = {OC_OK, ""};
  const char *fname = "outcrop.difference";
  oclua_checkargs(L, 2, fname, "(a, b)");
  oc_node *a = oclua_checknode(L, 1, fname, "argument #1");
  oc_node *b = oclua_checknode(L, 2, fname, "argument #2");
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_difference(a, b, &err), &err, fname);
}

typedef oc_node *(*smooth_fn)(oc_node *, oc_node *, double, oc_error *);

static int smooth(lua_State *L, const char *fname, smooth_fn fn) {
  static const char *const known[] = {"radius", NULL};
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  size_t n;
  oclua_checkargs(L, 1, fname, "{a, b, radius = r}");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 1);
  if (f.narray != 2)
    oclua_error(L, fname,
                "needs exactly 2 child nodes {a, b, radius = r} "
                "(got %I)",
                (LUAI_UACINT)f.narray);
  double r = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  oc_node **kids = children(L, &f, &n);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, fn(kids[0], kids[1], r, &err), &err, fname);
}

static int l_smooth_union(lua_State *L) {
  return smooth(L, "outcrop.smooth_union", oc_smooth_union);
}
static int l_smooth_intersection(lua_State *L) {
  return smooth(L, "outcrop.smooth_intersection", oc_smooth_intersection);
}

/* ---- noise-driven operators ----------------------------------------- */

static int l_warp(lua_State *L) {
  static const char *const known[] = {"wavelength", "amplitude", "octaves",
                                      "seed",       "control",   NULL};
  const char *fname = "outcrop.warp";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_noise nz;
  oc_node *control = NULL;
  oclua_checkargs(L, 2, fname, "(node, {wavelength =, amplitude =, ...})");
  oc_node *child = oclua_checknode(L, 1, fname, "argument #1");
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oclua_field_noise(&f, &nz, NAN, 3, 0);
  /* The control node stays on the stack until oc_warp has retained it:
  ** it may come from an __index metamethod and have no other owner. */
  if (oclua_field_push(&f, "control") != LUA_TNIL) {
    oclua_node *c = oclua_testnode(L, -1);
    if (c == NULL)
      oclua_field_error(&f, "control", -1, "must be an outcrop node");
    control = c->node;
  }
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_warp(child, &nz, control, &err), &err, fname);
}

static int l_perturb(lua_State *L) {
  static const char *const known[] = {"wavelength", "amplitude", "octaves",
                                      "seed", NULL};
  const char *fname = "outcrop.perturb";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_noise nz;
  oclua_checkargs(L, 2, fname, "(node, {wavelength =, amplitude =, ...})");
  oc_node *child = oclua_checknode(L, 1, fname, "argument #1");
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oclua_field_noise(&f, &nz, NAN, 3, 0);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_perturb(child, &nz, &err), &err, fname);
}

/* ---- transform ------------------------------------------------------- */

/* The maps themselves are the lib's (oc_xform_*): here only the fields. */
static void check_rotate(lua_State *L, const char *fname, int idx,
                         double rot[12]) {
  static const char *const known[] = {"axis", "angle", NULL};
  oclua_fields f;
  oclua_fields_open(&f, L, idx, fname, "rotate.", known, 1);
  oc_error err = {OC_OK, ""};
  oc_xform_identity(rot);
  if (f.narray > 0) {
    oc_vec3 e;
    int named = lua_getfield(L, idx, "axis") != LUA_TNIL;
    named |= lua_getfield(L, idx, "angle") != LUA_TNIL;
    lua_pop(L, 2);
    if (named || f.narray != 3)
      oclua_error(L, fname,
                  "'rotate' must be {axis = {x, y, z}, angle = "
                  "degrees} or Euler angles {rx, ry, rz} in degrees");
    e = oclua_tovec(L, idx, fname, "rotate", 0);
    if (oc_xform_euler(e, rot, &err)) oclua_liberror(L, fname, &err);
    return;
  }
  oc_vec3 axis = oclua_field_vec(&f, "axis");
  double angle = oclua_field_number(&f, "angle", OCLUA_FINITE);
  if (oc_xform_axis_angle(axis, angle, rot, &err))
    oclua_liberror(L, fname, &err);
}

static int l_transform(lua_State *L) {
  static const char *const known[] = {"translate", "rotate", "scale", NULL};
  const char *fname = "outcrop.transform";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  double m[12], rot[12];
  oc_vec3 t = {0, 0, 0}, s = {1, 1, 1};
  oclua_checkargs(L, 2, fname, "(node, {translate =, rotate =, scale =})");
  oc_node *child = oclua_checknode(L, 1, fname, "argument #1");
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oclua_field_optvec(&f, "translate", &t);
  oc_xform_identity(rot);
  if (oclua_field_push(&f, "rotate") != LUA_TNIL)
    check_rotate(L, fname, lua_gettop(L), rot);
  lua_pop(L, 1);
  switch (oclua_field_push(&f, "scale")) {
  case LUA_TNIL:
    lua_pop(L, 1);
    break;
  case LUA_TNUMBER:
    lua_pop(L, 1);
    s.x = s.y = s.z = oclua_field_number(&f, "scale", OCLUA_NONZERO);
    break;
  default:
    if (!lua_istable(L, -1))
      oclua_field_error(&f, "scale", -1, "must be a number or {sx, sy, sz}");
    lua_pop(L, 1);
    oclua_field_optvec(&f, "scale", &s);
  }
  /* M = T * R * S, the lib's; it refuses zero scale factors */
  if (oc_xform_compose(t, rot, s, m, &err)) oclua_liberror(L, fname, &err);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_transform(child, m, &err), &err, fname);
}

/* ---- metamethods ----------------------------------------------------- */

/* "number", "string", "outcrop.node", ...: the operand's kind, not its
** value, reads best in "cannot apply '+' to outcrop.node and number". */
static const char *kindname(lua_State *L, int idx) {
  if (luaL_getmetafield(L, idx, "__name") == LUA_TSTRING)
    return lua_tostring(L, -1);
  return lua_pushstring(L, luaL_typename(L, idx));
}

static void binary_operands(lua_State *L, const char *op, oc_node *kids[2]) {
  for (int i = 0; i < 2; i++) {
    oclua_node *u = oclua_testnode(L, i + 1);
    if (u == NULL)
      oclua_error(L, "outcrop",
                  "cannot apply %s to %s and %s: both operands must be "
                  "outcrop nodes",
                  op, kindname(L, 1), kindname(L, 2));
    kids[i] = u->node;
  }
}

static int op_nary(lua_State *L, const char *op, nary_fn fn) {
  oc_node *kids[2];
  oc_error err = {OC_OK, ""};
  binary_operands(L, op, kids);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, fn(kids, 2, &err), &err, "outcrop");
}

static int op_add(lua_State *L) {
  return op_nary(L, "'+' (blend)", oc_blend);
}
static int op_bor(lua_State *L) {
  return op_nary(L, "'|' (union)", oc_union);
}
static int op_band(lua_State *L) {
  return op_nary(L, "'&' (intersection)", oc_intersection);
}

static int op_sub(lua_State *L) {
  oc_node *kids[2];
  oc_error err = {OC_OK, ""};
  binary_operands(L, "'-' (difference)", kids);
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_difference(kids[0], kids[1], &err), &err,
                       "outcrop");
}

static int op_unm(lua_State *L) {
  oc_error err = {OC_OK, ""};
  oc_node *a = oclua_checknode(L, 1, "outcrop", "the operand of unary '-'");
  oclua_node *u = oclua_newnode(L);
  return oclua_setnode(L, u, oc_scale_field(a, -1.0, &err), &err, "outcrop");
}

const luaL_Reg oclua_node_operators[] = {{"__add", op_add},   {"__sub", op_sub},
                                         {"__unm", op_unm},   {"__bor", op_bor},
                                         {"__band", op_band}, {NULL, NULL}};

static const luaL_Reg ops_funcs[] = {
    {"blend", l_blend},
    {"union", l_union},
    {"intersection", l_intersection},
    {"difference", l_difference},
    {"smooth_union", l_smooth_union},
    {"smooth_intersection", l_smooth_intersection},
    {"warp", l_warp},
    {"transform", l_transform},
    {"perturb", l_perturb},
    {NULL, NULL}};

void oclua_open_ops(lua_State *L) {
  luaL_setfuncs(L, ops_funcs, 0);
}
