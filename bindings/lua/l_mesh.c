/*
** l_mesh.c — outcrop.polygonize and the mesh userdata (write, stats,
** counts, vertex, triangle, components).
**
** polygonize defaults (the lib's, oc_polygonize_default_box and _cell):
** box = the node's bounds (an error when they are
** infinite or empty); when neither 'cell' nor 'resolution' is given,
** cubic cells of 1/64 of the box's longest side; threshold =
** outcrop.threshold; open = false; steps = 6; full_grid = false;
** max_triangles = 2^27 (a mesh projected to have more, from probes
** through the box before meshing, is refused with the figure);
** min_component = 0 (keep every connected component). The node
** is compiled with the threshold it is meshed at, since difference and
** the smooth operators depend on T.
**
** Colours are a property of the mesh: `colors =` in polygonize's table or
** in write's options stores them, and every later write carries them
** (.ply and .glb; .obj has no colours). Either
**   {field = node, palette = {{value, {r, g, b}}, ...}}
** (the node evaluated at each vertex with outcrop.threshold, mapped
** through the palette: values ascending, linear between stops, clamped
** at the ends), {blend = {{node, {r, g, b}}, ...}, texture = 0.3,
** texture_scale = 8} (colours blended by the nodes' values with a
** triplanar texture each: texturing by material, e.g. stacks:colors())
** or a function (x, y, z, nx, ny, nz) -> r, g, b called once per vertex
** in index order. Components are linear, in [0, 1].
**
** Every write carries the provenance images get (l_provenance.h).
*/
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "l_blend.h"
#include "l_field.h"
#include "l_mesh.h"
#include "l_progress.h"
#include "l_provenance.h"

#define MAX_CELLS (1 << 20) /* per axis, as the lib allows */
#define DEFAULT_STEPS 6
#define MAX_STEPS 64

static void mesh_release(oclua_handle *h) {
  oclua_mesh *u = (oclua_mesh *)h;
  if (u->mesh) oc_mesh_free(u->mesh);
  u->mesh = NULL;
}

oclua_mesh *oclua_newmesh(lua_State *L) {
  oclua_mesh *u = lua_newuserdatauv(L, sizeof *u, 0);
  oclua_handle_init(&u->h, "mesh", mesh_release);
  u->mesh = NULL;
  luaL_setmetatable(L, OCLUA_MESH);
  return u;
}

/* The mesh at 1, open; pinned for the rest of the call when pin is set. */
static oclua_mesh *checkmesh(lua_State *L, const char *fname, int pin) {
  oclua_mesh *u = luaL_checkudata(L, 1, OCLUA_MESH);
  oclua_handle_check(L, &u->h, fname);
  if (u->mesh == NULL) oclua_error(L, fname, "the mesh is not made");
  if (pin) oclua_pin(L, 1, &u->h, fname);
  return u;
}

/* ---- colours --------------------------------------------------------- */

enum { COLORS_NONE, COLORS_FUNCTION, COLORS_FIELD, COLORS_BLEND };

/* What a `colors` field asked for. Everything it points to stays on the
** Lua stack (the function or node at `idx`, the stops in a userdata)
** until the colours are applied. */
typedef struct colors {
  int kind;
  int idx;
  const double *stops; /* value, r, g, b per stop */
  int nstops;
  const double *blend; /* COLORS_BLEND: r, g, b per node of the table at idx */
  int nblend;
  double texture, texture_scale;
} colors;

static const char *const rgb_names[3] = {"r", "g", "b"};

static void read_palette(const oclua_fields *cf, colors *c) {
  lua_State *L = cf->L;
  if (oclua_field_push(cf, "palette") == LUA_TNIL)
    oclua_field_missing(cf, "palette", "an array of {value, {r, g, b}}");
  const char *label = lua_pushfstring(L, "%spalette", cf->prefix);
  c->stops = oclua_read_palette(L, -2, cf->fname, label, &c->nstops);
}

