/*
** rocks.c — rock piles (Peytavie et al. 2009, section 5): a periodic tile
** of eroded Voronoi cells, placed by the replication operator of the
** block family wherever the stacks hold rocks.
**
** The tile: periodic maximal Poisson centres p_i in the cube [0, s)^3
** (closest two `radius` r apart), each the site of a Voronoi cell of the
** 3-torus. Every point lies within r of a site (the set is maximal), so a
** cell's vertices are within r of its site and its faces come from the
** sites' images within 2r: the cell is found from those bisector planes
** by intersecting them three at a time (the candidates are few, ~40).
** Then the erosion: on each face shared by cells V_i and V_j, `contacts`
** random points c_ij (Dirichlet weights over the face's vertices, drawn
** from a stream keyed by the pair, so both cells get the same points);
** a point x of the face is eroded inward by e (1 - rho(x)), rho(x) =
** max exp(-|x - c|^2 / spread^2) over the face's contacts (the paper's
** resistance, spread = r by default). The rock is the convex hull of the
** cell's faces offset inward by e (erosion by a ball) and of rings of
** eroded face points around each contact: convex, inside its cell (so
** no two rocks overlap), and touching its neighbours at the contacts.
** The paper erodes with spheroidal erosion (Beardall et al. 2007); a
** hull gives the convex block primitive of the rock blocks (Paris et al.
** 2020) its half-spaces directly, rounded by its smooth intersection.
**
** A rock tile is a block tile (oc_btile): its blocks are the rocks, their
** centroids the Voronoi sites. Placement (oc_stacks_rocks) is the blocks'
** replication with a presence test instead of its criteria: a rock is an
** instance when its site lies in a rocks layer of the stacks at most
** `depth` (default twice the largest distance from a site to its rock's
** vertices) below the top of the solid there; deeper rocks are culled, as
** the paper drops rocks farther than twice the largest embedding sphere
** from the surface.
*/
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "blocks/btile.h"
#include "core/error.h"
#include "core/rng.h"

#define KEY_SITES 0x726f636b73ull
#define KEY_CONTACT 0x636f6e74616374ull
#define ROCKS_MAX 20000 /* sites at most */
#define CAND_MAX 400    /* candidate planes of a cell at most */
#define RING_R 4        /* rings around a contact, out to 2 spread */
#define RING_A 8        /* points on a ring */

/* ---- Voronoi cells --------------------------------------------------- */

typedef struct rface {
  uint32_t j;    /* the neighbour's site */
  int o[3];      /* its image: p_j + s o */
  double pl[4];  /* unit normal, offset: n . x + off <= 0 inside */
  size_t v0, nv; /* its vertices: fv[v0 .. v0 + nv) index the cell's */
} rface;

typedef struct rcell {
  size_t nf, nv;
  rface *f;
  double *v;    /* 3 per vertex */
  size_t *fv;   /* vertex indices of the faces */
  double reach; /* largest distance from the site to a vertex */
} rcell;

static void cell_free(rcell *c) {
  free(c->f);
  free(c->v);
  free(c->fv);
  memset(c, 0, sizeof *c);
}

