/*
** alloc.c — allocation-failure injection: runs small scenes of every area
** of the API, failing the Nth allocation for every N (or every Nth with a
** stride on the bigger scenes), once alone and once with every later
** allocation of the engine failing too, and checks that each run either
*succeeds (Lua's
** emergency collection retried the allocation) or stops with a clear
** out-of-memory error; ASan reports crashes and, at exit, leaks.
**
** The engine's allocations are counted and failed by linking this program
** with -Wl,--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=free: only
** calls from the statically linked objects (lib/, bindings/, runtime/)
** go through the wrappers, not those of libgomp, OpenImageIO or libc. The
** Lua state's allocator shares the counter (as Lua's ltests.c fails the
** Nth allocation). Run with OMP_NUM_THREADS=1 so the order of allocations,
** and so the meaning of N, is the same at every run.
**
**   alloc [-v] [-n N] [SCENE-NAME ...]   (default: every case of every
**   scene; -n N: only the cases failing allocation N)
*/
#include <ctype.h>
#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../fuzz/runner.h"

void *__real_malloc(size_t n);
void *__real_calloc(size_t n, size_t size);
void *__real_realloc(void *p, size_t n);
void __real_free(void *p);

static int armed;    /* counting only while a scene runs */
static long counter; /* allocations so far in this run */
static long fail_at; /* the allocation to fail, 0: none */
static long failed;  /* engine allocations failed in this run */
static int sticky;   /* fail every engine allocation from fail_at on */

/* Who asks for memory: the engine, Lua for data (strings, tables,
** userdata), or Lua for calling a function (a CallInfo, a larger stack). */
enum { ENGINE, LUA_DATA, LUA_CALL };

/* Counts one allocation; returns 1 when it must fail. With `sticky`, the
** engine's allocations fail from fail_at on, and a Lua data allocation
** failing at fail_at fails again when Lua retries it after its emergency
** collection, so that Lua raises its memory error. Lua's allocations
** never fail for good, and those for calls never: a finalizer that Lua
** cannot call (inside a collection step Lua does not retry) is skipped
** and its userdata freed without it, a leak of Lua's making that would
** hide the engine's. */
static int should_fail(int who) {
  if (!armed) return 0;
  long k = __atomic_add_fetch(&counter, 1, __ATOMIC_RELAXED);
  int fail = k == fail_at && who != LUA_CALL;
  if (sticky && fail_at && k > fail_at)
    fail = who == ENGINE || (who == LUA_DATA && k == fail_at + 1);
  if (fail && who == ENGINE) failed++;
  return fail;
}

void *__wrap_malloc(size_t n) {
  return should_fail(ENGINE) ? NULL : __real_malloc(n);
}

void *__wrap_calloc(size_t n, size_t size) {
  return should_fail(ENGINE) ? NULL : __real_calloc(n, size);
}

void *__wrap_realloc(void *p, size_t n) {
  /* shrinking never fails (trimming to size may ignore a failure) */
  if (n > 0 && (p == NULL || n > malloc_usable_size(p)) && should_fail(ENGINE))
    return NULL;
  return __real_realloc(p, n);
}

void __wrap_free(void *p) {
  __real_free(p);
}

/* The Lua allocator: growth counts (and may fail) like engine calls;
** shrinking never fails, as Lua's own test allocator. Calls need a new
** CallInfo or a larger stack: untyped blocks (osize 0 for a new block)
** of 16-byte slots (Lua 5.4 on x86-64: a CallInfo is 64 bytes; 5.4.4
** moves a growing stack to a new block, earlier versions reallocate it).
** A few data allocations (array parts, buffers) of such sizes are taken
** for them and never fail. */
static void *lua_alloc(void *ud, void *p, size_t osize, size_t nsize) {
  (void)ud;
  if (nsize == 0) {
    __real_free(p);
    return NULL;
  }
  if (nsize > osize) {
    int call = nsize % 16 == 0 && (p == NULL ? osize == 0 : osize % 16 == 0);
    if (should_fail(call ? LUA_CALL : LUA_DATA)) return NULL;
  }
  return __real_realloc(p, nsize);
}

static void arm(void *ud) {
  (void)ud;
  armed = 1;
}

