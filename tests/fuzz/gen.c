/*
** gen.c — bytes to a Lua scene calling the whole outcrop API.
**
** The bytes are read as a sequence of choices: each statement takes one
** byte for its kind and more for its arguments; when the bytes run out
** every further choice is 0, so every input gives a finished, valid
** scene. Values are mostly ordinary (so calls get past their checks and
** reach the engine) and sometimes odd: NaN, infinities, -0, 1e308, the
** smallest subnormal, the integer extremes, wrong types. Every statement
** runs under pcall, so one failed call does not end the scene; objects
** live in the tables N (nodes), H (heightfields), I (images), M (meshes),
** P (point sets), so later statements can use, close or drop them.
** Sizes are kept small so that one scene runs in milliseconds.
**
** Statements are written as templates for emit(), whose directives draw
** from the bytes:
**   %n a number          %v a vector           %w a size in [lo, hi]
**   %N a node (or not)   %T a slot of table T  %H a heightfield slot
**   %o an options table  %b a boolean          %m mischief (see below)
**   %f a colour function %p a palette          %x a list of points
**   %s, %d as printf     %[ ... %] an optional part (half the time)
** (%w takes two int arguments, %T a table name, %o a template of fields.)
**
** Two versions of the grammar. Version 1 is every input that does not
** start with the two bytes of V2_MARK: it decodes exactly as it did before
** version 2 existed, so the stored corpus keeps its meaning (check with
** scripts/fuzz-show before and after a change). Version 2 (inputs that
** start with V2_MARK) adds statements for the later families: elevation
** trees (table E), feature curves (C) and diffusion, block tiles (B) and
** the relief warp, material layers (S) and their tools and rocks; in
** its templates also:
**   %E, %C, %B, %S a slot of that table (now and then a wrong type)
**   %y a point {x, y}   %Y a list of them   %k knots {{d, v}, ...}
**   %q a coordinate (odd now and then only)
**   %c constraints of a feature curve       %z a short binary string
**   %t the stabilisation of a layers tool
**   %W as %w, never nil (for fields whose default is a lot of work)
** Changing version 1 changes what every stored file means: never do it.
** Add to version 2 at the end of a switch where possible (a stored
** version-2 file then keeps its meaning up to the new case), or start a
** version 3 behind a mark of its own.
*/
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"

#define NSLOT 6    /* slots per object table */
#define MAXSTMT 40 /* statements per scene */
#define MAXDEPTH 2 /* callbacks and option tables nested in a statement */

/* The first bytes of a version-2 input (see above). */
static const uint8_t V2_MARK[2] = {0xfe, 0x02};

typedef struct gen {
  const uint8_t *p;
  size_t n, i;
  int flags;
  int v2; /* the input starts with V2_MARK */
  int depth;
  char *s; /* output, NULL after a failed allocation */
  size_t len, cap;
} gen;

static unsigned byte(gen *g) {
  return g->i < g->n ? g->p[g->i++] : 0;
}

static unsigned pick(gen *g, unsigned n) {
  return byte(g) % n;
}

static void put(gen *g, const char *s, size_t k) {
  if (g->s == NULL) return;
  if (k >= g->cap - g->len) {
    size_t cap = 2 * g->cap + k;
    char *t = realloc(g->s, cap);
    if (t == NULL) {
      free(g->s);
      g->s = NULL;
      return;
    }
    g->s = t;
    g->cap = cap;
  }
  memcpy(g->s + g->len, s, k);
  g->len += k;
  g->s[g->len] = '\0';
}

static void puts_(gen *g, const char *s) {
  put(g, s, strlen(s));
}

static void emit(gen *g, const char *fmt, ...);
static void vemit(gen *g, const char *fmt, va_list *ap, int skip);

/* ---- values ---------------------------------------------------------- */

static const char *const odd[] = {"0/0",
                                  "1/0",
                                  "-1/0",
                                  "-0.0",
                                  "1e308",
                                  "-1e308",
                                  "5e-324",
                                  "-5e-324",
                                  "math.maxinteger",
                                  "math.mininteger",
                                  "2^53",
                                  "2^63",
                                  "-2^31",
                                  "1e-300",
                                  "1e30",
                                  "-1e9",
                                  "'7'",
                                  "'x'",
                                  "{}",
                                  "nil",
                                  "true",
                                  "print",
                                  "N[1]",
                                  "H[1]"};
#define NODD (sizeof odd / sizeof odd[0])

static const char *const plain[] = {"0",   "1",  "2",  "3",   "4",  "5",
                                    "0.5", "8",  "10", "-1",  "-2", "0.25",
                                    "16",  "20", "-5", "1.5", "6",  "0.1"};
#define NPLAIN (sizeof plain / sizeof plain[0])

/* Wrong but harmless values for fields that size the work. */
static const char *const bad_size[] = {"0",   "-1",  "0/0", "0.5",
                                       "'a'", "nil", "1/0", "{}"};

static void num(gen *g) {
  unsigned b = byte(g);
  puts_(g, b < 210 ? plain[b % NPLAIN] : odd[b % NODD]);
}

/* A number for a field that sizes the work (counts, cells, radii):
** ordinary values are small; odd ones only without OCFZ_NO_HUGE. */
static void sized(gen *g, int lo, int hi, const char *const *huge,
                  unsigned nhuge, const char *const *bad, unsigned nbad) {
  unsigned b = byte(g);
  char buf[16];
  if (b >= 236 && !(g->flags & OCFZ_NO_HUGE)) {
    puts_(g, huge[b % nhuge]);
  } else if (b >= 228) {
    puts_(g, bad[b % nbad]);
  } else {
    snprintf(buf, sizeof buf, "%d", lo + (int)(b % (unsigned)(hi - lo + 1)));
    puts_(g, buf);
  }
}

static void work(gen *g, int lo, int hi) {
  sized(g, lo, hi, odd, NODD, bad_size, 8);
}

