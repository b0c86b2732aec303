/*
** l_config.h — the run's configuration inside the module: the seed,
** parameters and output folder outcrop.configure (or the interpreter)
** fixed, the parameters outcrop.param read and the input files the
** engine's loaders read, all of which provenance records (see oclua.h
** for what the interpreter shares).
*/
#ifndef L_CONFIG_H
#define L_CONFIG_H

#include "l_util.h"

/* Adds outcrop.param and outcrop.configure to the module table at the
** top of the stack. */
void oclua_open_config(lua_State *L);

/* Pushes the value at idx as --set would spell it: strings as they are,
** integers in decimal, floats in the shortest of %.14g and %.17g that
** reads back exactly (with ".0" when it looks like an integer, so the
** type survives), true and false. Other types (set by a host directly)
** as tostring would show them. Returns the pushed string. */
const char *oclua_param_text(lua_State *L, int idx);

/* Records that the file `path` was read as an input of the run (by
** heightfield.load and every other loader): its SHA-256, in read order,
** each name and hash once. Raises, prefixed with fname, when the file
** cannot be read any more. */
void oclua_record_input(lua_State *L, const char *path, const char *fname);

/* Notes that an output is being written: from now on outcrop.configure
** may not change anything (oclua_push_provenance calls it). */
void oclua_mark_written(lua_State *L);

#endif
