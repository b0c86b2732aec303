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
#include <stdint.h>

#include "core/log2.h"
#include "core/pmap.h"
#include "core/vec.h"
#include "elevation/etaylor.h"
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

/* Noise sums of discs and warps, as evaluation reads them (unpacked from
** a node by oc_edisc_noise). */
/* The most octaves a noise sum has (checked at construction). */
#define OC_ENOISE_MAXOCT 16
typedef struct oc_enoise {
  int kind; /* oc_enoise_kind */
  int octaves;
  double amplitude, wavelength, gain, lacunarity;
  uint64_t seed;
} oc_enoise;

/*
** Storage. Every node starts with this 8-byte header and is allocated at
** the size of its kind's fields (oc_edisc, oc_eprim, oc_eblend, oc_ebin,
** oc_eun below; oc_enode_size). What evaluation reads is kept exactly
** (doubles); what only bounds read is kept as floats rounded outward
** (oc_erectf, oc_eboundf: never tighter than the double they round), or
** derived when that is cheap:
**  - a disc's box and whole-plane bound come from its parameters (and
**    its noise's range and slope, kept), so they are the doubles they
**    always were; a transform's and a warp's bound from their child's;
**  - curves, lakes and images keep theirs as doubles (their data dwarfs
**    them);
**  - operators keep both as floats. The exact doubles (what construction
**    in doubles would give) are recomputed through the DAG by
**    oc_enode_exact for what scripts see: e:bounds(), e:lipschitz(), the
**    terrain's box and the level of detail's reference height.
*/
struct oc_enode {
  uint32_t refs;   /* built from one thread (Lua), like 3D nodes */
  uint8_t kind;    /* oc_ekind */
  uint8_t flags;   /* OC_EF_* */
  uint8_t nzkind;  /* disc: its noise's oc_enoise_kind */
  uint8_t octaves; /* disc and warp */
};

/* Flags. */
#define OC_EF_GLF 1    /* disc: gain and lacunarity are floats exactly */
#define OC_EF_GLDEF 2  /* disc: they are 1/2 and 2 (not stored) */
#define OC_EF_DISCS 1  /* blend: every child is a disc (eops.c) */
#define OC_EF_SLOPE 4  /* add: with a slope weight (its angle, fade, step) */
#define OC_EF_SUMW 8   /* add: alpha = alpha_A + w^2 */
#define OC_EF_BELOW 16 /* add: with an altitude weight (below_z, fade) */
#define OC_EF_STEPF 32 /* add: the slope weight's step a float exactly */
#define OC_EF_LERP 64  /* replace: the lerped weight */
/* every kind: its f model holds only where its weight is > 0 (a curve,
** lake or image, or an operator of one in A's place:
** oc_eop_taylor_partial), set by oc_enode_alloc from the kind and the children
*/
#define OC_EF_PARTIAL 128

/* The parameters (doubles) operators store (eops.c, lod.c). A replace
** stores none (its weight is a flag); an add the altitude weight's
** below_z and fade when it has one, then the slope weight's angle and
** fade (radians) and its step (a float when OC_EF_STEPF) when it has one
** (oc_eadd_size). */
#define OC_ELOD_NPAR 3
#define OC_EXFORM_NPAR 8
#define OC_EWARP_NPAR 5

/* A box and bounds rounded outward to floats. */
typedef struct oc_erectf {
  float x0, y0, x1, y1;
} oc_erectf;
typedef struct oc_eboundf {
  float flo, fhi, alo, ahi, lf, la;
} oc_eboundf;

/* disc: 40 bytes; with a noise 80, 88 when gain and lacunarity are not
** the defaults but floats, 96 else. */
typedef struct oc_edisc {
  oc_enode h;
  double par[4]; /* cx, cy, radius, height */
  /* with a noise (h.nzkind != OC_ENOISE_NONE): */
  double amplitude, wavelength;
  uint64_t seed;
  /* the noise sum's bound over the plane (disc.c, noise_bounds): its
  ** range [-nhi, nhi] (plain) or [0, nhi], its Lipschitz bound nlip */
  double nhi, nlip;
  union {
    float f[2]; /* OC_EF_GLF */
    double d[2];
  } gl; /* gain, lacunarity (none with OC_EF_GLDEF) */
} oc_edisc;

