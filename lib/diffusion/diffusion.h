/*
** diffusion.h — what the files of lib/diffusion share (Hnaidi et al.
** 2010): the feature curve's insides, the natural cubic spline, the
** multigrid levels with their constraint maps, and the steps of
** oc_diffusion (rasterisation, restriction, Jacobi sweeps, cascade and
** V-cycles, noise detail).
*/
#ifndef OC_DIFFUSION_H
#define OC_DIFFUSION_H

#include <stddef.h>
#include <stdint.h>

#include "core/curve.h"
#include "outcrop.h"

/* ---- natural cubic spline (nspline.c) ---- */

/* Through n >= 1 knots (u[i], v[i]), u strictly increasing: second
** derivatives m[i] with m[0] = m[n-1] = 0 (a line for n = 2, a constant
** for n = 1). */
void oc_nspline_fit(const double *u, const double *v, size_t n, double *m,
                    double *work);
/* The spline at t, constant beyond the end knots. */
double oc_nspline_eval(const double *u, const double *v, const double *m,
                       size_t n, double t);
/* The piecewise linear interpolant, constant beyond the end knots. */
double oc_linear_eval(const double *u, const double *v, size_t n, double t);

/* ---- feature curves (fcurve.c) ---- */

/* One interpolated attribute: its knots among the constraint points. */
typedef struct oc_fattr {
  size_t n;
  double *u, *v, *m; /* m: spline second derivatives (height only) */
} oc_fattr;

enum {
  FA_HEIGHT,
  FA_RADIUS,
  FA_LEFT,
  FA_RIGHT,
  FA_EXTA,
  FA_EXTB,
  FA_AMP,
  FA_ROUGH,
  FA_COUNT
};

struct oc_fcurve {
  int refs;
  oc_pcurve *c;
  double length;
  unsigned has;
  oc_fattr attr[FA_COUNT];
  double *xy; /* the control points as given (for the encoding) */
  size_t npoints;
  int bezier;
  oc_fconstraint *k; /* the constraint points as given */
  size_t nk;
};

/* The attributes of `want` (bits 1 << FA_*) at normalised arc length u
** into v[FA_COUNT] (0 where absent; the slope angles as tan theta). */
void oc_fcurve_attrs(const oc_fcurve *c, double u, unsigned want, double *v);

/* ---- levels and constraint maps ---- */

/* Flags of a sample. */
enum {
  DF_H = 1,        /* strict elevation */
  DF_SLOPE = 2,    /* gradient constrained (n, norm) */
  DF_CONFLICT = 4, /* gradients of different curves met: left empty */
  DF_NOISE = 8     /* strict amplitude and roughness */
};
#define DF_GUIDE (DF_SLOPE | DF_CONFLICT) /* h follows the gradient there */

/* Maps of one level (0 the finest): h (elevation), gx, gy (the guide
** direction n), gd (drop per metre along n), A, R; samples (i, j) at
** (x0 + (i + o) cell, y0 + (j + o) cell) with o = (2^level - 1) / 2 in
** the finest grid's cells. */
enum { MAP_H, MAP_GX, MAP_GY, MAP_GD, MAP_A, MAP_R, MAP_COUNT };

typedef struct oc_dlevel {
  int nx, ny;
  double cell;
  float *map[MAP_COUNT];
  uint8_t *flags;
} oc_dlevel;

typedef struct oc_dpyramid {
  int nlevels;
  oc_dlevel *lv;
  float *own0;    /* level 0's maps but the elevation (if given) */
  void *block;    /* the rasteriser's counters, then the coarser levels'
                  ** maps and flags and the scratch grid */
  float *scratch; /* nx ny of level 0 (in block) */
} oc_dpyramid;

/* Levels down to a coarsest grid of at most 8 samples a side. Allocates
** the maps of level 0 (its elevation is h, nx ny floats the caller owns,
** when not NULL), and one block that holds the rasteriser's counters
** (oc_dpyramid_counters) until oc_dpyramid_grow lays the
** coarser levels' maps and the scratch grid over it; oc_dpyramid_shrink
** frees that block again. So the peak holds level 0, the block and the
** output grid, and the counters' pages are the coarse levels' (memory
** touched for the first time costs a page fault, as much as the work on
** it). */
int oc_dpyramid_init(oc_dpyramid *py, int nx, int ny, double cell, float *h,
                     oc_error *err);
/* The rasteriser's 4 nx ny counters, in the block. */
uint16_t *oc_dpyramid_counters(oc_dpyramid *py);
void oc_dpyramid_grow(oc_dpyramid *py);
void oc_dpyramid_shrink(oc_dpyramid *py);
void oc_dpyramid_free(oc_dpyramid *py);
/* Coarse flags and constrained values from level k - 1 to k, for every
** k: a coarse sample is constrained if any child is, with the mean of
** the constrained children. */
void oc_dpyramid_restrict(oc_dpyramid *py);

