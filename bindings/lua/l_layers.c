/*
** l_layers.c — material layer stacks (Peytavie et al. 2009): the
** outcrop.layers table and the stacks userdata.
**
**   outcrop.layers.new{size = {nx, ny}, cell = 1, origin = {0, 0},
**        base = 0, layers = {{"bedrock", 10}, {"sand", 1}, ...}}
**   outcrop.layers.from_heightfield(hf [, {base = min - 1, sand = 0}])
**   outcrop.layers.from_node(node, {box = {x0, y0, z0, x1, y1, z1},
**        cell =, material = "bedrock", step = cell / 4})
**
** Methods (i, j from 1):
**   s:get(i, j) -> {{material, thickness}, ...} bottom-up
**   s:set(i, j, {{material, thickness}, ...})
**   s:size() -> nx, ny;  s:cell();  s:origin() -> x0, y0;  s:base()
**   s:heightfield(material) -> the top of material per stack
**   s:volume(material) -> m^3
**   s:stats() -> {stacks =, layers =, bytes =}
**   s:field{materials = {"bedrock", "sand", "rocks"}, sigma = cell} -> node
**   s:stabilize{angle = {sand = 32, rocks = 42}, rate = 0.25,
**        tolerance = cell / 1000, iterations = 100000}
**        -> {iterations =, converged =, moved =}
**   s:deposit{center = {x, y}, radius =, amount =, material = "sand",
**        stabilize = true | false | {stabilize's fields}}
**        -> volume added (m^3), {iterations =, converged =, moved =}
**   s:erode{region = {x0, y0, x1, y1}, ratio = 0.5 (sand; the rest rocks),
**        mode = "surface" | "collapse", depth = 1 cell (surface: how deep;
**        collapse: the thickest roof that falls; default 5 cells),
**        stabilize = true | false | {...}} -> bedrock volume turned, {...}
**   s:sculpt{center = {x, y, z}, radius =, strength = 1, mode = "add" |
**        "carve", delta = radius / 2, stabilize = true | false | {...}}
**        -> bedrock volume added (negative: removed), {...}
**   s:sweep{path = {{x, y [, z] [, profile = k]}, ...} or {branch, ...},
**        profiles = {{u, v}, ...} or {{{u, v}, ...}, ...},
**        mode = "crack" | "tunnel", stabilize = true | false | {...}}
**        -> bedrock volume added (negative), {...}
**   s:colors{sigma = 1 cell, ratio = "visible" | "volume", sand = {r, g,
**        b}, ...} -> {blend = {{node, {r, g, b}}, ...}}: each material
**        present (bedrock first) with its weight around a point and its
**        colour, for render's `color =` and a mesh's `colors =`
**        (texturing by material). visible: the share of the surface
**        within the box of half-side sigma that exposes the material
**        (oc_stacks_visible); volume: its share of the box's volume
**        (its convolution surface, oc_stacks_field)
**   outcrop.layers.rocks{...} and s:rocks(tile, {...}): rock piles
**        (l_rocks.c)
**
** Stacks are mutable: a node made by s:field is a snapshot. `local s
** <close>` frees the grid early.
*/
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "l_field.h"
#include "l_handle.h"
#include "l_heightfield.h"
#include "l_layers.h"
#include "l_progress.h"

typedef struct oclua_layers {
  oclua_handle h; /* first: pins and closing (l_handle.h) */
  oc_stacks *s;
} oclua_layers;

static void layers_release(oclua_handle *h) {
  oclua_layers *u = (oclua_layers *)h;
  oc_stacks_free(u->s);
  u->s = NULL;
}

static oclua_layers *newlayers(lua_State *L) {
  oclua_layers *u = lua_newuserdatauv(L, sizeof *u, 0);
  oclua_handle_init(&u->h, "layers", layers_release);
  u->s = NULL;
  luaL_setmetatable(L, OCLUA_LAYERS);
  return u;
}

static int setlayers(lua_State *L, oclua_layers *u, oc_stacks *s,
                     const oc_error *err, const char *fname) {
  if (!s) return oclua_liberror(L, fname, err);
  u->s = s;
  return 1;
}

/* The stacks at idx, pinned for the rest of the call. */
static oc_stacks *pinlayers(lua_State *L, int idx, const char *fname) {
  oclua_layers *u = luaL_testudata(L, idx, OCLUA_LAYERS);
  if (!u)
    oclua_error(L, fname, "expected material stacks (got %s)",
                oclua_got(L, idx));
  oclua_handle_check(L, &u->h, fname);
  if (!u->s) oclua_error(L, fname, "the stacks are not made");
  oclua_pin(L, idx, &u->h, fname);
  return u->s;
}

/* A material name at idx; `what` names it in the message. */
static int tomaterial(lua_State *L, int idx, const char *fname,
                      const char *what) {
  const char *name =
      lua_type(L, idx) == LUA_TSTRING ? lua_tostring(L, idx) : NULL;
  int m = oc_material_parse(name);
  if (m < 0)
    oclua_error(
        L, fname, "%s must be one of air, water, sand, rocks, bedrock (got %s)",
        what, name ? lua_pushfstring(L, "'%s'", name) : oclua_got(L, idx));
  return m;
}