/* Reads the optional `colors` field of f, leaving what it needs on the
** stack. */
static void read_colors(const oclua_fields *f, colors *c) {
  static const char *const known[] = {"field",   "palette",       "blend",
                                      "texture", "texture_scale", NULL};
  lua_State *L = f->L;
  oclua_fields cf;
  int t = oclua_field_push(f, "colors");
  c->kind = COLORS_NONE;
  if (t == LUA_TNIL) {
    lua_pop(L, 1);
    return;
  }
  if (t == LUA_TFUNCTION) {
    c->kind = COLORS_FUNCTION;
    c->idx = lua_gettop(L);
    return;
  }
  if (t != LUA_TTABLE)
    oclua_field_error(f, "colors", -1,
                      "must be a function or a table {field =, palette =}");
  oclua_fields_open(&cf, L, -1, f->fname, "colors.", known, 0);
  /* `field` first: once read, the node stays on the stack whatever the
  ** table's __index does when the other fields are read */
  if (oclua_field_push(&cf, "field") == LUA_TNIL) {
    lua_pop(L, 1);
    if (oclua_field_push(&cf, "blend") != LUA_TNIL) { /* by material */
      c->kind = COLORS_BLEND;
      c->idx = lua_gettop(L);
      c->nblend =
          oclua_read_blend(L, c->idx, f->fname, "colors.blend", &c->blend);
      c->texture = oclua_field_optnumber(&cf, "texture", OCLUA_FINITE, 0.3);
      if (!(c->texture >= 0 && c->texture <= 1))
        oclua_error(L, f->fname, "'colors.texture' must be in [0, 1] (got %f)",
                    (LUAI_UACNUMBER)c->texture);
      c->texture_scale =
          oclua_field_optnumber(&cf, "texture_scale", OCLUA_POSITIVE, 8);
      return;
    }
    lua_pop(L, 1);
    oclua_field_missing(&cf, "field", "an outcrop node");
  }
  if (oclua_testnode(L, -1) == NULL)
    oclua_field_error(&cf, "field", -1, "must be an outcrop node");
  int node = lua_gettop(L);
  if (oclua_field_push(&cf, "texture") != LUA_TNIL ||
      oclua_field_push(&cf, "texture_scale") != LUA_TNIL)
    oclua_error(L, f->fname, "'colors.texture' goes with 'colors.blend'");
  lua_settop(L, node);
  c->kind = COLORS_FIELD;
  c->idx = node;
  read_palette(&cf, c);
}

/* Calls the function at fn for every vertex. The function may do
** anything, closing this very mesh included: the caller has pinned it, so
** a close takes effect when the call returns. The colours gather in a
** Lua-owned buffer, so an error raised in the function leaks nothing. */
static void color_by_function(lua_State *L, oclua_mesh *u, int fn,
                              const char *fname) {
  oc_error err = {OC_OK, ""};
  size_t nv = oc_mesh_vertex_count(u->mesh);
  float *rgb;
  if (nv > ((size_t)-1) / (3 * sizeof *rgb) - 1)
    oclua_error(L, fname, "too many vertices to colour (%I)", (LUAI_UACINT)nv);
  rgb = lua_newuserdatauv(L, (nv ? nv : 1) * 3 * sizeof *rgb, 0);
  luaL_checkstack(L, 8, NULL);
  for (size_t i = 0; i < nv; i++) {
    const float *p, *n;
    p = oc_mesh_positions(u->mesh) + 3 * i;
    n = oc_mesh_normals(u->mesh) + 3 * i;
    lua_pushvalue(L, fn);
    for (int k = 0; k < 3; k++)
      lua_pushnumber(L, p[k]);
    for (int k = 0; k < 3; k++)
      lua_pushnumber(L, n[k]);
    lua_call(L, 6, 3);
    for (int k = 0; k < 3; k++) {
      int idx = k - 3;
      double x = lua_tonumber(L, idx);
      if (lua_type(L, idx) != LUA_TNUMBER || !(x >= 0 && x <= 1))
        oclua_error(L, fname,
                    "the colors function must return r, g, b in [0, 1] "
                    "(got %s = %s at vertex %I)",
                    rgb_names[k], oclua_got(L, idx), (LUAI_UACINT)(i + 1));
      rgb[3 * i + (size_t)k] = (float)x;
    }
    lua_pop(L, 3);
  }
  if (oc_mesh_set_colors(u->mesh, rgb, &err) != OC_OK)
    oclua_liberror(L, fname, &err);
  lua_pop(L, 1);
}

