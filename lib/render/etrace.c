/*
** etrace.c — ray versus an elevation surface z = f(x, y).
**
** Along the ray p(t) = o + t u the height above the surface is
** h(t) = p_z(t) - f(p_xy(t)). Where |grad f| <= lambda on the xy box of a
** segment [t, t + delta], h changes along it at a rate of at least
** k = u_z - |u_xy| lambda, so when h > 0 the surface is not crossed
** before t + h / -k (k < 0), nor anywhere on the segment (k >= 0).
**  - The accelerated tracer (Génevaux et al. 2015, section 7.2) takes
**    lambda from the source's bound on that segment's box alone, skips
**    the segment at once when the ray stays above the box's elevation
**    range (and, descending, up to where it comes down to the range's
**    top, when that is farther than the slope's step), and doubles the
**    candidate delta after each step, so that it strides over flat ground
**    and far from the surface. A step the slope limits is over-relaxed
**    (kept only when the slope proves the stretch behind its sample free
**    too), and the range and slope come from one query (oc_elevation's
**    bound, when the source has it).
**    A source with first-order models (oc_elevation's taylor: elevation
**    trees) steps on them instead (march_taylor): at each sample one query
**    gives h, a linear part and a remainder on a disc around it, and the
**    step goes to the first zero of the height above that model, which
**    near the surface is Newton-like (the remainder is quadratic there).
**    Where a model is poor (ridged octaves folded along their ridges) or
**    not needed (high above the terrain), the ray takes the box bound's
**    steps on height calls instead.
**  - Sphere tracing (`OC_TRACE_SPHERE`, section 7.1) uses the slope bound of
**    the whole domain for every step: the baseline the paper compares to.
** Both clip the ray to the domain x [min f, max f] first, never step below
** the pixel-footprint tolerance of trace.c nor leave more than that
** unproved, and count a hit at the first sample on or below the surface
** (where the weight allows one), located between it and the sample
** before by samples with gradients (refine), the last of which above the
** surface gives the normal. A hole's edge (where
** the weight falls below T) is not bounded by the slopes: over a hole the
** steps are the slopes' as elsewhere (a ray may cross an edge within one
** step), and under its surface the tolerance, so that a ray passing under
** a hole meets its wall within that; on models, where the surface has a
** weight bound (oc_esurface's weight_bound), as far as that proves the
** ray still in the hole (hole_step), and the tolerance past it.
*/
#include <math.h>

#include "core/vec.h"
#include "render/etrace.h"
#include "render/trace.h"

