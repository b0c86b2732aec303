/*
** disc.c — the disc primitive of elevation trees (Génevaux et al. 2015,
** section 4.1): alpha = g(|p - c| / r) with Wyvill's g(x) = (1 - x^2)^3,
** and f = height + a sum of noise octaves centred on c, plain, turbulent
** or ridged (Musgrave's ridged multifractal). The noise eta is the
** engine's simplex noise on z = 0 remapped to [-1, 1], whose Lipschitz
** bound is proven (core/noise.c), so the disc's is too: lambda_eta sum
** a_i s_i for plain and turbulent sums (the extracted text of the paper
** prints a_i lambda_eta / s_i).
*/
#include <math.h>
#include <stddef.h>

#include "core/error.h"
#include "core/falloff.h"
#include "core/noise.h"
#include "core/rng.h"
#include "core/vec.h"
#include "elevation/enode.h"
#include "elevation/etaylor.h"

_Static_assert(OC_ENOISE_MAXOCT == OC_NOISE_MAXOCT,
               "a disc's octaves and their room: oc_noise3_z0_octaves'");

/* Ridged octaves: w_i = clamp(RIDGE_GAIN s_(i-1), 0, 1). */
#define RIDGE_GAIN 2.0

double oc_eta(uint64_t seed, double x, double y, double g[2]) {
  oc_vec3 gr;
  double n = oc_noise3(seed, oc_v3(x, y, 0), g ? &gr : NULL);
  if (g) {
    g[0] = 2 * gr.x;
    g[1] = 2 * gr.y;
  }
  return 2 * n - 1;
}

/* The noise of octaves [0, n) of nz at (u, v) in one call
** (oc_noise3_z0_octaves: eight octaves at a time under AVX-512, else two,
** oc_noise3's values and gradients bit for bit; oc_eta remaps them), the
** gradients when ex and ey are not NULL. ev, ex and ey have room for
** OC_ENOISE_MAXOCT values (those past n may be overwritten). */
static void octave_noise(const oc_enoise *nz, double u, double v, int n,
                         double *ev, double *ex, double *ey) {
  double s[OC_ENOISE_MAXOCT], f = 1 / nz->wavelength;
  /* the default lacunarity: the frequencies f 2^i made in the kernel's
  ** lanes (oc_noise3_z0_octaves2, the same bits); this loop's dependent
  ** products, stored then reloaded as a vector, cost 20 % of a 5-octave
  ** call (57.3 -> 46.9 ns, best of 6 x 2M calls, AVX-512) */
  if (nz->lacunarity == 2) {
    if (n) oc_noise3_z0_octaves2(nz->seed, f, u, v, (size_t)n, ev, ex, ey);
    return;
  }
  for (int i = 0; i < n; i++, f *= nz->lacunarity)
    s[i] = f;
  if (n) oc_noise3_z0_octaves(nz->seed, s, u, v, (size_t)n, ev, ex, ey);
}

/* log2 of the lacunarity: the step of t_i = log2(w_i / foot) from one
** octave to the next (log2 2 is 1: the default lacunarity spares the
** call). */
static inline double octave_dt(const oc_enoise *nz) {
  return nz->lacunarity == 2 ? 1 : log2(nz->lacunarity);
}

/* Continuous level of detail (lod.c): octave i weighted b(t_i), t_i =
** log2(w_i / foot) = t0 - i dt, all with the gradient (gx, gy) of t. */
typedef struct octlod {
  double t0, dt, gx, gy;
} octlod;

/* The noise sum at (u, v) = p - c, and its gradient in g when not NULL;
** under lod, octaves filtered (the term of octave i times b_i, plus the
** term times grad b_i in g), and none evaluated past the first whose
** weight is 0 (wavelengths only shrink). Without it, or where every b_i
** is 1, the sum is bit for bit the unfiltered one. */
static double noise_sum(const oc_enoise *nz, double u, double v, double g[2],
                        const octlod *lod) {
  /* the octaves' points and filters first, then their noise in one call
  ** (oc_noise3_z0_multi: two octaves at a time, the values and gradients
  ** oc_eta gives), then the sum octave by octave as it always was */
  double e[OC_ENOISE_MAXOCT], ex[OC_ENOISE_MAXOCT], ey[OC_ENOISE_MAXOCT];
  double bws[OC_ENOISE_MAXOCT], dbs[OC_ENOISE_MAXOCT];
  int cnt = 0;
  for (; cnt < nz->octaves; cnt++) {
    double bw = 1, db = 0;
    if (lod) {
      bw = oc_elod_b(lod->t0 - cnt * lod->dt, &db);
      if (bw == 0) break;
    }
    bws[cnt] = bw, dbs[cnt] = db;
  }
  octave_noise(nz, u, v, cnt, e, g ? ex : NULL, g ? ey : NULL);
  double sum = 0, a = nz->amplitude, s = 1 / nz->wavelength;
  double prev = 1, gprev[2] = {0, 0}; /* ridged: s_(i-1) and its gradient */
  if (g) g[0] = g[1] = 0;
  for (int i = 0; i < cnt; i++) {
    double ge[2] = {0, 0}, bw = bws[i], db = dbs[i], a0 = a;
    if (lod) a = a0 * bw;
    e[i] = 2 * e[i] - 1; /* (oc_eta) */
    if (g) ge[0] = 2 * ex[i], ge[1] = 2 * ey[i];
    double term = 0; /* the octave's unfiltered term, where db != 0 */
    switch (nz->kind) {
    case OC_ENOISE_PLAIN:
      sum += a * e[i];
      term = e[i];
      if (g) g[0] += a * s * ge[0], g[1] += a * s * ge[1];
      break;
    case OC_ENOISE_TURBULENCE: {
      double sg = e[i] < 0 ? -1 : 1;
      sum += a * fabs(e[i]);
      term = fabs(e[i]);
      if (g) g[0] += a * s * sg * ge[0], g[1] += a * s * sg * ge[1];
      break;
    }
    default: { /* ridged */
      double sg = e[i] < 0 ? -1 : 1, r = 1 - fabs(e[i]);
      double w = 1, gw[2] = {0, 0};
      if (i > 0) {
        w = RIDGE_GAIN * prev;
        if (w >= 1) {
          w = 1;
        } else if (w <= 0) {
          w = 0;
        } else if (g) {
          gw[0] = RIDGE_GAIN * gprev[0];
          gw[1] = RIDGE_GAIN * gprev[1];
        }
      }
      double t = w * r * r;
      sum += a * t;
      term = t;
      if (g) {
        /* grad t = r^2 grad w - 2 w r sign(e) s grad eta */
        double k = -2 * w * r * sg * s;
        gprev[0] = r * r * gw[0] + k * ge[0];
        gprev[1] = r * r * gw[1] + k * ge[1];
        g[0] += a * gprev[0];
        g[1] += a * gprev[1];
      }
      prev = t; /* the chain runs on the unfiltered terms */
    }
    }
    if (g && db != 0) {
      g[0] += a0 * term * db * lod->gx;
      g[1] += a0 * term * db * lod->gy;
    }
    a = a0 * nz->gain;
    s *= nz->lacunarity;
  }
  return sum;
}