static void vec(gen *g) {
  switch (pick(g, 16)) {
  case 0:
    emit(g, "{x = %n, y = %n, z = %n}");
    break;
  case 1:
    emit(g, "{%n, %n}");
    break;
  case 2:
    num(g);
    break;
  default:
    emit(g, "{%n, %n, %n}");
  }
}

static void slot(gen *g, const char *table) {
  char buf[16];
  snprintf(buf, sizeof buf, "%s[%u]", table, 1 + pick(g, NSLOT));
  puts_(g, buf);
}

/* Lua code run from inside a call: a callback's body, a finalizer, an
** option table's __index. Without OCFZ_NO_CLOSE it closes or collects
** objects that may be in use. */
static void mischief(gen *g) {
  static const char *const t[] = {"H", "M", "I", "P"};
  unsigned k = pick(g, g->v2 ? 14 : 10);
  if (g->flags & OCFZ_NO_CLOSE) k = 6 + k % 4;
  if (k >= 10) { /* version 2 only */
    static const char *const v2[] = {"close(%T)", "close(%T)", "gc(%T)"};
    static const char *const t2[] = {"B", "S", "E"};
    if (k == 13)
      puts_(g, "E, C, B, S = {}, {}, {}, {} collectgarbage()");
    else
      emit(g, v2[k - 10], t2[k - 10]);
    return;
  }
  switch (k) {
  case 0:
  case 1:
  case 2:
  case 3:
    emit(g, "close(%T)", t[k]);
    break;
  case 4:
    emit(g, "gc(%T)", "N");
    break;
  case 5:
    puts_(g, "N, H, I, M = {}, {}, {}, {} collectgarbage()");
    break;
  case 6:
    puts_(g, "collectgarbage()");
    break;
  case 7:
    puts_(g, "error('boom')");
    break;
  case 8:
    puts_(g, "local _ = {}");
    break;
  default:
    emit(g, "outcrop.threshold = %n");
  }
}

/* An options table from the template `fields`, whose arguments follow in
** `ap`: plain, or read through an __index that runs mischief first, or a
** wrong type. Anything but a table constructor is parenthesized, so `f`
** followed by it is still a call. */
static void opts(gen *g, const char *fields, va_list *ap) {
  unsigned k = pick(g, 8);
  if (k == 0 && g->depth < MAXDEPTH) {
    g->depth++;
    puts_(g, "(hostile({");
    vemit(g, fields, ap, 0);
    emit(g, "}, function() %m end))");
    g->depth--;
  } else if (k == 1) {
    emit(g, "(%n)");
    vemit(g, fields, ap, 1);
  } else {
    puts_(g, "{");
    vemit(g, fields, ap, 0);
    puts_(g, "}");
  }
}

/* A colour callback (x, y, z, nx, ny, nz) -> r, g, b. */
static void colorfn(gen *g) {
  if (g->depth >= MAXDEPTH) {
    puts_(g, "nil");
    return;
  }
  g->depth++;
  emit(g, "function(x, y, z) %[%m%] return %n, 0.5, z end");
  g->depth--;
}

/* A table constructor of n items, each written from the template `item`. */
static void list(gen *g, unsigned n, const char *item) {
  puts_(g, "{");
  while (n--)
    emit(g, item);
  puts_(g, "}");
}

static void palette(gen *g) {
  list(g, 1 + pick(g, 3), "{%n, {0.2, %n, 0.7}}, ");
}

static void points(gen *g) {
  list(g, pick(g, 8), "%v, ");
}

/* ---- values of version 2 --------------------------------------------- */

/* A slot of table `t`, now and then a number or a slot of `other` (an
** object of another kind). */
static void slot_or(gen *g, const char *t, const char *other) {
  unsigned k = pick(g, 24);
  if (k == 0)
    emit(g, "(%n)");
  else if (k == 1)
    slot(g, other);
  else
    slot(g, t);
}

/* A coordinate: odd far less often than %n (a list of points is refused
** when one is odd, which would leave curves and contours unmade). */
static void coord(gen *g) {
  unsigned b = byte(g);
  puts_(g, b < 248 ? plain[b % NPLAIN] : odd[b % NODD]);
}

/* A number for a field that sizes the work and whose default is large
** (a tile's size, a render's or a grid's size, a mesh cell, a count of
** passes): like %w, but never nil, so the work stays bounded. */
static void extent(gen *g, int lo, int hi) {
  static const char *const odd_extent[] = {
      "0",   "-1", "0/0",  "1/0",    "-1/0",   "1e308", "2^53",
      "'a'", "{}", "-1e9", "5e-324", "1e-300", "true",  "math.maxinteger"};
  /* (the first four: wrong but harmless) */
  sized(g, lo, hi, odd_extent, 14, odd_extent, 4);
}

static void xy(gen *g) {
  switch (pick(g, 32)) {
  case 0:
    num(g);
    break;
  case 1:
    emit(g, "{%n, %n, %n}");
    break;
  default:
    emit(g, "{%q, %q}");
  }
}

/* A count of 2 to `hi` items, now and then 0 or 1 (refused by most). */
static unsigned count2(gen *g, unsigned hi) {
  unsigned b = byte(g);
  return b < 232 ? 2 + b % (hi - 1) : b % 2;
}

static void xys(gen *g) {
  list(g, count2(g, 9), "%y, ");
}

static void knots(gen *g) {
  list(g, pick(g, 6), "{%n, %n}, ");
}

/* The constraint points of a feature curve: evenly spaced in u, now and
** then a u of its own. */
static void constraints(gen *g) {
  unsigned i, n = count2(g, 4);
  puts_(g, "{");
  for (i = 0; i < n; i++) {
    char u[32];
    snprintf(u, sizeof u, "%g", n > 1 ? (double)i / (n - 1) : 0.0);
    if (pick(g, 8) == 0)
      emit(g, "{u = %n");
    else
      emit(g, "{u = %s", u);
    emit(
        g,
        "%[, height = %n%]%[, radius = %n%]%[, slope = %o%]%[, noise = %o%]}, ",
        "left = %n, right = %n, extent = {%n, %n}",
        "amplitude = %n%[, roughness = %n%]");
  }
  puts_(g, "}");
}