#define MAX_LAYERS 65536

/* {{material, thickness}, ...} at idx into Lua-owned arrays (pushed). */
static size_t read_layers(lua_State *L, int idx, const char *fname,
                          const char *label, uint8_t **mat, double **thick) {
  idx = lua_absindex(L, idx);
  if (!lua_istable(L, idx))
    oclua_error(L, fname,
                "'%s' must be an array of {material, thickness} (got %s)",
                label, oclua_got(L, idx));
  lua_Integer n = (lua_Integer)lua_rawlen(L, idx);
  if (n > MAX_LAYERS)
    oclua_error(L, fname, "'%s': %I layers, at most %d", label, n, MAX_LAYERS);
  double *t = lua_newuserdatauv(L, (size_t)(n ? n : 1) * 9, 0);
  uint8_t *m = (uint8_t *)(t + (n ? n : 1));
  for (lua_Integer i = 1; i <= n; i++) {
    lua_rawgeti(L, idx, i);
    if (!lua_istable(L, -1) || lua_rawlen(L, -1) != 2)
      oclua_error(L, fname, "'%s[%I]' must be {material, thickness} (got %s)",
                  label, i, oclua_got(L, -1));
    lua_rawgeti(L, -1, 1);
    int v = lua_gettop(L);
    m[i - 1] = (uint8_t)tomaterial(
        L, v, fname, lua_pushfstring(L, "'%s[%I]' material", label, i));
    lua_pop(L, 2);
    lua_rawgeti(L, -1, 2);
    int ok = lua_type(L, -1) == LUA_TNUMBER;
    t[i - 1] = lua_tonumber(L, -1);
    if (!ok || !isfinite(t[i - 1]) || t[i - 1] < 0)
      oclua_error(L, fname, "'%s[%I]' thickness must be a number >= 0 (got %s)",
                  label, i, oclua_got(L, -1));
    lua_pop(L, 2);
  }
  *mat = m;
  *thick = t;
  return (size_t)n;
}

/* ---- constructors -------------------------------------------------------- */

static int l_new(lua_State *L) {
  static const char *const known[] = {"size", "cell",   "origin",
                                      "base", "layers", NULL};
  const char *fname = "outcrop.layers.new";
  oclua_checkargs(L, 1, fname, "a table of named fields");
  oclua_fields f;
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  double sz[2], org[2] = {0, 0};
  if (!oclua_field_numbers(&f, "size", 2, sz, "must be {nx, ny}"))
    oclua_field_missing(&f, "size", "must be {nx, ny}");
  if (sz[0] != floor(sz[0]) || sz[1] != floor(sz[1]) || sz[0] < 1 ||
      sz[1] < 1 || sz[0] > 65535 || sz[1] > 65535)
    oclua_error(L, fname, "'size' must be two integers in 1 .. 65535");
  double cell = oclua_field_optnumber(&f, "cell", OCLUA_POSITIVE, 1);
  oclua_field_numbers(&f, "origin", 2, org, "must be {x0, y0}");
  double base = oclua_field_optnumber(&f, "base", OCLUA_FINITE, 0);
  uint8_t *m = NULL;
  double *t = NULL;
  size_t n = 0;
  if (oclua_field_push(&f, "layers") != LUA_TNIL)
    n = read_layers(L, -1, fname, "layers", &m, &t);
  oclua_layers *u = newlayers(L);
  oc_error err = {OC_OK, ""};
  oc_stacks *s =
      oc_stacks_new((int)sz[0], (int)sz[1], cell, org[0], org[1], base, &err);
  if (s && n && oc_stacks_fill(s, m, t, n, &err)) {
    oc_stacks_free(s);
    s = NULL;
  }
  return setlayers(L, u, s, &err, fname);
}

static int l_from_heightfield(lua_State *L) {
  static const char *const known[] = {"base", "sand", NULL};
  const char *fname = "outcrop.layers.from_heightfield";
  oclua_checkargs(L, 2, fname, "(heightfield [, {base=, sand=}])");
  lua_settop(L, 2);
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  oc_stacks_hf_params p = {NAN, 0};
  if (!lua_isnil(L, 2)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    p.zbase = oclua_field_optnumber(&f, "base", OCLUA_FINITE, NAN);
    p.sand = oclua_field_optnumber(&f, "sand", OCLUA_FINITE, 0);
    if (p.sand < 0)
      oclua_error(L, fname, "'sand' must be >= 0 (got %f)",
                  (LUAI_UACNUMBER)p.sand);
  }
  oclua_layers *u = newlayers(L);
  oc_error err = {OC_OK, ""};
  return setlayers(L, u, oc_stacks_from_heightfield(hf, &p, &err), &err, fname);
}