/* Under footprints in [fb->lo, fb->hi], octave i's t_i = log2(w_i /
** foot) lies in [tmin - i dt, tmax - i dt], dt = log2 lacunarity (one
** log2 each, padded against the evaluator's rounding). */
typedef struct octspan {
  double tmin, tmax, dt;
} octspan;

static void oct_span(const oc_enoise *nz, const oc_efootb *fb, octspan *t) {
  t->dt = octave_dt(nz);
  t->tmin = oc_log2_any(nz->wavelength / fb->hi) - 1e-12;
  t->tmax =
      fb->lo > 0 ? oc_log2_any(nz->wavelength / fb->lo) + 1e-12 : INFINITY;
}

/* Range and Lipschitz bound {lo, hi, lip} of the noise sum in all, under
** footprints fb with the spans ts (both NULL: full detail): octave i
** weighted b_i in [0, bh], |grad b_i| <= lb, its term (|term| <= 1)
** contributing a (bh lambda_term + lb). In part (when not NULL) the same
** for the octaves from `from` on, those before counting nothing (the
** ridged chain runs through them). One pass: each octave's filter bound
** is made once for both. */
static void noise_bounds(const oc_enoise *nz, const oc_efootb *fb,
                         const octspan *ts, int from, double all[3],
                         double part[3]) {
  double a = nz->amplitude, s = 1 / nz->wavelength, lr = 0;
  double asum[2] = {0, 0}, l[2] = {0, 0};
  double le = 2 * oc_noise3_lipschitz;
  /* |grad t_i| on octave i's ramp, k / (ln 2 max(lo, w_i / 2)) (lod.c,
  ** oc_elod_kappa_bound_t), is min(k / (ln 2 lo), 2 k s_i / ln 2): two
  ** constants a box where two divisions an octave were (1 / s_i and the
  ** quotient), padded for s_i's rounding (a product an octave) */
  double clo = 0, cs = 0;
  if (fb) {
    clo = fb->lo > 0 ? fb->k / (0.69314718055994530942 * fb->lo) : INFINITY;
    cs = 2 * fb->k / 0.69314718055994530942;
  }
  for (int i = 0; i < nz->octaves; i++) {
    double bh = 1, lb = 0, bl, li;
    /* (those before from, when it is the whole octaves' count, have bh 1
    ** and lb 0: oc_elod_kappa_bound_t's, not asked) */
    if (fb && i >= from)
      oc_elod_kappa_bound_c(ts->tmin - i * ts->dt, ts->tmax - i * ts->dt,
                            oc_fmin(clo, cs * s) * (1 + 1e-14), &bl, &bh, &lb);
    if (bh == 0) break;
    if (nz->kind == OC_ENOISE_RIDGED) {
      /* |grad s_i| <= G |grad s_(i-1)| + 2 lambda_eta s_i */
      lr = (i ? RIDGE_GAIN * lr : 0) + 2 * le * s;
      li = a * lr * bh + a * lb;
    } else {
      li = a * le * s * bh + a * lb;
    }
    asum[0] += a * bh, l[0] += li;
    if (i >= from) asum[1] += a * bh, l[1] += li;
    a *= nz->gain;
    s *= nz->lacunarity;
  }
  for (int k = 0; k < (part ? 2 : 1); k++) {
    double *o = k ? part : all;
    o[0] = nz->kind == OC_ENOISE_PLAIN ? -asum[k] : 0;
    o[1] = asum[k];
    o[2] = l[k];
  }
}

/* ---- first-order models of continuous-LoD discs (etaylor.h) ------------
** Under a view a disc's noise is sum a_i b(tau - i dt) T_i, tau = log2(w /
** foot) (w the first wavelength, dt = log2 lacunarity) and T_i octave i's
** term, unfiltered (the ridged chain runs on those): each octave is the
** product (etaylor.h) of its filter's model (lod.c, oc_elod_b_taylor: b
** composed with tau's model) and its term's (noise_taylor's octave
** models). An octave whose filter is 0 on the whole disc (tau - i dt <= 0
** there: the finer ones too) is not evaluated; one whose filter is 1
** there is its term's model alone. */

static oc_etay octave_model(double e, const double g[2], double s, double R,
                            int absval, double k);

/* Octave i's term at frequency s from its noise e (gradient g, lattice
** units), as noise_sum computes it, and its model in *t; the ridged
** chain's previous term and model in *prev and *tprev (updated), k
** octave_model's split. Full detail (noise_taylor) and the filtered sum
** alike. */
static double ridged_term(int i, double e, const double g[2], double s,
                          double R, double k, double *prev, oc_etay *tprev,
                          oc_etay *t) {
  /* w rho^2, rho = 1 - |eta| (|eta|'s model negated, plus 1), w =
  ** clamp(2 t_(i-1)) */
  double r = 1 - fabs(e), w = 1;
  oc_etay rho = octave_model(e, g, s, R, 1, k), wm = oc_etay_const(1);
  rho.v = r, rho.gx = -rho.gx, rho.gy = -rho.gy;
  if (i > 0) {
    w = RIDGE_GAIN * *prev;
    w = w >= 1 ? 1 : w <= 0 ? 0 : w;
    oc_etay x = oc_etay_scale(tprev, RIDGE_GAIN);
    wm = oc_etay_clamp01(&x, R);
  }
  oc_etay rho2 = oc_etay_mul(&rho, &rho, R);
  *t = oc_etay_mul(&wm, &rho2, R);
  t->v = *prev = w * r * r;
  *tprev = *t;
  return t->v;
}

/* (plain and turbulent terms inline: a call showed in the LoD sums) */
static inline __attribute__((always_inline)) double
octave_term(const oc_enoise *nz, int i, double e, const double g[2], double s,
            double R, double k, double *prev, oc_etay *tprev, oc_etay *t) {
  if (nz->kind != OC_ENOISE_RIDGED) {
    int turb = nz->kind == OC_ENOISE_TURBULENCE;
    *t = octave_model(e, g, s, R, turb, k);
    return turb ? fabs(e) : e;
  }
  return ridged_term(i, e, g, s, R, k, prev, tprev, t);
}

/* A noise sum's model being summed octave by octave: the sum of the
** terms (the value, as noise_sum adds it) and of the models times their
** amplitudes; the next octave's amplitude a and frequency s; the ridged
** chain's previous term and model. */
typedef struct octsum {
  double sum, a, s, prev;
  oc_etay m, tprev;
} octsum;

static void octsum_init(const oc_enoise *nz, octsum *q) {
  *q = (octsum){0, nz->amplitude,    1 / nz->wavelength,
                1, oc_etay_const(0), oc_etay_const(1)};
}

