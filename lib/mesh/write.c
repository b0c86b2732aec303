/*
** write.c — oc_mesh_write: the format from the extension (any case), a
** check that the mesh can be written at all, then the format's encoder
** into an atomic output, in the C locale so that numbers in text always
** use a decimal point whatever locale the host program set.
*/
#include <fcntl.h>
#include <locale.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"
#include "io/metatext.h"
#include "mesh/write.h"

static const struct {
  const char *ext;
  int (*write)(const oc_mesh *, oc_atomic *, oc_error *);
  int (*fits)(const oc_mesh *, const char *, oc_error *);
} formats[] = {
    {".ply", oc_mesh_write_ply, NULL},
    {".obj", oc_mesh_write_obj, NULL},
    {".glb", oc_mesh_write_glb, oc_mesh_glb_fits},
};

/* The extension of the last path component, or NULL. */
static const char *extension(const char *path) {
  const char *slash = strrchr(path, '/');
  const char *base = slash ? slash + 1 : path;
  const char *dot = strrchr(base, '.');
  return dot && dot != base ? dot : NULL;
}

/* The file formats cannot carry what a broken mesh holds (an index past
** the vertices, NaN in a glTF bound or in OBJ text), so such a mesh is
** refused instead of written as a file other tools would reject. */
static int check_mesh(const oc_mesh *m, const char *path, oc_error *err) {
  for (size_t i = 0; i < 3 * m->nt; i++)
    if (m->tri[i] >= m->nv)
      return oc_seterr(err, OC_EINVAL,
                       "cannot write '%s': triangle %zu uses vertex %lu, but "
                       "the mesh has %zu vertices",
                       path, i / 3, (unsigned long)m->tri[i], m->nv);
  for (size_t i = 0; i < 3 * m->nv; i++) {
    if (!isfinite(m->pos[i]))
      return oc_seterr(err, OC_EINVAL,
                       "cannot write '%s': vertex %zu has a non-finite "
                       "position",
                       path, i / 3);
    if (!isfinite(m->nrm[i]))
      return oc_seterr(err, OC_EINVAL,
                       "cannot write '%s': vertex %zu has a non-finite "
                       "normal",
                       path, i / 3);
  }
  return OC_OK;
}

int oc_mesh_write_meta_lines(const oc_mesh *m, oc_atomic *a, const char *prefix,
                             oc_error *err) {
  for (size_t i = 0; i < m->meta.n; i++) {
    const oc_kv *e = &m->meta.v[i];
    char *q = malloc(oc_meta_quoted_size(e->value));
    if (!q)
      return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory",
                       a->path);
    size_t n = oc_meta_quote(e->value, q);
    oc_atomic_write(a, prefix, strlen(prefix));
    oc_atomic_write(a, e->key, strlen(e->key));
    oc_atomic_write(a, "=", 1);
    oc_atomic_write(a, q, n);
    oc_atomic_write(a, "\n", 1);
    free(q);
  }
  return OC_OK;
}

int oc_mesh_write(const oc_mesh *mesh, const char *path, oc_error *err) {
  return oc_mesh_write_at(mesh, AT_FDCWD, path, err);
}

int oc_mesh_write_at(const oc_mesh *mesh, int dirfd, const char *path,
                     oc_error *err) {
  if (!mesh) return oc_seterr(err, OC_EINVAL, "'mesh' is NULL");
  if (!path || !*path)
    return oc_seterr(err, OC_EINVAL, "'path' must be a non-empty file name");
  const char *ext = extension(path);
  int k = -1;
  for (int i = 0; ext && i < (int)(sizeof formats / sizeof *formats); i++)
    if (strcasecmp(ext, formats[i].ext) == 0) k = i;
  if (k < 0)
    return oc_seterr(err, OC_EINVAL,
                     "cannot write '%s': unknown mesh format (use .ply, .obj "
                     "or .glb)",
                     path);
  int rc = formats[k].fits ? formats[k].fits(mesh, path, err) : OC_OK;
  if (rc == OC_OK) rc = check_mesh(mesh, path, err);
  if (rc) return rc;

  locale_t c = newlocale(LC_ALL_MASK, "C", (locale_t)0);
  if (c == (locale_t)0)
    return oc_seterr(err, OC_ENOMEM, "cannot write '%s': out of memory", path);
  oc_atomic a;
  rc = oc_atomic_begin_at(&a, dirfd, path, err);
  if (rc == OC_OK) {
    locale_t prev = uselocale(c); /* this thread only */
    rc = formats[k].write(mesh, &a, err);
    uselocale(prev);
    if (rc == OC_OK)
      rc = oc_atomic_commit(&a, err);
    else
      oc_atomic_abort(&a);
  }
  freelocale(c);
  return rc;
}