#define GROW 2.0 /* candidate step after a step s: GROW s */
/* Over-relaxation of slope-limited steps (Keinert et al. 2014): a step of
** RELAX s is kept when the free stretch before its sample (h over the
** slope backwards) meets the stretch s proved free after the last one,
** else the ray goes back to the plain step. */
#define RELAX 1.6
/* A ray whose relaxed steps failed this often (the slope bound is tight
** there) goes on with plain steps. */
#define MAX_FAILS 1
/* The march on first-order models (march_taylor): the candidate after a
** step s is TGROW s, and a step the model limits is over-relaxed by
** TRELAX (kept when the model at its sample proves the stretch behind it
** free: a model covers a disc around its sample, backwards too). Measured
** on bench_elev -qq (calls a pixel, fig3 and fig22): TGROW 1.5, 2, 3 gave
** 14.5, 14.9, 17.1 and 17.4, 18.0, 20.5; TRELAX 1 (none), 1.4, 1.7, 2
** gave fig3 19.5, 16.0, 15.1, 20.1 (at TGROW 2); stopping a ray's
** relaxation after 1 or 3 failures 16.5 and 15.6 instead of 15.1. */
/* A relaxed step also goes a tolerance further (TRELAX s + tol), and
** its backward proof need only reach within the tolerance of the stretch
** proved before (the gap a tolerance step leaves unproved); a failed one
** samples a tolerance past that stretch, not at its end. Measured on
** bench_elev -q fig3 and fig22 (calls a pixel, 8.2 and 11.6 before):
** the backward allowance with the failed step's tolerance 8.1, 11.3;
** with the relaxed step's tolerance too 8.0, 11.1 (TRELAX 1.85 and 2
** then 8.7, 11.8 and 10.9, 15.0: the backward proof of a model reaches
** about as far as the forward one, s, so that 2 s fails); the tolerance
** step (proved < tol: proved + tol) up to proved < 1.43 tol 8.0, 11.3
** instead of the relaxed step's tolerance. With these, the beams'
** relaxation and model_back (calls of fig3 and fig22 together at -q):
** TRELAX 1.5, 1.6, 1.7, 1.8 gave 4512664, 4464520, 4495294, 4692554
** (fig1, fig19, fig20, fig21 10.25, 4.58, 10.78, 4.01 calls a pixel at
** 1.6, 10.28, 4.67, 10.77, 4.07 at 1.7); TGROW 1.4, 1.7 4513486,
** 4504874. */
#define TGROW 1.5
#define TRELAX 1.6
/* A ray on box steps turns to models where its step is under TSW of the
** candidate; on models, it asks the box bound too where the model's step
** is under TBOX of the candidate, and goes back to box steps when that
** proves more. Measured on bench_elev -qq (calls a pixel, fig1, fig3,
** fig21, fig22): TSW 0.25, 0.5, 0.9 gave 21.9, 15.9, 7.5, 17.8; 19.9,
** 14.5, 7.6, 16.9; 19.7, 14.4, 7.6, 16.9 (TBOX 0.25); TBOX 0.1, 0.25,
** 0.5 gave 19.9, 14.5, 7.6, 17.0; 19.9, 14.5, 7.6, 16.9; 19.7, 14.4,
** 7.6, 16.8 with 4 to 13 % more box queries (TSW 0.5). Under callgrind
** (fig3 and fig21) TSW 0.5 with TBOX 0.25 took 3.69 and 1.52 10^9
** instructions, 0.9 with 0.25 3.64 and 1.53, 0.9 with 0.1 3.44 and 1.51
** (the box queries cost fig3 more than the calls they save). A ray's
** relaxations are not limited (before the box steps, one failure a ray
** took fig3 to 15.2 calls and fig21 to 8.1). Since the beams' parts go
** on on models (oc_etrace_beam), at 1920 x 1080 (a pixel: calls, range
** queries; the replayed costs of both, us: fig3 0.42, 0.30; fig21 0.56,
** 0.37; fig22 0.84, 0.73; fig1 0.76, 0.66) TBOX 0.1, 0.01, 0 gave fig3
** 4.66, 0.55; 4.66, 0.37; 4.66, 0.35; fig21 4.72, 1.25; 4.71, 0.96;
** 4.86, 0.37; fig22 6.65, 0.61; 6.65, 0.33; 6.65, 0.29; and 0.1, 0 fig1
** 6.04, 0.59; 6.04, 0.33 (at -q fig19 and fig20 too the least cost at
** 0.01 or 0). 0.01 keeps the box for models that collapse (a step of 1 %
** of its candidate), where at 0 a ray crawls on them. */
#define TSW 0.9
#define TBOX 0.01
/* A beam on models (beam_models) starts from where its ranges stopped
** with a candidate of BEAM_STEP times its width there, and stops where
** its step falls under BSTOP times that width (its parts, or its rays,
** go on). Measured on bench_elev -qq fig3 (calls a pixel; blocks down to
** 2 pixels, rays starting on models): BSTOP 0.05, 0.1, 0.2, 0.4 gave
** 13.3, 12.9, 12.7, 12.7 (rays from box steps); BEAM_STEP 0.25, 0.5, 1
** gave 13.0, 12.9, 12.9 (BSTOP 0.1). */
#define BEAM_STEP 0.5
#define BSTOP 0.2
/* A beam's step its models limit is over-relaxed by BRELAX, kept when
** the model at its end proves every corner's ray free back to where the
** plain step would have ended (else the plain step). Measured on
** bench_elev -q fig3 and fig22 (calls a pixel, 8.0 and 11.1 without; the
** beams' calls of both 1126792 without): BRELAX 1.3, 1.5, 1.7, 1.85, 2
** gave 7.7, 10.6; 7.5, 10.5; 7.4, 10.4 (beams 804960); 7.4, 10.5; 8.1,
** 11.3. */
#define BRELAX 1.7
/* OC_ETRACE_REFINE_STOP (etrace.h): a hit is located to that fraction of the
** tolerance (refine). Measured on bench_elev -q fig3 (calls a pixel,
** refinement and normals): Illinois to 1e-3 with a normal call 10.8; samples
** with gradients (the normal from the last above the surface), 1e-3, 1e-2,
** 5e-2 gave 9.9, 9.6, 9.4 (5e-2 turned 14 normals by more than a degree).
** Since the models bracket hits (model_back), at 1920 x 1080 (bench_elev
** fig3, a pixel: refine's calls and model_hit's, all calls) 1e-2, 5e-2, 1e-1
** gave 0.72 and 0.29, 4.42; 0.50 and 0.35, 4.24; 0.41 and 0.37, 4.16: a
** model's bracket (its remainder, about e2 r^2 back from the sample) is
** mostly a few 1e-2 tolerances wide, so that 1e-2 took two calls in it where
** 5e-2 takes one. Of fig3's 1 181 717 hits, 5e-2 against 1e-2 moved the
** normals by 0.005 degrees on average (1 271 by more than 0.1, 34 by more
** than 1: crests) and the depths by 1e-6 of theirs; 1e-1 by 0.011 degrees
** (84 over 1) for 2 % fewer calls more, and the primary rays' CPU time was
** no lower (3.87, 3.88 s against 3.90, 4.02 s; 1e-2 4.02, 4.01 s, run in
** turns). The tolerance itself is a quarter pixel (render.c EPS_PIXEL): 5e-2
** of it is 1/80 of a pixel. */
/* A hit that the model of the sample under the surface locates alone
** (model_hit) takes its normal from that model's linear part g, no call,
** where the model's remainder is quadratic but for roundings: its g is
** then the gradient at the sample to within e1 + 2 sqrt(2 e0 e2) (from
** |(grad f - g).d| r <= e0 + e1 r + 2 e2 r^2, f's curvature within the
** model's, at the best r), at most GRAD_MODEL; the sample lies a
** tenth of a tolerance or so past the hit (AIM_PAST). Else a call at
** the hit, as before. On bench_elev fig3 at 1920 x 1080 the model-located
** hits' calls went from 0.35 to 0.0065 a pixel (all calls 4.24 -> 3.90),
** the normals moved by 0.07 degrees on average, 910 of 1 181 717 by more
** than 1 (at most 2.3: crests, where the normal turns that much within
** 1/40 of a pixel), the hits themselves not at all. */
#define GRAD_MODEL 1e-4
/* A ray on models whose next zero (by the model's linear part) is
** within a tolerance of the stretch it proved free samples AIM_PAST
** tolerances past it, at least AIM_LEAST tolerances on. Measured on
** bench_elev -q fig3 (calls a pixel, from 9.6): a tolerance past the
** proved stretch 9.4; AIM_PAST 0.03, 0.1, 0.2 (AIM_LEAST 0) 9.2, 9.1,
** 9.2; AIM_LEAST 0.25, 0.5 9.1, 9.2 (the floor keeps a ray grazing a
** ridge from stepping by hairs). */
#define AIM_PAST 0.1
#define AIM_LEAST 0.25

void oc_etracer_init(oc_etracer *tr, const oc_esurface *s,
                     oc_render_tracer mode, double eps_k, double eps_min) {
  const oc_elevation *src = s->src;
  double lo, hi;
  src->range(src->ud, src->x0, src->y0, src->x1, src->y1, &lo, &hi);
  /* a flat surface still needs a box with some height to clip against */
  double pad = 1e-9 * (1 + fmax(fabs(lo), fabs(hi)) + (hi - lo));
  tr->s = s;
  tr->mode = mode;
  tr->lo[0] = src->x0, tr->lo[1] = src->y0, tr->lo[2] = lo - pad;
  tr->hi[0] = src->x1, tr->hi[1] = src->y1, tr->hi[2] = hi + pad;
  tr->L = src->slope(src->ud, src->x0, src->y0, src->x1, src->y1);
  tr->eps_k = eps_k;
  tr->eps_min = eps_min;
  tr->refine = 1;
}

static inline oc_vec3 at(oc_vec3 o, oc_vec3 u, double t) {
  oc_vec3 p = {o.x + t * u.x, o.y + t * u.y, o.z + t * u.z};
  return p;
}

static inline double tol(const oc_etracer *tr, double d0, double t) {
  return tr->eps_k * (d0 + t) + tr->eps_min;
}

/* The unit upward normal of a surface whose height gradient is g. */
static oc_vec3 normal_of(const double g[2]) {
  oc_vec3 n = {-g[0], -g[1], 1};
  double l = sqrt(n.x * n.x + n.y * n.y + 1);
  if (!isfinite(l)) return (oc_vec3){0, 0, 1};
  return (oc_vec3){n.x / l, n.y / l, 1 / l};
}