static int l_from_node(lua_State *L) {
  static const char *const known[] = {"box", "cell", "material", "step", NULL};
  const char *fname = "outcrop.layers.from_node";
  oclua_checkargs(L, 2, fname, "(node, {box=, cell=, material=, step=})");
  oclua_checknode(L, 1, fname, "argument #1");
  oclua_fields f;
  if (!lua_istable(L, 2))
    oclua_error(L, fname, "argument #2 must be a table {box=, cell=} (got %s)",
                oclua_got(L, 2));
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  double b[6];
  if (!oclua_field_numbers(&f, "box", 6, b, "must be {x0, y0, z0, x1, y1, z1}"))
    oclua_field_missing(&f, "box", "must be {x0, y0, z0, x1, y1, z1}");
  oc_stacks_node_params p;
  p.box = (oc_aabb){{b[0], b[1], b[2]}, {b[3], b[4], b[5]}};
  if (!(b[0] <= b[3] && b[1] <= b[4] && b[2] < b[5]))
    oclua_error(L, fname, "'box' needs x0 <= x1, y0 <= y1 and z0 < z1");
  p.cell = oclua_field_number(&f, "cell", OCLUA_POSITIVE);
  p.step = oclua_field_optnumber(&f, "step", OCLUA_POSITIVE, 0);
  p.material = OC_MAT_BEDROCK;
  if (oclua_field_push(&f, "material") != LUA_TNIL)
    p.material = tomaterial(L, -1, fname, "'material'");
  if (p.material == OC_MAT_AIR)
    oclua_error(L, fname, "'material' must not be air");
  const oc_program *prog = oclua_program(L, 1, fname);
  oclua_layers *u = newlayers(L);
  oc_error err = {OC_OK, ""};
  oclua_progress pl; /* the line on stderr and Ctrl-C */
  p.progress = oclua_progress_start(L, &pl, fname);
  oc_stacks *s = oc_stacks_from_program(prog, &p, &err);
  oclua_progress_end(&pl);
  return setlayers(L, u, s, &err, fname);
}

/* ---- methods ------------------------------------------------------------- */

static void check_ij(lua_State *L, oc_stacks *s, const char *fname, int *i,
                     int *j) {
  int n[2] = {oc_stacks_nx(s), oc_stacks_ny(s)};
  for (int k = 0; k < 2; k++) {
    int isint;
    lua_Integer v = lua_tointegerx(L, 2 + k, &isint);
    if (lua_type(L, 2 + k) != LUA_TNUMBER || !isint || v < 1 || v > n[k])
      oclua_error(L, fname, "%s must be an integer in 1..%d (got %s)",
                  k == 0 ? "i" : "j", n[k], oclua_got(L, 2 + k));
    if (k == 0)
      *i = (int)v - 1;
    else
      *j = (int)v - 1;
  }
}

static int m_get(lua_State *L) {
  const char *fname = "layers:get";
  oclua_checkargs(L, 3, fname, "(i, j)");
  oc_stacks *s = pinlayers(L, 1, fname);
  int i, j;
  check_ij(L, s, fname, &i, &j);
  size_t n = oc_stacks_get(s, i, j, NULL, NULL, 0);
  double *t = lua_newuserdatauv(L, (n ? n : 1) * 9, 0);
  uint8_t *m = (uint8_t *)(t + (n ? n : 1));
  oc_stacks_get(s, i, j, m, t, n);
  lua_createtable(L, n > 1000000 ? 0 : (int)n, 0);
  for (size_t l = 0; l < n; l++) {
    lua_createtable(L, 2, 0);
    lua_pushstring(L, oc_material_name(m[l]));
    lua_rawseti(L, -2, 1);
    lua_pushnumber(L, t[l]);
    lua_rawseti(L, -2, 2);
    lua_rawseti(L, -2, (lua_Integer)l + 1);
  }
  return 1;
}

static int m_set(lua_State *L) {
  const char *fname = "layers:set";
  oclua_checkargs(L, 4, fname, "(i, j, {{material, thickness}, ...})");
  lua_settop(L, 4);
  oc_stacks *s = pinlayers(L, 1, fname);
  int i, j;
  check_ij(L, s, fname, &i, &j);
  uint8_t *m;
  double *t;
  size_t n = read_layers(L, 4, fname, "layers", &m, &t);
  oc_error err = {OC_OK, ""};
  if (oc_stacks_set(s, i, j, m, t, n, &err)) oclua_liberror(L, fname, &err);
  lua_settop(L, 1);
  return 1;
}

static int m_size(lua_State *L) {
  oc_stacks *s = pinlayers(L, 1, "layers:size");
  lua_pushinteger(L, oc_stacks_nx(s));
  lua_pushinteger(L, oc_stacks_ny(s));
  return 2;
}

static int m_cell(lua_State *L) {
  lua_pushnumber(L, oc_stacks_cell(pinlayers(L, 1, "layers:cell")));
  return 1;
}