/* curve, lake, image: 96 bytes, and their data (skeleton, profiles,
** grids). */
typedef struct oc_eprim {
  oc_enode h;
  oc_erect box;   /* Omega_0 lies inside */
  oc_ebound glob; /* over the whole plane */
  void *data;     /* owned (ecurve.c, lake.c, eimage.c) */
} oc_eprim;

/* blend: 56 bytes and 8 a child; from OC_EGRID_MIN to 64 OC_EGRID_WORDS
** children, then its grid (eops.c): G x G cells over its box (G =
** h.octaves), stored as its two scales (cells a unit, doubles) and the
** masks of the children whose box meets each of its G columns and G
** rows, W = ceil(nkids / 64) words a mask, G the largest with 8 (2 + 2 G
** W) <= 6 nkids (6 bytes a child at most). A query visits the children
** of the cells it meets (its columns' masks ORed, ANDed with its rows'),
** in their order, and tests their boxes as before: the same children,
** the same sums, fewer tests. */
typedef struct oc_eblend {
  oc_enode h;
  oc_erectf box;
  oc_eboundf glob;
  uint32_t nkids;
  oc_enode *kids[]; /* retained; then the grid's uint64_t masks */
} oc_eblend;
#define OC_EGRID_MIN 24
#define OC_EGRID_WORDS 4

/* The 8-byte words of a blend's grid with nkids children and G cells a
** side: its two scales, G column masks and G row masks. */
static inline size_t oc_eblend_grid_words(size_t nkids, int G) {
  return G ? 2 + 2 * (size_t)G * ((nkids + 63) / 64) : 0;
}

/* replace (64 bytes), add (64; 80 with an altitude weight, 88 with a slope
** weight, 100 with both and a step that is a float, else 104), lod (88). */
typedef struct oc_ebin {
  oc_enode h;
  oc_erectf box;
  oc_eboundf glob;
  oc_enode *kids[2]; /* retained */
  double par[];      /* eops.c, lod.c */
} oc_ebin;

/* transform (96 bytes) and warp (72): the bound is the child's, mapped. */
typedef struct oc_eun {
  oc_enode h;
  oc_erectf box;
  oc_enode *kid; /* retained */
  double par[];  /* eops.c */
} oc_eun;

static inline size_t oc_eadd_size(int flags) {
  return offsetof(oc_ebin, par) + (flags & OC_EF_BELOW ? 16 : 0) +
         (flags & OC_EF_SLOPE ? (flags & OC_EF_STEPF ? 20 : 24) : 0);
}

#define OC_EDISC(n) ((const oc_edisc *)(n))
#define OC_EPRIM(n) ((const oc_eprim *)(n))
#define OC_EBLEND(n) ((const oc_eblend *)(n))
#define OC_EBIN(n) ((const oc_ebin *)(n))
#define OC_EUN(n) ((const oc_eun *)(n))

/* The bytes of n (its children's pointers included, its data not). */
size_t oc_enode_size(const oc_enode *n);

/* Allocation (refs = 1) of size bytes (at least the kind's header) with
** nkids children retained from kids. */
oc_enode *oc_enode_alloc(oc_ekind kind, size_t size, oc_enode *const *kids,
                         size_t nkids, oc_error *err);

/* The children. */
static inline size_t oc_enode_nkids(const oc_enode *n) {
  switch (n->kind) {
  case OC_E_BLEND:
    return OC_EBLEND(n)->nkids;
  case OC_E_REPLACE:
  case OC_E_ADD:
  case OC_E_LOD:
    return 2;
  case OC_E_XFORM:
  case OC_E_WARP:
    return 1;
  default:
    return 0;
  }
}
static inline oc_enode *const *oc_enode_kids(const oc_enode *n) {
  switch (n->kind) {
  case OC_E_BLEND:
    return OC_EBLEND(n)->kids;
  case OC_E_REPLACE:
  case OC_E_ADD:
  case OC_E_LOD:
    return OC_EBIN(n)->kids;
  case OC_E_XFORM:
  case OC_E_WARP:
    return &OC_EUN(n)->kid;
  default:
    return NULL;
  }
}
static inline const oc_enode *oc_enode_kid(const oc_enode *n, size_t i) {
  return oc_enode_kids(n)[i];
}

