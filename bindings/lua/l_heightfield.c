/*
** l_heightfield.c — the heightfield userdata and outcrop.heightfield:
** load, fbm, from; methods height, gradient, size, cell, bounds, get,
** min, max, sum, resample, crop, save, clamp, mask, map, and the
** operators + - * (the analysis methods come from
** l_hfanalysis.c and share the metatable).
**
** Sample (i, j), 1-based in Lua, lies at (x0 + (i - 1) cell, y0 + (j - 1)
** cell): i along x, j along y. Files are north up (the image's top row is
** j = ny). Defaults: cell 1, origin {0, 0}; load: scale 1, offset 0 unless
** the file says otherwise (files saved by hf:save do); fbm: octaves 6,
** offset 0, seed the scene seed; from: zrange the node's z bounds,
** threshold outcrop.threshold; from an elevation tree: the grid over its
** terrain box (513 samples along the longer side), f kept where alpha <
** 1/2 unless holes = z.
*/
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "l_elevation.h"
#include "l_field.h"
#include "l_heightfield.h"
#include "l_progress.h"
#include "l_image.h"
#include "l_config.h"
#include "l_provenance.h"

#define MAX_SIDE 65535
#define DEFAULT_OCTAVES 6

static void hf_release(oclua_handle *h) {
  oclua_heightfield *u = (oclua_heightfield *)h;
  oc_heightfield_release(u->hf);
  u->hf = NULL;
}

oclua_heightfield *oclua_newheightfield(lua_State *L) {
  oclua_heightfield *u = lua_newuserdatauv(L, sizeof *u, 0);
  oclua_handle_init(&u->h, "heightfield", hf_release);
  u->hf = NULL;
  luaL_setmetatable(L, OCLUA_HEIGHTFIELD);
  return u;
}

int oclua_isheightfield(lua_State *L, int idx) {
  return luaL_testudata(L, idx, OCLUA_HEIGHTFIELD) != NULL;
}

static oclua_heightfield *checkhf(lua_State *L, int idx, const char *fname) {
  oclua_heightfield *u = luaL_testudata(L, idx, OCLUA_HEIGHTFIELD);
  if (u == NULL)
    oclua_error(L, fname, "expected a heightfield (got %s)", oclua_got(L, idx));
  oclua_handle_check(L, &u->h, fname);
  if (u->hf == NULL) oclua_error(L, fname, "the heightfield is not made");
  return u;
}

oc_heightfield *oclua_checkheightfield(lua_State *L, int idx,
                                       const char *fname) {
  return checkhf(L, idx, fname)->hf;
}

oc_heightfield *oclua_pinheightfield(lua_State *L, int idx, const char *fname) {
  oclua_heightfield *u = checkhf(L, idx, fname);
  oclua_pin(L, idx, &u->h, fname);
  return u->hf;
}

int oclua_sethf(lua_State *L, oclua_heightfield *u, oc_heightfield *hf,
                const oc_error *err, const char *fname) {
  if (hf == NULL) {
    if (err->code == OC_ECANCEL) return luaL_error(L, "interrupted");
    oclua_liberror(L, fname, err);
  }
  u->hf = hf;
  return 1;
}

/* ---- shared field readers --------------------------------------------- */

/* `size` = {nx, ny}, integers in 2..65535; required. */
static void field_size(const oclua_fields *f, int *nx, int *ny) {
  lua_State *L = f->L;
  double s[2];
  const char *what = "must be {nx, ny} with integers in 2..65535";
  if (!oclua_field_numbers(f, "size", 2, s, what))
    oclua_field_missing(f, "size", "{nx, ny} samples");
  for (int k = 0; k < 2; k++)
    if (s[k] != floor(s[k]) || s[k] < 2 || s[k] > MAX_SIDE) {
      if (s[k] == floor(s[k]) && fabs(s[k]) < 1e18)
        lua_pushinteger(L, (lua_Integer)s[k]);
      else
        lua_pushnumber(L, s[k]);
      oclua_error(L, f->fname, "'size' %s (item %d is %s)", what, k + 1,
                  oclua_got(L, -1));
    }
  *nx = (int)s[0];
  *ny = (int)s[1];
}

oc_heightfield_grid oclua_field_grid(const oclua_fields *f) {
  oc_heightfield_grid g;
  double o[2] = {0, 0};
  field_size(f, &g.nx, &g.ny);
  g.cell = oclua_field_optnumber(f, "cell", OCLUA_POSITIVE, 1);
  oclua_field_numbers(f, "origin", 2, o, "must be {x0, y0}");
  g.x0 = o[0];
  g.y0 = o[1];
  return g;
}

/* An optional options table at idx: an empty one when nil or absent. */
static void opt_table(lua_State *L, int idx) {
  if (lua_isnoneornil(L, idx)) {
    lua_settop(L, idx - 1);
    lua_newtable(L);
  }
}