/* A short binary string as a Lua literal (for decoders). */
static void binary(gen *g) {
  unsigned i, n = pick(g, 24);
  puts_(g, "'");
  for (i = 0; i < n; i++) {
    char buf[8];
    snprintf(buf, sizeof buf, "\\%u", byte(g));
    puts_(g, buf);
  }
  puts_(g, "'");
}

/* The `stabilize` field of a layers tool, its work bounded. */
static void stabilize(gen *g) {
  switch (pick(g, 4)) {
  case 0:
    puts_(g, "stabilize = false");
    break;
  case 1:
    puts_(g, "stabilize = true");
    break;
  default:
    emit(g,
         "stabilize = {iterations = %W%[, tolerance = %n%]%[, rate = %n%]"
         "%[, angle = {sand = %n, rocks = %n}%]}",
         1, 200);
  }
}

/* Writes `fmt` with its directives (see the top of the file). Inside a
** skipped %[ ... %] (and everywhere when `skip` is set) directives
** consume their arguments but no bytes and write nothing. */
static void vemit(gen *g, const char *fmt, va_list *ap, int skip) {
  const int base = skip; /* skip counts the skipped parts we are in */
  const char *q;
  while (*fmt) {
    char buf[24];
    for (q = fmt; *q && *q != '%'; q++)
      ;
    if (!skip) put(g, fmt, (size_t)(q - fmt));
    if (*q == '\0') break;
    fmt = q + 2;
    switch (q[1]) {
    case '[':
      if (skip || pick(g, 2) == 0) skip++;
      continue;
    case ']':
      if (skip > base) skip--;
      continue;
    case 'w': {
      int lo = va_arg(*ap, int), hi = va_arg(*ap, int);
      if (!skip) work(g, lo, hi);
      continue;
    }
    case 'W': {
      int lo = va_arg(*ap, int), hi = va_arg(*ap, int);
      if (!skip) extent(g, lo, hi);
      continue;
    }
    case 'T': {
      const char *t = va_arg(*ap, const char *);
      if (!skip) slot(g, t);
      continue;
    }
    case 'o': {
      const char *f = va_arg(*ap, const char *);
      if (skip)
        vemit(g, f, ap, 1);
      else
        opts(g, f, ap);
      continue;
    }
    case 's': {
      const char *s = va_arg(*ap, const char *);
      if (!skip) puts_(g, s);
      continue;
    }
    case 'd': {
      int d = va_arg(*ap, int);
      snprintf(buf, sizeof buf, "%d", d);
      if (!skip) puts_(g, buf);
      continue;
    }
    default:
      break;
    }
    if (skip) continue;
    switch (q[1]) {
    case 'n':
      num(g);
      break;
    case 'v':
      vec(g);
      break;
    case 'N':
      if (g->v2)
        slot_or(g, "N", "E"); /* an elevation node is a terrain source */
      else if (pick(g, 24) == 0)
        emit(g, "(%n)"); /* a wrong type now and then */
      else
        slot(g, "N");
      break;
    case 'E':
      slot_or(g, "E", "N");
      break;
    case 'C':
      slot_or(g, "C", "E");
      break;
    case 'B':
      slot_or(g, "B", "N");
      break;
    case 'S':
      slot_or(g, "S", "H");
      break;
    case 'y':
      xy(g);
      break;
    case 'q':
      coord(g);
      break;
    case 'Y':
      xys(g);
      break;
    case 'k':
      knots(g);
      break;
    case 'c':
      constraints(g);
      break;
    case 'z':
      binary(g);
      break;
    case 't':
      stabilize(g);
      break;
    case 'H':
      slot(g, "H");
      break;
    case 'b':
      puts_(g, pick(g, 2) ? "true" : "false");
      break;
    case 'm':
      mischief(g);
      break;
    case 'f':
      colorfn(g);
      break;
    case 'p':
      palette(g);
      break;
    case 'x':
      points(g);
      break;
    default:
      put(g, q + 1, 1); /* %% and unknown: the character */
    }
  }
}

static void emit(gen *g, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vemit(g, fmt, &ap, 0);
  va_end(ap);
}

/* ---- statements ------------------------------------------------------ */

#define F_SPHERE "center = %v, radius = %w%[, energy = %n%]%[, falloff = %n%]"
#define F_NOISE                                                                \
  "wavelength = %w, amplitude = %n, octaves = %w%[, seed = %n%]", 2, 20, 1, 5
#define F_GRID "size = {%w, %w}, cell = %w%[, origin = {%n, %n}%]"
#define GRID_ARGS 2, 24, 2, 24, 1, 4

static void primitive(gen *g) {
  switch (pick(g, 8)) {
  case 0:
    emit(g, "%T = outcrop.point%o", "N", F_SPHERE, 1, 12);
    break;
  case 1:
    emit(g, "%T = outcrop.sphere%o", "N", F_SPHERE, 1, 12);
    break;
  case 2:
    emit(g, "%T = outcrop.box%o", "N",
         "min = %v, max = {%w, %w, %w}%[, falloff = %n%]", 1, 12, 1, 12, 1, 12);
    break;
  case 3:
    emit(g, "%T = outcrop.segment{a = %v, b = %v, radius = %w}", "N", 1, 8);
    break;
  case 4:
    emit(g, "%T = outcrop.curve{points = %x, radius = %w, bezier = %b}", "N", 1,
         8);
    break;
  case 5:
    emit(g, "%T = outcrop.cone{base = %v, apex = %v, radius = %w}", "N", 1, 8);
    break;
  case 6:
    emit(g, "%T = outcrop.plane{origin = %v, normal = %v, falloff = %n}", "N");
    break;
  default:
    emit(g,
         "%T = outcrop.turbulence{wavelength = %n, amplitude = %n, "
         "octaves = %w, seed = %n}",
         "N", 1, 6);
  }
}