/* The box of n (Omega_0 lies inside): a disc's exactly as built, a
** curve's, lake's or image's as stored, an operator's rounded outward. */
/* Curves, lakes and images keep a double box; operators a float one, at
** the same place in each of their layouts. */
#define OC_EPRIM_KIND(k)                                                       \
  ((1u << (k)) & ((1u << OC_E_CURVE) | (1u << OC_E_LAKE) | (1u << OC_E_IMAGE)))
_Static_assert(offsetof(oc_eblend, box) == offsetof(oc_ebin, box) &&
                   offsetof(oc_eblend, box) == offsetof(oc_eun, box),
               "operators keep their box at one offset");
static inline const oc_erectf *oc_enode_boxf(const oc_enode *n) {
  return &OC_EBLEND(n)->box;
}

static inline oc_erect oc_enode_box(const oc_enode *n) {
  if (n->kind == OC_E_DISC) { /* (the commonest child: tested first) */
    const double *p = OC_EDISC(n)->par;
    return (oc_erect){p[0] - p[2], p[1] - p[2], p[0] + p[2], p[1] + p[2]};
  }
  if (OC_EPRIM_KIND(n->kind)) return OC_EPRIM(n)->box;
  const oc_erectf *f = oc_enode_boxf(n);
  return (oc_erect){f->x0, f->y0, f->x1, f->y1};
}

/* Whether (x, y) is in n's box (NaN is not); whether n's box meets r.
** (A disc's tests compare as they always did, its edges computed as they
** come; one side at a time.) */
static inline int oc_edisc_holds(const oc_enode *n, double x, double y) {
  const double *p = OC_EDISC(n)->par;
  return x >= p[0] - p[2] && x <= p[0] + p[2] && y >= p[1] - p[2] &&
         y <= p[1] + p[2];
}
static inline int oc_enode_holds(const oc_enode *n, double x, double y) {
  if (n->kind == OC_E_DISC) return oc_edisc_holds(n, x, y);
  if (OC_EPRIM_KIND(n->kind)) {
    const oc_erect *b = &OC_EPRIM(n)->box;
    return x >= b->x0 && x <= b->x1 && y >= b->y0 && y <= b->y1;
  }
  const oc_erectf *f = oc_enode_boxf(n);
  return x >= f->x0 && x <= f->x1 && y >= f->y0 && y <= f->y1;
}
static inline int oc_edisc_meets(const oc_enode *n, const oc_erect *r) {
  const double *p = OC_EDISC(n)->par;
  return p[0] - p[2] <= r->x1 && p[0] + p[2] >= r->x0 && p[1] - p[2] <= r->y1 &&
         p[1] + p[2] >= r->y0;
}
static inline int oc_enode_meets(const oc_enode *n, const oc_erect *r) {
  if (n->kind == OC_E_DISC) return oc_edisc_meets(n, r);
  if (OC_EPRIM_KIND(n->kind)) {
    const oc_erect *b = &OC_EPRIM(n)->box;
    return b->x0 <= r->x1 && b->x1 >= r->x0 && b->y0 <= r->y1 && b->y1 >= r->y0;
  }
  const oc_erectf *f = oc_enode_boxf(n);
  return f->x0 <= r->x1 && f->x1 >= r->x0 && f->y0 <= r->y1 && f->y1 >= r->y0;
}

/* The bound of n over the whole plane: exact for primitives, else from
** the stored floats (conservative). */
void oc_enode_glob(const oc_enode *n, oc_ebound *o);

/* The bound and box that construction in doubles gives (recomputed
** through the DAG; the stored ones contain them). */
void oc_enode_exact(const oc_enode *n, oc_ebound *glob, oc_erect *box);

/* Rounding outward to floats, and back. */
float oc_efloat_down(double v);
float oc_efloat_up(double v);
void oc_erect_round(const oc_erect *r, oc_erectf *o);
void oc_ebound_round(const oc_ebound *b, oc_eboundf *o);
void oc_ebound_widen(const oc_eboundf *f, oc_ebound *o);