/* Octaves [i0, i1) unfiltered, from their noise at p (ev, ex, ey, as
** octave_noise gives it) into q: noise_taylor's sum, and a filtered sum's
** octaves whose filter is 1 on the whole disc (the same bits: b = 1). */
static inline __attribute__((always_inline)) void
octaves_taylor(const oc_enoise *nz, int i0, int i1, const double *ev,
               const double *ex, const double *ey, double R, double k,
               octsum *q) {
  double sum = q->sum, a = q->a, s = q->s, prev = q->prev;
  oc_etay m = q->m, tprev = q->tprev;
  if (nz->kind != OC_ENOISE_RIDGED) {
    /* plain or turbulent: octave_model's terms scaled and added as
    ** oc_etay_scale and oc_etay_add would (the same operations in the
    ** same order: the same bits), in registers */
    int turb = nz->kind == OC_ENOISE_TURBULENCE;
    for (int i = i0; i < i1; i++) {
      double g[2] = {2 * ex[i], 2 * ey[i]}, e = 2 * ev[i] - 1; /* (oc_eta) */
      oc_etay t = octave_model(e, g, s, R, turb, k);           /* (inline) */
      double aa = fabs(a);
      sum += a * t.v; /* (octave_term's value: |e| or e) */
      m.gx += a * t.gx, m.gy += a * t.gy;
      m.e0 += aa * t.e0, m.e1 += aa * t.e1, m.e2 += aa * t.e2;
      a = a * nz->gain;
      s *= nz->lacunarity;
    }
    *q = (octsum){sum, a, s, prev, m, tprev};
    return;
  }
  for (int i = i0; i < i1; i++) {
    double ge[2] = {2 * ex[i], 2 * ey[i]}, e = 2 * ev[i] - 1; /* (oc_eta) */
    oc_etay t;
    sum += a * octave_term(nz, i, e, ge, s, R, k, &prev, &tprev, &t);
    oc_etay at = oc_etay_scale(&t, a);
    oc_etay_add(&m, &at);
    a = a * nz->gain;
    s *= nz->lacunarity;
  }
  *q = (octsum){sum, a, s, prev, m, tprev};
}

/* Of n octaves with dt = 1 and tau's range [tlo, thi] on the disc: those
** whose filter is not 0 on the whole disc (cnt), the leading ones whose
** filter is 1 there (whole). The general loops' tests (noise_taylor_lod)
** without the loops: for integers i, thi - i > 0 exactly when i < thi,
** and tlo - i >= 1 when i + 1 <= tlo, the differences rounding
** monotonically and none of those below 1 rounding up to it. */
static inline void counts1(int n, double tlo, double thi, int *cnt,
                           int *whole) {
  /* ceil(thi) and floor(tlo) clamped to [0, n] and [0, cnt], on values
  ** clamped first (then converted: no branches) */
  double c = thi > 0 ? thi < n ? thi : n : 0;
  int ic = (int)c;
  ic += ic < c;
  double w = tlo > 0 ? tlo < ic ? tlo : ic : 0;
  *cnt = ic, *whole = (int)w;
}

/* The filtered sum's model at (u, v) = p - c, its value noise_sum's with
** the footprint tf->p; 0 where a filter ramps and tau has no model. The
** leading octaves, whose filter is 1 on the whole disc, are summed as
** at full detail; each of the next is its filter's model times its
** term's. */
static int noise_taylor_lod(const oc_enoise *nz, double lw, double u, double v,
                            double R, const oc_etfoot *tf, oc_etay *o) {
  oc_etay tau;
  oc_etfoot own;
  tf = oc_etfoot_for(tf, R, &own);
  double tlo, thi, dt = octave_dt(nz);
  int curved = oc_elod_tau_taylor_l(lw, tf, &tau, &tlo, &thi);
  /* the octaves whose filter is not 0 on the whole disc (cnt), the
  ** leading ones whose filter is 1 there (whole); their noise at p in one
  ** call (as noise_sum) */
  double ev[OC_ENOISE_MAXOCT], ex[OC_ENOISE_MAXOCT], ey[OC_ENOISE_MAXOCT];
  int cnt = 0, whole = 0;
  if (dt == 1) {
    /* the counts first from oc_log2_coarse (tlo and thi then within
    ** 0.00565 + 2.2e-9 of those below, the pad 1e-12 (1 + |lw - lf|) <
    ** 2.2e-9 being left out: |lw - lf| < 2200), sure when both ends of a
    ** span of 2^-7 about them give the same counts (monotonic in tlo and
    ** thi), else (3.5 % of bench_disc_lod's calls) from tlo and thi: the
    ** same counts, without oc_log2's latency (about 30 cycles) ahead of
    ** the branches they decide (bench_disc_lod, plain: 125 ns with it
    ** there, 114 without, 113.7 with lw kept in the disc) */
    double vq = oc_log2_coarse(nz->wavelength) - tf->lf, D = 0x1p-7;
    double hq = tf->curved ? vq + tf->dhi : INFINITY, lq = vq - tf->dlo;
    int c0, w0, c1, w1;
    counts1(nz->octaves, lq - D, hq - D, &c0, &w0);
    counts1(nz->octaves, lq + D, hq + D, &c1, &w1);
    if (c0 == c1 && w0 == w1)
      cnt = c0, whole = w0;
    else
      counts1(nz->octaves, tlo, thi, &cnt, &whole);
  } else {
    while (cnt < nz->octaves && thi - cnt * dt > 0)
      cnt++;
    while (whole < cnt && tlo - whole * dt >= 1)
      whole++;
  }
  if (!curved && whole < cnt) return 0;
  octave_noise(nz, u, v, cnt, ev, ex, ey);
  octsum q;
  octsum_init(nz, &q);
  octaves_taylor(nz, 0, whole, ev, ex, ey, R, OC_ETAY_LOD_CHOICE, &q);
  /* the ramping octaves on locals: with q's fields passed by address
  ** (the ridged chain) q lived in memory, its fields stored one by one
  ** and reloaded in pairs, a stalled store forwarding (perf annotate:
  ** 18 % of this function's samples at three such loads) */
  double sum = q.sum, a = q.a, s = q.s, prev = q.prev;
  oc_etay m = q.m, tprev = q.tprev;
  /* Each ramping octave is b(tau - i dt) times its term: oc_elod_b_taylor
  ** then oc_etay_mul, written out for tau's model, which has no e0 or e1
  ** and whose linear part's norm G is the query's (tf->tg): b's model is
  ** bw + db tau's linear part with the remainder (|db| E + M (G + E R)^2
  ** / 2) r^2 (oc_etay_compose, M = max |b''| on the octave's range), and
  ** the product's terms with b's e0 and e1 (zero) drop out. Two square
  ** roots, two filters and the branches of the general rules fewer: a
  ** ramping octave cost 25-40 ns of a 150 ns call (plain, 75 of 300
  ** ridged). (The general rule's flat model where b's remainder passes
  ** the gap to its far end is not needed: tau varies by G R, 1/100 of an
  ** octave, on a disc.) */
  double G = tf->tg, E = tau.e2;
  int live = 1; /* noise_sum adds octave i (its filter at p is not 0) */
  for (int i = whole; i < cnt; i++, a *= nz->gain, s *= nz->lacunarity) {
    double g[2] = {2 * ex[i], 2 * ey[i]}, db; /* (oc_eta) */
    double lo = tlo - i * dt, hi = thi - i * dt;
    double bw = oc_elod_b(tau.v - i * dt, &db);
    oc_etay t;
    double term = octave_term(nz, i, 2 * ev[i] - 1, g, s, R, OC_ETAY_LOD_CHOICE,
                              &prev, &tprev, &t);
    live = live && bw != 0;
    if (live) sum += a * bw * term;
    double bgx = 0, bgy = 0, bg = 0, be2 = 0; /* b's model but its value */
    if (hi > 0 && lo < 1) {
      double M = oc_elod_bpp_max(lo, hi), gr = G + E * R;
      bgx = db * tau.gx, bgy = db * tau.gy, bg = fabs(db) * G;
      be2 = fabs(db) * E + 0.5 * M * (gr * gr);
    }
    /* oc_etay_mul(b's, t's) (its polymul with b's e0 = e1 = 0), times a */
    double tg = sqrt(t.gx * t.gx + t.gy * t.gy) + t.e1;
    double kb = fabs(bw), aa = fabs(a);
    double c2 = bg * tg + be2 * t.e0 + R * (bg * t.e2 + be2 * tg) +
                R * R * (be2 * t.e2);
    m.gx += a * (bw * t.gx + t.v * bgx);
    m.gy += a * (bw * t.gy + t.v * bgy);
    m.e0 += aa * (kb * t.e0);
    m.e1 += aa * (kb * t.e1 + bg * t.e0);
    m.e2 += aa * (kb * t.e2 + fabs(t.v) * be2 + c2);
  }
  m.v = sum;
  *o = m;
  return 1;
}