int oc_etrace_clip(const double lo[3], const double hi[3], oc_vec3 o, oc_vec3 u,
                   double *t0, double *t1) {
  double a = *t0, b = *t1;
  const double oo[3] = {o.x, o.y, o.z}, uu[3] = {u.x, u.y, u.z};
  for (int k = 0; k < 3; k++) {
    if (uu[k] == 0) {
      if (oo[k] < lo[k] || oo[k] > hi[k]) return 0;
      continue;
    }
    double ta = (lo[k] - oo[k]) / uu[k], tb = (hi[k] - oo[k]) / uu[k];
    if (ta > tb) {
      double x = ta;
      ta = tb, tb = x;
    }
    /* (fmax and fmin to the bit, inline: they were library calls) */
    a = oc_fmax(a, ta);
    b = oc_fmin(b, tb);
  }
  if (!(a <= b)) return 0;
  *t0 = a, *t1 = b;
  return 1;
}

/* Whether a sample at height h above the surface at p is solid ground
** (above it, or where the surface exists: a hole has none), with the
** weight in *w when it was asked (else *w untouched). */
static int solid_weight(const oc_esurface *s, oc_vec3 p, double h, double *w) {
  if (h > 0 || !s->weight) return 1;
  *w = s->weight(s->wud, p.x, p.y);
  return *w >= s->T;
}

/* h at p, one height call; with solid, *solid: the weight allows a
** surface there, asked only under the surface (h <= 0 or NaN), the one
** place where a caller reads it. */
static double height_above(const oc_etracer *tr, oc_vec3 p, int *solid,
                           double *n) {
  const oc_esurface *s = tr->s;
  (*n)++;
  double h = p.z - s->src->height(s->src->ud, p.x, p.y, NULL);
  double w;
  if (solid) *solid = solid_weight(s, p, h, &w);
  return h;
}

/* h(a) = ha > 0 >= h(b) = hb: the root located to OC_ETRACE_REFINE_STOP of
** the tolerance, keeping the end above the surface (returned). Each sample is
** a height call with its gradient, whose derivative along the ray
** (u_z - grad f . u_xy) gives a Newton estimate of the root from it (the
** bracket's secant at first, or where Newton leaves the bracket); near
** an end of the bracket the next sample goes a little past the estimate,
** to close the bracket in one call. Where that does not halve the
** bracket in three samples, bisection. ga (when not NULL) gets the
** gradient at the returned end, *ga_ok whether a sample there gave it. */
static double refine(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double a,
                     double ha, double b, double hb, double d0, double *n,
                     double ga[2], int *ga_ok) {
  const oc_elevation *src = tr->s->src;
  double stop = OC_ETRACE_REFINE_STOP * tol(tr, d0, a);
  double r = a + (b - a) * (ha / (ha - hb)), w = b - a;
  for (int k = 0; k < 24 && b - a > stop; k++) {
    double m = r;
    if (r - a <= 0.6 * stop)
      m = r + 0.4 * stop; /* just past the root: closes the bracket */
    else if (b - r <= 0.6 * stop)
      m = r - 0.4 * stop;
    if (!(m > a && m < b) || (k % 3 == 2 && b - a > 0.5 * w)) m = 0.5 * (a + b);
    if (k % 3 == 2) w = b - a;
    oc_vec3 p = at(o, u, m);
    double g[2];
    (*n)++;
    double h = p.z - src->height(src->ud, p.x, p.y, g);
    if (h > 0) {
      a = m, ha = h;
      if (ga) ga[0] = g[0], ga[1] = g[1], *ga_ok = 1;
    } else {
      b = m, hb = h;
    }
    double kd = u.z - (g[0] * u.x + g[1] * u.y);
    r = kd < 0 ? m - h / kd : NAN;
    if (!(r > a && r < b)) r = a + (b - a) * (ha / (ha - hb));
  }
  return a;
}

/* The step from a sample at height h that the slope bound lam proves free
** of the surface on a candidate segment of length e. Under the surface
** (h <= 0, in a hole) nothing bounds the distance to the hole's wall: the
** ray goes on by the tolerance. */
static double safe_step(double h, double uz, double uxy, double lam, double e) {
  if (h > 0) {
    double k = uz - uxy * lam;
    return k >= 0 ? e : fmin(e, h / -k);
  }
  (void)uz, (void)uxy, (void)lam, (void)e;
  return 0; /* the tolerance: a hole's wall may be near */
}

/* fmin and fmax for the finite values of the loop below, where the
** library calls showed in profiles. */
static inline double lesser(double a, double b) {
  return a < b ? a : b;
}
static inline double greater(double a, double b) {
  return a > b ? a : b;
}

/* The first positive zero of c0 - c1 s - c2 s^2 (c0 > 0, c2 >= 0; none
** when there is none: c2 = 0 and c1 <= 0). */
static inline double first_root(double c0, double c1, double c2, double none) {
  if (c2 > 0) return 2 * c0 / (c1 + sqrt(c1 * c1 + 4 * c2 * c0));
  return c1 > 0 ? c0 / c1 : none;
}

/* The step from t that a first-order model of f around the sample proves
** free (etaylor.h): for q = p + t u, r = t |u_xy| and, with the model's
** linear part g, h(p + t u) >= h + k t - E(r), k = u_z - g.u_xy; its
** first zero on [0, e], where c0 = h - e0 > 0, c1 = e1 |u_xy| - k and c2
** = e2 |u_xy|^2 >= 0 (the smallest positive root of c0 - c1 t - c2 t^2). */
static double model_step(double h, const double g[2], const double E[3],
                         oc_vec3 u, double uxy, double e) {
  double c0 = h - E[0];
  if (!(c0 > 0)) return 0;
  double k = u.z - (g[0] * u.x + g[1] * u.y);
  double c1 = E[1] * uxy - k, c2 = E[2] * uxy * uxy;
  return lesser(first_root(c0, c1, c2, e), e);
}