static void operator(gen *g) {
  static const char *const bin[] = {"+", "-", "|", "&"};
  static const char *const nary[] = {"blend", "union", "intersection"};
  switch (pick(g, 10)) {
  case 0:
  case 1:
    emit(g, "%T = %N %s %N", "N", bin[pick(g, 4)]);
    break;
  case 2:
    emit(g, "%T = -%N", "N");
    break;
  case 3:
    emit(g, "%T = outcrop.%s{%N, %N%[, %N%]}", "N", nary[pick(g, 3)]);
    break;
  case 4:
    emit(g, "%T = outcrop.difference(%N, %N)", "N");
    break;
  case 5:
    emit(g, "%T = outcrop.%s{%N, %N, radius = %n}", "N",
         pick(g, 2) ? "smooth_union" : "smooth_intersection");
    break;
  case 6:
    emit(g, "%T = outcrop.warp(%N, %o)", "N", F_NOISE);
    break;
  case 7:
    emit(g, "%T = outcrop.perturb(%N, %o)", "N", F_NOISE);
    break;
  default:
    emit(g, "%T = outcrop.transform(%N, %o)", "N",
         pick(g, 2) ? "translate = %v, rotate = {axis = %v, angle = %n}, "
                      "scale = %n"
                    : "translate = %v%[, rotate = %v%], scale = %n");
  }
}

static void query(gen *g) {
  static const char *const q[] = {"bounds", "lipschitz", "stats", "kind"};
  switch (pick(g, 3)) {
  case 0:
    emit(g, "use(%N:eval(%n, %n, %n))");
    break;
  case 1:
    emit(g, "use(%N:gradient(%n, %n, %n))");
    break;
  default:
    emit(g, "use(%N:%s())", q[pick(g, 4)]);
  }
}

static void heightfield(gen *g) {
  static const char *const files[] = {"h.png", "h.exr", "h.tif",
                                      "i.png", "m.ply", "nothing.png"};
  switch (pick(g, 5)) {
  case 0:
  case 1:
    emit(g, "%H = outcrop.heightfield.fbm%o",
         F_GRID ", wavelength = %w, amplitude = %n, octaves = %w"
                "%[, seed = %n%]",
         GRID_ARGS, 4, 40, 1, 6);
    break;
  case 2:
  from_function:
    emit(g,
         "%H = outcrop.heightfield.from(function(x, y) %[%m%] "
         "return x * %n + y end, %o)",
         F_GRID, GRID_ARGS);
    break;
  case 3:
    /* its work grows with the node's Lipschitz bound, up to a column
    ** budget (lib/terrain/hf_make.c) */
    if (g->flags & OCFZ_NO_HUGE) goto from_function;
    emit(g, "%H = outcrop.heightfield.from(%N, %o)",
         F_GRID "%[, zrange = {%n, %n}%]", GRID_ARGS);
    break;
  default:
    emit(g,
         "%H = outcrop.heightfield.load(OUT .. '/%s'"
         "%[, {cell = %n, scale = %n}%])",
         files[pick(g, 6)]);
  }
}

static void analysis(gen *g) {
  static const char *const make[] = {":slope()",
                                     ":filled()",
                                     ":drainage{exponent = %n}",
                                     ":stream_power()",
                                     ":accessibility{rays = %w, distance = %n}",
                                     ":distance_to_level(%n)",
                                     ":resample{cell = %w}",
                                     ":crop{%n, %n, %n, %n}"};
  static const char *const look[] = {":sinks()",          ":height(%n, %n)",
                                     ":gradient(%n, %n)", ":get(%n, %n)",
                                     ":bounds()",         ":sum()"};
  unsigned k = pick(g, 14);
  if (k < 8) {
    emit(g, "%H = %H");
    emit(g, make[k], 1, k == 6 ? 4 : 16);
  } else {
    emit(g, "use(%H");
    emit(g, look[k - 8]);
    puts_(g, ")");
  }
}

static void terrain(gen *g) {
  emit(g, "%T = outcrop.terrain(%H%[, %o%])", "N",
       "falloff = %n%[, transition = %n%]%[, thickness = %n%]"
       "%[, invert = true%]%[, mask = %H%]");
}

static void geology(gen *g) {
  switch (pick(g, 9)) {
  case 0:
    emit(g, "%T = outcrop.geology.strata%o", "N", F_NOISE);
    break;
  case 1:
    emit(g,
         "%T = outcrop.geology.layer{origin = %v, normal = %v, radius = %n, "
         "resistance = %n}",
         "N");
    break;
  case 2:
    emit(g,
         "%T = outcrop.geology.sphere{center = %v, radius = %n, "
         "resistance = %n}",
         "N");
    break;
  case 3:
    emit(g,
         "%T = outcrop.geology.curve{points = %x, radius = %n, "
         "resistance = %n}",
         "N");
    break;
  case 4:
    emit(g, "%T = outcrop.geology.fold(%N, %o)", "N", F_NOISE);
    break;
  case 5:
    emit(g,
         "%T = outcrop.geology.taper(%N, {to = %n, factor = %n, "
         "height = %n})",
         "N");
    break;
  case 6:
    emit(g, "%T = outcrop.geology.fault(%N, {domain = %s, offset = %v})", "N",
         pick(g, 2) ? "{min = {0, 0, 0}, max = {2, 2, 2}}" : "N[2]");
    break;
  case 7:
    emit(g, "%T = outcrop.geology.clamp(%N)", "N");
    break;
  default:
    emit(g, "%T = outcrop.erosion(%N, %N, {depth = %n%[, control = %N%]})",
         "N");
  }
}

#define F_GEN                                                                  \
  "heightfield = %H%[, geology = %N%]%[, terrain = false%], radius = %w, "     \
  "seed = %n"

