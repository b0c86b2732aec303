/*
** bench_elev.c — rendering elevation surfaces z = f(x, y) (issue 14).
**
** First a 2 x 2 km fBm heightfield (1025 x 1025 samples, 8 octaves, 300 m
** of relief), then the six scenes of Table 1 of Génevaux et al. 2015
** rebuilt as elevation trees with the paper's areas and primitive and
** operator counts (figures 1, 3, 19, 20, 21 and 22), each rendered at
** 1920 x 1080 on 2 threads, shaded with shadows and AO, through the
** surface the Lua front end traces (holes where alpha < 1/2). Per scene:
** the seconds of the render of the primary rays and normals (the
** fastest of OUTCROP_BENCH_ROUNDS renders, 3 by default) and of the
** whole shaded render, the height calls per pixel of the primary rays
** (normals included, as the paper counts its calls) and the tree's
** memory. The ratio of plain sphere tracing's calls to the
** accelerated tracer's is measured on the heightfield and on figure 1
** (geometry pass only; figure 1's at a quarter of the size in each axis,
** since sphere tracing there takes minutes). Prints `name: value unit`
** lines; '#' lines are context.
**
** The scenes are plausible terrains, not copies of the paper's: a base
** disc covering the scene (alpha >= 1/2 everywhere), noisy hills, rocks
** added, rivers and roads replaced in; counts are checked against Table
** 1. Calls count height calls, as the paper counts calls of f: a step of
** the tracer is one query of the tree's first-order model (value,
** gradient and remainder in one traversal: a call, also printed as
** `elev.model_steps_per_pixel`), besides the hits' refinement and
** normals; a block's beam, on models, makes such calls too, shared by
** the block's pixels in the evals channel (render.c), so that the calls
** per pixel count every call; `elev.bounds_per_pixel` counts the box
** queries made besides (beams, and those inside the models' fallbacks:
** curves, lakes...).
*`bench_elev [-q | -qq] [hf] [fig1 ...]`: those scenes only, every
** image 4 or 8 times smaller in each axis with -q and -qq (for work on
** the code: the figures then are not the HD ones). `bench_elev --bytes
** [fig1 ...]`: the trees' memory alone (`elev.bytes.<scene>`, the nodes
** and the data of curves and images, each shared node or grid once;
** `elev.bytes_per_node.<scene>`, the nodes alone per node, and
** `elev.bytes_per_node_with_data.<scene>`), no rendering.
** `bench_elev --replay [-q | -qq] [fig1 ...]`: the cost of a call alone,
** without the march around it: the first-order model queries (taylor)
** and box queries (bound) of a one-thread geometry render recorded, then
** replayed on one thread, each hook's CPU time a call the best of 3
** passes (`elev.replay_taylor_us.<scene>`, `elev.replay_bound_us`), and
** hashes of the replayed outputs and of the geometry image (`#` lines:
** a change that keeps the same bits keeps them). Instructions a call:
**   valgrind --tool=callgrind --toggle-collect='replay_log*' \
**       build/release/bench/bench_elev --replay -qq fig22
** (callgrind runs the noise's scalar path, not its AVX-512 one).
*/
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "benchout.h"
#include "outcrop.h"

/* bench_elev -q: every size divided by 4 (while working on the code) */
static int shrink = 1;
/* bench_elev --bytes: the trees' memory, no rendering */
static int bytes_only = 0;
/* bench_elev --replay: the calls of a render replayed alone */
static int replay = 0;

static void die(const char *what, const oc_error *err) {
  fprintf(stderr, "bench_elev: %s: %s\n", what, err->msg);
  exit(1);
}

/* Height calls of the primary rays of a geometry image, and its hits. */
static double primary_calls(const oc_image *g, double *hits) {
  size_t n = (size_t)oc_image_width(g) * oc_image_height(g);
  const float *d = oc_image_cdata(g);
  double ev = 0;
  *hits = 0;
  for (size_t k = 0; k < n; k++) {
    ev += d[k * OC_RG_COUNT + OC_RG_EVALS];
    *hits += d[k * OC_RG_COUNT + OC_RG_HIT];
  }
  return ev;
}