/* The step along q0 + s D (s >= 0) that the model m proves free of the
** surface, up to smax: the first zero of its lower bound on the height,
** L(q) = q_z - f - g.(q - p)_xy - E(|q - p|_xy) <= h(q), where |q -
** p|_xy <= ra + s |D_xy| (ra = |q0 - p|_xy; E is nondecreasing), so
** that L >= c0 - c1 s - c2 s^2 (model_step's form, *c0 the bound at q0),
** and no farther than the model's disc; 0 where L(q0) <= 0 or q0 is off
** the disc. dxy is hypot(D.x, D.y), which the callers have already. */
static double model_free(const oc_emodel *m, oc_vec3 q0, oc_vec3 D, double dxy,
                         double smax, double *lo) {
  double ax = q0.x - m->x, ay = q0.y - m->y, ra = hypot(ax, ay);
  const double *g = m->g, *E = m->E;
  *lo = 0;
  if (!(ra < m->R)) return 0;
  double c0 =
      q0.z - m->f - (g[0] * ax + g[1] * ay) - (E[0] + ra * (E[1] + ra * E[2]));
  if (!(c0 > 0)) return 0;
  *lo = c0;
  if (dxy > 0) smax = lesser(smax, (m->R - ra) / dxy);
  double k = D.z - (g[0] * D.x + g[1] * D.y);
  double c1 = (E[1] + 2 * E[2] * ra) * dxy - k, c2 = E[2] * dxy * dxy;
  /* a hair short of the zero, where L may be 0 */
  return lesser(first_root(c0, c1, c2, smax), smax) * (1 - 1e-9);
}

/* The step the candidate segment's box bound proves from a sample at
** height h (march's rule): *slope the slope's step (and *lam its bound),
** the step returned is that or, for a descending ray, the way down to the
** highest elevation the box holds when that is longer. */
static double box_step(const oc_etracer *tr, oc_vec3 p, oc_vec3 u, double uxy,
                       double h, double e, double *slope, double *lam) {
  const oc_elevation *src = tr->s->src;
  oc_vec3 q = at(p, u, e);
  double x0 = lesser(p.x, q.x), x1 = greater(p.x, q.x);
  double y0 = lesser(p.y, q.y), y1 = greater(p.y, q.y);
  double lo, hi;
  *lam = -1;
  if (src->bound)
    src->bound(src->ud, x0, y0, x1, y1, &lo, &hi, lam);
  else
    src->range(src->ud, x0, y0, x1, y1, &lo, &hi);
  if (lesser(p.z, q.z) > hi) { /* above everything the box holds */
    *slope = -1;
    return e;
  }
  if (*lam < 0) *lam = src->slope(src->ud, x0, y0, x1, y1);
  double s = safe_step(h, u.z, uxy, *lam, e);
  *slope = s;
  if (p.z > hi) s = greater(s, (p.z - hi) / -u.z);
  return s;
}

/* The stretch from p, in a hole (its weight w < T), on a candidate
** segment e that the surface's weight bound proves still in the hole (no
** surface, hence no hit, there): all of it where the segment's box holds
** no weight up to T, else as far as the weight's slope lets it rise to T
** (an xy distance of (T - w) / lip); 0 (the tolerance, as before) without
** a weight bound. */
static double hole_step(const oc_etracer *tr, oc_vec3 p, oc_vec3 u, double uxy,
                        double w, double e) {
  const oc_esurface *s = tr->s;
  if (!s->weight_bound || !(w < s->T)) return 0;
  oc_vec3 q = at(p, u, e);
  double lo, hi, lip;
  s->weight_bound(s->wud, lesser(p.x, q.x), lesser(p.y, q.y), greater(p.x, q.x),
                  greater(p.y, q.y), &lo, &hi, &lip);
  if (hi < s->T || uxy * e * lip < s->T - w) return e;
  if (!(lip > 0)) return 0; /* NaN */
  /* a hair short, where the weight may reach T */
  return (s->T - w) / (lip * uxy) * (1 - 1e-9);
}

/* The hit before a sample under the surface (h < 0) located on its model
** (linear part g, remainder E), no call: back along the ray by s, the
** height is within h - k s -+ E(s |u_xy|) (k its slope along u by the
** model), so that it is above the surface at s_lo, where the lower bound
** turns positive, and under it before s_hi, where the upper one does;
** the lower bound stays positive back to s_lo2, its second zero. When
** s_lo <= smax (the model's disc, the bracket), those and 1: the hit is
** in [t - s_lo, t], a bracket of no call (located there when s_lo - s_hi
** is within refine's stop, model_hit). Measured on bench_elev -q (calls
** a pixel, fig3 and fig22, from 7.40 and 10.40, where the model located
** a hit only within the stop and a relaxed sample under the surface sent
** the ray back to its plain step): refine from [t - s_lo, t] instead of
** the samples' bracket 7.35, 10.35; a relaxed sample under the surface
** taken as the hit's bracket when s_lo2 reaches the stretch proved before
** it 7.19, 10.23; both 7.15, 10.19. */
static int model_back(double h, const double g[2], const double E[3], oc_vec3 u,
                      double uxy, double smax, double *s_lo, double *s_hi,
                      double *s_lo2) {
  double k = u.z - (g[0] * u.x + g[1] * u.y), A = E[2] * uxy * uxy;
  double B = -(k + E[1] * uxy), C = h - E[0]; /* L = C + B s - A s^2 */
  double D = B * B + 4 * A * C;
  if (!(C < 0 && B > 0 && D >= 0)) return 0;
  double lo = -2 * C / (B + sqrt(D)) * (1 + 1e-9);
  double Bh = -k + E[1] * uxy, Ch = h + E[0],
         hi = 0; /* U = Ch + Bh s + A s^2 */
  if (Ch < 0) hi = -2 * Ch / (Bh + sqrt(Bh * Bh - 4 * A * Ch));
  if (!(lo <= smax)) return 0;
  *s_lo = lo, *s_hi = hi;
  /* L's second zero, a hair short: L > 0 between the two */
  *s_lo2 = A > 0 ? (B + sqrt(D)) / (2 * A) * (1 - 1e-9) : INFINITY;
  return 1;
}

/* The hit in [t - s_lo, t] (model_back's: a point above the surface, the
** sample under it, the ray above the surface before them as far as the
** tolerance allows): on the model when s_lo - s_hi is within refine's
** stop (the normal, when ga is asked for, the model's own where it is
** quadratic, GRAD_MODEL, else a call at t - s_lo), else refine from that
** bracket, its upper end at the model's linear estimate there. */
static double model_hit(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double t,
                        double h, const double g[2], const double E[3],
                        double s_lo, double s_hi, double d0, double *n,
                        double ga[2], int *ga_ok) {
  const oc_elevation *src = tr->s->src;
  double a = t - s_lo;
  if (s_lo - s_hi <= OC_ETRACE_REFINE_STOP * tol(tr, d0, a)) {
    if (!ga) return a;
    if (E[1] + 2 * sqrt(2 * E[0] * E[2]) <= GRAD_MODEL) {
      ga[0] = g[0], ga[1] = g[1], *ga_ok = 1;
      return a;
    }
    oc_vec3 q = at(o, u, a);
    double gq[2];
    (*n)++;
    src->height(src->ud, q.x, q.y, gq);
    if (ga) ga[0] = gq[0], ga[1] = gq[1], *ga_ok = 1;
    return a;
  }
  double k = u.z - (g[0] * u.x + g[1] * u.y);
  return refine(tr, o, u, a, greater(h - k * s_lo, 0), t, h, d0, n, ga, ga_ok);
}