/* An operator's (blend, replace, add, transform, warp; eops.c) or a lod's
** (lod.c) whole-plane bound and box from its children's kb and kbox. */
void oc_eop_derive(const oc_enode *n, const oc_ebound *kb, const oc_erect *kbox,
                   oc_ebound *glob, oc_erect *box);
void oc_elod_derive(const oc_enode *n, const oc_ebound *kb,
                    const oc_erect *kbox, oc_ebound *glob, oc_erect *box);

/* The noise of a disc, unpacked; its bytes (with those flags); and its
** whole-plane bound (disc.c). */
void oc_edisc_noise(const oc_enode *n, oc_enoise *nz);
size_t oc_edisc_size(int nzkind, int flags);
void oc_edisc_glob(const oc_enode *n, oc_ebound *o);

/* The bytes of a curve's, lake's or image's data: their skeletons,
** profiles and grids; a grid shared by several images counts once (seen
** holds the grids counted; OC_ENOMEM when it cannot grow). */
size_t oc_ecurve_bytes(const void *data);
size_t oc_elake_bytes(const void *data);
int oc_eimage_bytes(const void *data, oc_pmap *seen, size_t *bytes);

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

/* Rows (sampling: full detail, no gradients). For m < cnt, f[m] and a[m]
** are bit for bit the f and alpha of oc_enode_ev(n, x[m], y, NULL, want,
** &s), want a mix of OC_EV_LAZY and OC_EV_ALPHA (f is not written under
** OC_EV_ALPHA); x finite and non-decreasing, y finite, cnt <= OC_EROW.
** A row shares per-row work (which children's boxes it crosses, the noise
** octaves' keys, lattice corners' hashes, a curve's distance) that points
** repeat. Discs, curves, blends and replaces have row code; other kinds
** take their points one by one. */
#define OC_EROW 64
void oc_enode_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                     int want, double *f, double *a);
void oc_edisc_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                     int want, double *f, double *a);
/* a curve's: a row farther than its reach at once, else point by point */
void oc_ecurve_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                      int want, double *f, double *a);
/* blend and replace; 0 for the other operators (no row code) */
int oc_eop_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                  int want, double *f, double *a);
/* The range [*i0, *i1) of x[0..cnt) that k's box holds on the line y
** (oc_enode_holds' comparisons; x non-decreasing). */
void oc_enode_row_span(const oc_enode *k, const double *x, double y, int cnt,
                       int *i0, int *i1);

/* Kinds' parts (disc.c, eops.c): evaluation and bounds in a box. */
void oc_edisc_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                 int want, oc_enode_sample *s);
void oc_edisc_bound_in(const oc_enode *n, const oc_erect *b,
                       const oc_efootb *fb, oc_ebound *o);
void oc_ecurve_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                  int want, oc_enode_sample *s);
void oc_ecurve_bound_in(const oc_enode *n, const oc_erect *b,
                        const oc_efootb *fb, oc_ebound *o);
/* A replace's two queries of its curve B (eops.c, weight_taylor) in one:
** oc_ecurve_bound_in(n, b) in *o (its decision and f bound; alpha's range
** and slope tighter, from the distance found) and, where its weight is
** not 0 on b, oc_ecurve_ev(n, x, y, OC_EV_LAZY) in *s, (x, y) the centre
** of b, the same bits. Returns 0 where alpha = 0 on b (*s unset then);
** *boxes grows by the box queries it still makes (rare: ecurve.c). */
int oc_ecurve_weight_in(const oc_enode *n, double x, double y,
                        const oc_erect *b, oc_ebound *o, oc_enode_sample *s,
                        int *boxes);
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