static int m_origin(lua_State *L) {
  double x0, y0;
  oc_stacks_origin(pinlayers(L, 1, "layers:origin"), &x0, &y0);
  lua_pushnumber(L, x0);
  lua_pushnumber(L, y0);
  return 2;
}

static int m_base(lua_State *L) {
  lua_pushnumber(L, oc_stacks_base(pinlayers(L, 1, "layers:base")));
  return 1;
}

static int m_heightfield(lua_State *L) {
  const char *fname = "layers:heightfield";
  oclua_checkargs(L, 2, fname, "(material)");
  oc_stacks *s = pinlayers(L, 1, fname);
  int m = tomaterial(L, 2, fname, "argument #1 (material)");
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_error err = {OC_OK, ""};
  return oclua_sethf(L, u, oc_stacks_heightfield(s, m, &err), &err, fname);
}

static int m_volume(lua_State *L) {
  const char *fname = "layers:volume";
  oclua_checkargs(L, 2, fname, "(material)");
  oc_stacks *s = pinlayers(L, 1, fname);
  lua_pushnumber(L, oc_stacks_volume(
                        s, tomaterial(L, 2, fname, "argument #1 (material)")));
  return 1;
}

static int m_stats(lua_State *L) {
  const char *fname = "layers:stats";
  oclua_checkargs(L, 1, fname, "()");
  oc_stacks_stats st;
  oc_stacks_get_stats(pinlayers(L, 1, fname), &st);
  lua_createtable(L, 0, 3);
  lua_pushinteger(L, (lua_Integer)st.stacks);
  lua_setfield(L, -2, "stacks");
  lua_pushinteger(L, (lua_Integer)st.layers);
  lua_setfield(L, -2, "layers");
  lua_pushinteger(L, (lua_Integer)st.bytes);
  lua_setfield(L, -2, "bytes");
  return 1;
}

static int m_field(lua_State *L) {
  static const char *const known[] = {"materials", "sigma", NULL};
  const char *fname = "layers:field";
  oclua_checkargs(L, 2, fname, "([{materials=, sigma=}])");
  lua_settop(L, 2);
  oc_stacks *s = pinlayers(L, 1, fname);
  unsigned mask = 1u << OC_MAT_BEDROCK | 1u << OC_MAT_SAND | 1u << OC_MAT_ROCKS;
  double sigma = NAN;
  if (!lua_isnil(L, 2)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    if (oclua_field_push(&f, "sigma") != LUA_TNIL) {
      lua_pop(L, 1);
      sigma = oclua_field_number(&f, "sigma", OCLUA_FINITE);
      if (!(sigma > 0))
        oclua_error(L, fname, "'sigma' must be > 0 (got %f)",
                    (LUAI_UACNUMBER)sigma);
    } else {
      lua_pop(L, 1);
    }
    if (oclua_field_push(&f, "materials") != LUA_TNIL) {
      int t = lua_gettop(L);
      if (!lua_istable(L, t) || lua_rawlen(L, t) < 1)
        oclua_field_error(&f, "materials", t,
                          "must be a non-empty array of material names");
      mask = 0;
      for (lua_Integer k = 1; k <= (lua_Integer)lua_rawlen(L, t); k++) {
        lua_rawgeti(L, t, k);
        int v = lua_gettop(L);
        int m =
            tomaterial(L, v, fname, lua_pushfstring(L, "'materials[%I]'", k));
        if (m == OC_MAT_AIR)
          oclua_error(L, fname, "'materials[%I]' must not be air", k);
        mask |= 1u << m;
        lua_pop(L, 2);
      }
    }
  }
  oclua_node *u = oclua_newnode(L);
  oc_error err = {OC_OK, ""};
  return oclua_setnode(L, u, oc_stacks_field(s, mask, sigma, &err), &err,
                       fname);
}

/* The stabilisation fields of table idx (opened as f) into p. */
static void read_stab(oclua_fields *f, oc_stabilize_params *p) {
  static const char *const angles[] = {"sand", "rocks", NULL};
  lua_State *L = f->L;
  if (oclua_field_push(f, "angle") != LUA_TNIL) {
    if (!lua_istable(L, -1))
      oclua_field_error(f, "angle", -1, "must be a table {sand=, rocks=}");
    oclua_fields a;
    oclua_fields_open(&a, L, lua_gettop(L), f->fname, "angle.", angles, 0);
    p->angle[OC_MAT_SAND] =
        oclua_field_optnumber(&a, "sand", OCLUA_FINITE, p->angle[OC_MAT_SAND]);
    p->angle[OC_MAT_ROCKS] = oclua_field_optnumber(&a, "rocks", OCLUA_FINITE,
                                                   p->angle[OC_MAT_ROCKS]);
  }
  lua_pop(L, 1);
  p->rate = oclua_field_optnumber(f, "rate", OCLUA_POSITIVE, p->rate);
  p->tolerance =
      oclua_field_optnumber(f, "tolerance", OCLUA_POSITIVE, p->tolerance);
  p->iterations =
      (long)oclua_field_optint(f, "iterations", 1, 1000000000, p->iterations);
}

