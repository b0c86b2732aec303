/*
** lfield.c — the convolution surface of a set of materials (Peytavie et
** al. 2009, section 3.3) as a node kind on the node-family seam
** (field/kind.h), and the visible material ratio for texturing (section
** 6) as another, at the end.
**
** The kernel is the cube Omega of half-side sigma (the paper's infinity
** norm), so the convolution is the volume V_M of the materials inside the
** cube, and in the engine's convention f = 2T V_M / V_Omega, V_Omega =
** 8 sigma^3: T where the cube is half full, 2T deep inside, 0 farther
** than sigma from any of them (the paper's 2 V_M / V_Omega - 1 shifted
** and scaled). Each stack keeps the z-intervals of the materials and the
** thickness below each, so V_M is a sum over the (at most (2 sigma /
** cell + 2)^2) stacks the cube overlaps of overlap area times
** F(z + sigma) - F(z - sigma), F found by binary search.
**
** Gradient: dV/dx is the signed area of the cube's faces x = +-sigma in
** material, here the x-overlap's derivative (+1, 0 or -1 per stack)
** times the rest; dV/dz the material area on the top face minus the
** bottom's. Exact off the layer and stack boundaries (the field is C0).
** Lipschitz: a face has area 4 sigma^2, so |grad V| <= sqrt 3 4 sigma^2
** and |grad f| <= sqrt 3 T / sigma. Column spans: f varies along a column
** only within sigma of a layer boundary, and across the footprint also
** where the stacks around disagree (a vertical wall).
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "field/kind.h"
#include "layers/layers.h"

typedef struct lfield {
  int nx, ny;
  double cell, X0, Y0; /* the corner of stack (0, 0) */
  double sigma, zlo, zhi;
  uint32_t *off; /* stack k: intervals off[k] .. off[k + 1] - 1 */
  double *iv;    /* a, b, thickness below a: 3 per interval */
} lfield;

enum { P_K, P_SIGMA, P_N }; /* K = 2T / V_Omega */

/* The material below z in intervals v[0 .. n - 1], and whether z is in
** one (*in). */
static double below(const double *v, uint32_t n, double z, int *in) {
  uint32_t lo = 0, hi = n;
  while (lo < hi) {
    uint32_t m = (lo + hi) / 2;
    if (v[3 * m] <= z)
      lo = m + 1;
    else
      hi = m;
  }
  if (lo == 0) {
    *in = 0;
    return 0;
  }
  const double *c = v + 3 * (lo - 1);
  *in = z < c[1];
  return c[2] + (*in ? z : c[1]) - c[0];
}

/* Stacks [*i0, *i1] overlapping [lo, hi] along one axis (empty: i0 > i1),
** and 1 when [lo, hi] reaches past the grid. */
static int axis_range(double lo, double hi, double X0, double s, int n, int *i0,
                      int *i1) {
  double a = floor((lo - X0) / s), b = floor((hi - X0) / s);
  *i0 = a < 0 ? 0 : a > n ? n : (int)a;
  *i1 = b < -1 ? -1 : b > n - 1 ? n - 1 : (int)b;
  return lo < X0 || hi > X0 + n * s;
}

/* V_M in the cube of half-side sigma around p, and its gradient in *g
** when g (unscaled: K f = K V). */
static double lf_volume(const lfield *d, oc_vec3 p, oc_vec3 *g) {
  double sg = d->sigma, s = d->cell;
  if (g) *g = (oc_vec3){0, 0, 0};
  if (p.z + sg <= d->zlo || p.z - sg >= d->zhi) return 0;
  int i0, i1, j0, j1;
  axis_range(p.x - sg, p.x + sg, d->X0, s, d->nx, &i0, &i1);
  axis_range(p.y - sg, p.y + sg, d->Y0, s, d->ny, &j0, &j1);
  double V = 0, gx = 0, gy = 0, gz = 0;
  for (int j = j0; j <= j1; j++) {
    double c0 = d->Y0 + j * s, c1 = c0 + s;
    double wy = fmin(p.y + sg, c1) - fmax(p.y - sg, c0);
    if (!(wy > 0)) continue;
    double dwy = (p.y + sg < c1) - (p.y - sg > c0);
    for (int i = i0; i <= i1; i++) {
      double e0 = d->X0 + i * s, e1 = e0 + s;
      double wx = fmin(p.x + sg, e1) - fmax(p.x - sg, e0);
      if (!(wx > 0)) continue;
      size_t q = (size_t)j * d->nx + i;
      uint32_t n = d->off[q + 1] - d->off[q];
      if (n == 0) continue;
      const double *v = d->iv + 3 * (size_t)d->off[q];
      int inhi, inlo;
      double D = below(v, n, p.z + sg, &inhi) - below(v, n, p.z - sg, &inlo);
      V += wx * wy * D;
      if (g) {
        double dwx = (p.x + sg < e1) - (p.x - sg > e0);
        gx += dwx * wy * D;
        gy += wx * dwy * D;
        gz += wx * wy * (inhi - inlo);
      }
    }
  }
  if (g) *g = (oc_vec3){gx, gy, gz};
  return V;
}