/* A finite number argument; `what` names it. */
static double check_coord(lua_State *L, int idx, const char *fname,
                          const char *what) {
  double v = lua_tonumber(L, idx);
  if (lua_type(L, idx) != LUA_TNUMBER || !isfinite(v))
    oclua_error(L, fname, "%s must be a finite number (got %s)", what,
                oclua_got(L, idx));
  return v;
}

/* ---- outcrop.heightfield.load ----------------------------------------- */

/* Whether the path names a RAW 16-bit file (.r16, .raw): they have no
** signature, so the name tells. */
static int is_raw(const char *path) {
  const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
  if (!dot || (slash && dot < slash)) return 0;
  return !strcasecmp(dot, ".r16") || !strcasecmp(dot, ".raw");
}

static int l_load(lua_State *L) {
  static const char *const known[] = {"cell",  "scale", "offset", "origin",
                                      "range", "size",  NULL};
  const char *fname = "outcrop.heightfield.load";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_heightfield_load_params p;
  double o[2];
  memset(&p, 0, sizeof p);
  if (lua_type(L, 1) != LUA_TSTRING)
    oclua_error(L, fname, "the path must be a string (got %s)",
                oclua_got(L, 1));
  oclua_checkargs(L, 2, fname,
                  "(path [, {cell =, scale =, offset =, origin =, range =, "
                  "size =}])");
  opt_table(L, 2);
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  int raw = is_raw(lua_tostring(L, 1));
  double range[2];
  int hasrange = oclua_field_numbers(&f, "range", 2, range, "must be {lo, hi}");
  int hassize = oclua_field_push(&f, "size") != LUA_TNIL, nx = 0, ny = 0;
  lua_pop(L, 1);
  if ((hasrange || hassize) && !raw)
    oclua_error(L, fname,
                "'range' and 'size' apply to RAW files (.r16, .raw) only");
  if (hassize) field_size(&f, &nx, &ny);
  if (hasrange && !(range[0] <= range[1]))
    oclua_error(L, fname, "'range' = {lo, hi} needs lo <= hi (got {%f, %f})",
                (LUAI_UACNUMBER)range[0], (LUAI_UACNUMBER)range[1]);
  if (oclua_field_push(&f, "cell") != LUA_TNIL)
    p.given |= OC_HEIGHTFIELD_GIVE_CELL;
  lua_pop(L, 1);
  p.cell = oclua_field_optnumber(&f, "cell", OCLUA_POSITIVE, 1);
  if (oclua_field_push(&f, "scale") != LUA_TNIL)
    p.given |= OC_HEIGHTFIELD_GIVE_SCALE;
  lua_pop(L, 1);
  p.scale = oclua_field_optnumber(&f, "scale", OCLUA_NONZERO, 1);
  if (oclua_field_push(&f, "offset") != LUA_TNIL)
    p.given |= OC_HEIGHTFIELD_GIVE_OFFSET;
  lua_pop(L, 1);
  p.offset = oclua_field_optnumber(&f, "offset", OCLUA_FINITE, 0);
  if (oclua_field_numbers(&f, "origin", 2, o, "must be {x0, y0}")) {
    p.given |= OC_HEIGHTFIELD_GIVE_ORIGIN;
    p.x0 = o[0];
    p.y0 = o[1];
  }
  if (hasrange) {
    if (p.given & (OC_HEIGHTFIELD_GIVE_SCALE | OC_HEIGHTFIELD_GIVE_OFFSET))
      oclua_error(L, fname, "give either 'range' or 'scale' and 'offset'");
    p.given |= OC_HEIGHTFIELD_GIVE_SCALE | OC_HEIGHTFIELD_GIVE_OFFSET;
    p.scale = (range[1] - range[0]) / 65535.0;
    p.offset = range[0];
  }
  oclua_progress pl;
  p.progress = oclua_progress_start(L, &pl, fname); /* Ctrl-C while reading */
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_heightfield *hf =
      raw ? oc_heightfield_load_raw(lua_tostring(L, 1), nx, ny, &p, &err)
          : oc_heightfield_load(lua_tostring(L, 1), &p, &err);
  oclua_progress_end(&pl);
  oclua_sethf(L, u, hf, &err, fname);
  /* once the grid is Lua's, so that a raise here leaks nothing */
  oclua_record_input(L, lua_tostring(L, 1), fname);
  return 1;
}

/* ---- outcrop.heightfield.fbm ------------------------------------------ */

