/*
** enode.h — the nodes of 2D elevation trees (Génevaux et al. 2015)
** (internal): every node maps a point p of the plane to an elevation f and
** a weight alpha, with their gradients, in one traversal.
**
** Conventions (docs/fields.md, "Elevation trees"):
**  - alpha has compact support Omega_0 = {alpha > 0}, inside the node's
**    box; the terrain is where alpha >= T (T = OC_ENODE_T, 1/2).
**  - f is defined and Lipschitz on the whole plane. The paper leaves a
**    blend undefined where the weights vanish; here a blend divides by
**    max(sum alpha, T), which is the paper's f on Omega_T and fades to 0
**    outside it, so one Lipschitz bound holds everywhere (what tracing,
**    implicitization and sampling need).
**  - Bounds come in one struct, for the whole plane (at construction) or
**    inside a box (oc_enode_bound_in): the range of f and of alpha and
**    Lipschitz bounds of both.
*/
#ifndef OC_ENODE_H
#define OC_ENODE_H

#include <stddef.h>

#include "outcrop.h"

typedef enum oc_ekind {
  OC_E_DISC,
  OC_E_CURVE,
  OC_E_BLEND,
  OC_E_REPLACE,
  OC_E_ADD,
  OC_E_XFORM,
  OC_E_WARP,
  OC_E_LAKE,
  OC_E_IMAGE,
  OC_E_LOD,
  OC_E_COUNT
} oc_ekind;

/* Ranges and Lipschitz bounds of f and alpha over a region (outcrop.h). */
typedef oc_enode_bound oc_ebound;

/* A rectangle [x0, x1] x [y0, y1]. */
typedef struct oc_erect {
  double x0, y0, x1, y1;
} oc_erect;

/* Noise sums of discs and warps. */
typedef struct oc_enoise {
  int kind; /* oc_enoise_kind */
  int octaves;
  double amplitude, wavelength, gain, lacunarity;
  uint64_t seed;
} oc_enoise;

struct oc_enode {
  int refs; /* built from one thread (Lua), like 3D nodes */
  oc_ekind kind;
  size_t nkids;
  oc_enode **kids; /* retained */
  oc_enode *inl[2];
  oc_erect box;   /* Omega_0 lies inside */
  oc_ebound glob; /* over the whole plane */
  oc_enoise noise;
  void *data; /* curve: skeleton and profiles (ecurve.c), owned */
  /* Parameters, as many as the kind uses (enode.c, par_count): a blend
  ** stores none, a transform 11; kinds not in that table get
  ** OC_ENODE_NPAR. Last, so that each node is allocated at its size. */
  double par[];
};
#define OC_ENODE_NPAR 12

/* The bytes of n, its children's array included. */
size_t oc_enode_size(const oc_enode *n);

/* Level of detail (lod.c): the pixel footprint where a node is evaluated,
** in the node's local units (a transform divides it by its scale), with
** its gradient there, so that a tree under a view is a genuine C1
** function of p whose gradients include the footprint's terms. NULL (or
** v = 0): full detail. */
typedef struct oc_efoot {
  double v, gx, gy;
} oc_efoot;

/* The footprint over a box: its range and a Lipschitz bound k of it
** there. NULL: full detail. */
typedef struct oc_efootb {
  double lo, hi, k;
} oc_efootb;

/* What a caller asks of eval. */
#define OC_EV_GRAD 1 /* gradients too */
#define OC_EV_LAZY 2 /* f may be left 0 where alpha = 0 (blend children) */
/* alpha and nothing else (f and the gradients left unset): no operator's
** alpha depends on an f, so a weight query skips every noise sum */
#define OC_EV_ALPHA 4

void oc_enode_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                 int want, oc_enode_sample *s);

/* Allocation (refs = 1) with nkids children retained from kids. */
oc_enode *oc_enode_alloc(oc_ekind kind, oc_enode *const *kids, size_t nkids,
                         oc_error *err);

/* Kinds' parts (disc.c, eops.c): evaluation and bounds in a box. */
void oc_edisc_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                 int want, oc_enode_sample *s);
void oc_edisc_bound_in(const oc_enode *n, const oc_erect *b,
                       const oc_efootb *fb, oc_ebound *o);
