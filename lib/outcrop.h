/*
** outcrop.h — public C API of the outcrop engine.
**
** Everything a front end needs: node constructors, compilation of a node
** DAG into a read-only evaluation program, queries, images and slices.
** No Lua in here. All handles are opaque.
**
** Ownership, stated once for the whole header and repeated where it
** differs:
**  - Every function returning `oc_node *` returns a NEW reference that the
**    caller owns and must drop with oc_node_release(). On error it returns
**    NULL and fills `err` (which may be NULL).
**  - Operators RETAIN the children they are given; the caller keeps its own
**    references and may release them at once.
**  - oc_compile() returns a program owned by the caller (oc_program_free).
**    The program holds its own references to the nodes it was compiled
**    from; it is immutable and may be evaluated from many threads at once.
**  - oc_image_* functions returning `oc_image *` return an image owned by
**    the caller (oc_image_free).
**
** Field convention (see DESIGN.md): inside where f > T (T = threshold,
** default 0.5); primitives are f = energy * g(d / R) with Wyvill's falloff
** g(x) = (1 - x^2)^3 for x < 1, exactly 0 outside their support.
*/
#ifndef OUTCROP_H
#define OUTCROP_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define OC_VERSION "0.1.0"
#define OC_DEFAULT_THRESHOLD 0.5

/* ---- values ---------------------------------------------------------- */

typedef struct oc_vec3 {
  double x, y, z;
} oc_vec3;

/* Axis-aligned box; may have infinite coordinates (half-spaces, noise).
** An empty box has lo > hi on some axis. */
typedef struct oc_aabb {
  oc_vec3 lo, hi;
} oc_aabb;

/* ---- errors ---------------------------------------------------------- */

typedef enum oc_status {
  OC_OK = 0,
  OC_EINVAL,   /* a parameter is out of range or malformed */
  OC_ENOMEM,   /* allocation failed or the request would exhaust memory */
  OC_EIO,      /* reading or writing a file failed */
  OC_ETOODEEP, /* tree deeper than OC_MAX_DEPTH after flattening */
  OC_ECANCEL,  /* long work cancelled through its progress callback */
  OC_EUNSUPPORTED
} oc_status;

#define OC_MAX_DEPTH 512
#define OC_ERRMSG 256

/* Messages name the parameter with the same name the Lua field has, in
** single quotes, e.g. "'radius' must be > 0 (got -1)". */
typedef struct oc_error {
  oc_status code;
  char msg[OC_ERRMSG];
} oc_error;

/* ---- nodes ----------------------------------------------------------- */

typedef struct oc_node oc_node;

/* Noise parameters shared by turbulence, warp and perturb.
** t(p) = sum_{k=0..octaves-1} 2^-k n(2^k p), n in [0, 1] simplex noise.
** The node's value is offset + amplitude * t(p / wavelength). */
typedef struct oc_noise {
  double wavelength; /* > 0 */
  double amplitude;  /* any sign; for warp/perturb a length in metres */
  double offset;     /* turbulence primitive only */
  int octaves;       /* 1 .. 16 */
  uint64_t seed;
} oc_noise;

/* Primitives. `radius` of skeletal primitives and `falloff` of volumetric
** ones is the distance over which the field falls from `energy` to 0. */
oc_node *oc_point(oc_vec3 center, double radius, double energy, oc_error *err);
oc_node *oc_sphere(oc_vec3 center, double radius, double falloff, double energy,
                   oc_error *err);
oc_node *oc_box(oc_vec3 lo, oc_vec3 hi, double falloff, double energy,
                oc_error *err);
oc_node *oc_segment(oc_vec3 a, oc_vec3 b, double radius, double energy,
                    oc_error *err);
/* Polyline through `pts`, or (bezier != 0) a composite cubic Bezier whose
** control points are pts[0..3], pts[3..6], ... (n = 3k + 1). Closed when
** the last point equals the first. `pts` is copied. */
oc_node *oc_curve(const oc_vec3 *pts, size_t n, int bezier, double radius,
                  double energy, oc_error *err);
/* Solid cone: disc of `radius` at `base`, tip at `apex`. */
oc_node *oc_cone(oc_vec3 base, oc_vec3 apex, double radius, double falloff,
                 double energy, oc_error *err);