static double dot3(const double *a, const double *b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The point on planes a, b, c, or 0 when they are near parallel. */
static int meet3(const double *a, const double *b, const double *c, double *x) {
  double bc[3] = {b[1] * c[2] - b[2] * c[1], b[2] * c[0] - b[0] * c[2],
                  b[0] * c[1] - b[1] * c[0]};
  double det = dot3(a, bc);
  if (fabs(det) < 1e-9) return 0;
  double ca[3] = {c[1] * a[2] - c[2] * a[1], c[2] * a[0] - c[0] * a[2],
                  c[0] * a[1] - c[1] * a[0]};
  double ab[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                  a[0] * b[1] - a[1] * b[0]};
  for (int k = 0; k < 3; k++)
    x[k] = -(a[3] * bc[k] + b[3] * ca[k] + c[3] * ab[k]) / det;
  return 1;
}

/* The vertices of {x : pl_k . x + off_k + shrink <= 0 for all k} into a
** new array *v (count *nv): the planes met three at a time, kept when
** inside all (within eps), without duplicates. */
static int vertices(const double *pl, size_t np, double shrink, double eps,
                    double **v, size_t *nv) {
  size_t cap = 64, n = 0;
  double *out = malloc(cap * 3 * sizeof *out);
  if (!out) return OC_ENOMEM;
  double a[4], b[4], c[4];
  for (size_t i = 0; i < np; i++) {
    memcpy(a, pl + 4 * i, sizeof a);
    a[3] += shrink;
    for (size_t j = i + 1; j < np; j++) {
      memcpy(b, pl + 4 * j, sizeof b);
      b[3] += shrink;
      for (size_t k = j + 1; k < np; k++) {
        memcpy(c, pl + 4 * k, sizeof c);
        c[3] += shrink;
        double x[3];
        if (!meet3(a, b, c, x)) continue;
        size_t m = 0;
        for (; m < np; m++)
          if (dot3(pl + 4 * m, x) + pl[4 * m + 3] + shrink > eps) break;
        if (m < np) continue;
        for (m = 0; m < n; m++) {
          const double *y = out + 3 * m;
          double dx = x[0] - y[0], dy = x[1] - y[1], dz = x[2] - y[2];
          if (dx * dx + dy * dy + dz * dz < eps * eps) break;
        }
        if (m < n) continue;
        if (n == cap) {
          double *g = realloc(out, 2 * cap * 3 * sizeof *out);
          if (!g) {
            free(out);
            return OC_ENOMEM;
          }
          out = g;
          cap *= 2;
        }
        memcpy(out + 3 * n++, x, sizeof x);
      }
    }
  }
  *v = out;
  *nv = n;
  return OC_OK;
}

/* Cell i of the sites p (n of them, in [0, s)^3). */
static int cell_make(const double *p, size_t n, size_t i, double s, double r,
                     rcell *c, oc_error *err) {
  const double *pi = p + 3 * i;
  double eps = 1e-9 * r, D = 2 * r * (1 + 1e-9);
  rface *cand = malloc(CAND_MAX * sizeof *cand);
  double *pl = malloc(CAND_MAX * 4 * sizeof *pl);
  int rc = OC_ENOMEM;
  memset(c, 0, sizeof *c);
  if (!cand || !pl) goto done;
  size_t m = 0;
  for (size_t j = 0; j < n; j++)
    for (int oz = -1; oz <= 1; oz++)
      for (int oy = -1; oy <= 1; oy++)
        for (int ox = -1; ox <= 1; ox++) {
          double q[3] = {p[3 * j] + s * ox, p[3 * j + 1] + s * oy,
                         p[3 * j + 2] + s * oz};
          double d[3] = {q[0] - pi[0], q[1] - pi[1], q[2] - pi[2]};
          double l = sqrt(dot3(d, d));
          if (!(l > eps) || l > D) continue;
          if (m == CAND_MAX) {
            rc = oc_seterr(err, OC_EINVAL,
                           "more than %d neighbours for rock %zu: 'radius' "
                           "too small for 'size'",
                           CAND_MAX, i + 1);
            goto done;
          }
          rface *f = &cand[m];
          f->j = (uint32_t)j;
          f->o[0] = ox, f->o[1] = oy, f->o[2] = oz;
          for (int a = 0; a < 3; a++)
            f->pl[a] = d[a] / l;
          f->pl[3] = -(f->pl[0] * (pi[0] + 0.5 * d[0]) +
                       f->pl[1] * (pi[1] + 0.5 * d[1]) +
                       f->pl[2] * (pi[2] + 0.5 * d[2]));
          memcpy(pl + 4 * m, f->pl, sizeof f->pl);
          m++;
        }
  rc = vertices(pl, m, 0, 1e-7 * r, &c->v, &c->nv);
  if (rc) goto done;
  /* the faces: candidates holding 3 vertices or more */
  c->f = malloc((m ? m : 1) * sizeof *c->f);
  c->fv = malloc((c->nv * m + 1) * sizeof *c->fv);
  if (!c->f || !c->fv) {
    rc = OC_ENOMEM;
    goto done;
  }
  size_t nfv = 0;
  for (size_t k = 0; k < m; k++) {
    size_t v0 = nfv;
    for (size_t v = 0; v < c->nv; v++)
      if (fabs(dot3(cand[k].pl, c->v + 3 * v) + cand[k].pl[3]) < 1e-6 * r)
        c->fv[nfv++] = v;
    if (nfv - v0 < 3) {
      nfv = v0;
      continue;
    }
    c->f[c->nf] = cand[k];
    c->f[c->nf].v0 = v0;
    c->f[c->nf].nv = nfv - v0;
    c->nf++;
  }
  c->reach = 0;
  for (size_t v = 0; v < c->nv; v++) {
    const double *x = c->v + 3 * v;
    double d[3] = {x[0] - pi[0], x[1] - pi[1], x[2] - pi[2]};
    c->reach = fmax(c->reach, sqrt(dot3(d, d)));
  }
  if (c->nf < 4 || !(c->reach < r * (1 + 1e-6)))
    rc = oc_seterr(err, OC_EINVAL, "rock %zu: its Voronoi cell is not closed",
                   i + 1);
done:
  free(cand);
  free(pl);
  return rc;
}

/* ---- erosion --------------------------------------------------------- */

/* Contact k of face f of cell a (site index ia): Dirichlet weights over
** the face's vertices, from a stream keyed by the face. */
static void contact(const rcell *a, size_t ia, const rface *f, int k,
                    uint64_t seed, double *x) {
  uint64_t key = oc_hash2(
      oc_hash2(ia, f->j),
      (uint64_t)((f->o[0] + 1) + 3 * (f->o[1] + 1) + 9 * (f->o[2] + 1)));
  oc_rng g = oc_rng_stream(oc_hash2(seed, KEY_CONTACT), oc_hash2(key, k));
  double w = 0;
  x[0] = x[1] = x[2] = 0;
  for (size_t v = 0; v < f->nv; v++) {
    double e = -log(1 - oc_rng_uniform(&g));
    const double *y = a->v + 3 * a->fv[f->v0 + v];
    for (int q = 0; q < 3; q++)
      x[q] += e * y[q];
    w += e;
  }
  for (int q = 0; q < 3; q++)
    x[q] /= w;
}

/* Is site i the owner of its face with (j, o)? The owner draws the
** contacts; the other cell finds them through its own face (i, -o). */
static int owns(size_t i, const rface *f) {
  if (i != f->j) return i < f->j;
  for (int a = 2; a >= 0; a--)
    if (f->o[a]) return f->o[a] > 0;
  return 1;
}

static const rface *mirror(const rcell *cj, size_t i, const int *o) {
  for (size_t k = 0; k < cj->nf; k++) {
    const rface *f = &cj->f[k];
    if (f->j == i && f->o[0] == -o[0] && f->o[1] == -o[1] && f->o[2] == -o[2])
      return f;
  }
  return NULL;
}

typedef struct pts {
  double *x;
  size_t n, cap;
} pts;

static int pts_add(pts *p, const double *x) {
  if (p->n == p->cap) {
    size_t nc = p->cap ? 2 * p->cap : 1024;
    double *g = realloc(p->x, nc * 3 * sizeof *g);
    if (!g) return OC_ENOMEM;
    p->x = g;
    p->cap = nc;
  }
  memcpy(p->x + 3 * p->n++, x, 3 * sizeof *x);
  return OC_OK;
}

/* The rock of cell i into b. */
static int rock_make(const rcell *cells, const double *sites, size_t i,
                     const oc_rocks_params *rp, pts *P, oc_bblock *b,
                     oc_error *err) {
  const rcell *c = &cells[i];
  double s = rp->size, e = rp->erosion * rp->radius,
         sp = rp->spread * rp->radius, eps = 1e-9 * rp->radius;
  int nc = rp->contacts;
  P->n = 0;
  /* the cell eroded by a ball of radius e: its faces offset inward */
  double *pl = malloc(c->nf * 4 * sizeof *pl), *v = NULL;
  double *ct = malloc((c->nf * (size_t)nc + 1) * 3 * sizeof *ct);
  size_t nv = 0;
  int rc = OC_ENOMEM;
  if (!pl || !ct) goto done;
  for (size_t k = 0; k < c->nf; k++)
    memcpy(pl + 4 * k, c->f[k].pl, 4 * sizeof *pl);
  if ((rc = vertices(pl, c->nf, e, 1e-7 * rp->radius, &v, &nv))) goto done;
  for (size_t k = 0; k < nv; k++)
    if ((rc = pts_add(P, v + 3 * k))) goto done;
  /* the contacts of each face, in this cell's coordinates */
  for (size_t k = 0; k < c->nf; k++) {
    const rface *f = &c->f[k];
    for (int q = 0; q < nc; q++) {
      double *x = ct + 3 * (k * nc + q);
      const rface *g = owns(i, f) ? NULL : mirror(&cells[f->j], i, f->o);
      if (g) {
        contact(&cells[f->j], f->j, g, q, rp->seed, x);
        for (int a = 0; a < 3; a++)
          x[a] += s * f->o[a];
      } else {
        contact(c, i, f, q, rp->seed, x);
      }
    }
  }
  /* rings of eroded points around each contact, on its face */
  for (size_t k = 0; k < c->nf; k++) {
    const double *n = c->f[k].pl;
    double u[3], w[3],
        t[3] = {fabs(n[0]) < 0.6 ? 1 : 0, fabs(n[0]) < 0.6 ? 0 : 1, 0};
    u[0] = n[1] * t[2] - n[2] * t[1];
    u[1] = n[2] * t[0] - n[0] * t[2];
    u[2] = n[0] * t[1] - n[1] * t[0];
    double ul = sqrt(dot3(u, u));
    for (int a = 0; a < 3; a++)
      u[a] /= ul;
    w[0] = n[1] * u[2] - n[2] * u[1];
    w[1] = n[2] * u[0] - n[0] * u[2];
    w[2] = n[0] * u[1] - n[1] * u[0];
    for (int q = 0; q < nc; q++) {
      const double *cq = ct + 3 * (k * nc + q);
      for (int ri = 0; ri <= RING_R; ri++)
        for (int ai = 0; ai < (ri ? RING_A : 1); ai++) {
          double d = 2 * sp * ri / RING_R, th = 6.283185307179586 * ai / RING_A;
          double x[3];
          for (int a = 0; a < 3; a++)
            x[a] = cq[a] + d * (cos(th) * u[a] + sin(th) * w[a]);
          size_t m = 0; /* on the face: inside the cell's other planes */
          for (; m < c->nf; m++)
            if (m != k && dot3(c->f[m].pl, x) + c->f[m].pl[3] > eps) break;
          if (m < c->nf) continue;
          double rho = 0;
          for (int z = 0; z < nc; z++) {
            const double *cz = ct + 3 * (k * nc + z);
            double dd[3] = {x[0] - cz[0], x[1] - cz[1], x[2] - cz[2]};
            rho = fmax(rho, exp(-dot3(dd, dd) / (sp * sp)));
          }
          double in = e * (1 - rho);
          for (int a = 0; a < 3; a++)
            x[a] -= in * n[a];
          /* near an acute edge, inward along n may leave through another
          ** face: such a point is dropped */
          for (m = 0; m < c->nf; m++)
            if (dot3(c->f[m].pl, x) + c->f[m].pl[3] > eps) break;
          if (m < c->nf) continue;
          if ((rc = pts_add(P, x))) goto done;
        }
    }
  }
  rc = oc_bblock_hull(P->x, P->n, b, err);
  if (!rc)
    b->centroid = (oc_vec3){sites[3 * i], sites[3 * i + 1], sites[3 * i + 2]};
  goto out;
done:
  if (rc == OC_ENOMEM) oc_seterr(err, OC_ENOMEM, "out of memory for rocks");
out:
  free(pl);
  free(v);
  free(ct);
  return rc;
}

/* ---- the tile -------------------------------------------------------- */

void oc_rocks_defaults(oc_rocks_params *p) {
  memset(p, 0, sizeof *p);
  p->size = 8;
  p->radius = 1.5;
  p->erosion = 0.3;
  p->spread = 1;
  p->contacts = 1;
  p->rounding = 0.15;
  p->width = 0.75;
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int check(const oc_rocks_params *p, oc_error *err) {
  if (!(p->radius > 0) || !isfinite(p->radius))
    return oc_seterr(err, OC_EINVAL, "'radius' must be > 0 (got %g)",
                     p->radius);
  if (!(p->size >= 4 * p->radius) || !isfinite(p->size))
    return oc_seterr(err, OC_EINVAL,
                     "'size' must be at least 4 'radius' (got %g, radius %g)",
                     p->size, p->radius);
  double cube = p->size / p->radius;
  if (cube * cube * cube > 2.0 * ROCKS_MAX)
    return oc_seterr(err, OC_EINVAL,
                     "'size' / 'radius' too large: (%g)^3 > %d (at most %d "
                     "rocks)",
                     cube, 2 * ROCKS_MAX, ROCKS_MAX);
  if (!(p->erosion >= 0 && p->erosion <= 0.45))
    return oc_seterr(err, OC_EINVAL,
                     "'erosion' must be in [0, 0.45] (of the radius; got %g)",
                     p->erosion);
  if (!(p->spread > 0) || !isfinite(p->spread))
    return oc_seterr(err, OC_EINVAL, "'spread' must be > 0 (got %g)",
                     p->spread);
  if (p->contacts < 1 || p->contacts > 8)
    return oc_seterr(err, OC_EINVAL, "'contacts' must be in 1 .. 8 (got %d)",
                     p->contacts);
  if (!(p->rounding >= 0) || !isfinite(p->rounding))
    return oc_seterr(err, OC_EINVAL, "'rounding' must be >= 0 (got %g)",
                     p->rounding);
  if (!(p->width > 0) || !isfinite(p->width))
    return oc_seterr(err, OC_EINVAL, "'width' must be > 0 (got %g)", p->width);
  return OC_OK;
}

oc_btile *oc_rocks_tile(const oc_rocks_params *rp, oc_error *err) {
  if (!rp) {
    oc_seterr(err, OC_EINVAL, "layers.rocks needs params");
    return NULL;
  }
  if (check(rp, err)) return NULL;
  double t0 = now();
  oc_btile *t = calloc(1, sizeof *t);
  rcell *cells = NULL;
  pts P = {NULL, 0, 0};
  int rc = OC_ENOMEM;
  if (!t) goto fail;
  oc_btile_defaults(OC_BLOCKS_POLYHEDRAL, &t->pp);
  t->pp.size = rp->size;
  t->pp.radius = rp->radius;
  t->pp.rounding = rp->rounding * rp->radius;
  t->pp.width = rp->width;
  t->pp.seed = rp->seed;
  t->pp.fractures = 0;
  oc_poisson_params pp;
  memset(&pp, 0, sizeof pp);
  pp.box = (oc_aabb){{0, 0, 0}, {rp->size, rp->size, rp->size}};
  pp.radius = rp->radius;
  pp.seed = oc_hash2(rp->seed, KEY_SITES);
  pp.periodic = 1;
  oc_samples *sm = oc_poisson3d(&pp, err);
  if (!sm) {
    rc = OC_EINVAL;
    goto fail;
  }
  t->np = oc_samples_count(sm);
  t->pts = malloc((t->np ? t->np : 1) * 3 * sizeof *t->pts);
  if (t->pts) memcpy(t->pts, oc_samples_data(sm), t->np * 3 * sizeof *t->pts);
  oc_samples_free(sm);
  if (t->np > ROCKS_MAX) {
    rc = oc_seterr(err, OC_EINVAL, "%zu rocks: at most %d", t->np, ROCKS_MAX);
    goto fail;
  }
  cells = calloc(t->np ? t->np : 1, sizeof *cells);
  t->block = calloc(t->np ? t->np : 1, sizeof *t->block);
  if (!t->pts || !cells || !t->block) goto nomem;
  for (size_t i = 0; i < t->np; i++)
    if ((rc =
             cell_make(t->pts, t->np, i, rp->size, rp->radius, &cells[i], err)))
      goto fail;
  for (size_t i = 0; i < t->np; i++) {
    if ((rc = rock_make(cells, t->pts, i, rp, &P, &t->block[i], err)))
      goto fail;
    t->nb = t->ncl = i + 1;
  }
  for (size_t i = 0; i < t->np; i++)
    cell_free(&cells[i]);
  free(cells);
  free(P.x);
  t->seconds = now() - t0;
  return t;
nomem:
  rc = oc_seterr(err, OC_ENOMEM, "out of memory for rocks");
fail:
  (void)rc;
  if (cells)
    for (size_t i = 0; i < t->np; i++)
      cell_free(&cells[i]);
  free(cells);
  free(P.x);
  oc_btile_free(t);
  return NULL;
}

double oc_rocks_reach(const oc_btile *t) {
  double m = 0;
  for (size_t i = 0; i < t->nb; i++) {
    const oc_bblock *b = &t->block[i];
    for (size_t v = 0; v < b->nvert; v++) {
      const double *x = b->vert + 3 * v;
      double d[3] = {x[0] - b->centroid.x, x[1] - b->centroid.y,
                     x[2] - b->centroid.z};
      m = fmax(m, sqrt(dot3(d, d)));
    }
  }
  return m;
}

/* ---- placement ------------------------------------------------------- */

typedef struct presence {
  const oc_stacks *s;
  double depth, x0, y0, cell, base;
  int nx, ny;
  size_t cap; /* of the scratch layers below */
  uint8_t *mat;
  double *thick;
  int nomem;
} presence;

/* Stack (i, j)'s layers into q's scratch (grown as needed; the public
** reader, so the storage may change); the count, or 0 out of memory. */
static size_t layers_of(presence *q, int i, int j) {
  size_t n = oc_stacks_get(q->s, i, j, q->mat, q->thick, q->cap);
  if (n > q->cap) {
    uint8_t *m = realloc(q->mat, n);
    double *t = m ? realloc(q->thick, n * sizeof *t) : NULL;
    if (m) q->mat = m;
    if (!t) {
      q->nomem = 1;
      return 0;
    }
    q->thick = t;
    q->cap = n;
    oc_stacks_get(q->s, i, j, q->mat, q->thick, q->cap);
  }
  return n;
}

/* 1 when p lies in a rocks layer at most depth below the top of the
** solid above it (rocks, then any loose material or bedrock on it). */
static int present(void *ctx, oc_vec3 p) {
  presence *q = ctx;
  double fi = floor((p.x - q->x0) / q->cell + 0.5),
         fj = floor((p.y - q->y0) / q->cell + 0.5);
  if (!(fi >= 0 && fj >= 0 && fi < q->nx && fj < q->ny)) return 0;
  size_t n = layers_of(q, (int)fi, (int)fj), l = 0;
  double z = q->base;
  for (; l < n; l++) {
    double top = z + q->thick[l];
    if (p.z < top) break;
    z = top;
  }
  if (l == n || p.z < z || q->mat[l] != OC_MAT_ROCKS) return 0;
  double top = z;
  for (; l < n && q->mat[l] != OC_MAT_AIR && q->mat[l] != OC_MAT_WATER; l++)
    top += q->thick[l];
  return top - p.z <= q->depth;
}

oc_node *oc_stacks_rocks(const oc_stacks *s, const oc_btile *tile,
                         oc_node *ground, const oc_stacks_rocks_params *p,
                         oc_error *err) {
  if (!s || !tile || !p) {
    oc_seterr(err, OC_EINVAL, "layers:rocks needs stacks, a tile, params");
    return NULL;
  }
  presence q = {s,
                p->depth,
                0,
                0,
                oc_stacks_cell(s),
                oc_stacks_base(s),
                oc_stacks_nx(s),
                oc_stacks_ny(s),
                0,
                NULL,
                NULL,
                0};
  oc_stacks_origin(s, &q.x0, &q.y0);
  if (isnan(q.depth)) q.depth = 2 * oc_rocks_reach(tile);
  if (!(q.depth >= 0) || !isfinite(q.depth)) {
    oc_seterr(err, OC_EINVAL, "'depth' must be >= 0 (got %g)", q.depth);
    return NULL;
  }
  /* where rocks are: the grid's footprint, the rocks layers' heights */
  oc_aabb where = {
      {q.x0 - 0.5 * q.cell, q.y0 - 0.5 * q.cell, INFINITY},
      {q.x0 + (q.nx - 0.5) * q.cell, q.y0 + (q.ny - 0.5) * q.cell, -INFINITY}};
  for (int j = 0; j < q.ny; j++)
    for (int i = 0; i < q.nx; i++) {
      size_t n = layers_of(&q, i, j);
      double z = q.base;
      for (size_t l = 0; l < n; l++) {
        double top = z + q.thick[l];
        if (q.mat[l] == OC_MAT_ROCKS) {
          where.lo.z = fmin(where.lo.z, z);
          where.hi.z = fmax(where.hi.z, top);
        }
        z = top;
      }
    }
  if (where.lo.z > where.hi.z) /* no rocks: nothing placed */
    where.lo.z = q.base + 1, where.hi.z = q.base;
  oc_node *own = NULL, *out = NULL;
  if (!ground) {
    own =
        oc_stacks_field(s, 1u << OC_MAT_BEDROCK | 1u << OC_MAT_SAND, NAN, err);
    if (!own) goto done;
    ground = own;
  }
  oc_replicate_tile rt = {tile, -INFINITY, INFINITY};
  oc_replicate_params rp;
  oc_replicate_defaults(&rp);
  rp.tiles = &rt;
  rp.ntiles = 1;
  rp.anchors = 1; /* the site alone */
  rp.threshold = p->threshold;
  rp.present = present;
  rp.ctx = &q;
  rp.where = &where;
  out = oc_blocks_replicate(ground, &rp, err);
  if (out && q.nomem) {
    oc_node_release(out);
    out = NULL;
    oc_seterr(err, OC_ENOMEM, "out of memory for rocks");
  }
done:
  if (own) oc_node_release(own);
  free(q.mat);
  free(q.thick);
  return out;
}