static int noise_local(const oc_enoise *nz, double u0, double v0, double u1,
                       double v1, double *lo, double *hi, double *lip);

/* The noise's range and slope on the box [u0, u1] x [v0, v1] (relative to
** the centre) under footprints: the j leading octaves, whose filter is 1
** on the whole box (t_i >= 1 at its largest footprint), bounded locally
** (noise_local: where it gains, the coarse octaves), the others by
** noise_bounds' filtered rule (the ridged chain's global slopes), given
** in rest. 0 where no octave is kept whole or noise_local gains
** nothing. */
static int noise_local_lod(const oc_enoise *nz, int j, const double rest[3],
                           double u0, double v0, double u1, double v1,
                           double *lo, double *hi, double *lip) {
  double l = 0, h = 0, lf = 0;
  oc_enoise whole = *nz;
  whole.octaves = j;
  if (!j || !noise_local(&whole, u0, v0, u1, v1, lo, hi, lip)) return 0;
  if (j < nz->octaves) l = rest[0], h = rest[1], lf = rest[2];
  /* rounding of the sums: a relative hair */
  double eps = 1e-12 * (fabs(*lo) + fabs(*hi) + fabs(l) + fabs(h));
  *lo += l - eps, *hi += h + eps;
  *lip = (*lip + lf) * (1 + 1e-12);
  return 1;
}

int oc_edisc_taylor_f_view(const oc_enode *n, double x, double y, double R,
                           const oc_etfoot *tf, oc_etay *f) {
  const double *p = OC_EDISC(n)->par; /* cx, cy, r, height */
  if (!tf || n->nzkind == OC_ENOISE_NONE) {
    oc_edisc_taylor_f(n, x, y, R, f);
    return 1;
  }
  oc_enoise noise;
  oc_edisc_noise(n, &noise);
  if (!noise_taylor_lod(&noise, oc_edisc_lw(n), x - p[0], y - p[1], R, tf, f))
    return 0;
  f->v = p[3] + f->v;
  return 1;
}

int oc_edisc_taylor_lod(const oc_enode *n, double x, double y, double R,
                        const oc_etfoot *tf, oc_etaylor *o) {
  if (!oc_edisc_taylor_f_view(n, x, y, R, tf, &o->f)) return 0;
  oc_edisc_taylor_alpha(n, x, y, R, &o->a);
  return 1;
}

void oc_edisc_noise(const oc_enode *n, oc_enoise *nz) {
  const oc_edisc *d = OC_EDISC(n);
  nz->kind = n->nzkind;
  nz->octaves = n->octaves;
  if (n->nzkind == OC_ENOISE_NONE) {
    nz->amplitude = nz->wavelength = nz->gain = nz->lacunarity = 0;
    nz->seed = 0;
    return;
  }
  nz->amplitude = d->amplitude;
  nz->wavelength = d->wavelength;
  nz->seed = d->seed;
  if (n->flags & OC_EF_GLDEF) {
    nz->gain = 0.5;
    nz->lacunarity = 2;
  } else if (n->flags & OC_EF_GLF) {
    nz->gain = d->gl.f[0];
    nz->lacunarity = d->gl.f[1];
  } else {
    nz->gain = d->gl.d[0];
    nz->lacunarity = d->gl.d[1];
  }
}

size_t oc_edisc_size(int nzkind, int flags) {
  if (nzkind == OC_ENOISE_NONE) return offsetof(oc_edisc, amplitude);
  if (flags & OC_EF_GLDEF) return offsetof(oc_edisc, gl);
  if (flags & OC_EF_GLF) return offsetof(oc_edisc, gl) + 2 * sizeof(float);
  return offsetof(oc_edisc, gl) + 2 * sizeof(double);
}

/* The bound over the whole plane: the noise's, from noise_bounds at
** construction (what it always was). */
void oc_edisc_glob(const oc_enode *n, oc_ebound *o) {
  const oc_edisc *d = OC_EDISC(n);
  double lo = 0, hi = 0, lip = 0;
  if (n->nzkind != OC_ENOISE_NONE) {
    hi = d->nhi;
    lo = n->nzkind == OC_ENOISE_PLAIN ? -hi : 0; /* (noise_bounds' rule) */
    lip = d->nlip;
  }
  *o = (oc_ebound){d->par[3] + lo,
                   d->par[3] + hi,
                   0,
                   1,
                   lip,
                   OC_FALLOFF_LIPSCHITZ / d->par[2]};
}

/* A disc unpacked: what its bounds read. */
typedef struct dview {
  const double *par; /* cx, cy, r, height */
  oc_enoise noise;
  oc_erect box;   /* Omega_0 lies inside */
  oc_ebound glob; /* over the whole plane */
} dview;

static void unpack(const oc_enode *n, dview *v) {
  v->par = OC_EDISC(n)->par;
  oc_edisc_noise(n, &v->noise);
  v->box = oc_enode_box(n);
  oc_edisc_glob(n, &v->glob);
}