/* ---- rasterisation (raster.c) ---- */

typedef struct oc_draster_stats {
  size_t strict, slope, conflict, strict_noise;
} oc_draster_stats;

/* Paints the curves into level 0 of py (grid origin x0, y0; every map
** and flag written) with the pyramid's counters: strict elevation and
** noise averaged, slopes with their guide direction, conflicts flagged. Reports
*[0, span] of pr, which may cancel. */
int oc_draster(oc_dpyramid *py, double x0, double y0, oc_fcurve *const *curves,
               size_t ncurves, oc_progress pr, double span,
               oc_draster_stats *st, oc_error *err);

/* ---- solving (jacobi.c, solve.c) ---- */

typedef enum oc_dkind {
  DK_LAPLACE, /* Laplace, identity where (flags & mask) */
  DK_GUIDED   /* the elevation: identity on DF_H, gradient + Laplace on
              ** DF_GUIDE, Laplace elsewhere */
} oc_dkind;

typedef struct oc_dop {
  oc_dkind kind;
  int map;      /* MAP_* being solved */
  uint8_t mask; /* DK_LAPLACE: the flags holding constraints */
  int paper;    /* DK_GUIDED: the paper's printed gradient term */
  int hom;      /* the correction equation: 0 where constrained, no G */
} oc_dop;

/* Flag bits oc_dguide_prepare sets on the gradient samples of the
** elevation that have a direction (|nx| + |ny| > 0): the guide applies,
** and its upwind neighbour is i + 1 (DF_SX) or j + 1 (DF_SY) instead of
** i - 1, j - 1. */
enum { DF_GACT = 16, DF_SX = 32, DF_SY = 64 };

/* Folds the guide of level lv (n in MAP_GX, MAP_GY, the drop per metre
** in MAP_GD) into the relaxation's coefficients: MAP_GX becomes the
** weight t of the upwind x neighbour, MAP_GY the constant c (see
** jacobi.c), and the flags get DF_GACT, DF_SX, DF_SY. With coherent >= 0
** (after the gradient diffusion) n is first set back to unit length, or
** to 0 where shorter than coherent (1e-6 on slope samples). Before the
** elevation's diffusion. */
void oc_dguide_prepare(oc_dlevel *lv, int paper, double coherent);

/* One Jacobi sweep of level lv from x into y: y = M x + c, or with
** op->hom (the correction equation of a V-cycle) y = M x + rhs (rhs NULL:
** 0), 0 where constrained and without the constant term. Returns the
** largest |y - x| over the samples not constrained. Rows in parallel. */
double oc_djacobi(const oc_dop *op, const oc_dlevel *lv, const float *x,
                  float *y, const float *rhs);
/* n Jacobi sweeps of x (no rhs), the result in x, using scr (the size of
** lv's grid): on grids run in parallel, fused in blocks of rows so that
** the grid is read and written once (the same values as n separate
** sweeps). Returns the last sweep's largest update. */
double oc_djacobi_n(const oc_dop *op, const oc_dlevel *lv, float *x, float *scr,
                    int n);
/* One red-black Gauss-Seidel sweep of x in place (the samples with i + j
** even, then the others): the same result for any thread count. Returns
** the largest update. */
double oc_dgauss_seidel(const oc_dop *op, const oc_dlevel *lv, float *x,
                        const float *rhs);
/* The residual of x: r = M x + c (or rhs) - x, 0 where constrained;
** returns its largest magnitude. */
double oc_dresidual(const oc_dop *op, const oc_dlevel *lv, const float *x,
                    const float *rhs, float *r);
/* Adds the bilinear prolongation of coarse values c (level lc) to (add)
** or sets (!add) the unconstrained samples of fine values f (level lf). */
void oc_dprolong(const oc_dop *op, const oc_dlevel *lc, const float *c,
                 const oc_dlevel *lf, float *f, int add);
/* Fine sample i of a cell-centred level lies at coarse coordinate
** (i - 1/2) / 2: between coarse samples a and b (of nc) with weight wb
** on b (1/4 or 3/4), clamped at the ends. */
static inline void oc_dsplit(int i, int nc, int *a, int *b, float *wb) {
  int a0 = (i & 1) ? (i - 1) / 2 : i / 2 - 1;
  *wb = (i & 1) ? 0.25f : 0.75f;
  *a = a0 < 0 ? 0 : a0 >= nc ? nc - 1 : a0;
  *b = a0 + 1 >= nc ? nc - 1 : a0 + 1;
}

