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
/* Cubic smooth max/min of Paris et al. 2020, section 4.2 with a radius that
** fades
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

/* Building such maps (core/xform.c), as the Lua front end does: */
void oc_xform_identity(double m[12]);
/* out = a * b (b applied first); out may be a or b. */
void oc_xform_mul(const double a[12], const double b[12], double out[12]);
/* Rotation by `degrees` about `axis` (normalised here; right-handed).
** OC_EINVAL naming 'rotate.axis' for a zero or non-finite axis. */
int oc_xform_axis_angle(oc_vec3 axis, double degrees, double m[12],
                        oc_error *err);
/* Euler angles in degrees applied about X, then Y, then Z: Rz Ry Rx. */
int oc_xform_euler(oc_vec3 degrees, double m[12], oc_error *err);
/* M = T * R * S: scale (non-zero factors, else OC_EINVAL naming 'scale'),
** then the rotation `rotate` (NULL: none), then the translation. */
int oc_xform_compose(oc_vec3 translate, const double rotate[12], oc_vec3 scale,
                     double m[12], oc_error *err);
/* Star-shaped anisotropic perturbation of a skeletal or volumetric
** primitive (Paris et al. 2019, section 5.2): d / (R + amplitude *
** t(v(p)/wl)). */
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
  oc_aabb box;      /* region to mesh: finite, non-empty (see
                    ** oc_polygonize_default_box) */
  double cell;      /* cell size; or 0 to use nx, ny, nz */
  int nx, ny, nz;   /* cells per axis when cell == 0; all 0 (with cell 0):
                    ** oc_polygonize_default_cell(box) */
  double threshold; /* iso-value; 0 means the program's T */
  int open;         /* 1: no caps; the surface runs up to the box faces */
  int steps;        /* root-finding steps per edge (0: default 6) */
  int full_grid;    /* 1: ignore surface bounds (benchmarks, tests) */
  int no_direct;    /* 1: no direct elevation extraction: root finding on
                    ** the field even where one terrain or plane alone
                    ** governs a column (benchmarks, tests) */
  /* refuse when the projected mesh has more triangles (an estimate from
  ** probes through the box, made before meshing); 0: the default,
  ** OC_POLYGONIZE_MAX_TRIANGLES */
  size_t max_triangles;
  /* drop the connected components of fewer vertices than this (loose
  ** specks); 0 or 1 keep every component (the default) */
  size_t min_component;
  oc_progress progress;
  /* NULL, or where a warning goes (a sentence, "" when none) when the
  ** mesh comes out empty for a reason the engine can tell, such as a
  ** terrain whose solid is thinner than a cell */
  char *warning;
  size_t warning_size;
} oc_polygonize_params;
/* 2^27 triangles: about 3 GiB of mesh (positions, normals, indices). */
#define OC_POLYGONIZE_MAX_TRIANGLES ((size_t)1 << 27)

/* Marching cubes over the box with a topologically consistent case table:
** a closed, manifold, consistently oriented mesh (outward normals), capped
** where a solid meets the box unless `open`. Returns a new mesh (caller
** frees with oc_mesh_free) or NULL with err. Byte-identical for any
** thread count. */
oc_mesh *oc_polygonize(const oc_program *prog, const oc_polygonize_params *pp,
                       oc_error *err);

/* The defaults every front end takes (mesh/polygonize.c). The box: prog's
** bounds, OC_EINVAL when they are empty (the field is 0 everywhere) or
** infinite (*box then unchanged). The cell: cubic, 1 /
** OC_POLYGONIZE_DEFAULT_RESOLUTION of the box's longest side. */
#define OC_POLYGONIZE_DEFAULT_RESOLUTION 64
int oc_polygonize_default_box(const oc_program *prog, oc_aabb *box,
                              oc_error *err);
double oc_polygonize_default_cell(oc_aabb box);
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

/* Per-vertex colours, linear: rgb has 3 floats per vertex in [0, 1]
** (copied). */
int oc_mesh_set_colors(oc_mesh *mesh, const float *rgb, oc_error *err);
/* Colours from a field through a palette: `n` stops (value, r, g, b)
** sorted by value, linearly interpolated, clamped at the ends. */
int oc_mesh_color_by_field(oc_mesh *mesh, const oc_program *field,
                           const double *stops, int n, oc_error *err);
/* Colours blended by n weight programs, as a render's OC_COLOR_BLEND
** (oc_render_params) with the vertex normals: texture amplitude in
** [0, 1], texture_scale > 0 metres a period. Parallel, independent of
** the thread count. */
int oc_mesh_color_by_blend(oc_mesh *mesh, const oc_program *const *fields,
                           const double *colors, int n, double texture,
                           double texture_scale, oc_error *err);

/* Connected components (triangles joined by shared edges and vertices):
** (*sizes)[i] is the vertex count of component i, components numbered in
** order of their lowest vertex index; a vertex no triangle uses is a
** component of its own. *sizes is malloc'ed (free it), NULL when the mesh
** has no vertices. */
int oc_mesh_components(const oc_mesh *mesh, size_t **sizes, size_t *count,
                       oc_error *err);
/* Removes every component of fewer than min_vertices vertices (0 or 1:
** nothing). Kept vertices and triangles keep their order and are
** re-indexed; whole components go, so a closed manifold mesh stays so. */
int oc_mesh_drop_components(oc_mesh *mesh, size_t min_vertices, oc_error *err);

/* Metadata (provenance) carried by every later write: a PLY "comment
** key=value" line and an OBJ "# key=value" line each (values quoted as
** oc_meta_quote does, so no value can break or forge a line), and a
** string member of the glTF asset.extras object. Keys: 1..64 letters,
** digits, '_', '.', ':', '-', starting with a letter, compared exactly;
** setting a key again replaces its value. Values up to 65535 bytes; at
** most 64 keys. */
int oc_mesh_set_meta(oc_mesh *mesh, const char *key, const char *value,
                     oc_error *err);
size_t oc_mesh_meta_count(const oc_mesh *mesh);
const char *oc_mesh_meta_key(const oc_mesh *mesh, size_t i);   /* or NULL */
const char *oc_mesh_meta_value(const oc_mesh *mesh, size_t i); /* or NULL */

/* Writes by extension: .ply (binary little-endian: positions, normals,
** colours when set), .obj (positions, normals), .glb (glTF 2.0 binary).
** Colours are linear: PLY stores them sRGB-encoded as bytes, GLB as
** linear COLOR_0 floats with a default material that shows them. PLY and
** OBJ keep the engine's Z-up axes; GLB is Y-up as glTF requires: engine
** (x, y, z) is written as glTF (x, z, -y), positions and normals (a
** rotation, so triangles stay counter-clockwise seen from outside).
** Atomic (temporary name, then rename); on error no file is left. */
int oc_mesh_write(const oc_mesh *mesh, const char *path, oc_error *err);
/* The same, with `path` relative to the directory descriptor `dirfd`
** (AT_FDCWD: the current folder), so a folder resolved once is written
** without its path being looked up again. The temporary file is created
** and renamed in path's parent; every write, the flush, fsync and close
** are checked, and a failure ("cannot write 'path': No space left on
** device") leaves neither the file nor a temporary. The same holds for
** oc_image_write_at and oc_heightfield_save_at. */
int oc_mesh_write_at(const oc_mesh *mesh, int dirfd, const char *path,
                     oc_error *err);

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
/* Read access to an image's metadata (in the order set; keys compare
** without case): the count, the i-th key and value (NULL past the end),
** and the value of `key` (NULL when absent). The strings are the image's. */
size_t oc_image_meta_count(const oc_image *img);
const char *oc_image_meta_key(const oc_image *img, size_t i);
const char *oc_image_meta_value(const oc_image *img, size_t i);
const char *oc_image_meta_get(const oc_image *img, const char *key);
/* Writes through OpenImageIO; the format follows the extension (.png,
** .jpg, .tif, .exr). `bits` is 8 or 16 for PNG/TIFF (0: 8 for PNG/JPEG,
** 16 for TIFF, half for EXR). Atomic: written to a temporary name in the
** same folder and renamed; on error no file is left. Values are written
** as given (clamped to [0, 1] for integer formats), except in an image
** with the metadata outcrop:colorspace=linear (renders): there the colour
** channels are sRGB-encoded for integer formats, and files are tagged
** with their colour space (sRGB, or Linear for float formats). */
int oc_image_write(const oc_image *img, const char *path, int bits,
                   oc_error *err);
/* oc_image_write relative to a directory descriptor (see
** oc_mesh_write_at). */
int oc_image_write_at(const oc_image *img, int dirfd, const char *path,
                      int bits, oc_error *err);

/* ---- palettes ------------------------------------------------------- */

/* Colour maps (core/palette.c): n stops of 4 doubles (value, r, g, b)
** sorted by value, linear between neighbours, the end colours beyond them.
** Meshes, renders, slices and heightfield images colour values through
** them. */

/* OC_OK when n >= 1 stops have finite, ascending values and colour
** components in [0, 1]; else OC_EINVAL naming 'stops'. */
int oc_palette_check(const double *stops, int n, oc_error *err);
/* The colour of v. Where stops share a value the colour steps (the later
** stop wins from that value on). NaN takes the first stop's colour. */
void oc_palette_eval(const double *stops, int n, double v, double rgb[3]);
/* Built-in palettes, static (never freed), their stop count in *n:
** - strata: soft sandstone to hard limestone for a resistance in [0, 1],
**   linear albedos about as bright as the render rules' rock (the
**   default of a render coloured by a node);
** - resistance: dark for soft rock to pale for hard (Paris et al. 2019,
**   figure 4; the default of a geology slice). */
const double *oc_palette_strata(int *n);
const double *oc_palette_resistance(int *n);

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
  int width, height;     /* pixels, each 1 .. 16384, 2^25 in all */
} oc_slice_params;

/* 5-channel image: R, G, B, A (colour map with the T iso-line in black,
** linear values in [0, 1]) and the raw field value in channel 4, named
** "field". Pixel (i, j) samples
** u = u0 + (i + 0.5) (u1 - u0) / width, v = v1 - (j + 0.5) (v1 - v0) /
** height (v grows upwards). */
oc_image *oc_slice(const oc_program *prog, const oc_slice_params *sp,
                   oc_error *err);

/* The window a slice takes when none is given (render/slice.c): the
** program's bounds on sp->plane's two axes (x, y for "xy", x, z for "xz",
** y, z for "yz") into u0, v0, u1, v1. OC_EINVAL when they are infinite
** (they may be empty: oc_slice refuses those); sp is then unchanged. */
int oc_slice_default_window(const oc_program *prog, oc_slice_params *sp,
                            oc_error *err);

/* Recolours a slice image (made by oc_slice) through a palette: R, G, B
** from the value in its "field" channel (oc_palette_eval), A = 1; the
** iso-line is not drawn. The "field" channel is kept. */
int oc_slice_apply_palette(oc_image *img, const double *stops, int n,
                           oc_error *err);

/* ---- rendering --------------------------------------------------------- */

/* Images of a field by sphere tracing the surface f = T, no mesh.
** Colours are LINEAR RGB (the writers encode sRGB for 8/16-bit files, see
** oc_image_write). Two ways to call it:
**  - oc_render(): trace, colour and shade in one call;
**  - oc_render_geometry(), then oc_render_shade(): for a caller that
**    computes the albedo of each pixel itself (serially, e.g. a Lua
**    function) from the hit positions and normals of the first call. */

typedef struct oc_camera {
  oc_vec3 eye, target; /* distinct points */
  oc_vec3 up;          /* not parallel to target - eye */
  double fov;          /* vertical field of view, degrees, in (0, 179] */
} oc_camera;

typedef enum oc_render_tracer {
  OC_TRACE_SEGMENT = 0, /* local directional bounds along the ray segment,
                        ** growing candidate step, empty-space skipping */
  OC_TRACE_SPHERE       /* plain sphere tracing: one global Lipschitz
                        ** bound, the ray clipped to the scene's box only */
} oc_render_tracer;

typedef enum oc_render_color {
  OC_COLOR_RULES = 0, /* rock, grass, snow, sand by altitude and slope */
  OC_COLOR_FIELD,     /* a program (e.g. geology) through a palette */
  OC_COLOR_BLEND      /* colours blended by weight programs (materials) */
} oc_render_color;

/* How linear colours become display values in 8/16-bit files (see
** oc_render_shade). */
typedef enum oc_render_tone {
  OC_TONE_CLAMP = 0, /* clamp to [0, 1]: values over 1 are white */
  OC_TONE_FILMIC     /* the ACES fit of Narkowicz (2015):
                     ** x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14) */
} oc_render_tone;

/* Rule palette. Slopes are in degrees from the horizontal. When `levels`
** is 0, sea_level and snow_line are derived from the altitudes of the
** visible surface (z0 = lowest hit, z1 = highest): sea_level = z0 +
** 0.04 (z1 - z0), snow_line = z0 + 0.75 (z1 - z0); when it is 1, each
** level is used as given, except a NaN one, which is derived so. */
typedef struct oc_render_rules {
  int levels;        /* 1: use sea_level and snow_line as given */
  double sea_level;  /* sand below sea_level + beach */
  double snow_line;  /* snow above it where the slope < snow_slope */
  double beach;      /* metres; 0 allowed; default 1.5% of (z1 - z0) when
                     ** levels is 0 */
  double rock_slope; /* steeper: bare rock (default 38) */
  double snow_slope; /* steeper: no snow (default 45) */
} oc_render_rules;

typedef struct oc_render_params {
  oc_camera camera;
  int width, height; /* 1 .. 16384 each, width height <= 2^25 */

  oc_vec3 sun_direction; /* towards the sun (normalised here) */
  double sun_color[3];   /* linear RGB, >= 0 */
  double sun_intensity;  /* >= 0 */
  double sun_radius;     /* the sun's angular radius, radians in [0, 0.1]
                         ** (0.00465): under a level-of-detail source
                         ** (oc_elevation's coarser) a shadow ray's cone,
                         ** at least a pixel's, widens by it, and detail
                         ** finer than the cone is dropped */
  double sky[3];         /* linear RGB of the sky: ambient and misses */
  int shadows;           /* 1: shadow rays towards the sun */
  int ao;                /* 1: ambient occlusion */
  double ao_distance;    /* metres between AO samples; 0: auto */
  double fog_density;    /* per metre, >= 0 (0: none); transmittance
                         ** exp(-fog_density * distance) */
  double fog_color[3];   /* linear RGB */
  int has_background;    /* 1: misses get `background`, else the sky */
  double background[4];  /* linear RGBA, alpha included */
  double texture;        /* triplanar colour variation, 0 .. 1 */
  double texture_scale;  /* metres per texture period; 0: auto */

  oc_render_color color;         /* colour source when no albedo is given */
  oc_render_rules rules;         /* OC_COLOR_RULES */
  const oc_program *color_field; /* OC_COLOR_FIELD: evaluated at hits */
  const double *stops;           /* OC_COLOR_FIELD: n stops (value, r, g, b),
                                 ** values ascending, components in [0, 1] */
  int nstops;                    /* 1 .. 256 */
  /* OC_COLOR_BLEND (texturing by material, Peytavie et al. 2009 section
  ** 6): nblend (1 .. 16) weight programs and colours (r, g, b in [0, 1]);
  ** the albedo at p is sum w_i c_i k_i / sum w_i, w_i = max(f_i(p), 0)
  ** (for material stacks, each material's convolution surface: its share
  ** of the box around p), k_i the gain of material i's own triplanar
  ** texture (weights |n_x|^8, |n_y|^8, |n_z|^8 for the planes orthogonal
  ** to x, y, z; amplitude `texture`); c_0 where every weight is 0. */
  const oc_program *const *blend_fields;
  const double *blend_colors;
  int nblend;

  double threshold;        /* iso-value; 0 means the program's T */
  double max_distance;     /* farthest hit, metres; 0: auto (the scene's
                           ** box, or 1000 |target - eye| when unbounded) */
  oc_render_tracer tracer; /* OC_TRACE_SEGMENT by default */
  int aov;                 /* 1 (default): add the AOV channels (see
                           ** oc_render_shade); 0: R, G, B, A only */
  double exposure;         /* stops (EV) in [-20, 20]: colours are
                           ** multiplied by 2^exposure (default 0) */
  oc_render_tone tone;     /* OC_TONE_CLAMP by default */
  oc_progress progress;
  /* NULL (default), or where a warning goes (a sentence, "" when none)
  ** when the image shows a terrain badly for a reason the engine can
  ** tell: rays reached the scene's box and a terrain's solid is thinner
  ** than their hit tolerance (at the box's nearest point; at its far end
  ** when nothing was hit), so that it shows as scattered pixels or not at
  ** all */
  char *warning;
  size_t warning_size;
} oc_render_params;

