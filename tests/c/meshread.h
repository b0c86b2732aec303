/*
** meshread.h — a mesh file reader and checker for the tests, written
** without lib/: it parses the files the writers produced (PLY binary
** little-endian, OBJ, GLB with its JSON chunk) and measures the mesh
** (closedness, orientation, duplicates, degenerate triangles, Euler
** characteristic, enclosed volume). Any test may use it:
**
**   char why[256];
**   mr_mesh *m = mr_read(path, why, sizeof why);
**   ck_assert_msg(m, "%s", why);
**   mr_report r;
**   mr_check(m, &r);
**   ck_assert_msg(r.closed && r.consistent && r.outward, "%s",
**                 mr_report_str(&r, buf, sizeof buf));
**   mr_free(m);
**
** The reader is strict: anything the format forbids, or anything outcrop
** never writes and the reader does not understand, fails the read with
** the reason in `why`. For GLB it also validates the structure: chunk
** layout and padding, every accessor inside its bufferView, every
** bufferView inside the buffer, alignment, attribute formats, POSITION
** min/max equal to the data (compared as float, as glTF does).
*/
#ifndef MESHREAD_H
#define MESHREAD_H

#include <stddef.h>
#include <stdint.h>

/* ---- JSON (for the GLB JSON chunk) -------------------------------------- */

typedef enum mr_jtype {
  MR_JNULL,
  MR_JFALSE,
  MR_JTRUE,
  MR_JNUMBER,
  MR_JSTRING,
  MR_JARRAY,
  MR_JOBJECT
} mr_jtype;

typedef struct mr_json {
  mr_jtype type;
  double number;         /* MR_JNUMBER */
  char *string;          /* MR_JSTRING: UTF-8, NUL-terminated */
  size_t n;              /* MR_JARRAY elements, MR_JOBJECT members */
  struct mr_json *items; /* the n values, in file order */
  char **keys;           /* MR_JOBJECT: the n keys (unique) */
} mr_json;

/* Parses `len` bytes holding exactly one JSON value (surrounded by
** whitespace only). NULL with the reason in `why` on any syntax error,
** duplicate key or nesting deeper than 64. Free with mr_json_free. */
mr_json *mr_json_parse(const char *text, size_t len, char *why, size_t whysize);
void mr_json_free(mr_json *v);
/* The member `key` of an object, element i of an array: NULL when `v` is
** NULL, of another type, or has no such member or element. */
const mr_json *mr_json_get(const mr_json *v, const char *key);
const mr_json *mr_json_at(const mr_json *v, size_t i);
/* A string value's text, or NULL. */
const char *mr_json_str(const mr_json *v);

/* ---- meshes ------------------------------------------------------------- */

typedef enum mr_format { MR_PLY, MR_OBJ, MR_GLB } mr_format;

typedef struct mr_mesh {
  mr_format format;
  size_t nv, nt;
  float *pos;    /* 3 per vertex */
  float *nrm;    /* 3 per vertex, or NULL when the file has no normals */
  float *col;    /* 3 per vertex in [0, 1] (PLY uchar: value / 255), or NULL */
  uint32_t *tri; /* 3 per triangle, each < nv */
  /* PLY: the first comment; OBJ: the first comment line without "# ";
  ** GLB: asset.generator. Empty when absent. */
  char generator[128];
  /* GLB only (else NULL / 0): the parsed JSON chunk and chunk sizes. */
  mr_json *gltf;
  size_t json_length, bin_length;
} mr_mesh;

/* Reads a .ply, .obj or .glb file (format from the extension, any case;
** the PLY and GLB magic must agree). NULL with the reason in `why`. */
mr_mesh *mr_read(const char *path, char *why, size_t whysize);
void mr_free(mr_mesh *m);
/* Turns a GLB mesh's glTF axes (+Y up) back into outcrop's (+Z up):
** glTF (X, Y, Z) is engine (X, -Z, Y), positions and normals. Exact (a
** permutation and a negation), so the floats equal those written. */
void mr_gltf_to_engine(mr_mesh *m);

typedef struct mr_report {
  size_t vertices, triangles;
  size_t referenced;           /* vertices used by some triangle */
  size_t edges;                /* distinct undirected edges */
  size_t boundary_edges;       /* used by one triangle */
  size_t nonmanifold_edges;    /* used by more than two */
  size_t misoriented_edges;    /* used by two, in the same direction */
  size_t duplicate_vertices;   /* same position as another vertex */
  size_t degenerate_triangles; /* a repeated index or zero area */
  size_t components;           /* connected by shared vertices */
  long euler;                  /* referenced - edges + triangles */
  int closed;     /* triangles > 0, no boundary or non-manifold edge */
  int consistent; /* every edge used once in each direction (boundary
                  ** edges once); no non-manifold edge */
  int outward;    /* closed, consistent and volume > 0 */
  double volume;  /* divergence theorem; meaningful when closed */
  double area;
  double lo[3], hi[3]; /* bounds of the referenced vertices */
  /* With normals: the largest | |n| - 1 |, and how many referenced
  ** vertices have a normal pointing against the area-weighted normal of
  ** their triangles. */
  double normal_length_error;
  size_t normals_against;
} mr_report;

void mr_check(const mr_mesh *m, mr_report *r);
/* One line summarizing the report, for assertion messages; returns buf. */
const char *mr_report_str(const mr_report *r, char *buf, size_t size);

/* ---- files -------------------------------------------------------------- */

/* The whole file, malloc'ed (free it), or NULL; *len gets its size. */
unsigned char *mr_slurp(const char *path, size_t *len);
/* 1 when both files exist and hold the same bytes. */
int mr_same_bytes(const char *a, const char *b);

#endif
