/*
** l_gen.c — outcrop.poisson2d and outcrop.poisson3d: maximal Poisson
** disk and sphere sampling, and the point-set userdata.
**
** Both return an array of {x, y} ({x, y, z}) tables, or with flat = true
** a point set (count, dim, get, table; # gives the count) holding the
** coordinates in one C array, for millions of points. `density` (2D) is a
** function (x, y) -> probability in [0, 1], called once per sample of the
** maximal set, serially and in the order of the result, or a heightfield
** whose interpolated value, clamped to [0, 1], is that probability.
*/
#include <limits.h>
#include <math.h>
#include <string.h>

#include "l_gen.h"
#include "l_handle.h"
#include "l_heightfield.h"
#include "l_progress.h"

typedef struct oclua_points {
  oclua_handle h; /* first: pins and closing (l_handle.h) */
  oc_samples *s;  /* NULL while being made, or once freed */
} oclua_points;

static void points_release(oclua_handle *h) {
  oclua_points *u = (oclua_points *)h;
  oc_samples_free(u->s);
  u->s = NULL;
}

/* The point set at 1, open; pinned for the rest of the call when pin is
** set. */
static oclua_points *checkpoints(lua_State *L, const char *fname, int pin) {
  oclua_points *u = luaL_checkudata(L, 1, OCLUA_POINTS);
  oclua_handle_check(L, &u->h, fname);
  if (u->s == NULL) oclua_error(L, fname, "the point set is not made");
  if (pin) oclua_pin(L, 1, &u->h, fname);
  return u;
}

/* ---- density --------------------------------------------------------- */

/* The density, called by the library from this thread. A Lua function
** runs under lua_pcall, so an error cannot jump across the library: its
** error object, or a message about a bad return, waits in slot `err`
** while the library unwinds (the NaN returned makes it stop). */
typedef struct density {
  lua_State *L;
  int fn;             /* stack index of the function, or 0 */
  oc_heightfield *hf; /* or the grid */
  int err;            /* stack index of the error slot */
  int raised;         /* 1: a Lua error; 2: a message for oclua_error */
} density;

static double density_hf(void *ud, double x, double y) {
  const density *D = ud;
  double v = oc_heightfield_height(D->hf, x, y, NULL);
  return v < 0 ? 0 : v > 1 ? 1 : v;
}

static double density_fn(void *ud, double x, double y) {
  density *D = ud;
  lua_State *L = D->L;
  lua_pushvalue(L, D->fn);
  lua_pushnumber(L, x);
  lua_pushnumber(L, y);
  if (lua_pcall(L, 2, 1, 0) != LUA_OK) {
    lua_replace(L, D->err);
    D->raised = 1;
    return NAN;
  }
  double v = lua_tonumber(L, -1);
  if (lua_type(L, -1) != LUA_TNUMBER || !(v >= 0 && v <= 1)) {
    oclua_got(L, -1);
    lua_pushfstring(L,
                    "'density' must return a number in [0, 1] (got %s at "
                    "x = %f, y = %f)",
                    lua_tostring(L, -1), (LUAI_UACNUMBER)x, (LUAI_UACNUMBER)y);
    lua_replace(L, D->err);
    lua_pop(L, 2);
    D->raised = 2;
    return NAN;
  }
  lua_pop(L, 1);
  return v;
}

/* ---- results ----------------------------------------------------------- */

static void push_table(lua_State *L, const oc_samples *s) {
  size_t n = oc_samples_count(s);
  int d = oc_samples_dim(s);
  const double *p = oc_samples_data(s);
  if (n > (size_t)INT_MAX) luaL_error(L, "too many points for a table");
  lua_createtable(L, (int)n, 0);
  for (size_t i = 0; i < n; i++) {
    lua_createtable(L, d, 0);
    for (int k = 0; k < d; k++) {
      lua_pushnumber(L, p[(size_t)d * i + (size_t)k]);
      lua_rawseti(L, -2, k + 1);
    }
    lua_rawseti(L, -2, (lua_Integer)i + 1);
  }
}

