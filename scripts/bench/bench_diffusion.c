/*
** bench_diffusion.c — feature curves and multigrid diffusion (issue 15;
** Hnaidi et al. 2010, Tables 1 and 2). Six scenes with the curve counts of
** Table 1 (mountain 59, lake 45, canyon 74, hills 55, volcanic island 48,
** desert 26), generated from a fixed stream over a 2048 m square: ridges,
** riverbeds, cliffs, hills and cracks as cubic Bézier curves of one or
** two pieces with two or three constraint points, some with noise.
** Each is diffused at 512^2, 1024^2 and 2048^2 over the same square with
** the paper's schedule on 2 threads (the best of two runs):
**   diffusion.seconds_512/_1024/_2048  the worst scene (targets 0.08,
**                                      0.13, 0.35 s; the paper's 8800 GTS
**                                      0.17-0.22, 0.25-0.34, 0.61-0.81 s)
**   diffusion.converged_seconds_2048   the canyon to a 1e-4 tolerance (3 s)
**   diffusion.peak_mb_1024             peak resident memory of a child
**                                      process diffusing the canyon at
**                                      1024^2 (40 MB: the paper's 10 grids)
**   diffusion.curves_kb                the largest scene in the compact
**                                      encoding (oc_fcurve_encode; Table 1:
**                                      1.30-4.48 kB)
** Prints `name: value unit` lines; '#' lines are context. Parts
** (OUTCROP_BENCH_ONLY): peak, curves, schedule (or one size of it:
** schedule_512, schedule_1024, schedule_2048), converged.
*/
#define _GNU_SOURCE
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "benchout.h"
#include "outcrop.h"

#define SIDE 2048.0
#define MAXC 80

static const char *const names[6] = {"mountain", "lake",     "canyon",
                                     "hills",    "volcanic", "desert"};
static const int counts[6] = {59, 45, 74, 55, 48, 26};

static void die(const char *what, const oc_error *err) {
  fprintf(stderr, "bench_diffusion: %s: %s\n", what, err->msg);
  exit(1);
}

static double unif(uint64_t *s, double lo, double hi) {
  *s = *s * 6364136223846793005ull + 1442695040888963407ull;
  return lo + (hi - lo) * (double)(*s >> 11) / 9007199254740992.0;
}

/* One curve of kind k (0 ridge, 1 riverbed, 2 cliff, 3 hill, 4 crack). */
static oc_fcurve *make_curve(uint64_t *s, int k) {
  double xy[14];
  int pieces = unif(s, 0, 1) < 0.5 ? 1 : 2, np = 3 * pieces + 1;
  double x = unif(s, 200, SIDE - 200), y = unif(s, 200, SIDE - 200);
  double a = unif(s, 0, 6.283185307179586), len = unif(s, 300, 900) / pieces;
  for (int i = 0; i < np; i++) {
    xy[2 * i] = x, xy[2 * i + 1] = y;
    a += unif(s, -0.5, 0.5);
    x += len / 3 * cos(a), y += len / 3 * sin(a);
  }
  oc_fconstraint c[3];
  memset(c, 0, sizeof c);
  int nk = unif(s, 0, 1) < 0.5 ? 2 : 3;
  double base = unif(s, 100, 600);
  for (int i = 0; i < nk; i++) {
    oc_fconstraint *q = &c[i];
    q->u = (double)i / (nk - 1);
    q->has = OC_FC_RADIUS;
    q->radius = unif(s, 2, 12);
    double th = 0, ext = unif(s, 40, 160);
    switch (k) {
    case 0: /* ridge */
      q->has |= OC_FC_HEIGHT, q->height = base + unif(s, 100, 400);
      th = unif(s, 20, 40);
      break;
    case 1: /* riverbed */
      q->has |= OC_FC_HEIGHT, q->height = base * 0.3 - 20 * i;
      th = -unif(s, 5, 15), ext = unif(s, 10, 40);
      break;
    case 2: /* cliff */
      q->has |= OC_FC_HEIGHT, q->height = base;
      q->has |= OC_FC_SLOPE;
      q->left = 70, q->right = -10, q->extent_a = 30, q->extent_b = 60;
      break;
    case 3: /* hill */
      q->has |= OC_FC_HEIGHT, q->height = base * 0.8;
      th = 0;
      break;
    default: /* crack: no strict elevation */
      th = -unif(s, 30, 50), ext = unif(s, 10, 30);
    }
    if (k != 2) {
      q->has |= OC_FC_SLOPE;
      q->left = q->right = th, q->extent_a = q->extent_b = ext;
    }
    if (unif(s, 0, 1) < 0.4) {
      q->has |= OC_FC_NOISE;
      q->amplitude = unif(s, 2, 20), q->roughness = unif(s, 0, 1);
    }
  }
  oc_fcurve_params p = {xy, (size_t)np, 1, c, (size_t)nk};
  oc_error err;
  oc_fcurve *fc = oc_fcurve_new(&p, &err);
  if (!fc) die("curve", &err);
  return fc;
}