static void heightfield_bench(void) {
  oc_error err;
  oc_heightfield_grid grid = {1025, 1025, 2, -1024, -1024};
  oc_noise nz = {600, 300, 0, 8, 14};
  oc_progress none = {0};
  oc_heightfield *hf = oc_heightfield_fbm(&grid, &nz, none, &err);
  if (!hf) die("fbm", &err);
  oc_elevation src;
  if (oc_heightfield_elevation(hf, &src, &err)) die("source", &err);
  oc_render_params rp;
  oc_render_defaults(&rp);
  rp.camera.eye = (oc_vec3){-1500, -1700, 900};
  rp.camera.target = (oc_vec3){0, 0, 50};
  rp.camera.fov = 40;
  rp.width = 1920;
  rp.height = 1080;
  oc_render_stats st;
  double t0 = omp_get_wtime();
  clock_t c0 = clock();
  oc_image *img = oc_render_elevation(&src, &rp, &st, &err);
  double secs = omp_get_wtime() - t0;
  double cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
  if (!img) die("render", &err);
  oc_image_free(img);
  double calls[2], hits[2], gsecs[2];
  for (int m = 0; m < 2; m++) {
    rp.tracer = m ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT;
    t0 = omp_get_wtime();
    oc_image *g = oc_render_elevation_geometry(&src, &rp, &err);
    gsecs[m] = omp_get_wtime() - t0;
    if (!g) die("geometry", &err);
    calls[m] = primary_calls(g, &hits[m]);
    oc_image_free(g);
  }
  double n = (double)rp.width * rp.height;
  printf("# fBm heightfield 1025 x 1025 (2 km, 8 octaves), 1920 x 1080, "
         "%.0f%% of pixels hit\n",
         100 * st.hits / n);
  /* on a shared machine the wall time is what the other processes left */
  printf("# the render took %.2f s of CPU over both threads\n", cpu);
  printf("# primary rays alone: accelerated %.2f s, sphere %.2f s; "
         "%.1f calls per pixel with shadows and AO\n",
         gsecs[0], gsecs[1], st.calls_total_per_pixel);
  printf("# sphere tracing: %.1f calls per pixel (hits %.0f / %.0f)\n",
         calls[1] / n, hits[0], hits[1]);
  printf("elev.render_hd_seconds_2t.hf: %.2f s\n", secs);
  printf("elev.calls_per_pixel.hf: %.1f calls\n", st.calls_per_pixel);
  printf("elev.accel_ratio.hf: %.2f x\n", calls[1] / calls[0]);
  src.release(src.ud);
  oc_heightfield_release(hf);
}

/* ---- building the Table 1 scenes ---------------------------------------- */

/* A scene under construction: every node made is kept here (released at
** the end), and the primitives and operators are counted. */
typedef struct scene {
  const char *name, *what;
  oc_enode *made[512];
  int nmade, prims, ops;
  uint64_t rng;
  oc_enode *root;
  double half;         /* the scene spans [-half, half]^2 */
  oc_vec3 eye, target; /* the view */
  double fov;
} scene;

static oc_enode *keep(scene *s, oc_enode *e, int prim, const oc_error *err) {
  if (!e) die(s->name, err);
  if (s->nmade == (int)(sizeof s->made / sizeof *s->made)) {
    fprintf(stderr, "bench_elev: %s: too many nodes\n", s->name);
    exit(1);
  }
  s->made[s->nmade++] = e;
  if (prim)
    s->prims++;
  else
    s->ops++;
  return e;
}

/* Uniform in [a, b), from a 64-bit LCG: the scenes are the same on every
** run. */
static double urand(scene *s, double a, double b) {
  s->rng = s->rng * 6364136223846793005ull + 1442695040888963407ull;
  return a + (b - a) * (double)(s->rng >> 11) / 9007199254740992.0;
}

static oc_enode *disc(scene *s, double cx, double cy, double r, double h,
                      oc_enoise_kind kind, double amp, double wl, int oct) {
  oc_error err;
  oc_enode_disc_params p = {cx, cy, r, h, {kind, amp, wl, oct, 0, 0, 0}};
  p.noise.seed = s->rng ^ (uint64_t)s->nmade * 0x9e3779b97f4a7c15ull;
  return keep(s, oc_enode_disc(&p, &err), 1, &err);
}

static oc_enode *blend(scene *s, oc_enode **k, size_t n) {
  oc_error err;
  return keep(s, oc_enode_blend(k, n, &err), 0, &err);
}

static oc_enode *replace(scene *s, oc_enode *a, oc_enode *b) {
  oc_error err;
  return keep(s, oc_enode_replace(a, b, 0, &err), 0, &err);
}

static oc_enode *add(scene *s, oc_enode *a, oc_enode *b, double below,
                     double fade) {
  oc_error err;
  oc_enode_add_params p = {.below = fade > 0, .below_z = below, .fade = fade};
  return keep(s, oc_enode_add(a, b, &p, &err), 0, &err);
}

static oc_enode *xform(scene *s, oc_enode *e, double tx, double ty,
                       double angle, double scale, double vscale) {
  oc_error err;
  oc_enode_xform x = {tx, ty, angle, scale, vscale, 0};
  return keep(s, oc_enode_transform(e, &x, &err), 0, &err);
}