/* Closing the state runs the finalizers, which need memory to be called
** at all: failing there would only leak what they free. */
static void disarm(void *ud) {
  (void)ud;
  armed = 0;
}

typedef struct scene {
  const char *name;
  int from_start; /* count the state's setup too */
  const char *code;
} scene;

#define SPHERE "outcrop.sphere{center = {0, 0, 0}, radius = 3}"
#define SMALL_HF                                                               \
  "local h = outcrop.heightfield.fbm{size = {24, 24}, cell = 2, "              \
  "wavelength = 20, amplitude = 12, seed = 3}\n"

static const scene scenes[] = {
    {"setup", 1, "return 1"},
    {"primitives", 0,
     "local a = outcrop.sphere{center = {0, 0, 0}, radius = 2}\n"
     "local b = outcrop.box{min = {-1, -1, -1}, max = {1, 1, 3}}\n"
     "local c = outcrop.point{center = {1, 0, 0}, radius = 1}\n"
     "local s = outcrop.segment{a = {0, 0, 0}, b = {1, 1, 1}, radius = 1}\n"
     "local k = outcrop.cone{base = {0, 0, 0}, apex = {0, 0, 2}, radius = 1}\n"
     "local q = outcrop.curve{points = {{0, 0, 0}, {1, 1, 0}, {2, 0, 0}, "
     "{3, 1, 1}}, radius = 1, bezier = true}\n"
     "local p = outcrop.plane{origin = {0, 0, 0}, normal = {0, 0, 1}}\n"
     "local t = outcrop.turbulence{wavelength = 4}\n"
     "local u = ((a + b) | c) & -s - k\n"
     "u = outcrop.blend{u, q, p} + outcrop.union{a, b, c}\n"
     "u = outcrop.smooth_union{u, outcrop.intersection{a, t}, radius = 0.5}\n"
     "u = outcrop.warp(u, {wavelength = 4, amplitude = 1})\n"
     "u = outcrop.transform(u, {translate = {1, 2, 3}, rotate = {10, 20, 30},"
     " scale = 2})\n"
     "u = outcrop.perturb(a, {wavelength = 3, amplitude = 0.5}) + u\n"
     "u:eval(0, 0, 0); u:gradient(0.5, 0.5, 0.5); u:bounds()\n"
     "u:lipschitz(); u:stats(); u:kind(); tostring(u)\n"},
    {"polygonize", 0,
     "local m = outcrop.polygonize(" SPHERE " - outcrop.point{center = "
     "{2, 0, 0}, radius = 2}, {cell = 1, colors = function(x, y, z) "
     "return 1, 0, 0 end})\n"
     "m:counts(); m:vertex(1); m:triangle(1); m:stats()\n"
     "assert(m:write('m.ply')); assert(m:write('m.obj'))\n"
     "assert(m:write('m.glb', {colors = {field = " SPHERE ", palette = "
     "{{0, {0, 0, 0}}, {1, {1, 1, 1}}}}}))\n"
     "outcrop.polygonize(outcrop.plane{origin = {0, 0, 0}, normal = "
     "{0, 0, 1}}, {box = {-2, -2, -2, 2, 2, 2}, resolution = {4, 4, 4}, "
     "open = true})\n"},
    {"render", 0,
     "local img = outcrop.render(" SPHERE ", {size = {8, 6}, aov = true,"
     " color = function(x, y, z) return 0.5, 0.5, 0.5 end})\n"
     "assert(img:write('i.png', {meta = {note = 'x'}}))\n"
     "assert(img:write('i.exr'))\n"
     "img:get(1, 1); img:size(); img:channels()\n"
     "local s = outcrop.slice(" SPHERE ", {size = {8, 8}})\n"
     "assert(s:write('s.tif'))\n"},
    {"heightfield", 0,
     SMALL_HF
     "h:slope(); h:filled(); h:drainage(); h:stream_power(); h:sinks()\n"
     "h:accessibility{rays = 4, distance = 10}\n"
     "h:distance_to_level(h:min() + 1); h:resample{cell = 4}\n"
     "h:crop{1, 1, 8, 8}; h:height(3, 3); h:gradient(3, 3)\n"
     "local t = outcrop.terrain(h, {mask = h}); t:eval(5, 5, 5)\n"
     "assert(h:save('h.png')); assert(h:save('h.exr'))\n"
     "outcrop.heightfield.load(OUT .. '/h.png')\n"
     "outcrop.heightfield.from(function(x, y) return x + y end, "
     "{size = {5, 5}})\n"
     "outcrop.heightfield.from(" SPHERE ", {size = {5, 5}, origin = "
     "{-3, -3}})\n"},
    {"geology", 0,
     "local G = outcrop.geology\n"
     "local g = G.strata{wavelength = 3} + G.layer{origin = {0, 0, 0}, "
     "normal = {0, 0, 1}, radius = 1, resistance = -0.5}\n"
     "g = g + G.sphere{center = {0, 0, 0}, radius = 2, resistance = 1}\n"
     "g = g + G.curve{points = {{0, 0, 0}, {2, 2, 2}}, radius = 1, "
     "resistance = 0.5}\n"
     "g = G.fold(g, {wavelength = 5, amplitude = 1})\n"
     "g = G.taper(g, {to = 4, factor = 2, height = 3})\n"
     "g = G.fault(g, {domain = {min = {0, 0, 0}, max = {1, 1, 1}}, "
     "offset = {0, 0, 1}})\n"
     "g = G.clamp(g); g:eval(0, 0, 0)\n"
     "local e = outcrop.erosion(" SPHERE ", g, {depth = 0.5})\n"
     "e:eval(0, 0, 1)\n"
     "assert(G.slice(g, {box = {-2, -2, 2, 2}, size = {6, 6}})"
     ":write('g.png'))\n"},
    {"sea", 0,
     SMALL_HF
     "local n = outcrop.generate.sea{heightfield = h, radius = 3, rays = 4,"
     " steps = 2, sea_level = 6}\n"
     "n:stats()\n"},
    {"river", 0,
     SMALL_HF
     "outcrop.generate.river{heightfield = h, radius = 3, steps = 1}\n"},
    {"karst", 0,
     SMALL_HF "outcrop.generate.karst{heightfield = h, radius = 3, "
              "max_primitives = 30}\n"},
    {"hoodoos", 0,
     SMALL_HF
     "outcrop.generate.hoodoos{heightfield = h, radius = 6, margin = 1, "
     "mask = function(x, y) return 1 end}\n"},
    {"terrain", 0,
     SMALL_HF
     "local t = outcrop.terrain(h, {falloff = 4}) - " SPHERE "\n"
     "local m = outcrop.polygonize(t, {cell = 3})\n"
     "assert(m:write('t.obj'))\n"
     "outcrop.polygonize(t, {cell = 4, full_grid = true, open = true})\n"
     "assert(outcrop.render(t, {size = {6, 4}, shadows = false})"
     ":write('t.jpg'))\n"
     "assert(h:save('h.tif', {bits = 16})); assert(h:save('p.png', "
     "{palette = true}))\n"
     "outcrop.heightfield.load(OUT .. '/h.tif')\n"},
    {"diffusion", 0,
     "local c = outcrop.feature_curve{points = {{2, 2}, {6, 10}, {12, 12}, "
     "{14, 4}}, bezier = true, constraints = {{u = 0, height = 5, radius = "
     "1, slope = {left = 20, right = 20, extent = {3, 3}}, noise = "
     "{amplitude = 1, roughness = 0.5}}, {u = 1, height = 8}}}\n"
     "local k = {u = 0, slope = {left = -30, right = -30, extent = {2, 2}}}\n"
     "local d = outcrop.feature_curve{points = {{0, 8}, {16, 8}}, "
     "constraints = {k, {u = 1, slope = k.slope}}}\n"
     "local h, m = outcrop.diffusion{size = {16, 12}, curves = {c, d}, "
     "seed = 1, converged = true, noise = {wavelength = 8}}\n"
     "h:height(3, 3); m.detail:height(2, 2)\n"
     "outcrop.feature_curve_load(c:save()):sample(0.5)\n"},
    {"poisson", 0,
     "local p = outcrop.poisson2d{box = {0, 0, 20, 20}, radius = 3, "
     "density = function(x, y) return 0.5 end}\n"
     "local q = outcrop.poisson3d{box = {0, 0, 0, 8, 8, 8}, radius = 3, "
     "flat = true}\n"
     "q:get(1); q:table(); assert(#q > 0)\n"},
};
#define NSCENES (sizeof scenes / sizeof scenes[0])