static size_t scene(int sc, oc_fcurve **c) {
  uint64_t s = 1000 + (uint64_t)sc;
  for (int i = 0; i < counts[sc]; i++)
    c[i] = make_curve(&s, i == 0 ? 0 : (int)unif(&s, 0, 5));
  return (size_t)counts[sc];
}

static double run(oc_fcurve **c, size_t n, int side, double tol, double *cpu,
                  int *cycles) {
  oc_diffusion_params p = {0};
  p.grid = (oc_heightfield_grid){side, side, SIDE / side, 0, 0};
  p.curves = c, p.ncurves = n, p.seed = 1, p.tolerance = tol;
  p.wavelength = 256;
  oc_diffusion_result r;
  oc_error err;
  double t0 = omp_get_wtime();
  clock_t c0 = clock();
  if (oc_diffusion(&p, &r, &err)) die("diffusion", &err);
  double t = omp_get_wtime() - t0;
  if (cpu) *cpu = (double)(clock() - c0) / CLOCKS_PER_SEC;
  if (cycles) *cycles = r.cycles;
  oc_diffusion_result_clear(&r);
  return t;
}

static void peak_child(void) {
  oc_fcurve *c[MAXC];
  size_t n = scene(2, c);
  run(c, n, 1024, 0, NULL, NULL);
}

static double child_peak_mb(void (*fn)(void)) {
  fflush(stdout);
  pid_t pid = fork();
  if (pid == 0) {
    fn();
    _exit(0);
  }
  int status;
  struct rusage ru;
  if (wait4(pid, &status, 0, &ru) < 0 || !WIFEXITED(status) ||
      WEXITSTATUS(status) != 0) {
    fprintf(stderr, "bench_diffusion: child failed\n");
    exit(1);
  }
  return ru.ru_maxrss / 1024.0;
}

int main(void) {
  omp_set_num_threads(2);
  static const int sides[3] = {512, 1024, 2048};
  /* first: a child forked after OpenMP started its threads would wait
  ** for them forever (libgomp's pool does not survive fork) */
  if (bench_wanted("peak"))
    printf("diffusion.peak_mb_1024: %.1f MB\n", child_peak_mb(peak_child));
  if (bench_wanted("curves")) {
    double worst = 0;
    for (int sc = 0; sc < 6; sc++) {
      oc_fcurve *c[MAXC];
      size_t n = scene(sc, c), bytes = 0;
      for (size_t i = 0; i < n; i++) {
        bytes += oc_fcurve_encode(c[i], NULL, 0);
        oc_fcurve_release(c[i]);
      }
      printf("# %s: %zu curves in %zu bytes\n", names[sc], n, bytes);
      if (bytes / 1024.0 > worst) worst = bytes / 1024.0;
    }
    printf("diffusion.curves_kb: %.2f kB\n", worst);
  }
  for (int z = 0; z < 3; z++) {
    char part[32];
    snprintf(part, sizeof part, "schedule_%d", sides[z]);
    if (bench_wanted("schedule") || bench_wanted(part)) {
      double worst = 0, wcpu = 0;
      for (int sc = 0; sc < 6; sc++) {
        oc_fcurve *c[MAXC];
        size_t n = scene(sc, c);
        double cpu, cpu2, t = run(c, n, sides[z], 0, &cpu, NULL);
        double t2 = run(c, n, sides[z], 0, &cpu2, NULL);
        if (t2 < t) t = t2, cpu = cpu2;
        printf("# %s (%zu curves) at %d^2: %.3f s, %.2f s of CPU\n", names[sc],
               n, sides[z], t, cpu);
        if (t > worst) worst = t, wcpu = cpu;
        for (size_t i = 0; i < n; i++)
          oc_fcurve_release(c[i]);
      }
      printf("diffusion.seconds_%d: %.3f s\n", sides[z], worst);
      printf("# (its CPU time %.2f s)\n", wcpu);
    }
  }
  if (bench_wanted("converged")) {
    oc_fcurve *c[MAXC];
    size_t n = scene(2, c);
    double cpu;
    int cycles;
    double t = run(c, n, 2048, 1e-4, &cpu, &cycles);
    printf("# canyon at 2048^2 to 1e-4: %d steps, %.2f s of CPU\n", cycles,
           cpu);
    printf("diffusion.converged_seconds_2048: %.3f s\n", t);
    for (size_t i = 0; i < n; i++)
      oc_fcurve_release(c[i]);
  }
  return 0;
}