void oc_ecurve_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                  int want, oc_enode_sample *s);
void oc_ecurve_bound_in(const oc_enode *n, const oc_erect *b,
                        const oc_efootb *fb, oc_ebound *o);
void oc_ecurve_free(void *data);
/* The skeleton through points (z carried along) as the curve primitive
** builds it (ecurve.c): a uniform Catmull-Rom spline, cubic Bézier
** control points or segments. The caller frees it (oc_curve_free). */
struct oc_pcurve *oc_ecurve_skeleton(const oc_vec3 *points, size_t n,
                                     oc_ecurve_spline spline, oc_error *err);
/* lake.c and eimage.c: the contour and image primitives (state in data). */
void oc_elake_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                 int want, oc_enode_sample *s);
void oc_elake_bound_in(const oc_enode *n, const oc_erect *b,
                       const oc_efootb *fb, oc_ebound *o);
void oc_elake_free(void *data);
void oc_eimage_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                  int want, oc_enode_sample *s);
void oc_eimage_bound_in(const oc_enode *n, const oc_erect *b,
                        const oc_efootb *fb, oc_ebound *o);
void oc_eimage_free(void *data);
void oc_eop_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
               int want, oc_enode_sample *s);
void oc_eop_bound_in(const oc_enode *n, const oc_erect *b, const oc_efootb *fb,
                     oc_ebound *o);

/* The bound of n in box b (dispatch), under the footprint fb. */
void oc_enode_bnd(const oc_enode *n, const oc_erect *b, const oc_efootb *fb,
                  oc_ebound *o);

static inline int oc_erect_meets(const oc_erect *a, const oc_erect *b) {
  return a->x0 <= b->x1 && a->x1 >= b->x0 && a->y0 <= b->y1 && a->y1 >= b->y0;
}

/* ---- level of detail (lod.c) ---- */

/* A view: the footprint at p is k sqrt(|p - e_xy|^2 + dz^2), dz the eye's
** height above the tree's mid elevation (fixed, so the footprint is C1
** and k-Lipschitz). */
typedef struct oc_eview {
  double ex, ey, dz, k;
} oc_eview;

void oc_eview_foot(const oc_eview *v, double x, double y, oc_efoot *ft);
void oc_eview_footb(const oc_eview *v, const oc_erect *b, oc_efootb *fb);

/* The octave filter b(t) = 1 - (1 - t^2)^3 of t clamped to [0, 1]
** (Génevaux et al. 2015, the increasing form) and its derivative. */
static inline double oc_elod_b(double t, double *db) {
  if (t <= 0 || t >= 1) {
    *db = 0;
    return t >= 1 ? 1 : 0;
  }
  double q = 1 - t * t;
  *db = 6 * t * q * q;
  return 1 - q * q * q;
}

/* For a detail of wavelength w under footprints in fb: the range of
** kappa = b(log2(w / foot)) and its Lipschitz bound. */
void oc_elod_kappa_bound(double w, const oc_efootb *fb, double *lo, double *hi,
                         double *lip);
/* The same for t = log2(w / foot) known to lie in [tmin, tmax]. */
void oc_elod_kappa_bound_t(double w, double tmin, double tmax,
                           const oc_efootb *fb, double *lo, double *hi,
                           double *lip);

/* The box of Omega_T under view v (NULL: none), as oc_enode_terrain_box;
** and the domain of a source: domain, or that box, checked. */
int oc_enode_terrain_box_in(const oc_enode *e, const oc_eview *v,
                            double box[4]);
int oc_enode_domain(const oc_enode *e, const oc_eview *v, const double *domain,
                    double d[4], oc_error *err);

void oc_elod_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                int want, oc_enode_sample *s);
void oc_elod_bound_in(const oc_enode *n, const oc_erect *b, const oc_efootb *fb,
                      oc_ebound *o);

/* Noise: eta on z = 0 remapped to [-1, 1], and its Lipschitz bound. */
double oc_eta(uint64_t seed, double x, double y, double g[2]);
extern const double oc_eta_lipschitz;

#endif
