/*
** karst.c — karst networks by invasion percolation (Paris et al. 2019, section
** 6.2): oc_karst_cavities runs the percolation, oc_generate_karst turns
** its cavities into a blend of negative point primitives.
**
** Invasion percolation is sequential: each pop depends on every push
** before it. What makes it fast is that a pop costs a heap operation, a
** few hash probes and `branches` resistance evaluations, with nothing
** allocated but the amortized growth of the point arrays.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/error.h"
#include "core/rng.h"

#define DEFAULT_MAX 100000
#define MAX_BRANCHES 64
/* The hash grid addresses cells with 32-bit coordinates. */
#define MAX_CELLS_AXIS 1.0e9
#define REPORT_EVERY 1024

/* ---- candidates ----------------------------------------------------- */

typedef struct pts {
  oc_vec3 *p;
  double *rho;
  int64_t *parent; /* cavity index of the parent, -1 at a sink */
  uint32_t *next;  /* next point in the same hash cell, or UINT32_MAX */
  size_t n, cap;
} pts;

static int pts_grow(pts *P) {
  if (P->n < P->cap) return 0;
  size_t cap = P->cap ? 2 * P->cap : 4096;
  if (cap > UINT32_MAX - 1) cap = UINT32_MAX - 1;
  if (cap <= P->n) return -1;
  void *a = realloc(P->p, cap * sizeof *P->p);
  if (a) P->p = a;
  void *b = a ? realloc(P->rho, cap * sizeof *P->rho) : NULL;
  if (b) P->rho = b;
  void *c = b ? realloc(P->parent, cap * sizeof *P->parent) : NULL;
  if (c) P->parent = c;
  void *d = c ? realloc(P->next, cap * sizeof *P->next) : NULL;
  if (d) P->next = d;
  if (!d) return -1;
  P->cap = cap;
  return 0;
}

static void pts_free(pts *P) {
  free(P->p);
  free(P->rho);
  free(P->parent);
  free(P->next);
}

/* ---- the priority queue: a binary min-heap on (key, index) ------------ */

typedef struct hent {
  double key;
  uint32_t id;
} hent;

typedef struct heap {
  hent *a;
  size_t n, cap;
} heap;

/* Older candidates win ties, so the order never depends on the heap's
** internal layout. */
static int less(hent x, hent y) {
  return x.key < y.key || (x.key == y.key && x.id < y.id);
}

static int heap_push(heap *H, hent e) {
  if (H->n == H->cap) {
    size_t cap = H->cap ? 2 * H->cap : 4096;
    hent *a = realloc(H->a, cap * sizeof *a);
    if (!a) return -1;
    H->a = a;
    H->cap = cap;
  }
  size_t i = H->n++;
  while (i > 0) {
    size_t up = (i - 1) / 2;
    if (!less(e, H->a[up])) break;
    H->a[i] = H->a[up];
    i = up;
  }
  H->a[i] = e;
  return 0;
}

static hent heap_pop(heap *H) {
  hent top = H->a[0], e = H->a[--H->n];
  size_t i = 0, n = H->n;
  for (;;) {
    size_t k = 2 * i + 1;
    if (k >= n) break;
    if (k + 1 < n && less(H->a[k + 1], H->a[k])) k++;
    if (!less(H->a[k], e)) break;
    H->a[i] = H->a[k];
    i = k;
  }
  if (n) H->a[i] = e;
  return top;
}

/* ---- Poisson-sphere rejection: a hash of grid cells of side `spacing` -- */

typedef struct cell {
  int32_t c[3];
  uint32_t head; /* first point, UINT32_MAX: empty slot */
} cell;

typedef struct grid {
  cell *t;
  size_t cap, used; /* cap a power of two */
  double inv, s2;   /* 1 / spacing, spacing^2 */
  oc_vec3 o;        /* origin of cell (0, 0, 0) */
} grid;

static size_t slot_of(const grid *G, const int32_t c[3]) {
  uint64_t h =
      oc_hash2(oc_hash2((uint32_t)c[0], (uint32_t)c[1]), (uint32_t)c[2]);
  size_t i = (size_t)h & (G->cap - 1);
  for (;;) {
    const cell *e = &G->t[i];
    if (e->head == UINT32_MAX ||
        (e->c[0] == c[0] && e->c[1] == c[1] && e->c[2] == c[2]))
      return i;
    i = (i + 1) & (G->cap - 1);
  }
}

