/*
** discs.c — fracture discs (Paris et al. 2020, section 4.1): their
** distribution per block type, thrown as counted darts with a minimum
** spacing of their centres on the torus, the user's discs after them, and
** their periodic images.
**
** Types (the paper's, with its constants):
**  - equidimensional: normal along a random axis (x, y or z), radius
**    uniform in [disc_lo, disc_hi] (7 .. 11 m by default: the paper's
**    "about 5 m" gives blocks twice as large as its Table 1's);
**  - rhombohedral: the same over three mutually oblique axes: x, x turned
**    60 degrees about z, and z tilted 30 degrees towards (1, 1, 0);
**  - polyhedral: uniform random normals, centres 1 m apart, more discs;
**  - tabular: the first third of the discs are bedding planes (normal z,
**    radius s, centres at least min(spacing, s / (2 #beds)) apart in z),
**    the rest cross
**    discs with a normal along x or y and radius s / 10.
** Extensions (documented in the README, not in Table 1):
**  - prismatic: "similar in shape [to equidimensional] but formed under
**    slightly more irregular fracture distributions": each normal is a
**    random axis tilted by up to 20 degrees in a random direction, radius
**    in [disc_lo, disc_hi] (7 .. 11 m), 12 discs (about 100 blocks of
**    130 points at the defaults, as Table 1's equidimensional);
**  - columnar: "several sets of continuous, parallel fractures", columns
**    much longer than wide: three vertical sets, normals horizontal at 0,
**    60 and 120 degrees, and every 8th disc a horizontal joint; radii
**    10 .. 14 m, 12 discs 1.5 m apart (about 130 blocks, their height
**    2.7 times their width on average).
** Darts: up to DART_TRIES throws per disc; fewer discs than asked is an
** error naming 'fractures' and 'spacing'.
*/
#include <math.h>
#include <stdlib.h>

#include "blocks/btile.h"
#include "core/error.h"
#include "core/rng.h"

#define DART_TRIES 2000
#define PI 3.14159265358979323846
#define KEY_DISCS 0x6469736373ull
/* prismatic: largest tilt of a set from its axis (20 degrees) */
#define PRISM_TILT (PI / 9)
/* columnar: every COLUMN_JOINT-th disc is a horizontal joint */
#define COLUMN_JOINT 8

static double wrapd(double d, double s) {
  d = fabs(d);
  d = fmod(d, s);
  return fmin(d, s - d);
}

static double tdist2(oc_vec3 a, oc_vec3 b, double s) {
  double x = wrapd(a.x - b.x, s), y = wrapd(a.y - b.y, s),
         z = wrapd(a.z - b.z, s);
  return x * x + y * y + z * z;
}

static oc_vec3 unit(double x, double y, double z) {
  double l = sqrt(x * x + y * y + z * z);
  return (oc_vec3){x / l, y / l, z / l};
}

/* The normal and radius of disc number i of the type. */
static void shape(const oc_btile_params *pp, size_t i, size_t nbed, oc_rng *u,
                  oc_bdisc *d) {
  static const double rh[3][3] = {
      {1, 0, 0},
      {0.5, 0.86602540378443865, 0},
      {0.35355339059327373, 0.35355339059327373, 0.86602540378443865}};
  int axis = (int)(oc_rng_uniform(u) * 3) % 3;
  double r = oc_rng_range(u, pp->disc_lo, pp->disc_hi);
  switch (pp->type) {
  case OC_BLOCKS_RHOMBOHEDRAL:
    d->n = (oc_vec3){rh[axis][0], rh[axis][1], rh[axis][2]};
    d->r = r;
    break;
  case OC_BLOCKS_POLYHEDRAL: {
    double z = oc_rng_range(u, -1, 1), a = oc_rng_range(u, 0, 2 * PI);
    double q = sqrt(fmax(0, 1 - z * z));
    d->n = (oc_vec3){q * cos(a), q * sin(a), z};
    d->r = r;
    break;
  }
  case OC_BLOCKS_TABULAR:
    if (i < nbed) {
      d->n = (oc_vec3){0, 0, 1};
      d->r = pp->size;
    } else {
      d->n = axis & 1 ? (oc_vec3){1, 0, 0} : (oc_vec3){0, 1, 0};
      d->r = pp->size / 10;
    }
    break;
  case OC_BLOCKS_PRISMATIC: {
    /* the axis tilted by up to PRISM_TILT towards a random direction */
    double tilt = oc_rng_range(u, 0, PRISM_TILT),
           a = oc_rng_range(u, 0, 2 * PI);
    double e[3] = {0, 0, 0}, q[3], w[3];
    e[axis] = 1;
    q[(axis + 1) % 3] = 1, q[axis] = q[(axis + 2) % 3] = 0;
    w[(axis + 2) % 3] = 1, w[axis] = w[(axis + 1) % 3] = 0;
    double c = cos(tilt), sn = sin(tilt);
    d->n = unit(c * e[0] + sn * (cos(a) * q[0] + sin(a) * w[0]),
                c * e[1] + sn * (cos(a) * q[1] + sin(a) * w[1]),
                c * e[2] + sn * (cos(a) * q[2] + sin(a) * w[2]));
    d->r = r;
    break;
  }
  case OC_BLOCKS_COLUMNAR:
    if (i % COLUMN_JOINT == COLUMN_JOINT - 1) {
      d->n = (oc_vec3){0, 0, 1};
    } else {
      double a = axis * PI / 3;
      d->n = (oc_vec3){cos(a), sin(a), 0};
    }
    d->r = r;
    break;
  default:
    d->n = (oc_vec3){axis == 0, axis == 1, axis == 2};
    d->r = r;
  }
}