/* Fills `rp` with the defaults: a 640 x 360 view of nothing in particular
** (set the camera), sun from (-0.5, -0.4, 0.77) colour (1, 0.95, 0.86)
** intensity 2.2 angular radius 0.00465, sky (0.45, 0.6, 0.85), shadows
** and AO on, no fog (fog colour = sky), no background (sky), texture
** 0.3, rule colours with derived levels, segment tracer, AOV channels
** on, exposure 0, tone OC_TONE_CLAMP; camera up (0, 0, 1), fov 40
** degrees (vertical). */
void oc_render_defaults(oc_render_params *rp);

/* The default framing (render/framing.c), the one the Lua front end uses:
** where has_target is 0 the target becomes the centre of prog's bounds;
** where has_eye is 0 the eye looks at the target from the south-west
** (azimuth -135 degrees), 30 degrees above the horizon, along
** rp->camera.up, just far enough (4 % margin, never inside the bounds'
** sphere) for the eight corners of the bounds to fall inside the view of
** rp->camera.fov at rp->width x rp->height. Both given: nothing changes.
** OC_EINVAL when the bounds are empty or infinite, or camera.up is
** parallel to the view; rp is then unchanged. */
int oc_render_default_camera(const oc_program *prog, oc_render_params *rp,
                             int has_eye, int has_target, oc_error *err);
/* The same framing for any bounds b (an elevation surface's: its domain x
** its elevation range). */
int oc_render_frame_box(oc_aabb b, oc_render_params *rp, int has_eye,
                        int has_target, oc_error *err);
/* Every check oc_render makes of prog and rp before it traces anything
** (the messages name the Lua table fields): for a caller that does work
** of its own between oc_render_geometry and oc_render_shade. */
int oc_render_check(const oc_program *prog, const oc_render_params *rp,
                    oc_error *err);

/* Channels of a geometry image (OC_RG_COUNT floats per pixel). */
enum {
  OC_RG_HIT = 0, /* 1 on a surface hit, 0 on a miss */
  OC_RG_Z,       /* ray distance from the eye; +inf on a miss */
  OC_RG_NX,      /* unit normal (from the gradient, outwards) x, y, z */
  OC_RG_PX = OC_RG_NX + 3,    /* world position of the hit x, y, z */
  OC_RG_EVALS = OC_RG_PX + 3, /* field evaluations of the primary ray (its
                              ** steps, + 1 for the normal on a hit) */
  OC_RG_COUNT
};

/* Traces one primary ray per pixel (through the pixel's centre) and
** returns an image of OC_RG_COUNT channels named "hit", "Z", "N.x",
** "N.y", "N.z", "P.x", "P.y", "P.z", "evals"; on a miss N and P are 0.
** Only the camera, size, threshold, max_distance, tracer, progress and
** warning of `rp` are used. NULL with err: OC_EINVAL (naming the parameter),
** OC_ENOMEM (sizes checked before allocating), OC_ECANCEL. */
oc_image *oc_render_geometry(const oc_program *prog, const oc_render_params *rp,
                             oc_error *err);

/* Shades a geometry image made by oc_render_geometry with the same
** program and parameters. `albedo` (3 linear floats per pixel, row 0 at
** the top, read on hit pixels only) replaces the colour source when not
** NULL. Returns the final image: R, G, B, A, and when rp->aov also "Z",
** "N.x", "N.y", "N.z", "P.x", "P.y", "P.z", "evals" (evals includes the
** shadow, AO and colour evaluations). A is 1 on hits, the background's
** alpha (1 for the sky) on misses. R, G, B are linear and multiplied by
** 2^rp->exposure (sky and background included). The image carries the
** metadata outcrop:colorspace=linear, which makes oc_image_write encode
** its colour channels as sRGB in 8/16-bit files (EXR and float TIFF keep
** the linear values), and with OC_TONE_FILMIC outcrop:tone=filmic, which
** makes it pass them through the filmic curve before the sRGB encoding
** (again integer files only). */
oc_image *oc_render_shade(const oc_program *prog, const oc_render_params *rp,
                          const oc_image *geometry, const float *albedo,
                          oc_error *err);

/* oc_render_geometry then oc_render_shade; one progress range. */
oc_image *oc_render(const oc_program *prog, const oc_render_params *rp,
                    oc_error *err);

/* ---- sampling (gen/poisson.c) -------------------------------------- */

/* A set of points, `dim` coordinates each, stored one after the other
** (x0, y0[, z0], x1, ...). Made by the samplers below; the caller frees it
** with oc_samples_free. */
typedef struct oc_samples oc_samples;

/* Cap on the number of samples a request may need, checked before
** anything is allocated against an upper bound of the count (the box
** grown by r/2 on each side, over the area of a disk of radius r/2; a
** maximal set holds about 55 % of that bound in 2D, 38 % in 3D). */
#define OC_POISSON_MAX 50000000

typedef struct oc_poisson_params {
  oc_aabb box;   /* finite, non-empty; poisson2d ignores z */
  double radius; /* > 0: no two samples closer than this */
  uint64_t seed;
  /* 2D only, optional (NULL: keep all): the probability of keeping the
  ** sample at (x, y), in [0, 1]. Called from the calling thread, once per
  ** sample of the maximal set, in the order of the result. Anything
  ** outside [0, 1] (NaN to abort) fails with OC_EINVAL. */
  double (*density)(void *ud, double x, double y);
  void *density_ud;
  oc_progress progress;
  /* 1: sample the torus made of the box by identifying opposite faces
  ** (distances are periodic; the box must be a square in 2D, a cube in 3D,
  ** with its side larger than 2 radius). Samples lie in [lo, hi) on each
  ** axis; the set is maximal on the torus, so copies of it tile space. */
  int periodic;
} oc_poisson_params;

/* Maximal Poisson disk (2D) or sphere (3D) sampling of the closed box: no
** two samples closer than `radius`, and no point of the box farther than
** `radius` (up to a relative 1e-10) from every sample, so no room is left
** for another. Darts are thrown uniformly over the uncovered area (the
** distribution of a dart thrower run to the end), then the last gaps are
** found exactly and filled. With `density`, each sample of that maximal set
** is then kept with the probability it gives, drawn from a stream keyed by
** the seed and the sample's grid cell: the result is still at least
** `radius` apart, and a higher density keeps a superset. Samples come in
** the order of the cells of a grid (x fastest). Deterministic: the same
** bytes for the same parameters and any thread count. Returns a new set or
** NULL with err (OC_EINVAL, OC_ENOMEM, OC_ECANCEL). */
oc_samples *oc_poisson2d(const oc_poisson_params *pp, oc_error *err);
oc_samples *oc_poisson3d(const oc_poisson_params *pp, oc_error *err);
void oc_samples_free(oc_samples *s);
size_t oc_samples_count(const oc_samples *s);
int oc_samples_dim(const oc_samples *s);
const double *oc_samples_data(const oc_samples *s);

/* ---- rock blocks (blocks/, Paris et al. 2020) ------------------------- */

/* A fracture tile: a periodic cube of side s cut into convex blocks
** (section 4.1). Made by oc_btile_new, freed with oc_btile_free; nodes made
** from it hold their own copies of what they need. */
typedef struct oc_btile oc_btile;

/* The block types of Table 1: how fracture discs are distributed. */
typedef enum oc_block_type {
  OC_BLOCKS_EQUIDIMENSIONAL, /* three axis-aligned sets */
  OC_BLOCKS_RHOMBOHEDRAL,    /* three mutually oblique sets */
  OC_BLOCKS_POLYHEDRAL,      /* random normals, more discs */
  OC_BLOCKS_TABULAR,         /* bedding discs of radius s, rare small cross
                             ** discs of radius s / 10 */
  /* extensions (not in Table 1): */
  OC_BLOCKS_PRISMATIC, /* axis-aligned sets tilted up to 20 degrees */
  OC_BLOCKS_COLUMNAR,  /* three vertical sets 60 degrees apart, sparse
                       ** horizontal joints */
  OC_BLOCKS_NTYPES
} oc_block_type;
/* The four types of Table 1 are the first OC_BLOCKS_TABLE1. */
#define OC_BLOCKS_TABLE1 4

/* A user-placed fracture disc. */
typedef struct oc_block_disc {
  oc_vec3 center, normal; /* normal: any non-zero length */
  double radius;
} oc_block_disc;

/* An authored block: the convex hull of `points` (3 doubles each, at
** least 4 not coplanar), or, when npoints is 0, the intersection of the
** half-spaces n . p + d <= 0 of `planes` (4 doubles each, bounded). Tile
** points inside it are removed, edges across its boundary cut, generated
** blocks reaching into it cut back by its faces, and it becomes a block
** of the tile itself (the last ones, in order). */
typedef struct oc_block_shape {
  const double *points;
  size_t npoints;
  const double *planes;
  size_t nplanes;
} oc_block_shape;

typedef struct oc_btile_params {
  oc_block_type type;
  double size;      /* s: side of the tile (m), default 20 */
  double radius;    /* r: Poisson radius of the points, default 0.75 */
  double neighbour; /* k: edges join points closer than k r, default 2 */
  size_t fractures; /* #D discs thrown (Table 1's defaults), >= 1 */
  double spacing;   /* minimum distance of disc centres (2; 1 polyhedral) */
  double disc_lo, disc_hi; /* disc radii (equidimensional 7 .. 11,
                           ** rhombohedral 4 .. 6, polyhedral 2.5 .. 3.5;
                           ** tabular: s and s / 10) */
  double rounding;         /* R of the smooth intersection, default 0.25 */
  double width;            /* W: blocks' fields fall to 0 W outside, 0.75
                           ** (>= 1.5 T keeps the Lipschitz bound 1) */
  uint64_t seed;
  const oc_block_disc *discs; /* user discs, added to the thrown ones */
  size_t ndiscs;
  const oc_block_shape *blocks; /* authored blocks (borrowed, copied) */
  size_t nblocks;
} oc_btile_params;

/* The defaults of type `type` (Table 1) into *pp. */
void oc_btile_defaults(oc_block_type type, oc_btile_params *pp);
/* The name of a type ("equidimensional", ...), or NULL; and its number by
** name (-1 when unknown). */
const char *oc_block_type_name(oc_block_type type);
int oc_block_type_find(const char *name);

/* Builds a tile. NULL with err: OC_EINVAL naming the parameter ('radius'
** too large for 'size', 'fractures' 0, a zero 'normal'...), OC_ENOMEM
** (sizes checked before allocating). Deterministic by seed. */
oc_btile *oc_btile_new(const oc_btile_params *pp, oc_error *err);
void oc_btile_free(oc_btile *t);

typedef struct oc_btile_stats {
  size_t points, fractures, blocks, edges, cut, thick;
  size_t separated;        /* pairs of overlapping hulls cut apart */
  size_t merged;           /* clusters of < 8 points merged into another */
  size_t authored;         /* authored blocks (the last ones) */
  double points_per_block; /* mean points of a block */
  double seconds;          /* wall time of oc_btile_new */
} oc_btile_stats;
void oc_btile_stats_get(const oc_btile *t, oc_btile_stats *st);

/* Block i (0 <= i < blocks) as a node: the smooth intersection of its hull's
** half-spaces (distance d <= 0 inside), made a field f = sigma(-d) with the
** terrain's cubic sigma of width W, so f = T on the rounded hull and f = 0
** beyond W outside it. OC_EINVAL for i out of range. */
oc_node *oc_btile_block(const oc_btile *t, size_t i, oc_error *err);
/* The union of all the tile's blocks (each at the place of its centroid's
** cell: blocks straddling the tile's faces stick out of it). */
oc_node *oc_btile_node(const oc_btile *t, oc_error *err);
/* Block i's hull: its planes (n.x, n.y, n.z, offset: n . p + offset <= 0
** inside) and vertices; counts in *nplane, *nvert. NULL for i out of range. */
const double *oc_btile_planes(const oc_btile *t, size_t i, size_t *nplane);
const double *oc_btile_vertices(const oc_btile *t, size_t i, size_t *nvert);

/* Block i as a mesh: its field (oc_btile_block) compiled at threshold T
** (0: the default) and polygonized with cubic cells of `cell` over its
** support, where the tile has it (at its centroid's cell: move a copy by
** size (i, j, k) for cell (i, j, k)). Closed and convex up to the
** polygonizer's error. A new mesh, or NULL with err (OC_EINVAL for i out
** of range or a bad cell, the polygonizer's errors). */
oc_mesh *oc_btile_mesh(const oc_btile *t, size_t i, double cell, double T,
                       oc_progress progress, oc_error *err);

/* Saves the tile (its parameters, points, discs, blocks and statistics)
** to a versioned binary file, atomically: whole or absent (OC_EIO naming
** the path). _at: path relative to the folder descriptor dirfd. */
int oc_btile_save(const oc_btile *t, const char *path, oc_error *err);
int oc_btile_save_at(const oc_btile *t, int dirfd, const char *path,
                     oc_error *err);
/* A tile saved by oc_btile_save (free with oc_btile_free): its blocks are
** the saved ones bit for bit. NULL with err: OC_EIO naming an unreadable
** path, OC_EINVAL saying what is wrong with a file that is not a tile, of
** another version, damaged (checksum) or crafted (every count and number
** is checked before use), OC_ENOMEM. */
oc_btile *oc_btile_load(const char *path, oc_error *err);

/* Replication (Paris et al. 2020, section 5): a tile's blocks placed over
** a terrain where they are present. */
typedef struct oc_replicate_tile {
  const oc_btile *tile; /* borrowed: the node copies what it needs */
  double lo, hi;        /* resistance range where the tile applies (with a
                        ** geology; ignored without) */
} oc_replicate_tile;

typedef struct oc_replicate_params {
  const oc_replicate_tile *tiles; /* 1 .. 7 */
  size_t ntiles;
  oc_node *geology; /* resistance node, or NULL */
  double slope;     /* present only where |g . z| < slope (default 1) */
  double va, vb;    /* distance estimate (f - T) / |grad f| (> 0 inside)
                    ** in [va, vb] (default -1 .. 1) */
  int anchors;      /* centroid + hull vertices voting (default 9) */
  double inset;     /* >= 0: the terrain sinks by about this many metres
                    ** where blocks are (f - inset L min(1, t / T), L its
                    ** Lipschitz bound, t the blocks), so the wall does
                    ** not fill the joints; default 0 (the paper's) */
  double threshold; /* T of the criteria; 0: OC_DEFAULT_THRESHOLD */
  /* Optional (NULL: unused): present(ctx, anchor) decides each anchor's
  ** vote instead of the criteria above (called from the calling thread),
  ** and blocks are placed where their supports meet *where (instead of
  ** the terrain's bounds). */
  int (*present)(void *ctx, oc_vec3 anchor);
  void *ctx;
  const oc_aabb *where;
} oc_replicate_params;

