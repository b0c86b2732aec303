/*
** l_gen_sea.c — sea and river erosion (Paris et al. 2019, section 6.1):
** outcrop.generate.sea{...} and outcrop.generate.river{...}.
**
**   field (both)   | default
**   ---------------+--------------------------------------------------------
**   heightfield    | required: the footprint, slopes, stream power
**   terrain        | outcrop.terrain(heightfield): the tree the rays march
**                  | and the primitives are blended with; false: the
**                  | rays march that default, the primitives come alone
**   geology        | none: resistance 0.5 everywhere
**   seed           | the scene seed
**   radius         | sea: range; river: 1.5 cells (negative point radius)
**   spacing        | radius / 2: Poisson disk radius of the columns
**   beta           | 0.2: e(1, 1), the bite on the hardest rock
**   strength       | sea 4, river 2: energy = -strength e(rho, sigma)
**   cutoff         | 0.05: samples with a smaller e make no primitive
**   steps          | sea 3, river 2: rounds on the updated tree
**
**   sea only       |
**   sea_level      | 0 when the heightfield spans it, else its lowest
**                  | sample plus a quarter of its relief (the lib's
**                  | oc_heightfield_sea_level)
**   range          | 8 (metres): sigma falls off over range from sea level
**   reach          | 2 radius: cliff columns sampled this far from the band
**   rays           | 16: accessibility rays per sample (0: alpha = 1)
**
**   river only     |
**   power          | the 95th percentile of hf:stream_power(): riverbed
**   banks          | 3 (cells): widening of the bed to the banks
**   depth          | 3 radius: bank rays are cast down to this below h
**
** Each returns the node (blend of the terrain and the primitives) and a
** table {columns=, samples=, primitives=}. The shared fields go into the
** lib's oc_gen_erode_params (p.erode), whose checks report what is wrong.
*/
#include "l_field.h"
#include "l_gen.h"
#include "l_heightfield.h"
#include "l_progress.h"

/* A node or nil; false sets *nofalse when nofalse is not NULL. The value
** stays on the stack (an __index may have made it, or a finalizer drop
** it from the table) until the generator has retained the node. */
static oc_node *optnode(oclua_fields *f, const char *name, int *nofalse) {
  oc_node *n = NULL;
  int t = oclua_field_push(f, name);
  if (nofalse && t == LUA_TBOOLEAN && !lua_toboolean(f->L, -1))
    *nofalse = 1;
  else if (t != LUA_TNIL) {
    oclua_node *u = oclua_testnode(f->L, -1);
    if (!u)
      oclua_field_error(f, name, -1,
                        nofalse ? "must be a node or false" : "must be a node");
    n = u->node;
  }
  return n;
}

/* The fields the sea and river share, into the lib's shared struct c
** (its defaults already in it). */
static void read_common(oclua_fields *f, oc_gen_erode_params *c) {
  if (oclua_field_push(f, "heightfield") == LUA_TNIL)
    oclua_field_missing(f, "heightfield", "a heightfield");
  if (!oclua_isheightfield(f->L, -1))
    oclua_field_error(f, "heightfield", -1, "must be a heightfield");
  c->heightfield =
      oclua_pinheightfield(f->L, -1, f->fname); /* value and pin stay */
  c->no_terrain = 0;
  c->terrain = optnode(f, "terrain", &c->no_terrain);
  c->geology = optnode(f, "geology", NULL);
  c->seed = oclua_field_seed(f, "seed");
  c->radius = oclua_field_optnumber(f, "radius", OCLUA_POSITIVE, 0);
  c->spacing = oclua_field_optnumber(f, "spacing", OCLUA_POSITIVE, 0);
  /* beta's range and cutoff's sign are the lib's to check */
  c->beta = oclua_field_optnumber(f, "beta", OCLUA_FINITE, c->beta);
  c->strength =
      oclua_field_optnumber(f, "strength", OCLUA_POSITIVE, c->strength);
  c->cutoff = oclua_field_optnumber(f, "cutoff", OCLUA_FINITE, c->cutoff);
  c->steps = (int)oclua_field_optint(f, "steps", 1, 64, c->steps);
  c->threshold = oclua_threshold(f->L, f->fname);
}