int oc_bdiscs_make(oc_btile *t, oc_error *err) {
  const oc_btile_params *pp = &t->pp;
  double s = pp->size, sp2 = pp->spacing * pp->spacing;
  size_t n = pp->fractures, nbed = pp->type == OC_BLOCKS_TABULAR ? n / 3 : 0;
  t->disc = malloc((n + pp->ndiscs) * sizeof *t->disc);
  if (!t->disc) return oc_seterr(err, OC_ENOMEM, "out of memory for discs");
  oc_rng u = oc_rng_stream(pp->seed, KEY_DISCS);
  size_t nd = 0;
  /* beds: `spacing` apart, or closer when that many could not fit */
  double bed_gap = nbed ? fmin(pp->spacing, 0.5 * s / (double)nbed) : 0;
  for (size_t i = 0; i < n; i++) {
    oc_bdisc d;
    int ok = 0;
    for (int tr = 0; tr < DART_TRIES && !ok; tr++) {
      d.c = (oc_vec3){s * oc_rng_uniform(&u), s * oc_rng_uniform(&u),
                      s * oc_rng_uniform(&u)};
      ok = 1;
      for (size_t j = 0; j < nd && ok; j++) {
        /* beds are spaced in z alone; any other pair in 3D */
        if (i < nbed) {
          double dz = wrapd(d.c.z - t->disc[j].c.z, s);
          ok = dz >= bed_gap;
        } else {
          ok = tdist2(d.c, t->disc[j].c, s) >= sp2;
        }
      }
    }
    if (!ok) {
      t->nd = nd;
      return oc_seterr(err, OC_EINVAL,
                       "could place only %zu of %zu 'fractures' %g apart "
                       "('spacing') in a tile of 'size' %g",
                       nd, n, pp->spacing, s);
    }
    shape(pp, i, nbed, &u, &d);
    t->disc[nd++] = d;
  }
  for (size_t i = 0; i < pp->ndiscs; i++) {
    const oc_block_disc *b = &pp->discs[i];
    oc_bdisc d;
    d.n = unit(b->normal.x, b->normal.y, b->normal.z);
    d.c = (oc_vec3){s * floor(b->center.x / s), s * floor(b->center.y / s),
                    s * floor(b->center.z / s)};
    d.c = (oc_vec3){b->center.x - d.c.x, b->center.y - d.c.y,
                    b->center.z - d.c.z};
    d.r = b->radius;
    t->disc[nd++] = d;
  }
  t->nd = nd;
  return 0;
}

/* Image index range along one axis: shifts k with [c + k s - e, c + k s +
** e] meeting [lo, hi]. */
static void krange(double c, double e, double s, double lo, double hi,
                   double *k0, double *k1) {
  *k0 = ceil((lo - c - e) / s);
  *k1 = floor((hi - c + e) / s);
}