static void generator(gen *g) {
  switch (pick(g, 4)) {
  case 0:
    emit(g,
         "%T = outcrop.generate.sea{" F_GEN ", range = %n, rays = %w, "
         "steps = %w}",
         "N", 2, 6, 0, 8, 1, 3);
    break;
  case 1:
    emit(g,
         "%T = outcrop.generate.river{" F_GEN ", banks = %w, depth = %w, "
         "steps = %w}",
         "N", 2, 6, 0, 4, 1, 8, 1, 2);
    break;
  case 2:
    emit(g,
         "%T = outcrop.generate.karst{" F_GEN ", rho0 = %n, branches = %w, "
         "max_primitives = %w}",
         "N", 2, 6, 1, 6, 1, 300);
    break;
  default:
    emit(g,
         "%T = outcrop.generate.hoodoos{" F_GEN ", height = {%n, %n}, "
         "max_depth = %w%[, mask = function(x, y) %[%m%] return %n end%]}",
         "N", 2, 6, 2, 8);
  }
}

static void poisson(gen *g) {
  static const char *const density[] = {
      "", ", density = %H", ", density = function(x, y) %[%m%] return %n end"};
  if (pick(g, 2)) {
    emit(g, "%T = outcrop.poisson2d{box = {0, 0, %w, %w}, radius = %w", "P", 1,
         40, 1, 40, 1, 8);
    emit(g, density[pick(g, 3)]);
  } else {
    emit(g, "%T = outcrop.poisson3d{box = {0, 0, 0, %w, %w, %w}, radius = %w",
         "P", 1, 12, 1, 12, 1, 12, 1, 6);
  }
  emit(g, ", seed = %n, flat = %b}");
}

#define F_SLICE                                                                \
  "plane = '%s', at = %n, box = {-4, -4, 4, 4}, size = {%w, %w}"               \
  "%[, palette = %p%]"

static void output(gen *g) {
  static const char *const planes[] = {"xy", "xz", "yz", "q"};
  switch (pick(g, 4)) {
  case 0:
    emit(g, "%T = outcrop.slice(%N, %o)", "I", F_SLICE, planes[pick(g, 4)], 1,
         16, 1, 16);
    break;
  case 1:
    emit(g, "%T = outcrop.geology.slice(%N, %o)", "I", F_SLICE,
         planes[pick(g, 4)], 1, 16, 1, 16);
    break;
  case 2:
    emit(g, "%T = outcrop.polygonize(%N, %o)", "M",
         pick(g, 2) ? "box = {-6, -6, -6, %w, 6, 6}, cell = %w%[, open = "
                      "true%]%[, steps = %w%]%[, colors = %f%]"
                    : "box = {-6, -6, -6, %w, 6, 6}, resolution = {%w, %w, "
                      "%w}%[, full_grid = true%]%[, colors = {field = %N, "
                      "palette = %p}%]",
         1, 8, 1, 3, 1, 10, 1, 10);
    break;
  default:
    emit(g, "%T = outcrop.render(%N, %o)", "I",
         "size = {%w, %w}, camera = {eye = {-20, -30, 15}, target = "
         "{0, 0, 0}, fov = %n}%[, aov = true%]%[, shadows = false, ao = "
         "false%]%[, fog = %n%]%[, tracer = 'sphere'%]%[, color = %f%]"
         "%[, color = %N%]",
         1, 12, 1, 9);
  }
}

static void writer(gen *g) {
  static const char *const img[] = {"i.png",   "i.jpg",    "i.tif", "i.exr",
                                    "d/i.png", "../x.png", "i.bmp"};
  static const char *const msh[] = {"m.ply", "m.obj", "m.glb", "m.stl"};
  static const char *const hfs[] = {"h.png", "h.tif", "h.exr", "h.jpg"};
  switch (pick(g, 3)) {
  case 0:
    emit(g, "use(%T:write('%s'%[, %o%]))", "I", img[pick(g, 7)],
         "bits = %n%[, meta = {note = 'a\\nb', ['k.1'] = 'v'}%]");
    break;
  case 1:
    emit(g, "use(%T:write('%s'%[, %o%]))", "M", msh[pick(g, 4)], "colors = %f");
    break;
  default:
    emit(g, "use(%H:save('%s'%[, %o%]))", hfs[pick(g, 4)],
         "bits = %n%[, scale = %n%]%[, palette = true%]");
  }
}

static void accessor(gen *g) {
  switch (pick(g, 8)) {
  case 0:
    emit(g, "use(%T:get(%n, %n))", "I");
    break;
  case 1:
    emit(g, "use(%T:size(), %T:channels())", "I", "I");
    break;
  case 2:
    emit(g, "use(%T:vertex(%n))", "M");
    break;
  case 3:
    emit(g, "use(%T:triangle(%n), %T:counts())", "M", "M");
    break;
  case 4:
    emit(g, "use(%T:stats())", "M");
    break;
  case 5:
    emit(g, "use(%T:get(%n), #%T)", "P", "P");
    break;
  case 6:
    emit(g, "use(%T:table())", "P");
    break;
  default:
    emit(g, "use(tostring(%T), tostring(%H))", "N");
  }
}

/* ---- statements of version 2 ------------------------------------------ */

#define F_ENOISE                                                               \
  "kind = '%s', amplitude = %n%[, wavelength = %n%]%[, octaves = %w%]"         \
  "%[, gain = %n%]%[, lacunarity = %n%]%[, seed = %n%]"
#define F_EPTS "points = %x%[, spline = '%s'%]"

static const char *const splines[] = {"catmull", "bezier", "linear", "x"};

