// SPDX-License-Identifier: BSD-3-Clause
// Collision mesh: signed distance on a grid, its sign far from the cloud
// by a flood fill, marching tetrahedra (the header says why it is watertight).
#include "graspfill/mesh/collision_mesh.hpp"

#include <open3d/geometry/KDTreeFlann.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace graspfill::mesh {
namespace {

constexpr int64_t kMaxNodes = int64_t{64} << 20;
// Neighbours of the plane fit when the cloud has no normals.
constexpr int kNormalNeighbors = 16;
// |distance| is kept at least this many cells from zero, so that every
// mesh vertex lies at least ~2% of an edge from the edge's ends: a node near
// zero would otherwise gather micron-sized triangles that Open3D's
// self-intersection test (absolute tolerance 1e-6) takes for crossings. The
// surface moves by at most this much.
constexpr double kMinAbsDistanceCells = 0.05;
constexpr double kGridOffsetCells = 0.37;

// Node labels: within the band (a distance is computed), or beyond it and
// either reached by the flood fill from the border (outside) or not (inside).
// Node labels: in the band (a distance is computed); in the wider fill
// band only (it stops the fill); beyond both, reached by the fill from the
// border (outside) or not (inside).
enum Label : uint8_t { kInside = 0, kNear = 1, kOutside = 2, kBarrier = 3 };

struct Grid {
  Eigen::Vector3d origin;
  double h{0.0};
  Eigen::Vector3i dims;

  int64_t size() const { return int64_t{dims.x()} * dims.y() * dims.z(); }
  int64_t Index(int i, int j, int k) const { return i + int64_t{dims.x()} * (j + int64_t{dims.y()} * k); }
  Eigen::Vector3d Position(int64_t index) const {
    const int64_t i = index % dims.x();
    const int64_t j = (index / dims.x()) % dims.y();
    const int64_t k = index / (int64_t{dims.x()} * dims.y());
    return origin +
           h * Eigen::Vector3d(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
  }
  // The node nearest to `p`, or -1 outside the grid.
  int64_t Nearest(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d c = (p - origin) / h;
    std::array<int, 3> n;
    for (int a = 0; a < 3; ++a) {
      n[a] = static_cast<int>(std::lround(c[a]));
      if (n[a] < 0 || n[a] >= dims[a]) return -1;
    }
    return Index(n[0], n[1], n[2]);
  }
};

void ValidateCloud(const ObjectCloud& cloud) {
  if (cloud.size() < 4) {
    throw std::invalid_argument("collision mesh: the cloud has " + std::to_string(cloud.size()) +
                                " points; at least 4 are needed");
  }
  for (size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points_G[i].allFinite()) {
      throw std::invalid_argument("collision mesh: point " + std::to_string(i) + " is not finite");
    }
  }
  if (!cloud.normals_G.empty() && cloud.normals_G.size() != cloud.size()) {
    throw std::invalid_argument("collision mesh: " + std::to_string(cloud.normals_G.size()) +
                                " normals for " + std::to_string(cloud.size()) + " points");
  }
}

// The cloud's normals, or plane-fit ones turned away from the centroid.
std::vector<Eigen::Vector3d> StartNormals(const ObjectCloud& cloud,
                                          const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> normals;
  normals.reserve(points.size());
  bool usable = !cloud.normals_G.empty();
  for (size_t i = 0; usable && i < points.size(); ++i) {
    const Eigen::Vector3d n = cloud.normals_G[i].cast<double>();
    usable = n.allFinite() && n.norm() > 0.5;
    normals.push_back(n.normalized());
  }
  if (usable) return normals;
  open3d::geometry::PointCloud pc;
  pc.points_ = points;
  pc.EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(kNormalNeighbors), false);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  normals = pc.normals_;
  for (size_t i = 0; i < points.size(); ++i) {
    if (normals[i].dot(points[i] - centroid) < 0.0) normals[i] = -normals[i];
  }
  return normals;
}