static int l_fbm(lua_State *L) {
  static const char *const known[] = {"size",      "cell",       "origin",
                                      "amplitude", "wavelength", "octaves",
                                      "seed",      "offset",     NULL};
  const char *fname = "outcrop.heightfield.fbm";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_noise nz;
  oclua_progress pl;
  oclua_checkargs(L, 1, fname,
                  "{size =, cell =, origin =, amplitude =, wavelength =, "
                  "octaves =, seed =, offset =}");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_heightfield_grid g = oclua_field_grid(&f);
  oclua_field_noise(&f, &nz, NAN, DEFAULT_OCTAVES, 1);
  oc_progress pr = oclua_progress_start(L, &pl, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_heightfield *hf = oc_heightfield_fbm(&g, &nz, pr, &err);
  oclua_progress_end(&pl);
  return oclua_sethf(L, u, hf, &err, fname);
}

/* ---- outcrop.heightfield.from ----------------------------------------- */

/* Calls the function below its nargs arguments (then x, y are pushed)
** and returns the finite elevation it gives for sample (i, j). */
static float call_elevation(lua_State *L, int nargs, double x, double y, int i,
                            int j, const char *fname) {
  lua_pushnumber(L, x);
  lua_pushnumber(L, y);
  lua_call(L, nargs + 2, 1);
  double v = lua_tonumber(L, -1);
  if (lua_type(L, -1) != LUA_TNUMBER || !isfinite(v) || fabs(v) > 3.4e38)
    oclua_error(L, fname,
                "the function must return a finite elevation (got %s at "
                "sample (%d, %d), x = %f, y = %f)",
                oclua_got(L, -1), i + 1, j + 1, (LUAI_UACNUMBER)x,
                (LUAI_UACNUMBER)y);
  lua_pop(L, 1);
  return (float)v;
}

/* Calls fn(x, y) for every sample, rows from j = 1 up, serially. The grid
** is already in its userdata (the only reference: writing is allowed). */
static void from_function(lua_State *L, int fn, oc_heightfield *hf,
                          const char *fname) {
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double x0, y0, cell = oc_heightfield_cell(hf);
  float *z = oc_heightfield_samples_mut(hf);
  oc_heightfield_origin(hf, &x0, &y0);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      lua_pushvalue(L, fn);
      z[(size_t)j * (size_t)nx + (size_t)i] =
          call_elevation(L, 0, x0 + i * cell, y0 + j * cell, i, j, fname);
    }
}