static double lf_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  if (g) *g = (oc_vec3){0, 0, 0};
  if (!(p.x == p.x && p.y == p.y && p.z == p.z)) return NAN;
  double K = k->par[P_K], V = lf_volume(k->data, p, g);
  if (g) *g = (oc_vec3){K * g->x, K * g->y, K * g->z};
  return K * V;
}

/* ---- local queries ----------------------------------------------------- */

#define EXACT_STACKS 4096
#define MAX_ZSPANS 256

/* 1 when no interval of the stacks under footprint [x0, x1] x [y0, y1]
** (grown by sigma) meets [z0 - sigma, z1 + sigma]; 0 when some may, or
** the footprint holds too many stacks to tell. */
static int lf_zero_box(const lfield *d, double x0, double y0, double x1,
                       double y1, double z0, double z1) {
  double sg = d->sigma;
  int i0, i1, j0, j1;
  axis_range(x0 - sg, x1 + sg, d->X0, d->cell, d->nx, &i0, &i1);
  axis_range(y0 - sg, y1 + sg, d->Y0, d->cell, d->ny, &j0, &j1);
  if (i0 > i1 || j0 > j1) return 1;
  if ((double)(i1 - i0 + 1) * (j1 - j0 + 1) > EXACT_STACKS) return 0;
  for (int j = j0; j <= j1; j++)
    for (int i = i0; i <= i1; i++) {
      size_t q = (size_t)j * d->nx + i;
      for (uint32_t l = d->off[q]; l < d->off[q + 1]; l++)
        if (d->iv[3 * l] < z1 + sg && d->iv[3 * l + 1] > z0 - sg) return 0;
    }
  return 1;
}

static int lf_zero_in(const oc_kctx *k, const oc_aabb *b) {
  return lf_zero_box(k->data, b->lo.x, b->lo.y, b->hi.x, b->hi.y, b->lo.z,
                     b->hi.z);
}

static double lf_lip_in(const oc_kctx *k, const oc_aabb *b) {
  return lf_zero_in(k, b) ? 0 : k->lip;
}

/* The union of the disjoint spans acc[0, n) (sorted) and add[0, na)
** (sorted by lower end), as disjoint sorted spans (touching ones joined)
** back in acc; tmp has room for n + na. The union is the same whatever
** order the spans come in: merging each stack's sorted list as it comes
** replaced sorting all of them (a qsort was 45 % of meshing a cave). */
static int union_spans(oc_zspan *acc, int n, const oc_zspan *add, int na,
                       oc_zspan *tmp) {
  int a = 0, b = 0, m = -1;
  while (a < n || b < na) {
    oc_zspan v =
        b >= na || (a < n && acc[a].lo <= add[b].lo) ? acc[a++] : add[b++];
    if (m >= 0 && v.lo <= tmp[m].hi)
      tmp[m].hi = fmax(tmp[m].hi, v.hi);
    else
      tmp[++m] = v;
  }
  memcpy(acc, tmp, (size_t)(m + 1) * sizeof *acc);
  return m + 1;
}

/* Whether stack q is in the materials at z. */
static int inside_at(const lfield *d, size_t q, double z) {
  int in;
  below(d->iv + 3 * (size_t)d->off[q], d->off[q + 1] - d->off[q], z, &in);
  return in;
}