/* At most this many images of all discs together: the tile's checks
** keep radii within OC_BTILE_MAX_DISC_SIZES sizes, but many large discs
** could still ask for billions. Table 1's tiles make about 2 000; 5
** million (250 discs of 16 sizes) took 139 s to cut the graph. */
#define MAX_IMAGES 1e6

int oc_bdiscs_images(const oc_btile *t, oc_aabb in, oc_bimage **out, size_t *n,
                     oc_error *err) {
  double s = t->pp.size;
  size_t cap = 0, m = 0;
  int k0[3], k1[3];
  /* the images' count first, in doubles: ranges are refused before a
  ** loop or an int sees them; counted over the widest box the tile asks
  ** ([-s, 2s] a side: clusters and merging), so that the first call (the
  ** graph's cut, over a smaller box) refuses what a later one would,
  ** before its work */
  double total = 0;
  for (size_t i = 0; i < t->nd; i++) {
    const oc_bdisc *d = &t->disc[i];
    double n3[3] = {d->n.x, d->n.y, d->n.z}, c3[3] = {d->c.x, d->c.y, d->c.z};
    double lo3[3] = {fmin(in.lo.x, -s), fmin(in.lo.y, -s), fmin(in.lo.z, -s)},
           hi3[3] = {fmax(in.hi.x, 2 * s), fmax(in.hi.y, 2 * s),
                     fmax(in.hi.z, 2 * s)},
           cnt = 1;
    for (int a = 0; a < 3; a++) {
      double e = d->r * sqrt(fmax(0, 1 - n3[a] * n3[a])), a0, a1;
      krange(c3[a], e, s, lo3[a], hi3[a], &a0, &a1);
      cnt *= a1 >= a0 ? a1 - a0 + 1 : 0;
    }
    total += cnt;
  }
  if (!(total <= MAX_IMAGES))
    return oc_seterr(err, OC_EINVAL,
                     "the fracture discs make %g periodic images in the tile "
                     "(at most %g): smaller 'disc_radius' or fewer "
                     "'fractures'",
                     total, MAX_IMAGES);
  for (int pass = 0; pass < 2; pass++) {
    for (size_t i = 0; i < t->nd; i++) {
      const oc_bdisc *d = &t->disc[i];
      double n3[3] = {d->n.x, d->n.y, d->n.z}, c3[3] = {d->c.x, d->c.y, d->c.z};
      double lo3[3] = {in.lo.x, in.lo.y, in.lo.z},
             hi3[3] = {in.hi.x, in.hi.y, in.hi.z}, e[3];
      for (int a = 0; a < 3; a++) {
        e[a] = d->r * sqrt(fmax(0, 1 - n3[a] * n3[a]));
        double a0, a1;
        krange(c3[a], e[a], s, lo3[a], hi3[a], &a0, &a1);
        k0[a] = (int)a0, k1[a] = (int)a1; /* (within MAX_IMAGES: small) */
      }
      for (int kz = k0[2]; kz <= k1[2]; kz++)
        for (int ky = k0[1]; ky <= k1[1]; ky++)
          for (int kx = k0[0]; kx <= k1[0]; kx++) {
            if (pass == 0) {
              cap++;
              continue;
            }
            oc_bimage *im = &(*out)[m++];
            im->c = (oc_vec3){c3[0] + kx * s, c3[1] + ky * s, c3[2] + kz * s};
            im->n = d->n;
            im->r2 = d->r * d->r;
            im->box.lo =
                (oc_vec3){im->c.x - e[0], im->c.y - e[1], im->c.z - e[2]};
            im->box.hi =
                (oc_vec3){im->c.x + e[0], im->c.y + e[1], im->c.z + e[2]};
          }
    }
    if (pass == 0) {
      *out = malloc((cap ? cap : 1) * sizeof **out);
      if (!*out) return oc_seterr(err, OC_ENOMEM, "out of memory for discs");
    }
  }
  *n = m;
  return 0;
}

int oc_bimage_cuts(const oc_bimage *d, const double *p, const double *q) {
  double a = (p[0] - d->c.x) * d->n.x + (p[1] - d->c.y) * d->n.y +
             (p[2] - d->c.z) * d->n.z;
  double b = (q[0] - d->c.x) * d->n.x + (q[1] - d->c.y) * d->n.y +
             (q[2] - d->c.z) * d->n.z;
  return oc_bimage_cuts_at(d, p, q, a, b);
}