/* At most this many failure points per scene: a stride beyond. */
#define MAXCASES 700

static ocfz_dirs dirs;
static int verbose;
static long only; /* -n N: run case N alone */

static int is_memory_error(const char *msg) {
  char low[512];
  size_t i;
  for (i = 0; msg[i] && i < sizeof low - 1; i++)
    low[i] = (char)tolower((unsigned char)msg[i]);
  low[i] = '\0';
  return strstr(low, "memory") != NULL;
}

static int run(const scene *sc, long n, int stick, char *msg, size_t msgsize) {
  ocfz_limits lim = {0,     0, lua_alloc, NULL, sc->from_start ? NULL : arm,
                     disarm};
  int st;
  counter = 0;
  fail_at = n;
  sticky = stick;
  failed = 0;
  armed = sc->from_start;
  st = ocfz_run(sc->code, strlen(sc->code), dirs.out, &lim, msg, msgsize);
  armed = 0;
  if (!ocfz_dirs_check(&dirs, msg, msgsize)) {
    fprintf(stderr, "alloc: %s, allocation %ld%s failed: left '%s' behind\n",
            sc->name, n, stick ? " and on" : "", msg);
    exit(1);
  }
  return st;
}

/* One case: allocation n fails (and with `stick` every one after it). A
** success is right only when the failure was retried (Lua collects and
** tries again) and none stuck; otherwise the error must say memory. */
static int check(const scene *sc, long n, int stick) {
  char msg[512];
  int st = run(sc, n, stick, msg, sizeof msg);
  if (verbose)
    fprintf(stderr, "  %s #%ld%s: %d %s\n", sc->name, n, stick ? "+" : "", st,
            msg);
  if (st != 0 && !is_memory_error(msg)) {
    fprintf(stderr, "alloc: %s, allocation %ld%s failed: unclear error: %s\n",
            sc->name, n, stick ? " and on" : "", msg);
    return 0;
  }
  if (st == 0 && stick && failed > 1) {
    fprintf(stderr,
            "alloc: %s, allocations %ld and on failed (%ld of them) but "
            "the scene succeeded\n",
            sc->name, n, failed);
    return 0;
  }
  return 1;
}

