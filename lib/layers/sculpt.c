/*
** sculpt.c — the sculpting tool (Peytavie et al. 2009, section 4, figure
** 9): a point primitive of potential K(r) = (1 - (r / R)^2)^2 added to or
** subtracted from the bedrock's convolution surface, its centre moved by
** delta (R / 2) along the surface normal at the picked point, and the
** stacks around rebuilt from the roots of f' = T along their axes.
**
** Only the window [c'.z - R, c'.z + R] of the stacks whose centres lie
** within R of c' is rebuilt, and inside it only where K > 0: elsewhere
** the layers stay as they were. There the column is sampled every
** cell / 8 and each change of f' > T refined by bisection.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "field/kind.h"
#include "layers/layers.h"

typedef struct sctx {
  const oc_program *P;
  oc_vec3 c;
  double R, amp, T; /* amp: +-strength 2T */
} sctx;

static double kernel(const sctx *x, oc_vec3 p) {
  double dx = p.x - x->c.x, dy = p.y - x->c.y, dz = p.z - x->c.z;
  double q = (dx * dx + dy * dy + dz * dz) / (x->R * x->R);
  return q < 1 ? (1 - q) * (1 - q) : 0;
}

/* The material at z after the edit: m0 the one before. */
static int after(const sctx *x, double px, double py, double z, int m0) {
  oc_vec3 p = {px, py, z};
  double k = kernel(x, p);
  if (k <= 0) return m0;
  int in = oc_program_eval(x->P, p) + x->amp * k > x->T;
  if (in) return OC_MAT_BEDROCK;
  return m0 == OC_MAT_BEDROCK ? OC_MAT_AIR : m0;
}

/* The material of layers l[0 .. n - 1] (from zbase) at z; air above. */
static int material_at(const oc_layer *l, size_t n, double zbase, double z) {
  double top = zbase;
  for (size_t q = 0; q < n; q++) {
    top += l[q].t;
    if (z < top) return l[q].m;
  }
  return OC_MAT_AIR;
}

typedef struct lbuf {
  oc_layer *l;
  size_t n, cap;
} lbuf;

/* Room for one more layer; 1 when out of memory. */
static int room(lbuf *b) {
  if (b->n < b->cap) return 0;
  size_t cap = b->cap ? 2 * b->cap : 32;
  oc_layer *l = realloc(b->l, cap * sizeof *l);
  if (!l) return 1;
  b->l = l;
  b->cap = cap;
  return 0;
}

static int push(lbuf *b, double t, int m) {
  if (!(t > 0)) return 0;
  if (b->n && b->l[b->n - 1].m == m) {
    b->l[b->n - 1].t += t;
    return 0;
  }
  if (room(b)) return 1;
  b->l[b->n++] = (oc_layer){t, m};
  return 0;
}

static int sculpt_after(const void *x, double px, double py, double z, int m0) {
  return after(x, px, py, z, m0);
}