/* A meandering polyline from a to b: n points, sideways swings of
** `swing` (a sine plus jitter), elevation from za to zb. */
static void path(scene *s, oc_vec3 *pts, int n, double ax, double ay, double bx,
                 double by, double za, double zb, double swing, double turns) {
  double dx = bx - ax, dy = by - ay, l = hypot(dx, dy);
  double nx = -dy / l, ny = dx / l;
  for (int i = 0; i < n; i++) {
    double t = (double)i / (n - 1);
    double w = swing * (sin(t * turns * 6.283185307179586) +
                        (i > 0 && i < n - 1 ? urand(s, -0.15, 0.15) : 0));
    pts[i] = (oc_vec3){ax + t * dx + w * nx, ay + t * dy + w * ny,
                       za + t * (zb - za)};
  }
}

static oc_enode *river(scene *s, const oc_vec3 *pts, size_t n,
                       oc_river_kind kind) {
  oc_error err;
  oc_enode_river_params p = {pts, n, OC_ECURVE_CATMULL, kind, 0, 0, 0};
  return keep(s, oc_enode_river(&p, &err), 1, &err);
}

static oc_enode *road(scene *s, const oc_vec3 *pts, size_t n) {
  oc_error err;
  oc_enode_road_params p = {pts, n, OC_ECURVE_CATMULL, 0, -1, 0};
  return keep(s, oc_enode_road(&p, &err), 1, &err);
}

/* The covering base: a disc wide enough that alpha >= 1/2 over the whole
** scene (a lone disc is terrain for d <= 0.4542 r). */
static oc_enode *base(scene *s, double h, oc_enoise_kind kind, double amp,
                      double wl, int oct) {
  return disc(s, 0, 0, 1.5 * s->half / 0.4542, h, kind, amp, wl, oct);
}

/* n noisy hills scattered over the scene, pushed into k. */
static int hills(scene *s, oc_enode **k, int n, double rlo, double rhi,
                 double hlo, double hhi, oc_enoise_kind kind, double wlr,
                 int oct) {
  for (int i = 0; i < n; i++) {
    double r = urand(s, rlo, rhi), h = urand(s, hlo, hhi);
    double x = urand(s, -s->half, s->half), y = urand(s, -s->half, s->half);
    k[i] = disc(s, x, y, r, h, kind, 0.3 * h + 1, wlr * r, oct);
  }
  return n;
}

/* The image primitive of figure 19: a 61 x 61 fBm grid mapped on a
** quadrangle about 2 half wide round (cx, cy), turned by 20 degrees, f =
** h + 1.2 h t (t the grid's fBm), fading over 8 km at its border. (A 257
** x 257 grid before, with its min/max pyramid 1.3 MB of the paper's 81
** kB: 61 x 61 cells of 1.4 km keep the fBm's largest wavelength, 15 km,
** and its finest, 1.4 cells, in 80 kB.) */
static oc_enode *image(scene *s, double cx, double cy, double half, double h) {
  oc_error err;
  oc_heightfield_grid grid = {61, 61, 1, 0, 0};
  oc_noise nz = {11.25, 1, 0, 4, 19};
  oc_progress none = {0};
  oc_heightfield *hf = oc_heightfield_fbm(&grid, &nz, none, &err);
  if (!hf) die(s->name, &err);
  oc_enode_image_params p = {0};
  p.heightfield = hf;
  p.height = 1.2 * h;
  p.offset = h;
  p.falloff = 8000;
  double c = cos(20 * 3.14159265358979323846 / 180);
  double sn = sin(20 * 3.14159265358979323846 / 180);
  double corner[4][2] = {{-1, -0.9}, {1.1, -1}, {1, 1}, {-1, 0.95}};
  for (int k = 0; k < 4; k++) {
    double x = corner[k][0] * half, y = corner[k][1] * half;
    p.quad[2 * k] = cx + c * x - sn * y;
    p.quad[2 * k + 1] = cy + sn * x + c * y;
  }
  oc_enode *e = oc_enode_image(&p, &err);
  oc_heightfield_release(hf); /* the node keeps it */
  return keep(s, e, 1, &err);
}