/* The accelerated march with the source's first-order models. A ray
** samples in one of two ways: a model query (h there and the step
** model_step proves over a candidate segment TGROW times the last step),
** or a height call and the candidate's box bound (march's step, RELAX and
** GROW). A ray starts on box steps (cheap while it is high above the
** terrain) and turns to models where a box step is short (under TSW of
** its candidate: a slope limits it, the model's is Newton-like there);
** where a model step is under TBOX of its candidate (collapsed there),
** the box bound is asked too and the longer step taken, and when the
** box's wins the ray goes back to box steps (the model is poor there:
** octaves folded by |eta|, whose sign the model cannot prove). A
** relaxed step's sample is kept only when its own proof (the model over
** a disc reaching back to where the last proof ended, a descending ray
** rising backwards; or the slope as march) shows the stretch behind it
** free (on models, up to a tolerance's gap); else the ray takes the plain
** step (on models, a tolerance past it), unless the sample is under the
** surface and its model proves the ray above it back to that stretch:
** then the hit is bracketed there (model_back). Steps, hits, holes and
** walls are march's. */
static int march_taylor(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double t,
                        double t1, double d0, double delta0,
                        const oc_emodel *m0, double *thit, double *n,
                        double ga[2], int *ga_ok) {
  const oc_elevation *src = tr->s->src;
  double uxy = hypot(u.x, u.y), delta = (t1 - t) / 16, prev = t, hp = 0;
  oc_vec3 ub = {-u.x, -u.y, -u.z};
  int have_prev = 0, relaxed = 0, model = 0;
  if (delta0 > 0) delta = delta0, model = 1;
  if (model && m0 && m0->ok) {
    /* a first step on the beam's model, no call: from t, where the
    ** height is at least lo > 0 */
    double lo, s = model_free(m0, at(o, u, t), u, uxy, t1 - t, &lo);
    if (s > 0) {
      prev = t, hp = lo, have_prev = 1;
      t += s;
      if (t >= t1) return 0;
    }
  }
  double rsafe = 0, rlam = 0; /* a relaxed step's proved part and slope */
  double rtl = 0;
  for (long k = 0; k < OC_TRACE_MAX_STEPS; k++) {
    oc_vec3 p = at(o, u, t);
    double e = lesser(delta, t1 - t), g[2], E[3], h;
    double back = relaxed ? t - (prev + rsafe) : 0, mR = greater(e, back) * uxy;
    (*n)++;
    if (model)
      h = p.z - src->taylor(src->ud, p.x, p.y, mR, g, E, NULL);
    else
      h = p.z - src->height(src->ud, p.x, p.y, NULL);
    if (h != h) return 0; /* NaN: no surface can be located */
    if (relaxed) {
      relaxed = 0;
      double kb = u.z + uxy * rlam;
      /* (on models the proof may stop short of the stretch proved
      ** before by the tolerance there, rtl: a tolerance step's gap) */
      int ok = model ? h > 0 && model_step(h, g, E, ub, uxy, back) >= back - rtl
                     : h > 0 && (kb <= 0 || prev + rsafe + h / kb >= t);
      if (!ok && model && tr->refine) {
        /* under the surface: its model proves the ray above it back
        ** from s_lo to s_lo2; where that reaches the stretch proved
        ** before (to its tolerance), the hit is the crossing after s_lo */
        double w = 1, lo, hi, lo2;
        if (h <= 0 && solid_weight(tr->s, p, h, &w) &&
            model_back(h, g, E, u, uxy, back, &lo, &hi, &lo2) &&
            lesser(lo2, uxy > 0 ? mR / uxy : INFINITY) >= back - rtl) {
          *thit = model_hit(tr, o, u, t, h, g, E, lo, hi, d0, n, ga, ga_ok);
          return 1;
        }
      }
      if (!ok) {
        t = prev + rsafe; /* not proved: the plain step */
        /* on models, a tolerance past it (unproved as a tolerance step),
        ** unless the ray is under the surface there */
        if (model && h > 0 && back > rtl) t += rtl;
        delta = (model ? TGROW : GROW) * rsafe;
        continue;
      }
    }
    double w = 1;
    int solid = solid_weight(tr->s, p, h, &w);
    if (solid && h <= 0) {
      if (!(have_prev && hp > 0)) {
        *thit = t; /* through a side of the domain or of a hole */
        return 2;
      }
      double lo, hi, lo2;
      if (tr->refine && model &&
          model_back(h, g, E, u, uxy,
                     uxy > 0 ? lesser(t - prev, mR / uxy) : t - prev, &lo, &hi,
                     &lo2)) {
        *thit = model_hit(tr, o, u, t, h, g, E, lo, hi, d0, n, ga, ga_ok);
        return 1;
      }
      *thit =
          tr->refine ? refine(tr, o, u, prev, hp, t, h, d0, n, ga, ga_ok) : t;
      return 1;
    }
    /* under the surface in a hole: as far as the weight's bound proves
    ** the ray still in it, else the tolerance (its wall may be near) */
    double proved = 0, slope = -1, lam = 0;
    int next = model;
    if (model) {
      proved = h > 0 ? model_step(h, g, E, u, uxy, e) : 0;
      if (h > 0 && proved < TBOX * e) {
        double b = box_step(tr, p, u, uxy, h, e, &slope, &lam);
        if (b > proved) proved = b, next = 0;
      }
    } else if (h > 0) {
      proved = box_step(tr, p, u, uxy, h, e, &slope, &lam);
      if (proved < TSW * e) next = 1;
    }
    if (!solid) proved = hole_step(tr, p, u, uxy, w, e);
    proved = lesser(proved, e);
    double tl = tol(tr, d0, t), s = greater(proved, tl);
    /* a model proving less than the tolerance: the sample a tolerance
    ** past its proof (as unproved as a tolerance step from t, and no
    ** crawl by tolerances where the model's curvature bound is tight) */
    if (model && next && h > 0 && proved < tl) s = proved + tl;
    if (model && next && h > 0 && proved < e) {
      /* the zero z of the model's linear part (a Newton step) within a
      ** tolerance past the proved stretch: the sample goes AIM_PAST
      ** tolerances past z, likely just under the surface, so that the
      ** hit's bracket is short (not nearer than AIM_LEAST tolerances,
      ** nor farther than one past the proved stretch: unproved no longer
      ** than a tolerance step from there) */
      double k = u.z - (g[0] * u.x + g[1] * u.y);
      if (k < 0 && h < -k * (proved + tl))
        s = lesser(proved + tl, greater(greater(proved, AIM_LEAST * tl),
                                        h / -k + AIM_PAST * tl));
    }
    if (t + s == t || t + proved >= t1 || t >= t1) return 0; /* left it */
    if (t + s > t1) s = t1 - t; /* (as march: sample the box's end) */
    prev = t, hp = h, have_prev = 1;
    if (next == model && h > 0 && proved < e && s == proved) {
      /* limited by the model or the slope: try a longer step */
      if (model) {
        double r = lesser(TRELAX * s + tl, t1 - t);
        if (r > s) relaxed = 1, rsafe = s, rtl = tol(tr, d0, t + s), s = r;
        delta = TGROW * rsafe;
      } else if (s == slope) {
        double r = lesser(RELAX * s, e);
        if (r > s) relaxed = 1, rsafe = s, rlam = lam, s = r;
      }
    }
    if (next)
      delta = TGROW * (relaxed ? rsafe : s);
    else
      delta = GROW * (slope >= 0 ? greater(slope, tol(tr, d0, t + s)) : s);
    model = next;
    t += s;
  }
  return 0;
}