/* Rebuilds one stack's layers in into b: unchanged outside [z0, z1]
** (see oc_layers_rebuild_grid). */
static int rebuild(oc_layers_after_fn after, const void *x, double px,
                   double py, const oc_layer *in, size_t n, double zbase,
                   double z0, double z1, double step, lbuf *b) {
  b->n = 0;
  double z = zbase;
  int fail = 0;
  /* below the window, as before */
  for (size_t q = 0; q < n && z < z0; q++) {
    double top = fmin(z + in[q].t, z0);
    fail |= push(b, top - z, in[q].m);
    z += in[q].t;
  }
  if (z0 < zbase) z0 = zbase;
  double zc = z0; /* the bottom of the layer being made */
  int cur = after(x, px, py, z0, material_at(in, n, zbase, z0));
  long ns = (long)ceil((z1 - z0) / step);
  double za = z0;
  for (long k = 1; k <= ns; k++) {
    double zb = k == ns ? z1 : z0 + k * step;
    int mb = after(x, px, py, zb, material_at(in, n, zbase, zb));
    if (mb != cur) {
      /* refine where the material changes (bisection on the same test) */
      double a = za, c = zb;
      for (int it = 0; it < 40 && c - a > 1e-6 * step; it++) {
        double m = 0.5 * (a + c);
        if (after(x, px, py, m, material_at(in, n, zbase, m)) == cur)
          a = m;
        else
          c = m;
      }
      double zx = 0.5 * (a + c);
      fail |= push(b, zx - zc, cur);
      zc = zx;
      cur = mb;
    }
    za = zb;
  }
  fail |= push(b, z1 - zc, cur);
  size_t nwin = b->n; /* the layers up to the window's top */
  /* above the window, as before */
  z = zbase;
  for (size_t q = 0; q < n; q++) {
    double bot = z, top = z + in[q].t;
    if (top > z1) fail |= push(b, top - fmax(bot, z1), in[q].m);
    z = top;
  }
  /* loose material the new bedrock took: back on top of that bedrock
  ** (inserted after the last bedrock layer within the window; the
  ** canonical sorting settles it) */
  double lost[OC_MAT_COUNT] = {0};
  for (size_t q = 0; q < n; q++)
    lost[in[q].m] += in[q].t;
  for (size_t q = 0; q < b->n; q++)
    lost[b->l[q].m] -= b->l[q].t;
  size_t at = nwin;
  while (at > 0 && b->l[at - 1].m != OC_MAT_BEDROCK)
    at--;
  for (int m = OC_MAT_WATER; m <= OC_MAT_ROCKS && !fail; m++) {
    if (!(lost[m] > 0)) continue;
    if (room(b)) return 1;
    memmove(b->l + at + 1, b->l + at, (b->n - at) * sizeof *b->l);
    b->l[at] = (oc_layer){lost[m], m};
    b->n++;
  }
  return fail;
}

int oc_layers_rebuild_grid(oc_stacks *w, const oc_layers_edit *e,
                           oc_error *err) {
  size_t ns = (size_t)w->nx * w->ny, most = 0;
  for (size_t k = 0; k < ns; k++)
    if (oc_scount(w, k) > most) most = oc_scount(w, k);
  oc_layer *in = malloc((most + 1) * sizeof *in);
  oc_layer *out = NULL;
  lbuf b = {NULL, 0, 0};
  oc_stacks_builder bd;
  int rc = in ? oc_builder_init(&bd, ns, oc_soff(w, ns) + 64, err)
              : oc_seterr(err, OC_ENOMEM, "out of memory");
  for (size_t k = 0; k < ns && rc == OC_OK; k++) {
    size_t n0 = 0;
    for (size_t q = oc_soff(w, k), qend = q + oc_scount(w, k); q < qend; q++)
      in[n0++] = (oc_layer){oc_lay_t(w->lay[q]), oc_lay_m(w->lay[q])};
    double px = w->x0 + (double)(k % w->nx) * w->cell;
    double py = w->y0 + (double)(k / w->nx) * w->cell, z0, z1;
    if (!e->window(e->ctx, px, py, &z0, &z1)) {
      rc = oc_builder_push(&bd, in, n0, err);
      continue;
    }
    if (!((z1 - fmax(z0, w->zbase)) / e->step <= OC_LAYERS_MAX_SAMPLES)) {
      /* (a sweep profile of 1e30 m: a count of samples beyond long, and
      ** work without end) */
      rc = oc_seterr(err, OC_EINVAL,
                     "the edit spans %g m of height at (%g, %g): more than "
                     "%d samples of %g m",
                     z1 - z0, px, py, OC_LAYERS_MAX_SAMPLES, e->step);
      break;
    }
    if (rebuild(e->after, e->ctx, px, py, in, n0, w->zbase, z0, z1, e->step,
                &b)) {
      rc = oc_seterr(err, OC_ENOMEM, "out of memory");
      break;
    }
    oc_layer *o = realloc(out, (b.n + 1) * sizeof *o);
    if (!o) {
      rc = oc_seterr(err, OC_ENOMEM, "out of memory");
      break;
    }
    out = o;
    rc = oc_builder_push(&bd, out, oc_layers_canon(b.l, b.n, out), err);
  }
  if (rc == OC_OK)
    oc_builder_commit(&bd, w);
  else if (in)
    oc_builder_free(&bd);
  free(in);
  free(out);
  free(b.l);
  return rc;
}

/* The stacks within R of the kernel's centre, over [c'.z - R, c'.z + R]. */
static int sculpt_window(void *ctx, double px, double py, double *z0,
                         double *z1) {
  const sctx *x = ctx;
  double dx = px - x->c.x, dy = py - x->c.y;
  *z0 = x->c.z - x->R;
  *z1 = x->c.z + x->R;
  return dx * dx + dy * dy < x->R * x->R;
}