/* First-order models (etaylor.h) of f and alpha around (x, y) for the
** radius R, full detail: f and alpha at (x, y) are the bits oc_enode_ev
** gives. Discs, blends, replaces, adds (without a slope weight) and
** transforms have rules; other nodes, and those rules where they have none
** (a blend whose weight crosses T on the disc...), take the flat model of
** oc_enode_taylor_flat: their value, no linear part, and the box bound on
** [x - R, x + R] x [y - R, y + R] (its slope times r, or its range). A
** curve's, lake's or image's f model holds only where its weight is > 0,
** as their bounds: operators compose it apart (eops.c). *boxes counts
** the box queries made. */
void oc_enode_taylor(const oc_enode *n, double x, double y, double R,
                     oc_etaylor *o, int *boxes);
/* What a model under a view knows of the footprint, in the node's local
** units: its value and gradient at p (p, as evaluation computes them:
** p.v > 0) and, over the disc |q - p| <= R, its range and Lipschitz
** bound (b). NULL: full detail. */
typedef struct oc_etfoot {
  oc_efoot p;
  oc_efootb b;
  /* The parts of tau = log2(w / foot)'s model (oc_elod_tau_taylor) that
  ** do not depend on w, for the disc of radius R (oc_etfoot_prep; R NaN:
  ** none): every disc under a node shares them, and they cost five
  ** divisions a disc (oc_elod_tau_taylor took 2.5 % of bench_elev_lod's
  ** LoD primary rays, perf). */
  double R, tc, dlo, dhi, e2;
  /* the norm of tau's linear part (oc_etay_gnorm of it), for the discs'
  ** ramping octaves (disc.c, noise_taylor_lod); log2(p.v), the discs'
  ** tau(p) being their lw minus it (oc_edisc_lw) */
  double tg, lf;
  int curved;
} oc_etfoot;
/* Fills tf's shared parts of tau's model for the disc of radius R (tf->p
** and tf->b set). */
void oc_etfoot_prep(oc_etfoot *tf, double R);
/* The prep of a similarity's child (scale s, disc radius Rc = R / s (1
** + 1e-12); cf->p and cf->b set, tf's footprints mapped into the
** child's units) from tf's for R (lod.c): tc and lf as
** oc_etfoot_prep(cf, Rc) makes them, the rest bounding its (dlo, dhi, e2
** and tg no less). */
void oc_etfoot_scaled(const oc_etfoot *tf, double R, double s, double Rc,
                      oc_etfoot *cf);
/* tf when it was prepared for R, else a copy of it in *own prepared for R. */
static inline const oc_etfoot *oc_etfoot_for(const oc_etfoot *tf, double R,
                                             oc_etfoot *own) {
  if (tf->R == R) return tf;
  *own = *tf;
  oc_etfoot_prep(own, R);
  return own;
}
/* oc_enode_taylor under a view (tf NULL: full detail, oc_enode_taylor):
** f and alpha at (x, y) are the bits oc_enode_ev gives with the footprint
** tf->p. Discs (continuous LoD), lod operators and the operators with
** rules have models under a view too (disc.c, lod.c); the others the flat
** one from their box bound under the footprints tf->b. */
void oc_enode_taylor_view(const oc_enode *n, double x, double y, double R,
                          const oc_etfoot *tf, oc_etaylor *o, int *boxes);
void oc_enode_taylor_flat(const oc_enode *n, double x, double y, double R,
                          const oc_etfoot *tf, oc_etaylor *o, int *boxes);
/* The tree's model of f as oc_elevation's taylor gives it (enode.c):
** returns f at (x, y), the linear part in g, the remainder (padded for
** rounding) in e; *boxes (when not NULL) grows by the box queries. */
double oc_enode_taylor_src(const oc_enode *n, double x, double y, double R,
                           const oc_etfoot *tf, double g[2], double e[3],
                           int *boxes);
void oc_edisc_taylor(const oc_enode *n, double x, double y, double R,
                     oc_etaylor *o);
/* A continuous-LoD disc's model under a view (disc.c); 0 where it has no
** rule (a filter ramps on a disc reaching a footprint of 0). */
int oc_edisc_taylor_lod(const oc_enode *n, double x, double y, double R,
                        const oc_etfoot *tf, oc_etaylor *o);
/* Its f model alone (tf NULL: oc_edisc_taylor_f's), for a caller that
** made alpha's (a blend); 0 where oc_edisc_taylor_lod has no rule. */
int oc_edisc_taylor_f_view(const oc_enode *n, double x, double y, double R,
                           const oc_etfoot *tf, oc_etay *f);