void oc_edisc_ev(const oc_enode *n, double x, double y, const oc_efoot *ft,
                 int want, oc_enode_sample *s) {
  const double *p = OC_EDISC(n)->par; /* cx, cy, r, height */
  double u = x - p[0], v = y - p[1], r = p[2];
  double q = (u * u + v * v) / (r * r);
  int grad = want & OC_EV_GRAD;
  s->ax = s->ay = 0;
  if (q < 1) {
    double k = 1 - q;
    s->a = k * k * k;
    if (grad) {
      double c = -6 * k * k / (r * r);
      s->ax = c * u;
      s->ay = c * v;
    }
  } else {
    s->a = q == q ? 0 : q; /* NaN stays NaN */
    if (want & OC_EV_LAZY && s->a == 0) {
      s->f = s->fx = s->fy = 0;
      return;
    }
  }
  if (want & OC_EV_ALPHA) return;
  double g[2] = {0, 0};
  oc_enoise noise;
  oc_edisc_noise(n, &noise);
  octlod lod, *lp = NULL;
  if (ft && ft->v > 0 && noise.kind != OC_ENOISE_NONE) {
    double c = -1 / (ft->v * 0.69314718055994530942);
    /* (t0 as the models' tau: oc_elod_tau_taylor_l) */
    lod = (octlod){oc_edisc_lw(n) - oc_log2_any(ft->v), octave_dt(&noise),
                   c * ft->gx, c * ft->gy};
    lp = &lod;
  }
  s->f = p[3] + (noise.kind == OC_ENOISE_NONE
                     ? 0
                     : noise_sum(&noise, u, v, grad ? g : NULL, lp));
  s->fx = g[0];
  s->fy = g[1];
}

/* noise_sum without lod or gradient over the cnt points (u[j], v), into
** sum[j]: per octave one key and one row of noise (corners' hashes shared
** along the row), each point's sum the same octave by octave. */
static void noise_sum_row(const oc_enoise *nz, const double *u, double v,
                          int cnt, double *sum) {
  double a = nz->amplitude, s = 1 / nz->wavelength;
  double px[OC_EROW], py[OC_EROW], e[OC_EROW], prev[OC_EROW];
  for (int j = 0; j < cnt; j++)
    sum[j] = 0, prev[j] = 1;
  for (int i = 0; i < nz->octaves; i++) {
#pragma omp simd
    for (int j = 0; j < cnt; j++)
      px[j] = s * u[j], py[j] = s * v;
    oc_noise3_z0_row(oc_noise_octave_seed(nz->seed, i), px, py, (size_t)cnt, e);
#pragma omp simd
    for (int j = 0; j < cnt; j++)
      e[j] = 2 * e[j] - 1; /* (oc_eta) */
    switch (nz->kind) {
    case OC_ENOISE_PLAIN:
#pragma omp simd
      for (int j = 0; j < cnt; j++)
        sum[j] += a * e[j];
      break;
    case OC_ENOISE_TURBULENCE:
#pragma omp simd
      for (int j = 0; j < cnt; j++)
        sum[j] += a * fabs(e[j]);
      break;
    default: /* ridged */
#pragma omp simd
      for (int j = 0; j < cnt; j++) {
        double r = 1 - fabs(e[j]), w = 1;
        if (i > 0) {
          w = RIDGE_GAIN * prev[j];
          w = w >= 1 ? 1 : w <= 0 ? 0 : w;
        }
        double t = w * r * r;
        sum[j] += a * t;
        prev[j] = t;
      }
    }
    a = a * nz->gain;
    s *= nz->lacunarity;
  }
}

void oc_edisc_ev_row(const oc_enode *n, const double *x, double y, int cnt,
                     int want, double *f, double *a) {
  const double *p = OC_EDISC(n)->par; /* cx, cy, r, height */
  double v = y - p[1], r = p[2], u[OC_EROW], sum[OC_EROW];
  int idx[OC_EROW], nn = 0; /* the points whose f is wanted */
  for (int m = 0; m < cnt; m++) {
    double um = x[m] - p[0], q = (um * um + v * v) / (r * r);
    if (q < 1) {
      double k = 1 - q;
      a[m] = k * k * k;
    } else {
      a[m] = q == q ? 0 : q; /* NaN stays NaN */
      if (want & OC_EV_LAZY && a[m] == 0) {
        if (!(want & OC_EV_ALPHA)) f[m] = 0;
        continue;
      }
    }
    u[nn] = um, idx[nn++] = m;
  }
  if (want & OC_EV_ALPHA || !nn) return;
  oc_enoise noise;
  oc_edisc_noise(n, &noise);
  if (noise.kind == OC_ENOISE_NONE) {
    for (int j = 0; j < nn; j++)
      f[idx[j]] = p[3] + 0;
    return;
  }
  noise_sum_row(&noise, u, v, nn, sum);
  for (int j = 0; j < nn; j++)
    f[idx[j]] = p[3] + sum[j];
}

/* Distances from (cx, cy) to the nearest and farthest points of b. */
static void rect_dist(const oc_erect *b, double cx, double cy, double *dmin,
                      double *dmax) {
  double dx = oc_fmax(oc_fmax(b->x0 - cx, cx - b->x1), 0);
  double dy = oc_fmax(oc_fmax(b->y0 - cy, cy - b->y1), 0);
  double fx = oc_fmax(fabs(b->x0 - cx), fabs(b->x1 - cx));
  double fy = oc_fmax(fabs(b->y0 - cy), fabs(b->y1 - cy));
  *dmin = sqrt(dx * dx + dy * dy);
  *dmax = sqrt(fx * fx + fy * fy);
}

static double wyvill(double x) {
  if (!(x < 1)) return 0;
  double k = 1 - x * x;
  return k * k * k;
}

static double clamp01(double x) {
  return x <= 0 ? 0 : x >= 1 ? 1 : x;
}

/* fmin and fmax for the finite values of noise_local (calls in this
** build, and the box queries of tracing make many). */
static inline double lesser(double a, double b) {
  return a < b ? a : b;
}
static inline double greater(double a, double b) {
  return a > b ? a : b;
}