static int march(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double t,
                 double t1, double d0, double delta0, const oc_emodel *m0,
                 double *thit, double *n, double ga[2], int *ga_ok) {
  if (tr->mode == OC_TRACE_SEGMENT && tr->s->src->taylor)
    return march_taylor(tr, o, u, t, t1, d0, delta0, m0, thit, n, ga, ga_ok);
  const oc_elevation *src = tr->s->src;
  double uxy = hypot(u.x, u.y), delta = (t1 - t) / 16, prev = t, hp = 0;
  int accel = tr->mode == OC_TRACE_SEGMENT, have_prev = 0, relaxed = 0;
  double rsafe = 0, rlam = 0; /* a relaxed step's plain step and slope */
  if (delta0 > 0) delta = delta0;
  int fails = 0; /* of relaxed steps on this ray */
  for (long k = 0; k < OC_TRACE_MAX_STEPS; k++) {
    oc_vec3 p = at(o, u, t);
    int solid;
    double h = height_above(tr, p, &solid, n);
    if (h != h) return 0; /* NaN: no surface can be located */
    if (relaxed) {
      /* from t back to prev + rsafe the ray is free when h > 0 and
      ** h / (u_z + |u_xy| lambda) reaches there (the slope holds on the
      ** box of the whole candidate) */
      double kb = u.z + uxy * rlam;
      relaxed = 0;
      if (!(h > 0 && (kb <= 0 || prev + rsafe + h / kb >= t))) {
        t = prev + rsafe; /* not proved: the plain step */
        fails++;
        continue;
      }
    }
    if (solid && h <= 0) {
      if (!(have_prev && hp > 0)) {
        *thit = t; /* through a side of the domain or of a hole */
        return 2;
      }
      *thit =
          tr->refine ? refine(tr, o, u, prev, hp, t, h, d0, n, ga, ga_ok) : t;
      return 1;
    }
    double s, grow = -1, rlam_of_step = 0;
    if (accel) {
      double e = lesser(delta, t1 - t);
      oc_vec3 q = at(o, u, t + e);
      double x0 = lesser(p.x, q.x), x1 = greater(p.x, q.x);
      double y0 = lesser(p.y, q.y), y1 = greater(p.y, q.y);
      double lo, hi, lam = -1;
      if (src->bound)
        src->bound(src->ud, x0, y0, x1, y1, &lo, &hi, &lam);
      else
        src->range(src->ud, x0, y0, x1, y1, &lo, &hi);
      if (lesser(p.z, q.z) > hi) {
        s = e; /* above everything the segment's box holds */
      } else {
        if (lam < 0) lam = src->slope(src->ud, x0, y0, x1, y1);
        s = safe_step(h, u.z, uxy, lam, e);
        rlam_of_step = lam;
        /* a descending ray is free, too, until it comes down to hi (the
        ** candidate grows from the slope's step: the range's may end
        ** right above a slope) */
        grow = s;
        if (p.z > hi) s = greater(s, (p.z - hi) / -u.z);
      }
    } else {
      s = safe_step(h, u.z, uxy, tr->L, t1 - t);
    }
    double proved = s; /* free of the surface up to t + proved */
    s = greater(s, tol(tr, d0, t));
    if (t + s == t || t + proved >= t1 || t >= t1) return 0; /* left it */
    /* the tolerance would step out of the box: sample its end, where a
    ** floor at the box's lowest elevation is (a ray leaves through the
    ** bottom just under it) */
    if (t + s > t1) s = t1 - t;
    prev = t, hp = h, have_prev = 1;
    if (accel && fails < MAX_FAILS && grow >= 0 && h > 0 && s == grow) {
      /* limited by the slope: try a longer step within the candidate */
      double e = lesser(delta, t1 - t), r = lesser(RELAX * s, e);
      if (r > s) {
        relaxed = 1, rsafe = s, rlam = rlam_of_step;
        s = r;
      }
    }
    t += s;
    delta = GROW * (grow >= 0 ? greater(grow, tol(tr, d0, t)) : s);
  }
  return 0;
}

/* The unit upward normal at (x, y) from the height gradient: one height
** call, counted in *evals. */
static oc_vec3 esurface_normal(const oc_esurface *s, double x, double y,
                               double *evals) {
  double g[2] = {0, 0};
  s->src->height(s->src->ud, x, y, g);
  (*evals)++;
  return normal_of(g);
}

int oc_etrace(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double t0, double t1,
              double d0, double *t, double *evals) {
  return oc_etrace_hit(tr, o, u, t0, t1, d0, 0, NULL, t, NULL, evals);
}

int oc_etrace_hit(const oc_etracer *tr, oc_vec3 o, oc_vec3 u, double t0,
                  double t1, double d0, double step, const oc_emodel *m,
                  double *t, oc_vec3 *nrm, double *evals) {
  *t = INFINITY;
  double ts = t0;
  if (!oc_etrace_clip(tr->lo, tr->hi, o, u, &t0, &t1)) return 0;
  /* entering the box after the start: the step does not apply */
  if (t0 > ts) step = 0;
  double g[2];
  int g_ok = 0;
  int hit =
      march(tr, o, u, t0, t1, d0, step, m, t, evals, nrm ? g : NULL, &g_ok);
  if (!hit) *t = INFINITY;
  if (hit == 1 && nrm) {
    if (g_ok) {
      *nrm = normal_of(g);
    } else {
      oc_vec3 p = at(o, u, *t);
      *nrm = esurface_normal(tr->s, p.x, p.y, evals);
    }
  }
  return hit;
}

