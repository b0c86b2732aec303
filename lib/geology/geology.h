/*
** geology.h — the node kinds of resistance trees and the erosion node
** (internal): strata, clamp, taper, fault (geology.c) and erosion
** (erosion.c). docs/fields.md, "Geology", has the formulas.
**
** Each kind is an extension kind of lib/field (field/kind.h): a table of
** query functions in the file of its formulas, reaching its children
** through the oc_child_* helpers.
*/
#ifndef OC_GEOLOGY_H
#define OC_GEOLOGY_H

#include "field/kind.h"

/* Strata sample the 3D turbulence on the vertical line (X, Y, z / wl),
** away from the lattice's axes, where simplex noise is more regular. */
#define OC_STRATA_X 0.318309886
#define OC_STRATA_Y 0.587785252

/* Parameter slots, in the node and (same order) in the compiled op. */
enum {
  /* strata: the noise, packed as 6 doubles */
  OC_GP_NOISE = 0, /* OC_NOISE_NPAR of them (core/noise.h) */
  /* clamp */
  OC_GP_LO = 0,
  OC_GP_HI = 1,
  /* taper: origin, unit axis, unit `along`, from, to, factor, height */
  OC_GP_TO = 0,
  OC_GP_TA = 3,
  OC_GP_TB = 6,
  OC_GP_U0 = 9,
  OC_GP_U1 = 10,
  OC_GP_K = 11,
  OC_GP_H = 12,
  /* fault: offset, domain kind, then box lo and hi or half-space origin
  ** and unit normal */
  OC_GP_OFF = 0,
  OC_GP_DOM = 3,
  OC_GP_DA = 4,
  OC_GP_DB = 7,
  /* erosion: depth, and 1 when a control node is given */
  OC_GP_DEPTH = 0,
  OC_GP_HASCTL = 1,
  OC_GP_COUNT = 13
};

#endif