/* Returns the number of cases run, or -1 after a failed check. */
static long one_scene(const scene *sc) {
  char msg[512];
  long total, n, stride, cases = 0;
  if (run(sc, 0, 0, msg, sizeof msg) != 0) {
    fprintf(stderr, "alloc: %s fails without injection: %s\n", sc->name, msg);
    return -1;
  }
  total = counter;
  stride = total / MAXCASES + 1;
  for (n = only ? only : 1; n <= (only ? only : total); n += stride) {
    if (!check(sc, n, 0) || !check(sc, n, 1)) return -1;
    cases += 2;
  }
  printf("alloc: %-12s %5ld allocations, %4ld cases (stride %ld)\n", sc->name,
         total, cases, stride);
  return cases;
}

int main(int argc, char **argv) {
  size_t i;
  long all = 0;
  int a, bad = 0;
  if (ocfz_dirs_open(&dirs, "ocalloc") != 0) {
    perror("alloc: output folder");
    return 2;
  }
  for (a = 1; a < argc && argv[a][0] == '-'; a++) {
    if (strcmp(argv[a], "-v") == 0)
      verbose = 1;
    else if (strcmp(argv[a], "-n") == 0 && a + 1 < argc)
      only = atol(argv[++a]);
  }
  for (i = 0; i < NSCENES; i++) {
    int want = a == argc, k;
    for (k = a; k < argc; k++)
      want |= strcmp(argv[k], scenes[i].name) == 0;
    if (!want) continue;
    long c = one_scene(&scenes[i]);
    if (c < 0)
      bad = 1;
    else
      all += c;
  }
  ocfz_dirs_close(&dirs);
  printf("alloc: %ld allocation-failure cases\n", all);
  return bad;
}