/* The range and a Lipschitz bound of the noise sum (unfiltered) on the box
** [u0, u1] x [v0, v1] relative to the disc's centre, from each octave's
** value and gradient at the box's centre c. With H the proved bound of
** eta's Hessian on the plane (2 oc_noise3_hessian, core/noise.c) and
** r = s rho the box's half-diagonal in the octave's units, on the box
**   |grad eta| <= |grad eta(c)| + H r,
**   |eta - eta(c)| <= s (|eta_x(c)| hx + |eta_y(c)| hy) + H r^2 / 2
** (Taylor), each capped by the global bounds lambda_eta and lambda_eta r.
** Turbulence takes |eta|'s range (as Lipschitz as eta); a ridged octave
** t = w (1 - |eta|)^2 carries the range and slope of the previous term
** into its weight w = clamp(2 t_prev). From the first octave where
** neither the slope (H r >= lambda_eta) nor the first-order range
** (lambda_eta r >= 1) gains, the octaves keep the whole plane's bounds.
** Measured on bench_elev: the range condition is worth 5 % of fig1's
** calls and costs 5 % of fig3's instructions (callgrind, 240 x 135);
** fewer octaves (H r < 0.7 lambda_eta) cost more instructions than they
** saved. Returns 0 when the first octave already gains nothing. */
static int noise_local(const oc_enoise *nz, double u0, double v0, double u1,
                       double v1, double *lo, double *hi, double *lip) {
  const double L = 2 * OC_NOISE3_LIPSCHITZ, H = 2 * OC_NOISE3_HESSIAN;
  double u = 0.5 * (u0 + u1), v = 0.5 * (v0 + v1);
  /* half-sides, a hair wider than the box: the rounding of the centre, of
  ** p - c in the evaluator and of s p */
  double pad = 1e-12 * (fabs(u) + fabs(v));
  double hx = 0.5 * (u1 - u0) * (1 + 1e-12) + pad;
  double hy = 0.5 * (v1 - v0) * (1 + 1e-12) + pad;
  double a = nz->amplitude, s = 1 / nz->wavelength;
  double rho = sqrt(hx * hx + hy * hy) * (1 + 1e-15);
  if (!(H * s * rho < L || L * s * rho < 1)) return 0;
  /* the octaves that gain, and their noise at the centre in one call */
  double ev[OC_ENOISE_MAXOCT], ex[OC_ENOISE_MAXOCT], ey[OC_ENOISE_MAXOCT];
  int cnt = 0;
  for (double sc = s; cnt < nz->octaves; cnt++, sc *= nz->lacunarity) {
    double r = sc * rho;
    if (!(H * r < L || L * r < 1)) break;
  }
  octave_noise(nz, u, v, cnt, ev, ex, ey);
  double l = 0, h = 0, lf = 0;
  double tlo = 1, thi = 1, tl = 0; /* ridged: the previous term's bounds */
  int i = 0;
  for (; i < cnt; i++, a *= nz->gain, s *= nz->lacunarity) {
    double r = s * rho;
    /* (oc_eta) */
    double g[2] = {2 * ex[i], 2 * ey[i]}, e = 2 * ev[i] - 1;
    double gn = sqrt(g[0] * g[0] + g[1] * g[1]) * (1 + 1e-15);
    double sl = lesser(L, gn + H * r); /* |grad eta| */
    double dv = lesser(L * r, s * (fabs(g[0]) * hx + fabs(g[1]) * hy) +
                                  0.5 * H * r * r);
    double elo = greater(-1, e - dv), ehi = lesser(1, e + dv);
    if (nz->kind == OC_ENOISE_PLAIN) {
      l += a * elo, h += a * ehi, lf += a * s * sl;
      continue;
    }
    /* |eta| in [mlo, mhi] */
    double mlo = elo > 0 ? elo : ehi < 0 ? -ehi : 0, mhi = greater(-elo, ehi);
    if (nz->kind == OC_ENOISE_TURBULENCE) {
      l += a * mlo, h += a * mhi, lf += a * s * sl;
      continue;
    }
    /* ridged: |grad t| <= r^2 |grad w| + 2 w r s |grad eta|, with
    ** r = 1 - |eta| in [1 - mhi, 1 - mlo] and |grad w| <= 2 |grad t_prev|
    ** (0 where the clamp holds w constant on the whole box) */
    double rlo = 1 - mhi, rhi = 1 - mlo, wlo = 1, whi = 1, wl = 0;
    if (i > 0) {
      wlo = clamp01(RIDGE_GAIN * tlo), whi = clamp01(RIDGE_GAIN * thi);
      wl = RIDGE_GAIN * thi <= 0 || RIDGE_GAIN * tlo >= 1 ? 0 : RIDGE_GAIN * tl;
    }
    tl = rhi * rhi * wl + 2 * whi * rhi * s * sl;
    tlo = wlo * rlo * rlo, thi = whi * rhi * rhi;
    l += a * tlo, h += a * thi, lf += a * tl;
  }
  for (; i < nz->octaves; i++, a *= nz->gain, s *= nz->lacunarity) {
    if (nz->kind == OC_ENOISE_RIDGED) { /* as noise_bounds */
      tl = (i ? RIDGE_GAIN * tl : 0) + 2 * L * s;
      h += a, lf += a * tl;
    } else {
      l -= nz->kind == OC_ENOISE_PLAIN ? a : 0, h += a, lf += a * L * s;
    }
  }
  /* rounding of the sums: a relative hair */
  double eps = 1e-12 * (fabs(l) + fabs(h) + nz->amplitude);
  *lo = l - eps, *hi = h + eps;
  *lip = lf * (1 + 1e-12);
  return 1;
}

void oc_edisc_bound_in(const oc_enode *node, const oc_erect *b,
                       const oc_efootb *fb, oc_ebound *o) {
  dview v, *n = &v; /* (the disc unpacked) */
  unpack(node, n);
  *o = n->glob;
  int filtered = 0; /* some octave may be weighted below 1 in the box */
  int j = 0;        /* then the leading octaves kept whole in the box */
  double all[3], rest[3];
  if (fb && fb->hi > 0 && n->noise.kind != OC_ENOISE_NONE) {
    octspan ts;
    oct_span(&n->noise, fb, &ts);
    /* (every octave kept in the box, the finest included: the glob's) */
    if (ts.tmin - (n->noise.octaves - 1) * ts.dt < 1) {
      while (j < n->noise.octaves && ts.tmin - j * ts.dt >= 1)
        j++;
      /* the octaves the footprints keep; those after the j whole ones */
      noise_bounds(&n->noise, fb, &ts, j, all, rest);
      o->flo = n->par[3] + all[0];
      o->fhi = n->par[3] + all[1];
      o->lf = all[2];
      filtered = 1;
    }
  }
  if (!oc_erect_meets(&n->box, b)) {
    o->alo = o->ahi = o->la = 0;
    return;
  }
  double dmin, dmax, r = n->par[2];
  rect_dist(b, n->par[0], n->par[1], &dmin, &dmax);
  if (dmin / r >= 1) {
    /* alpha = 0 on the whole box: its f counts nowhere (a blend drops
    ** the child, an add or replace weighs it by 0), so no noise for a
    ** local f bound (the box meets the disc's square in its corners) */
    o->alo = o->ahi = o->la = 0;
    return;
  }
  double nlo, nhi, nlip;
  /* the octaves' values at the centre bound the unfiltered sum only (or,
  ** filtered, the octaves kept whole on the box) */
  double u0 = b->x0 - n->par[0], v0 = b->y0 - n->par[1];
  double u1 = b->x1 - n->par[0], v1 = b->y1 - n->par[1];
  if (n->noise.kind != OC_ENOISE_NONE &&
      (filtered ? noise_local_lod(&n->noise, j, rest, u0, v0, u1, v1, &nlo,
                                  &nhi, &nlip)
                : noise_local(&n->noise, u0, v0, u1, v1, &nlo, &nhi, &nlip))) {
    o->flo = oc_fmax(o->flo, n->par[3] + nlo);
    o->fhi = oc_fmin(o->fhi, n->par[3] + nhi);
    o->lf = oc_fmin(o->lf, nlip);
  }
  /* rounding: alpha's bounds a hair wider than the formula */
  o->alo = oc_fmax(0, wyvill(dmax / r) * (1 - 1e-12) - 1e-300);
  o->ahi = oc_fmin(1, wyvill(dmin / r) * (1 + 1e-12));
  /* |grad alpha| = 6 x (1 - x^2)^2 / r at x = d / r rises up to x =
  ** 1/sqrt(5) (the global bound) and falls after: its largest value on
  ** [dmin, dmax] is there or at the end nearer to it */
  double x0 = dmin / r, x1 = oc_fmin(dmax / r, 1), xs = 1 / sqrt(5.0);
  if (x0 >= 1) {
    o->la = 0; /* outside the disc: alpha = 0 on the whole box */
  } else if (x1 < xs || x0 > xs) {
    double x = x1 < xs ? x1 : x0, k = 1 - x * x;
    o->la = oc_fmin(o->la, 6 * x * k * k / r * (1 + 1e-12));
  }
}