/* Half-space {(p - origin) . normal <= 0}; normal points to the outside. */
oc_node *oc_plane(oc_vec3 origin, oc_vec3 normal, double falloff, double energy,
                  oc_error *err);
/* offset + amplitude * t(p / wavelength); unbounded support. */
oc_node *oc_turbulence(const oc_noise *noise, oc_error *err);

/* Operators (retain their children). n >= 1. */
oc_node *oc_blend(oc_node *const *children, size_t n, oc_error *err);
oc_node *oc_union(oc_node *const *children, size_t n, oc_error *err);
oc_node *oc_intersection(oc_node *const *children, size_t n, oc_error *err);
/* min(fa, 2T - fb) */
oc_node *oc_difference(oc_node *a, oc_node *b, oc_error *err);
/* Cubic smooth max/min of seed 002 section 4.2 with a radius that fades
** out where both fields vanish, so compact support is kept. */
oc_node *oc_smooth_union(oc_node *a, oc_node *b, double radius, oc_error *err);
oc_node *oc_smooth_intersection(oc_node *a, oc_node *b, double radius,
                                oc_error *err);
/* factor * f (negation: factor = -1). */
oc_node *oc_scale_field(oc_node *a, double factor, oc_error *err);
/* f(p + w(p) * delta(p)), delta = amplitude * (t(p/wl) - c) per axis
** (three decorrelated noises, centred), w = clamp(control, 0, 1) or 1 when
** control is NULL. */
oc_node *oc_warp(oc_node *child, const oc_noise *noise, oc_node *control,
                 oc_error *err);
/* Affine transform. `m` is the 3x4 row-major FORWARD map from the child's
** space to world space: world = M[:, 0:3] * local + M[:, 3]. Must be
** invertible. */
oc_node *oc_transform(oc_node *child, const double m[12], oc_error *err);
/* Star-shaped anisotropic perturbation of a skeletal or volumetric
** primitive (seed 000 section 5.2): d / (R + amplitude * t(v(p)/wl)). */
oc_node *oc_perturb(oc_node *primitive, const oc_noise *noise, oc_error *err);

void oc_node_retain(oc_node *node);
void oc_node_release(oc_node *node); /* frees deep trees without recursion */

const char *oc_node_kind(const oc_node *node); /* "point", "blend", ... */
size_t oc_node_child_count(const oc_node *node);
oc_node *oc_node_child(const oc_node *node, size_t i); /* borrowed */
/* Bounds, value ranges and Lipschitz bounds depend on the threshold T
** (difference, smooth operators), so they are answered by the compiled
** program, not by the node. */

/* ---- compiled programs ----------------------------------------------- */

typedef struct oc_program oc_program;

typedef struct oc_compile_options {
  double threshold; /* T; 0 means OC_DEFAULT_THRESHOLD */
  int no_bvh;       /* 1: visit every child (brute force, for tests) */
} oc_compile_options;

/* opts may be NULL. */
oc_program *oc_compile(oc_node *root, const oc_compile_options *opts,
                       oc_error *err);
void oc_program_free(oc_program *prog);

/* Thread-safe, allocation-free. NaN in gives NaN out. */
double oc_program_eval(const oc_program *prog, oc_vec3 p);
/* Returns the value and stores the gradient in *grad. */
double oc_program_gradient(const oc_program *prog, oc_vec3 p, oc_vec3 *grad);
/* Batch evaluation over both cores (OpenMP); out[i] = f(p[i]). */
void oc_program_eval_many(const oc_program *prog, const oc_vec3 *p, double *out,
                          size_t n);

oc_aabb oc_program_bounds(const oc_program *prog);
/* Global Lipschitz bound: |f(p) - f(q)| <= L |p - q| for all p, q. */
double oc_program_lipschitz(const oc_program *prog);
double oc_program_threshold(const oc_program *prog);

typedef struct oc_program_stats {
  size_t nodes;      /* distinct nodes of the DAG */
  size_t primitives; /* distinct primitive nodes */
  size_t bytes;      /* memory of the compiled program, BVH included */
} oc_program_stats;
void oc_program_get_stats(const oc_program *prog, oc_program_stats *st);