/* Figure 1: 2 x 2 km, 70 primitives, 9 operators. Hills over a base,
** small bumps added, two rivers and a road replaced in. */
static void fig1(scene *s) {
  oc_enode *k[80], *b[20];
  oc_vec3 p[3][12];
  s->half = 1000;
  int n = 0;
  k[n++] = base(s, 60, OC_ENOISE_PLAIN, 40, 700, 7);
  n += hills(s, k + n, 48, 150, 400, 40, 220, OC_ENOISE_PLAIN, 1.0, 5);
  oc_enode *t = blend(s, k, n);
  int m = hills(s, b, 12, 60, 150, 8, 25, OC_ENOISE_PLAIN, 1, 4);
  t = add(s, t, blend(s, b, m), 0, 0);
  m = hills(s, b, 5, 200, 350, 20, 60, OC_ENOISE_TURBULENCE, 0.7, 5);
  t = add(s, t, blend(s, b, m), 120, 30); /* crags only below 120 m */
  path(s, p[0], 12, -1000, -700, 1000, 500, 40, 25, 150, 1.5);
  path(s, p[1], 10, -800, 1000, 200, -100, 60, 30, 100, 1);
  t = replace(s, t, river(s, p[0], 12, OC_RIVER_RIVER));
  t = replace(s, t, river(s, p[1], 10, OC_RIVER_STREAM));
  path(s, p[2], 10, -1000, 300, 1000, -900, 70, 50, 120, 1);
  t = replace(s, t, road(s, p[2], 10));
  /* a levelled plateau */
  s->root = replace(s, t, disc(s, 300, 300, 120, 90, OC_ENOISE_NONE, 0, 1, 1));
  s->what = "hills, bumps, crags below 120 m, two rivers, a road, a plateau";
  s->eye = (oc_vec3){-1300, -1500, 650};
  s->target = (oc_vec3){100, 100, 60};
  s->fov = 45;
}

/* Figure 3: 1 x 1 km, 20 primitives, 3 operators: a river in hills. */
static void fig3(scene *s) {
  oc_enode *k[24];
  oc_vec3 p[12];
  s->half = 500;
  int n = 0;
  k[n++] = base(s, 40, OC_ENOISE_PLAIN, 25, 400, 7);
  n += hills(s, k + n, 16, 100, 260, 30, 140, OC_ENOISE_PLAIN, 1.0, 5);
  k[n++] = disc(s, -200, 250, 150, 12, OC_ENOISE_TURBULENCE, 8, 80, 5);
  oc_enode *t = blend(s, k, n);
  t = add(s, t, disc(s, 250, -200, 130, 10, OC_ENOISE_TURBULENCE, 7, 70, 5), 0,
          0);
  path(s, p, 12, -500, -350, 500, 350, 30, 20, 80, 1.5);
  s->root = replace(s, t, river(s, p, 12, OC_RIVER_RIVER));
  s->what = "a river in hills, turbulent rocks added";
  s->eye = (oc_vec3){-700, -750, 300};
  s->target = (oc_vec3){50, 50, 40};
  s->fov = 45;
}

/* Figure 19: 200 x 200 km, 15 primitives (one an image), 3 operators:
** a multi-scale scene, ranges over plains with a main-stem river. */
static void fig19(scene *s) {
  oc_enode *k[16];
  oc_vec3 p[16];
  s->half = 100000;
  int n = 0;
  k[n++] = base(s, 200, OC_ENOISE_PLAIN, 300, 60000, 9);
  k[n++] = image(s, 20000, 10000, 40000, 1800);
  n += hills(s, k + n, 11, 10000, 30000, 500, 2500, OC_ENOISE_RIDGED, 0.6, 8);
  oc_enode *h = blend(s, k, n);
  oc_enode *pl =
      disc(s, -50000, -40000, 30000, 150, OC_ENOISE_PLAIN, 20, 8000, 5);
  oc_enode *t = replace(s, h, pl); /* a plain */
  path(s, p, 16, -100000, -70000, 100000, 60000, 120, 60, 12000, 2);
  s->root = replace(s, t, river(s, p, 16, OC_RIVER_MAIN));
  s->what = "an image (an fBm grid on an 80 km quad), ranges, a plain and a "
            "main-stem river";
  s->eye = (oc_vec3){-130000, -150000, 40000};
  s->target = (oc_vec3){10000, 10000, 500};
  s->fov = 45;
}

/* Figure 20: 2 x 2 km, 78 primitives, 10 operators: a valley with
** terraces, streams and a road. */
static void fig20(scene *s) {
  oc_enode *k[80], *b[24];
  oc_vec3 p[4][12];
  s->half = 1000;
  int n = 0;
  k[n++] = base(s, 80, OC_ENOISE_PLAIN, 60, 900, 7);
  n += hills(s, k + n, 47, 120, 380, 60, 260, OC_ENOISE_PLAIN, 1.0, 5);
  oc_enode *t = blend(s, k, n);
  for (int j = 0; j < 2; j++) { /* rocks */
    int m = hills(s, b, 10, 50, 120, 5, 20, OC_ENOISE_TURBULENCE, 1, 4);
    t = add(s, t, blend(s, b, m), 0, 0);
  }
  for (int i = 0; i < 7; i++) /* terraces */
    b[i] = disc(s, urand(s, -800, 800), urand(s, -800, 800), urand(s, 60, 110),
                urand(s, 60, 160), OC_ENOISE_PLAIN, 1.5, 30, 3);
  t = replace(s, t, blend(s, b, 7));
  path(s, p[0], 12, -1000, -900, 900, 1000, 50, 30, 120, 2);
  path(s, p[1], 10, 1000, -600, -200, 200, 70, 40, 90, 1);
  path(s, p[2], 10, -1000, 500, 500, -1000, 90, 60, 100, 1.2);
  t = replace(s, t, river(s, p[0], 12, OC_RIVER_RIVER));
  t = replace(s, t, river(s, p[1], 10, OC_RIVER_STREAM));
  s->root = replace(s, t, road(s, p[2], 10));
  s->what = "hills, rocks, seven terraces, two streams, a road";
  s->eye = (oc_vec3){1400, -1500, 700};
  s->target = (oc_vec3){-50, 80, 80};
  s->fov = 45;
}