static int check_noise(const oc_enode_noise *nz, oc_enoise *out,
                       oc_error *err) {
  if ((unsigned)nz->kind > OC_ENOISE_RIDGED)
    return oc_seterr(err, OC_EINVAL, "'noise.kind' is not a noise kind (%d)",
                     (int)nz->kind);
  out->kind = nz->kind;
  out->amplitude = nz->amplitude;
  out->wavelength = nz->wavelength;
  out->octaves = nz->octaves;
  out->gain = nz->gain == 0 ? 0.5 : nz->gain;
  out->lacunarity = nz->lacunarity == 0 ? 2 : nz->lacunarity;
  out->seed = nz->seed;
  if (nz->kind == OC_ENOISE_NONE) return OC_OK;
  if (!(isfinite(nz->amplitude) && nz->amplitude >= 0))
    return oc_seterr(err, OC_EINVAL,
                     "'noise.amplitude' must be a finite number >= 0 (got %g)",
                     nz->amplitude);
  if (!(isfinite(nz->wavelength) && nz->wavelength > 0))
    return oc_seterr(err, OC_EINVAL,
                     "'noise.wavelength' must be a positive number (got %g)",
                     nz->wavelength);
  if (nz->octaves < 1 || nz->octaves > OC_ENOISE_MAXOCT)
    return oc_seterr(err, OC_EINVAL,
                     "'noise.octaves' must be an integer in 1..16 (got %d)",
                     nz->octaves);
  if (!(out->gain > 0 && out->gain <= 1))
    return oc_seterr(err, OC_EINVAL, "'noise.gain' must be in (0, 1] (got %g)",
                     nz->gain);
  if (!(isfinite(out->lacunarity) && out->lacunarity >= 1))
    return oc_seterr(err, OC_EINVAL,
                     "'noise.lacunarity' must be a finite number >= 1 (got %g)",
                     nz->lacunarity);
  return OC_OK;
}

oc_enode *oc_enode_disc(const oc_enode_disc_params *p, oc_error *err) {
  oc_enoise nz = {.kind = OC_ENOISE_NONE}; /* (set by check_noise) */
  if (!p) {
    oc_seterr(err, OC_EINVAL, "disc: no parameters");
    return NULL;
  }
  if (!isfinite(p->cx) || !isfinite(p->cy)) {
    oc_seterr(err, OC_EINVAL, "'center' must have finite coordinates");
    return NULL;
  }
  if (!(isfinite(p->radius) && p->radius > 0)) {
    oc_seterr(err, OC_EINVAL, "'radius' must be a positive number (got %g)",
              p->radius);
    return NULL;
  }
  if (!isfinite(p->height)) {
    oc_seterr(err, OC_EINVAL, "'height' must be a finite number (got %g)",
              p->height);
    return NULL;
  }
  if (check_noise(&p->noise, &nz, err)) return NULL;
  double lo = 0, hi = 0, lip = 0;
  if (nz.kind != OC_ENOISE_NONE) {
    double all[3];
    noise_bounds(&nz, NULL, NULL, 0, all, NULL);
    lo = all[0], hi = all[1], lip = all[2];
  }
  oc_erect box = {p->cx - p->radius, p->cy - p->radius, p->cx + p->radius,
                  p->cy + p->radius};
  if (!isfinite(p->height + lo) || !isfinite(p->height + hi) ||
      !isfinite(lip) || !isfinite(box.x0) || !isfinite(box.x1) ||
      !isfinite(box.y0) || !isfinite(box.y1) ||
      !isfinite(OC_FALLOFF_LIPSCHITZ / p->radius)) {
    oc_seterr(err, OC_EINVAL,
              "disc: the elevations or slopes of these parameters overflow "
              "(height %g, radius %g, noise amplitude %g, wavelength %g)",
              p->height, p->radius, nz.amplitude, nz.wavelength);
    return NULL;
  }
  /* gain and lacunarity: none stored when they are the defaults, floats
  ** when they are floats exactly; evaluation reads the same doubles */
  int flags = nz.gain == 0.5 && nz.lacunarity == 2 ? OC_EF_GLDEF
              : (double)(float)nz.gain == nz.gain &&
                      (double)(float)nz.lacunarity == nz.lacunarity
                  ? OC_EF_GLF
                  : 0;
  oc_enode *n =
      oc_enode_alloc(OC_E_DISC, oc_edisc_size(nz.kind, flags), NULL, 0, err);
  if (!n) return NULL;
  oc_edisc *d = (oc_edisc *)n;
  d->par[0] = p->cx;
  d->par[1] = p->cy;
  d->par[2] = p->radius;
  d->par[3] = p->height;
  n->nzkind = (uint8_t)nz.kind;
  if (nz.kind != OC_ENOISE_NONE) {
    n->octaves = (uint8_t)nz.octaves;
    d->amplitude = nz.amplitude;
    d->wavelength = nz.wavelength;
    d->seed = nz.seed;
    d->nhi = hi;
    d->nlip = lip;
    n->flags = (uint8_t)flags;
    if (flags & OC_EF_GLF) {
      d->gl.f[0] = (float)nz.gain;
      d->gl.f[1] = (float)nz.lacunarity;
    } else if (!flags) {
      d->gl.d[0] = nz.gain;
      d->gl.d[1] = nz.lacunarity;
    }
  }
  return n; /* (its box and bound: oc_enode_box, oc_edisc_glob) */
}