/* Local queries, for meshing and tracing. Both are conservative: they may
** overestimate, never underestimate.
**
** Column spans: z-intervals covering every z at which the field may vary
** anywhere in the column footprint [x0, x1] x [y0, y1] (x0 <= x1,
** y0 <= y1). Between two spans the field is constant over the whole
** footprint, so no surface crosses a cell lying there. Volumetric nodes
** report their support box; heightfield-like nodes (a plane, later
** terrains) the thin z-range where they vary; operators the union of their
** children's. Writes at most `max` sorted, disjoint spans to out (merging
** the closest when there are more) and returns the count; returns -1 when
** the whole column must be considered. */
typedef struct oc_zspan {
  double lo, hi;
} oc_zspan;
int oc_program_column_spans(const oc_program *prog, double x0, double y0,
                            double x1, double y1, oc_zspan *out, int max);

/* A Lipschitz bound of the field valid inside `box` only: it counts only
** the nodes whose support meets the box (through the BVH). */
double oc_program_lipschitz_in(const oc_program *prog, oc_aabb box);

/* ---- progress and cancellation --------------------------------------- */

/* Long work calls fn from one thread with the fraction done, in [0, 1];
** a non-zero return cancels the work (OC_ECANCEL, nothing written). */
typedef struct oc_progress {
  int (*fn)(void *ud, double fraction);
  void *ud;
} oc_progress;

/* ---- meshes ------------------------------------------------------------ */

typedef struct oc_mesh oc_mesh;

typedef struct oc_polygonize_params {
  oc_aabb box;      /* region to mesh: finite, non-empty */
  double cell;      /* cell size; or 0 to use nx, ny, nz */
  int nx, ny, nz;   /* cells per axis when cell == 0 */
  double threshold; /* iso-value; 0 means the program's T */
  int open;         /* 1: no caps; the surface runs up to the box faces */
  int steps;        /* root-finding steps per edge (0: default 6) */
  int full_grid;    /* 1: ignore surface bounds (benchmarks, tests) */
  oc_progress progress;
} oc_polygonize_params;

/* Marching cubes over the box with a topologically consistent case table:
** a closed, manifold, consistently oriented mesh (outward normals), capped
** where a solid meets the box unless `open`. Returns a new mesh (caller
** frees with oc_mesh_free) or NULL with err. Byte-identical for any
** thread count. */
oc_mesh *oc_polygonize(const oc_program *prog, const oc_polygonize_params *pp,
                       oc_error *err);
void oc_mesh_free(oc_mesh *mesh);

size_t oc_mesh_vertex_count(const oc_mesh *mesh);
size_t oc_mesh_triangle_count(const oc_mesh *mesh);
const float *oc_mesh_positions(const oc_mesh *mesh);  /* 3 per vertex */
const float *oc_mesh_normals(const oc_mesh *mesh);    /* 3 per vertex, unit */
const float *oc_mesh_colors(const oc_mesh *mesh);     /* 3 per vertex or NULL */
const uint32_t *oc_mesh_indices(const oc_mesh *mesh); /* 3 per triangle, CCW
                                                      ** seen from outside */

typedef struct oc_mesh_stats {
  size_t vertices, triangles;
  size_t field_calls;   /* value and gradient evaluations */
  size_t cells_visited; /* cells whose corners were sampled */
  double seconds;
} oc_mesh_stats;
void oc_mesh_get_stats(const oc_mesh *mesh, oc_mesh_stats *st);

/* Per-vertex colours: rgb has 3 floats per vertex in [0, 1] (copied). */
int oc_mesh_set_colors(oc_mesh *mesh, const float *rgb, oc_error *err);
/* Colours from a field through a palette: `n` stops (value, r, g, b)
** sorted by value, linearly interpolated, clamped at the ends. */
int oc_mesh_color_by_field(oc_mesh *mesh, const oc_program *field,
                           const double *stops, int n, oc_error *err);

/* Writes by extension: .ply (binary little-endian: positions, normals,
** colours when set), .obj (positions, normals), .glb (glTF 2.0 binary).
** Atomic (temporary name, then rename); on error no file is left. */
int oc_mesh_write(const oc_mesh *mesh, const char *path, oc_error *err);

/* ---- images ---------------------------------------------------------- */

/* Float pixels, row 0 at the top, channels interleaved. */
typedef struct oc_image oc_image;