/* alpha's model alone (its value 0 where (x, y) is outside the disc),
** and f's alone: oc_edisc_taylor is the two */
void oc_edisc_taylor_alpha(const oc_enode *n, double x, double y, double R,
                           oc_etay *a);
void oc_edisc_taylor_f(const oc_enode *n, double x, double y, double R,
                       oc_etay *f);
/* 0 where the operator has no rule (tf: under a view, or NULL) */
int oc_eop_taylor(const oc_enode *n, double x, double y, double R,
                  const oc_etfoot *tf, oc_etaylor *o, int *boxes);
/* Whether n's f model holds only where its weight is > 0 (a curve's,
** lake's or image's, and operators' of one in A's place): its f model is
** not composed as it stands (eops.c, lod.c). */
static inline int oc_eop_taylor_partial(const oc_enode *n) {
  return (n->flags & OC_EF_PARTIAL) != 0; /* (set by oc_enode_alloc) */
}
/* alpha's model alone, as oc_enode_taylor's (discs, and operators whose
** weight has its own rule: blends, transforms, replaces and adds with A's
** weight); 0 for the others. */
int oc_enode_taylor_alpha(const oc_enode *n, double x, double y, double R,
                          oc_etay *a, int *boxes);
int oc_eop_taylor_alpha(const oc_enode *n, double x, double y, double R,
                        oc_etay *a, int *boxes);

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

/* The largest |b''| on [lo, hi]: b'' = 6 (1 - t^2) (1 - 5 t^2) on (0, 1),
** 0 outside; |b''| falls from 6 at 0 to 0 at 1 / sqrt 5, rises to 4.8 at
** sqrt(3/5) and falls to 0 at 1. */
static inline double oc_elod_bpp_max(double lo, double hi) {
  lo = oc_fmin(oc_fmax(lo, 0), 1), hi = oc_fmin(oc_fmax(hi, 0), 1);
  double ql = lo * lo, qh = hi * hi;
  double m = oc_fmax(fabs(6 * (1 - ql) * (1 - 5 * ql)),
                     fabs(6 * (1 - qh) * (1 - 5 * qh)));
  if (lo <= 0.7745966692414834 && hi >= 0.7745966692414834) m = oc_fmax(m, 4.8);
  return m * (1 + 1e-12);
}

/* oc_elod_b_taylor (lod.c: b composed with t's model by the chain rule,
** or the flat gap to b's far end where less) with bv and db =
** oc_elod_b(t->v): inline for the discs' filtered octaves, whose filter
** value they have already computed (one call and two b's fewer per
** ramping octave: the same bits). */
static inline oc_etay oc_elod_b_taylor_at(const oc_etay *t, double bv,
                                          double db, double lo, double hi,
                                          double R) {
  double d;
  if (hi <= 0 || lo >= 1) return oc_etay_const(bv);
  oc_etay m = oc_etay_compose(t, bv, db, oc_elod_bpp_max(lo, hi), R);
  /* b is non-decreasing: it stays in [b(lo), b(hi)] (the gap to the far
  ** end, flat, where that is less) */
  double gap = oc_fmax(bv - oc_elod_b(lo, &d), oc_elod_b(hi, &d) - bv);
  if (oc_etay_rem(&m, R) > gap) m = (oc_etay){bv, 0, 0, gap, 0, 0};
  return m;
}

/* The largest b' on [t0, t1] clamped to [0, 1]: b' = 6 t (1 - t^2)^2
** rises to its maximum 1.7173994704548507 at t = 1 / sqrt 5, then
** falls. */
static inline double oc_elod_bp_max(double t0, double t1) {
  t0 = oc_fmin(oc_fmax(t0, 0), 1);
  t1 = oc_fmin(oc_fmax(t1, 0), 1);
  if (t0 <= 0.44721359549995794 && t1 >= 0.44721359549995794)
    return 1.7173994704548507;
  double d0, d1;
  oc_elod_b(t0, &d0);
  oc_elod_b(t1, &d1);
  return oc_fmax(d0, d1) * (1 + 1e-12);
}