/* Figure 21: 100 x 100 km, 50 primitives, 25 operators: one mountain
** patch instanced twenty times (a DAG), dunes added below 400 m, a
** lake. */
static void fig21(scene *s) {
  oc_enode *k[48], *inst[24];
  s->half = 8000; /* the patch, near the origin */
  int n = hills(s, k, 45, 800, 3000, 300, 1600, OC_ENOISE_RIDGED, 0.7, 7);
  s->half = 50000;
  oc_enode *patch = blend(s, k, n);
  int m = 0;
  inst[m++] = base(s, 150, OC_ENOISE_PLAIN, 120, 30000, 8);
  for (int i = 0; i < 20; i++)
    inst[m++] =
        xform(s, patch, urand(s, -40000, 40000), urand(s, -40000, 40000),
              urand(s, 0, 360), urand(s, 0.15, 0.35), urand(s, 0.6, 1.2));
  oc_enode *t = blend(s, inst, m);
  oc_enode *d[4];
  for (int i = 0; i < 3; i++)
    d[i] = disc(s, urand(s, -30000, 30000), urand(s, -30000, 30000), 15000, 40,
                OC_ENOISE_TURBULENCE, 40, 900, 5);
  t = add(s, t, blend(s, d, 3), 400, 100); /* dunes below 400 m */
  oc_enode *lake = disc(s, 10000, -15000, 6000, 120, OC_ENOISE_NONE, 0, 1, 1);
  s->root = replace(s, t, lake);
  s->what = "20 instances of one 45-disc patch, dunes below 400 m, a lake";
  s->eye = (oc_vec3){-65000, -70000, 18000};
  s->target = (oc_vec3){5000, 5000, 400};
  s->fov = 45;
}

/* Figure 22: 0.6 x 0.6 km, 148 primitives, 9 operators: a winding road
** levelling a hillside strewn with rocks. */
static void fig22(scene *s) {
  oc_enode *k[40], *b[112];
  oc_vec3 p[2][16];
  s->half = 300;
  int n = 0;
  k[n++] = base(s, 60, OC_ENOISE_PLAIN, 15, 250, 7);
  /* the hillside: discs rising towards +y */
  for (int i = 0; i < 30; i++) {
    double y = urand(s, -300, 300);
    k[n++] =
        disc(s, urand(s, -300, 300), y, urand(s, 80, 160),
             90 + 0.25 * y + urand(s, -10, 10), OC_ENOISE_PLAIN, 12, 120, 5);
  }
  oc_enode *h = blend(s, k, n);
  int m = hills(s, b, 60, 6, 20, 1, 4, OC_ENOISE_PLAIN, 1, 3);
  oc_enode *t = add(s, h, blend(s, b, m), 0, 0);
  m = hills(s, b, 50, 3, 8, 0.5, 2, OC_ENOISE_TURBULENCE, 1, 3);
  t = add(s, t, blend(s, b, m), 0, 0);
  for (int i = 0; i < 5; i++)
    b[i] = disc(s, urand(s, -250, 250), urand(s, -250, 250), urand(s, 30, 60),
                urand(s, 3, 8), OC_ENOISE_TURBULENCE, 3, 20, 4);
  t = add(s, t, blend(s, b, 5), 0, 0);
  /* the road winds up the slope; a track runs along its foot */
  for (int i = 0; i < 16; i++) {
    double u = (double)i / 15;
    p[0][i] = (oc_vec3){150 * sin(7.85 * u), -260 + 520 * u, 30 + 140 * u};
  }
  t = replace(s, t, road(s, p[0], 16));
  path(s, p[1], 10, -300, -220, 300, -200, 8, 14, 20, 1);
  s->root = replace(s, t, road(s, p[1], 10));
  s->what = "a road winding up a rocky hillside, a track at its foot";
  s->eye = (oc_vec3){-420, -480, 260};
  s->target = (oc_vec3){0, 20, 90};
  s->fov = 45;
}

static double tree_weight(void *wud, double x, double y) {
  return oc_enode_weight(wud, x, y);
}