/* outcrop.heightfield.from(e, {size=, cell=, origin=, holes=}) for an
** elevation tree e at 1: f at every sample (one evaluation each), the
** grid covering the tree's terrain box where size/cell/origin are
** missing (oc_elevation_grid); holes = z puts z where alpha < 1/2. */
static int from_tree(lua_State *L, oc_enode *e, const char *fname) {
  static const char *const known[] = {"size", "cell", "origin", "holes", NULL};
  opt_table(L, 2);
  oclua_fields f;
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  int nx = 0, ny = 0;
  if (oclua_field_push(&f, "size") != LUA_TNIL) field_size(&f, &nx, &ny);
  lua_pop(L, 1);
  double cell = oclua_field_optnumber(&f, "cell", OCLUA_POSITIVE, 0), o[2];
  int haso = oclua_field_numbers(&f, "origin", 2, o, "must be {x0, y0}");
  int holes = oclua_field_push(&f, "holes") != LUA_TNIL;
  lua_pop(L, 1);
  double hole = oclua_field_optnumber(&f, "holes", OCLUA_FINITE, 0);
  oc_error err = {OC_OK, ""};
  oc_elevation src;
  oc_heightfield_grid g;
  if (oc_enode_elevation(e, NULL, &src, &err) != OC_OK)
    return oclua_liberror(L, fname, &err);
  if (oc_elevation_grid(&src, nx, ny, cell, haso ? o : NULL, &g, &err)) {
    src.release(src.ud);
    return oclua_liberror(L, fname, &err);
  }
  oclua_progress pl;
  oc_progress pr = oclua_progress_start(L, &pl, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_heightfield *hf =
      oc_heightfield_from_elevation(&src, &g, holes, hole, pr, &err);
  oclua_progress_end(&pl);
  src.release(src.ud);
  return oclua_sethf(L, u, hf, &err, fname);
}

static int l_from(lua_State *L) {
  static const char *const known[] = {"size",   "cell",      "origin",
                                      "zrange", "threshold", NULL};
  const char *fname = "outcrop.heightfield.from";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  double zr[2];
  oclua_checkargs(L, 2, fname,
                  "(function or node, {size =, cell =, origin =, zrange =, "
                  "threshold =})");
  oc_enode *tree = oclua_testenode(L, 1);
  if (tree) return from_tree(L, tree, fname); /* immutable: on the stack */
  int isfn = lua_type(L, 1) == LUA_TFUNCTION;
  if (!isfn && oclua_testnode(L, 1) == NULL)
    oclua_error(L, fname,
                "argument #1 must be a function (x, y) -> z, an outcrop "
                "node or an elevation tree (got %s)",
                oclua_got(L, 1));
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  oc_heightfield_grid g = oclua_field_grid(&f);
  int hasz = oclua_field_numbers(&f, "zrange", 2, zr, "must be {z0, z1}");
  double t = oclua_field_optnumber(&f, "threshold", OCLUA_POSITIVE, 0);
  if (isfn) {
    if (hasz || t != 0)
      oclua_error(L, fname,
                  "'zrange' and 'threshold' apply to nodes, not to functions");
    oclua_heightfield *u = oclua_newheightfield(L);
    int ud = lua_gettop(L);
    u->hf = oc_heightfield_new(g.nx, g.ny, g.cell, g.x0, g.y0, NULL, &err);
    if (u->hf == NULL) oclua_liberror(L, fname, &err);
    from_function(L, 1, u->hf, fname);
    lua_settop(L, ud);
    return 1;
  }
  if (t == 0) t = oclua_threshold(L, fname);
  const oc_program *prog = oclua_program_at(L, 1, fname, t);
  if (!hasz) {
    oc_aabb b = oc_program_bounds(prog);
    zr[0] = b.lo.z;
    zr[1] = b.hi.z;
    if (!isfinite(zr[0]) || !isfinite(zr[1]) || !(zr[0] < zr[1]))
      oclua_error(L, fname,
                  "the node's z bounds are infinite or empty: give 'zrange' "
                  "= {z0, z1}");
  } else if (!(zr[0] < zr[1])) {
    oclua_error(L, fname, "'zrange' = {z0, z1} needs z0 < z1 (got {%f, %f})",
                (LUAI_UACNUMBER)zr[0], (LUAI_UACNUMBER)zr[1]);
  }
  oclua_progress pl;
  oc_progress pr = oclua_progress_start(L, &pl, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_heightfield *hf =
      oc_heightfield_from_program(prog, &g, zr[0], zr[1], t, pr, &err);
  oclua_progress_end(&pl);
  return oclua_sethf(L, u, hf, &err, fname);
}

/* ---- queries ------------------------------------------------------------ */

static int hf_height(lua_State *L) {
  const char *fname = "heightfield:height";
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  oclua_checkargs(L, 3, fname, "(x, y)");
  double x = check_coord(L, 2, fname, "x"), y = check_coord(L, 3, fname, "y");
  lua_pushnumber(L, oc_heightfield_height(hf, x, y, NULL));
  return 1;
}

static int hf_gradient(lua_State *L) {
  const char *fname = "heightfield:gradient";
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  double g[2];
  oclua_checkargs(L, 3, fname, "(x, y)");
  double x = check_coord(L, 2, fname, "x"), y = check_coord(L, 3, fname, "y");
  oc_heightfield_height(hf, x, y, g);
  lua_pushnumber(L, g[0]);
  lua_pushnumber(L, g[1]);
  return 2;
}

static int hf_size(lua_State *L) {
  oc_heightfield *hf = oclua_checkheightfield(L, 1, "heightfield:size");
  oclua_checkargs(L, 1, "heightfield:size", "()");
  lua_pushinteger(L, oc_heightfield_nx(hf));
  lua_pushinteger(L, oc_heightfield_ny(hf));
  return 2;
}

static int hf_cell(lua_State *L) {
  oc_heightfield *hf = oclua_checkheightfield(L, 1, "heightfield:cell");
  oclua_checkargs(L, 1, "heightfield:cell", "()");
  lua_pushnumber(L, oc_heightfield_cell(hf));
  return 1;
}

static int hf_bounds(lua_State *L) {
  oc_heightfield *hf = oclua_checkheightfield(L, 1, "heightfield:bounds");
  double x0, y0, lo, hi, c = oc_heightfield_cell(hf);
  oclua_checkargs(L, 1, "heightfield:bounds", "()");
  oc_heightfield_origin(hf, &x0, &y0);
  oc_heightfield_minmax(hf, &lo, &hi);
  lua_pushnumber(L, x0);
  lua_pushnumber(L, y0);
  lua_pushnumber(L, lo);
  lua_pushnumber(L, x0 + (oc_heightfield_nx(hf) - 1) * c);
  lua_pushnumber(L, y0 + (oc_heightfield_ny(hf) - 1) * c);
  lua_pushnumber(L, hi);
  return 6;
}

static int hf_get(lua_State *L) {
  const char *fname = "heightfield:get";
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  int n[2] = {oc_heightfield_nx(hf), oc_heightfield_ny(hf)};
  lua_Integer ij[2];
  oclua_checkargs(L, 3, fname, "(i, j)");
  for (int k = 0; k < 2; k++) {
    int isint;
    ij[k] = lua_tointegerx(L, 2 + k, &isint);
    if (lua_type(L, 2 + k) != LUA_TNUMBER || !isint || ij[k] < 1 ||
        ij[k] > n[k])
      oclua_error(L, fname, "%s must be an integer in 1..%d (got %s)",
                  k == 0 ? "i" : "j", n[k], oclua_got(L, 2 + k));
  }
  lua_pushnumber(L, oc_heightfield_samples(
                        hf)[(size_t)(ij[1] - 1) * n[0] + (size_t)(ij[0] - 1)]);
  return 1;
}

static int hf_min(lua_State *L) {
  oc_heightfield *hf = oclua_checkheightfield(L, 1, "heightfield:min");
  double lo;
  oclua_checkargs(L, 1, "heightfield:min", "()");
  oc_heightfield_minmax(hf, &lo, NULL);
  lua_pushnumber(L, lo);
  return 1;
}

static int hf_max(lua_State *L) {
  oc_heightfield *hf = oclua_checkheightfield(L, 1, "heightfield:max");
  double hi;
  oclua_checkargs(L, 1, "heightfield:max", "()");
  oc_heightfield_minmax(hf, NULL, &hi);
  lua_pushnumber(L, hi);
  return 1;
}

/* The lib's sum: in index order, in double. */
static int hf_sum(lua_State *L) {
  oc_heightfield *hf = oclua_checkheightfield(L, 1, "heightfield:sum");
  oclua_checkargs(L, 1, "heightfield:sum", "()");
  lua_pushnumber(L, oc_heightfield_sum(hf));
  return 1;
}

/* ---- resample and crop ------------------------------------------------- */

static int hf_resample(lua_State *L) {
  static const char *const known[] = {"cell", "size", NULL};
  const char *fname = "heightfield:resample";
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_heightfield_grid g;
  oclua_progress pl;
  oclua_checkargs(L, 2, fname, "{cell = or size =}");
  hf = oclua_pinheightfield(L, 1, fname);
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  int hassize = oclua_field_push(&f, "size") != LUA_TNIL;
  lua_pop(L, 1);
  double cell = oclua_field_optnumber(&f, "cell", OCLUA_POSITIVE, 0);
  int nx = 0, ny = 0;
  if (hassize && cell > 0)
    nx = ny = -1; /* both: the lib's to refuse */
  else if (hassize)
    field_size(&f, &nx, &ny);
  if (oc_heightfield_resample_grid(hf, cell, nx, ny, &g, &err))
    oclua_liberror(L, fname, &err);
  oc_progress pr = oclua_progress_start(L, &pl, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_heightfield *out = oc_heightfield_resample(hf, &g, pr, &err);
  oclua_progress_end(&pl);
  return oclua_sethf(L, u, out, &err, fname);
}

/* crop{i0, j0, i1, j1}: 1-based inclusive sample indices; or
** crop{box = {x0, y0, x1, y1}}: the samples lying in the box. */
static int hf_crop(lua_State *L) {
  static const char *const known[] = {"box", NULL};
  const char *fname = "heightfield:crop";
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf), ij[4];
  double box[4];
  oclua_checkargs(L, 2, fname, "{i0, j0, i1, j1} or {box = {x0, y0, x1, y1}}");
  hf = oclua_pinheightfield(L, 1, fname);
  oclua_fields_open(&f, L, 2, fname, NULL, known, 1);
  int hasbox =
      oclua_field_numbers(&f, "box", 4, box, "must be {x0, y0, x1, y1}");
  if (hasbox == (f.narray != 0) || (!hasbox && f.narray != 4))
    oclua_error(L, fname,
                "give the sample range {i0, j0, i1, j1} (1-based, inclusive) "
                "or box = {x0, y0, x1, y1}");
  if (hasbox) {
    if (oc_heightfield_crop_range(hf, box[0], box[1], box[2], box[3], ij, &err))
      oclua_liberror(L, fname, &err);
  } else {
    for (int k = 0; k < 4; k++) {
      int isint, lim = k % 2 == 0 ? nx : ny;
      lua_geti(L, 2, k + 1);
      lua_Integer v = lua_tointegerx(L, -1, &isint);
      if (lua_type(L, -1) != LUA_TNUMBER || !isint || v < 1 || v > lim)
        oclua_error(L, fname,
                    "item %d (%s) must be an integer in 1..%d (got %s)", k + 1,
                    (const char *[]){"i0", "j0", "i1", "j1"}[k], lim,
                    oclua_got(L, -1));
      ij[k] = (int)v - 1;
      lua_pop(L, 1);
    }
  }
  oclua_heightfield *u = oclua_newheightfield(L);
  return oclua_sethf(L, u,
                     oc_heightfield_crop(hf, ij[0], ij[1], ij[2], ij[3], &err),
                     &err, fname);
}

/* ---- save -------------------------------------------------------------- */

/* The provenance pairs of l_provenance.h, gathered on a scratch image
** (oclua_stamp_provenance works on images) kept in a userdata on the
** stack, so the strings live until the write is over. */
static const char **provenance(lua_State *L, size_t *n) {
  oc_error err = {OC_OK, ""};
  oclua_image *scratch = oclua_newimage(L);
  scratch->img = oc_image_new(1, 1, 1, &err);
  if (scratch->img == NULL) oclua_liberror(L, "heightfield:save", &err);
  oclua_stamp_provenance(L, scratch->img);
  *n = oc_image_meta_count(scratch->img);
  const char **meta = lua_newuserdatauv(L, (2 * *n + 1) * sizeof *meta, 0);
  for (size_t i = 0; i < *n; i++) {
    meta[2 * i] = oc_image_meta_key(scratch->img, i);
    meta[2 * i + 1] = oc_image_meta_value(scratch->img, i);
  }
  return meta;
}

static int hf_save(lua_State *L) {
  static const char *const known[] = {"bits",    "scale", "offset",
                                      "palette", "range", NULL};
  const char *fname = "heightfield:save";
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_heightfield_save_params p;
  double used[2];
  memset(&p, 0, sizeof p);
  if (lua_type(L, 2) != LUA_TSTRING)
    oclua_error(L, fname, "the path must be a string (got %s)",
                oclua_got(L, 2));
  oclua_checkargs(L, 3, fname,
                  "(path [, {bits =, scale =, offset =, palette =}])");
  opt_table(L, 3);
  hf = oclua_pinheightfield(L, 1, fname);
  oclua_fields_open(&f, L, 3, fname, NULL, known, 0);
  int pt = oclua_field_push(&f, "palette");
  if (pt == LUA_TBOOLEAN && lua_toboolean(L, -1)) {
    /* the default: dark blue-green lows to pale highs over the grid */
    static const double ramp[5][4] = {{0, 0.10, 0.20, 0.35},
                                      {0.25, 0.15, 0.45, 0.45},
                                      {0.5, 0.55, 0.65, 0.30},
                                      {0.75, 0.75, 0.55, 0.30},
                                      {1, 0.97, 0.95, 0.90}};
    double lo, hi;
    oc_heightfield_minmax(hf, &lo, &hi);
    double *st = lua_newuserdatauv(L, sizeof ramp, 0);
    for (int k = 0; k < 5; k++) {
      st[4 * k] = lo + ramp[k][0] * (hi - lo);
      for (int c = 1; c < 4; c++)
        st[4 * k + c] = ramp[k][c];
    }
    p.stops = st;
    p.nstops = 5;
  } else if (pt != LUA_TNIL && pt != LUA_TBOOLEAN) {
    p.stops = oclua_read_palette(L, -1, fname, "palette", &p.nstops);
  } else if (pt == LUA_TBOOLEAN) {
    /* palette = false: the elevations, as without it */
  }
  p.bits = (int)oclua_field_optint(&f, "bits", 8, 32, 0);
  p.fixed = oclua_field_push(&f, "scale") != LUA_TNIL;
  p.fixed |= oclua_field_push(&f, "offset") != LUA_TNIL;
  lua_pop(L, 2);
  p.scale = oclua_field_optnumber(&f, "scale", OCLUA_POSITIVE, 1);
  p.offset = oclua_field_optnumber(&f, "offset", OCLUA_FINITE, 0);
  double range[2];
  if (oclua_field_numbers(&f, "range", 2, range, "must be {lo, hi}")) {
    if (p.fixed)
      oclua_error(L, fname, "give either 'range' or 'scale' and 'offset'");
    if (!(range[0] < range[1]))
      oclua_error(L, fname, "'range' = {lo, hi} needs lo < hi (got {%f, %f})",
                  (LUAI_UACNUMBER)range[0], (LUAI_UACNUMBER)range[1]);
    p.fixed = 1;
    p.scale = (range[1] - range[0]) / (p.bits == 8 ? 255.0 : 65535.0);
    p.offset = range[0];
  }
  p.meta = provenance(L, &p.nmeta);
  oclua_target t;
  int e = oclua_output_target(L, fname, lua_tostring(L, 2), OCLUA_TARGET_CREATE,
                              &t);
  if (e) return oclua_output_fail(L, &t, strerror(e));
  int rc = oc_heightfield_save_at(hf, t.dir, t.name, &p, used, &err);
  oclua_target_close(L, &t);
  if (rc != OC_OK) {
    /* A file that cannot be written is an expected failure, as io.open. */
    if (err.code == OC_EIO)
      return oclua_output_fail(
          L, &t, err.msg[0] ? err.msg : "cannot write the heightfield");
    oclua_liberror(L, fname, &err);
  }
  /* scale, offset, and the range the counts span (what a RAW file,
  ** which keeps none, needs to be read back) */
  lua_pushnumber(L, used[0]);
  lua_pushnumber(L, used[1]);
  const char *dot = strrchr(lua_tostring(L, 2), '.');
  int integer = p.bits == 8 || p.bits == 16 ||
                (dot && (!strcasecmp(dot, ".png") || is_raw(dot)));
  if (p.nstops > 0 || !integer) return 2;
  lua_pushnumber(L, used[1]);
  lua_pushnumber(L, used[1] + used[0] * (p.bits == 8 ? 255.0 : 65535.0));
  return 4;
}

/* ---- arithmetic, clamp, mask, map --------------------------------------- */

/* hf op hf2, hf op k, k op hf: a new grid. */
static int hf_arith(lua_State *L, oc_heightfield_op op, const char *fname) {
  int a = oclua_isheightfield(L, 1), b = oclua_isheightfield(L, 2);
  oc_error err = {OC_OK, ""};
  for (int k = 1; k <= 2; k++)
    if (!oclua_isheightfield(L, k) && lua_type(L, k) != LUA_TNUMBER)
      oclua_error(L, fname,
                  "operand %d must be a heightfield or a number (got %s)", k,
                  oclua_got(L, k));
  /* pinned: making the result may run finalizers that close them */
  oc_heightfield *ha = a ? oclua_pinheightfield(L, 1, fname) : NULL;
  oc_heightfield *hb = b ? oclua_pinheightfield(L, 2, fname) : NULL;
  double k = a && b ? 0 : check_coord(L, a ? 2 : 1, fname, "the number");
  if (!a && op == OC_HEIGHTFIELD_SUB) op = OC_HEIGHTFIELD_RSUB;
  oclua_heightfield *u = oclua_newheightfield(L);
  oc_heightfield *out = a && b
                            ? oc_heightfield_combine(ha, hb, op, &err)
                            : oc_heightfield_scalar(a ? ha : hb, k, op, &err);
  return oclua_sethf(L, u, out, &err, fname);
}

static int hf_add(lua_State *L) {
  return hf_arith(L, OC_HEIGHTFIELD_ADD, "heightfield +");
}
static int hf_sub(lua_State *L) {
  return hf_arith(L, OC_HEIGHTFIELD_SUB, "heightfield -");
}
static int hf_mul(lua_State *L) {
  return hf_arith(L, OC_HEIGHTFIELD_MUL, "heightfield *");
}
static int hf_unm(lua_State *L) {
  const char *fname = "heightfield unary -";
  oc_error err = {OC_OK, ""};
  oc_heightfield *hf = oclua_pinheightfield(L, 1, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  return oclua_sethf(L, u,
                     oc_heightfield_scalar(hf, -1, OC_HEIGHTFIELD_MUL, &err),
                     &err, fname);
}

/* clamp(lo, hi) or clamp{lo =, hi =}: either bound may be left out
** (nil) in the table form. */
static int hf_clamp(lua_State *L) {
  static const char *const known[] = {"lo", "hi", NULL};
  const char *fname = "heightfield:clamp";
  oc_error err = {OC_OK, ""};
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  double lo, hi;
  if (lua_type(L, 2) == LUA_TTABLE) {
    oclua_fields f;
    oclua_checkargs(L, 2, fname, "(lo, hi) or {lo =, hi =}");
    oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
    lo = oclua_field_optnumber(&f, "lo", OCLUA_FINITE, -HUGE_VAL);
    hi = oclua_field_optnumber(&f, "hi", OCLUA_FINITE, HUGE_VAL);
  } else {
    oclua_checkargs(L, 3, fname, "(lo, hi) or {lo =, hi =}");
    lo = check_coord(L, 2, fname, "lo");
    hi = check_coord(L, 3, fname, "hi");
  }
  if (!(lo <= hi))
    oclua_error(L, fname, "needs lo <= hi (got %f, %f)", (LUAI_UACNUMBER)lo,
                (LUAI_UACNUMBER)hi);
  hf = oclua_pinheightfield(L, 1, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  return oclua_sethf(L, u, oc_heightfield_clamp(hf, lo, hi, &err), &err, fname);
}

static int hf_mask(lua_State *L) {
  static const char *const known[] = {"above", "below", "falloff", NULL};
  const char *fname = "heightfield:mask";
  oc_error err = {OC_OK, ""};
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  oclua_fields f;
  oc_heightfield_mask_params mp;
  memset(&mp, 0, sizeof mp);
  oclua_checkargs(L, 2, fname, "{above =, below =, falloff =}");
  oclua_fields_open(&f, L, 2, fname, NULL, known, 0);
  mp.has_above = oclua_field_push(&f, "above") != LUA_TNIL;
  mp.has_below = oclua_field_push(&f, "below") != LUA_TNIL;
  lua_pop(L, 2);
  mp.above = oclua_field_optnumber(&f, "above", OCLUA_FINITE, 0);
  mp.below = oclua_field_optnumber(&f, "below", OCLUA_FINITE, 0);
  mp.falloff = oclua_field_optnumber(&f, "falloff", OCLUA_FINITE, 0);
  if (mp.falloff < 0)
    oclua_error(L, fname, "'falloff' must be >= 0 (got %f)",
                (LUAI_UACNUMBER)mp.falloff);
  if (!mp.has_above && !mp.has_below)
    oclua_error(L, fname, "give 'above', 'below' or both");
  hf = oclua_pinheightfield(L, 1, fname);
  oclua_heightfield *u = oclua_newheightfield(L);
  return oclua_sethf(L, u, oc_heightfield_mask(hf, &mp, &err), &err, fname);
}

/* map(fn): fn(z, x, y) for every sample, rows from j = 1 up, serially,
** into a new grid. The source is pinned while fn runs (fn may close it
** or drop every reference to it), and read through the pin. */
static int hf_map(lua_State *L) {
  const char *fname = "heightfield:map";
  oc_error err = {OC_OK, ""};
  oc_heightfield *hf = oclua_checkheightfield(L, 1, fname);
  oclua_checkargs(L, 2, fname, "(function (z, x, y) -> z)");
  if (lua_type(L, 2) != LUA_TFUNCTION)
    oclua_error(L, fname, "argument #1 must be a function (got %s)",
                oclua_got(L, 2));
  hf = oclua_pinheightfield(L, 1, fname);
  int nx = oc_heightfield_nx(hf), ny = oc_heightfield_ny(hf);
  double x0, y0, cell = oc_heightfield_cell(hf);
  oc_heightfield_origin(hf, &x0, &y0);
  oclua_heightfield *u = oclua_newheightfield(L);
  int ud = lua_gettop(L);
  u->hf = oc_heightfield_new(nx, ny, cell, x0, y0, NULL, &err);
  if (u->hf == NULL) oclua_liberror(L, fname, &err);
  const float *zin = oc_heightfield_samples(hf);
  float *z = oc_heightfield_samples_mut(u->hf);
  for (int j = 0; j < ny; j++)
    for (int i = 0; i < nx; i++) {
      size_t k = (size_t)j * (size_t)nx + (size_t)i;
      lua_pushvalue(L, 2);
      lua_pushnumber(L, zin[k]);
      z[k] = call_elevation(L, 1, x0 + i * cell, y0 + j * cell, i, j, fname);
    }
  lua_settop(L, ud);
  return 1;
}

/* ---- metamethods --------------------------------------------------------- */

static int hf_gc(lua_State *L) {
  oclua_handle_close(luaL_checkudata(L, 1, OCLUA_HEIGHTFIELD));
  return 0;
}

static int hf_tostring(lua_State *L) {
  oclua_heightfield *u = luaL_checkudata(L, 1, OCLUA_HEIGHTFIELD);
  if (u->hf == NULL || u->h.closed) {
    lua_pushliteral(L, OCLUA_HEIGHTFIELD ": (closed)");
    return 1;
  }
  double x0, y0, lo, hi;
  char buf[200];
  oc_heightfield_origin(u->hf, &x0, &y0);
  oc_heightfield_minmax(u->hf, &lo, &hi);
  snprintf(buf, sizeof buf,
           OCLUA_HEIGHTFIELD ": %d x %d, cell %g, origin (%g, %g), z %g .. %g",
           oc_heightfield_nx(u->hf), oc_heightfield_ny(u->hf),
           oc_heightfield_cell(u->hf), x0, y0, lo, hi);
  lua_pushstring(L, buf);
  return 1;
}

static const luaL_Reg hf_methods[] = {
    {"height", hf_height}, {"gradient", hf_gradient},
    {"size", hf_size},     {"cell", hf_cell},
    {"bounds", hf_bounds}, {"get", hf_get},
    {"min", hf_min},       {"max", hf_max},
    {"sum", hf_sum},       {"resample", hf_resample},
    {"crop", hf_crop},     {"save", hf_save},
    {"clamp", hf_clamp},   {"mask", hf_mask},
    {"map", hf_map},       {NULL, NULL}};

static const luaL_Reg hf_meta[] = {
    {"__gc", hf_gc},
    {"__close", hf_gc}, /* `local hf <close>` frees the samples early */
    {"__tostring", hf_tostring},
    {"__add", hf_add},
    {"__sub", hf_sub},
    {"__mul", hf_mul},
    {"__unm", hf_unm},
    {NULL, NULL}};

static const luaL_Reg hf_funcs[] = {
    {"load", l_load}, {"fbm", l_fbm}, {"from", l_from}, {NULL, NULL}};

void oclua_open_heightfield(lua_State *L) {
  oclua_newmeta(L, OCLUA_HEIGHTFIELD, hf_meta, hf_methods);
  lua_getfield(L, -1, "__index");
  luaL_setfuncs(L, oclua_heightfield_analysis, 0);
  lua_pop(L, 2);
  luaL_newlib(L, hf_funcs);
  lua_setfield(L, -2, "heightfield");
}