// Labels every node beyond the band outside (reached from the border) or
// inside; nodes in the band are kNear.
void FloodFill(const Grid& grid, std::vector<uint8_t>* labels) {
  std::vector<uint8_t>& label = *labels;
  std::deque<int64_t> queue;
  auto visit = [&](int64_t n) {
    if (label[n] != kInside) return;  // near, or already outside
    label[n] = kOutside;
    queue.push_back(n);
  };
  const Eigen::Vector3i& d = grid.dims;
  for (int k = 0; k < d.z(); ++k) {
    for (int j = 0; j < d.y(); ++j) {
      for (int i = 0; i < d.x(); ++i) {
        if (i == 0 || j == 0 || k == 0 || i == d.x() - 1 || j == d.y() - 1 || k == d.z() - 1) {
          visit(grid.Index(i, j, k));
        }
      }
    }
  }
  const std::array<int64_t, 3> stride{1, d.x(), int64_t{d.x()} * d.y()};
  while (!queue.empty()) {
    const int64_t n = queue.front();
    queue.pop_front();
    const std::array<int64_t, 3> at{n % d.x(), (n / d.x()) % d.y(), n / stride[2]};
    for (int a = 0; a < 3; ++a) {
      if (at[a] > 0) visit(n - stride[a]);
      if (at[a] + 1 < d[a]) visit(n + stride[a]);
    }
  }
}

// Relabels outside the fill-band nodes (kBarrier) reached from the outside
// in at most `max_steps` steps through such nodes, and inside the rest.
void RegrowOutside(const Grid& grid, int max_steps, std::vector<uint8_t>* labels) {
  std::vector<uint8_t>& label = *labels;
  const Eigen::Vector3i& d = grid.dims;
  const std::array<int64_t, 3> stride{1, d.x(), int64_t{d.x()} * d.y()};
  std::vector<int64_t> front, next;
  for (int64_t n = 0; n < grid.size(); ++n) {
    if (label[n] == kOutside) front.push_back(n);
  }
  for (int step = 0; step < max_steps && !front.empty(); ++step) {
    next.clear();
    for (const int64_t n : front) {
      const std::array<int64_t, 3> at{n % d.x(), (n / d.x()) % d.y(), n / stride[2]};
      for (int a = 0; a < 3; ++a) {
        if (at[a] > 0 && label[n - stride[a]] == kBarrier) {
          label[n - stride[a]] = kOutside;
          next.push_back(n - stride[a]);
        }
        if (at[a] + 1 < d[a] && label[n + stride[a]] == kBarrier) {
          label[n + stride[a]] = kOutside;
          next.push_back(n + stride[a]);
        }
      }
    }
    front.swap(next);
  }
  for (uint8_t& l : label) {
    if (l == kBarrier) l = kInside;
  }
}

// The tetrahedron of the grid that holds `p` (the Triangulator's six per
// cube along its main diagonal: the one whose path from corner 0 to 7
// steps along the axes in the order of p's coordinates within the cube,
// largest first): its four nodes and p's barycentric weights on them.
struct TetrahedronAt {
  std::array<int64_t, 4> node;
  std::array<double, 4> weight;
};

TetrahedronAt LocateInGrid(const Grid& grid, const Eigen::Vector3d& p) {
  const Eigen::Vector3d c = (p - grid.origin) / grid.h;
  const Eigen::Vector3i cell = c.array().floor().cast<int>();
  const Eigen::Vector3d u = c - cell.cast<double>();
  std::array<int, 3> axis{0, 1, 2};
  std::sort(axis.begin(), axis.end(), [&](int a, int b) { return u[a] > u[b]; });
  TetrahedronAt t;
  Eigen::Vector3i corner = cell;
  t.node[0] = grid.Index(corner.x(), corner.y(), corner.z());
  t.weight[0] = 1.0 - u[axis[0]];
  for (int step = 0; step < 3; ++step) {
    corner[axis[step]] += 1;
    t.node[step + 1] = grid.Index(corner.x(), corner.y(), corner.z());
    t.weight[step + 1] = u[axis[step]] - (step < 2 ? u[axis[step + 1]] : 0.0);
  }
  return t;
}