/* oc_elod_kappa_bound_t's range, and its Lipschitz bound from a factor c
** >= k / (ln 2 max(fb->lo, w / 2)) the caller made (|grad t| on the
** ramp): lip = max b' c. A disc's box bound makes c per octave from two
** constants a box (disc.c, noise_bounds: two divisions fewer an
** octave). */
static inline void oc_elod_kappa_bound_c(double tmin, double tmax, double c,
                                         double *lo, double *hi, double *lip) {
  double d;
  *lo = oc_elod_b(tmin, &d);
  *hi = oc_elod_b(tmax, &d);
  *lip = tmax <= 0 || tmin >= 1 ? 0 : oc_elod_bp_max(tmin, tmax) * c;
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

/* First-order models under a view (lod.c). tau = log2(w / foot) around
** p: its model (value log2(w / tf->p.v), as evaluation computes it) and
** its range [*lo, *hi] on the disc |q - p| <= R; returns 0 when the
** footprint may reach 0 there (no bound of tau's curvature: m's
** remainder is then left 0 and must not be used). The parts that do not
** depend on w come from tf when it was prepared for R (oc_etfoot_prep),
** else are made afresh: the same bits either way. */
int oc_elod_tau_taylor(double w, const oc_etfoot *tf, double R, oc_etay *m,
                       double *lo, double *hi);
/* log2 of a noisy disc's wavelength: under a view its octave i's t =
** log2(w_i / foot) is lw - log2(foot) - i dt, the footprint's log2 made
** once per query for every disc's model (oc_etfoot.lf) and the disc's
** made here inline (core/log2.h: within 2e-15 + 2^-52 |lw| of log2 w,
** the models' tau and the evaluation's t0 alike). glibc's log2 per disc
** model was 15-18 of its 130 ns (10 octaves, 5-7 of them kept); keeping
** lw in the disc saved them but cost 8 bytes a disc. */
static inline double oc_edisc_lw(const oc_enode *n) {
  return oc_log2(((const oc_edisc *)n)->wavelength);
}

/* The same for a disc, tau(p) = lw - tf->lf (oc_edisc_lw, its evaluation's
** t0 bit for bit), tf prepared for R (oc_etfoot_prep): a subtraction
** where a call of log2 per disc was (its latency stalled the LoD sum,
** whose octave counts it decides). */
static inline int oc_elod_tau_taylor_v(double v, const oc_etfoot *tf,
                                       oc_etay *m, double *lo, double *hi);
static inline int oc_elod_tau_taylor_l(double lw, const oc_etfoot *tf,
                                       oc_etay *m, double *lo, double *hi) {
  return oc_elod_tau_taylor_v(lw - tf->lf, tf, m, lo, hi);
}
/* tau's model from its value v at p, tf prepared for R: both rules' (the
** disc's lw - lf, the lod operator's log2(w / foot)). */
static inline int oc_elod_tau_taylor_v(double v, const oc_etfoot *tf,
                                       oc_etay *m, double *lo, double *hi) {
  *m = (oc_etay){v, tf->tc * tf->p.gx, tf->tc * tf->p.gy, 0, 0, 0};
  double pad = 1e-12 * (1 + fabs(v)); /* (against rounding) */
  *lo = v - tf->dlo - pad;
  *hi = tf->curved ? v + tf->dhi + pad : INFINITY;
  if (!tf->curved) return 0;
  m->e2 = tf->e2;
  return 1;
}
/* b(t) for the model t of an argument whose range on the disc is [lo,
** hi]: its value oc_elod_b(t->v). */
oc_etay oc_elod_b_taylor(const oc_etay *t, double lo, double hi, double R);
/* The lod operator's model under a view; 0 where it has no rule (full
** detail: the box bound, as before; partial children). */
int oc_elod_taylor(const oc_enode *n, double x, double y, double R,
                   const oc_etfoot *tf, oc_etaylor *o, int *boxes);

/* Noise: eta on z = 0 remapped to [-1, 1], and its Lipschitz bound. */
double oc_eta(uint64_t seed, double x, double y, double g[2]);
extern const double oc_eta_lipschitz;

#endif