/* ---- beams ---------------------------------------------------------------
** A beam's piece between depths da and db is convex (the image of the
** polytope da <= d <= db, d x0 <= X <= d x1, d y0 <= Y <= d y1 by the
** linear map (d, X, Y) -> o + d w + X r + Y v), so its box and lowest
** point are those of its 8 vertices. Where the piece lies above the
** highest elevation the source gives for that box (or outside the
** domain), none of its rays meets the surface there: the beam strides
** on, doubling, and halves where that fails, down to about its own width
** (below which a box stops shrinking with the step). */

/* The direction of the beam's ray through (x, y) of its image plane. */
static oc_vec3 beam_dir(const oc_ebeam *b, double x, double y) {
  oc_vec3 D = {b->w.x + x * b->r.x + y * b->v.x,
               b->w.y + x * b->r.y + y * b->v.y,
               b->w.z + x * b->r.z + y * b->v.z};
  return D;
}

/* The directions of the beam's 4 corner rays, corner j through (j & 1 ?
** x1 : x0, j & 2 ? y1 : y0): computed once a beam, not at every piece's
** 8 vertices. */
static void beam_corners(const oc_ebeam *b, oc_vec3 D[4]) {
  for (int j = 0; j < 4; j++)
    D[j] = beam_dir(b, j & 1 ? b->x1 : b->x0, j & 2 ? b->y1 : b->y0);
}

static void piece_box(const oc_ebeam *b, const oc_vec3 corner[4], double da,
                      double db, double lo[3], double hi[3]) {
  /* in locals, unrolled: lo and hi may alias *b for the compiler, which
  ** then reloaded b->o at every vertex */
  const oc_vec3 o = b->o;
  double lx = INFINITY, ly = INFINITY, lz = INFINITY;
  double hx = -INFINITY, hy = -INFINITY, hz = -INFINITY;
  for (int k = 0; k < 8; k++) {
    double d = k & 1 ? db : da;
    oc_vec3 D = corner[k >> 1];
    double px = o.x + d * D.x, py = o.y + d * D.y, pz = o.z + d * D.z;
    lx = lesser(lx, px), hx = greater(hx, px);
    ly = lesser(ly, py), hy = greater(hy, py);
    lz = lesser(lz, pz), hz = greater(hz, pz);
  }
  /* rounding of the vertices: a relative hair outward */
  double pad = 1e-9 * (fabs(lx) + fabs(hx));
  lo[0] = lx - pad, hi[0] = hx + pad;
  pad = 1e-9 * (fabs(ly) + fabs(hy));
  lo[1] = ly - pad, hi[1] = hy + pad;
  pad = 1e-9 * (fabs(lz) + fabs(hz));
  lo[2] = lz - pad, hi[2] = hz + pad;
}

/* 1 when no ray of the piece whose box is lo, hi meets the surface. */
static int piece_free(const oc_etracer *tr, const double lo[3],
                      const double hi[3], double *bounds) {
  double x0 = greater(lo[0], tr->lo[0]), x1 = lesser(hi[0], tr->hi[0]);
  double y0 = greater(lo[1], tr->lo[1]), y1 = lesser(hi[1], tr->hi[1]);
  if (!(x0 <= x1 && y0 <= y1) || lo[2] > tr->hi[2] || hi[2] < tr->lo[2])
    return 1; /* outside the domain's box */
  const oc_elevation *src = tr->s->src;
  double flo, fhi, lam;
  if (bounds) (*bounds)++;
  if (src->bound)
    src->bound(src->ud, x0, y0, x1, y1, &flo, &fhi, &lam);
  else
    src->range(src->ud, x0, y0, x1, y1, &flo, &fhi);
  return lo[2] > fhi;
}