// Lowers the field around every point it leaves outside, by just enough
// (and a margin): on the four nodes of the point's tetrahedron, each in
// proportion to its weight (the smallest change, in the least-squares
// sense, that brings the linear field at the point down by that much), so
// the bulge stays where the point is. Lowering never raises any other
// point's field, so one pass holds them all.
void HoldPoints(const Grid& grid, const std::vector<Eigen::Vector3d>& points, float min_abs,
                std::vector<float>* f) {
  for (const Eigen::Vector3d& p : points) {
    const TetrahedronAt t = LocateInGrid(grid, p);
    double value = 0.0, weight2 = 0.0;
    for (int k = 0; k < 4; ++k) {
      value += t.weight[k] * (*f)[t.node[k]];
      weight2 += t.weight[k] * t.weight[k];
    }
    if (value < -min_abs) continue;
    const double lower = (value + 2.0 * min_abs) / weight2;
    for (int k = 0; k < 4; ++k) {
      float& v = (*f)[t.node[k]];
      v -= static_cast<float>(lower * t.weight[k]);
      // Kept off zero as everywhere, by lowering only.
      if (std::abs(v) < min_abs) v = -min_abs;
    }
  }
}

// Marching tetrahedra over the grid: vertices on the edges whose ends differ
// in sign (one per edge, shared), triangles turned to face the positive side.
class Triangulator {
 public:
  Triangulator(const Grid& grid, const std::vector<float>& f) : grid_(grid), f_(f) {}

  TriangleMesh Run() {
    // The six tetrahedra of a cube along its main diagonal 0-7 (corner bits:
    // x = 1, y = 2, z = 4); neighbouring cubes split their shared faces alike.
    static constexpr std::array<std::array<int, 4>, 6> kTets{
        {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}}};
    const Eigen::Vector3i& d = grid_.dims;
    for (int k = 0; k + 1 < d.z(); ++k) {
      for (int j = 0; j + 1 < d.y(); ++j) {
        for (int i = 0; i + 1 < d.x(); ++i) {
          std::array<int64_t, 8> corner;
          int negative = 0;
          for (int c = 0; c < 8; ++c) {
            corner[c] = grid_.Index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
            negative += f_[corner[c]] < 0.0f;
          }
          if (negative == 0 || negative == 8) continue;
          for (const std::array<int, 4>& t : kTets) {
            Tetrahedron({corner[t[0]], corner[t[1]], corner[t[2]], corner[t[3]]});
          }
        }
      }
    }
    return std::move(mesh_);
  }

 private:
  void Tetrahedron(const std::array<int64_t, 4>& v) {
    std::array<int64_t, 4> in, out;
    int num_in = 0, num_out = 0;
    for (int64_t n : v) {
      if (f_[n] < 0.0f)
        in[num_in++] = n;
      else
        out[num_out++] = n;
    }
    if (num_in == 0 || num_out == 0) return;
    // From the inside corners' centre to the outside ones': where the
    // triangles must face.
    Eigen::Vector3d towards_out = Eigen::Vector3d::Zero();
    for (int a = 0; a < num_out; ++a) towards_out += grid_.Position(out[a]) / num_out;
    for (int a = 0; a < num_in; ++a) towards_out -= grid_.Position(in[a]) / num_in;
    if (num_in == 1) {
      Emit(Edge(in[0], out[0]), Edge(in[0], out[1]), Edge(in[0], out[2]), towards_out);
    } else if (num_in == 3) {
      Emit(Edge(out[0], in[0]), Edge(out[0], in[1]), Edge(out[0], in[2]), towards_out);
    } else {  // a quad: its edge points in the order a-c, a-d, b-d, b-c
      const int ac = Edge(in[0], out[0]), ad = Edge(in[0], out[1]);
      const int bd = Edge(in[1], out[1]), bc = Edge(in[1], out[0]);
      Emit(ac, ad, bd, towards_out);
      Emit(ac, bd, bc, towards_out);
    }
  }

  // The vertex where the field crosses zero on the edge a-b (made once).
  int Edge(int64_t a, int64_t b) {
    const int64_t key = a < b ? a * kMaxNodes + b : b * kMaxNodes + a;
    const auto [it, added] = vertex_of_edge_.try_emplace(key, static_cast<int>(mesh_.vertices.size()));
    if (added) {
      const double fa = f_[a], fb = f_[b];
      const double t = fa / (fa - fb);
      const Eigen::Vector3d pa = grid_.Position(a);
      mesh_.vertices.push_back((pa + t * (grid_.Position(b) - pa)).cast<float>());
    }
    return it->second;
  }

  void Emit(int a, int b, int c, const Eigen::Vector3d& towards_out) {
    const Eigen::Vector3d pa = mesh_.vertices[a].cast<double>();
    const Eigen::Vector3d normal =
        (mesh_.vertices[b].cast<double>() - pa).cross(mesh_.vertices[c].cast<double>() - pa);
    if (normal.dot(towards_out) < 0.0) std::swap(b, c);
    mesh_.triangles.emplace_back(a, b, c);
  }

  const Grid& grid_;
  const std::vector<float>& f_;
  TriangleMesh mesh_;
  std::unordered_map<int64_t, int> vertex_of_edge_;
};