/* The field `stabilize` of a tool: true (the default) or false, or a
** table of stabilize's fields read into p. Returns whether to stabilise.
** (The value stays on the stack.) */
static int read_stab_option(oclua_fields *f, oc_stabilize_params *p) {
  static const char *const sknown[] = {"angle", "rate", "tolerance",
                                       "iterations", NULL};
  lua_State *L = f->L;
  int t = oclua_field_push(f, "stabilize");
  if (t == LUA_TBOOLEAN) return lua_toboolean(L, -1);
  if (t == LUA_TTABLE) {
    oclua_fields g;
    oclua_fields_open(&g, L, lua_gettop(L), f->fname, "stabilize.", sknown, 0);
    read_stab(&g, p);
  } else if (t != LUA_TNIL) {
    oclua_field_error(f, "stabilize", -1,
                      "must be a boolean or a table of stabilisation fields");
  }
  return 1;
}

static void push_result(lua_State *L, const oc_stabilize_result *r) {
  lua_createtable(L, 0, 3);
  lua_pushinteger(L, r->iterations);
  lua_setfield(L, -2, "iterations");
  lua_pushboolean(L, r->converged);
  lua_setfield(L, -2, "converged");
  lua_pushnumber(L, r->moved);
  lua_setfield(L, -2, "moved");
}

static int m_stabilize(lua_State *L) {
  static const char *const known[] = {"angle", "rate", "tolerance",
                                      "iterations", NULL};
  const char *fname = "layers:stabilize";
  oclua_checkargs(L, 2, fname, "([{angle=, rate=, tolerance=, iterations=}])");
  lua_settop(L, 2);
  oc_stacks *s = pinlayers(L, 1, fname);
  oc_stabilize_params p;
  oc_stabilize_defaults(s, &p);
  if (!lua_isnil(L, 2)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    read_stab(&f, &p);
  }
  oc_error err = {OC_OK, ""};
  oc_stabilize_result r;
  if (oc_stacks_stabilize(s, &p, &r, &err)) oclua_liberror(L, fname, &err);
  push_result(L, &r);
  return 1;
}

static int m_deposit(lua_State *L) {
  static const char *const known[] = {"center",   "radius",    "amount",
                                      "material", "stabilize", NULL};
  const char *fname = "layers:deposit";
  oclua_checkargs(L, 2, fname,
                  "({center=, radius=, amount=, material=, stabilize=})");
  oc_stacks *s = pinlayers(L, 1, fname);
  oclua_fields f;
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  double c[2];
  if (!oclua_field_numbers(&f, "center", 2, c, "must be {x, y}"))
    oclua_field_missing(&f, "center", "must be {x, y}");
  oc_stabilize_params sp;
  oc_stabilize_defaults(s, &sp);
  oc_deposit_params p = {c[0], c[1], 0, 0, OC_MAT_SAND, 1, &sp};
  p.radius = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  p.amount = oclua_field_number(&f, "amount", OCLUA_FINITE);
  if (p.amount < 0)
    oclua_error(L, fname, "'amount' must be >= 0 (got %f)",
                (LUAI_UACNUMBER)p.amount);
  if (oclua_field_push(&f, "material") != LUA_TNIL) {
    p.material = tomaterial(L, -1, fname, "'material'");
    if (p.material != OC_MAT_SAND && p.material != OC_MAT_ROCKS &&
        p.material != OC_MAT_WATER)
      oclua_error(L, fname, "'material' must be sand, rocks or water");
  }
  p.stabilize = read_stab_option(&f, &sp);
  oc_error err = {OC_OK, ""};
  oc_stabilize_result r;
  double added;
  if (oc_stacks_deposit(s, &p, &added, &r, &err))
    oclua_liberror(L, fname, &err);
  lua_pushnumber(L, added);
  push_result(L, &r);
  return 2;
}

static int m_erode(lua_State *L) {
  static const char *const known[] = {"region", "ratio",     "depth",
                                      "mode",   "stabilize", NULL};
  static const char *const modes[] = {"surface", "collapse", NULL};
  const char *fname = "layers:erode";
  oclua_checkargs(L, 2, fname,
                  "({region=, ratio=, depth=, mode=, stabilize=})");
  oc_stacks *s = pinlayers(L, 1, fname);
  oclua_fields f;
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  double r[4];
  if (!oclua_field_numbers(&f, "region", 4, r, "must be {x0, y0, x1, y1}"))
    oclua_field_missing(&f, "region", "must be {x0, y0, x1, y1}");
  oc_stabilize_params sp;
  oc_stabilize_defaults(s, &sp);
  oc_stacks_erode_params p = {
      r[0], r[1], r[2], r[3], 0.5, 0, OC_STACKS_ERODE_SURFACE, 1, &sp};
  p.ratio = oclua_field_optnumber(&f, "ratio", OCLUA_FINITE, 0.5);
  p.mode = (oc_stacks_erode_mode)oclua_field_optoption(&f, "mode", modes, 0);
  p.depth = oclua_field_optnumber(&f, "depth", OCLUA_POSITIVE,
                                  (p.mode == OC_STACKS_ERODE_SURFACE ? 1 : 5) *
                                      oc_stacks_cell(s));
  p.stabilize = read_stab_option(&f, &sp);
  oc_error err = {OC_OK, ""};
  oc_stabilize_result res;
  double eroded;
  if (oc_stacks_erode(s, &p, &eroded, &res, &err))
    oclua_liberror(L, fname, &err);
  lua_pushnumber(L, eroded);
  push_result(L, &res);
  return 2;
}

