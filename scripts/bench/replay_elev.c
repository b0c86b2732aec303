/*
** replay_elev.c — the first-order model queries of a bench_elev scene,
** recorded once and replayed on one thread: deterministic work per call
** (for callgrind, or for timing without the tracer around it) and a hash
** of every output, to show a change keeps the same bits. Not part of
** `make bench` (not a bench_*.c): `make build/release/bench/replay_elev`.
**
**   replay_elev rec SCENE FILE [shrink]   render SCENE's geometry at
**       1920 x 1080 / shrink (4 unless given, bench_elev -q's size) on 2
**       threads, writing every (x, y, R) its taylor calls were given
**   replay_elev play SCENE FILE [reps [stride]]   replay every stride-th
**       query reps times (reps 0: load only); prints the queries, the
**       hash of the first pass's outputs (h, g, e: equal hashes, equal
**       bits; in the file's order, which the threads set when recording:
**       compare builds on one recorded file), the box queries per call
**       and ns per call
**
** Instructions per call, e.g. of fig22 on 1/16 of its queries:
**   valgrind --tool=callgrind --toggle-collect='replay_loop*' \
**       build/release/bench/replay_elev play fig22 /tmp/fig22.q 1 16
** (callgrind runs the noise's scalar path, not its AVX-512 one: count
** the noise's functions apart). Scenes are bench_elev's, included whole.
*/
#define main bench_main
#include "bench_elev.c"
#undef main
#include <stdint.h>

typedef struct {
  double x, y, R;
} q3;
static q3 *qs;
static size_t nq, capq;
static const oc_elevation *rec_inner;
static double rec_taylor(void *ud, double x, double y, double R, double g[2],
                         double e[3], int *boxes) {
#pragma omp critical
  {
    if (nq == capq) {
      capq = capq ? 2 * capq : 1 << 20;
      q3 *nqs = realloc(qs, capq * sizeof *qs);
      if (!nqs) {
        fprintf(stderr, "replay_elev: out of memory\n");
        exit(1);
      }
      qs = nqs;
    }
    qs[nq++] = (q3){x, y, R};
  }
  return rec_inner->taylor(ud, x, y, R, g, e, boxes);
}

static void build_scene(const char *name, scene *s) {
  static const struct {
    const char *name;
    void (*build)(scene *);
  } sc[] = {{"fig1", fig1},   {"fig3", fig3},   {"fig19", fig19},
            {"fig20", fig20}, {"fig21", fig21}, {"fig22", fig22}};
  memset(s, 0, sizeof *s);
  s->name = name;
  s->rng = 0x5eed0000u + (uint64_t)strlen(name) * 977;
  for (size_t i = 0; i < 6; i++)
    if (!strcmp(sc[i].name, name)) {
      sc[i].build(s);
      return;
    }
  fprintf(stderr, "no scene %s\n", name);
  exit(1);
}

static uint64_t mix(uint64_t h, double v) {
  uint64_t u;
  memcpy(&u, &v, 8);
  h ^= u;
  h *= 0x100000001b3ull;
  h ^= h >> 29;
  return h;
}

__attribute__((noinline)) static void replay_loop(const oc_elevation *sp,
                                                  int reps, size_t stride,
                                                  uint64_t *hp, long *bp) {
  oc_elevation src = *sp;
  uint64_t h = *hp;
  long boxes = 0;
  for (int r = 0; r < reps; r++)
    for (size_t i = 0; i < nq; i += stride) {
      double g[2], e[3];
      int b = 0;
      double v = src.taylor(src.ud, qs[i].x, qs[i].y, qs[i].R, g, e, &b);
      boxes += b;
      if (r == 0) {
        h = mix(h, v);
        h = mix(h, g[0]);
        h = mix(h, g[1]);
        h = mix(h, e[0]);
        h = mix(h, e[1]);
        h = mix(h, e[2]);
      }
    }
  *hp = h;
  *bp = boxes;
}

int main(int argc, char **argv) {
  if (argc < 4 || (strcmp(argv[1], "rec") && strcmp(argv[1], "play"))) {
    fprintf(stderr, "usage: replay_elev rec SCENE FILE [shrink] | play SCENE "
                    "FILE [reps [stride]]\n");
    return 2;
  }
  scene s;
  build_scene(argv[2], &s);
  oc_error err;
  oc_elevation src;
  if (oc_enode_elevation(s.root, NULL, &src, &err)) die("src", &err);
  if (!strcmp(argv[1], "rec")) {
    int sh = argc > 4 ? atoi(argv[4]) : 4;
    omp_set_num_threads(2);
    oc_elevation r = src;
    rec_inner = &src;
    r.taylor = rec_taylor;
    oc_esurface es = {&r, tree_weight, s.root, OC_ENODE_T, src.weight_range};
    oc_render_params rp;
    params(&s, &rp, 1920 / sh, 1080 / sh);
    oc_image *geo = oc_render_surface_geometry(&es, &rp, &err);
    if (!geo) die("render", &err);
    FILE *f = fopen(argv[3], "wb");
    if (!f || fwrite(qs, sizeof *qs, nq, f) != nq || fclose(f)) {
      fprintf(stderr, "replay_elev: cannot write %s\n", argv[3]);
      return 1;
    }
    printf("%zu queries\n", nq);
    return 0;
  }
  FILE *f = fopen(argv[3], "rb");
  long sz = -1;
  if (f && !fseek(f, 0, SEEK_END)) sz = ftell(f);
  if (f) rewind(f);
  qs = sz > 0 ? malloc((size_t)sz) : NULL;
  if (!qs || fread(qs, 1, (size_t)sz, f) != (size_t)sz) {
    fprintf(stderr, "replay_elev: cannot read %s\n", argv[3]);
    return 1;
  }
  fclose(f);
  nq = (size_t)sz / sizeof *qs;
  int reps = argc > 4 ? atoi(argv[4]) : 1;
  size_t stride = argc > 5 && atoi(argv[5]) > 0 ? (size_t)atoi(argv[5]) : 1;
  uint64_t h = 1469598103934665603ull;
  long boxes = 0;
  double t0 = omp_get_wtime();
  replay_loop(&src, reps, stride, &h, &boxes);
  double t = omp_get_wtime() - t0;
  nq /= stride;
  printf("%s: %zu queries, hash %016llx, boxes/query %.4f, %.1f ns/query\n",
         argv[2], nq, (unsigned long long)h, (double)boxes / (double)nq / reps,
         1e9 * t / (double)nq / reps);
  return 0;
}