static void elevation(gen *g) {
  static const char *const noises[] = {"plain", "turbulence", "ridged", "x"};
  static const char *const rivers[] = {"stream", "river", "meander", "main",
                                       "x"};
  static const char *const places[] = {
      "quad = {{0, 0}, {%w, 0}, {%w, %w}, {0, %w}}",
      "segment = {%y, %y}, width = %n", "curve = %Y, width = %n", "quad = %Y"};
  switch (pick(g, 7)) {
  case 0:
  case 1:
    emit(g, "%T = outcrop.elevation.disc%o", "E",
         "center = %y, radius = %w%[, height = %n%]%[, noise = %o%]", 1, 40,
         F_ENOISE, noises[pick(g, 4)], 1, 16);
    break;
  case 2:
    emit(g, "%T = outcrop.elevation.curve%o", "E",
         F_EPTS
         ", radius = %w%[, core = %n%]%[, profile = %k%]"
         "%[, profiles = {{at = 0, knots = %k}, {at = %n, knots = %k}}%]",
         splines[pick(g, 4)], 1, 8);
    break;
  case 3: {
    /* (one pick per call: the order in which a compiler evaluates
    ** arguments is unspecified, and gcc and clang differ) */
    const char *spline = splines[pick(g, 4)];
    emit(g, "%T = outcrop.elevation.river%o", "E",
         F_EPTS "%[, kind = '%s'%]%[, width = %n%]%[, depth = %n%]"
                "%[, bank = %n%]",
         spline, rivers[pick(g, 5)]);
    break;
  }
  case 4:
    emit(g, "%T = outcrop.elevation.road%o", "E",
         F_EPTS "%[, width = %n%]%[, shoulder = %n%]%[, embankment = %n%]",
         splines[pick(g, 4)]);
    break;
  case 5:
    emit(g, "%T = outcrop.elevation.lake%o", "E",
         "center = %y%[, radius = %w%]%[, radius = {%n, %n, %n%[, %n%]}%]"
         "%[, contour = %Y%]%[, level = %n%]%[, falloff = %n%]%[, depth = %n%]"
         "%[, bank = %n%]%[, profile = %k%]"
         "%[, profiles = {{angle = %n, knots = %k}%[, {angle = %n, knots = "
         "%k}%]}%]",
         1, 12);
    break;
  default: {
    char f[256]; /* the fields, with the placement's template inside */
    snprintf(f, sizeof f,
             "heightfield = %%H%%[, weight = %%H%%], %s%%[, spline = "
             "'bezier'%%]%%[, height = %%n%%]%%[, offset = %%n%%]"
             "%%[, falloff = %%n%%]",
             places[pick(g, 4)]);
    emit(g, "%T = outcrop.elevation.image%o", "E", f, 1, 40, 1, 40, 1, 40, 1,
         40);
  }
  }
}

static void elevation_op(gen *g) {
  switch (pick(g, 7)) {
  case 0:
  case 1:
    emit(g, "%T = outcrop.elevation.blend{%E, %E%[, %E%]}", "E");
    break;
  case 2:
    emit(g, "%T = outcrop.elevation.replace(%E, %E%[, %o%])", "E",
         "weight = '%s'", pick(g, 2) ? "a" : "lerp");
    break;
  case 3:
    emit(g, "%T = outcrop.elevation.add(%E, %E%[, %o%])", "E",
         "weight = '%s'%[, below = %n%]%[, fade = %n%]%[, slope = %n%]"
         "%[, slope_fade = %n%]%[, slope_step = %n%]",
         pick(g, 2) ? "a" : "sum");
    break;
  case 4:
    emit(g, "%T = outcrop.elevation.warp(%E, %o)", "E",
         "amplitude = %n, wavelength = %n%[, octaves = %w%]%[, seed = %n%]", 1,
         16);
    break;
  case 5:
    emit(g, "%T = outcrop.elevation.transform(%E, %o)", "E",
         "translate = %y%[, rotate = %n%]%[, scale = %n%]%[, vscale = %n%]"
         "%[, voffset = %n%]");
    break;
  default:
    emit(g, "%T = outcrop.elevation.lod(%E, %E, %o)", "E",
         "wavelength = %n%[, k0 = %n%]%[, k1 = %n%]");
  }
}

static void elevation_use(gen *g) {
  static const char *const q[] = {"bounds", "lipschitz", "stats", "kind"};
  switch (pick(g, 7)) {
  case 0:
    emit(g, "use(%E:eval(%n, %n%[, {eye = %v, k = %n}%]))");
    break;
  case 1:
    emit(g, "use(%E:gradient(%n, %n%[, {eye = %v, k = %n}%]))");
    break;
  case 2:
    emit(g, "use(%E:%s())", q[pick(g, 4)]);
    break;
  case 3:
    emit(g, "%T = outcrop.terrain(%E%[, %o%])", "N",
         "falloff = %n%[, transition = %n%]%[, thickness = %n%]"
         "%[, invert = true%]%[, edges = 'slab'%]%[, mask = %H%]"
         "%[, domain = {%n, %n, %w, %w}%]",
         1, 40, 1, 40);
    break;
  case 4:
    emit(g, "%H = outcrop.heightfield.from(%E, %o)",
         "size = {%W, %W}, cell = %W%[, origin = {%n, %n}%]%[, holes = %n%]",
         GRID_ARGS);
    break;
  default:
    emit(g, "%T = outcrop.render(%E, %o)", "I",
         "size = {%W, %W}, camera = {eye = {-20, -30, 15}, target = "
         "{0, 0, 0}, fov = %n}%[, aov = true%]%[, shadows = false, ao = "
         "false%]%[, lod = %b%]%[, tracer = 'sphere'%]%[, color = %f%]",
         1, 12, 1, 9);
  }
}

static void feature_curve(gen *g) {
  switch (pick(g, 5)) {
  case 0:
  case 1:
    emit(g, "%T = outcrop.feature_curve%o", "C",
         "points = %Y%[, bezier = %b%], constraints = %c");
    break;
  case 2:
    emit(g, "use(%C:length(), %C:sample(%n), tostring(%C))");
    break;
  case 3:
    /* round trip, or the encoding with a byte changed or cut */
    emit(g,
         "local s = %C:save() %[s = s:sub(1, %w) .. string.char(%w) .. "
         "s:sub(%w)%] %T = outcrop.feature_curve_load(s)",
         1, 24, 0, 255, 1, 24, "C");
    break;
  default:
    emit(g, "%T = outcrop.feature_curve_load(%z)", "C");
  }
}

