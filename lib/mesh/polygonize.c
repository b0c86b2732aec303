/*
** polygonize.c — oc_polygonize: checks the request, lays out the grid,
** meshes slabs of cube rows in parallel and merges them in order.
**
** The slab layout depends on the grid alone, each slab's output on its
** rows alone, and the merge runs in slab order, so the mesh is the same to
** the byte for any thread count. Slabs are appended to the mesh in order
** as soon as their predecessors are in, so only the slabs in flight are
** held twice. Vertices on the sample row two slabs share are computed by
** both (identically) and kept once, from the lower slab.
*/
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "mesh/mcgrid.h"
#include "mesh/mcwork.h"
#include "mesh/mesh.h"
#include "terrain/terrain.h"

#define MAX_AXIS (1 << 20)
#define MAX_CUBES ((double)(1ull << 40))
#define DEFAULT_STEPS 6
#define MAX_STEPS 64
#define SLAB_ROWS 16
/* Samples of one slab's band: 20 bytes each with their edge slots, so
** at most 640 MiB per thread. */
#define MAX_SLAB_SAMPLES ((size_t)1 << 25)

/* Refuses a mesh projected to exceed max_triangles, before any of it is
** made. */
static int check_output(const oc_mcgrid *g, const oc_polygonize_params *pp,
                        oc_error *err) {
  size_t most =
      pp->max_triangles ? pp->max_triangles : OC_POLYGONIZE_MAX_TRIANGLES;
  double t = oc_mc_project_triangles(g, (double)most);
  if (t <= (double)most) return 0;
  /* a triangle: 3 indices, and half a vertex of position and normal */
  double gib = t * (3 * 4 + 0.5 * 6 * 4) / (1 << 30);
  return oc_seterr(err, OC_ENOMEM,
                   "the mesh would have about %.3g triangles (%.3g GiB), more "
                   "than 'max_triangles' (%zu); use a larger 'cell' or a "
                   "smaller 'box', or raise 'max_triangles'",
                   t, gib, most);
}

static int setup(const oc_program *prog, const oc_polygonize_params *pp,
                 oc_mcgrid *g, oc_error *err) {
  if (!prog || !pp)
    return oc_seterr(err, OC_EINVAL, "polygonize needs a program and params");
  const double lo[3] = {pp->box.lo.x, pp->box.lo.y, pp->box.lo.z};
  const double hi[3] = {pp->box.hi.x, pp->box.hi.y, pp->box.hi.z};
  for (int a = 0; a < 3; a++)
    if (!isfinite(lo[a]) || !isfinite(hi[a]) || !(lo[a] < hi[a]) ||
        !isfinite(hi[a] - lo[a]))
      return oc_seterr(err, OC_EINVAL,
                       "'box' must be finite and non-empty (got %g %g %g "
                       "to %g %g %g)",
                       lo[0], lo[1], lo[2], hi[0], hi[1], hi[2]);
  memset(g, 0, sizeof *g);
  g->prog = prog;
  double cell = pp->cell;
  if (cell == 0 && pp->nx == 0 && pp->ny == 0 && pp->nz == 0)
    cell = oc_polygonize_default_cell(pp->box);
  if (cell != 0) {
    if (!(cell > 0) || !isfinite(cell))
      return oc_seterr(err, OC_EINVAL, "'cell' must be > 0 (got %g)", cell);
    for (int a = 0; a < 3; a++) {
      double n = (hi[a] - lo[a]) / cell;
      n = ceil(n * (1 - 1e-12)); /* 127.5 / 0.25 is 510 cells, not 511 */
      if (!(n <= MAX_AXIS))
        return oc_seterr(err, OC_EINVAL,
                         "'cell' %g gives %.0f cells along %c (at most %d)",
                         cell, n, "xyz"[a], MAX_AXIS);
      g->n[a] = n < 1 ? 1 : (int)n;
    }
  } else {
    int n[3] = {pp->nx, pp->ny, pp->nz};
    for (int a = 0; a < 3; a++) {
      if (n[a] < 1 || n[a] > MAX_AXIS)
        return oc_seterr(err, OC_EINVAL,
                         "'resolution' must be 1 .. %d cells per axis (got "
                         "%d x %d x %d)",
                         MAX_AXIS, n[0], n[1], n[2]);
      g->n[a] = n[a];
    }
  }
  double cubes = 1;
  for (int a = 0; a < 3; a++) {
    g->lo[a] = lo[a];
    g->hi[a] = hi[a];
    g->h[a] = (hi[a] - lo[a]) / g->n[a];
    cubes *= g->n[a] + 1.0;
  }
  if (cubes > MAX_CUBES)
    return oc_seterr(err, OC_ENOMEM,
                     "grid of %d x %d x %d cells is too large to mesh (at "
                     "most 2^40 cells)",
                     g->n[0], g->n[1], g->n[2]);
  for (int a = 0; a < 3; a++) {
    /* 4 float ulps of the largest coordinate, in edge lengths */
    double m = fmax(fabs(lo[a]), fabs(hi[a]));
    double ulps = ldexp(m, -20) / g->h[a];
    if (ulps > 0.25)
      return oc_seterr(err, OC_EINVAL,
                       "'cell' %g along %c is too small for single-precision "
                       "vertices at coordinates up to %g (move the box "
                       "nearer the origin)",
                       g->h[a], "xyz"[a], m);
    g->tmin[a] = fmax(1e-3, ulps);
  }
  g->T = pp->threshold != 0 ? pp->threshold : oc_program_threshold(prog);
  if (!isfinite(g->T))
    return oc_seterr(err, OC_EINVAL, "'threshold' must be finite (got %g)",
                     g->T);
  if (pp->steps < 0 || pp->steps > MAX_STEPS)
    return oc_seterr(err, OC_EINVAL, "'steps' must be 0 .. %d (got %d)",
                     MAX_STEPS, pp->steps);
  g->steps = pp->steps ? pp->steps : DEFAULT_STEPS;
  g->newton_tol = pow(10, -g->steps / 3.0);
  g->open = pp->open != 0;
  g->full = pp->full_grid != 0;
  g->max_samples = MAX_SLAB_SAMPLES;
  double col = (g->n[0] + 2.0) * (g->n[2] + 2.0);
  if (g->full && OC_MC_BLOCK * col > (double)g->max_samples)
    return oc_seterr(err, OC_ENOMEM,
                     "grid of %d x %d x %d cells is too large for "
                     "'full_grid' (a slab would hold %.3g samples)",
                     g->n[0], g->n[1], g->n[2], OC_MC_BLOCK * col);
  return check_output(g, pp, err);
}