static void apply_colors(lua_State *L, oclua_mesh *u, const colors *c,
                         const char *fname) {
  oc_error err = {OC_OK, ""};
  if (c->kind == COLORS_FUNCTION) {
    color_by_function(L, u, c->idx, fname);
  } else if (c->kind == COLORS_FIELD) {
    const oc_program *prog = oclua_program(L, c->idx, fname);
    if (oc_mesh_color_by_field(u->mesh, prog, c->stops, c->nstops, &err) !=
        OC_OK)
      oclua_liberror(L, fname, &err);
  } else if (c->kind == COLORS_BLEND) {
    const oc_program *const *p = oclua_blend_programs(
        L, c->idx, c->nblend, fname, oclua_threshold(L, fname));
    if (oc_mesh_color_by_blend(u->mesh, p, c->blend, c->nblend, c->texture,
                               c->texture_scale, &err) != OC_OK)
      oclua_liberror(L, fname, &err);
  }
}

/* ---- methods --------------------------------------------------------- */

static int mesh_write(lua_State *L) {
  static const char *const known[] = {"colors", NULL};
  const char *fname = "mesh:write";
  checkmesh(L, fname, 0);
  oc_error err = {OC_OK, ""};
  colors c = {COLORS_NONE, 0, NULL, 0, NULL, 0, 0, 0};
  if (lua_type(L, 2) != LUA_TSTRING)
    oclua_error(L, fname, "the path must be a string (got %s)",
                oclua_got(L, 2));
  oclua_checkargs(L, 3, fname, "(path [, {colors = ...}])");
  lua_settop(L, 3);
  oclua_mesh *u = checkmesh(L, fname, 1);
  if (!lua_isnil(L, 3)) {
    oclua_fields f;
    oclua_fields_open(&f, L, 3, fname, NULL, known, 0);
    read_colors(&f, &c);
  }
  apply_colors(L, u, &c, fname);
  /* The same pairs as images, set anew for each write (a mesh may be
  ** written again after a --set changes). */
  const char *kv[2 * OCLUA_PROVENANCE_PAIRS];
  oclua_push_provenance(L, kv);
  for (int i = 0; i < OCLUA_PROVENANCE_PAIRS; i++)
    if (oc_mesh_set_meta(u->mesh, kv[2 * i], kv[2 * i + 1], &err) != OC_OK)
      oclua_liberror(L, fname, &err);
  lua_pop(L, OCLUA_PROVENANCE_PAIRS);
  /* resolved after the colour callbacks, which may move folders */
  oclua_target t;
  int e = oclua_output_target(L, fname, lua_tostring(L, 2), OCLUA_TARGET_CREATE,
                              &t);
  if (e) return oclua_output_fail(L, &t, strerror(e));
  int rc = oc_mesh_write_at(u->mesh, t.dir, t.name, &err);
  oclua_target_close(L, &t);
  if (rc != OC_OK) {
    /* A file that cannot be written is an expected failure, as io.open. */
    if (err.code == OC_EIO)
      return oclua_output_fail(L, &t,
                               err.msg[0] ? err.msg : "cannot write the mesh");
    oclua_liberror(L, fname, &err);
  }
  lua_pushboolean(L, 1);
  return 1;
}