static int finish(lua_State *L, const char *fname, oclua_node *u, oc_node *n,
                  const oc_error *err, const oc_gen_sea_stats *st) {
  if (!n && err->code == OC_ECANCEL) return luaL_error(L, "interrupted");
  oclua_setnode(L, u, n, err, fname);
  lua_createtable(L, 0, 3);
  lua_pushinteger(L, (lua_Integer)st->columns);
  lua_setfield(L, -2, "columns");
  lua_pushinteger(L, (lua_Integer)st->samples);
  lua_setfield(L, -2, "samples");
  lua_pushinteger(L, (lua_Integer)st->primitives);
  lua_setfield(L, -2, "primitives");
  return 2;
}

/* Runs the sea (sea = 1) or river generator on params (whose progress
** field is prog) with progress, and returns finish's results. */
static int run(lua_State *L, const char *fname, int sea, void *params,
               oc_progress *prog) {
  oclua_node *u = oclua_newnode(L);
  oclua_progress pl;
  oc_gen_sea_stats st = {0, 0, 0};
  oc_error err = {OC_OK, ""};
  *prog = oclua_progress_start(L, &pl, fname);
  oc_node *n = sea ? oc_generate_sea(params, &st, &err)
                   : oc_generate_river(params, &st, &err);
  oclua_progress_end(&pl);
  return finish(L, fname, u, n, &err, &st);
}

static int l_sea(lua_State *L) {
  static const char *const known[] = {
      "heightfield", "terrain", "geology",  "seed",   "radius",
      "spacing",     "beta",    "strength", "cutoff", "steps",
      "sea_level",   "range",   "reach",    "rays",   NULL};
  const char *fname = "outcrop.generate.sea";
  oclua_fields f;
  oc_gen_sea_params p;
  oclua_checkargs(L, 1, fname, "{heightfield =, sea_level =, range =, ...}");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_gen_sea_defaults(&p);
  read_common(&f, &p.erode);
  p.sea_level =
      oclua_field_optnumber(&f, "sea_level", OCLUA_FINITE,
                            oc_heightfield_sea_level(p.erode.heightfield));
  p.range = oclua_field_optnumber(&f, "range", OCLUA_POSITIVE, p.range);
  p.reach = oclua_field_optnumber(&f, "reach", OCLUA_POSITIVE, 0);
  p.rays = (int)oclua_field_optint(&f, "rays", 0, 4096, p.rays);
  return run(L, fname, 1, &p, &p.erode.progress);
}

static int l_river(lua_State *L) {
  static const char *const known[] = {
      "heightfield", "terrain", "geology", "seed",  "radius", "spacing", "beta",
      "strength",    "cutoff",  "steps",   "power", "banks",  "depth",   NULL};
  const char *fname = "outcrop.generate.river";
  oclua_fields f;
  oc_gen_river_params p;
  oclua_checkargs(L, 1, fname, "{heightfield =, power =, banks =, ...}");
  oclua_fields_open(&f, L, 1, fname, NULL, known, 0);
  oc_gen_river_defaults(&p);
  read_common(&f, &p.erode);
  p.power = oclua_field_optnumber(&f, "power", OCLUA_POSITIVE, 0);
  p.banks = (int)oclua_field_optint(&f, "banks", 0, 64, p.banks);
  p.depth = oclua_field_optnumber(&f, "depth", OCLUA_POSITIVE, 0);
  return run(L, fname, 0, &p, &p.erode.progress);
}

const luaL_Reg oclua_gen_sea[] = {
    {"sea", l_sea}, {"river", l_river}, {NULL, NULL}};
