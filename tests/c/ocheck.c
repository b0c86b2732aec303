/*
** ocheck.c — shared support of the C field tests (see ocheck.h).
*/
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>
#include "ocheck.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- random stream ----------------------------------------------------- */

oct_rng oct_rng_new(uint64_t seed) {
  oct_rng r = {seed * 0x2545f4914f6cdd1dull + 1};
  return r;
}

static uint64_t next64(oct_rng *r) {
  uint64_t z = (r->s += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

double oct_unif(oct_rng *r, double lo, double hi) {
  return lo + (hi - lo) * ((double)(next64(r) >> 11) * 0x1.0p-53);
}

oc_vec3 oct_in_box(oct_rng *r, oc_vec3 lo, oc_vec3 hi) {
  return oct_v(oct_unif(r, lo.x, hi.x), oct_unif(r, lo.y, hi.y),
               oct_unif(r, lo.z, hi.z));
}

oc_vec3 oct_dir(oct_rng *r) {
  for (;;) {
    oc_vec3 v =
        oct_v(oct_unif(r, -1, 1), oct_unif(r, -1, 1), oct_unif(r, -1, 1));
    double l = oct_len(v);
    if (l > 0.1 && l <= 1.0) return oct_mul(v, 1.0 / l);
  }
}

/* ---- reference falloff and distances ----------------------------------- */

double oct_g(double x) {
  if (x < 0 || x >= 1) return 0.0;
  double u = 1.0 - x * x;
  return u * u * u;
}

double oct_ginv(double y) {
  if (y <= 0) return 1.0;
  if (y >= 1) return 0.0;
  return sqrt(1.0 - cbrt(y));
}

double oct_dist_segment(oc_vec3 p, oc_vec3 a, oc_vec3 b, oc_vec3 *cp) {
  oc_vec3 ab = oct_sub(b, a);
  double l2 = oct_dot(ab, ab);
  double t = l2 > 0 ? oct_dot(oct_sub(p, a), ab) / l2 : 0.0;
  if (t < 0) t = 0;
  if (t > 1) t = 1;
  oc_vec3 c = oct_add(a, oct_mul(ab, t));
  if (cp) *cp = c;
  return oct_len(oct_sub(p, c));
}

double oct_dist_box(oc_vec3 p, oc_vec3 lo, oc_vec3 hi) {
  double dx = fmax(0, fmax(lo.x - p.x, p.x - hi.x));
  double dy = fmax(0, fmax(lo.y - p.y, p.y - hi.y));
  double dz = fmax(0, fmax(lo.z - p.z, p.z - hi.z));
  return sqrt(dx * dx + dy * dy + dz * dz);
}

double oct_dist_polyline(oc_vec3 p, const oc_vec3 *pts, size_t n, double *gap) {
  double best = INFINITY, second = INFINITY;
  oc_vec3 bestcp = {0, 0, 0};
  for (size_t i = 0; i + 1 < n; i++) {
    oc_vec3 cp;
    double d = oct_dist_segment(p, pts[i], pts[i + 1], &cp);
    if (d < best) {
      if (oct_len(oct_sub(cp, bestcp)) > 1e-12) second = best;
      best = d;
      bestcp = cp;
    } else if (d < second && oct_len(oct_sub(cp, bestcp)) > 1e-12) {
      second = d;
    }
  }
  if (gap) *gap = second - best;
  return best;
}

/* ---- building and compiling -------------------------------------------- */

oc_node *oct_ok_(oc_node *n, const char *what, const char *file, int line) {
  if (!n) ck_abort_msg("%s:%d: %s returned NULL", file, line, what);
  return n;
}

oc_node *oct_random_prim(oct_rng *r, oc_vec3 lo, oc_vec3 hi, double rmin,
                         double rmax, double pneg) {
  oc_vec3 c = oct_in_box(r, lo, hi);
  double R = oct_unif(r, rmin, rmax);
  double E = oct_unif(r, 0.3, 2.0);
  if (oct_unif(r, 0, 1) < pneg) E = -E;
  oc_error e;
  oc_node *n = NULL;
  switch ((int)oct_unif(r, 0, 4)) {
  case 0:
    n = oc_point(c, R, E, &e);
    break;
  case 1:
    n = oc_sphere(c, oct_unif(r, 0.1, 1) * R, R, E, &e);
    break;
  case 2: {
    oc_vec3 b = oct_add(c, oct_mul(oct_dir(r), oct_unif(r, 0, 2) * R));
    n = oc_segment(c, b, R, E, &e);
    break;
  }
  default: {
    oc_vec3 hi2 =
        oct_add(c, oct_v(oct_unif(r, 0.05, 1) * R, oct_unif(r, 0.05, 1) * R,
                         oct_unif(r, 0.05, 1) * R));
    n = oc_box(c, hi2, R, E, &e);
  }
  }
  ck_assert_msg(n != NULL, "random primitive: %s", e.msg);
  return n;
}

oc_program *oct_compile(oc_node *n, double T, int no_bvh) {
  oc_compile_options o = {T, no_bvh};
  oc_error e = {0};
  oc_program *pr = oc_compile(n, &o, &e);
  ck_assert_msg(pr != NULL, "oc_compile failed: %d %s", (int)e.code, e.msg);
  oc_node_release(n);
  return pr;
}

/* ---- checks ------------------------------------------------------------ */

oc_vec3 oct_fd_grad(const oc_program *pr, oc_vec3 p, double h) {
  oc_vec3 g;
  g.x = (oc_program_eval(pr, oct_v(p.x + h, p.y, p.z)) -
         oc_program_eval(pr, oct_v(p.x - h, p.y, p.z))) /
        (2 * h);
  g.y = (oc_program_eval(pr, oct_v(p.x, p.y + h, p.z)) -
         oc_program_eval(pr, oct_v(p.x, p.y - h, p.z))) /
        (2 * h);
  g.z = (oc_program_eval(pr, oct_v(p.x, p.y, p.z + h)) -
         oc_program_eval(pr, oct_v(p.x, p.y, p.z - h))) /
        (2 * h);
  return g;
}

void oct_check_grad(const oc_program *pr, oc_vec3 p, double h, double atol) {
  oc_vec3 g = {NAN, NAN, NAN};
  double v = oc_program_gradient(pr, p, &g);
  double f = oc_program_eval(pr, p);
  ck_assert_msg(fabs(v - f) <= 1e-12 * (1 + fabs(f)),
                "gradient() value %.17g != eval %.17g at (%.9g %.9g %.9g)", v,
                f, p.x, p.y, p.z);
  oc_vec3 fd = oct_fd_grad(pr, p, h);
  double err = oct_len(oct_sub(g, fd));
  ck_assert_msg(err <= 1e-5 * oct_len(fd) + atol,
                "gradient (%.9g %.9g %.9g) vs central differences "
                "(%.9g %.9g %.9g) at (%.9g %.9g %.9g), f=%.9g",
                g.x, g.y, g.z, fd.x, fd.y, fd.z, p.x, p.y, p.z, f);
}

static void lip_pair(const oc_program *pr, double L, oc_vec3 p, oc_vec3 q,
                     double *worst) {
  double fp = oc_program_eval(pr, p), fq = oc_program_eval(pr, q);
  double d = oct_len(oct_sub(p, q));
  if (d == 0) return;
  double df = fabs(fp - fq);
  /* Rounding in f itself, not a Lipschitz violation. */
  double slack = 1e-14 * (1 + fabs(fp) + fabs(fq));
  ck_assert_msg(df <= L * d * (1 + 1e-9) + slack,
                "Lipschitz bound %.9g exceeded: |f(p)-f(q)|/|p-q| = %.9g, "
                "p=(%.12g %.12g %.12g) q=(%.12g %.12g %.12g)",
                L, df / d, p.x, p.y, p.z, q.x, q.y, q.z);
  if (df > slack && df / (L * d) > *worst) *worst = df / (L * d);
}

double oct_check_lipschitz(const oc_program *pr, oc_vec3 lo, oc_vec3 hi,
                           int npairs, oct_rng *r) {
  double L = oc_program_lipschitz(pr);
  ck_assert_msg(L >= 0 && !isnan(L), "Lipschitz bound %g", L);
  double size = oct_len(oct_sub(hi, lo));
  double worst = 0;
  static const double scales[] = {1.0, 1e-1, 1e-3, 1e-5, 1e-7};
  for (int i = 0; i < npairs; i++) {
    oc_vec3 p = oct_in_box(r, lo, hi);
    oc_vec3 q;
    if (i % 6 == 0)
      q = oct_in_box(r, lo, hi);
    else
      q = oct_add(p, oct_mul(oct_dir(r), size * scales[i % 6 - 1]));
    lip_pair(pr, L, p, q, &worst);
  }
  return worst;
}

static int outside(oc_aabb b, oc_vec3 p) {
  return p.x < b.lo.x || p.x > b.hi.x || p.y < b.lo.y || p.y > b.hi.y ||
         p.z < b.lo.z || p.z > b.hi.z;
}

static void zero_outside(const oc_program *pr, oc_aabb b, oc_vec3 p) {
  if (!outside(b, p)) return;
  double f = oc_program_eval(pr, p);
  ck_assert_msg(f == 0.0,
                "f = %.17g at (%.12g %.12g %.12g), outside the bounds "
                "[%g %g %g]-[%g %g %g]",
                f, p.x, p.y, p.z, b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y,
                b.hi.z);
}

int oct_check_bounds(const oc_program *pr, oc_vec3 lo, oc_vec3 hi, int n,
                     oct_rng *r) {
  oc_aabb b = oc_program_bounds(pr);
  int nonzero = 0;
  for (int i = 0; i < n; i++) {
    oc_vec3 p = oct_in_box(r, lo, hi);
    zero_outside(pr, b, p);
    if (oc_program_eval(pr, p) != 0) nonzero++;
  }
  /* Just outside each finite face of the box. */
  double *blo = &b.lo.x, *bhi = &b.hi.x;
  for (int i = 0; i < n; i++) {
    oc_vec3 p = oct_in_box(r, lo, hi);
    double *pc = &p.x;
    int axis = i % 3;
    if (i / 3 % 2 == 0 && isfinite(blo[axis]))
      pc[axis] = nextafter(blo[axis], -INFINITY);
    else if (isfinite(bhi[axis]))
      pc[axis] = nextafter(bhi[axis], INFINITY);
    else
      continue;
    zero_outside(pr, b, p);
  }
  return nonzero;
}

void oct_einval_(oc_node *n, const oc_error *err, const char *param,
                 const char *what, const char *file, int line) {
  if (n) {
    oc_node_release(n);
    ck_abort_msg("%s:%d: %s accepted invalid input", file, line, what);
  }
  if (err->code != OC_EINVAL)
    ck_abort_msg("%s:%d: %s: code %d, expected OC_EINVAL (%s)", file, line,
                 what, (int)err->code, err->msg);
  /* `param` may list alternatives: "apex|base". */
  char buf[128];
  snprintf(buf, sizeof buf, "%s", param);
  for (char *tok = strtok(buf, "|"); tok; tok = strtok(NULL, "|")) {
    char quoted[64];
    snprintf(quoted, sizeof quoted, "'%s'", tok);
    if (strstr(err->msg, quoted)) return;
  }
  ck_abort_msg("%s:%d: %s: message \"%s\" does not name '%s'", file, line, what,
               err->msg, param);
}

int oct_run(Suite *s) {
  SRunner *sr = srunner_create(s);
  /* No fork per test unless CK_FORK asks for it: a binary that loads
  ** OpenImageIO also loads log4cplus (through OpenVDB), which starts a
  ** thread at load time and whose exit-time finalizer waits for it, so a
  ** forked child hangs on exit (threads are not copied by fork); and
  ** libgomp cannot run parallel regions in a child forked after the
  ** parent used them. */
  if (!getenv("CK_FORK")) srunner_set_fork_status(sr, CK_NOFORK);
  srunner_run_all(sr, CK_ENV);
  int failed = srunner_ntests_failed(sr);
  srunner_free(sr);
  return failed == 0 ? 0 : 1;
}

/* ---- scratch folders ---------------------------------------------------- */

const char *oct_tmpdir(const char *tag) {
  static char dir[128];
  snprintf(dir, sizeof dir, "/tmp/oc-test-%s-XXXXXX", tag);
  ck_assert_ptr_nonnull(mkdtemp(dir));
  return dir;
}

const char *oct_in_dir(const char *dir, const char *name) {
  static char buf[8][256];
  static int k;
  k = (k + 1) % 8;
  snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
  return buf[k];
}

int oct_count_entries(const char *d, char *names, size_t size) {
  DIR *dp = opendir(d);
  ck_assert_ptr_nonnull(dp);
  int n = 0;
  if (names && size) names[0] = '\0';
  struct dirent *e;
  while ((e = readdir(dp))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    n++;
    if (names && strlen(names) + strlen(e->d_name) + 2 < size) {
      strcat(names, e->d_name);
      strcat(names, " ");
    }
  }
  closedir(dp);
  return n;
}

void oct_rm_tree(const char *d) {
  DIR *dp = opendir(d);
  if (!dp) return;
  struct dirent *e;
  while ((e = readdir(dp))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
    char p[512];
    snprintf(p, sizeof p, "%s/%s", d, e->d_name);
    struct stat st;
    if (lstat(p, &st) == 0 && S_ISDIR(st.st_mode)) {
      chmod(p, 0755);
      oct_rm_tree(p);
    } else {
      unlink(p);
    }
  }
  closedir(dp);
  rmdir(d);
}