static int mesh_stats(lua_State *L) {
  oc_mesh_stats st;
  oclua_checkargs(L, 1, "mesh:stats", "()");
  oc_mesh_get_stats(checkmesh(L, "mesh:stats", 0)->mesh, &st);
  lua_createtable(L, 0, 5);
  lua_pushinteger(L, (lua_Integer)st.vertices);
  lua_setfield(L, -2, "vertices");
  lua_pushinteger(L, (lua_Integer)st.triangles);
  lua_setfield(L, -2, "triangles");
  lua_pushinteger(L, (lua_Integer)st.field_calls);
  lua_setfield(L, -2, "field_calls");
  lua_pushinteger(L, (lua_Integer)st.cells_visited);
  lua_setfield(L, -2, "cells_visited");
  lua_pushnumber(L, st.seconds);
  lua_setfield(L, -2, "seconds");
  return 1;
}

static int mesh_counts(lua_State *L) {
  const oc_mesh *m;
  oclua_checkargs(L, 1, "mesh:counts", "()");
  m = checkmesh(L, "mesh:counts", 0)->mesh;
  lua_pushinteger(L, (lua_Integer)oc_mesh_vertex_count(m));
  lua_pushinteger(L, (lua_Integer)oc_mesh_triangle_count(m));
  return 2;
}

/* A C array owned by a Lua userdata: freed by its __gc, so that an
** error raised while it is held leaks nothing. */
#define SIZES_BOX "outcrop.mesh_sizes"

static int sizes_gc(lua_State *L) {
  size_t **box = luaL_checkudata(L, 1, SIZES_BOX);
  free(*box);
  *box = NULL;
  return 0;
}

