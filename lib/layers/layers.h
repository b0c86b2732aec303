/*
** layers.h — the material-stack grid of Peytavie et al. 2009, section 3.2
** (internal to lib/layers): its packed storage, the canonical form of a
** stack, and the segment view (the gaps between bedrock layers) that the
** stabilisation and the tools edit.
**
** Storage: compressed rows. Stack k = j nx + i holds layers
** oc_soff(s, k) .. oc_soff(s, k + 1) - 1 of one array of packed layers
** (4 bytes a layer), bottom-up from zbase. The offsets are compact when
** every stack holds at most 255 layers: a byte of layer count per stack
** and the offset of every block of OC_SBLOCK stacks (1.25 bytes a stack);
** otherwise one offset per stack (4 bytes). Edits decode stacks to
** doubles, work there, and re-encode (rounding each thickness once).
*/
#ifndef OC_LAYERS_H
#define OC_LAYERS_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "outcrop.h"

struct oc_stacks {
  int nx, ny;
  double cell, x0, y0, zbase;
  uint32_t *off;  /* nx ny + 1 offsets, or NULL when compact: */
  uint8_t *cnt;   /* nx ny layer counts */
  uint32_t *base; /* nx ny / OC_SBLOCK + 1 block offsets */
  uint32_t *lay;  /* oc_soff(s, nx ny) packed layers (oc_lay_pack) */
  size_t cap;     /* capacity of lay */
};

#define OC_SBLOCK 16

/* The offset of stack k's first layer (k = nx ny: the layer count). */
static inline size_t oc_soff(const oc_stacks *s, size_t k) {
  if (s->off) return s->off[k];
  size_t o = s->base[k / OC_SBLOCK];
  for (size_t q = k - k % OC_SBLOCK; q < k; q++)
    o += s->cnt[q];
  return o;
}
/* The layer count of stack k. */
static inline size_t oc_scount(const oc_stacks *s, size_t k) {
  return s->off ? s->off[k + 1] - s->off[k] : s->cnt[k];
}
/* Full offsets (nx ny + 1, malloc'ed) made s's, compact when they can be
** (then freed); s's old offsets are freed. */
void oc_stacks_take_offsets(oc_stacks *s, uint32_t *off);

/* A layer in 32 bits: the bits of its thickness as a float (>= 0, so the
** sign bit is free) moved up one bit, their two lowest mantissa bits
** dropped (rounded to nearest: 21 bits of mantissa, a relative error of
** at most 2^-22), and the material in the lowest 3 bits. */
/* x (a stack index in double) clamped to [lo, hi] and converted; NaN
** gives lo. For windows of stacks around a region, whose bounds can lie
** anywhere (an origin of 1e308): clamped first, so the conversion to int
** is defined. */
static inline int oc_sindex(double x, int lo, int hi) {
  return x >= hi ? hi : x > lo ? (int)x : lo;
}

static inline uint32_t oc_lay_pack(double t, int m) {
  float f = (float)t;
  uint32_t b, r;
  memcpy(&b, &f, sizeof b);
  r = (b + 2u) & ~3u;
  if ((r & 0x7f800000u) == 0x7f800000u) r = b & ~3u; /* no carry to inf */
  return r << 1 | (uint32_t)m;
}
static inline double oc_lay_t(uint32_t w) {
  uint32_t b = (w >> 1) & ~3u;
  float f;
  memcpy(&f, &b, sizeof f);
  return f;
}
static inline int oc_lay_m(uint32_t w) {
  return (int)(w & 7u);
}

/* One layer while being edited. */
typedef struct oc_layer {
  double t;
  int m;
} oc_layer;

/* The canonical form of n layers (see outcrop.h) into out (room for n;
** may not alias in): drops empty layers, merges, sorts each gap between
** bedrock layers (sand, rocks, water, air) and drops trailing air.
** Returns the count. */
size_t oc_layers_canon(const oc_layer *in, size_t n, oc_layer *out);

/* A segment: the gap above a bedrock layer (or above zbase for the
** first), and the bedrock below it. floor: its bottom elevation; cap:
** its height up to the next bedrock (INFINITY for the last); a: its
** sand, rocks and water (air fills the rest). */
enum { OC_SEG_SAND, OC_SEG_ROCKS, OC_SEG_WATER, OC_SEG_N };
typedef struct oc_lseg {
  double floor, cap, bed;
  double a[OC_SEG_N];
} oc_lseg;

