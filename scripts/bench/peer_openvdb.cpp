/*
** peer_openvdb.cpp — our mesher against OpenVDB's volumeToMesh on the
** same sampled shape (issue 3, mesh.vs_peer). Optional: built only when
** libopenvdb-dev is installed (`make bench-peer-deps`).
**
** The scene is bench_mesh.c's mesh.spheres1000 one, built the same way:
** 1000 spheres blended with a ground plane, box [-13.75, 113.75]^2 x
** [-5, 122.5], cell 0.25, T = 0.5, 2 threads.
**
** What is compared: OpenVDB gets a FloatGrid already holding T - f at
** our polygonizer's sample points (inside negative, iso-value 0), so its
** time is extraction only; ours is oc_polygonize end to end, sampling the
** field included. The grid is sampled by this program through the C API
** (not timed against the peer: it is our engine's work) and then reduced
** to a narrow band, the input volumeToMesh is built for (the voxels with
** a sign change to a face neighbour, dilated by one; the rest inactive
** tiles of the right sign). Prints `name: value unit` lines; '#' lines
** are context.
*/
#include <openvdb/openvdb.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/rng.h"
#include "outcrop.h"

/* libopenvdb already holds these instantiations; declaring them here keeps
** this file from instantiating the grid's I/O code, which would make it
** link against Imath directly (the Makefile links -lopenvdb -ltbb only). */
extern template class openvdb::tree::LeafBuffer<float, 3>;
extern template class openvdb::tree::LeafNode<float, 3>;
extern template class openvdb::tree::InternalNode<
    openvdb::tree::LeafNode<float, 3>, 4>;
extern template class openvdb::tree::InternalNode<
    openvdb::tree::InternalNode<openvdb::tree::LeafNode<float, 3>, 4>, 5>;
extern template class openvdb::tree::RootNode<
    openvdb::FloatTree::RootNodeType::ChildNodeType>;
extern template class openvdb::tree::Tree<openvdb::FloatTree::RootNodeType>;
extern template class openvdb::Grid<openvdb::FloatTree>;