int oc_stacks_sculpt(oc_stacks *s, const oc_sculpt_params *p, double *changed,
                     oc_stabilize_result *res, oc_error *err) {
  if (changed) *changed = 0;
  if (res) *res = (oc_stabilize_result){0, 1, 0};
  if (!oc_check_vec(p->center, "center", err) ||
      !oc_check_positive(p->radius, "radius", err) ||
      !oc_check_positive(p->strength, "strength", err))
    return OC_EINVAL;
  double delta = isnan(p->delta) ? p->radius / 2 : p->delta;
  if (!isfinite(delta) || delta < 0)
    return oc_seterr(err, OC_EINVAL, "'delta' must be >= 0 (got %g)", delta);
  double T = p->threshold == 0 ? OC_DEFAULT_THRESHOLD : p->threshold;
  if (!oc_check_positive(T, "threshold", err)) return OC_EINVAL;
  oc_stabilize_params sp;
  if (oc_layers_tool_stab(s, p->stab, p->stabilize, &sp, err)) return OC_EINVAL;
  /* the stacks around, edited as a grid of their own: the footprint
  ** (found below) grown by the kernel's reach and a margin */
  double c = s->cell, R = p->radius;
  double ext = R + delta + 3 * c;
  int wi0 = oc_sindex(ceil((p->center.x - ext - s->x0) / c), 0, s->nx);
  int wi1 = oc_sindex(floor((p->center.x + ext - s->x0) / c), -1, s->nx - 1);
  int wj0 = oc_sindex(ceil((p->center.y - ext - s->y0) / c), 0, s->ny);
  int wj1 = oc_sindex(floor((p->center.y + ext - s->y0) / c), -1, s->ny - 1);
  if (wi0 > wi1 || wj0 > wj1) return OC_OK;
  oc_stacks *w = oc_stacks_window(s, wi0, wj0, wi1, wj1, err);
  if (!w) return OC_ENOMEM;
  double before = oc_stacks_volume(w, OC_MAT_BEDROCK);
  oc_node *n = oc_stacks_field(w, 1u << OC_MAT_BEDROCK, NAN, err);
  oc_program *P = NULL;
  if (n) {
    oc_compile_options co = {T, 0};
    P = oc_compile(n, &co, err);
    oc_node_release(n);
  }
  if (!P) {
    oc_stacks_free(w);
    return err ? err->code : OC_ENOMEM;
  }
  /* the normal at the picked point: outward is down the gradient */
  oc_vec3 g;
  oc_program_gradient(P, p->center, &g);
  double gl = sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
  oc_vec3 nrm =
      gl > 0 ? (oc_vec3){-g.x / gl, -g.y / gl, -g.z / gl} : (oc_vec3){0, 0, 1};
  double sg = p->carve ? delta : -delta;
  sctx x = {P,
            {p->center.x + sg * nrm.x, p->center.y + sg * nrm.y,
             p->center.z + sg * nrm.z},
            p->radius,
            (p->carve ? -1 : 1) * p->strength * 2 * T,
            T};
  double i0 = fmax(ceil((x.c.x - R - s->x0) / c), 0);
  double i1 = fmin(floor((x.c.x + R - s->x0) / c), s->nx - 1);
  double j0 = fmax(ceil((x.c.y - R - s->y0) / c), 0);
  double j1 = fmin(floor((x.c.y + R - s->y0) / c), s->ny - 1);
  oc_layers_edit ed = {sculpt_window, sculpt_after, &x, c / 8};
  int rc = oc_layers_rebuild_grid(w, &ed, err);
  oc_program_free(P);
  double after = oc_stacks_volume(w, OC_MAT_BEDROCK);
  if (rc == OC_OK) rc = oc_stacks_splice(s, w, wi0, wj0, err);
  oc_stacks_free(w);
  if (rc) return rc;
  if (changed) *changed = after - before;
  if (!p->stabilize || i0 > i1 || j0 > j1) return OC_OK;
  sp.region[0] = (int)i0;
  sp.region[1] = (int)j0;
  sp.region[2] = (int)i1;
  sp.region[3] = (int)j1;
  return oc_layers_stabilize_local(s, &sp, res, err);
}