/* Cube rows per slab: a multiple of the culling block, small enough that
** a slab of whole columns fits the sample budget and that there are a few
** slabs to share out. Depends on the grid only. */
static int slab_rows(const oc_mcgrid *g) {
  int rows = SLAB_ROWS;
  double col = (g->n[0] + 2.0) * (g->n[2] + 2.0);
  while (rows > OC_MC_BLOCK &&
         (g->n[1] + 1 < 8 * rows || rows * col > (double)g->max_samples))
    rows -= OC_MC_BLOCK;
  return rows;
}

/* Pairs the first-row vertices of slab b with the last-row ones of slab
** a (both sorted by edge key): remap_b[x] = remap_a[y] for each pair.
** Returns the number of pairs. */
static size_t join(const oc_mcout *a, const oc_mcout *b, uint32_t *remap_b,
                   const uint32_t *remap_a) {
  size_t i = a->nb, j = 0, n = 0;
  while (i < a->nk && j < b->nb) {
    if (a->key[i] < b->key[j])
      i++;
    else if (a->key[i] > b->key[j])
      j++;
    else {
      remap_b[b->kidx[j]] = remap_a[a->kidx[i]];
      i++, j++, n++;
    }
  }
  return n;
}

/* The mesh being assembled, slab after slab in order, while later slabs
** are still being meshed; a slab's output is freed once its successor is
** in (it holds the shared row the successor looks up). */
typedef struct merger {
  oc_mcout *outs; /* per slab */
  char *ready;
  int next; /* first slab not merged */
  float *pos, *nrm;
  size_t nv, capv, capn;
  uint32_t *tri;
  size_t nt, capt;
  uint32_t *prev, *cur; /* local -> global of slabs next - 1 and next */
  size_t capprev, capcur;
  size_t calls, cells;
  int nslab;
  /* outputs of merged slabs, emptied, for slabs still to mesh: their
  ** memory is warm, where fresh memory would fault at every page */
  oc_mcout *pool;
  int npool;
} merger;

/* Grows a merged array to hold `need` items after slab s of nslab: to
** what the slabs so far project for the whole mesh, a quarter more, so
** that realloc copies it once or twice rather than at every doubling
** (untouched capacity costs no memory). */
static int reserve(void *pp, size_t *cap, size_t need, int s, int nslab,
                   size_t elem) {
  if (need <= *cap) return 0;
  double want = (double)need * nslab / (s + 1) * 1.25;
  double most = (double)SIZE_MAX / 2 / elem;
  size_t c = want < most ? (size_t)want : need;
  if (c < need) c = need;
  void *p = realloc(*(void **)pp, c * elem);
  if (!p && c > need) /* the projection overshot what the system gives */
    p = realloc(*(void **)pp, (c = need) * elem);
  if (!p) return -1;
  *(void **)pp = p;
  *cap = c;
  return 0;
}