/* Loops over a grid of fewer samples run on one thread: a parallel
** region costs more than the work there (and much more on a busy
** machine, where idle threads spin). */
#define OC_DPAR(lv) ((size_t)(lv)->nx * (size_t)(lv)->ny > 65536)

/* Whether sample k of lv is constrained for op. */
static inline int oc_dfixed(const oc_dop *op, const oc_dlevel *lv, size_t k) {
  return op->kind == DK_LAPLACE ? (lv->flags[k] & op->mask) != 0
                                : (lv->flags[k] & DF_H) != 0;
}
/* Whether sample k follows the gradient (after oc_dguide_prepare). */
static inline int oc_dguided(const oc_dop *op, const oc_dlevel *lv, size_t k) {
  return op->kind == DK_GUIDED && (lv->flags[k] & DF_GACT);
}

/* ---- Galerkin coarse operators (galerkin.c) ---- */

#define GQ_PLANES 10 /* 3 x 3 stencil coefficients, then 1 / diagonal */

/* A_{k+1} = R A_k P for every level k + 1 >= 1 of a pyramid: per level
** GQ_PLANES planes of nx ny floats in a[k] (a[0] unused: level 0's
** operator is the relaxation's). */
typedef struct oc_dgalerkin {
  int nlevels, five; /* five: 5-point stencils (the elevation's) */
  float *a[32];
  uint8_t *dead[32]; /* per level: 1 where every child is constrained */
  float *block;      /* the planes, then the dead flags */
  size_t cap;        /* its floats */
} oc_dgalerkin;

/* The coarse operators of op's correction equation, into g (zeroed, or
** holding an earlier build, whose memory is used again when large
** enough). OC_OK or OC_ENOMEM. */
int oc_dgalerkin_build(oc_dgalerkin *g, const oc_dpyramid *py, const oc_dop *op,
                       oc_error *err);
void oc_dgalerkin_free(oc_dgalerkin *g);
/* n Gauss-Seidel sweeps of A_k x = b at level k >= 1 (4 colours, or
** red-black where the stencils have no corners). */
void oc_dgalerkin_smooth(const oc_dgalerkin *g, const oc_dlevel *lv, int k,
                         float *x, const float *b, int n);
/* r = b - A_k x (0 where dead). */
void oc_dgalerkin_residual(const oc_dgalerkin *g, const oc_dlevel *lv, int k,
                           const float *x, const float *b, float *r);
/* b = R r: the sum over the children. */
void oc_dgalerkin_restrict(const oc_dlevel *f, const float *r,
                           const oc_dlevel *c, float *b);
/* f += P c on level kf >= 1 (nothing where dead). */
void oc_dgalerkin_prolong(const oc_dgalerkin *g, int kf, const oc_dlevel *lc,
                          const float *c, const oc_dlevel *lf, float *f);

/* A block of floats kept across solves (oc_dsolve's work): memory
** touched for the first time costs a page fault. */
typedef struct oc_dwork {
  float *f;
  size_t cap;
} oc_dwork;

typedef struct oc_dsolve {
  oc_progress progress;
  double lo, span;  /* this solve's part of the progress range */
  double tolerance; /* 0: the cascade; > 0: the cascade, then cycles */
  double *residual; /* NULL or OC_DIFFUSION_MAX_CYCLES + 1 values */
  int *cycles;
  const oc_dgalerkin *gal; /* NULL or op's coarse operators (tolerance > 0) */
  oc_dwork *work;          /* NULL or the V-cycles' buffers, kept */
} oc_dsolve;

/* Solves op's map on every level: the paper's coarse-to-fine cascade,
** or (tolerance > 0) the cascade, then V-cycles and BiCGSTAB to the
** tolerance (with gal's coarse operators, or its own when NULL). OC_OK,
*OC_ENOMEM or OC_ECANCEL. */
int oc_dsolve_map(oc_dpyramid *py, const oc_dop *op, const oc_dsolve *s,
                  oc_error *err);

/* ---- noise detail (detail.c) ---- */

typedef struct oc_ddetail {
  double x0, y0, cell, wavelength, ratio;
  int octaves;
  uint64_t seed;
} oc_ddetail;

/* N at (x, y) for amplitude A and roughness R, every octave sampled
** exactly. */
double oc_ddetail_at(const oc_ddetail *d, double x, double y, double A,
                     double R);
/* The final heights z = h + N over the samples of lv (its maps H, A, R;
** z may be H),
** each octave interpolated from a lattice (detail.c); N also into detail
** unless NULL. Rows in parallel, the same for any thread count; reports
** [lo, lo + span] of pr, which may cancel. OC_OK, OC_ENOMEM, OC_ECANCEL. */
int oc_ddetail_grid(const oc_ddetail *d, const oc_dlevel *lv, float *z,
                    float *detail, oc_progress pr, double lo, double span,
                    oc_error *err);

#endif