/* The vertex count of each connected component, in order of each
** component's lowest vertex index. */
static int mesh_components(lua_State *L) {
  const char *fname = "mesh:components";
  oc_error err = {OC_OK, ""};
  size_t n;
  oclua_checkargs(L, 1, fname, "()");
  const oc_mesh *m = checkmesh(L, fname, 0)->mesh;
  size_t **box = lua_newuserdatauv(L, sizeof *box, 0);
  *box = NULL;
  luaL_setmetatable(L, SIZES_BOX);
  if (oc_mesh_components(m, box, &n, &err) != OC_OK)
    oclua_liberror(L, fname, &err);
  if (n > (size_t)INT_MAX)
    oclua_error(L, fname, "too many components (%I)", (LUAI_UACINT)n);
  lua_createtable(L, (int)n, 0);
  for (size_t i = 0; i < n; i++) {
    lua_pushinteger(L, (lua_Integer)(*box)[i]);
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
  free(*box);
  *box = NULL;
  return 1;
}

/* The 1-based index at argument 2, checked against 1..n; `what` names
** the item, `whats` its plural. */
static size_t checkindex(lua_State *L, const char *fname, const char *what,
                         const char *whats, size_t n) {
  int isint;
  lua_Integer i = lua_tointegerx(L, 2, &isint);
  oclua_checkargs(L, 2, fname, "(i)");
  if (n == 0)
    oclua_error(L, fname, "the mesh has no %s (got %s)", whats,
                oclua_got(L, 2));
  if (lua_type(L, 2) != LUA_TNUMBER || !isint || i < 1 ||
      (lua_Unsigned)i > (lua_Unsigned)n)
    oclua_error(L, fname, "the %s index must be an integer in 1..%I (got %s)",
                what, (LUAI_UACINT)n, oclua_got(L, 2));
  return (size_t)(i - 1);
}

static int mesh_vertex(lua_State *L) {
  const char *fname = "mesh:vertex";
  const oc_mesh *m = checkmesh(L, fname, 0)->mesh;
  size_t i =
      checkindex(L, fname, "vertex", "vertices", oc_mesh_vertex_count(m));
  const float *p = oc_mesh_positions(m) + 3 * i;
  const float *n = oc_mesh_normals(m) + 3 * i;
  for (int k = 0; k < 3; k++)
    lua_pushnumber(L, p[k]);
  for (int k = 0; k < 3; k++)
    lua_pushnumber(L, n[k]);
  return 6;
}

static int mesh_triangle(lua_State *L) {
  const char *fname = "mesh:triangle";
  const oc_mesh *m = checkmesh(L, fname, 0)->mesh;
  size_t i =
      checkindex(L, fname, "triangle", "triangles", oc_mesh_triangle_count(m));
  const uint32_t *t = oc_mesh_indices(m) + 3 * i;
  for (int k = 0; k < 3; k++)
    lua_pushinteger(L, (lua_Integer)t[k] + 1);
  return 3;
}

static int mesh_gc(lua_State *L) {
  oclua_handle_close(luaL_checkudata(L, 1, OCLUA_MESH));
  return 0;
}

static int mesh_tostring(lua_State *L) {
  oclua_mesh *u = luaL_checkudata(L, 1, OCLUA_MESH);
  if (u->mesh == NULL || u->h.closed)
    lua_pushliteral(L, OCLUA_MESH ": (closed)");
  else
    lua_pushfstring(L, OCLUA_MESH ": %I vertices, %I triangles",
                    (LUAI_UACINT)oc_mesh_vertex_count(u->mesh),
                    (LUAI_UACINT)oc_mesh_triangle_count(u->mesh));
  return 1;
}

/* ---- outcrop.polygonize ---------------------------------------------- */

static int field_resolution(const oclua_fields *f, int res[3]) {
  lua_State *L = f->L;
  double r[3];
  const char *what = lua_pushfstring(
      L, "must be {nx, ny, nz} with integers in 1..%d", MAX_CELLS);
  int given = oclua_field_numbers(f, "resolution", 3, r, what);
  for (int k = 0; given && k < 3; k++) {
    if (r[k] != floor(r[k]) || r[k] < 1 || r[k] > MAX_CELLS) {
      if (r[k] == floor(r[k]) && fabs(r[k]) < 1e18)
        lua_pushinteger(L, (lua_Integer)r[k]);
      else
        lua_pushnumber(L, r[k]);
      oclua_error(L, f->fname, "'resolution' %s (item %d is %s)", what, k + 1,
                  oclua_got(L, -1));
    }
    res[k] = (int)r[k];
  }
  lua_pop(L, 1);
  return given;
}

static int l_polygonize(lua_State *L) {
  static const char *const known[] = {
      "box",       "cell",   "resolution",    "threshold",     "open", "steps",
      "full_grid", "colors", "max_triangles", "min_component", NULL};
  const char *fname = "outcrop.polygonize";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_polygonize_params pp;
  oclua_progress pl;
  colors c;
  double box[6], cell, t;
  int res[3] = {0, 0, 0}, hasbox, hasres, open, steps, full_grid;
  oclua_checkargs(L, 2, fname,
                  "(node, {box =, cell = or resolution =, threshold =, "
                  "open =, steps =, full_grid =, colors =, "
                  "max_triangles =, min_component =})");
  oclua_checknode(L, 1, fname, "argument #1");
  lua_settop(L, 2);
  if (lua_isnil(L, 2)) {
    lua_newtable(L);
    lua_replace(L, 2);
  }
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  hasbox = oclua_field_numbers(&f, "box", 6, box,
                               "must be {x0, y0, z0, x1, y1, z1}");
  cell = oclua_field_optnumber(&f, "cell", OCLUA_POSITIVE, 0);
  hasres = field_resolution(&f, res);
  if (cell > 0 && hasres)
    oclua_error(L, fname, "give either 'cell' or 'resolution', not both");
  t = oclua_field_optnumber(&f, "threshold", OCLUA_POSITIVE, 0);
  if (t == 0) t = oclua_threshold(L, fname);
  open = oclua_field_optbool(&f, "open", 0);
  steps = (int)oclua_field_optint(&f, "steps", 1, MAX_STEPS, DEFAULT_STEPS);
  full_grid = oclua_field_optbool(&f, "full_grid", 0);
  lua_Integer max_tri =
      oclua_field_optint(&f, "max_triangles", 1, (lua_Integer)1 << 40,
                         OC_POLYGONIZE_MAX_TRIANGLES);
  /* above 2^32 vertices nothing is kept anyway (indices are 32-bit) */
  lua_Integer min_comp =
      oclua_field_optint(&f, "min_component", 0, (lua_Integer)1 << 40, 0);
  read_colors(&f, &c);

  const oc_program *prog = oclua_program_at(L, 1, fname, t);
  if (!hasbox) {
    oc_aabb b;
    if (oc_polygonize_default_box(prog, &b, &err))
      oclua_liberror(L, fname, &err);
    box[0] = b.lo.x, box[1] = b.lo.y, box[2] = b.lo.z;
    box[3] = b.hi.x, box[4] = b.hi.y, box[5] = b.hi.z;
  }
  for (int k = 0; k < 3; k++)
    if (!(box[k] < box[k + 3]))
      oclua_error(L, fname,
                  "'box' = {x0, y0, z0, x1, y1, z1} needs x0 < x1, y0 < y1 "
                  "and z0 < z1 (got {%f, %f, %f, %f, %f, %f})%s",
                  box[0], box[1], box[2], box[3], box[4], box[5],
                  hasbox ? "" : " (from the node's bounds)");
  /* A cell too small for the box is the lib's to refuse: it knows its
  ** grid limits. */
  if (!hasres && cell == 0)
    cell = oc_polygonize_default_cell(
        (oc_aabb){{box[0], box[1], box[2]}, {box[3], box[4], box[5]}});

  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{box[0], box[1], box[2]}, {box[3], box[4], box[5]}};
  pp.cell = hasres ? 0 : cell;
  pp.nx = res[0], pp.ny = res[1], pp.nz = res[2];
  pp.threshold = t;
  pp.open = open;
  pp.steps = steps;
  pp.full_grid = full_grid;
  pp.max_triangles = (size_t)max_tri;
  pp.min_component = (size_t)min_comp;
  char warning[300];
  pp.warning = warning;
  pp.warning_size = sizeof warning;
  pp.progress = oclua_progress_start(L, &pl, fname);
  /* The userdata first, so that nothing can leak once the mesh exists. */
  oclua_mesh *u = oclua_newmesh(L);
  int midx = lua_gettop(L);
  u->mesh = oc_polygonize(prog, &pp, &err);
  oclua_progress_end(&pl);
  if (u->mesh == NULL && err.code == OC_ECANCEL)
    return luaL_error(L, "interrupted");
  if (u->mesh == NULL) oclua_liberror(L, fname, &err);
  if (warning[0]) oclua_warn(L, fname, "%s", warning);
  apply_colors(L, u, &c, fname);
  lua_pushvalue(L, midx);
  return 1;
}

static const luaL_Reg mesh_methods[] = {{"write", mesh_write},
                                        {"stats", mesh_stats},
                                        {"counts", mesh_counts},
                                        {"vertex", mesh_vertex},
                                        {"triangle", mesh_triangle},
                                        {"components", mesh_components},
                                        {NULL, NULL}};

static const luaL_Reg mesh_meta[] = {
    {"__gc", mesh_gc},
    {"__close", mesh_gc}, /* `local m <close>` frees the mesh early */
    {"__tostring", mesh_tostring},
    {NULL, NULL}};

static const luaL_Reg mesh_funcs[] = {{"polygonize", l_polygonize},
                                      {NULL, NULL}};

void oclua_open_mesh(lua_State *L) {
  oclua_newmeta(L, OCLUA_MESH, mesh_meta, mesh_methods);
  lua_pop(L, 1);
  luaL_newmetatable(L, SIZES_BOX);
  lua_pushcfunction(L, sizes_gc);
  lua_setfield(L, -2, "__gc");
  lua_pushliteral(L, "locked");
  lua_setfield(L, -2, "__metatable");
  lua_pop(L, 1);
  luaL_setfuncs(L, mesh_funcs, 0);
}