static int lf_column(const oc_kctx *k, const oc_foot *f, oc_colq *q) {
  const lfield *d = k->data;
  double sg = d->sigma, pad = 1e-9 * (fabs(d->zlo) + fabs(d->zhi) + sg);
  int i0, i1, j0, j1;
  int out = axis_range(f->x0 - sg, f->x1 + sg, d->X0, d->cell, d->nx, &i0, &i1);
  out |= axis_range(f->y0 - sg, f->y1 + sg, d->Y0, d->cell, d->ny, &j0, &j1);
  if (i0 > i1 || j0 > j1) return 0;
  /* sp: the union so far; st: one stack's spans (sorted, as its layers
  ** are); at most MAX_ZSPANS spans in all, else one span for the range */
  oc_zspan sp[MAX_ZSPANS], st[MAX_ZSPANS], tmp[2 * MAX_ZSPANS];
  int n = 0, raw = 0,
      exact = (double)(i1 - i0 + 1) * (j1 - j0 + 1) <= EXACT_STACKS;
  double zmin = INFINITY, zmax = -INFINITY;
  for (int j = j0; j <= j1; j++)
    for (int i = i0; i <= i1; i++) {
      size_t s = (size_t)j * d->nx + i;
      int ns = 0;
      for (uint32_t l = d->off[s]; l < d->off[s + 1]; l++) {
        double a = d->iv[3 * l], b = d->iv[3 * l + 1];
        zmin = fmin(zmin, a);
        zmax = fmax(zmax, b);
        if (exact && raw + 2 <= MAX_ZSPANS) {
          st[ns++] = (oc_zspan){a - sg - pad, a + sg + pad};
          st[ns++] = (oc_zspan){b - sg - pad, b + sg + pad};
          raw += 2;
        } else {
          exact = 0;
        }
      }
      if (exact && ns) n = union_spans(sp, n, st, ns, tmp);
    }
  if (!(zmin <= zmax)) return 0; /* no material around: f = 0 */
  if (!exact) {
    oc_col_add(q, zmin - sg - pad, zmax + sg + pad);
    return 0;
  }
  for (int r = 0; r < n; r++) {
    oc_col_add(q, sp[r].lo, sp[r].hi);
    if (r + 1 == n) break;
    /* the gap above: constant along z; across the footprint too when
    ** every stack around (and the outside, empty) agrees */
    double z = 0.5 * (sp[r].hi + sp[r + 1].lo);
    int first = out ? 0 : inside_at(d, (size_t)j0 * d->nx + i0, z), agree = 1;
    for (int j = j0; j <= j1 && agree; j++)
      for (int i = i0; i <= i1 && agree; i++)
        agree = inside_at(d, (size_t)j * d->nx + i, z) == first;
    if (!agree) oc_col_add(q, sp[r].hi, sp[r + 1].lo);
  }
  return 0;
}

/* ---- the kind ------------------------------------------------------------ */

/* The support: the grid and the materials' z-range grown by sigma. */
static oc_aabb lf_box(const lfield *d) {
  double sg = d->sigma;
  return (oc_aabb){{d->X0 - sg, d->Y0 - sg, d->zlo - sg},
                   {d->X0 + d->nx * d->cell + sg, d->Y0 + d->ny * d->cell + sg,
                    d->zhi + sg}};
}

static int lf_compile(oc_kcompile *c, oc_error *err) {
  const lfield *d = c->data;
  double sg = d->sigma;
  (void)err;
  c->par[P_K] = 2 * c->T / (8 * sg * sg * sg);
  c->par[P_SIGMA] = sg;
  c->npar = P_N;
  c->info.lo = 0;
  c->info.hi = 2 * c->T;
  c->info.lip = sqrt(3.0) * c->T / sg * (1 + 1e-9);
  c->info.box = lf_box(d);
  return OC_OK;
}

static void lf_release(void *data) {
  lfield *d = data;
  if (!d) return;
  free(d->off);
  free(d->iv);
  free(d);
}

static const oc_kind_def layers_kind = {
    .name = "layers",
    .flags = OC_KF_PRIM,
    .compile = lf_compile,
    .eval = lf_eval,
    .lipschitz_in = lf_lip_in,
    .zero_in = lf_zero_in,
    .column = lf_column,
    .release = lf_release,
};