static int merge_one(merger *M, int s, oc_error *err) {
  oc_mcout *o = &M->outs[s];
  if (oc_mc_grow(&M->cur, &M->capcur, o->nv, sizeof *M->cur)) goto nomem;
  if (o->nv) memset(M->cur, 0xff, o->nv * sizeof *M->cur);
  size_t shared = s ? join(&M->outs[s - 1], o, M->cur, M->prev) : 0;
  size_t nv = M->nv + (o->nv - shared);
  /* 32-bit indices, and UINT32_MAX is glTF's primitive restart */
  if (nv > (size_t)UINT32_MAX - 1)
    return oc_seterr(err, OC_ENOMEM,
                     "mesh too large: more than %lu vertices (indices are "
                     "32-bit); use a larger 'cell' or a smaller 'box'",
                     (unsigned long)UINT32_MAX - 1);
  size_t nt = M->nt + o->nt;
  if (reserve(&M->pos, &M->capv, nv, s, M->nslab, 3 * sizeof(float)) ||
      reserve(&M->nrm, &M->capn, nv, s, M->nslab, 3 * sizeof(float)) ||
      reserve(&M->tri, &M->capt, nt, s, M->nslab, 3 * sizeof(uint32_t)))
    goto nomem;
  for (size_t v = 0; v < o->nv; v++) {
    if (M->cur[v] != OC_MC_NONE) continue;
    memcpy(M->pos + 3 * M->nv, o->pos + 3 * v, 3 * sizeof(float));
    memcpy(M->nrm + 3 * M->nv, o->nrm + 3 * v, 3 * sizeof(float));
    M->cur[v] = (uint32_t)M->nv++;
  }
  /* indexed: with no triangle yet M->tri may be NULL (NULL + 0 is
  ** undefined) */
  for (size_t k = 0; k < 3 * o->nt; k++)
    M->tri[3 * M->nt + k] = M->cur[o->tri[k]];
  M->nt += o->nt;
  M->calls += o->calls;
  M->cells += o->cells;
  uint32_t *x = M->prev;
  size_t c = M->capprev;
  M->prev = M->cur, M->capprev = M->capcur;
  M->cur = x, M->capcur = c;
  if (s) {
    oc_mcout_reset(&M->outs[s - 1]);
    M->pool[M->npool++] = M->outs[s - 1];
    memset(&M->outs[s - 1], 0, sizeof M->outs[s - 1]);
  }
  return 0;
nomem:
  return oc_seterr(err, OC_ENOMEM, "out of memory while assembling the mesh");
}

static void merger_free(merger *M, int nslab) {
  for (int s = 0; s < nslab; s++)
    oc_mcout_clear(&M->outs[s]);
  for (int k = 0; k < M->npool; k++)
    oc_mcout_clear(&M->pool[k]);
  free(M->pool);
  free(M->outs);
  free(M->ready);
  free(M->pos);
  free(M->nrm);
  free(M->tri);
  free(M->prev);
  free(M->cur);
}

/* Hands the assembled arrays to a new mesh (trimmed to size). */
static oc_mesh *finish(merger *M, oc_error *err) {
  oc_mesh *m = oc_mesh_alloc(0, 0, err);
  if (!m) return NULL;
  if (M->nv) {
    float *p = realloc(M->pos, M->nv * 3 * sizeof(float));
    float *n = realloc(M->nrm, M->nv * 3 * sizeof(float));
    M->pos = p ? p : M->pos;
    M->nrm = n ? n : M->nrm;
  }
  if (M->nt) {
    uint32_t *t = realloc(M->tri, M->nt * 3 * sizeof(uint32_t));
    M->tri = t ? t : M->tri;
  }
  m->pos = M->pos;
  m->nrm = M->nrm;
  m->tri = M->tri;
  M->pos = M->nrm = NULL;
  M->tri = NULL;
  m->nv = M->nv;
  m->nt = M->nt;
  m->stats.vertices = M->nv;
  m->stats.triangles = M->nt;
  m->stats.field_calls = M->calls;
  m->stats.cells_visited = M->cells;
  return m;
}