// The mesh without its small closed pieces (each piece is closed, so what
// stays is too): those of fewer than `min_fraction` of the largest piece's
// triangles, the skins around stray points off the object.
TriangleMesh DropSmallPieces(const TriangleMesh& mesh, double min_fraction) {
  std::vector<int> parent(mesh.vertices.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const Eigen::Vector3i& t : mesh.triangles) {
    parent[root(t[1])] = root(t[0]);
    parent[root(t[2])] = root(t[0]);
  }
  std::unordered_map<int, size_t> triangles_of;
  for (const Eigen::Vector3i& t : mesh.triangles) ++triangles_of[root(t[0])];
  size_t largest = 0;
  for (const auto& [piece, count] : triangles_of) largest = std::max(largest, count);
  TriangleMesh kept;
  std::vector<int> new_index(mesh.vertices.size(), -1);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    if (static_cast<double>(triangles_of[root(t[0])]) < min_fraction * largest) continue;
    Eigen::Vector3i u;
    for (int k = 0; k < 3; ++k) {
      int& n = new_index[t[k]];
      if (n < 0) {
        n = static_cast<int>(kept.vertices.size());
        kept.vertices.push_back(mesh.vertices[t[k]]);
      }
      u[k] = n;
    }
    kept.triangles.push_back(u);
  }
  return kept;
}