void oc_replicate_defaults(oc_replicate_params *rp);
/* f~ = max(f, t), t the present blocks (decided here, by a majority of
** each block's anchors). The terrain's bounds must be finite. A new node
** retaining terrain, or NULL with err (OC_EINVAL naming the parameter). */
oc_node *oc_blocks_replicate(oc_node *terrain, const oc_replicate_params *rp,
                             oc_error *err);
/* 1 and the count of instances (Table 2's #R) when n is a replication
** node, else 0. */
int oc_blocks_instances(const oc_node *n, size_t *count);
/* Instance i (0 <= i < count) of a replication node: its block (numbered
** through the tiles in order) and its offset (the block's field is
** evaluated at p - off). 1, or 0 when n is not a replication node or i is
** out of range. */
int oc_blocks_instance(const oc_node *n, size_t i, size_t *block,
                       double off[3]);
/* 1 and the bytes a replication node holds (Table 2's memory: the
** blocks' fields, the instances and their grid), else 0. */
int oc_blocks_memory(const oc_node *n, size_t *bytes);

/* Gradient-based warping (Paris et al. 2020, section 4.2), a node over any
** field: f(p + u(p) s(p)), u the direction of the field's gradient (a
** tetrahedral difference of step `step`, fading to 0 where the field is
** less than half as steep as its Lipschitz bound), s the relief d on the
** planes xy, xz, yz weighted by |u.z|, |u.y|, |u.x| (normalised to sum
** 1), d in [-|amplitude|, |amplitude|] metres at world coordinates (d > 0
** moves the surface outwards). Lipschitz bound: L (1 + L_d + 2 (1 + 2
** sqrt 3) |amplitude| / step), L the field's, L_d the relief's
** (lib/blocks/relief.c derives it). */
typedef enum oc_relief_kind {
  OC_RELIEF_TURBULENCE, /* d = A (2 t(x / wavelength) / t_max - 1) */
  OC_RELIEF_IMAGE       /* d = A (2 v - 1), v the image's first channel
                        ** clamped to [0, 1], bilinear, repeated every
                        ** `wavelength` metres along the image's width */
} oc_relief_kind;

typedef struct oc_relief_params {
  oc_relief_kind kind;
  double wavelength; /* > 0 (default 1) */
  int octaves;       /* turbulence: 1 .. 16 (default 4) */
  uint64_t seed;     /* turbulence (default 1) */
  const char *path;  /* image: PNG, TIFF, EXR or JPEG (read now) */
  double amplitude;  /* A, metres, finite */
  double step;       /* the gradient's step; 0: 4 |A| (0.01 for A = 0) */
} oc_relief_params;

void oc_relief_defaults(oc_relief_params *rp);
/* A new node retaining child, or NULL with err (OC_EINVAL naming the
** parameter, OC_EIO naming an unreadable image). */
oc_node *oc_relief_warp(oc_node *child, const oc_relief_params *rp,
                        oc_error *err);

/* ---- heightfields ----------------------------------------------------- */

/* A grid of float elevations: sample (i, j), 0 <= i < nx, 0 <= j < ny,
** lies at (x0 + i cell, y0 + j cell) and is stored at z[j nx + i].
** Reference counted: oc_heightfield_new returns one reference (release it
** with oc_heightfield_release); whoever keeps a grid (a terrain node)
** retains it. A grid is immutable once shared: write its samples through
** oc_heightfield_samples_mut only while you hold the only reference. */
typedef struct oc_heightfield oc_heightfield;

/* Samples of a grid at most (1 GiB of floats). */
#define OC_HEIGHTFIELD_MAX_SAMPLES (1ull << 28)

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
** at most OC_HEIGHTFIELD_OVERSHOOT times their spread. */
#define OC_HEIGHTFIELD_OVERSHOOT 0.28125
double oc_heightfield_height(const oc_heightfield *hf, double x, double y,
                             double grad[2]);

/* -- heightfield files (terrain/hf_io.c) -- */

/* The fields of oc_heightfield_load_params the caller gives; the others
** come from the file's metadata (outcrop:cell, outcrop:x0, outcrop:y0,
** outcrop:scale, outcrop:offset, as oc_heightfield_save writes them),
** else default to cell 1, scale 1, offset 0, origin (0, 0). */
enum {
  OC_HEIGHTFIELD_GIVE_CELL = 1,
  OC_HEIGHTFIELD_GIVE_SCALE = 2,
  OC_HEIGHTFIELD_GIVE_OFFSET = 4,
  OC_HEIGHTFIELD_GIVE_ORIGIN = 8
};

typedef struct oc_heightfield_load_params {
  unsigned given;       /* OC_HEIGHTFIELD_GIVE_* bits */
  double cell;          /* > 0 */
  double scale, offset; /* elevation = stored value * scale + offset */
  double x0, y0;        /* position of sample (0, 0) */
  oc_progress progress; /* polled while reading; may be {NULL, NULL} */
} oc_heightfield_load_params;

/* Reads the first channel of an image file into a new grid. The format
** (PNG, TIFF, EXR or JPEG) is told by the file's signature, not its name;
** only regular files are read (FIFOs, devices and folders are refused
** without blocking). Integer samples are raw counts (0..255 for 8 bits,
** 0..65535 for 16 bits: not normalized, so `scale` is metres per count);
** half and float samples are taken as stored. North up: the image's top
** row is the grid's last row (j = ny - 1), its left column i = 0. p may
** be NULL. On error NULL and `err`: OC_EIO naming the path for
** unreadable, corrupt or unrecognised files, OC_EINVAL for an image
** under 2 x 2 pixels, over 65535 per side or with a non-finite
** elevation, OC_ENOMEM (before allocating) for images over the size
** limit of oc_heightfield_new, OC_ECANCEL when p->progress stops it. */
oc_heightfield *oc_heightfield_load(const char *path,
                                    const oc_heightfield_load_params *p,
                                    oc_error *err);

/* A RAW 16-bit heightmap (.r16 / .raw, as Unity and Unreal read them):
** nx x ny little-endian uint16, no header, rows in image order (the first
** row is the grid's last, j = ny - 1, as in PNG), each row from i = 0.
** nx = ny = 0: a square grid, its side from the file's size. Elevation =
** count * scale + offset (scale 1, offset 0 unless given: a RAW keeps no
** range); cell and origin from p as in oc_heightfield_load. Only regular
** files are read. New grid or NULL with err (OC_EIO for unreadable files,
** OC_EINVAL for a size that does not match the file's bytes). */
oc_heightfield *oc_heightfield_load_raw(const char *path, int nx, int ny,
                                        const oc_heightfield_load_params *p,
                                        oc_error *err);

typedef struct oc_heightfield_save_params {
  /* 0: the format's default: 16 for PNG, 32 (float) for TIFF and EXR.
  ** PNG takes 8 or 16, TIFF 16 or 32, EXR 16 (half) or 32. */
  int bits;
  /* Integer formats: 0 fits scale and offset to the grid (offset = the
  ** lowest sample, scale = range / (2^bits - 1), 1 for a flat grid), 1
  ** uses the scale and offset below (an error when a sample falls outside
  ** the counts). Float formats store elevations as they are: fixed = 1 is
  ** an error there. */
  int fixed;
  double scale, offset;
  const char *const *meta; /* extra metadata: key0, value0, key1, ... */
  size_t nmeta;            /* number of (key, value) pairs */
  /* With nstops > 0: a picture instead of the elevations, for looking at
  ** analysis results: 8-bit RGB (PNG or TIFF), each sample's value
  ** through the palette (stops (value, r, g, b), as oc_mesh_color_by_field
  ** takes them); bits, fixed, scale and offset do not apply. */
  const double *stops;
  int nstops;
} oc_heightfield_save_params;

/* Writes the grid by extension (.png, .tif, .tiff, .exr; .r16 and .raw:
** RAW 16-bit, as oc_heightfield_load_raw reads it, with no metadata) as
** one channel "Y", north up as oc_heightfield_load reads it, integer
** formats holding floor((z - offset) / scale + 0.5). The cell, origin, scale
** and offset go into
** the file as metadata (numbers with 17 significant digits, so they read
** back exactly). used[0], used[1] (when used is not NULL) get the scale
** and offset (1 and 0 for float formats). Loading a saved 16-bit PNG gives
** the quantized elevations, and saving those again gives the same file.
** Atomic; returns OC_OK or an error code with `err`. */
int oc_heightfield_save(const oc_heightfield *hf, const char *path,
                        const oc_heightfield_save_params *p, double used[2],
                        oc_error *err);
/* oc_heightfield_save relative to a directory descriptor (see
** oc_mesh_write_at). */
int oc_heightfield_save_at(const oc_heightfield *hf, int dirfd,
                           const char *path,
                           const oc_heightfield_save_params *p, double used[2],
                           oc_error *err);

/* -- grid arithmetic (terrain/hf_math.c) -- */

/* Sample by sample: a + b, a - b, b - a, a * b. */
typedef enum oc_heightfield_op {
  OC_HEIGHTFIELD_ADD,
  OC_HEIGHTFIELD_SUB,
  OC_HEIGHTFIELD_RSUB,
  OC_HEIGHTFIELD_MUL
} oc_heightfield_op;

/* a op b over two grids of the same layout (size, cell and origin equal,
** else OC_EINVAL saying how they differ). A new grid (caller releases),
** or NULL with err: also when a sample leaves float range, named. */
oc_heightfield *oc_heightfield_combine(const oc_heightfield *a,
                                       const oc_heightfield *b,
                                       oc_heightfield_op op, oc_error *err);
/* a op k, k finite (RSUB: k - a). New grid or NULL with err. */
oc_heightfield *oc_heightfield_scalar(const oc_heightfield *a, double k,
                                      oc_heightfield_op op, oc_error *err);
/* Samples clamped to [lo, hi] (lo <= hi, no NaN; either may be infinite).
** New grid or NULL with err. */
oc_heightfield *oc_heightfield_clamp(const oc_heightfield *a, double lo,
                                     double hi, oc_error *err);

typedef struct oc_heightfield_mask_params {
  int has_above, has_below;
  double above, below; /* finite levels */
  /* >= 0; 0: a 0/1 mask (1 where z >= above and z <= below), else a
  ** linear ramp through 1/2 at each level, falloff wide */
  double falloff;
} oc_heightfield_mask_params;
/* A mask grid of values in [0, 1] on the same layout: the product of
** the ramps of the levels given; mask >= 0.5 where the hard mask is 1, as
** oc_terrain_params.mask reads it. New grid or NULL with err. */
oc_heightfield *oc_heightfield_mask(const oc_heightfield *a,
                                    const oc_heightfield_mask_params *p,
                                    oc_error *err);

/* -- procedural grids (terrain/hf_make.c) -- */

/* Where the samples of a grid to be made lie: sample (i, j) at
** (x0 + i cell, y0 + j cell); the limits of oc_heightfield_new apply. */
typedef struct oc_heightfield_grid {
  int nx, ny;
  double cell, x0, y0;
} oc_heightfield_grid;

/* fBm: z(x, y) = offset + amplitude t((x, y, 0) / wavelength), the
** turbulence primitive of the same noise on the plane z = 0 (so the grid
** samples an oc_turbulence node). Rows in parallel; byte-identical for any
** thread count; cancellable through `progress` (OC_ECANCEL). */
oc_heightfield *oc_heightfield_fbm(const oc_heightfield_grid *g,
                                   const oc_noise *noise, oc_progress progress,
                                   oc_error *err);

/* The surface of a field seen from above: at each sample, the highest z in
** [z0, z1] where f goes from f <= T above to f > T below (T = threshold,
** 0 for the program's); z1 where f > T at z1 already, z0 where the column
** holds no inside point. Found by stepping down the column with local
** Lipschitz bounds (skipping what the column spans prove constant), then
** bisecting to (z1 - z0) 1e-9. Features thinner than (z1 - z0) 1e-5 may be
** stepped over; in a column whose bounds are so loose that it took 1024
** steps, those thinner than (z1 - z0) / 1024 (so a sample costs at most
** about 2048 evaluations). Parallel, deterministic, cancellable. */
oc_heightfield *oc_heightfield_from_program(
    const oc_program *prog, const oc_heightfield_grid *g, double z0, double z1,
    double threshold, oc_progress progress, oc_error *err);

/* The grid sampled on another grid g (positions outside hf are clamped to
** it): the Catmull-Rom interpolant where g->cell <= the cell of hf; where
** it is coarser, the samples of hf averaged under a tent of radius
** g->cell (so downsampling does not alias). Parallel, deterministic,
** cancellable. */
oc_heightfield *oc_heightfield_resample(const oc_heightfield *hf,
                                        const oc_heightfield_grid *g,
                                        oc_progress progress, oc_error *err);

/* The samples i0..i1, j0..j1 (0-based, inclusive; at least 2 x 2) as a new
** grid, its origin at sample (i0, j0). */
oc_heightfield *oc_heightfield_crop(const oc_heightfield *hf, int i0, int j0,
                                    int i1, int j1, oc_error *err);

/* -- resampling and cropping in the caller's terms (terrain/hf_resample.c) */

/* The grid oc_heightfield_resample makes from hf given either `cell` > 0
** (nx = ny = 0: floor(extent / cell) + 1 samples per side, the extent
** kept up to a cell) or nx, ny in 2..65535 (cell = 0: the extent kept,
** cells square, so nx, ny must keep hf's proportions), with hf's origin.
** OC_EINVAL naming 'cell' or 'size' when neither or both are given, or
** the grid would have fewer than 2 or too many samples. */
int oc_heightfield_resample_grid(const oc_heightfield *hf, double cell, int nx,
                                 int ny, oc_heightfield_grid *g, oc_error *err);
/* The 0-based inclusive sample range {i0, j0, i1, j1} of the samples of
** hf lying in the box [x0, x1] x [y0, y1] (with a slack of 1e-9 cell);
** OC_EINVAL when x0 >= x1 or y0 >= y1 or the box holds fewer than 2 x 2
** samples. oc_heightfield_crop_box crops to it (a new grid). */
int oc_heightfield_crop_range(const oc_heightfield *hf, double x0, double y0,
                              double x1, double y1, int ij[4], oc_error *err);
oc_heightfield *oc_heightfield_crop_box(const oc_heightfield *hf, double x0,
                                        double y0, double x1, double y1,
                                        oc_error *err);
/* The sum of the samples, in index order in double (the same for any
** thread count); 0 for NULL. */
double oc_heightfield_sum(const oc_heightfield *hf);

/* -- analysis (terrain/slope.c, fill.c, flow.c, sinks.c, access.c,
**    edt.c) -- */

/* Each returns a NEW grid (one reference: oc_heightfield_release) with the
** size, cell and origin of hf, or NULL with err. Heavy ones run over both
** cores and are byte-identical for any thread count; `progress` (which
** may hold NULL) can cancel them: NULL with OC_ECANCEL. The 8 neighbours
** of a sample are its axis and diagonal ones; a border sample has fewer. */

/* |grad h|, rise over run (tan of the slope angle), by central
** differences (the Catmull-Rom derivative at a sample), one-sided on the
** border. */
oc_heightfield *oc_heightfield_slope(const oc_heightfield *hf, oc_error *err);