static void cell_of(const grid *G, oc_vec3 p, int32_t c[3]) {
  c[0] = (int32_t)floor((p.x - G->o.x) * G->inv);
  c[1] = (int32_t)floor((p.y - G->o.y) * G->inv);
  c[2] = (int32_t)floor((p.z - G->o.z) * G->inv);
}

static int grid_rehash(grid *G) {
  size_t cap = G->cap ? 2 * G->cap : 1 << 14;
  cell *old = G->t;
  size_t ocap = G->cap;
  G->t = malloc(cap * sizeof *G->t);
  if (!G->t) {
    G->t = old;
    return -1;
  }
  G->cap = cap;
  for (size_t i = 0; i < cap; i++)
    G->t[i].head = UINT32_MAX;
  for (size_t i = 0; i < ocap; i++)
    if (old[i].head != UINT32_MAX) G->t[slot_of(G, old[i].c)] = old[i];
  free(old);
  return 0;
}

/* 1 when some point of the grid lies closer than spacing to q. */
static int grid_near(const grid *G, const pts *P, oc_vec3 q) {
  int32_t c[3], d[3];
  cell_of(G, q, c);
  for (int dz = -1; dz <= 1; dz++)
    for (int dy = -1; dy <= 1; dy++)
      for (int dx = -1; dx <= 1; dx++) {
        d[0] = c[0] + dx;
        d[1] = c[1] + dy;
        d[2] = c[2] + dz;
        for (uint32_t k = G->t[slot_of(G, d)].head; k != UINT32_MAX;
             k = P->next[k]) {
          double ex = P->p[k].x - q.x, ey = P->p[k].y - q.y,
                 ez = P->p[k].z - q.z;
          if (ex * ex + ey * ey + ez * ez < G->s2) return 1;
        }
      }
  return 0;
}

static int grid_add(grid *G, pts *P, uint32_t k) {
  if (2 * (G->used + 1) > G->cap && grid_rehash(G)) return -1;
  int32_t c[3];
  cell_of(G, P->p[k], c);
  cell *e = &G->t[slot_of(G, c)];
  if (e->head == UINT32_MAX) {
    memcpy(e->c, c, sizeof c);
    G->used++;
  }
  P->next[k] = e->head;
  e->head = k;
  return 0;
}

/* ---- parameters ------------------------------------------------------- */

void oc_gen_karst_defaults(oc_gen_karst_params *p) {
  memset(p, 0, sizeof *p);
  p->seed = 1;
  p->cover = NAN;
  p->floor = NAN;
  p->epsilon = 0.1;
  p->rho0 = 0.5;
  p->energy = 1.5;
  p->beta = 0.5;
  p->branches = 6;
  p->max_primitives = DEFAULT_MAX;
}

/* The run's resolved settings. */
typedef struct run {
  const oc_gen_karst_params *p;
  const oc_heightfield *hf;
  const oc_program *geo;
  double R, step, spacing, cover, floor;
  double x0, y0, x1, y1; /* where centres may lie */
} run;