static int sample(lua_State *L, int d) {
  static const char *const known2[] = {"box",     "radius", "seed",
                                       "density", "flat",   NULL};
  static const char *const known3[] = {"box", "radius", "seed", "flat", NULL};
  const char *fname = d == 2 ? "outcrop.poisson2d" : "outcrop.poisson3d";
  oclua_fields f;
  oc_error err = {OC_OK, ""};
  oc_poisson_params pp;
  oclua_progress pl;
  density D = {L, 0, NULL, 0, 0};
  double box[6];
  oclua_checkargs(L, 1, fname,
                  d == 2 ? "{box = {x0, y0, x1, y1}, radius =, seed =, "
                           "density =, flat =}"
                         : "{box = {x0, y0, z0, x1, y1, z1}, radius =, "
                           "seed =, flat =}");
  oclua_fields_open(&f, L, 1, fname, NULL, d == 2 ? known2 : known3, 0);
  const char *what =
      d == 2 ? "must be {x0, y0, x1, y1}" : "must be {x0, y0, z0, x1, y1, z1}";
  if (!oclua_field_numbers(&f, "box", 2 * d, box, what))
    oclua_field_missing(
        &f, "box", d == 2 ? "{x0, y0, x1, y1}" : "{x0, y0, z0, x1, y1, z1}");
  memset(&pp, 0, sizeof pp);
  pp.radius = oclua_field_number(&f, "radius", OCLUA_POSITIVE);
  pp.seed = oclua_field_seed(&f, "seed");
  int flat = oclua_field_optbool(&f, "flat", 0);
  if (d == 2) {
    pp.box = (oc_aabb){{box[0], box[1], 0}, {box[2], box[3], 0}};
    int t = oclua_field_push(&f, "density");
    if (t == LUA_TFUNCTION) {
      D.fn = lua_gettop(L);
      pp.density = density_fn;
    } else if (t != LUA_TNIL) {
      if (!oclua_isheightfield(L, -1))
        oclua_field_error(&f, "density", -1,
                          "must be a function (x, y) -> [0, 1] or a "
                          "heightfield");
      D.hf = oclua_pinheightfield(L, -1, fname);
      pp.density = density_hf;
    }
    pp.density_ud = &D;
  } else {
    pp.box = (oc_aabb){{box[0], box[1], box[2]}, {box[3], box[4], box[5]}};
  }
  lua_pushnil(L);
  D.err = lua_gettop(L);
  luaL_checkstack(L, 8, NULL);
  /* The userdata first, so that nothing can leak once the set exists. */
  oclua_points *u = lua_newuserdatauv(L, sizeof *u, 0);
  oclua_handle_init(&u->h, "point set", points_release);
  u->s = NULL;
  luaL_setmetatable(L, OCLUA_POINTS);
  pp.progress = oclua_progress_start(L, &pl, fname);
  u->s = d == 2 ? oc_poisson2d(&pp, &err) : oc_poisson3d(&pp, &err);
  oclua_progress_end(&pl);
  if (u->s == NULL) {
    if (D.raised == 1) {
      lua_pushvalue(L, D.err); /* the function's own error, as raised */
      return lua_error(L);
    }
    if (D.raised == 2)
      return oclua_error(L, fname, "%s", lua_tostring(L, D.err));
    if (err.code == OC_ECANCEL) return luaL_error(L, "interrupted");
    return oclua_liberror(L, fname, &err);
  }
  if (flat) return 1;
  push_table(L, u->s);
  oc_samples_free(u->s); /* the table holds them now */
  u->s = NULL;
  return 1;
}

static int l_poisson2d(lua_State *L) {
  return sample(L, 2);
}
static int l_poisson3d(lua_State *L) {
  return sample(L, 3);
}

/* ---- the point set ------------------------------------------------------ */

static int points_count(lua_State *L) {
  oclua_checkargs(L, 1, "points:count", "()");
  lua_pushinteger(
      L, (lua_Integer)oc_samples_count(checkpoints(L, "points:count", 0)->s));
  return 1;
}

static int points_len(lua_State *L) {
  oclua_points *u = luaL_checkudata(L, 1, OCLUA_POINTS);
  lua_pushinteger(L, u->s && !u->h.closed ? (lua_Integer)oc_samples_count(u->s)
                                          : 0);
  return 1;
}

static int points_dim(lua_State *L) {
  oclua_checkargs(L, 1, "points:dim", "()");
  lua_pushinteger(L, oc_samples_dim(checkpoints(L, "points:dim", 0)->s));
  return 1;
}

static int points_get(lua_State *L) {
  const char *fname = "points:get";
  const oc_samples *s = checkpoints(L, fname, 0)->s;
  size_t n = oc_samples_count(s);
  int isint, d = oc_samples_dim(s);
  lua_Integer i = lua_tointegerx(L, 2, &isint);
  oclua_checkargs(L, 2, fname, "(i)");
  if (lua_type(L, 2) != LUA_TNUMBER || !isint || i < 1 ||
      (lua_Unsigned)i > (lua_Unsigned)n)
    oclua_error(L, fname, "the index must be an integer in 1..%I (got %s)",
                (LUAI_UACINT)n, oclua_got(L, 2));
  const double *p = oc_samples_data(s) + (size_t)d * (size_t)(i - 1);
  for (int k = 0; k < d; k++)
    lua_pushnumber(L, p[k]);
  return d;
}

static int points_table(lua_State *L) {
  oclua_checkargs(L, 1, "points:table", "()");
  push_table(L, checkpoints(L, "points:table", 1)->s);
  return 1;
}

static int points_gc(lua_State *L) {
  oclua_handle_close(luaL_checkudata(L, 1, OCLUA_POINTS));
  return 0;
}

static int points_tostring(lua_State *L) {
  oclua_points *u = luaL_checkudata(L, 1, OCLUA_POINTS);
  if (u->s == NULL || u->h.closed)
    lua_pushliteral(L, OCLUA_POINTS ": (closed)");
  else
    lua_pushfstring(L, OCLUA_POINTS ": %I points in %dD",
                    (LUAI_UACINT)oc_samples_count(u->s), oc_samples_dim(u->s));
  return 1;
}

static const luaL_Reg points_methods[] = {{"count", points_count},
                                          {"dim", points_dim},
                                          {"get", points_get},
                                          {"table", points_table},
                                          {NULL, NULL}};

static const luaL_Reg points_meta[] = {
    {"__gc", points_gc},
    {"__close", points_gc}, /* `local p <close>` frees
                               the points early */
    {"__len", points_len},
    {"__tostring", points_tostring},
    {NULL, NULL}};

static const luaL_Reg sample_funcs[] = {
    {"poisson2d", l_poisson2d}, {"poisson3d", l_poisson3d}, {NULL, NULL}};

void oclua_open_gen(lua_State *L) {
  oclua_newmeta(L, OCLUA_POINTS, points_meta, points_methods);
  lua_pop(L, 1);
  luaL_setfuncs(L, sample_funcs, 0);
  lua_createtable(L, 0, 4);
  luaL_setfuncs(L, oclua_gen_sea, 0);
  luaL_setfuncs(L, oclua_gen_karst, 0);
  luaL_setfuncs(L, oclua_gen_hoodoos, 0);
  lua_setfield(L, -2, "generate");
}