/* Depression filling by Priority-Flood+epsilon (Barnes, Lehman, Mulla
** 2014) from the border: filled >= hf everywhere, and every interior
** sample has a strictly lower neighbour, so water drains from everywhere
** to the border. A depression is raised to its spill level, then by one
** float ulp per sample away from its outlet (flats likewise), so its
** surface stays within (samples across) ulps of the spill level. Samples
** with a strictly descending path to the border keep their elevation
** (up to a few ulps where such a path meets a filled flat). Sequential
** (the algorithm is): about 4 s for 4096 x 4096 samples. */
oc_heightfield *oc_heightfield_fill(const oc_heightfield *hf,
                                    oc_progress progress, oc_error *err);

#define OC_HEIGHTFIELD_FREEMAN_EXPONENT 1.1

typedef struct oc_heightfield_flow_params {
  double
      exponent;  /* Freeman's p in (0, 4]; 0: OC_HEIGHTFIELD_FREEMAN_EXPONENT */
  int prefilled; /* 1: hf is already filled (skip the filling) */
  oc_progress progress;
} oc_heightfield_flow_params;

/* Upstream area in m^2 by Freeman's (1991) multiple flow directions on
** the filled grid: each sample holds its own cell^2 plus what its higher
** neighbours send, and sends it all to its strictly lower neighbours k in
** proportion to tan(b_k)^p (b_k the angle down to k). Samples with no
** lower neighbour (after filling, border samples only) keep it: it leaves
** the grid there, and those samples sum to nx ny cell^2. Every sample is
** >= cell^2. fp may be NULL. */
oc_heightfield *oc_heightfield_drainage(const oc_heightfield *hf,
                                        const oc_heightfield_flow_params *fp,
                                        oc_error *err);
/* Stream power A^(1/2) s (Paris et al. 2019, section 6.1): A the drainage
** above, s
** the slope of the filled grid (so filled lakes are ~0). */
oc_heightfield *
oc_heightfield_stream_power(const oc_heightfield *hf,
                            const oc_heightfield_flow_params *fp,
                            oc_error *err);

/* Pits: interior samples strictly lower than all 8 neighbours (border
** samples never are; flat-bottomed depressions have none). Their
** positions (x0 + i cell, y0 + j cell, z) in row order go to a new array
** *out that the caller frees with free() (NULL when none), the count to
** *n. Returns OC_OK or an error code with err. */
int oc_heightfield_sinks(const oc_heightfield *hf, oc_vec3 **out, size_t *n,
                         oc_error *err);

typedef struct oc_heightfield_access_params {
  int rays;        /* per sample, 1 .. 4096; 0: 64 */
  double distance; /* ray length in metres, > 0; 0: 50 cells */
  uint64_t seed;
  oc_progress progress;
} oc_heightfield_access_params;

/* Sky visibility after Miller (1994): per sample, the fraction of `rays`
** directions, uniform in solid angle over the upper hemisphere about the
** vertical (a randomly shifted spherical Fibonacci lattice), that the
** terrain does not block within `distance`. Rays march the bilinear
** surface in half-cell steps; leaving the grid or rising above its
** highest sample escapes. A flat plane gives 1, a plane tilted by a gives
** 1 - a / pi, the bottom of a V valley with sides at a 1 - 2 a / pi. ap
** may be NULL. */
oc_heightfield *
oc_heightfield_accessibility(const oc_heightfield *hf,
                             const oc_heightfield_access_params *ap,
                             oc_error *err);

/* Horizontal distance in metres from each sample to the nearest sample at
** or below `level` (0 there; unsigned), exact (Felzenszwalb-Huttenlocher
** Euclidean distance transform): the float of sqrt(di^2 + dj^2) cell.
** OC_EINVAL when no sample is at or below the level. */
oc_heightfield *oc_heightfield_distance_to_level(const oc_heightfield *hf,
                                                 double level, oc_error *err);

/* ---- terrain: implicitized elevation (terrain/terrain.c) ---------------- */

/* An elevation source: a 2D elevation function h(x, y) over a rectangular
** domain, as the terrain node consumes it. Heightfields are the first
** source (oc_heightfield_elevation); feature-primitive trees or diffusion
** from curves plug in the same way. Every function must be thread-safe
** and allocation-free; bounds must be conservative (never too small). */
typedef struct oc_elevation {
  /* h(x, y); when grad is not NULL, dh/dx and dh/dy go to grad[0..1].
  ** Called only with finite positions (they may lie outside the domain). */
  double (*height)(void *ud, double x, double y, double grad[2]);
  /* lo <= h <= hi everywhere on [x0, x1] x [y0, y1] (x0 <= x1, y0 <= y1). */
  void (*range)(void *ud, double x0, double y0, double x1, double y1,
                double *lo, double *hi);
  /* An upper bound of |grad h| on [x0, x1] x [y0, y1]: h is Lipschitz
  ** with that constant there. */
  double (*slope)(void *ud, double x0, double y0, double x1, double y1);
  /* Reference counting of ud; either may be NULL (a static source). */
  void (*retain)(void *ud);
  void (*release)(void *ud);
  void *ud;
  double x0, y0, x1, y1; /* the domain: finite, x0 < x1, y0 < y1 */
  /* Optional (NULL for grids: the surface covers the domain): a weight
  ** alpha(x, y) saying where the surface exists, alpha >= 1/2 (the
  ** elevation trees' Omega_T). height_weight returns h as height does and
  ** puts alpha in *alpha (its gradient in agrad when not NULL), in one
  ** traversal; weight_range gives alo <= alpha <= ahi on the box and a
  ** Lipschitz bound of alpha there. Both or neither. */
  double (*height_weight)(void *ud, double x, double y, double grad[2],
                          double *alpha, double agrad[2]);
  void (*weight_range)(void *ud, double x0, double y0, double x1, double y1,
                       double *alo, double *ahi, double *alip);
  /* Optional (NULL: range then slope): both at once, from one traversal
  ** of a source's hierarchy (elevation trees); the tracer asks for both
  ** on every segment. */
  void (*bound)(void *ud, double x0, double y0, double x1, double y1,
                double *lo, double *hi, double *slope);
  /* Optional (NULL: height_weight point by point): for m < n, h[m] and
  ** alpha[m] as height_weight(ud, x[m], y, NULL, &alpha[m], NULL) gives
  ** them, bit for bit, x finite and non-decreasing (a row of a grid:
  ** sampling shares per-row work). */
  void (*height_weight_row)(void *ud, const double *x, double y, int n,
                            double *h, double *alpha);
  /* Optional (NULL: height, then bound or range and slope): h at p = (x,
  ** y), as height gives it, and a first-order model of h around p from the
  ** same traversal: a linear part g and a remainder e[0] + e[1] r + e[2]
  ** r^2 (e[k] >= 0) with |h(q) - h(p) - g.(q - p)| <= e[0] + e[1] r +
  ** e[2] r^2 for every q with r = |q - p| <= R (Euclidean). *boxes (when
  ** not NULL) grows by the box queries it made (elevation trees:
  ** lib/elevation/etaylor.h). */
  double (*taylor)(void *ud, double x, double y, double R, double g[2],
                   double e[3], int *boxes);
  /* Optional (NULL: the source has one level of detail, which every query
  ** gets): the same surface with the detail finer than a footprint m >= 0
  ** (metres) dropped, for queries that need less detail than a pixel's
  ** (a level-of-detail render's shadow rays and AO, render/shade.c). Fills
  ** *out holding one reference of its own (drop it with
  ** out->release(out->ud)), on the same domain; its weight, where the
  ** source's is a function of ud (oc_enode_view_weight), is that
  ** function of out->ud. Level-of-detail trees (oc_enode_elevation_view):
  ** the view's footprint foot(p) becomes sqrt(foot(p)^2 + m^2). OC_OK, or
  ** an error code with err. */
  int (*coarser)(void *ud, double m, struct oc_elevation *out, oc_error *err);
} oc_elevation;

/* The source of a heightfield: its Catmull-Rom interpolant over the grid's
** extent, with a min/max pyramid (per pair of cells, the hull of the
** bicubic patches' Bezier coefficients) for ranges and slopes. Fills *src
** holding one reference (drop it with src->release(src->ud)), which
** retains hf. Returns OC_OK, or OC_ENOMEM with err. */
int oc_heightfield_elevation(oc_heightfield *hf, oc_elevation *src,
                             oc_error *err);

/* ---- rendering elevation surfaces (render/render.c, render/etrace.c) ---- */

/* Images of the surface z = h(x, y) of an elevation source, traced
** directly (no implicitization): the height above the surface along the
** ray, p_z - h(p_xy), is marched with the accelerated local-Lipschitz
** step of Génevaux et al. 2015, section 7.2 (rp->tracer =
** OC_TRACE_SEGMENT, the default: per segment [t, t + delta] of the ray
** the slope and elevation range of its xy box, the candidate delta
** doubling after each step) or with plain sphere tracing on the slope
** bound of the whole domain (OC_TRACE_SPHERE), the ray first clipped to
** the domain x [min h, max h]. Normals are analytic (the height
** gradient). Camera, size, shading, colours, AOVs, exposure, tone,
** progress and the returned image are those of oc_render (threshold and
** warning are unused: there is no iso-value and no thin solid). */

typedef struct oc_render_stats {
  long long pixels, hits;
  double calls;           /* height calls of the primary rays, the normal
                          ** of each hit included */
  double calls_per_pixel; /* calls / pixels */
  double calls_total;     /* the same with shadow rays and AO */
  double calls_total_per_pixel;
} oc_render_stats;

/* What the renderer traces: an elevation source, and where it has holes.
** A surface exists at (x, y) only where weight(wud, x, y) >= T (the
** elevation trees' Omega_T); weight NULL (heightfields): everywhere on
** the source's domain. */
typedef struct oc_esurface {
  const oc_elevation *src;
  double (*weight)(void *wud, double x, double y);
  void *wud;
  double T;
  /* Optional (NULL: none): bounds of weight(wud, .) on the box [x0, x1] x
  ** [y0, y1] (x0 <= x1, y0 <= y1) as oc_elevation's weight_range gives
  ** them, lo <= weight <= hi and a Lipschitz bound lip there: where the
  ** weight is the source's own, that hook (trees: src.weight_range). The
  ** tracer proves stretches of rays in holes free with it (a wall is
  ** where the weight reaches T), instead of crossing a hole by tolerance
  ** steps. */
  void (*weight_bound)(void *wud, double x0, double y0, double x1, double y1,
                       double *lo, double *hi, double *lip);
} oc_esurface;

/* oc_render_elevation and its two phases for a surface with holes; the
** oc_render_elevation* functions below pass none. */
oc_image *oc_render_surface(const oc_esurface *es, const oc_render_params *rp,
                            oc_render_stats *st, oc_error *err);
oc_image *oc_render_surface_geometry(const oc_esurface *es,
                                     const oc_render_params *rp, oc_error *err);
oc_image *oc_render_surface_shade(const oc_esurface *es,
                                  const oc_render_params *rp,
                                  const oc_image *geometry, const float *albedo,
                                  oc_error *err);
/* oc_render_check for a surface: a usable source, then the tracing
** parameters; and the shading parameters alone. */
int oc_render_check_surface(const oc_esurface *es, const oc_render_params *rp,
                            oc_error *err);
int oc_render_check_shade(const oc_render_params *rp, oc_error *err);

/* Traces and shades in one call; *st (when not NULL) receives the height
** calls, summed in pixel order (the same for any thread count). NULL with
** err as oc_render (OC_EINVAL also for a source without its functions or
** with an empty or infinite domain). */
oc_image *oc_render_elevation(const oc_elevation *src,
                              const oc_render_params *rp, oc_render_stats *st,
                              oc_error *err);

/* The two phases, as oc_render_geometry and oc_render_shade (the "evals"
** channel counts height calls). */
oc_image *oc_render_elevation_geometry(const oc_elevation *src,
                                       const oc_render_params *rp,
                                       oc_error *err);
oc_image *oc_render_elevation_shade(const oc_elevation *src,
                                    const oc_render_params *rp,
                                    const oc_image *geometry,
                                    const float *albedo, oc_error *err);

typedef struct oc_terrain_params {
  double falloff;    /* R > 0: the prism P = (Omega shrunk by R) x dz and
                     ** the distance over which f falls to 0 outside it */
  double transition; /* W > 0: half-width of sigma (0: 1 metre) */
  int invert;        /* 1: solid above the surface (sigma(z - h)) */
  double thickness;  /* >= 0: the prism's z-range, [min h, max h] in the
                     ** paper, reaches this much farther on the solid side
                     ** (below; above when inverted): deeper bedrock, or
                     ** the top of a floating island's inverted underside */
  /* NULL, or Omega = the nodes of this grid where mask >= 0.5 (and inside
  ** the source's domain); f then falls off with the distance to the mask
  ** shrunk by R. Retained by nothing: the node keeps a distance grid. */
  const oc_heightfield *mask;
  /* How the solid ends at the sides of the source's domain [x0, x1] x
  ** [y0, y1]: OC_TERRAIN_OPEN (the default without a mask) cuts it at
  ** those vertical sides, the surface z = h over the whole domain, border
  ** included, and f = 0 exactly outside; OC_TERRAIN_SLAB is the paper's
  ** prism, Omega shrunk by R with f falling off over R around it. A mask
  ** always shapes its own slab (OC_TERRAIN_OPEN with a mask is refused). */
  int edges;
} oc_terrain_params;
enum { OC_TERRAIN_EDGES_DEFAULT, OC_TERRAIN_OPEN, OC_TERRAIN_SLAB };

/* The implicitization of Paris et al. 2019, section 5.1: f = min(f_T, f_P) with
** f_T = sigma(h(x, y) - z) (inverted: sigma(z - h)), sigma the odd cubic
** of range [0, 2T], and f_P = 2T g(d(p, P) / R), P = (Omega shrunk by R)
** x [min h, max h] (slab edges; open edges: d the vertical distance to
** [min h, max h] inside the domain, f = 0 outside it). The surface f = T
** is z = h(x, y) wherever Omega shrunk by R (open: the domain) covers
** (x, y). The exact definition is in docs/fields.md.
** Retains the source (src is copied). New reference or NULL with err. */
oc_node *oc_terrain(const oc_elevation *src, const oc_terrain_params *tp,
                    oc_error *err);

/* -- the defaults front ends take from a grid (terrain/hf_defaults.c) -- */

/* The default terrain parameters for hf: falloff 4 cells of hf,
** transition 1 (metre), no mask, open edges, not inverted, thickness 0. */
void oc_terrain_defaults(const oc_heightfield *hf, oc_terrain_params *tp);
/* The terrain node of hf's elevation with tp, or with
** oc_terrain_defaults(hf) when tp is NULL: the node outcrop.terrain(hf)
** makes, and the one the generators march when given no terrain. New
** reference or NULL with err. */
oc_node *oc_heightfield_terrain(oc_heightfield *hf, const oc_terrain_params *tp,
                                oc_error *err);
/* The sea generator's default sea level: 0 when hf's samples span it
** (lowest < 0 < highest), else the lowest plus a quarter of the relief. */
double oc_heightfield_sea_level(const oc_heightfield *hf);
/* A mask for oc_terrain_params.mask from the grey image at `path`:
** stretched over hf's width (its cell = hf's extent along x / (its nx -
** 1), origin hf's), its samples divided by the brightest, so Omega is
** where the image is >= half its brightest pixel. New grid, or NULL with
** err: the read's error after "'mask': ", or OC_EINVAL when the image is
** black. */
oc_heightfield *oc_heightfield_load_mask(const char *path,
                                         const oc_heightfield *hf,
                                         oc_error *err);

/* ---- elevation trees (Génevaux et al. 2015) ----------------------- */