// The grid: the cloud's box, padded by `reach` cells and more so that the
// border lies beyond the bands.
Grid GridAround(const std::vector<Eigen::Vector3d>& points, double h, int reach) {
  Eigen::Vector3d lo = points[0], hi = points[0];
  for (const Eigen::Vector3d& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Grid grid;
  grid.h = h;
  // Offset by a fraction of a cell so that the flat faces of a box-shaped
  // cloud do not lie on grid planes: there the field is near zero at whole
  // planes of nodes and the mesh a stack of exactly symmetric slivers, which
  // Open3D's self-intersection test misreads as crossing.
  grid.origin = lo - Eigen::Vector3d::Constant((reach + 2 + kGridOffsetCells) * h);
  double nodes = 1.0;
  for (int a = 0; a < 3; ++a) {
    grid.dims[a] = static_cast<int>(std::ceil((hi[a] - lo[a]) / h)) + 2 * (reach + 2) + 2;
    nodes *= grid.dims[a];
  }
  if (nodes > static_cast<double>(kMaxNodes)) {
    throw std::runtime_error("collision mesh: a " + std::to_string(h) + " m grid over the cloud's " +
                             "box needs " + std::to_string(static_cast<int64_t>(nodes)) + " nodes (at most " +
                             std::to_string(kMaxNodes) + "); use larger cells");
  }
  return grid;
}

// The bands: nodes within fill_m of a point (kBarrier), and within band_m
// (kNear) with their nearest points into *nearest; every other node
// kInside, for the fill to decide.
std::vector<uint8_t> LabelBands(const Grid& grid, const std::vector<Eigen::Vector3d>& points,
                                const CollisionMeshConfig& config, int reach,
                                std::unordered_map<int64_t, std::vector<int>>* nearest) {
  const double h = grid.h;
  const double band_m = config.band_cells * h;
  const double fill_m = config.fill_band_cells * h;
  // The tree refers to `data` (not a copy): both live to the end.
  Eigen::MatrixXd data(3, static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) data.col(static_cast<Eigen::Index>(i)) = points[i];
  open3d::geometry::KDTreeFlann tree;
  if (!tree.SetMatrixData(data)) throw std::runtime_error("collision mesh: KD-tree build failed");
  std::vector<uint8_t> label(static_cast<size_t>(grid.size()), kInside);
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d c = (p - grid.origin) / h;
    const int ci = static_cast<int>(std::floor(c.x())), cj = static_cast<int>(std::floor(c.y())),
              ck = static_cast<int>(std::floor(c.z()));
    for (int k = ck - reach; k <= ck + reach + 1; ++k) {
      for (int j = cj - reach; j <= cj + reach + 1; ++j) {
        for (int i = ci - reach; i <= ci + reach + 1; ++i) label[grid.Index(i, j, k)] = kNear;
      }
    }
  }
  const int k_nn = std::min<int>(config.neighbors, static_cast<int>(points.size()));
  std::vector<int> index;
  std::vector<double> dist2;
  for (int64_t n = 0; n < grid.size(); ++n) {
    if (label[n] != kNear) continue;
    tree.SearchKNN(grid.Position(n), k_nn, index, dist2);
    if (dist2.empty() || dist2[0] > fill_m * fill_m) {
      label[n] = kInside;  // beyond both bands after all; the fill decides
    } else if (dist2[0] > band_m * band_m) {
      label[n] = kBarrier;
    } else {
      nearest->emplace(n, index);
    }
  }
  return label;
}

// Normals turned to face the outside where the grid tells: the first
// node beyond the band along the normal, walking a cell at a time, lies
// outside for an outward normal and inside for an inward one; where that
// walk leaves the grid or finds nothing, the walk the other way decides.
void OrientNormals(const Grid& grid, const std::vector<uint8_t>& label, double band_cells,
                   const std::vector<Eigen::Vector3d>& points, std::vector<Eigen::Vector3d>* normals) {
  const int max_steps = static_cast<int>(std::ceil(band_cells)) + 3;
  auto first_beyond_band = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& step) {
    for (int k = 1; k <= max_steps; ++k) {
      const int64_t n = grid.Nearest(p + k * step);
      if (n < 0) return kOutside;
      if (label[n] != kNear) return static_cast<Label>(label[n]);
    }
    return kNear;  // undecided
  };
  for (size_t i = 0; i < points.size(); ++i) {
    const Label front = first_beyond_band(points[i], grid.h * (*normals)[i]);
    const Label back = front == kNear ? first_beyond_band(points[i], -grid.h * (*normals)[i]) : kNear;
    if (front == kInside || back == kOutside) (*normals)[i] = -(*normals)[i];
  }
}