static int m_sculpt(lua_State *L) {
  static const char *const known[] = {"center", "radius",    "strength", "mode",
                                      "delta",  "stabilize", NULL};
  static const char *const modes[] = {"add", "carve", NULL};
  const char *fname = "layers:sculpt";
  oclua_checkargs(L, 2, fname,
                  "({center=, radius=, strength=, mode=, delta=, stabilize=})");
  oc_stacks *s = pinlayers(L, 1, fname);
  oclua_fields f;
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oc_stabilize_params sp;
  oc_stabilize_defaults(s, &sp);
  oc_sculpt_params p = {oclua_field_vec(&f, "center"), 0, 1, NAN, 0, 0, 1, &sp};
  p.radius = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  p.strength = oclua_field_optnumber(&f, "strength", OCLUA_POSITIVE, 1);
  p.carve = oclua_field_optoption(&f, "mode", modes, 0);
  p.delta = oclua_field_optnumber(&f, "delta", OCLUA_FINITE, p.radius / 2);
  if (p.delta < 0)
    oclua_error(L, fname, "'delta' must be >= 0 (got %f)",
                (LUAI_UACNUMBER)p.delta);
  p.stabilize = read_stab_option(&f, &sp);
  p.threshold = oclua_threshold(L, fname);
  oc_error err = {OC_OK, ""};
  oc_stabilize_result res;
  double changed;
  if (oc_stacks_sculpt(s, &p, &changed, &res, &err))
    oclua_liberror(L, fname, &err);
  lua_pushnumber(L, changed);
  push_result(L, &res);
  return 2;
}

/* One path point {x, y [, z] [, profile = k]} at the top of the stack into
** pt and its profile index (from 0); `label` names it in messages. */
static void read_point(lua_State *L, const char *fname, const char *label,
                       lua_Integer b, lua_Integer i, int tunnel, oc_vec3 *pt,
                       int *prof) {
  int n = lua_istable(L, -1) ? (int)lua_rawlen(L, -1) : 0;
  double v[3] = {0, 0, 0};
  int ok = n == 2 + tunnel || (!tunnel && n == 3);
  for (int k = 1; ok && k <= n; k++) {
    lua_rawgeti(L, -1, k);
    ok = lua_type(L, -1) == LUA_TNUMBER && isfinite(lua_tonumber(L, -1));
    v[k - 1] = lua_tonumber(L, -1);
    lua_pop(L, 1);
  }
  if (!ok) {
    const char *want = tunnel ? "{x, y, z}" : "{x, y}";
    if (b)
      oclua_error(L, fname, "'%s[%I][%I]' must be %s with finite numbers",
                  label, b, i, want);
    oclua_error(L, fname, "'%s[%I]' must be %s with finite numbers", label, i,
                want);
  }
  *pt = (oc_vec3){v[0], v[1], v[2]};
  lua_pushliteral(L, "profile");
  lua_rawget(L, -2);
  *prof = 0;
  if (!lua_isnil(L, -1)) {
    int isint;
    lua_Integer k = lua_tointegerx(L, -1, &isint);
    if (!isint || k < 1 || k > INT_MAX)
      oclua_error(L, fname,
                  "'profile' of a '%s' point must be an integer >= 1 "
                  "(got %s)",
                  label, oclua_got(L, -1));
    *prof = (int)(k - 1);
  }
  lua_pop(L, 1);
}