/* lib/elevation; docs/fields.md, "Elevation trees", has the formulas. A
** node maps a point (x, y) to an elevation f and a weight alpha, with
** compact support Omega_0 = {alpha > 0}; the terrain is where alpha >=
** 1/2. f is defined on the whole plane (a blend divides by max(sum
** alpha, 1/2), which is the paper's f where the terrain is), and every
** node knows the range of f and alpha and Lipschitz bounds of both, over
** the plane and inside any box. Nodes are immutable and reference
** counted; a tree is a DAG (instancing). Constructors retain their
** children and return a new reference or NULL with err. */
typedef struct oc_enode oc_enode;

typedef struct oc_enode_sample {
  double f, a;   /* elevation and weight */
  double fx, fy; /* grad f */
  double ax, ay; /* grad alpha */
} oc_enode_sample;

typedef enum oc_enoise_kind {
  OC_ENOISE_NONE,       /* flat: f = height */
  OC_ENOISE_PLAIN,      /* sum a_i eta(s_i (p - c)) */
  OC_ENOISE_TURBULENCE, /* sum a_i |eta| */
  OC_ENOISE_RIDGED      /* Musgrave's ridged multifractal, terms in [0, a_i] */
} oc_enoise_kind;

/* a_i = amplitude gain^i, s_i = lacunarity^i / wavelength, i < octaves;
** eta is the engine's simplex noise on z = 0 remapped to [-1, 1]. */
typedef struct oc_enode_noise {
  oc_enoise_kind kind;
  double amplitude;  /* >= 0 */
  double wavelength; /* > 0 */
  int octaves;       /* 1 .. 16 */
  double gain;       /* in (0, 1]; 0: 1/2 */
  double lacunarity; /* >= 1; 0: 2 */
  uint64_t seed;
} oc_enode_noise;

typedef struct oc_enode_disc_params {
  double cx, cy; /* centre */
  double radius; /* > 0: alpha = (1 - (d / radius)^2)^3 */
  double height; /* base elevation */
  oc_enode_noise noise;
} oc_enode_disc_params;

oc_enode *oc_enode_disc(const oc_enode_disc_params *p, oc_error *err);

/* A cross-section: knots (d[i], v[i]) of the signed distance d (> 0 on
** the left of the direction of travel), d increasing, interpolated by a
** C1 shape-preserving quadratic spline, constant beyond the end knots;
** placed at arc length fraction `at` in [0, 1] of the skeleton. */
typedef struct oc_enode_profile {
  double at;
  const double *d, *v;
  size_t n;
} oc_enode_profile;

typedef enum oc_ecurve_spline {
  OC_ECURVE_CATMULL, /* a C1 cubic through the points (uniform Catmull-Rom) */
  OC_ECURVE_BEZIER,  /* the points are cubic Bézier control points (3k + 1) */
  OC_ECURVE_LINEAR   /* segments (refused where they make a corner) */
} oc_ecurve_spline;

/* f = q_z + c(s, d), alpha = g(max(0, |p - q| - core) / (radius - core)),
** q the closest point of the skeleton (points x, y and its elevation z),
** c the profiles interpolated by arc length. Refused when radius is not
** below the skeleton's smallest radius of curvature, or at a corner. */
typedef struct oc_enode_curve_params {
  const oc_vec3 *points;
  size_t npoints;
  oc_ecurve_spline spline;
  double radius; /* > 0: where alpha reaches 0 */
  double core;   /* in [0, radius): where alpha is 1 */
  const oc_enode_profile *profiles;
  size_t nprofiles;
} oc_enode_curve_params;
oc_enode *oc_enode_curve(const oc_enode_curve_params *p, oc_error *err);

/* Presets (docs/fields.md, "Elevation trees", has their cross-sections):
** a river's channel (width, depth, banks; 0 picks the kind's) and a road
** levelling its neighbourhood (carriageway width 7, shoulders 1.5,
** embankment 12 by default: 0, or shoulder < 0, picks them). */
typedef enum oc_river_kind {
  OC_RIVER_STREAM,  /* 3 m wide, 0.8 deep, banks 4 */
  OC_RIVER_RIVER,   /* 20, 3, 25 */
  OC_RIVER_MEANDER, /* 40, 4, 60 */
  OC_RIVER_MAIN     /* main stem: 150, 10, 200 */
} oc_river_kind;
typedef struct oc_enode_river_params {
  const oc_vec3 *points;
  size_t npoints;
  oc_ecurve_spline spline;
  oc_river_kind kind;
  double width, depth, bank;
} oc_enode_river_params;
oc_enode *oc_enode_river(const oc_enode_river_params *p, oc_error *err);
typedef struct oc_enode_road_params {
  const oc_vec3 *points;
  size_t npoints;
  oc_ecurve_spline spline;
  double width, shoulder, embankment;
} oc_enode_road_params;
oc_enode *oc_enode_road(const oc_enode_road_params *p, oc_error *err);
/* f = sum alpha_i f_i / max(sum alpha_i, 1/2), alpha = sum alpha_i. */
oc_enode *oc_enode_blend(oc_enode *const *kids, size_t n, oc_error *err);
/* w = clamp(alpha_B, 0, 1): f = (1 - w) f_A + w f_B; alpha = alpha_A, or
** with lerp (1 - w) alpha_A + w^2. */
oc_enode *oc_enode_replace(oc_enode *a, oc_enode *b, int lerp, oc_error *err);

typedef struct oc_enode_add_params {
  int sum_weight; /* 1: alpha = alpha_A + w_B^2 (else alpha_A) */
  int below;      /* 1: B only below an altitude of A: */
  double below_z; /* the weight is 1 where f_A <= below_z - fade, 0 where */
  double fade;    /* f_A >= below_z, smooth between; fade > 0 */
  /* slope = 1: B only where A is gentle. With theta = atan |D| (A's slope
  ** angle over central differences of step h = slope_step: D = (f_A(p +
  ** h e_x) - f_A(p - h e_x), f_A(p + h e_y) - f_A(p - h e_y)) / 2h), the
  ** weight is 1 where theta <= slope_deg, 0 where theta >= slope_deg +
  ** slope_fade, smooth between. Degrees: slope_deg in [0, 90), slope_fade
  ** > 0; slope_step > 0 (0 means 5). */
  int slope;
  double slope_deg, slope_fade, slope_step;
} oc_enode_add_params;
/* w = clamp(alpha_B, 0, 1) (times the altitude and slope weights): f = f_A
** + w f_B. */
oc_enode *oc_enode_add(oc_enode *a, oc_enode *b, const oc_enode_add_params *p,
                       oc_error *err);

/* p = scale R(angle) p' + (tx, ty): f(p) = vscale f(p') + voffset,
** alpha(p) = alpha(p'). Consecutive transforms are concatenated. */
typedef struct oc_enode_xform {
  double tx, ty;
  double angle;  /* degrees, counter-clockwise */
  double scale;  /* > 0 (0: 1) */
  double vscale; /* != 0 (0: 1) */
  double voffset;
} oc_enode_xform;
oc_enode *oc_enode_transform(oc_enode *e, const oc_enode_xform *x,
                             oc_error *err);

/* f(p) = f_A(p + delta(p)), delta = amplitude (eta_1, eta_2) summed over
** octaves (gain 1/2, lacunarity 2) at p / wavelength; refused unless
** delta's Lipschitz bound is < 1, so p -> p + delta(p) is a bijection. */
typedef struct oc_enode_warp_params {
  double amplitude, wavelength;
  int octaves;
  uint64_t seed;
} oc_enode_warp_params;
oc_enode *oc_enode_warp(oc_enode *e, const oc_enode_warp_params *p,
                        oc_error *err);

/* The contour (lake) primitive (Génevaux et al. 2015, section 4, figure
** 7): a closed shore r(theta) around the centre, a C1 periodic
** interpolant (the shape-preserving quadratic spline of the cross-sections,
** wrapped) of either n >= 3 radii at equal angles from +x counter-clockwise
** (radii) or of the vertices of a polygon star-shaped around the centre
** (contour: x, y pairs, either orientation). With delta = |p - c| -
** r(theta) (< 0 inside), f = level + c(theta, delta), the profiles at
** their angles (oc_enode_profile.at: degrees in [0, 360), increasing)
** blended by a smoothstep between sectors, and alpha = 1 inside, g(delta /
** falloff) outside. Every profile must be flat below some d_lo > -min r
** and all at the same depth there (the lake's deepest part round the
** centre, where theta is undefined). nprofiles = 0 gives the default bed:
** knots (-D, -depth), (0, 0), (falloff / 4, 0), (falloff, bank) with D =
** min(min r / 2, 20 depth); depth 0 means 5, bank < 0 means 2. */
typedef struct oc_enode_lake_params {
  double cx, cy;
  const double *radii; /* nradii radii, or NULL */
  size_t nradii;
  const double *contour; /* ncontour (x, y) pairs, or NULL */
  size_t ncontour;
  double level;
  const oc_enode_profile *profiles;
  size_t nprofiles;
  double falloff; /* > 0; 0: half the largest radius */
  double depth, bank;
} oc_enode_lake_params;
oc_enode *oc_enode_lake(const oc_enode_lake_params *p, oc_error *err);

/* The image primitive (Génevaux et al. 2015, section 4.2, figure 8): a
** heightfield mapped on a convex counter-clockwise quadrangle quad[0..3]
** (x, y pairs; corner k takes the grid's corner (0, 0), (1, 0), (1, 1),
** (0, 1) in turn) by inverse bilinear mapping, or along a segment (seg,
** with width > 0: the rectangle whose axis it is, the grid's x along it),
** or along a curve (below).
** f = offset + height h(u, v) (the grid's C1 bicubic) inside, and the
** value at the closest point of the quad outside (so f is Lipschitz on
** the plane); alpha = clamp(weight(u, v), 0, 1) (1 without a weight grid)
** times prod_k G(d_k / falloff), d_k the distance to edge k inside, G(x) =
** 1 - (1 - x^2)^3 on [0, 1] (C1, 0 on the border). Both grids are
** retained. */
typedef struct oc_enode_image_params {
  oc_heightfield *heightfield;
  oc_heightfield *weight; /* or NULL */
  int segment;            /* 1: seg and width instead of quad */
  double quad[8];
  double seg[4], width;
  double height; /* vertical scale (!= 0; 0 means 1) */
  double offset;
  double falloff; /* > 0; 0: a tenth of the square root of the area */
  /* Along a curve (curve not NULL, with width): the skeleton through
  ** ncurve points (x, y; z is ignored) as the curve primitive's, open and
  ** without corners, width / 2 below its smallest radius of curvature.
  ** With s the arc length of the closest point (0..length) and d the
  ** signed distance (> 0 on the left), the grid's x goes along s and y
  ** across, (u, v) = (s / length, (d + width / 2) / width) (so a straight
  ** curve gives the segment's mapping); f outside the band is the value
  ** at (s, clamped d); alpha is as on a quad with the edge distances s,
  ** length - s and width / 2 -+ d. Its slope bounds hold where alpha >
  ** 0, as a curve primitive's. */
  const oc_vec3 *curve;
  size_t ncurve;
  oc_ecurve_spline spline;
} oc_enode_image_params;
oc_enode *oc_enode_image(const oc_enode_image_params *p, oc_error *err);

void oc_enode_retain(oc_enode *e);
void oc_enode_release(oc_enode *e);
const char *oc_enode_kind(const oc_enode *e);

/* f, alpha and their gradients at (x, y); NaN in gives NaN out. */
void oc_enode_eval(const oc_enode *e, double x, double y, oc_enode_sample *s);
/* alpha alone (cheaper: no gradients, f skipped where alpha = 0); the
** terrain is where it is >= OC_ENODE_T. */
#define OC_ENODE_T 0.5
double oc_enode_weight(const oc_enode *e, double x, double y);
/* The box holding Omega_0 (x0, y0, x1, y1) and the range of f over the
** plane; the Lipschitz bound of f over the plane. */
void oc_enode_get_bounds(const oc_enode *e, double box[4], double *flo,
                         double *fhi);
double oc_enode_lipschitz(const oc_enode *e);

/* Inside the box [x0, x1] x [y0, y1]: ranges of f and alpha, and
** Lipschitz bounds of f and alpha (conservative). */
typedef struct oc_enode_bound {
  double flo, fhi, alo, ahi, lf, la;
} oc_enode_bound;
void oc_enode_bound_in(const oc_enode *e, double x0, double y0, double x1,
                       double y1, oc_enode_bound *b);

typedef struct oc_enode_stats {
  size_t nodes;      /* distinct nodes of the DAG */
  size_t primitives; /* distinct primitives */
  size_t bytes;      /* their memory, with the data of curves, lakes and
                     ** images (skeletons, profiles, grids: each once) */
  size_t node_bytes; /* the nodes alone (bytes less that data) */
} oc_enode_stats;
/* OC_OK, or OC_ENOMEM with err. */
int oc_enode_get_stats(const oc_enode *e, oc_enode_stats *st, oc_error *err);

/* A box (x0, y0, x1, y1) holding the terrain, Omega_T = {alpha >= 1/2},
** from the tree's bounds (conservative, within 1/128 of Omega_0's box of
** the true one); 0 when the tree has no terrain. */
int oc_enode_terrain_box(const oc_enode *e, double box[4]);

/* An elevation source (for oc_terrain, oc_heightfield_from_elevation…)
** over domain (x0, y0, x1, y1; NULL: oc_enode_terrain_box): height f,
** ranges and slopes from the tree's own bounds. Holds one reference to
** e. OC_OK, or OC_EINVAL with err for an empty or infinite domain. */
int oc_enode_elevation(oc_enode *e, const double *domain, oc_elevation *src,
                       oc_error *err);

/* -- elevation trees as terrains and grids (terrain/elevation_tree.c) -- */

/* The default terrain parameters for a source without a grid (a tree's):
** falloff 1/100 of the domain's longer side, transition 1 (metre), no
** mask, open edges, not inverted, thickness 0. */
void oc_terrain_defaults_source(const oc_elevation *src, oc_terrain_params *tp);
/* The terrain node of tree e over domain (NULL: oc_enode_terrain_box)
** with tp (NULL: oc_terrain_defaults_source): solid below f where alpha
** >= 1/2, nothing where alpha < 1/2 (oc_terrain, the weight term). New
** reference or NULL with err (OC_EINVAL for a tree without terrain). */
oc_node *oc_enode_terrain(oc_enode *e, const double *domain,
                          const oc_terrain_params *tp, oc_error *err);
/* The grid over src's domain, filling what is missing (nx = ny = 0: no
** size; cell = 0: none; origin NULL: the domain's corner (x0, y0)):
** neither size nor cell: 513 samples along the longer side and enough
** along the other to cover it; a size alone: the smallest cell with which
** it covers the domain; a cell alone: the samples that cover it. OC_OK,
** or OC_EINVAL with err naming the field. */
int oc_elevation_grid(const oc_elevation *src, int nx, int ny, double cell,
                      const double *origin, oc_heightfield_grid *g,
                      oc_error *err);
/* src sampled at every node of g: one height_weight (else height) call
** per sample, f stored as a float; with holes set, the samples where
** alpha < 1/2 (off Omega_T) get hole_value instead. Rows on all cores,
** byte-identical for any thread count, cancellable through progress
** (OC_ECANCEL). New grid, or NULL with err. */
oc_heightfield *oc_heightfield_from_elevation(const oc_elevation *src,
                                              const oc_heightfield_grid *g,
                                              int holes, double hole_value,
                                              oc_progress progress,
                                              oc_error *err);