/* The beam on the source's first-order models, from depth d (proved
** free before it) with a candidate step e; returns the depth it proves
** free (INFINITY past far). At each step one model query at the point p
** of the beam's axis (its centre ray) at depth d, for a disc holding the
** candidate piece [d, d + e]: with the model's linear part g and
** remainder E, h(q) >= L(q) = q_z - f(p) - g.(q - p)_xy - E(|q - p|_xy)
** on the disc, and L is concave in q (E is convex and nondecreasing in
** r, r convex in q), so its least value on the piece (a convex polytope)
** is at one of its 8 vertices: the 4 corner rays at depths d and d + s.
** Corner j at depth d + s is q - p = a_j + s D_j (a_j = d (D_j - c)),
** where L >= c0 - c1 s - c2 s^2 with E bounded at |a_j,xy| + s
** |D_j,xy|; c0 > 0 is the corner's own height above the model at depth
** d, and the step is the least first root over the corners. The margin
** (a_j: the beam's radius at d, and its growth with s in D_j - c) is
** what makes this a proof for every ray of the beam, not the axis alone.
** The beam stops where a corner is not proved above the model at d or
** the step falls under BSTOP of the beam's width there (its rays' hits
** then differ: its parts go on). A step the models limit is relaxed as a
** ray's (BRELAX), the corners' bounds at its end run backwards (their
** rays' direction reversed) proving the stretch behind it. */
static double beam_models(const oc_etracer *tr, const oc_ebeam *b,
                          const oc_vec3 D[4], double d, double far, double e,
                          double *evals, double *next, oc_emodel *m) {
  const oc_elevation *src = tr->s->src;
  oc_vec3 c = beam_dir(b, 0.5 * (b->x0 + b->x1), 0.5 * (b->y0 + b->y1));
  double dxy[4], bxy[4]; /* |(D_j - c)_xy|, |D_j,xy| */
  oc_vec3 dc[4];         /* D_j - c, for every step */
  for (int j = 0; j < 4; j++) {
    dc[j] = (oc_vec3){D[j].x - c.x, D[j].y - c.y, D[j].z - c.z};
    dxy[j] = hypot(dc[j].x, dc[j].y);
    bxy[j] = hypot(D[j].x, D[j].y);
  }
  double width = greater(b->x1 - b->x0, b->y1 - b->y0);
  if (m->ok && d < far) {
    /* a first step on the enclosing beam's last model, no call: the least
    ** its corners' rays take */
    double s = lesser(e, far - d), lo;
    for (int j = 0; j < 4 && s > 0; j++)
      s = lesser(s, model_free(m, at(b->o, D[j], d), D[j], bxy[j], s, &lo));
    if (s > 0) d += s;
  }
  /* a relaxed step to d from dsafe, proved free, until its model proves
  ** the stretch back to dsafe free too */
  int relaxed = 0;
  double dsafe = d;
  for (long k = 0; k < OC_TRACE_MAX_STEPS; k++) {
    *next = e;
    if (d >= far) return INFINITY;
    e = lesser(e, far - d);
    double back = relaxed ? d - dsafe : 0, R = 0;
    for (int j = 0; j < 4; j++)
      R = greater(R, d * dxy[j] + greater(e, back) * bxy[j]);
    oc_vec3 p = at(b->o, c, d);
    double g[2], E[3];
    (*evals)++;
    double f = src->taylor(src->ud, p.x, p.y, R, g, E, NULL), h = p.z - f;
    if (!(h == h)) return relaxed ? dsafe : d; /* NaN: nothing proved */
    *m = (oc_emodel){1, p.x, p.y, f, R, {g[0], g[1]}, {E[0], E[1], E[2]}};
    double s = e;
    int ok = 1;
    for (int j = 0; j < 4 && ok; j++) {
      double ax = d * dc[j].x, ay = d * dc[j].y, az = d * dc[j].z,
             ra = d * dxy[j];
      double c0 =
          h + az - (g[0] * ax + g[1] * ay) - (E[0] + ra * (E[1] + ra * E[2]));
      if (!(c0 > 0)) {
        ok = 0;
        break;
      }
      double kj = D[j].z - (g[0] * D[j].x + g[1] * D[j].y);
      double c1 = (E[1] + 2 * E[2] * ra) * bxy[j] - kj;
      double c2 = E[2] * bxy[j] * bxy[j];
      /* back along the corner's ray (direction -D_j): L >= c0 - (c1 +
      ** 2 kj) s - c2 s^2, its first root past the relaxed stretch (a
      ** hair short, as below) */
      if (relaxed && first_root(c0, c1 + 2 * kj, c2, back) * (1 - 1e-9) < back)
        ok = 0;
      s = lesser(s, first_root(c0, c1, c2, e));
    }
    if (!ok) {
      if (!relaxed) return d;
      /* not proved: the plain step, its candidate as it was */
      d = dsafe, relaxed = 0;
      continue;
    }
    relaxed = 0;
    /* a hair short of the first root, where L may be 0 */
    s *= 1 - 1e-9;
    if (!(s > BSTOP * width * d) || d + s == d) return d;
    if (s < e && d + BRELAX * s < far)
      relaxed = 1, dsafe = d + s, d += BRELAX * s;
    else
      d += s;
    e = TGROW * s;
  }
  return relaxed ? dsafe : d;
}

double oc_etrace_beam(const oc_etracer *tr, const oc_ebeam *b, double d,
                      double dmax, double *bounds, double *evals, double *next,
                      oc_emodel *m) {
  double unused = 0, from = next ? *next : 0;
  oc_emodel none = {0};
  if (!next) next = &unused;
  if (!m) m = &none;
  *next = 0;
  /* past the farthest corner of the domain's box no ray is in it (a ray
  ** at depth d is at least d from o) */
  double far = 0;
  for (int k = 0; k < 8; k++) {
    double dx = (k & 1 ? tr->hi[0] : tr->lo[0]) - b->o.x;
    double dy = (k & 2 ? tr->hi[1] : tr->lo[1]) - b->o.y;
    double dz = (k & 4 ? tr->hi[2] : tr->lo[2]) - b->o.z;
    far = greater(far, sqrt(dx * dx + dy * dy + dz * dz));
  }
  far = lesser(far * (1 + 1e-9), dmax);
  double width = greater(b->x1 - b->x0, b->y1 - b->y0), e = (far - d) / 16;
  int models = tr->mode == OC_TRACE_SEGMENT && tr->s->src->taylor && evals;
  if (from > 0) e = from; /* a part goes on from its beam's candidate */
  /* A part of a beam that stopped on models is near the surface, where
  ** the boxes of its pieces hold the surface: halving them down to its
  ** width cost about 6 range queries a 2 x 2 block, each about as dear
  ** as a model query, mostly to no avail. Such a part tries its
  ** candidate's box once (it may still stride over a ridge), and goes
  ** on models where that fails. Measured on bench_elev (full size, a
  ** pixel: calls, range queries; the replayed costs of both about 0.42
  ** and 0.30 us on fig3, 0.84 and 0.73 on fig22): fig3 4.45, 1.54 to
  ** 4.66, 0.55; fig22 6.54, 1.07 to 6.65, 0.61; fig1 5.81, 1.24 to
  ** 6.04, 0.59. Going on models at once, no range query: fig3 4.72,
  ** 0.29 but fig22 at -q 11.6, 0.75 against 10.1, 1.77 before. */
  int part = models && m->ok && from > 0;
  oc_vec3 corner[4];
  beam_corners(b, corner);
  for (long k = 0; k < OC_TRACE_MAX_STEPS && d < far; k++) {
    e = lesser(e, far - d);
    double lo[3], hi[3];
    piece_box(b, corner, d, d + e, lo, hi);
    if (piece_free(tr, lo, hi, bounds)) {
      if (d + e == d) return d;
      d += e;
      e *= GROW;
      continue;
    }
    if (part || e <= greater(0.5 * width * d, tol(tr, 0, d))) {
      if (models)
        return beam_models(tr, b, corner, d, far, BEAM_STEP * width * d, evals,
                           next, m);
      return d;
    }
    e *= 0.5;
  }
  return d < far ? d : INFINITY;
}

oc_vec3 oc_etracer_wall(const oc_etracer *tr, oc_vec3 p, oc_vec3 u) {
  const double q[3] = {p.x, p.y, p.z};
  double best = INFINITY;
  oc_vec3 n = {0, 0, 0};
  for (int k = 0; k < 3; k++)
    for (int side = 0; side < 2; side++) {
      double d = fabs(q[k] - (side ? tr->hi[k] : tr->lo[k]));
      if (d < best) {
        double c[3] = {0, 0, 0};
        c[k] = side ? 1 : -1;
        best = d;
        n = (oc_vec3){c[0], c[1], c[2]};
      }
    }
  /* farther from every face: a hole's wall inside the domain, which faces
  ** the ray */
  double span = (tr->hi[0] - tr->lo[0]) + (tr->hi[1] - tr->lo[1]);
  if (!(best <= 1e-9 * span)) n = (oc_vec3){-u.x, -u.y, -u.z};
  return n;
}