static void diffusion(gen *g) {
  static const char *const schemes[] = {"upwind", "paper", "x"};
  static const char *const maps[] = {"smooth", "detail", "amplitude",
                                     "roughness", "gradient"};
  emit(g, "local h, m = outcrop.diffusion%o",
       "size = {%w, %w}%[, cell = %w%]"
       "%[, origin = {%n, %n}%], curves = {%C%[, %C%]%[, %C%]}%[, seed = %n%]"
       "%[, scheme = '%s'%]%[, converged = %b%]%[, converged = %n%]"
       "%[, noise = %o%]",
       2, 24, 2, 24, 1, 4, schemes[pick(g, 3)],
       "wavelength = %n%[, octaves = %w%]%[, ratio = %n%]", 1, 16);
  emit(g, " %H = h %H = m.%s use(m.levels, m.cycles, m.residuals, m.strict)",
       maps[pick(g, 5)]);
}

static void blocks(gen *g) {
  static const char *const types[] = {
      "equidimensional", "rhombohedral", "polyhedral", "tabular",
      "prismatic",       "columnar",     "x"};
  static const char *const authored[] = {
      "{box = {%n, %n, %n, %n, %n, %n}}", "{points = {%v, %v, %v, %v%[, %v%]}}",
      ("{planes = {{1, 0, 0, %n}, {-1, 0, 0, %n}, {0, 1, 0, %n}, "
       "{0, -1, 0, %n}, {0, 0, 1, %n}, {0, 0, -1, %n}%[, {%n, %n, %n, "
       "%n}%]}}")};
  switch (pick(g, 10)) {
  case 0:
  case 1: {
    /* small tiles: the work grows as (size / radius)^3, here at most
    ** (10 / 0.75)^3, an eighth of the default tile's, and as neighbour^3
    ** (here at most the default 2) */
    char f[512]; /* the fields, with an authored block's template inside */
    const char *type = types[pick(g, 7)];
    snprintf(
        f, sizeof f,
        "type = '%s', size = %%W, radius = %%W / 4%%[, neighbour = %%w / 4%%]"
        "%%[, fractures = %%w%%]%%[, spacing = %%n%%]"
        "%%[, disc_radius = {%%n, %%n}%%]%%[, rounding = %%n%%]"
        "%%[, width = %%n%%]%%[, seed = %%n%%]%%[, discs = {{center = "
        "%%v, normal = %%v, radius = %%n}}%%]%%[, blocks = {%s}%%]",
        type, authored[pick(g, 3)]);
    emit(g, "%T = outcrop.blocks.tile%o", "B", f, 6, 10, 3, 4, 5, 8, 1, 8);
    break;
  }
  case 2:
    emit(
        g, "%T = outcrop.layers.rocks%o", "B",
        "size = %W, radius = %W / 2%[, erosion = %n%]%[, spread = %n%]"
        "%[, contacts = %w%]%[, rounding = %n%]%[, width = %n%]%[, seed = %n%]",
        4, 6, 2, 3, 1, 8);
    break;
  case 3:
    emit(g, "use(%B:count(), %B:stats(), tostring(%B))");
    break;
  case 4:
    emit(g, "%T = ", "N");
    emit(g, pick(g, 2) ? "%B:block(%n)" : "%B:node()");
    break;
  case 5:
    emit(g, "local ms = %B:meshes%o use(#ms)", "cell = %W", 1, 4);
    break;
  case 6:
    /* saved, then loaded as is, cut short or with a byte changed */
    emit(g,
         "use(%B:save('t.octile')) "
         "%[local f = io.open(OUT .. '/t.octile', 'rb') local s = f:read('a') "
         "f:close() s = s:sub(1, %w) .. string.char(%w) .. s:sub(%w) "
         "f = io.open('t.octile', 'wb') f:write(s) f:close()%] "
         "%T = outcrop.blocks.load(OUT .. '/t.octile')",
         1, 200, 0, 255, 1, 200, "B");
    break;
  case 7:
  case 8:
    emit(g, "%T = outcrop.blocks.replicate(%N, %o)", "N",
         "tiles = {{tile = %B%[, resistance = {%n, %n}%]}%[, {tile = %B}%]}"
         "%[, geology = %N%]%[, slope = %n%]%[, distance = {%n, %n}%]"
         "%[, anchors = %w%]%[, inset = %n%]",
         1, 12);
    break;
  default:
    emit(g, "%T = outcrop.relief_warp(%N, %o)", "N",
         "%[relief = 'turbulence', %]%[relief = {kind = 'turbulence', "
         "wavelength = %n%[, octaves = %w%]%[, seed = %n%]}, %]"
         "%[relief = {kind = 'image', path = OUT .. '/i.png', "
         "wavelength = %n}, %]amplitude = %n%[, step = %n%]",
         1, 16);
  }
}

static const char *const materials[] = {"bedrock", "sand", "rocks",
                                        "water",   "air",  "x"};

static void layers(gen *g) {
  switch (pick(g, 9)) {
  case 0:
    emit(g, "%T = outcrop.layers.new%o", "S",
         "size = {%w, %w}%[, cell = %w%]%[, origin = {%n, %n}%]%[, base = %n%]"
         "%[, layers = {{'bedrock', %n}, {'%s', %n}%[, {'sand', %n}%]}%]",
         1, 24, 1, 24, 1, 4, materials[pick(g, 6)]);
    break;
  case 1:
    emit(g, "%T = outcrop.layers.from_heightfield(%H%[, %o%])", "S",
         "base = %n%[, sand = %n%]");
    break;
  case 2:
    emit(g, "%T = outcrop.layers.from_node(%N, %o)", "S",
         "box = {-4, -4, -4, %w, %w, %w}, cell = %w%[, material = '%s'%]"
         "%[, step = %w%]",
         1, 8, 1, 8, 1, 8, 1, 2, materials[pick(g, 6)], 1, 2);
    break;
  case 3:
    emit(g, "use(%S:get(%n, %n), %S:size(), %S:cell(), %S:origin(), "
            "%S:base(), %S:stats())");
    break;
  case 4:
    emit(g,
         "%S:set(%n, %n, {{'%s', %n}%[, {'sand', %n}%]%[, {'air', %n}, "
         "{'bedrock', %n}%]})",
         materials[pick(g, 6)]);
    break;
  case 5:
    emit(g, "%H = %S:heightfield('%s') use(%S:volume('%s'))",
         materials[pick(g, 6)], "sand");
    break;
  case 6:
    emit(g, "%T = %S:field%o", "N",
         "materials = {'bedrock'%[, 'sand'%]%[, '%s'%]}%[, sigma = %n%]",
         materials[pick(g, 6)]);
    break;
  case 7:
    emit(g, "%T = outcrop.render(%N, {size = {%W, %W}, color = %S:colors%o})",
         "I", 1, 8, 1, 8,
         "%[sigma = %n, %]ratio = '%s'%[, sand = {%n, %n, %n}%]",
         pick(g, 2) ? "visible" : "volume");
    break;
  default:
    emit(g, "local n, info = %S:rocks(%B%[, %o%]) %T = n use(info.instances)",
         "%[ground = %N, %]%[depth = %n, %]list = %b", "N");
  }
}