// The field: the mean plane distance in the band, +-band_m beyond it, never
// nearer zero than min_abs.
std::vector<float> SignedField(const Grid& grid, const std::vector<uint8_t>& label,
                               const std::unordered_map<int64_t, std::vector<int>>& nearest,
                               const std::vector<Eigen::Vector3d>& points,
                               const std::vector<Eigen::Vector3d>& normals, double band_m, float min_abs) {
  std::vector<float> f(static_cast<size_t>(grid.size()));
  for (int64_t n = 0; n < grid.size(); ++n) {
    double value = label[n] == kOutside ? band_m : -band_m;
    if (label[n] == kNear) {
      const Eigen::Vector3d x = grid.Position(n);
      const std::vector<int>& nn = nearest.at(n);
      value = 0.0;
      for (int j : nn) value += normals[j].dot(x - points[j]);
      value = std::clamp(value / static_cast<double>(nn.size()), -band_m, band_m);
    }
    float v = static_cast<float>(value);
    if (std::abs(v) < min_abs) v = v < 0.0f ? -min_abs : min_abs;
    f[n] = v;
  }
  return f;
}

}  // namespace

void CollisionMeshConfig::Validate() const {
  auto check = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("CollisionMeshConfig: " + what);
  };
  check(std::isfinite(cell_m) && cell_m >= 0.0002 && cell_m <= 0.02,
        "cell_m must be in 0.0002..0.02 m, not " + std::to_string(cell_m));
  check(neighbors >= 1 && neighbors <= 64, "neighbors must be in 1..64, not " + std::to_string(neighbors));
  check(std::isfinite(band_cells) && band_cells >= 1.5 && band_cells <= 8.0,
        "band_cells must be in 1.5..8, not " + std::to_string(band_cells));
  check(std::isfinite(fill_band_cells) && fill_band_cells >= band_cells && fill_band_cells <= 12.0,
        "fill_band_cells must be in band_cells..12, not " + std::to_string(fill_band_cells));
  check(std::isfinite(min_piece_fraction) && min_piece_fraction >= 0.0 && min_piece_fraction <= 1.0,
        "min_piece_fraction must be in 0..1, not " + std::to_string(min_piece_fraction));
}

TriangleMesh BuildCollisionMesh(const ObjectCloud& cloud, const CollisionMeshConfig& config) {
  config.Validate();
  ValidateCloud(cloud);
  std::vector<Eigen::Vector3d> points(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) points[i] = cloud.points_G[i].cast<double>();
  std::vector<Eigen::Vector3d> normals = StartNormals(cloud, points);

  const double h = config.cell_m;
  const int reach = static_cast<int>(std::ceil(std::max(config.band_cells, config.fill_band_cells)));
  const Grid grid = GridAround(points, h, reach);
  std::unordered_map<int64_t, std::vector<int>> nearest;  // band node -> its k nearest points
  std::vector<uint8_t> label = LabelBands(grid, points, config, reach, &nearest);
  // Beyond the bands: outside where the border reaches, else inside; the
  // wider fill band keeps holes up to twice its width from letting it in.
  // Then the outside grows back over the fill band's outer part, a few
  // steps only, so that it does not go in through such a hole.
  FloodFill(grid, &label);
  const int regrow_steps = static_cast<int>(std::ceil(config.fill_band_cells - config.band_cells)) + 2;
  RegrowOutside(grid, regrow_steps, &label);
  OrientNormals(grid, label, config.band_cells, points, &normals);

  const float min_abs = static_cast<float>(kMinAbsDistanceCells * h);
  std::vector<float> f = SignedField(grid, label, nearest, points, normals, config.band_cells * h, min_abs);
  if (config.hold_points) HoldPoints(grid, points, min_abs, &f);
  return DropSmallPieces(Triangulator(grid, f).Run(), config.min_piece_fraction);
}

}  // namespace graspfill::mesh