namespace {

const double CELL = 0.25;
const oc_aabb BOX = {{-13.75, -13.75, -5}, {113.75, 113.75, 122.5}};
const int MAXSPANS = 64;

oc_node *must(oc_node *n, const oc_error &err) {
  if (!n) {
    std::fprintf(stderr, "peer_openvdb: %s\n", err.msg);
    std::exit(1);
  }
  return n;
}

/* Exactly bench_mesh.c's spheres1000 scene: same stream, same draws in
** the same order. */
oc_node *spheres1000() {
  oc_error err;
  oc_rng r = oc_rng_stream(1000, 3);
  std::vector<oc_node *> k(1001);
  k[0] = must(oc_plane({0, 0, 0}, {0, 0, 1}, 1, 1, &err), err);
  for (int i = 1; i <= 1000; i++) {
    /* separate statements: the draws must happen in x, y, z order */
    double x = oc_rng_range(&r, 0, 100);
    double y = oc_rng_range(&r, 0, 100);
    double z = oc_rng_range(&r, 0, 20);
    double rad = oc_rng_range(&r, 1, 3);
    k[i] = must(oc_sphere({x, y, z}, rad, 1, 1, &err), err);
  }
  oc_node *b = must(oc_blend(k.data(), k.size(), &err), err);
  for (oc_node *n : k)
    oc_node_release(n);
  return b;
}

/* ---- sampling the grid ------------------------------------------------- */

/* Sample lattice: voxel (i, j, k) is the point lo + (idx + off) * CELL. */
struct lattice {
  int nx, ny, nz;
  double off;
  double x(int i) const { return BOX.lo.x + (i + off) * CELL; }
  double y(int j) const { return BOX.lo.y + (j + off) * CELL; }
  double z(int k) const { return BOX.lo.z + (k + off) * CELL; }
};

/* A run of voxels k0 <= k < k1 in column i; values at vals[off..]. */
struct run {
  int i, k0, k1;
  size_t off;
};
struct row {
  std::vector<run> runs;
  std::vector<float> vals;
  size_t evals = 0;
};

/* One row of columns. Inside a span every voxel is evaluated; between
** spans the field is constant over the column, so one evaluation gives
** the whole gap, stored only when it differs from the background. */
void sample_row(const oc_program *p, const lattice &L, double T, int j,
                row &R) {
  oc_zspan sp[MAXSPANS];
  std::vector<std::pair<int, int>> in; /* voxel ranges inside spans */
  double y = L.y(j);
  for (int i = 0; i < L.nx; i++) {
    double x = L.x(i);
    in.clear();
    int n = oc_program_column_spans(p, x, y, x, y, sp, MAXSPANS);
    if (n < 0) {
      in.push_back({0, L.nz});
    } else {
      for (int s = 0; s < n; s++) {
        double a = std::ceil((sp[s].lo - BOX.lo.z) / CELL - L.off);
        double b = std::floor((sp[s].hi - BOX.lo.z) / CELL - L.off);
        int k0 = (int)std::max(a, 0.0), k1 = (int)std::min(b + 1, (double)L.nz);
        if (k0 >= k1) continue;
        if (!in.empty() && k0 <= in.back().second)
          in.back().second = std::max(in.back().second, k1);
        else
          in.push_back({k0, k1});
      }
    }
    int k = 0;
    for (size_t s = 0; s <= in.size(); s++) {
      int g1 = s < in.size() ? in[s].first : L.nz;
      if (k < g1) { /* gap [k, g1): constant */
        float v = (float)(T - oc_program_eval(p, {x, y, L.z(k)}));
        R.evals++;
        if (v != (float)T) {
          R.runs.push_back({i, k, g1, R.vals.size()});
          R.vals.insert(R.vals.end(), g1 - k, v);
        }
      }
      if (s == in.size()) break;
      R.runs.push_back({i, in[s].first, in[s].second, R.vals.size()});
      for (int kk = in[s].first; kk < in[s].second; kk++)
        R.vals.push_back((float)(T - oc_program_eval(p, {x, y, L.z(kk)})));
      R.evals += in[s].second - in[s].first;
      k = in[s].second;
    }
  }
}

/* The whole band, every stored voxel active. */
openvdb::FloatGrid::Ptr sample(const oc_program *p, const lattice &L, double T,
                               size_t *evals) {
  std::vector<row> rows(L.ny);
#pragma omp parallel for schedule(dynamic, 4)
  for (int j = 0; j < L.ny; j++)
    sample_row(p, L, T, j, rows[j]);
  auto grid = openvdb::FloatGrid::create((float)T); /* outside */
  auto xf = openvdb::math::Transform::createLinearTransform(CELL);
  xf->postTranslate(openvdb::Vec3d(L.x(0), L.y(0), L.z(0)));
  grid->setTransform(xf);
  auto acc = grid->getAccessor();
  *evals = 0;
  for (int j = 0; j < L.ny; j++) {
    for (const run &r : rows[j].runs)
      for (int k = r.k0; k < r.k1; k++)
        acc.setValueOn(openvdb::Coord(r.i, j, k),
                       rows[j].vals[r.off + k - r.k0]);
    *evals += rows[j].evals;
    std::vector<run>().swap(rows[j].runs);
    std::vector<float>().swap(rows[j].vals);
  }
  return grid;
}

/* Keeps active only the voxels with a sign change to a face neighbour,
** dilated by one, and turns all-inactive leaves into tiles of their sign:
** a narrow band, as volumeToMesh expects of a level set. Values are kept,
** so every crossing and every value used to place a vertex is unchanged. */
void narrow(openvdb::FloatGrid &g) {
  using namespace openvdb;
  std::vector<Coord> keep;
  auto acc = g.getConstAccessor();
  static const Coord nb[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                              {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (auto it = g.cbeginValueOn(); it; ++it) {
    if (!it.isVoxelValue()) continue;
    Coord c = it.getCoord();
    bool in = *it < 0;
    for (const Coord &d : nb)
      if ((acc.getValue(c + d) < 0) != in) {
        keep.push_back(c);
        break;
      }
  }
  for (auto leaf = g.tree().beginLeaf(); leaf; ++leaf)
    leaf->setValuesOff();
  auto wacc = g.getAccessor();
  for (const Coord &c : keep)
    wacc.setActiveState(c, true);
  tools::dilateActiveValues(g.tree(), 1, tools::NN_FACE, tools::IGNORE_TILES);
  tools::pruneLevelSet(g.tree());
}

/* ---- meshing and measuring -------------------------------------------- */

struct vdb_mesh {
  std::vector<openvdb::Vec3s> pts;
  std::vector<openvdb::Vec3I> tris;
  std::vector<openvdb::Vec4I> quads;
  size_t triangles() const { return tris.size() + 2 * quads.size(); }
  double area() const {
    auto a3 = [&](unsigned a, unsigned b, unsigned c) {
      return 0.5 * (double)((pts[b] - pts[a]).cross(pts[c] - pts[a])).length();
    };
    double s = 0;
    for (auto &t : tris)
      s += a3(t[0], t[1], t[2]);
    for (auto &q : quads)
      s += a3(q[0], q[1], q[2]) + a3(q[0], q[2], q[3]);
    return s;
  }
};

double vdb_best(const openvdb::FloatGrid &g, int reps, vdb_mesh &m) {
  double best = INFINITY;
  for (int r = 0; r < reps; r++) {
    m = vdb_mesh();
    double t0 = omp_get_wtime();
    openvdb::tools::volumeToMesh(g, m.pts, m.tris, m.quads, 0.0);
    best = std::min(best, omp_get_wtime() - t0);
  }
  return best;
}

/* Bounds of n points, 3 floats each: lo[3], hi[3]. */
void bounds(const float *P, size_t n, double lo[3], double hi[3]) {
  for (int a = 0; a < 3; a++) {
    lo[a] = INFINITY;
    hi[a] = -INFINITY;
  }
  for (size_t i = 0; i < n; i++)
    for (int a = 0; a < 3; a++) {
      lo[a] = std::min(lo[a], (double)P[3 * i + a]);
      hi[a] = std::max(hi[a], (double)P[3 * i + a]);
    }
}

double mesh_area(const oc_mesh *m) {
  const float *P = oc_mesh_positions(m);
  const uint32_t *I = oc_mesh_indices(m);
  double s = 0;
  for (size_t t = 0; t < oc_mesh_triangle_count(m); t++) {
    const float *a = P + 3 * I[3 * t], *b = P + 3 * I[3 * t + 1],
                *c = P + 3 * I[3 * t + 2];
    double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double w[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                   u[0] * v[1] - u[1] * v[0]};
    s += 0.5 * std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  }
  return s;
}

} // namespace

int main() {
  openvdb::initialize();
  oc_error err;
  oc_node *scene = spheres1000();
  oc_program *p = oc_compile(scene, nullptr, &err);
  if (!p) {
    std::fprintf(stderr, "peer_openvdb: %s\n", err.msg);
    return 1;
  }
  double T = oc_program_threshold(p);

  /* ours: best of 2, 2 threads */
  omp_set_num_threads(2);
  oc_polygonize_params pp = {};
  pp.box = BOX;
  pp.cell = CELL;
  double ours = INFINITY;
  oc_mesh *m = nullptr;
  for (int r = 0; r < 2; r++) {
    if (m) oc_mesh_free(m);
    double t0 = omp_get_wtime();
    m = oc_polygonize(p, &pp, &err);
    double t = omp_get_wtime() - t0;
    if (!m) {
      std::fprintf(stderr, "peer_openvdb: %s\n", err.msg);
      return 1;
    }
    ours = std::min(ours, t);
  }
  oc_mesh_stats st;
  oc_mesh_get_stats(m, &st);

  /* the same sample points for OpenVDB */
  lattice L;
  L.nx = (int)std::lround((BOX.hi.x - BOX.lo.x) / CELL);
  L.ny = (int)std::lround((BOX.hi.y - BOX.lo.y) / CELL);
  L.nz = (int)std::lround((BOX.hi.z - BOX.lo.z) / CELL);
  L.off = 0.5; /* cell centres, as lib/mesh/mcgrid.h samples */
  size_t evals;
  double t0 = omp_get_wtime();
  openvdb::FloatGrid::Ptr band = sample(p, L, T, &evals);
  double ts = omp_get_wtime() - t0;
  openvdb::FloatGrid::Ptr nb = band->deepCopy();
  t0 = omp_get_wtime();
  narrow(*nb);
  double tn = omp_get_wtime() - t0;

  vdb_mesh vb, vn;
  double peer_band, peer;
  {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, 2);
    peer_band = vdb_best(*band, 2, vb);
    peer = vdb_best(*nb, 2, vn);
  }
  double dt = 100.0 * ((double)vn.triangles() / st.triangles - 1);
  double ao = mesh_area(m), av = vn.area();

  std::printf("# peer: OpenVDB %s volumeToMesh(grid, points, triangles, quads, "
              "isovalue 0), adaptivity 0, TBB limited to 2 threads\n",
              openvdb::getLibraryVersionString());
  std::printf("# compared: OpenVDB extracting from an already-sampled grid "
              "(extraction only) vs our oc_polygonize (sampling + "
              "extraction), both best of 2 on 2 threads\n");
  std::printf("# scene: 1000 spheres + ground (mesh.spheres1000), box "
              "[-13.75, 113.75]^2 x [-5, 122.5], cell 0.25, T %g\n",
              T);
  std::printf("# grid for OpenVDB: %dx%dx%d voxels at our sample points, "
              "value T - f; %zu field evaluations over the column spans in "
              "%.2f s (2 threads, not timed against the peer); narrow band "
              "%zu active voxels (made in %.2f s) of %zu sampled\n",
              L.nx, L.ny, L.nz, evals, ts, (size_t)nb->activeVoxelCount(), tn,
              (size_t)band->activeVoxelCount());
  std::printf("# OpenVDB on the whole sampled band (%zu active voxels): "
              "%.3f s\n",
              (size_t)band->activeVoxelCount(), peer_band);
  std::printf("# triangles: ours %zu, OpenVDB %zu (%zu quads x 2 + %zu "
              "triangles), %+.2f %%\n",
              st.triangles, vn.triangles(), vn.quads.size(), vn.tris.size(),
              dt);
  std::printf("# area: ours %.1f m^2, OpenVDB %.1f m^2 (%+.3f %%)\n", ao, av,
              100.0 * (av / ao - 1));
  double ol[3], oh[3], vl[3], vh[3];
  bounds(oc_mesh_positions(m), oc_mesh_vertex_count(m), ol, oh);
  bounds(vn.pts.empty() ? nullptr : &vn.pts[0][0], vn.pts.size(), vl, vh);
  std::printf("# bounds: ours (%.3f %.3f %.3f)..(%.3f %.3f %.3f), OpenVDB "
              "(%.3f %.3f %.3f)..(%.3f %.3f %.3f)\n",
              ol[0], ol[1], ol[2], oh[0], oh[1], oh[2], vl[0], vl[1], vl[2],
              vh[0], vh[1], vh[2]);
  std::printf("mesh.peer_seconds_2t: %.3f s\n", peer);
  std::printf("mesh.ours_seconds_2t: %.3f s\n", ours);
  std::printf("mesh.vs_peer: %.2f x\n", peer / ours);

  oc_mesh_free(m);
  oc_program_free(p);
  oc_node_release(scene);
  /* the figures mean something only if both meshed the same shape */
  if (vb.triangles() != vn.triangles() || std::fabs(dt) > 5) {
    std::fprintf(stderr,
                 "peer_openvdb: meshes disagree (ours %zu triangles, OpenVDB "
                 "%zu on the narrow band, %zu on the whole band)\n",
                 st.triangles, vn.triangles(), vb.triangles());
    return 1;
  }
  return 0;
}