static void layers_tool(gen *g) {
  switch (pick(g, 5)) {
  case 0:
    emit(g, "use(%S:stabilize%o)",
         "iterations = %W%[, tolerance = %n%]%[, rate = %n%]"
         "%[, angle = {sand = %n, rocks = %n}%]",
         1, 200);
    break;
  case 1:
    emit(g, "use(%S:deposit%o)",
         "center = %y, radius = %w, amount = %n%[, material = '%s'%], %t", 1, 8,
         materials[pick(g, 6)]);
    break;
  case 2:
    emit(g, "use(%S:erode%o)",
         "region = {%n, %n, %n, %n}%[, ratio = %n%]%[, mode = '%s'%]"
         "%[, depth = %n%], %t",
         pick(g, 2) ? "surface" : "collapse");
    break;
  case 3:
    emit(g, "use(%S:sculpt%o)",
         "center = %v, radius = %w%[, strength = %n%]%[, mode = '%s'%]"
         "%[, delta = %n%], %t",
         1, 4, pick(g, 2) ? "add" : "carve");
    break;
  default:
    emit(g, "use(%S:sweep%o)",
         "path = {%v, %v%[, %v%]}, profiles = {{%n, %n}, {%n, %n}, {%n, %n}"
         "%[, {%n, %n}%]}%[, mode = '%s'%], %t",
         pick(g, 2) ? "crack" : "tunnel");
  }
}

/* Lifetimes: closing, dropping, collecting, finalizers, <close>. */
static void lifetime(gen *g) {
  switch (pick(g, 6)) {
  case 0:
    mischief(g);
    break;
  case 1:
    emit(g, "do local x <close> = %H end");
    break;
  case 2:
    emit(g, "fin(function() %m end)");
    break;
  case 3:
    emit(g, "%T = nil collectgarbage()", "N");
    break;
  case 4:
    emit(g, "outcrop.threshold = %n");
    break;
  default:
    emit(g, "collectgarbage('step', %n)");
  }
}

static void statement(gen *g) {
  puts_(g, "pcall(function() ");
  switch (pick(g, g->v2 ? 24 : 16)) {
  case 0:
  case 1:
    primitive(g);
    break;
  case 2:
  case 3:
    operator(g);
    break;
  case 4:
    query(g);
    break;
  case 5:
    heightfield(g);
    break;
  case 6:
    analysis(g);
    break;
  case 7:
    terrain(g);
    break;
  case 8:
    geology(g);
    break;
  case 9:
    generator(g);
    break;
  case 10:
    poisson(g);
    break;
  case 11:
  case 12:
    output(g);
    break;
  case 13:
    writer(g);
    break;
  case 14:
    accessor(g);
    break;
  case 15:
    lifetime(g);
    break;
  case 16:
    elevation(g);
    break;
  case 17:
    elevation_op(g);
    break;
  case 18:
    elevation_use(g);
    break;
  case 19:
    feature_curve(g);
    break;
  case 20:
    diffusion(g);
    break;
  case 21:
    blocks(g);
    break;
  case 22:
    layers(g);
    break;
  default:
    layers_tool(g);
  }
  puts_(g, " end)\n");
}

/* Helpers every scene starts with. `close` calls an object's __close the
** way `local x <close>` would; `gc` reaches a node's __gc through its
** metatable when the metatable lets it. */
static const char prelude[] =
    "local N, H, I, M, P = {}, {}, {}, {}, {}\n"
    "local function use(...) return ... end\n"
    "local function close(x)\n"
    "  local mt = getmetatable(x)\n"
    "  if type(mt) == 'table' and mt.__close then mt.__close(x) end\n"
    "end\n"
    "local function gc(x)\n"
    "  local mt = getmetatable(x)\n"
    "  if type(mt) == 'table' and mt.__gc then mt.__gc(x) end\n"
    "end\n"
    "local function hostile(t, f)\n"
    "  return setmetatable({}, {__index = function(_, k) f() return t[k] "
    "end,\n"
    "    __pairs = function() f() return next, t, nil end})\n"
    "end\n"
    "local function fin(f) setmetatable({}, {__gc = f}) end\n";

int ocfz_skip_from_env(void) {
  const char *s = getenv("OCFUZZ_SKIP");
  int flags = 0;
  if (s == NULL) return 0;
  if (strstr(s, "close")) flags |= OCFZ_NO_CLOSE;
  if (strstr(s, "huge")) flags |= OCFZ_NO_HUGE;
  return flags;
}

char *ocfz_scene(const uint8_t *data, size_t size, int flags, size_t *len) {
  gen g = {data, size, 0, flags, 0, 0, NULL, 0, 4096};
  int k;
  g.s = malloc(g.cap);
  if (g.s == NULL) return NULL;
  g.s[0] = '\0';
  if (size >= sizeof V2_MARK && memcmp(data, V2_MARK, sizeof V2_MARK) == 0) {
    g.v2 = 1;
    g.i = sizeof V2_MARK;
  }
  puts_(&g, prelude);
  if (g.v2) puts_(&g, "local E, C, B, S = {}, {}, {}, {}\n");
  for (k = 0; k < MAXSTMT && g.i < g.n; k++)
    statement(&g);
  if (g.s && len) *len = g.len;
  return g.s;
}