oc_mesh *oc_polygonize(const oc_program *prog, const oc_polygonize_params *pp,
                       oc_error *err) {
  double t0 = omp_get_wtime();
  oc_mcgrid g;
  if (setup(prog, pp, &g, err)) return NULL;
  if (oc_mc_surfaces(&g, !pp->no_direct)) {
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  int rows = slab_rows(&g);
  int nslab = (g.n[1] + 1 + rows - 1) / rows;
  merger M;
  memset(&M, 0, sizeof M);
  M.nslab = nslab;
  M.outs = calloc((size_t)nslab, sizeof *M.outs);
  M.pool = calloc((size_t)nslab, sizeof *M.pool);
  M.ready = calloc((size_t)nslab, 1);
  if (!M.outs || !M.pool || !M.ready) {
    merger_free(&M, 0);
    oc_mc_surfaces_free(&g);
    oc_seterr(err, OC_ENOMEM, "out of memory");
    return NULL;
  }
  int stop = 0, cancelled = 0, failed_at = nslab, done = 0;
  oc_error ferr = {OC_OK, ""};
  const oc_progress cb = pp->progress;
#pragma omp parallel
  {
    oc_mcwork *w = oc_mcwork_new();
#pragma omp for schedule(dynamic, 1)
    for (int s = 0; s < nslab; s++) {
      int halt;
#pragma omp atomic read
      halt = stop;
      if (halt) continue;
      int ja = -1 + s * rows, jb = ja + rows < g.n[1] ? ja + rows : g.n[1];
      oc_error e = {OC_OK, ""};
#pragma omp critical(oc_polygonize_merge)
      if (M.npool) M.outs[s] = M.pool[--M.npool];
      int rc = w ? oc_mc_slab(&g, ja, jb, w, &M.outs[s], &e)
                 : oc_seterr(&e, OC_ENOMEM, "out of memory while meshing");
      if (!rc) {
#pragma omp critical(oc_polygonize_merge)
        {
          M.ready[s] = 1;
          while (!rc && M.next < nslab && M.ready[M.next])
            rc = merge_one(&M, M.next++, &e);
        }
      }
      if (rc) {
#pragma omp critical(oc_polygonize_err)
        if (s < failed_at) {
          failed_at = s;
          ferr = e;
        }
#pragma omp atomic write
        stop = 1;
      }
      int d;
#pragma omp atomic capture
      d = ++done;
      /* only the calling thread talks to the caller */
      if (cb.fn && omp_get_thread_num() == 0 && !rc &&
          cb.fn(cb.ud, 0.99 * d / nslab)) {
#pragma omp atomic write
        stop = 1;
#pragma omp atomic write
        cancelled = 1;
      }
    }
    oc_mcwork_free(w);
  }
  oc_mesh *m = NULL;
  if (failed_at < nslab)
    oc_seterr(err, ferr.code, "%s", ferr.msg);
  else if (cancelled || (cb.fn && cb.fn(cb.ud, 1.0)))
    oc_seterr(err, OC_ECANCEL, "polygonization cancelled");
  else
    m = finish(&M, err);
  merger_free(&M, nslab);
  /* After the ordered merge, on the whole mesh: serial, so the result is
  ** the same for any thread count. */
  if (m && oc_mesh_drop_components(m, pp->min_component, err) != OC_OK) {
    oc_mesh_free(m);
    m = NULL;
  }
  oc_mc_surfaces_free(&g);
  if (m) m->stats.seconds = omp_get_wtime() - t0;
  if (pp->warning && pp->warning_size) {
    pp->warning[0] = '\0';
    if (m && oc_mesh_triangle_count(m) == 0)
      oc_terrain_thin_reason(prog, g.h[2], "the cell", pp->warning,
                             pp->warning_size);
  }
  return m;
}

int oc_polygonize_default_box(const oc_program *prog, oc_aabb *box,
                              oc_error *err) {
  if (!prog || !box)
    return oc_seterr(err, OC_EINVAL, "polygonize needs a program and a box");
  oc_aabb b = oc_program_bounds(prog);
  const double lo[3] = {b.lo.x, b.lo.y, b.lo.z};
  const double hi[3] = {b.hi.x, b.hi.y, b.hi.z};
  for (int k = 0; k < 3; k++)
    if (lo[k] > hi[k])
      return oc_seterr(err, OC_EINVAL,
                       "the node's bounds are empty (its field is 0 "
                       "everywhere): give 'box' = {x0, y0, z0, x1, y1, z1}");
  for (int k = 0; k < 3; k++)
    if (!isfinite(lo[k]) || !isfinite(hi[k]))
      return oc_seterr(err, OC_EINVAL,
                       "the node's bounds are infinite: give 'box' = "
                       "{x0, y0, z0, x1, y1, z1}");
  *box = b;
  return OC_OK;
}

double oc_polygonize_default_cell(oc_aabb box) {
  double longest =
      fmax(fmax(box.hi.x - box.lo.x, box.hi.y - box.lo.y), box.hi.z - box.lo.z);
  return fmax(longest, 0) / OC_POLYGONIZE_DEFAULT_RESOLUTION;
}