static void params(const scene *s, oc_render_params *rp, int w, int h) {
  oc_render_defaults(rp);
  rp->camera.eye = s->eye;
  rp->camera.target = s->target;
  rp->camera.fov = s->fov;
  rp->width = w;
  rp->height = h;
}

/* Builds, renders and reports one scene; with accel, the calls of sphere
** tracing over the accelerated tracer's too. */
/* The tree's source with its box queries counted (the tracer's other
** cost: "calls" count height evaluations, as Table 1 does). */
static const oc_elevation *counted_inner;
static long counted_bounds;

static void counted_bound(void *ud, double x0, double y0, double x1, double y1,
                          double *lo, double *hi, double *slope) {
#pragma omp atomic
  counted_bounds++;
  counted_inner->bound(ud, x0, y0, x1, y1, lo, hi, slope);
}

/* The first-order models' queries (the tracer's steps, each one height
** call) and the box queries they make inside (fallbacks: curves...). */
static long counted_models, counted_model_boxes;

/* The weight's box queries (rays in holes). */
static void counted_weight_bound(void *wud, double x0, double y0, double x1,
                                 double y1, double *lo, double *hi,
                                 double *lip) {
#pragma omp atomic
  counted_bounds++;
  counted_inner->weight_range(wud, x0, y0, x1, y1, lo, hi, lip);
}

static double counted_taylor(void *ud, double x, double y, double R,
                             double g[2], double e[3], int *boxes) {
  int nb = 0;
  double h = counted_inner->taylor(ud, x, y, R, g, e, &nb);
  if (boxes) *boxes += nb;
#pragma omp atomic
  counted_models++;
#pragma omp atomic
  counted_model_boxes += nb;
  return h;
}

/* The tree's memory: everything (elev.bytes, against the paper's kB), and
** per node the nodes alone (elev.bytes_per_node, against its 100 bytes a
** node: the unit of the tree; the data of curves and images grows with
** their points and cells, not with the nodes) and with that data. */
static void print_bytes(const char *name, const oc_enode_stats *st) {
  printf("elev.bytes.%s: %zu B\n", name, st->bytes);
  printf("elev.bytes_per_node.%s: %.1f B\n", name,
         (double)st->node_bytes / (double)st->nodes);
  printf("elev.bytes_per_node_with_data.%s: %.1f B\n", name,
         (double)st->bytes / (double)st->nodes);
}