static int check(const oc_gen_karst_params *p, run *r, oc_error *err) {
  if (!p) return oc_seterr(err, OC_EINVAL, "karst needs parameters");
  if (!p->heightfield)
    return oc_seterr(err, OC_EINVAL, "'heightfield' is required");
  const oc_heightfield *hf = p->heightfield;
  double cell = oc_heightfield_cell(hf), hx0, hy0, lo, hi;
  oc_heightfield_origin(hf, &hx0, &hy0);
  oc_heightfield_minmax(hf, &lo, &hi);
  double w = cell * (oc_heightfield_nx(hf) - 1);
  double h = cell * (oc_heightfield_ny(hf) - 1);
  r->p = p;
  r->hf = hf;
  r->R = p->radius == 0 ? 2 * cell : p->radius;
  if (!(r->R > 0) || !isfinite(r->R))
    return oc_seterr(err, OC_EINVAL, "'radius' must be > 0 (got %g)",
                     p->radius);
  if (!(2 * r->R < w && 2 * r->R < h))
    return oc_seterr(err, OC_EINVAL,
                     "'radius' %g is too large for a heightfield of %g x %g",
                     r->R, w, h);
  r->step = p->step == 0 ? r->R : p->step;
  if (!(r->step > 0) || !isfinite(r->step))
    return oc_seterr(err, OC_EINVAL, "'step' must be > 0 (got %g)", p->step);
  if (!(r->step <= fmax(w, h)))
    return oc_seterr(err, OC_EINVAL,
                     "'step' %g is longer than the heightfield (%g x %g)",
                     r->step, w, h);
  r->spacing = p->spacing == 0 ? r->R / 2 : p->spacing;
  if (!(r->spacing > 0) || !isfinite(r->spacing))
    return oc_seterr(err, OC_EINVAL, "'spacing' must be > 0 (got %g)",
                     p->spacing);
  double span = fmax(fmax(w, h), hi - lo + 4 * r->R) + 2 * r->step;
  if (!(span / r->spacing < MAX_CELLS_AXIS))
    return oc_seterr(err, OC_EINVAL,
                     "'spacing' %g is too small for a heightfield %g wide",
                     r->spacing, span);
  r->cover = isnan(p->cover) ? r->R / 4 : p->cover;
  if (!(r->cover >= 0) || !isfinite(r->cover))
    return oc_seterr(err, OC_EINVAL, "'cover' must be >= 0 (got %g)", p->cover);
  r->floor = isnan(p->floor) ? lo + r->R : p->floor;
  if (!isfinite(r->floor))
    return oc_seterr(err, OC_EINVAL, "'floor' must be finite (got %g)",
                     p->floor);
  if (!((hi - r->floor) / r->spacing < MAX_CELLS_AXIS))
    return oc_seterr(err, OC_EINVAL,
                     "'floor' %g lies too far below the surface for "
                     "'spacing' %g",
                     r->floor, r->spacing);
  if (!(p->epsilon >= 0) || !isfinite(p->epsilon))
    return oc_seterr(err, OC_EINVAL, "'epsilon' must be >= 0 (got %g)",
                     p->epsilon);
  if (!(p->rho0 > 0 && p->rho0 <= 1))
    return oc_seterr(err, OC_EINVAL, "'rho0' must be in (0, 1] (got %g)",
                     p->rho0);
  if (!(p->energy > 0) || !isfinite(p->energy))
    return oc_seterr(err, OC_EINVAL, "'energy' must be > 0 (got %g)",
                     p->energy);
  if (!(p->beta >= 0 && p->beta <= 1))
    return oc_seterr(err, OC_EINVAL, "'beta' must be in [0, 1] (got %g)",
                     p->beta);
  if (p->branches < 1 || p->branches > MAX_BRANCHES)
    return oc_seterr(err, OC_EINVAL, "'branches' must be 1 .. %d (got %d)",
                     MAX_BRANCHES, p->branches);
  if (p->max_primitives < 1 || p->max_primitives > OC_KARST_MAX)
    return oc_seterr(err, OC_EINVAL,
                     "'max_primitives' must be 1 .. %d (got %zu)", OC_KARST_MAX,
                     p->max_primitives);
  if (p->nsinks && !p->sinks)
    return oc_seterr(err, OC_EINVAL, "'sinks' is NULL with a count");
  r->x0 = hx0 + r->R;
  r->y0 = hy0 + r->R;
  r->x1 = hx0 + w - r->R;
  r->y1 = hy0 + h - r->R;
  return OC_OK;
}

/* Where a centre may lie. */
static int allowed(const run *r, oc_vec3 q) {
  if (!(q.x >= r->x0 && q.x <= r->x1 && q.y >= r->y0 && q.y <= r->y1)) return 0;
  if (!(q.z >= r->floor)) return 0;
  return q.z <= oc_heightfield_height(r->hf, q.x, q.y, NULL) - r->cover;
}

