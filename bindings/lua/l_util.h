/*
** l_util.h — argument checking shared by the Lua binding files.
**
** Every constructor takes one table of named fields. An oclua_fields
** describes such a table while it is being read: opening it rejects
** unknown names, and each getter checks one field's type and range. All
** errors are raised as "file:line: <fname>: <message>", the file and line
** being those of the script that called the binding.
*/
#ifndef L_UTIL_H
#define L_UTIL_H

#include <stdint.h>

#include <lauxlib.h>
#include <lua.h>

#include "oclua.h"
#include "outcrop.h"

/* Registry key of the module table (queries read outcrop.threshold). */
#define OCLUA_MODULE "outcrop.module"

#define OCLUA_DEFAULT_SEED 1

/* Range rules for numbers; every rule also requires a finite value. */
enum { OCLUA_FINITE, OCLUA_POSITIVE, OCLUA_NONZERO };

typedef struct oclua_fields {
  lua_State *L;
  const char *fname;  /* "outcrop.point": the prefix of every message */
  const char *prefix; /* "" or the name of the enclosing field + "." */
  int t;              /* absolute stack index of the table */
  lua_Integer narray; /* length of the array part (0 unless allowed) */
} oclua_fields;

/* Raises "where: fname: message"; `fmt` as for lua_pushfstring. */
int oclua_error(lua_State *L, const char *fname, const char *fmt, ...);
/* "outcrop: warning: file:line: fname: message" on stderr. */
void oclua_warn(lua_State *L, const char *fname, const char *fmt, ...);
/* Raises with a library error message, prefixed with fname. */
int oclua_liberror(lua_State *L, const char *fname, const oc_error *err);
/* Pushes and returns a short description of a value for "(got ...)":
** the number itself, or the type name (__name for userdata). */
const char *oclua_got(lua_State *L, int idx);

/* Checks that `idx` is a table whose keys all appear in `known` (a NULL
** terminated list); with `array` set, keys 1..n are allowed too and must
** form a sequence (their count goes to f->narray). `prefix` names the
** enclosing field for nested tables, or is NULL. */
void oclua_fields_open(oclua_fields *f, lua_State *L, int idx,
                       const char *fname, const char *prefix,
                       const char *const *known, int array);

/* The sole argument of fname: a table of named fields, as
** oclua_fields_open checks it, or nothing (an empty table: all defaults). */
void oclua_fields_open_args(oclua_fields *f, lua_State *L, const char *fname,
                            const char *const *known);

/* Pushes t[name] and returns its type. */
int oclua_field_push(const oclua_fields *f, const char *name);
/* Raises "'name' <what> (got <value at idx>)". */
int oclua_field_error(const oclua_fields *f, const char *name, int idx,
                      const char *what);
int oclua_field_missing(const oclua_fields *f, const char *name,
                        const char *what);

double oclua_field_number(const oclua_fields *f, const char *name, int rule);
/* Reads field `name` as an array of exactly n finite numbers into out;
** returns 0 when the field is absent, raises (with `what`) when malformed. */
int oclua_field_numbers(const oclua_fields *f, const char *name, int n,
                        double *out, const char *what);
double oclua_field_optnumber(const oclua_fields *f, const char *name, int rule,
                             double def);
lua_Integer oclua_field_optint(const oclua_fields *f, const char *name,
                               lua_Integer lo, lua_Integer hi, lua_Integer def);
int oclua_field_optbool(const oclua_fields *f, const char *name, int def);
/* Index of the string value in `options` (NULL terminated), or def when
** the field is absent. */
int oclua_field_optoption(const oclua_fields *f, const char *name,
                          const char *const *options, int def);
/* An integer >= 0; absent: the scene seed. */
uint64_t oclua_field_seed(const oclua_fields *f, const char *name);

/* The noise fields of a table: wavelength (> 0, required), amplitude
** (required when amp is NaN, else amp by default), octaves (1 .. 16,
** `octaves` by default), offset (when `offset`, 0 by default; else 0)
** and seed, read in that order. */
void oclua_field_noise(const oclua_fields *f, oc_noise *nz, double amp,
                       int octaves, int offset);

/* A vector is {x, y, z} or {x = , y = , z = }, with finite numbers. */
oc_vec3 oclua_field_vec(const oclua_fields *f, const char *name);
/* Returns 0 and leaves *v alone when the field is absent. */
int oclua_field_optvec(const oclua_fields *f, const char *name, oc_vec3 *v);
/* Reads the vector at stack index idx; `label` names it in messages
** (elem > 0 appends "[elem]"). */
oc_vec3 oclua_tovec(lua_State *L, int idx, const char *fname, const char *label,
                    lua_Integer elem);

/* An array of {x, y} at stack index idx, n in [lo, hi] entries, into a
** Lua-owned array of 2 n doubles pushed on the stack (raw reads); `label`
** names the field in messages. */
double *oclua_read_xy(lua_State *L, int idx, const char *fname,
                      const char *label, lua_Integer lo, lua_Integer hi,
                      size_t *n);

/* The scene seed: registry OCLUA_SEED when it is an integer >= 0, else 1.
** Notes in OCLUA_STATE that the seed was used, so that a later
** outcrop.configure cannot change it. */
lua_Integer oclua_scene_seed(lua_State *L);

/* Pushes the table OCLUA_STATE (see oclua.h), created when missing. */
void oclua_state(lua_State *L);

/* Raises unless the call has at most `n` arguments. */
void oclua_checkargs(lua_State *L, int n, const char *fname, const char *usage);

/* Pushes {nodes =, primitives =, bytes =}: what :stats() returns for a
** 3D tree and for an elevation tree alike. */
void oclua_pushstats(lua_State *L, size_t nodes, size_t primitives,
                     size_t bytes);

/* Reads the palette at stack index idx (an array of {value, {r, g, b}},
** values ascending, components in [0, 1]) into a Lua-owned array of stops
** (value, r, g, b), pushed on the stack; `label` names the field in the
** messages ("palette", "colors.palette"). At most OCLUA_MAX_STOPS. */
#define OCLUA_MAX_STOPS 65536
const double *oclua_read_palette(lua_State *L, int idx, const char *fname,
                                 const char *label, int *nstops);

#endif