/* Level of detail (lib/elevation/lod.c; docs/fields.md, "Level of
** detail"). A view gives every point p a pixel footprint foot(p) = k
** sqrt(|p - eye_xy|^2 + dz^2), dz = |eye_z - the tree's mid elevation|
** (fixed, so foot is C1 and k-Lipschitz), k the angle of a pixel (0:
** full detail). A detail of wavelength w is weighted kappa = b(t), t =
** clamp(log2(w / foot), 0, 1), b(t) = 1 - (1 - t^2)^3: kept while w >= 2
** foot, dropped where w <= foot. Disc octaves are filtered so (those
** with weight 0 are not evaluated), and lod nodes blend a coarse tree
** into a detailed one. Under a view, a tree is a genuine C1 function of
** p: gradients and bounds include the footprint's terms. Without a view
** (oc_enode_eval, sampling, oc_terrain) every detail is kept: a lod node
** is its detailed tree b. */
typedef struct oc_enode_view {
  double eye[3];
  double k; /* >= 0, radians per pixel (times a quality factor) */
} oc_enode_view;

/* t = clamp((kappa - k0) / (k1 - k0), 0, 1), kappa for `wavelength` (the
** size of the detail b adds): f = (1 - t) f_a + t f_b, alpha likewise;
** only a is evaluated where t = 0, only b where t = 1. 0 <= k0 < k1 <= 1
** (k0 = k1 = 0: 0 and 1). */
typedef struct oc_enode_lod_params {
  double wavelength; /* > 0 */
  double k0, k1;
} oc_enode_lod_params;
oc_enode *oc_enode_lod(oc_enode *a, oc_enode *b, const oc_enode_lod_params *p,
                       oc_error *err);

/* oc_enode_eval under view v (NULL: oc_enode_eval). OC_OK, or OC_EINVAL
** with err for a view that is not finite or has k < 0. */
int oc_enode_eval_view(const oc_enode *e, double x, double y,
                       const oc_enode_view *v, oc_enode_sample *s,
                       oc_error *err);

/* oc_enode_elevation under view v: height, ranges and slopes include the
** footprint's terms (the domain, when NULL, is where alpha may reach T
** under the view), and so do its first-order models (taylor: the octave
** filters and the lod operators' t composed with a proved model of
** log2(w / foot); lib/elevation/lod.c). The source's weight for oc_esurface is
** oc_enode_view_weight with wud = src->ud, and its weight_bound
** oc_enode_view_weight_bound (the weight's bounds on a box under the
** view). Holds one reference to e. */
int oc_enode_elevation_view(oc_enode *e, const double *domain,
                            const oc_enode_view *v, oc_elevation *src,
                            oc_error *err);
double oc_enode_view_weight(void *ud, double x, double y);
void oc_enode_view_weight_bound(void *ud, double x0, double y0, double x1,
                                double y1, double *lo, double *hi, double *lip);
/* The size of a pixel at unit distance on the camera's axis, 2 tan(fov /
** 2) / height (render/render.c): a view's k is c times it. */
double oc_render_pixel_angle(const oc_render_params *rp);

/* ---- geology: resistance trees and the erosion node ----- */

/* geology/geology.c and geology/erosion.c; docs/fields.md, "Geology", has the
** formulas. A resistance tree is an ordinary node whose value is rock
** resistance (0 softest, 1 hardest). Trees are not clamped as they are
** built, so that blends add up as in Paris et al. 2019, section 4.2: the
** erosion
** node clamps what it reads to [0, 1], palettes clamp at their ends, and
** oc_clamp() clamps a tree explicitly. Constructors return a new
** reference, or NULL with err. */

/* Horizontal strata: offset + amplitude * t(p_z / wavelength) / tmax, t
** the turbulence along a vertical line, tmax = 2 - 2^(1 - octaves): the
** value spans [offset, offset + amplitude]. Unbounded support. */
oc_node *oc_strata(const oc_noise *noise, oc_error *err);

/* clamp(f, lo, hi); lo < hi, both finite. Retains child. */
oc_node *oc_clamp(oc_node *child, double lo, double hi, oc_error *err);

/* A plane layer (Paris et al. 2019, section 4.2): resistance * g(|d| /
** radius), d
** the signed distance to the plane through origin with that normal, plus
** the turbulence `noise` when not NULL (offset + amplitude t(p/wl)). Built
** from two half-space primitives (an intersection for resistance >= 0, a
** union below) blended with the turbulence. */
oc_node *oc_geology_layer(oc_vec3 origin, oc_vec3 normal, double radius,
                          double resistance, const oc_noise *noise,
                          oc_error *err);

/* Tapering: strata compressed by a factor that grows along a direction.
** rho'(p) = rho(p + (k(u) - 1) clamp(s, -height, height) a), s = (p - o).a,
** u = (p - o).b, k going from 1 at u = from to `factor` at u = to
** (smoothstep, constant beyond). */
typedef struct oc_taper_params {
  oc_vec3 origin;
  oc_vec3 axis;    /* a: the direction strata are compressed along */
  oc_vec3 along;   /* b: the direction the compression grows along */
  double from, to; /* positions along b from the origin; from != to */
  double factor;   /* > 0: 2 squeezes the strata to half their thickness */
  double height;   /* > 0: half-height of the compressed band along a */
} oc_taper_params;
oc_node *oc_taper(oc_node *child, const oc_taper_params *tp, oc_error *err);

/* Fault (Paris et al. 2019, section 4.4): rho(p - offset) strictly inside the
** domain, rho(p) elsewhere; discontinuous on the domain's boundary, so its
** global Lipschitz bound is infinite (local bounds of boxes that miss the
** boundary stay finite). */
typedef enum oc_fault_kind {
  OC_FAULT_BOX = 0,  /* the open box lo < p < hi */
  OC_FAULT_HALF = 1, /* the open half-space (p - origin).normal < 0 */
  OC_FAULT_NODE = 2  /* where node's field > T (node retained) */
} oc_fault_kind;
typedef struct oc_fault_domain {
  oc_fault_kind kind;
  oc_vec3 lo, hi;         /* box */
  oc_vec3 origin, normal; /* half-space */
  oc_node *node;          /* node */
} oc_fault_domain;
oc_node *oc_fault(oc_node *child, const oc_fault_domain *dom, oc_vec3 offset,
                  oc_error *err);

/* Erosion node (Paris et al. 2019, section 6): f~ = max(f - f_D (1 - rho^),
** min(f,
** 0)), rho^ = clamp(geology, 0, 1), f_D = depth * clamp(control, 0, 1)
** (depth everywhere when control is NULL). It only removes material: f~
** <= f, and f~ = 0 wherever f = 0. depth > 0 is in field units. Retains
** its three nodes. */
oc_node *oc_erosion(oc_node *terrain, oc_node *geology, oc_node *control,
                    double depth, oc_error *err);

/* ---- generators: karst (gen/karst.c) ---------------------------------- */

/* Karst networks by invasion percolation (Paris et al. 2019, section 6.2).
** From the
** sinks, a priority queue of candidate points ordered by resistance rho
** (the geology, clamped to [0, 1]) plus epsilon times a uniform draw: the
** least resistant candidate is popped; where rho < rho0 a negative point
** primitive carves there, and `branches` new candidates are tried at
** `step` from it in uniform random directions of the lower hemisphere
** (dz <= 0), each kept only when it lies inside the heightfield's domain
** (shrunk by radius), between `floor` and `cover` below the surface h(x,
** y) of the heightfield, and at least `spacing` from every point queued
** so far (Poisson spheres, through a grid hash). Stops when no candidate
** can have rho < rho0, or at max_primitives cavities. Ties pop the older
** candidate first; the draws of a candidate come from the stream (seed,
** its index): the same parameters give the same cavities, sequentially
** (the process is), on any number of threads. */
typedef struct oc_karst_cavity {
  oc_vec3 center;
  double radius, energy; /* energy < 0: carves */
  double rho;            /* clamped resistance at the centre */
  int64_t parent;        /* cavity it grew from (distance `step`), or -1
                         ** for one at a sink */
} oc_karst_cavity;

typedef struct oc_gen_karst_params {
  oc_heightfield *heightfield; /* required: the surface and the sinks */
  oc_node *terrain; /* blended with the cavities; NULL: the default terrain
                    ** of the heightfield (oc_heightfield_terrain) */
  int no_terrain;   /* 1 (with terrain NULL): the cavities alone */
  oc_node *geology; /* resistance; NULL: strata of wavelength 8 radius
                    ** (oc_strata, 3 octaves, the seed below) */
  const oc_vec3
      *sinks; /* nsinks starting points; NULL: oc_heightfield_sinks of the
              ** heightfield. A sink higher than `cover` below the
              ** surface is lowered to it. */
  size_t nsinks;
  uint64_t seed;
  double radius;         /* R of the point primitives > 0; 0: 2 cells */
  double step;           /* distance to new candidates > 0; 0: radius */
  double spacing;        /* Poisson-sphere radius > 0; 0: radius / 2 */
  double cover;          /* least depth of a centre under h >= 0; NAN: R / 4 */
  double floor;          /* lowest centre z; NAN: lowest sample + radius */
  double epsilon;        /* perturbation range >= 0 (0.1) */
  double rho0;           /* carve where rho < rho0, in (0, 1] (0.5) */
  double energy;         /* E > 0: a cavity's energy is -E (beta + (1 - beta)
                         ** (1 - rho)), e(rho, sigma = 1) of section 6.1 (1.5) */
  double beta;           /* in [0, 1] (0.5) */
  int branches;          /* candidates tried per cavity, 1 .. 64 (6) */
  size_t max_primitives; /* budget, 1 .. OC_KARST_MAX (100000) */
  oc_progress progress;
} oc_gen_karst_params;

#define OC_KARST_MAX 20000000

typedef struct oc_gen_karst_stats {
  size_t primitives; /* cavities carved */
  size_t candidates; /* points queued, sinks included */
  size_t sinks;      /* sinks queued */
  double seconds;
} oc_gen_karst_stats;

/* The defaults above (heightfield, terrain, geology, sinks NULL). */
void oc_gen_karst_defaults(oc_gen_karst_params *p);

/* Runs the percolation: the cavities in carving order go to a new array
** *out (free() it; NULL when none), their count to *n. st may be NULL.
** OC_OK, or OC_EINVAL naming the parameter, OC_ENOMEM, OC_ECANCEL. */
int oc_karst_cavities(const oc_gen_karst_params *p, oc_karst_cavity **out,
                      size_t *n, oc_gen_karst_stats *st, oc_error *err);

/* The blend of the terrain (when given) and one oc_point per cavity (so a
** compiled program stores them inline). NULL with err when the
** percolation fails, or when no terrain is given and nothing was carved. */
oc_node *oc_generate_karst(const oc_gen_karst_params *p, oc_gen_karst_stats *st,
                           oc_error *err);

/* ---- generators: hoodoos (gen/hoodoos.c, gen/grammar.c) ---------------- */

/* Hoodoos and goblins (Paris et al. 2019, section 6.3). Placement: the maximal
** Poisson disk set of spacing `radius` over the heightfield (shrunk by
** `margin`) is thinned with the probability
**   P = probability * exp(-((s - slope) / slope_spread)^2) / (1 + A /
**       drainage) * mask
** (clamped to [0, 1]; s = oc_heightfield_slope, A = oc_heightfield_drainage:
** hoodoos favour
** talus and cliffs, medium slope and low drainage). Each kept sample is an
** axiom of the grammar of figure 20, derived upwards from the surface:
**   A -> B;  B -> b B (p_B) | b C (1 - p_B);
**   C -> c B (p_C / 2) | c (p_C / 2) | d (1 - p_C),
** p_B = clamp(p_block (0.5 + rho)), p_C = clamp(p_cone (1.5 - rho)), rho
** the clamped geology at the centre of the symbol being produced. A
** symbol of size s at base p is followed at p + s z with size shrink * s;
** its half-width is width shrink^k (0.5 + rho) (hard rock: wide caps,
** soft rock: necks). At most max_depth symbols: a derivation is steered
** to a terminal (b C, then c or d) when the budget runs out. Terminals:
** b a block (an ellipsoid), c a cone (a spire), d a box (a caprock 1.3
** times wider); each with a random turn about z, a tilt of up to `tilt`
** radians, and a perturbed surface (oc_perturb, amplitude roughness). The
** first symbol's base sinks below the surface by 0.15 H + |grad h| width
** (at most half its size), so every hoodoo is attached to the ground; H,
** drawn in [height_lo, height_hi], is how far a derivation reaching
** max_depth rises above the surface. Draws come from the stream (seed,
** axiom index): the same parameters give the same symbols on any number
** of threads. */
typedef enum oc_hoodoo_kind {
  OC_HOODOO_BLOCK = 'b',
  OC_HOODOO_CONE = 'c',
  OC_HOODOO_BOX = 'd'
} oc_hoodoo_kind;

typedef struct oc_hoodoo_symbol {
  char kind;       /* an oc_hoodoo_kind */
  uint32_t hoodoo; /* index of its axiom (hoodoo) */
  int depth;       /* 0 for the base symbol */
  oc_vec3 base;    /* centre of its base; its axis is the local z */
  double size;     /* height s */
  double width;    /* half-width */
  double rho;      /* clamped resistance at its centre */
  double turn;     /* rotation about z, radians */
  double tilt;     /* tilt from the vertical, radians */
  double tilt_dir; /* azimuth of the tilt axis, radians */
  double aspect;   /* x / y half-width ratio (>= 1 / 1.3, <= 1.3) */
  uint64_t noise;  /* seed of its perturbation */
} oc_hoodoo_symbol;

typedef struct oc_gen_hoodoos_params {
  oc_heightfield *heightfield; /* required: placement and ground level */
  oc_node *terrain; /* blended with the hoodoos; NULL: the default terrain
                    ** of the heightfield (oc_heightfield_terrain) */
  int no_terrain;   /* 1 (with terrain NULL): the hoodoos alone */
  oc_node *geology; /* resistance; NULL: rho = 0.5 everywhere */
  const oc_heightfield *mask; /* NULL, or a factor of P (clamped [0, 1]) */
  /* NULL, or a factor of P in [0, 1], called from the calling thread once
  ** per sample of the maximal set (anything else fails, NaN to abort). */
  double (*mask_fn)(void *ud, double x, double y);
  void *mask_ud;
  uint64_t seed;
  double radius;               /* Poisson spacing > 0 (5 cells) */
  double height_lo, height_hi; /* 0 < lo <= hi (4 and 10 cells) */
  double width;        /* half-width of the base symbol > 0 (0.3 radius) */
  double margin;       /* >= 0: kept from the grid's edges (4 cells) */
  int max_depth;       /* symbols per hoodoo, 2 .. OC_HOODOO_MAX_DEPTH (6) */
  double p_block;      /* in [0, 1] (0.5) */
  double p_cone;       /* in [0, 1] (0.5) */
  double shrink;       /* lambda in [0.1, 1] (0.85) */
  double tilt;         /* radians in [0, 0.5] (0.1) */
  double roughness;    /* perturbation, fraction of the falloff, [0, 1]
                       ** (0.3) */
  double probability;  /* in [0, 1] (1) */
  double slope;        /* favoured slope, rise over run >= 0 (0.6) */
  double slope_spread; /* > 0 (0.4) */
  double drainage;     /* A0 in m^2 > 0 (20 cells^2) */
  double threshold;    /* T; 0: OC_DEFAULT_THRESHOLD */
  oc_progress progress;
} oc_gen_hoodoos_params;

#define OC_HOODOO_MAX_DEPTH 64
#define OC_HOODOO_MAX_SYMBOLS 4000000

typedef struct oc_gen_hoodoos_stats {
  size_t hoodoos;    /* axioms kept */
  size_t primitives; /* symbols made, one primitive each */
  size_t blocks, cones, boxes;
  double seconds;
} oc_gen_hoodoos_stats;