static void run_scene(const char *name, void (*build)(scene *), int prims,
                      int ops, int accel) {
  scene s;
  memset(&s, 0, sizeof s);
  s.name = name;
  s.rng = 0x5eed0000u + (uint64_t)strlen(name) * 977;
  build(&s);
  if (s.prims != prims || s.ops != ops) {
    fprintf(stderr,
            "bench_elev: %s has %d primitives and %d operators, "
            "Table 1 %d and %d\n",
            name, s.prims, s.ops, prims, ops);
    exit(1);
  }
  oc_error err;
  oc_elevation src;
  if (oc_enode_elevation(s.root, NULL, &src, &err)) die(name, &err);
  oc_esurface es = {&src, tree_weight, s.root, OC_ENODE_T, src.weight_range};
  oc_enode_stats es_st;
  if (oc_enode_get_stats(s.root, &es_st, &err)) die(name, &err);
  if (bytes_only) {
    printf("# %s: %zu nodes\n", name, es_st.nodes);
    print_bytes(name, &es_st);
    src.release(src.ud);
    for (int i = 0; i < s.nmade; i++)
      oc_enode_release(s.made[i]);
    return;
  }
  oc_render_params rp;
  params(&s, &rp, 1920 / shrink, 1080 / shrink);
  /* Table 1 times primary rays with their normals: the geometry phase;
  ** then the shading (shadow rays, ambient occlusion) on its own */
  /* timed without the counting wrappers below: their shared atomic
  ** counters, bumped from both threads per call, cost more than some
  ** calls */
  /* the fastest of `rounds` renders (the same bits each time): a slow
  ** spell of a shared machine then rarely sets the figure */
  double secs = INFINITY, cpu = INFINITY;
  oc_image *geo = NULL;
  for (int r = 0, rounds = bench_rounds(); r < rounds; r++) {
    double t0 = omp_get_wtime();
    clock_t c0 = clock();
    oc_image *g = oc_render_surface_geometry(&es, &rp, &err);
    double w = omp_get_wtime() - t0;
    double c = (double)(clock() - c0) / CLOCKS_PER_SEC;
    if (!g) die(name, &err);
    secs = w < secs ? w : secs;
    cpu = c < cpu ? c : cpu;
    oc_image_free(geo);
    geo = g;
  }
  /* the same render again, untimed, counting box queries and steps */
  oc_elevation counted = src;
  counted_inner = &src;
  counted_bounds = counted_models = counted_model_boxes = 0;
  counted.bound = counted_bound;
  if (src.taylor) counted.taylor = counted_taylor;
  es.src = &counted;
  es.weight_bound = counted_weight_bound;
  oc_image *cgeo = oc_render_surface_geometry(&es, &rp, &err);
  if (!cgeo) die(name, &err);
  oc_image_free(cgeo);
  double bounds = (double)(counted_bounds + counted_model_boxes);
  double models = (double)counted_models;
  es.src = &src;
  es.weight_bound = src.weight_range;
  double t0 = omp_get_wtime();
  oc_image *img = oc_render_surface_shade(&es, &rp, geo, NULL, &err);
  double shade_secs = omp_get_wtime() - t0;
  if (!img) die(name, &err);
  oc_image_free(img);
  double n = (double)rp.width * rp.height, hits;
  double calls = primary_calls(geo, &hits);
  oc_image_free(geo);
  printf("# %s: %s; %d primitives, %d operators, %zu nodes; %.0f%% of "
         "pixels hit; primary rays and normals %.2f s of CPU\n",
         name, s.what[0] == '#' ? s.what + 2 : s.what, s.prims, s.ops,
         es_st.nodes, 100 * hits / n, cpu);
  double box[4], flo, fhi;
  oc_enode_get_bounds(s.root, box, &flo, &fhi);
  printf("# %s: f in [%.0f, %.0f] m, Lipschitz bound %.3g\n", name, flo, fhi,
         oc_enode_lipschitz(s.root));
  printf("elev.calls_per_pixel.%s: %.1f calls\n", name, calls / n);
  printf("elev.bounds_per_pixel.%s: %.1f queries\n", name, bounds / n);
  printf("elev.model_steps_per_pixel.%s: %.1f steps\n", name, models / n);
  printf("elev.render_hd_seconds_2t.%s: %.2f s\n", name, secs);
  printf("elev.render_hd_shaded_seconds_2t.%s: %.2f s\n", name,
         secs + shade_secs);
  print_bytes(name, &es_st);
  if (accel) {
    double calls[2], hits[2];
    params(&s, &rp, 480 / shrink, 270 / shrink);
    for (int m = 0; m < 2; m++) {
      rp.tracer = m ? OC_TRACE_SPHERE : OC_TRACE_SEGMENT;
      oc_image *g = oc_render_surface_geometry(&es, &rp, &err);
      if (!g) die(name, &err);
      calls[m] = primary_calls(g, &hits[m]);
      oc_image_free(g);
    }
    double np = (double)rp.width * rp.height;
    printf("# %s at %d x %d: sphere tracing %.1f calls per pixel, "
           "accelerated %.1f\n",
           name, rp.width, rp.height, calls[1] / np, calls[0] / np);
    printf("elev.accel_ratio: %.2f x\n", calls[1] / calls[0]);
  }
  src.release(src.ud);
  for (int i = 0; i < s.nmade; i++)
    oc_enode_release(s.made[i]);
}

/* ---- bench_elev --replay ---------------------------------------------- */

/* A recorded query: the taylor hook's (x, y, R) or bound's box. */
typedef struct rquery {
  double a[4];
} rquery;

typedef struct rlog {
  rquery *q;
  size_t n, cap;
} rlog;

static rlog rec_taylor, rec_bound;

static void rlog_add(rlog *l, double a, double b, double c, double d) {
  if (l->n == l->cap) {
    l->cap = l->cap ? 2 * l->cap : 4096;
    l->q = realloc(l->q, l->cap * sizeof *l->q);
    if (!l->q) {
      fprintf(stderr, "bench_elev: out of memory\n");
      exit(1);
    }
  }
  l->q[l->n++] = (rquery){{a, b, c, d}};
}

static double rec_taylor_fn(void *ud, double x, double y, double R, double g[2],
                            double e[3], int *boxes) {
  rlog_add(&rec_taylor, x, y, R, 0);
  return counted_inner->taylor(ud, x, y, R, g, e, boxes);
}

static void rec_bound_fn(void *ud, double x0, double y0, double x1, double y1,
                         double *lo, double *hi, double *slope) {
  rlog_add(&rec_bound, x0, y0, x1, y1);
  counted_inner->bound(ud, x0, y0, x1, y1, lo, hi, slope);
}

/* FNV-1a over n bytes, from h. */
static uint64_t fnv(uint64_t h, const void *p, size_t n) {
  const unsigned char *c = p;
  for (size_t i = 0; i < n; i++)
    h = (h ^ c[i]) * 0x100000001b3ull;
  return h;
}