/* The clamped resistance; NaN from the geology stays NaN (an error). */
static double rho_at(const run *r, oc_vec3 q) {
  double v = oc_program_eval(r->geo, q);
  return v < 0 ? 0 : v > 1 ? 1 : v;
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* A geology program: the caller's, or the default strata. */
static oc_program *geology(const run *r, oc_error *err) {
  const oc_gen_karst_params *p = r->p;
  if (p->geology) return oc_compile(p->geology, NULL, err);
  oc_noise nz = {8 * r->R, 1, 0, 3, p->seed};
  oc_node *g = oc_strata(&nz, err);
  if (!g) return NULL;
  oc_program *prog = oc_compile(g, NULL, err);
  oc_node_release(g);
  return prog;
}

/* Queues point k (already stored) with its perturbed key. */
static int enqueue(const run *r, pts *P, heap *H, grid *G, uint32_t k,
                   oc_error *err) {
  double v = rho_at(r, P->p[k]);
  if (isnan(v))
    return oc_seterr(err, OC_EINVAL, "'geology' is NaN at (%g, %g, %g)",
                     P->p[k].x, P->p[k].y, P->p[k].z);
  P->rho[k] = v;
  oc_rng g = oc_rng_stream(r->p->seed, k);
  hent e = {v + r->p->epsilon * oc_rng_uniform(&g), k};
  if (heap_push(H, e) || grid_add(G, P, k))
    return oc_seterr(err, OC_ENOMEM, "out of memory queueing candidates");
  return OC_OK;
}

static int add_cavity(oc_karst_cavity **cav, size_t *n, size_t *cap,
                      oc_karst_cavity c) {
  if (*n == *cap) {
    size_t nc = *cap ? 2 * *cap : 1024;
    oc_karst_cavity *a = realloc(*cav, nc * sizeof *a);
    if (!a) return -1;
    *cav = a;
    *cap = nc;
  }
  (*cav)[(*n)++] = c;
  return 0;
}

/* The sinks given, or the heightfield's pits; into P and the queue. */
static int seed_sinks(const run *r, pts *P, heap *H, grid *G, size_t *nsinks,
                      oc_error *err) {
  const oc_gen_karst_params *p = r->p;
  oc_vec3 *found = NULL;
  const oc_vec3 *s = p->sinks;
  size_t n = p->nsinks;
  if (!s) {
    int rc = oc_heightfield_sinks(r->hf, &found, &n, err);
    if (rc) return rc;
    s = found;
  }
  int rc = OC_OK;
  *nsinks = 0;
  for (size_t i = 0; i < n && rc == OC_OK; i++) {
    oc_vec3 q = s[i];
    if (!isfinite(q.x) || !isfinite(q.y) || !isfinite(q.z)) {
      rc = oc_seterr(err, OC_EINVAL, "'sinks'[%zu] is not finite", i + 1);
      break;
    }
    if (p->sinks &&
        !(q.x >= r->x0 && q.x <= r->x1 && q.y >= r->y0 && q.y <= r->y1)) {
      rc = oc_seterr(err, OC_EINVAL,
                     "'sinks'[%zu] (%g, %g) lies outside the heightfield "
                     "shrunk by 'radius' ([%g, %g] x [%g, %g])",
                     i + 1, q.x, q.y, r->x0, r->x1, r->y0, r->y1);
      break;
    }
    double top = oc_heightfield_height(r->hf, q.x, q.y, NULL) - r->cover;
    if (q.z > top) q.z = top;
    if (!allowed(r, q) || grid_near(G, P, q)) continue;
    if (pts_grow(P)) {
      rc = oc_seterr(err, OC_ENOMEM, "out of memory queueing sinks");
      break;
    }
    uint32_t k = (uint32_t)P->n++;
    P->p[k] = q;
    P->parent[k] = -1;
    rc = enqueue(r, P, H, G, k, err);
    (*nsinks)++;
  }
  free(found);
  return rc;
}

/* A uniform direction of the lower hemisphere: dz uniform in [-1, 0]
** makes the area measure uniform (Archimedes). */
static oc_vec3 lower_dir(oc_rng *g) {
  double z = -oc_rng_uniform(g);
  double a = 6.283185307179586 * oc_rng_uniform(g);
  double s = sqrt(fmax(0, 1 - z * z));
  oc_vec3 d = {s * cos(a), s * sin(a), z};
  return d;
}

static int percolate(const run *r, pts *P, heap *H, grid *G,
                     oc_karst_cavity **cav, size_t *ncav, oc_error *err) {
  const oc_gen_karst_params *p = r->p;
  const double stop = p->rho0 + p->epsilon;
  size_t cap = 0, pops = 0;
  while (H->n > 0 && *ncav < p->max_primitives) {
    hent e = heap_pop(H);
    if (e.key >= stop) break; /* nothing left can have rho < rho0 */
    if (p->progress.fn && ++pops % REPORT_EVERY == 0 &&
        p->progress.fn(p->progress.ud,
                       (double)*ncav / (double)p->max_primitives))
      return oc_seterr(err, OC_ECANCEL, "karst cancelled");
    uint32_t k = e.id;
    double v = P->rho[k];
    if (!(v < p->rho0)) continue;
    oc_karst_cavity c = {P->p[k], r->R,
                         -p->energy * (p->beta + (1 - p->beta) * (1 - v)), v,
                         P->parent[k]};
    if (add_cavity(cav, ncav, &cap, c))
      return oc_seterr(err, OC_ENOMEM, "out of memory storing cavities");
    int64_t me = (int64_t)*ncav - 1;
    /* Draws after the key's: the candidate's own stream, counter 1 on. */
    oc_rng g = oc_rng_stream(p->seed, k);
    (void)oc_rng_uniform(&g);
    for (int b = 0; b < p->branches; b++) {
      oc_vec3 d = lower_dir(&g);
      oc_vec3 q = {c.center.x + r->step * d.x, c.center.y + r->step * d.y,
                   c.center.z + r->step * d.z};
      if (!allowed(r, q) || grid_near(G, P, q)) continue;
      if (pts_grow(P))
        return oc_seterr(err, OC_ENOMEM, "out of memory queueing candidates");
      uint32_t id = (uint32_t)P->n++;
      P->p[id] = q;
      P->parent[id] = me;
      int rc = enqueue(r, P, H, G, id, err);
      if (rc) return rc;
    }
  }
  return OC_OK;
}

int oc_karst_cavities(const oc_gen_karst_params *p, oc_karst_cavity **out,
                      size_t *n, oc_gen_karst_stats *st, oc_error *err) {
  double t0 = now();
  run r;
  if (!out || !n) return oc_seterr(err, OC_EINVAL, "karst needs outputs");
  *out = NULL;
  *n = 0;
  int rc = check(p, &r, err);
  if (rc) return rc;
  oc_program *geo = geology(&r, err);
  if (!geo) return err ? err->code : OC_ENOMEM;
  r.geo = geo;
  pts P = {0};
  heap H = {0};
  grid G = {0};
  G.inv = 1 / r.spacing;
  G.s2 = r.spacing * r.spacing;
  oc_heightfield_origin(r.hf, &G.o.x, &G.o.y);
  G.o.z = r.floor;
  size_t nsinks = 0;
  oc_karst_cavity *cav = NULL;
  if (grid_rehash(&G))
    rc = oc_seterr(err, OC_ENOMEM, "out of memory");
  else
    rc = seed_sinks(&r, &P, &H, &G, &nsinks, err);
  if (rc == OC_OK) rc = percolate(&r, &P, &H, &G, &cav, n, err);
  if (st) {
    st->primitives = *n;
    st->candidates = P.n;
    st->sinks = nsinks;
    st->seconds = now() - t0;
  }
  pts_free(&P);
  free(H.a);
  free(G.t);
  oc_program_free(geo);
  if (rc) {
    free(cav);
    *n = 0;
    if (st) st->primitives = 0;
    return rc;
  }
  *out = cav;
  return OC_OK;
}

oc_node *oc_generate_karst(const oc_gen_karst_params *p, oc_gen_karst_stats *st,
                           oc_error *err) {
  double t0 = now();
  oc_karst_cavity *cav;
  size_t n;
  if (oc_karst_cavities(p, &cav, &n, st, err)) return NULL;
  /* the default terrain, the one outcrop.generate.karst blends with */
  oc_node *terrain = p->terrain, *own = NULL;
  if (!terrain && !p->no_terrain &&
      !(terrain = own = oc_heightfield_terrain(p->heightfield, NULL, err))) {
    free(cav);
    return NULL;
  }
  size_t nt = terrain ? 1 : 0;
  if (n + nt == 0) {
    oc_seterr(err, OC_EINVAL,
              "nothing was carved and there is no 'terrain' to return");
    return NULL;
  }
  oc_node **kids = malloc((n + nt) * sizeof *kids);
  oc_node *res = NULL;
  size_t made = 0;
  if (!kids) {
    oc_seterr(err, OC_ENOMEM, "out of memory for %zu cavities", n);
    goto done;
  }
  if (terrain) kids[made++] = terrain;
  for (size_t i = 0; i < n; i++) {
    oc_node *pt = oc_point(cav[i].center, cav[i].radius, cav[i].energy, err);
    if (!pt) goto done;
    kids[made++] = pt;
  }
  res = oc_blend(kids, made, err);
done:
  for (size_t i = nt; i < made; i++)
    oc_node_release(kids[i]);
  free(kids);
  free(cav);
  oc_node_release(own); /* the blend holds its own reference */
  if (st) st->seconds = now() - t0;
  return res;
}