/* The defaults above for hf (cell-relative sizes); hf may be NULL (cell
** 1). terrain, geology and masks NULL, seed 0. */
void oc_gen_hoodoos_defaults(oc_gen_hoodoos_params *p, oc_heightfield *hf);

/* Places and derives the hoodoos: their symbols, hoodoo after hoodoo
** (base first), go to a new array *out (free() it; NULL when none), the
** count to *n. st may be NULL. OC_OK, or OC_EINVAL naming the parameter,
** OC_ENOMEM, OC_ECANCEL. */
int oc_hoodoo_symbols(const oc_gen_hoodoos_params *p, oc_hoodoo_symbol **out,
                      size_t *n, oc_gen_hoodoos_stats *st, oc_error *err);

/* The solid of one symbol: a transformed, perturbed primitive of energy
** 2T (T = threshold, 0 for the default). */
oc_node *oc_hoodoo_symbol_node(const oc_hoodoo_symbol *s, double roughness,
                               double threshold, oc_error *err);

/* The blend of the terrain (when given) and one primitive per symbol.
** NULL with err when placement fails, or when no terrain is given and no
** hoodoo was placed. */
oc_node *oc_generate_hoodoos(const oc_gen_hoodoos_params *p,
                             oc_gen_hoodoos_stats *st, oc_error *err);

/* ---- generators: sea and river (gen/sea.c, gen/river.c, gen/stress.c) -- */

/* Shallow erosion (Paris et al. 2019, section 6.1). Both make negative point
** primitives of radius `radius` and energy -strength e(rho, sigma), with
** e(rho, sigma) = sigma (1 - rho)(1 - beta) + sigma beta, rho the geology
** at the sample clamped to [0, 1], and drop those with e < cutoff. Samples
** are the points where horizontal rays, cast from Poisson disk columns
** (radius `spacing`, sampled on the tiles of the footprint that hold
** candidates and merged in tile order, still `spacing` apart) at a height
** drawn per step, enter the current tree:
** step k marches the terrain blended with the primitives of steps < k, so
** each step bites further into what earlier ones carved (into soft rock
** most). Each returns blend(terrain, primitives...), the terrain first
** (NULL terrain: oc_terrain of the heightfield, falloff 4 cells), or with
** `no_terrain` the blend of the primitives alone (the rays still march the
** terrain; OC_EINVAL when nothing was carved). Draws
** are keyed by (seed, step, column): the same primitives for any thread
** count. OC_EINVAL naming the parameter, OC_ENOMEM, OC_ECANCEL. */
/* Cap on columns x steps of sea and river erosion (each column makes at
** most one point primitive per step), checked once the columns are
** sampled, before any ray is cast. */
#define OC_ERODE_MAX_PRIMITIVES 20000000

typedef struct oc_gen_sea_stats {
  size_t columns;    /* Poisson columns kept as candidates */
  size_t samples;    /* rays that found the surface, over all steps */
  size_t primitives; /* primitives made */
} oc_gen_sea_stats;

/* The parameters the sea and river generators share (oc_gen_sea_params
** and oc_gen_river_params hold them as `erode`); oc_gen_erode_defaults
** fills beta and cutoff, the generators' own defaults the rest. */
typedef struct oc_gen_erode_params {
  oc_heightfield *heightfield; /* required */
  oc_node *terrain; /* or NULL: oc_heightfield_terrain(heightfield) */
  int no_terrain;   /* 1: return the primitives alone */
  oc_node *geology; /* resistance; NULL: 0.5 everywhere */
  uint64_t seed;
  double radius;    /* of the point primitives, > 0 (0: the generator's) */
  double spacing;   /* Poisson radius > 0 (0: radius / 2) */
  double beta;      /* in [0, 1] (0.2): e(1, 1), the bite on the hardest rock */
  double strength;  /* > 0: energy = -strength e (sea 4, river 2) */
  double cutoff;    /* >= 0 (0.05): samples with a smaller e make nothing */
  int steps;        /* 1 .. 64: rounds on the updated tree (sea 3, river 2) */
  double threshold; /* T; 0: OC_DEFAULT_THRESHOLD */
  oc_progress progress;
} oc_gen_erode_params;

/* Zero, then beta 0.2 and cutoff 0.05 (strength and steps stay 0: the
** sea's and river's defaults set them). */
void oc_gen_erode_defaults(oc_gen_erode_params *e);

typedef struct oc_gen_sea_params {
  oc_gen_erode_params erode; /* radius 0: range; strength 4; steps 3 */
  double sea_level; /* finite; NaN: oc_heightfield_sea_level(heightfield),
                    ** the default */
  double range;     /* > 0: sigma falls off as g(|z - sea_level| / range);
                    ** columns lower than sea_level - range are not
                    ** sampled (8, the paper's figure 11) */
  double reach;     /* > 0: columns above sea_level + range are candidates
                    ** within this horizontal distance of the band, their
                    ** ray cast at a height drawn in the band (steep cliff
                    ** faces) (0: 2 radius) */
  int rays;         /* accessibility rays per column, 0 .. 4096; 0: alpha
                    ** = 1 (16) */
} oc_gen_sea_params;

/* Sea erosion: candidate columns within `range` of sea level (the
** heightfield's surface z = h is in [sea_level - range, sea_level +
** range]) cast their ray landward (up the slope) at z = h; cliff columns
** (above the band, within `reach` of it) at z drawn in the band, landward
** along the gradient of the distance to the band. sigma = w alpha, w the
** falloff above, alpha the column's accessibility (Miller 1994): the
** fraction of `rays` directions over the upper hemisphere (uniform in
** solid angle) along which the heightfield stays below the ray within 8
** radius, the rays leaving 1.5 cells seaward of where the column's ray
** first met the surface (a vertical cliff face sees about half the sky).
** It is measured once per column and kept for later steps, since from
** inside a cave the heightfield sees only the cliff above. */
void oc_gen_sea_defaults(oc_gen_sea_params *p);
oc_node *oc_generate_sea(const oc_gen_sea_params *p, oc_gen_sea_stats *st,
                         oc_error *err);

typedef struct oc_gen_river_params {
  oc_gen_erode_params erode; /* radius 0: 1.5 cells; strength 2; steps 2 */
  double power;              /* stream power A^(1/2) s above which a sample is
                             ** riverbed, > 0; 0: the 95th percentile of the grid */
  int banks;                 /* widening of the bed in cells, 0 .. 64 (3) */
  double depth; /* > 0: bank rays are cast at z drawn in [h - depth, h]
                ** (0: 3 radius) */
} oc_gen_river_params;

/* River erosion: sigma per sample is 1 on the riverbed (stream power >=
** power) and falls off linearly to 0 at `banks` + 1 cells from it (a small
** max-convolution of the bed with a tent). Bed columns (slope < 0.05)
** carve at z = h; bank columns cast their ray away from the river (up the
** slope) at z drawn in [h - depth, h], so walls are undercut where the
** rock is soft. oc_gen_sea_stats counts as for the sea. */
void oc_gen_river_defaults(oc_gen_river_params *p);
oc_node *oc_generate_river(const oc_gen_river_params *p, oc_gen_sea_stats *st,
                           oc_error *err);

/* ---- feature curves and diffusion (Hnaidi et al. 2010; lib/diffusion) -- */

/* A feature curve: a planar curve (a polyline, or cubic Bézier pieces
** pts[0..3], pts[3..6], ...) carrying constraint points at normalised arc
** length u in [0, 1]. Each point gives any of the categories below; along
** the curve each attribute is interpolated between the points that give
** it (the elevation h by a natural cubic spline in u, linearly with two
** points; every other attribute linearly) and held constant beyond the
** first and last of them. An attribute given by no point is absent (a
** radius defaults to 0). Reference counted, immutable. */
typedef struct oc_fcurve oc_fcurve;

enum {
  OC_FC_HEIGHT = 1, /* height: the strict elevation h */
  OC_FC_RADIUS = 2, /* radius: the half-width r of the strict plateau */
  OC_FC_SLOPE = 4,  /* left, right (degrees), extent_a, extent_b */
  OC_FC_NOISE = 8   /* amplitude, roughness */
};

typedef struct oc_fconstraint {
  double u;      /* in [0, 1], strictly increasing along the array */
  unsigned has;  /* OC_FC_* categories given */
  double height; /* finite */
  double radius; /* >= 0 metres, each side of the curve */
  /* slope angles in degrees, |angle| <= 89, left and right of the
  ** direction of travel: > 0 where the ground falls away from the curve
  ** (ridge flanks, cliffs), < 0 where it rises (riverbanks, cracks); the
  ** slope band runs from r to r + extent_a (left) or r + extent_b (right),
  ** extents >= 0 metres */
  double left, right, extent_a, extent_b;
  double amplitude; /* >= 0 metres */
  double roughness; /* in [0, 1] */
} oc_fconstraint;

typedef struct oc_fcurve_params {
  const double *xy; /* npoints pairs (x, y) */
  size_t npoints;   /* >= 2; with bezier, 3 k + 1 */
  int bezier;       /* 1: cubic Bézier pieces; 0: a polyline */
  const oc_fconstraint *constraints;
  size_t nconstraints; /* >= 2 */
} oc_fcurve_params;

/* A new feature curve (one reference: oc_fcurve_release), or NULL with
** err naming the field ('points', 'constraints[2].u', ...). */
oc_fcurve *oc_fcurve_new(const oc_fcurve_params *p, oc_error *err);
void oc_fcurve_retain(oc_fcurve *c);
void oc_fcurve_release(oc_fcurve *c);
double oc_fcurve_length(const oc_fcurve *c); /* xy arc length */
unsigned oc_fcurve_has(const oc_fcurve *c);  /* OC_FC_* of any point */

/* The curve at normalised arc length u (clamped to [0, 1]): the point,
** the unit tangent and every attribute interpolated (absent ones 0; `has`
** says which are present). */
typedef struct oc_fcurve_sample {
  double x, y, tx, ty;
  unsigned has;
  double height, radius, left, right, extent_a, extent_b, amplitude, roughness;
} oc_fcurve_sample;
int oc_fcurve_sample_at(const oc_fcurve *c, double u, oc_fcurve_sample *out);

/* The compact encoding of a curve (lib/diffusion/fcodec.c), version 2: a
** bit stream of Exp-Golomb codes, coordinates in 1/8 m (second
** differences), u in 1/4096 (omitted when evenly spaced), heights, radii
** and extents in 1/8 m, angles in 1/64 degree, amplitude in 1/64 m,
** roughness in 1/1024, each attribute from its previous value, a
** symmetric slope's right side omitted; version 1 (LEB128 varints)
** still decodes. oc_fcurve_encode writes at most cap bytes to buf (NULL to
** measure) and returns the length of the whole encoding, 0 when a value
** is too large to quantise (beyond 2^49 m); oc_fcurve_decode builds the
** quantised curve (one reference) or NULL with err. */
size_t oc_fcurve_encode(const oc_fcurve *c, unsigned char *buf, size_t cap);
oc_fcurve *oc_fcurve_decode(const unsigned char *buf, size_t n, oc_error *err);

typedef enum oc_diffusion_scheme {
  /* F_G = (|nx| F(i - sx, j) + |ny| F(i, j - sy) - G) / (|nx| + |ny|):
  ** exact on planes in every direction */
  OC_DIFFUSION_UPWIND = 0,
  /* the paper's printed F_G = nx^2 F(i - sx, j) + ny^2 F(i, j - sy) - G:
  ** slopes up to sqrt 2 too steep at 45 degrees */
  OC_DIFFUSION_PAPER
} oc_diffusion_scheme;

#define OC_DIFFUSION_MAX_CYCLES 64
/* Grids of at most this many samples (6 floats each while solving). */
#define OC_DIFFUSION_MAX_SAMPLES (1ull << 26)

typedef struct oc_diffusion_params {
  oc_heightfield_grid grid;
  oc_fcurve *const *curves;
  size_t ncurves;
  uint64_t seed;
  oc_diffusion_scheme scheme;
  /* 0: the paper's cascade, 5 (l - i) Jacobi sweeps at level i of l (0
  ** the coarsest); > 0: from the cascade, V-cycles (Gauss-Seidel
  ** smoothing, Galerkin coarse operators), and once they stall BiCGSTAB
  ** preconditioned by V-cycles, until the largest update of each
  ** diffused map is at most tolerance times its constraints' scale (at
  ** most OC_DIFFUSION_MAX_CYCLES steps) */
  double tolerance;
  double wavelength; /* lambda_0 metres (> 0; 0: the grid's extent / 8) */
  int octaves;       /* n + 1 in 1..16 (0: 4) */
  double ratio;      /* r > 1 (0: 2) */
  int maps;          /* 1: fill the inspection grids of the result */
  oc_progress progress;
} oc_diffusion_params;

typedef struct oc_diffusion_result {
  oc_heightfield *height; /* smooth + detail */
  /* with maps only (else NULL): the smooth elevation, the noise detail,
  ** the diffused amplitude and roughness, and the diffused slope tan
  ** theta (> 0 where the ground falls along the guide direction) */
  oc_heightfield *smooth, *detail, *amplitude, *roughness, *gradient;
  int levels; /* grids of the multigrid pyramid */
  /* steps of the elevation's solve (V-cycles, then BiCGSTAB iterations),
  ** and its largest update (metres) after the cascade and after each
  ** step */
  int cycles;
  double residual[OC_DIFFUSION_MAX_CYCLES + 1];
  size_t strict, slope, conflict; /* constrained samples of the finest grid */
} oc_diffusion_result;

/* The terrain of the curves on p->grid: constraint maps rasterised,
** gradient (n, norm), elevation guided by them, amplitude and roughness
** diffused by multigrid, plus the noise detail
** N = A sum_{k<octaves} r^(-k (1 - R)) S(r^k p / lambda_0), S the simplex
** noise of lib/core scaled to [-1, 1]. Parallel, byte-identical for any
** thread count, cancellable (OC_ECANCEL). Fills *out (the caller
** releases its grids with oc_diffusion_result_clear); OC_OK or an error
** naming the field ('curves', 'size', ...). */
int oc_diffusion(const oc_diffusion_params *p, oc_diffusion_result *out,
                 oc_error *err);
void oc_diffusion_result_clear(oc_diffusion_result *r);

/* ---- hashes (provenance) --------------------------------------------- */

/* SHA-256 (FIPS 180-4): the hash of a scene file and of every input file a
** run read, recorded in the metadata of what it wrote. Incremental: init,
** update any number of times with any lengths, final. The state is a
** plain struct the caller owns; nothing is allocated. */
#define OC_SHA256_BYTES 32
#define OC_SHA256_HEX 65 /* 64 lowercase hex digits and the NUL */

typedef struct oc_sha256 {
  uint32_t h[8];
  uint64_t bytes; /* message length so far */
  unsigned char block[64];
  size_t n; /* bytes waiting in block */
} oc_sha256;

void oc_sha256_init(oc_sha256 *s);
void oc_sha256_update(oc_sha256 *s, const void *data, size_t n);
/* Writes the digest; s must be initialized again before reuse. */
void oc_sha256_final(oc_sha256 *s, unsigned char out[OC_SHA256_BYTES]);
/* The digest as lowercase hex, NUL terminated. */
void oc_sha256_hex(const unsigned char d[OC_SHA256_BYTES],
                   char hex[OC_SHA256_HEX]);
/* One call: the hex digest of n bytes. */
void oc_sha256_text(const void *data, size_t n, char hex[OC_SHA256_HEX]);

/* The SHA-256 of the regular file `path` as lowercase hex in `hex`
** (OC_SHA256_HEX bytes), for provenance. Refuses FIFOs, devices and
** folders without blocking, but takes any content. OC_OK, or OC_EIO with
** a message naming the path. (lib/io/infile.c) */
int oc_infile_sha256(const char *path, char *hex, oc_error *err);