/* The intervals of the materials in mask (checked) with sigma (checked;
** NaN: one cell), or NULL with err. */
static lfield *lf_build(const oc_stacks *s, unsigned mask, double sigma,
                        oc_error *err) {
  if (mask == 0 || mask >= (1u << OC_MAT_COUNT) || (mask & 1u << OC_MAT_AIR)) {
    oc_seterr(err, OC_EINVAL,
              "'materials' must name at least one of water, sand, rocks, "
              "bedrock (not air)");
    return NULL;
  }
  if (isnan(sigma)) sigma = s->cell;
  if (!oc_check_positive(sigma, "sigma", err)) return NULL;
  size_t ns = (size_t)s->nx * s->ny, nl = oc_soff(s, ns);
  lfield *d = calloc(1, sizeof *d);
  if (d) {
    d->off = malloc((ns + 1) * sizeof *d->off);
    d->iv = malloc((nl ? nl : 1) * 3 * sizeof *d->iv);
  }
  if (!d || !d->off || !d->iv) {
    lf_release(d);
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  d->nx = s->nx;
  d->ny = s->ny;
  d->cell = s->cell;
  d->X0 = s->x0 - 0.5 * s->cell;
  d->Y0 = s->y0 - 0.5 * s->cell;
  d->sigma = sigma;
  d->zlo = INFINITY;
  d->zhi = -INFINITY;
  uint32_t n = 0;
  for (size_t k = 0; k < ns; k++) {
    d->off[k] = n;
    double z = s->zbase, below_z = 0;
    for (size_t l = oc_soff(s, k), lend = l + oc_scount(s, k); l < lend; l++) {
      double t = oc_lay_t(s->lay[l]), z1 = z + t;
      if (mask & 1u << oc_lay_m(s->lay[l])) {
        if (n > d->off[k] && d->iv[3 * (n - 1) + 1] == z) {
          d->iv[3 * (n - 1) + 1] = z1; /* continues the interval */
        } else {
          d->iv[3 * n] = z;
          d->iv[3 * n + 1] = z1;
          d->iv[3 * n + 2] = below_z;
          n++;
        }
        below_z += t;
        d->zlo = fmin(d->zlo, d->iv[3 * (d->off[k])]);
        d->zhi = fmax(d->zhi, z1);
      }
      z = z1;
    }
  }
  d->off[ns] = n;
  if (n == 0) d->zlo = d->zhi = s->zbase;
  return d;
}

oc_node *oc_stacks_field(const oc_stacks *s, unsigned mask, double sigma,
                         oc_error *err) {
  lfield *d = lf_build(s, mask, sigma, err);
  return d ? oc_kind_node(&layers_kind, NULL, 0, NULL, 0, d, err) : NULL;
}

/* ---- the visible material ratio (section 6) ------------------------------
**
** The share of the surface within the cube of half-side sigma around p
** whose exposed material is M. The surface of a stack is its exposed
** boundaries: the top of each solid run under air or water (or the stack's
** top) and the underside of each run over air or water (not at the base),
** each with the material of its solid layer. A stack counts by the area it
** shares with the cube's footprint (as the volume field) and each boundary
** at height b by the tent 1 - |b - z| / sigma, so that the weights are
** continuous in p:
**   S_M(p) = sum_stacks wx wy / (4 sigma^2) sum_{b of M} max(0, 1 - |b - z| /
*sigma)
** and f = S_M + EPS V_M / V_Omega: where no boundary is within sigma (a
** cliff face between its top and foot) the volume ratio decides, which
** the tiny EPS leaves unseen wherever a boundary is near. The blend
** normalises over the materials, so f is a weight, not a distance. */

#define VIS_EPS 1e-6

typedef struct vfield {
  lfield *v;     /* the intervals of M: V_M, support and zero tests */
  uint32_t *off; /* stack k: boundaries off[k] .. off[k + 1] - 1 */
  double *b;     /* the heights of M's exposed boundaries, bottom-up */
  int maxb;      /* the most boundaries of M in a stack */
} vfield;

static double vf_eval(const oc_kctx *k, oc_vec3 p, oc_vec3 *g) {
  const vfield *d = k->data;
  const lfield *l = d->v;
  double sg = l->sigma, s = l->cell, A = 4 * sg * sg;
  if (g) *g = (oc_vec3){0, 0, 0};
  if (!(p.x == p.x && p.y == p.y && p.z == p.z)) return NAN;
  if (p.z + sg <= l->zlo || p.z - sg >= l->zhi) return 0;
  int i0, i1, j0, j1;
  axis_range(p.x - sg, p.x + sg, l->X0, s, l->nx, &i0, &i1);
  axis_range(p.y - sg, p.y + sg, l->Y0, s, l->ny, &j0, &j1);
  double S = 0, gx = 0, gy = 0, gz = 0;
  for (int j = j0; j <= j1; j++) {
    double c0 = l->Y0 + j * s, c1 = c0 + s;
    double wy = fmin(p.y + sg, c1) - fmax(p.y - sg, c0);
    if (!(wy > 0)) continue;
    double dwy = (p.y + sg < c1) - (p.y - sg > c0);
    for (int i = i0; i <= i1; i++) {
      double e0 = l->X0 + i * s, e1 = e0 + s;
      double wx = fmin(p.x + sg, e1) - fmax(p.x - sg, e0);
      if (!(wx > 0)) continue;
      size_t q = (size_t)j * l->nx + i;
      double t = 0, dt = 0;
      for (uint32_t r = d->off[q]; r < d->off[q + 1]; r++) {
        double u = (d->b[r] - p.z) / sg;
        if (u >= 1) break;
        if (u <= -1) continue;
        t += 1 - fabs(u);
        dt += (u > 0) - (u < 0);
      }
      if (t == 0) continue;
      S += wx * wy * t;
      if (g) {
        double dwx = (p.x + sg < e1) - (p.x - sg > e0);
        gx += dwx * wy * t;
        gy += wx * dwy * t;
        gz += wx * wy * dt / sg;
      }
    }
  }
  oc_vec3 gv;
  double K = VIS_EPS / (2 * sg * A), V = lf_volume(l, p, g ? &gv : NULL);
  if (g)
    *g = (oc_vec3){gx / A + K * gv.x, gy / A + K * gv.y, gz / A + K * gv.z};
  return S / A + K * V;
}

static int vf_zero_in(const oc_kctx *k, const oc_aabb *b) {
  const vfield *d = k->data;
  return lf_zero_box(d->v, b->lo.x, b->lo.y, b->hi.x, b->hi.y, b->lo.z,
                     b->hi.z);
}

static double vf_lip_in(const oc_kctx *k, const oc_aabb *b) {
  return vf_zero_in(k, b) ? 0 : k->lip;
}

static int vf_compile(oc_kcompile *c, oc_error *err) {
  const vfield *d = c->data;
  const lfield *l = d->v;
  double sg = l->sigma;
  (void)err;
  c->npar = 0;
  c->info.lo = 0;
  c->info.hi = d->maxb + VIS_EPS;
  /* per stack |d t / dz| <= maxb / sigma, the overlap's slopes <= 1 over
  ** a footprint of side 2 sigma: each component <= maxb / sigma */
  c->info.lip = sqrt(3.0) * (d->maxb + VIS_EPS) / sg * (1 + 1e-9);
  c->info.box = lf_box(l);
  return OC_OK;
}

static void vf_release(void *data) {
  vfield *d = data;
  if (!d) return;
  lf_release(d->v);
  free(d->off);
  free(d->b);
  free(d);
}

static const oc_kind_def visible_kind = {
    .name = "layers_visible",
    .flags = OC_KF_PRIM,
    .compile = vf_compile,
    .eval = vf_eval,
    .lipschitz_in = vf_lip_in,
    .zero_in = vf_zero_in,
    .release = vf_release,
};

/* Air and water are gaps: what lies under a lake shows through it. */
static int is_gap(int m) {
  return m == OC_MAT_AIR || m == OC_MAT_WATER;
}

oc_node *oc_stacks_visible(const oc_stacks *s, int material, double sigma,
                           oc_error *err) {
  if (material <= OC_MAT_AIR || material >= OC_MAT_COUNT) {
    oc_seterr(err, OC_EINVAL,
              "'material' must be water, sand, rocks or "
              "bedrock");
    return NULL;
  }
  lfield *l = lf_build(s, 1u << material, sigma, err);
  if (!l) return NULL;
  size_t ns = (size_t)s->nx * s->ny, nl = oc_soff(s, ns);
  vfield *d = calloc(1, sizeof *d);
  if (d) {
    d->v = l;
    d->off = malloc((ns + 1) * sizeof *d->off);
    d->b = malloc((2 * nl + 1) * sizeof *d->b);
  }
  if (!d || !d->off || !d->b) {
    if (!d) lf_release(l);
    vf_release(d);
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  uint32_t n = 0;
  for (size_t k = 0; k < ns; k++) {
    d->off[k] = n;
    size_t l0 = oc_soff(s, k), lend = l0 + oc_scount(s, k);
    double z = s->zbase;
    for (size_t r = l0; r < lend; r++) {
      int m = oc_lay_m(s->lay[r]);
      double z1 = z + oc_lay_t(s->lay[r]);
      if (m == material && z1 > z) {
        /* the underside, over a gap (not the base) */
        if (r > l0 && is_gap(oc_lay_m(s->lay[r - 1]))) d->b[n++] = z;
        /* the top, under a gap or the sky */
        if (r + 1 == lend || is_gap(oc_lay_m(s->lay[r + 1]))) d->b[n++] = z1;
      }
      z = z1;
    }
    if ((int)(n - d->off[k]) > d->maxb) d->maxb = (int)(n - d->off[k]);
  }
  d->off[ns] = n;
  return oc_kind_node(&visible_kind, NULL, 0, NULL, 0, d, err);
}