/* The segment index a granular material or water uses; -1 otherwise. */
int oc_seg_index(int m);
/* Stack k as segments (one more than its bedrock layers) into out, which
** has room for off[k + 1] - off[k] + 1. Returns the count. */
size_t oc_layers_segments(const oc_stacks *s, size_t k, oc_lseg *out);
/* Segments back to canonical layers into out (room for 5 nseg); returns
** the count. */
size_t oc_layers_from_segments(const oc_lseg *seg, size_t nseg, oc_layer *out);

/* A grid being rebuilt stack by stack, in order (k = 0, 1, ...). */
typedef struct oc_stacks_builder {
  uint32_t *off;
  uint32_t *lay;
  size_t n, cap, nstacks, k;
} oc_stacks_builder;
int oc_builder_init(oc_stacks_builder *b, size_t nstacks, size_t cap,
                    oc_error *err);
/* Appends the next stack (layers already canonical). */
int oc_builder_push(oc_stacks_builder *b, const oc_layer *l, size_t n,
                    oc_error *err);
/* Moves the arrays into s (freeing its old ones); b is empty after. */
void oc_builder_commit(oc_stacks_builder *b, oc_stacks *s);
void oc_builder_free(oc_stacks_builder *b);

/* A grid with no layers yet, its arrays unset (for converters). */
oc_stacks *oc_stacks_alloc(int nx, int ny, double cell, double x0, double y0,
                           double zbase, oc_error *err);

/* The coarsest stride of the stabilisation (stabilize.c): material moves
** at most this many stacks in one transfer. */
#define OC_LAYERS_STRIDE_MAX 8
/* The most samples a tool's edit takes along one stack (its window's height
** over its step): an edit beyond is refused. */
#define OC_LAYERS_MAX_SAMPLES (1 << 20)

/* Stabilisation over the stacks, with the segments already decoded
** (stabilize.c; deposit.c calls it after adding material). */
int oc_layers_stabilize_segs(oc_stacks *s, oc_lseg *seg, const size_t *soff,
                             const oc_stabilize_params *p,
                             oc_stabilize_result *res, oc_error *err);
/* Checks the stabilisation parameters (messages name the Lua fields). */
int oc_layers_check_stabilize(const oc_stabilize_params *p, oc_error *err);
/* A tool's stabilisation parameters: `given`, or the defaults when NULL;
** checked when the tool stabilises. */
int oc_layers_tool_stab(const oc_stacks *s, const oc_stabilize_params *given,
                        int stabilize, oc_stabilize_params *p, oc_error *err);
/* Stacks [i0, i1] x [j0, j1] of s as a grid of their own (origin moved;
** the caller frees it), and such a grid put back at (i0, j0) (window.c). */
oc_stacks *oc_stacks_window(const oc_stacks *s, int i0, int j0, int i1, int j1,
                            oc_error *err);
int oc_stacks_splice(oc_stacks *s, const oc_stacks *w, int i0, int j0,
                     oc_error *err);
/* Stabilisation from p->region (which must be set) in a window around
** it, grown until nothing reaches its border. */
int oc_layers_stabilize_local(oc_stacks *s, const oc_stabilize_params *p,
                              oc_stabilize_result *res, oc_error *err);
/* All stacks to segments: *seg (soff[k] .. soff[k + 1] - 1 for stack k)
** and *soff, both malloc'ed. */
int oc_layers_decode_all(const oc_stacks *s, oc_lseg **seg, size_t **soff,
                         oc_error *err);
/* Segments back into s's storage. */
int oc_layers_encode_all(oc_stacks *s, const oc_lseg *seg, const size_t *soff,
                         oc_error *err);

/* The stacks of w rebuilt where an edit changes them (sculpt.c, used by
** sweep.c): `window` says whether the stack centred on (px, py) may
** change and over which [z0, z1]; `after` gives the material at
** (px, py, z) after the edit, m0 the one before. Inside the window the
** column is sampled every `step` and each change refined by bisection;
** outside it the layers stay. Loose material that new bedrock took goes
** back on top of it; stacks are made canonical. */
typedef int (*oc_layers_after_fn)(const void *ctx, double px, double py,
                                  double z, int m0);
typedef struct oc_layers_edit {
  int (*window)(void *ctx, double px, double py, double *z0, double *z1);
  oc_layers_after_fn after;
  void *ctx;
  double step;
} oc_layers_edit;
int oc_layers_rebuild_grid(oc_stacks *w, const oc_layers_edit *e,
                           oc_error *err);

#endif