static double thread_secs(void) {
  struct timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The queries of l through src's hook (taylor, else bound), 3 passes:
** the best pass's CPU seconds a call, the first pass's outputs hashed. */
static double replay_log(const oc_elevation *src, const rlog *l, int taylor,
                         uint64_t *hash) {
  double best = INFINITY;
  *hash = 0xcbf29ce484222325ull;
  for (int pass = 0; pass < 3; pass++) {
    double t0 = thread_secs(), sink = 0;
    for (size_t k = 0; k < l->n; k++) {
      const double *a = l->q[k].a;
      double o[7] = {0};
      if (taylor) {
        int boxes = 0;
        o[0] = src->taylor(src->ud, a[0], a[1], a[2], o + 1, o + 3, &boxes);
        o[6] = boxes;
      } else {
        src->bound(src->ud, a[0], a[1], a[2], a[3], o, o + 1, o + 2);
      }
      if (!pass) *hash = fnv(*hash, o, sizeof o);
      sink += o[0];
    }
    double t = thread_secs() - t0;
    if (sink != sink) t += 0; /* (the calls' results used) */
    if (t < best) best = t;
  }
  return l->n ? best / (double)l->n : 0;
}

static void replay_scene(const char *name, void (*build)(scene *)) {
  scene s;
  memset(&s, 0, sizeof s);
  s.name = name;
  s.rng = 0x5eed0000u + (uint64_t)strlen(name) * 977;
  build(&s);
  oc_error err;
  oc_elevation src;
  if (oc_enode_elevation(s.root, NULL, &src, &err)) die(name, &err);
  oc_render_params rp;
  params(&s, &rp, 1920 / shrink, 1080 / shrink);
  oc_elevation rec = src;
  counted_inner = &src;
  rec.bound = rec_bound_fn;
  if (src.taylor) rec.taylor = rec_taylor_fn;
  oc_esurface es = {&rec, tree_weight, s.root, OC_ENODE_T, src.weight_range};
  rec_taylor.n = rec_bound.n = 0;
  omp_set_num_threads(1); /* (the logs in the order of one thread) */
  oc_image *geo = oc_render_surface_geometry(&es, &rp, &err);
  omp_set_num_threads(2);
  if (!geo) die(name, &err);
  size_t nf = (size_t)oc_image_width(geo) * oc_image_height(geo) * OC_RG_COUNT;
  uint64_t hg =
      fnv(0xcbf29ce484222325ull, oc_image_cdata(geo), nf * sizeof(float));
  oc_image_free(geo);
  uint64_t ht = 0, hb;
  double ut = src.taylor ? replay_log(&src, &rec_taylor, 1, &ht) : 0;
  double ub = replay_log(&src, &rec_bound, 0, &hb);
  printf("# %s replay at %d x %d: %zu taylor and %zu bound calls of a "
         "one-thread geometry render\n",
         name, rp.width, rp.height, rec_taylor.n, rec_bound.n);
  printf("# %s replay hashes: taylor %016llx bound %016llx geometry %016llx\n",
         name, (unsigned long long)ht, (unsigned long long)hb,
         (unsigned long long)hg);
  printf("elev.replay_taylor_us.%s: %.3f us\n", name, 1e6 * ut);
  printf("elev.replay_bound_us.%s: %.3f us\n", name, 1e6 * ub);
  src.release(src.ud);
  for (int i = 0; i < s.nmade; i++)
    oc_enode_release(s.made[i]);
}

int main(int argc, char **argv) {
  omp_set_num_threads(2);
  static const struct {
    const char *name;
    void (*build)(scene *);
    int prims, ops; /* Table 1's */
  } scenes[] = {{"fig1", fig1, 70, 9},    {"fig3", fig3, 20, 3},
                {"fig19", fig19, 15, 3},  {"fig20", fig20, 78, 10},
                {"fig21", fig21, 50, 25}, {"fig22", fig22, 148, 9}};
  /* bench_elev [scene...]: only those (hf for the heightfield) */
  if (argc > 1 && !strcmp(argv[1], "--replay")) replay = 1, argc--, argv++;
  if (argc > 1 && !strcmp(argv[1], "-q")) shrink = 4, argc--, argv++;
  if (argc > 1 && !strcmp(argv[1], "-qq")) shrink = 8, argc--, argv++;
  if (argc > 1 && !strcmp(argv[1], "--bytes")) bytes_only = 1, argc--, argv++;
  int hf = argc < 2 && !bytes_only && !replay;
  for (int a = 1; a < argc; a++)
    hf |= !strcmp(argv[a], "hf");
  if (hf) heightfield_bench();
  for (size_t i = 0; i < sizeof scenes / sizeof *scenes; i++) {
    int pick = argc < 2;
    for (int a = 1; a < argc; a++)
      pick |= !strcmp(argv[a], scenes[i].name);
    if (pick && replay)
      replay_scene(scenes[i].name, scenes[i].build);
    else if (pick)
      run_scene(scenes[i].name, scenes[i].build, scenes[i].prims, scenes[i].ops,
                i == 0);
  }
  return 0;
}