/* ---- first-order models (etaylor.h) -------------------------------------
** With L = lambda_eta and H the proved bound of eta's Hessian on the plane
** (as noise_local), an octave eta(s q) of the model around p, for |d| <=
** r <= R, is
**  - quadratic: linear part s grad eta(p), remainder H s^2 r^2 / 2
**    (Taylor with the integral remainder, |Hessian| <= H s^2);
**  - or flat (no linear part): |eta(s q) - eta(s p)| <= L s r, and <= 1 +
**    |eta(s p)| (eta lies in [-1, 1]);
** whichever bounds the remainder lower at r = k R (each holds up to R;
** k is OC_ETAY_CHOICE, OC_ETAY_LOD_CHOICE for the models under a view).
** Octaves coarser than R are quadratic (tiny near p), finer ones flat.
** |eta| (turbulence) is eta times its sign where that sign is proved
** constant on the disc (|eta(s p)| above its first-order deviation s
** |grad eta| R + H s^2 R^2 / 2),
** else flat (|eta| is L-Lipschitz and in [0, 1]). A ridged octave t_i =
** w_i rho_i^2, rho_i = 1 - |eta_i|, w_i = clamp(2 t_(i-1), 0, 1), is
** composed by the product and clamp rules (etaylor.h) from rho_i's model
** (as |eta|'s) and the previous term's. */

/* eta (or |eta| with abs, its sign proved constant) in the octave's world
** units: value e, octave gradient g (in lattice units), frequency s. */
static inline oc_etay octave_model(double e, const double g[2], double s,
                                   double R, int absval, double k) {
  const double L = 2 * OC_NOISE3_LIPSCHITZ, H = 2 * OC_NOISE3_HESSIAN;
  double sg = 1, ae = e;
  double quad = 0.5 * H * s * s, flat1 = L * s, flat0 = 1 + fabs(e);
  int can_quad = 1;
  if (absval) {
    sg = e < 0 ? -1 : 1, ae = fabs(e);
    flat0 = oc_fmax(ae, 1 - ae);
    /* (sqrt of the squares is within a few ulps of hypot, a libm call
    ** that showed in profiles: hypot decides only where the two sides
    ** are that close, so that the decisions, and the bits, are its) */
    double q2 = quad * R * R;
    double rhs = s * sqrt(g[0] * g[0] + g[1] * g[1]) * R + q2;
    if (fabs(ae - rhs) <= 1e-12 * (ae + rhs))
      rhs = s * hypot(g[0], g[1]) * R + q2;
    can_quad = ae > rhs;
  }
  double Rk = R * k;
  if (can_quad && quad * Rk * Rk <= oc_fmin(flat1 * Rk, flat0))
    return (oc_etay){ae, sg * s * g[0], sg * s * g[1], 0, 0, quad};
  return oc_etay_flat_at(ae, flat1, flat0, R, k);
}

static void noise_taylor(const oc_enoise *nz, double u, double v, double R,
                         oc_etay *o) {
  /* every octave's noise first, in one call */
  double ev[OC_ENOISE_MAXOCT], ex[OC_ENOISE_MAXOCT], ey[OC_ENOISE_MAXOCT];
  int cnt = nz->octaves;
  octave_noise(nz, u, v, cnt, ev, ex, ey);
  octsum q;
  octsum_init(nz, &q);
  octaves_taylor(nz, 0, cnt, ev, ex, ey, R, OC_ETAY_CHOICE, &q);
  q.m.v = q.sum; /* bit for bit noise_sum's (no level of detail) */
  *o = q.m;
}

/* sqrt(d2) >= lim (lim >= 0), the correctly rounded sqrt's answer: from
** the squares where they differ by more than their roundings can (a
** relative 1e-13; lim's square a normal number), else by the sqrt. */
static inline int sqrt_ge(double d2, double lim) {
  double l2 = lim * lim;
  if (l2 >= 0x1p-1000 && l2 <= 0x1p1000) {
    if (d2 > l2 * (1 + 1e-13)) return 1;
    if (d2 < l2 * (1 - 1e-13)) return 0;
  }
  return sqrt(d2) >= lim;
}

void oc_edisc_taylor_alpha(const oc_enode *n, double x, double y, double R,
                           oc_etay *a) {
  const double *p = OC_EDISC(n)->par; /* cx, cy, r, height */
  double u = x - p[0], v = y - p[1], r = p[2];
  double d2 = u * u + v * v, q = d2 / (r * r);
  /* alpha = G(|p - c|^2 / r^2), G(q) = (1 - q)^3 on [0, 1], 0 beyond, is
  ** C2 (G, G', G'' vanish at q = 1); its Hessian's eigenvalues are 2 G' /
  ** r^2 = -6 (1 - q)^2 / r^2 across and (1 - q)(30 q - 6) / r^2 along
  ** p - c, both in [-6, 4.8] / r^2: the remainder is at most 3 |d|^2 /
  ** r^2. Beyond |p - c| >= r + R alpha is 0 on the whole disc. */
  if (sqrt_ge(d2, (r + R) * (1 + 1e-12))) {
    *a = oc_etay_const(0); /* (its deviation 0: within the gap, 1) */
    return;
  }
  /* alpha lies in [0, 1]: at most the gap to the far end (flat) */
  double e2 = 3 / (r * r), rem = 0 + R * (0 + R * e2); /* (oc_etay_rem) */
  if (!(q < 1)) {
    /* (no linear part: the deviation is 0 R + rem, the gap 1) */
    *a = (oc_etay){0, 0, 0, 0, 0, e2};
    if (0 * R + rem > 1) *a = (oc_etay){0, 0, 0, 1, 0, 0};
    return;
  }
  double k = 1 - q, c = -6 * k * k / (r * r);
  *a = (oc_etay){k * k * k, c * u, c * v, 0, 0, e2};
  double gap = oc_fmax(a->v, 1 - a->v);
  /* oc_etay_dev(a, R) > gap: not where an upper bound of it, |gx| + |gy|
  ** for the norm and a relative 1e-12 over the roundings, is within the
  ** gap (a small disc: the commonest case), else computed */
  double gx = fabs(a->gx), gy = fabs(a->gy);
  if ((gx + gy) * R * (1 + 1e-12) + rem * (1 + 1e-12) <= gap) return;
  if (oc_etay_dev(a, R) > gap) *a = (oc_etay){a->v, 0, 0, gap, 0, 0};
}

void oc_edisc_taylor_f(const oc_enode *n, double x, double y, double R,
                       oc_etay *f) {
  const double *p = OC_EDISC(n)->par; /* cx, cy, r, height */
  oc_enoise noise;
  oc_edisc_noise(n, &noise);
  if (noise.kind == OC_ENOISE_NONE) {
    *f = oc_etay_const(p[3] + 0);
    return;
  }
  noise_taylor(&noise, x - p[0], y - p[1], R, f);
  f->v = p[3] + f->v;
}

void oc_edisc_taylor(const oc_enode *n, double x, double y, double R,
                     oc_etaylor *o) {
  oc_edisc_taylor_alpha(n, x, y, R, &o->a);
  oc_edisc_taylor_f(n, x, y, R, &o->f);
}