static int m_sweep(lua_State *L) {
  static const char *const known[] = {"path", "profiles", "mode", "stabilize",
                                      NULL};
  static const char *const modes[] = {"crack", "tunnel", NULL};
  const char *fname = "layers:sweep";
  oclua_checkargs(L, 2, fname, "({path=, profiles=, mode=, stabilize=})");
  oc_stacks *s = pinlayers(L, 1, fname);
  oclua_fields f;
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oc_stabilize_params sp;
  oc_stabilize_defaults(s, &sp);
  oc_sweep_params p;
  memset(&p, 0, sizeof p);
  p.tunnel = oclua_field_optoption(&f, "mode", modes, 0);
  p.stab = &sp;
  p.stabilize = read_stab_option(&f, &sp);
  /* path: one polyline, or branches (polylines sharing points) */
  if (oclua_field_push(&f, "path") != LUA_TTABLE)
    oclua_field_error(&f, "path", -1,
                      "must be an array of points or of arrays of points");
  int path = lua_gettop(L);
  lua_Integer nb = (lua_Integer)lua_rawlen(L, path);
  lua_rawgeti(L, path, 1);
  int branches = 0;
  if (lua_istable(L, -1)) {
    lua_rawgeti(L, -1, 1);
    branches = lua_istable(L, -1);
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  if (nb < 1 || nb > OC_SWEEP_MAX_POINTS)
    oclua_error(L, fname, "'path' must hold 1 .. %d entries (got %I)",
                OC_SWEEP_MAX_POINTS, nb);
  size_t np = 0;
  for (lua_Integer b = 1; branches && b <= nb; b++) {
    lua_rawgeti(L, path, b);
    lua_Integer n = lua_istable(L, -1) ? (lua_Integer)lua_rawlen(L, -1) : 0;
    if (n < 2)
      oclua_error(L, fname, "'path[%I]' must be an array of 2 or more points",
                  b);
    np += (size_t)n;
    lua_pop(L, 1);
    if (np > OC_SWEEP_MAX_POINTS)
      oclua_error(L, fname, "'path' must hold at most %d points",
                  OC_SWEEP_MAX_POINTS);
  }
  if (!branches) np = (size_t)nb;
  if (np < 2) oclua_error(L, fname, "'path' must hold 2 or more points");
  oc_vec3 *pts = lua_newuserdatauv(L, np * sizeof *pts, 0);
  int *prof = lua_newuserdatauv(L, np * sizeof *prof, 0);
  int *edges = lua_newuserdatauv(L, 2 * np * sizeof *edges, 0);
  size_t k = 0, ne = 0;
  for (lua_Integer b = 1; b <= (branches ? nb : 1); b++) {
    if (branches) lua_rawgeti(L, path, b);
    int line = branches ? lua_gettop(L) : path;
    lua_Integer n = (lua_Integer)lua_rawlen(L, line);
    for (lua_Integer i = 1; i <= n; i++, k++) {
      lua_rawgeti(L, line, i);
      read_point(L, fname, "path", branches ? b : 0, i, p.tunnel, &pts[k],
                 &prof[k]);
      lua_pop(L, 1);
      if (i > 1) {
        edges[2 * ne] = (int)k - 1;
        edges[2 * ne + 1] = (int)k;
        ne++;
      }
    }
    if (branches) lua_pop(L, 1);
  }
  /* profiles: one closed curve of {u, v}, or an array of them */
  if (oclua_field_push(&f, "profiles") != LUA_TTABLE)
    oclua_field_error(&f, "profiles", -1,
                      "must be a closed curve {{u, v}, ...} or an array of "
                      "them");
  int pidx = lua_gettop(L);
  lua_rawgeti(L, pidx, 1);
  int many = 0;
  if (lua_istable(L, -1)) {
    lua_rawgeti(L, -1, 1);
    many = lua_istable(L, -1);
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  lua_Integer nprof = many ? (lua_Integer)lua_rawlen(L, pidx) : 1;
  if (nprof < 1 || nprof > 4096)
    oclua_error(L, fname, "'profiles' must hold 1 .. 4096 curves (got %I)",
                nprof);
  size_t *off = lua_newuserdatauv(L, ((size_t)nprof + 1) * sizeof *off, 0);
  off[0] = 0;
  int first = lua_gettop(L) + 1;
  for (lua_Integer q = 1; q <= nprof; q++) {
    if (many) lua_rawgeti(L, pidx, q);
    size_t n;
    char label[32];
    snprintf(label, sizeof label, "profiles[%d]", (int)q);
    oclua_read_xy(L, many ? lua_gettop(L) : pidx, fname, label, 3, 1024, &n);
    if (many) lua_remove(L, -2);
    off[q] = off[q - 1] + n;
  }
  double *uv = lua_newuserdatauv(L, 2 * off[nprof] * sizeof *uv + 1, 0);
  for (lua_Integer q = 1; q <= nprof; q++)
    memcpy(uv + 2 * off[q - 1], lua_touserdata(L, first + (int)q - 1),
           2 * (off[q] - off[q - 1]) * sizeof *uv);
  p.points = pts;
  p.point_profile = prof;
  p.npoints = np;
  p.edges = edges;
  p.nedges = ne;
  p.profile_uv = uv;
  p.profile_off = off;
  p.nprofiles = (size_t)nprof;
  oc_error err = {OC_OK, ""};
  oc_stabilize_result res;
  double changed;
  if (oc_stacks_sweep(s, &p, &changed, &res, &err))
    oclua_liberror(L, fname, &err);
  lua_pushnumber(L, changed);
  push_result(L, &res);
  return 2;
}

/* Linear albedos of the materials (air: none), as the renderer's rule
** colours for sand and rock. */
static const double MAT_RGB[OC_MAT_COUNT][3] = {{0, 0, 0},
                                                {0.05, 0.12, 0.18},
                                                {0.50, 0.42, 0.28},
                                                {0.12, 0.11, 0.10},
                                                {0.22, 0.18, 0.15}};

static int m_colors(lua_State *L) {
  static const char *const known[] = {"sigma", "ratio",   "water", "sand",
                                      "rocks", "bedrock", NULL};
  static const char *const ratios[] = {"visible", "volume", NULL};
  const char *fname = "layers:colors";
  oclua_checkargs(L, 2, fname,
                  "([{sigma=, ratio=, water=, sand=, rocks=, bedrock=}])");
  lua_settop(L, 2);
  oc_stacks *s = pinlayers(L, 1, fname);
  double sigma = oc_stacks_cell(s), rgb[OC_MAT_COUNT][3];
  int volume = 0;
  memcpy(rgb, MAT_RGB, sizeof rgb);
  if (!lua_isnil(L, 2)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    sigma = oclua_field_optnumber(&f, "sigma", OCLUA_POSITIVE, sigma);
    volume = oclua_field_optoption(&f, "ratio", ratios, 0) == 1;
    for (int m = OC_MAT_WATER; m < OC_MAT_COUNT; m++) {
      const char *name = oc_material_name(m);
      if (!oclua_field_numbers(&f, name, 3, rgb[m], "must be {r, g, b}"))
        continue;
      for (int c = 0; c < 3; c++)
        if (!(rgb[m][c] >= 0 && rgb[m][c] <= 1))
          oclua_error(L, fname, "'%s' must be {r, g, b} in [0, 1]", name);
    }
  }
  /* {blend = {{field of m, {r, g, b}}, ...}} for the materials present */
  lua_createtable(L, 0, 1);
  lua_createtable(L, OC_MAT_COUNT, 0);
  int n = 0;
  for (int m = OC_MAT_COUNT - 1; m > OC_MAT_AIR; m--) {
    if (!(oc_stacks_volume(s, m) > 0)) continue;
    lua_createtable(L, 2, 0);
    oclua_node *u = oclua_newnode(L);
    oc_error err = {OC_OK, ""};
    oclua_setnode(L, u,
                  volume ? oc_stacks_field(s, 1u << m, sigma, &err)
                         : oc_stacks_visible(s, m, sigma, &err),
                  &err, fname);
    lua_rawseti(L, -2, 1);
    lua_createtable(L, 3, 0);
    for (int c = 0; c < 3; c++) {
      lua_pushnumber(L, rgb[m][c]);
      lua_rawseti(L, -2, c + 1);
    }
    lua_rawseti(L, -2, 2);
    lua_rawseti(L, -2, ++n);
  }
  if (n == 0) oclua_error(L, fname, "the stacks hold no material");
  lua_setfield(L, -2, "blend");
  return 1;
}

/* ---- metamethods ------------------------------------------------------- */

static int m_gc(lua_State *L) {
  oclua_handle_close(luaL_checkudata(L, 1, OCLUA_LAYERS));
  return 0;
}

static int m_tostring(lua_State *L) {
  oclua_layers *u = luaL_checkudata(L, 1, OCLUA_LAYERS);
  if (!u->s || u->h.closed) {
    lua_pushliteral(L, OCLUA_LAYERS ": (closed)");
    return 1;
  }
  oc_stacks_stats st;
  oc_stacks_get_stats(u->s, &st);
  char buf[200];
  snprintf(
      buf, sizeof buf, OCLUA_LAYERS ": %d x %d stacks, cell %g, %zu layers",
      oc_stacks_nx(u->s), oc_stacks_ny(u->s), oc_stacks_cell(u->s), st.layers);
  lua_pushstring(L, buf);
  return 1;
}

static const luaL_Reg methods[] = {{"get", m_get},
                                   {"set", m_set},
                                   {"size", m_size},
                                   {"cell", m_cell},
                                   {"origin", m_origin},
                                   {"base", m_base},
                                   {"heightfield", m_heightfield},
                                   {"volume", m_volume},
                                   {"stats", m_stats},
                                   {"field", m_field},
                                   {"stabilize", m_stabilize},
                                   {"deposit", m_deposit},
                                   {"erode", m_erode},
                                   {"sculpt", m_sculpt},
                                   {"sweep", m_sweep},
                                   {"colors", m_colors},
                                   {NULL, NULL}};

static const luaL_Reg meta[] = {{"__gc", m_gc},
                                {"__close", m_gc},
                                {"__tostring", m_tostring},
                                {NULL, NULL}};

static const luaL_Reg funcs[] = {{"new", l_new},
                                 {"from_heightfield", l_from_heightfield},
                                 {"from_node", l_from_node},
                                 {NULL, NULL}};

oc_stacks *oclua_pinlayers(lua_State *L, int idx, const char *fname) {
  return pinlayers(L, idx, fname);
}

void oclua_open_layers(lua_State *L) {
  oclua_newmeta(L, OCLUA_LAYERS, meta, methods);
  lua_pop(L, 1);
  luaL_newlib(L, funcs);
  oclua_open_rocks(L); /* l_rocks.c */
  lua_setfield(L, -2, "layers");
}