/* ---- material layers (Peytavie et al. 2009) (layers/) ------------------ */

/* A 2D grid of material stacks: stack (i, j), 0 <= i < nx, 0 <= j < ny,
** is the square of side `cell` centred on (x0 + i cell, y0 + j cell) (as
** the samples of a heightfield), and holds layers bottom-up from the
** common base elevation `zbase`; above its last layer is air. Layers are
** kept canonical: no empty layer, adjacent layers of one material merged,
** and between two bedrock layers (and below the first, above the last)
** sand, rocks, water, air upwards (the paper sorts sand, rocks, air;
** water just below air is outcrop's choice). A layer is packed in 4
** bytes (its thickness rounded to 21 bits of mantissa, a relative error
** of at most 2^-22, and its material), plus 1.25 bytes a stack (4 once a
** stack holds more than 255 layers).
** Mutable, with one owner: oc_stacks_new and the converters return a grid
** the caller frees with oc_stacks_free; edits are not thread-safe, the
** work inside them runs on both cores with results independent of the
** thread count. */
typedef struct oc_stacks oc_stacks;

typedef enum oc_material {
  OC_MAT_AIR = 0,
  OC_MAT_WATER,
  OC_MAT_SAND,
  OC_MAT_ROCKS,
  OC_MAT_BEDROCK,
  OC_MAT_COUNT
} oc_material;

/* "air", "water", "sand", "rocks", "bedrock"; NULL out of range. */
const char *oc_material_name(int m);
/* The material named `name`, or -1. */
int oc_material_parse(const char *name);

/* Stacks per grid at most (as heightfields), and layers in all. */
#define OC_STACKS_MAX (1ull << 28)
#define OC_STACKS_MAX_LAYERS (1ull << 31)

/* nx, ny in 1 .. 65535 and nx ny <= OC_STACKS_MAX; cell > 0; finite
** origin and base. Every stack starts empty (all air). */
oc_stacks *oc_stacks_new(int nx, int ny, double cell, double x0, double y0,
                         double zbase, oc_error *err);
void oc_stacks_free(oc_stacks *s);

int oc_stacks_nx(const oc_stacks *s);
int oc_stacks_ny(const oc_stacks *s);
double oc_stacks_cell(const oc_stacks *s);
void oc_stacks_origin(const oc_stacks *s, double *x0, double *y0);
double oc_stacks_base(const oc_stacks *s);

/* Replaces the layers of stack (i, j) by n layers (materials and
** thicknesses, bottom-up; each thickness finite and >= 0), made
** canonical. Rewrites the grid's tail: O(layers). OC_OK or OC_EINVAL
** naming 'i', 'j', 'material' or 'thickness'. */
int oc_stacks_set(oc_stacks *s, int i, int j, const uint8_t *mat,
                  const double *thick, size_t n, oc_error *err);
/* Every stack set to the same n layers (checked as oc_stacks_set). */
int oc_stacks_fill(oc_stacks *s, const uint8_t *mat, const double *thick,
                   size_t n, oc_error *err);
/* The layer count of stack (i, j); the first `max` layers go to mat and
** thick (either may be NULL). */
size_t oc_stacks_get(const oc_stacks *s, int i, int j, uint8_t *mat,
                     double *thick, size_t max);

typedef struct oc_stacks_stats {
  size_t stacks, layers, bytes; /* bytes: the grid's own arrays */
} oc_stacks_stats;
void oc_stacks_get_stats(const oc_stacks *s, oc_stacks_stats *st);
/* Volume of material m in m^3 (thicknesses times cell^2). */
double oc_stacks_volume(const oc_stacks *s, int m);
/* A heightfield of the grid's shape: the top of the highest layer of
** material m in each stack (zbase where there is none). The caller
** releases it. */
oc_heightfield *oc_stacks_heightfield(const oc_stacks *s, int m, oc_error *err);

/* From a heightfield: one stack per sample, bedrock from zbase (default:
** 1 below the lowest sample when zbase is NaN) to the sample, and `sand`
** metres of sand on it (>= 0). */
typedef struct oc_stacks_hf_params {
  double zbase; /* NaN: the lowest sample - 1 */
  double sand;  /* >= 0 */
} oc_stacks_hf_params;
oc_stacks *oc_stacks_from_heightfield(const oc_heightfield *hf,
                                      const oc_stacks_hf_params *p,
                                      oc_error *err);

/* From a compiled field: stacks of side `cell` whose centres cover
** box's x and y ([lo, hi] inclusive, floor((hi - lo) / cell) + 1 of
** them), each layering the column [box.lo.z, box.hi.z] at every f = T
** crossing (material inside, air outside; found by sampling every
** `step` (default cell / 4 when 0) where the column spans say f may
** vary, then bisection to 1e-6 cell). zbase = box.lo.z. Parallel by
** rows; `progress` (may hold NULL) can cancel it: NULL with OC_ECANCEL. */
typedef struct oc_stacks_node_params {
  oc_aabb box;
  double cell, step;
  int material;         /* OC_MAT_*, not air */
  oc_progress progress; /* may be {NULL, NULL} */
} oc_stacks_node_params;
oc_stacks *oc_stacks_from_program(const oc_program *prog,
                                  const oc_stacks_node_params *p,
                                  oc_error *err);

/* The convolution surface of the materials in `mask` (bits 1 << OC_MAT_*):
** f(p) = 2T V_M(p) / V_Omega, V_M the volume of those materials inside
** the cube Omega of half-side sigma around p (V_Omega = 8 sigma^3): T
** where the cube is half full. A snapshot: later edits of the grid do not
** change the node. sigma > 0 (NaN: one cell). */
oc_node *oc_stacks_field(const oc_stacks *s, unsigned mask, double sigma,
                         oc_error *err);

/* The visible ratio of `material` (OC_MAT_*, not air) around p, a weight
** for texturing (Peytavie et al. 2009, section 6): the share of the
** surface inside the cube of half-side sigma around p whose exposed
** material is `material`. The surface is each stack's exposed boundaries
** (a solid layer's top under air or water, its underside over them),
** counted by the stack's overlap with the cube's footprint times the tent
** 1 - |b - z| / sigma of its height b; plus 1e-6 times the volume ratio,
** which decides where no boundary is within sigma (a cliff face). Weights
** of the materials are meant to be normalised (as a colour blend does):
** f = sum over boundaries / (4 sigma^2) is not a distance. A snapshot;
** sigma > 0 (NaN: one cell). */
oc_node *oc_stacks_visible(const oc_stacks *s, int material, double sigma,
                           oc_error *err);

/* Stabilisation by the angle of repose (section 3.4). For sand, then
** rocks, until no transfer exceeds `tolerance`: every stack with material
** m at height h (the top of m in its segment between bedrock layers)
** moves to each of its 8 neighbours i an amount proportional to
** dh~_i = dh_i - t_i where dh_i = h - h_i > t_i, h_i the top of the solid
** in the neighbour's segment holding elevation h, t_i = cell tan(alpha)
** (sides) or cell sqrt(2) tan(alpha) (diagonals); the total moved is
** rate * max dh~_i capped by the material present, and each transfer by
** an eighth of the air of the receiving segment. For a large pile,
** coarse levels first (neighbours k = 8, 4, 2 stacks away down a slope,
** thresholds and tolerance times k; the first k from the extent of the
** unstable stacks) bring it near rest in few passes; the last level (the
** 8 neighbours) decides it. Double-buffered: the
** result does not depend on the thread count. Volume is conserved to
** rounding. */
typedef struct oc_stabilize_params {
  double angle[OC_MAT_COUNT]; /* degrees in (0, 90): sand and rocks read */
  double rate;                /* (0, 0.5] */
  double tolerance;           /* > 0, metres */
  long iterations;            /* per material, >= 1 */
  int region[4];              /* i0, j0, i1, j1 of the stacks first
                              ** examined (inclusive); i1 < i0: all */
} oc_stabilize_params;
typedef struct oc_stabilize_result {
  long iterations; /* passes over both materials */
  int converged;   /* 1: no transfer exceeds the tolerance */
  double moved;    /* m^3 moved in all */
} oc_stabilize_result;
/* sand 32, rocks 42 degrees; rate 0.25; tolerance 1e-3 cell; 100000
** iterations; the whole grid. */
void oc_stabilize_defaults(const oc_stacks *s, oc_stabilize_params *p);
int oc_stacks_stabilize(oc_stacks *s, const oc_stabilize_params *p,
                        oc_stabilize_result *res, oc_error *err);

/* Deposit (section 4): amount A g(|p - c| / R) metres of sand, rocks or
** water on top of every stack whose centre p lies within R of c (g the
** engine's falloff (1 - x^2)^3), then stabilisation from that region when
** `stabilize` (p->stab; NULL: defaults). *added gets the volume added
** (m^3). */
typedef struct oc_deposit_params {
  double cx, cy, radius, amount;
  int material; /* sand, rocks or water */
  int stabilize;
  const oc_stabilize_params *stab;
} oc_deposit_params;
int oc_stacks_deposit(oc_stacks *s, const oc_deposit_params *p, double *added,
                      oc_stabilize_result *res, oc_error *err);

/* Erosion (section 4): bedrock of the stacks whose centres lie in
** [x0, x1] x [y0, y1] turned into loose material, `ratio` of it sand and
** the rest rocks (volume conserved), then stabilised from that region when
** `stabilize`. OC_STACKS_ERODE_SURFACE: the top `depth` metres of each stack's
** highest bedrock; OC_STACKS_ERODE_COLLAPSE: every bedrock roof (a bedrock
*layer
** over air) at most `depth` thick, whose debris falls to the floor below.
** *eroded gets the bedrock volume turned (m^3). */
typedef enum oc_stacks_erode_mode {
  OC_STACKS_ERODE_SURFACE,
  OC_STACKS_ERODE_COLLAPSE
} oc_stacks_erode_mode;
typedef struct oc_stacks_erode_params {
  double x0, y0, x1, y1;
  double ratio; /* [0, 1]: the sand fraction */
  double depth; /* > 0 */
  oc_stacks_erode_mode mode;
  int stabilize;
  const oc_stabilize_params *stab; /* NULL: defaults */
} oc_stacks_erode_params;
int oc_stacks_erode(oc_stacks *s, const oc_stacks_erode_params *p,
                    double *eroded, oc_stabilize_result *res, oc_error *err);

/* Sculpting (section 4): the bedrock's convolution surface f (sigma one
** cell) plus or minus strength 2T K(|p - c'| / R), K(x) = (1 - x^2)^2,
** with c' offset by delta from c along the surface normal at c (inward
** when adding, outward when carving); the stacks within R of c' are
** rebuilt inside [c'.z - R, c'.z + R] from the crossings of f' = T along
** their axes (bedrock where f' > T, elsewhere air where there was bedrock
** and the material there before), then stabilised from that region.
** *changed gets the bedrock volume added (negative: removed), m^3. */
typedef struct oc_sculpt_params {
  oc_vec3 center;
  double radius;    /* > 0 */
  double strength;  /* > 0 */
  double delta;     /* NaN: radius / 2 */
  int carve;        /* 0: add */
  double threshold; /* T; 0: OC_DEFAULT_THRESHOLD */
  int stabilize;
  const oc_stabilize_params *stab; /* NULL: defaults */
} oc_sculpt_params;
int oc_stacks_sculpt(oc_stacks *s, const oc_sculpt_params *p, double *changed,
                     oc_stabilize_result *res, oc_error *err);

/* Sweeping (section 4.2): a graph of `npoints` points joined by `nedges`
** arcs (pairs of point indices from 0), each point carrying a profile: a
** closed cross-section, the Catmull-Rom spline through its control
** points (u, v) (u across the arc, to the right of travel; v along the
** up vector; non-convex allowed). The profiles, interpolated along each
** arc, sweep a volume V, with its arcs' ends (grouped by the points'
** coordinates) cut square where an end is alone, mitred where two meet,
** and where three or more meet (branches) the profile turned about the
** up vector past them, closing the joint; bedrock inside V becomes air (the
** difference), other materials stay and settle, and the stacks around
** are stabilised. Cracks (tunnel = 0): points are projected on the top of
** the solid (their z ignored) and the up vector is the surface normal
** there; tunnels: points are used as given, up is the vertical. Profile
** k is the pairs profile_off[k] .. profile_off[k + 1] - 1 of profile_uv
** (3 .. 1024 points). *changed gets the bedrock volume added (negative),
** m^3. */
#define OC_SWEEP_MAX_POINTS 100000
typedef struct oc_sweep_params {
  const oc_vec3 *points;
  const int *point_profile; /* per point: 0 .. nprofiles - 1 */
  size_t npoints;
  const int *edges; /* 2 nedges point indices */
  size_t nedges;
  const double *profile_uv;
  const size_t *profile_off; /* nprofiles + 1 */
  size_t nprofiles;
  int tunnel;
  int stabilize;
  const oc_stabilize_params *stab; /* NULL: defaults */
} oc_sweep_params;
int oc_stacks_sweep(oc_stacks *s, const oc_sweep_params *p, double *changed,
                    oc_stabilize_result *res, oc_error *err);
/* Rock piles (section 5): a rock tile is a block tile (oc_btile, freed
** with oc_btile_free; oc_btile_block, _node, _planes work on it) whose
** blocks are rocks: the Voronoi cells of periodic maximal Poisson sites
** in the cube [0, size)^3, eroded by `erosion` r except around `contacts`
** random points on each face shared with a neighbour (resistance
** exp(-|p - c|^2 / (spread r)^2)), as convex blocks. Rocks are convex,
** inside their cells (disjoint) and touch at the contacts; a block's
** centroid is its Voronoi site. Deterministic by seed. */
typedef struct oc_rocks_params {
  double size;     /* side of the tile (m), >= 4 radius; default 8 */
  double radius;   /* r: sites at least r apart, > 0; default 1.5 */
  double erosion;  /* depth eroded, in r, [0, 0.45]; default 0.3 */
  double spread;   /* width of the resistance, in r, > 0; default 1 */
  int contacts;    /* per shared face, 1 .. 8; default 1 */
  double rounding; /* of the blocks' smooth intersection, in r; 0.15 */
  double width;    /* W of the blocks' fields (m), > 0; default 0.75 */
  uint64_t seed;
} oc_rocks_params;
void oc_rocks_defaults(oc_rocks_params *p);
/* A new tile, or NULL with err (OC_EINVAL naming the parameter,
** OC_ENOMEM). At most 20000 rocks. */
oc_btile *oc_rocks_tile(const oc_rocks_params *p, oc_error *err);
/* The largest distance from a rock's site to its vertices. */
double oc_rocks_reach(const oc_btile *t);

/* The rocks of `tile` placed over the stacks (the blocks' replication):
** a rock of each tile cell is an instance when its site lies in a rocks
** layer at most `depth` below the top of the solid above it (deeper
** rocks are hidden and culled). The node is max(ground, instances);
** ground NULL: the stacks' bedrock and sand convolution surface (sigma one
** cell). oc_blocks_instances and oc_blocks_instance list the instances.
** Presence is decided now (later edits of the stacks do not move rocks).
** A new node, or NULL with err. */
typedef struct oc_stacks_rocks_params {
  double depth;     /* NaN: twice oc_rocks_reach */
  double threshold; /* T; 0: OC_DEFAULT_THRESHOLD */
} oc_stacks_rocks_params;
oc_node *oc_stacks_rocks(const oc_stacks *s, const oc_btile *tile,
                         oc_node *ground, const oc_stacks_rocks_params *p,
                         oc_error *err);

#ifdef __cplusplus
}
#endif
#endif