oc_image *oc_image_new(int width, int height, int channels, oc_error *err);
void oc_image_free(oc_image *img);
int oc_image_width(const oc_image *img);
int oc_image_height(const oc_image *img);
int oc_image_channels(const oc_image *img);
float *oc_image_data(oc_image *img);
const float *oc_image_cdata(const oc_image *img);
/* Channel names default to R, G, B, A, then "c4", "c5", ...; EXR files
** carry every channel under its name, other formats the first four. */
int oc_image_set_channel_name(oc_image *img, int channel, const char *name,
                              oc_error *err);
const char *oc_image_channel_name(const oc_image *img, int channel);
/* Adds a string attribute written as image metadata (provenance). */
int oc_image_set_meta(oc_image *img, const char *key, const char *value,
                      oc_error *err);
/* Writes through OpenImageIO; the format follows the extension (.png,
** .jpg, .tif, .exr). `bits` is 8 or 16 for PNG/TIFF (0: 8 for PNG/JPEG,
** 16 for TIFF, half for EXR). Atomic: written to a temporary name in the
** same folder and renamed; on error no file is left. */
int oc_image_write(const oc_image *img, const char *path, int bits,
                   oc_error *err);

/* ---- slices ---------------------------------------------------------- */

typedef enum oc_plane_axis {
  OC_PLANE_XY,
  OC_PLANE_XZ,
  OC_PLANE_YZ
} oc_plane_axis;

typedef struct oc_slice_params {
  oc_plane_axis plane;
  double at;             /* coordinate on the remaining axis */
  double u0, v0, u1, v1; /* window on the plane's two axes */
  int width, height;     /* pixels, each 1 .. 16384 */
} oc_slice_params;

/* 5-channel image: R, G, B, A (colour map with the T iso-line in black,
** linear values in [0, 1]) and the raw field value in channel 4, named
** "field". Pixel (i, j) samples
** u = u0 + (i + 0.5) (u1 - u0) / width, v = v1 - (j + 0.5) (v1 - v0) /
** height (v grows upwards). */
oc_image *oc_slice(const oc_program *prog, const oc_slice_params *sp,
                   oc_error *err);

/* ---- heightfields ----------------------------------------------------- */

/* A grid of float elevations: sample (i, j), 0 <= i < nx, 0 <= j < ny,
** lies at (x0 + i cell, y0 + j cell) and is stored at z[j nx + i].
** Reference counted: oc_heightfield_new returns one reference (release it
** with oc_heightfield_release); whoever keeps a grid (a terrain node)
** retains it. A grid is immutable once shared: write its samples through
** oc_heightfield_samples_mut only while you hold the only reference. */
typedef struct oc_heightfield oc_heightfield;

/* nx, ny in 2 .. 65535 and nx ny <= 2^28; cell > 0; finite origin. `z`
** (nx ny floats, all finite) is copied, or the grid starts at 0 when NULL. */
oc_heightfield *oc_heightfield_new(int nx, int ny, double cell, double x0,
                                   double y0, const float *z, oc_error *err);
void oc_heightfield_retain(oc_heightfield *hf);
void oc_heightfield_release(oc_heightfield *hf);

int oc_heightfield_nx(const oc_heightfield *hf);
int oc_heightfield_ny(const oc_heightfield *hf);
double oc_heightfield_cell(const oc_heightfield *hf);
void oc_heightfield_origin(const oc_heightfield *hf, double *x0, double *y0);
const float *oc_heightfield_samples(const oc_heightfield *hf);
float *oc_heightfield_samples_mut(oc_heightfield *hf);
/* Smallest and largest sample (recomputed on each call). */
void oc_heightfield_minmax(const oc_heightfield *hf, double *lo, double *hi);

/* C1 interpolation (bicubic Catmull-Rom: it passes through the samples)
** and its analytic gradient, stored in grad[0..1] when grad is not NULL.
** Outside the grid the position is clamped to it. Thread-safe. Between
** samples the value may leave the range of the 4 x 4 samples around by
** at most OC_HF_OVERSHOOT times their spread. */
#define OC_HF_OVERSHOOT 0.28125
double oc_heightfield_height(const oc_heightfield *hf, double x, double y,
                             double grad[2]);

#ifdef __cplusplus
}
#endif
#endif
