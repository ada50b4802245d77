#include "units/estimation/distance_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "units/estimation/occupancy_grid.h"

namespace linesim::estimation {
namespace {

using Point = std::array<double, 2>;
using Polygon = std::vector<Point>;

double Cross(const Point& o, const Point& a, const Point& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Andrew's monotone chain: the convex hull, counter-clockwise, collinear
// points dropped.
Polygon ConvexHull(Polygon p) {
  std::sort(p.begin(), p.end());
  p.erase(std::unique(p.begin(), p.end()), p.end());
  if (p.size() < 3) return {};
  Polygon h(2 * p.size());
  std::size_t k = 0;
  for (const Point& q : p) {
    while (k >= 2 && Cross(h[k - 2], h[k - 1], q) <= 0.0) --k;
    h[k++] = q;
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && Cross(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h.size() >= 3 ? h : Polygon{};
}

// Signed distance (positive INSIDE) from (x, y) to a convex CCW polygon.
double PolygonSignedDistance(const Polygon& poly, double x, double y) {
  double inside = std::numeric_limits<double>::infinity();  // least distance to an edge line
  double outside2 = std::numeric_limits<double>::infinity();
  bool in = true;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point& a = poly[i];
    const Point& b = poly[(i + 1) % n];
    const double ex = b[0] - a[0], ey = b[1] - a[1];
    const double len2 = ex * ex + ey * ey;
    const double wx = x - a[0], wy = y - a[1];
    const double side = (ex * wy - ey * wx) / std::sqrt(len2);  // > 0: left (inside)
    if (side < 0.0) in = false;
    inside = std::min(inside, side);
    const double t = std::clamp((wx * ex + wy * ey) / len2, 0.0, 1.0);
    const double dx = wx - t * ex, dy = wy - t * ey;
    outside2 = std::min(outside2, dx * dx + dy * dy);
  }
  return in ? inside : -std::sqrt(outside2);
}

// Felzenszwalb-Huttenlocher 1D squared distance transform of f (n samples,
// stride `stride`), in place; v, z scratch of n and n + 1.
void Transform1D(float* f, std::size_t n, std::size_t stride, std::vector<double>& in,
                 std::vector<int>& v, std::vector<double>& z) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (std::size_t q = 0; q < n; ++q) in[q] = f[q * stride];
  int k = 0;
  // Skip leading infinite samples: parabolas with f = inf never win.
  std::size_t q0 = 0;
  while (q0 < n && !(in[q0] < kInf)) ++q0;
  if (q0 == n) return;  // all infinite: unchanged
  v[0] = static_cast<int>(q0);
  z[0] = -kInf;
  z[1] = kInf;
  for (std::size_t q = q0 + 1; q < n; ++q) {
    if (!(in[q] < kInf)) continue;
    const double dq = static_cast<double>(q);
    double s;
    for (;;) {
      const double vk = v[static_cast<std::size_t>(k)];
      s = ((in[q] + dq * dq) - (in[static_cast<std::size_t>(vk)] + vk * vk)) / (2.0 * (dq - vk));
      if (s <= z[static_cast<std::size_t>(k)] && k > 0) {
        --k;
        continue;
      }
      break;
    }
    if (s <= z[static_cast<std::size_t>(k)]) {
      // k == 0 and the new parabola dominates everywhere.
      v[0] = static_cast<int>(q);
      z[0] = -kInf;
      z[1] = kInf;
      continue;
    }
    ++k;
    v[static_cast<std::size_t>(k)] = static_cast<int>(q);
    z[static_cast<std::size_t>(k)] = s;
    z[static_cast<std::size_t>(k) + 1] = kInf;
  }
  k = 0;
  for (std::size_t q = 0; q < n; ++q) {
    const double dq = static_cast<double>(q);
    while (z[static_cast<std::size_t>(k) + 1] < dq) ++k;
    const double vk = v[static_cast<std::size_t>(k)];
    f[q * stride] = static_cast<float>((dq - vk) * (dq - vk) + in[static_cast<std::size_t>(vk)]);
  }
}

// The 2D squared EDT (in cells^2) of the nodes where `target` is set.
std::vector<float> SquaredEdt(const std::vector<char>& target, int nx, int ny) {
  const auto inf = std::numeric_limits<float>::infinity();
  const auto sx = static_cast<std::size_t>(nx), sy = static_cast<std::size_t>(ny);
  std::vector<float> f(sx * sy);
  for (std::size_t k = 0; k < f.size(); ++k) f[k] = target[k] ? 0.0f : inf;
  const std::size_t m = std::max(sx, sy);
  std::vector<double> in(m), z(m + 1);
  std::vector<int> v(m);
  for (std::size_t ix = 0; ix < sx; ++ix) Transform1D(f.data() + ix, sy, sx, in, v, z);
  for (std::size_t iy = 0; iy < sy; ++iy) Transform1D(f.data() + iy * sx, sx, 1, in, v, z);
  return f;
}

// The footprint's bounding box of an obstacle solid.
DistanceMap::Region Footprint(const models::Solid& s) {
  double hx = s.radius_m, hy = s.radius_m;
  if (s.kind == models::Solid::Kind::kBox) {
    const double c = std::abs(std::cos(s.yaw_rad)), sn = std::abs(std::sin(s.yaw_rad));
    hx = 0.5 * (s.length_m * c + s.width_m * sn);
    hy = 0.5 * (s.length_m * sn + s.width_m * c);
  }
  return {s.x_m - hx, s.x_m + hx, s.y_m - hy, s.y_m + hy};
}

bool Within(const DistanceMap::Region& a, const DistanceMap::Region& r) {
  return a.min_x >= r.min_x && a.max_x <= r.max_x && a.min_y >= r.min_y && a.max_y <= r.max_y;
}

}  // namespace

std::vector<std::array<double, 2>> DistanceMap::TerrainSlice(const models::TerrainPiece& t,
                                                             double z) {
  // The piece's axes: R = Rz(yaw) Ry(-pitch) Rx(roll), + pitch raising the
  // far (+length) end (models::TerrainPiece; the laser's ray scene builds
  // the same box).
  const double cy = std::cos(t.yaw_rad), sy = std::sin(t.yaw_rad);
  const double cp = std::cos(-t.pitch_rad), sp = std::sin(-t.pitch_rad);
  const double cr = std::cos(t.roll_rad), sr = std::sin(t.roll_rad);
  const double ax[3] = {cy * cp, sy * cp, -sp};
  const double ay[3] = {cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr};
  const double az[3] = {cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr};
  const double h[3] = {0.5 * t.length_m, 0.5 * t.width_m, 0.5 * t.thickness_m};
  std::array<std::array<double, 3>, 8> corner{};
  for (int i = 0; i < 8; ++i) {
    const double u = (i & 1) ? h[0] : -h[0], v = (i & 2) ? h[1] : -h[1], w = (i & 4) ? h[2] : -h[2];
    for (int j = 0; j < 3; ++j) {
      corner[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = (j == 0   ? t.center_x_m
                                                                          : j == 1 ? t.center_y_m
                                                                                   : t.center_z_m) +
                                                                         u * ax[j] + v * ay[j] +
                                                                         w * az[j];
    }
  }
  Polygon pts;
  // The 12 edges: corner pairs differing in one bit.
  for (int i = 0; i < 8; ++i) {
    for (int bit = 1; bit < 8; bit <<= 1) {
      const int j = i | bit;
      if (j == i) continue;
      const auto& a = corner[static_cast<std::size_t>(i)];
      const auto& b = corner[static_cast<std::size_t>(j)];
      const double za = a[2] - z, zb = b[2] - z;
      if (za == 0.0) pts.push_back({a[0], a[1]});
      if (zb == 0.0) pts.push_back({b[0], b[1]});
      if ((za < 0.0 && zb > 0.0) || (za > 0.0 && zb < 0.0)) {
        const double s = za / (za - zb);
        pts.push_back({a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])});
      }
    }
  }
  return ConvexHull(std::move(pts));
}

DistanceMap::DistanceMap(const models::Scene& scene, double z, std::optional<Region> region,
                         Options o) {
  if (!(o.cell > 0.0) || !(o.margin >= 0.0) || !(o.band_cells >= 2.0)) {
    throw std::invalid_argument("distance map: cell must be > 0, margin >= 0, band_cells >= 2");
  }
  if (region && !(region->max_x > region->min_x && region->max_y > region->min_y)) {
    throw std::invalid_argument("distance map: the region must have max > min on x and y");
  }
  const double zs[1] = {z};
  for (const models::Obstacle& ob : scene.obstacles) {
    if (!OccupancyGrid::CoversPlane(ob.solid, zs)) continue;
    if (region && !Within(Footprint(ob.solid), *region)) continue;
    solids_.push_back(ob.solid);
  }
  for (const models::TerrainPiece& t : scene.terrain) {
    Polygon p = TerrainSlice(t, z);
    if (p.empty()) continue;
    Region b{p[0][0], p[0][0], p[0][1], p[0][1]};
    for (const Point& q : p) {
      b.min_x = std::min(b.min_x, q[0]);
      b.max_x = std::max(b.max_x, q[0]);
      b.min_y = std::min(b.min_y, q[1]);
      b.max_y = std::max(b.max_y, q[1]);
    }
    if (region && !Within(b, *region)) continue;
    slices_.push_back(std::move(p));
  }
  models::Floor rect = scene.floor;
  if (region) {
    rect.min_x_m = region->min_x;
    rect.max_x_m = region->max_x;
    rect.min_y_m = region->min_y;
    rect.max_y_m = region->max_y;
  }
  // The obstacles' occupancy and exact band: OccupancyGrid's profile on one
  // level at cell h (its grid is the one this map uses).
  OccupancyGrid::Options go;
  go.resolution = o.cell;
  go.levels = 1;
  go.margin = o.margin;
  go.profile_cells = o.band_cells;
  const OccupancyGrid grid(solids_, rect, go);
  const OccupancyGrid::Level& l = grid.level(0);
  cell_ = l.cell;
  inv_cell_ = l.inv_cell;
  origin_x_ = l.origin_x;
  origin_y_ = l.origin_y;
  nx_ = l.nx;
  ny_ = l.ny;
  const double w = l.w;
  const auto sx = static_cast<std::size_t>(nx_), sy = static_cast<std::size_t>(ny_);
  const std::size_t n = sx * sy;

  // Terrain: the largest signed distance (inside +) of the slices, within
  // the band of each (-inf elsewhere).
  std::vector<float> terrain(n, -std::numeric_limits<float>::infinity());
  for (const Polygon& p : slices_) {
    double x0 = p[0][0], x1 = p[0][0], y0 = p[0][1], y1 = p[0][1];
    for (const Point& q : p) {
      x0 = std::min(x0, q[0]);
      x1 = std::max(x1, q[0]);
      y0 = std::min(y0, q[1]);
      y1 = std::max(y1, q[1]);
    }
    const auto index = [&](double v, double origin, int count) {
      return std::clamp(static_cast<int>(std::floor((v - origin) * inv_cell_ - 0.5)), 0, count - 1);
    };
    const int ix0 = index(x0 - w - cell_, origin_x_, nx_),
              ix1 = index(x1 + w + cell_, origin_x_, nx_);
    const int iy0 = index(y0 - w - cell_, origin_y_, ny_),
              iy1 = index(y1 + w + cell_, origin_y_, ny_);
    for (int iy = iy0; iy <= iy1; ++iy) {
      const double y = origin_y_ + (iy + 0.5) * cell_;
      for (int ix = ix0; ix <= ix1; ++ix) {
        const double x = origin_x_ + (ix + 0.5) * cell_;
        float& t = terrain[static_cast<std::size_t>(iy) * sx + static_cast<std::size_t>(ix)];
        t = std::max(t, static_cast<float>(PolygonSignedDistance(p, x, y)));
      }
    }
  }

  // Occupancy, and the exact signed distance (inside +) where known.
  constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();
  std::vector<char> occupied(n, 0), free_node(n, 0);
  std::vector<float> exact(n, kUnknown);
  std::vector<char> deep(n, 0);
  occupied_ = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double m = l.value[k];
    const double t = terrain[k];
    occupied[k] = (m >= 1.0 || t >= 0.0) ? 1 : 0;
    free_node[k] = occupied[k] ? 0 : 1;
    occupied_ += static_cast<std::size_t>(occupied[k]);
    if (m >= 2.0 || t >= w) {
      deep[k] = 1;  // deeper than the band inside something: the EDT
      continue;
    }
    double e = -std::numeric_limits<double>::infinity();
    bool known = false;
    if (m > 0.0) {
      e = std::max(e, (m - 1.0) * w);
      known = true;
    }
    if (t > -w) {
      e = std::max(e, t);
      known = true;
    }
    if (known) exact[k] = static_cast<float>(e);
  }
  // Seen from a point: the free nodes connected to it (4-neighbours, within
  // the region) are the only free space; the rest reads as inside.
  std::vector<char> seen;
  if (o.seen_from) {
    seen = SeenFreeNodes(free_node, *o.seen_from, region);
    for (std::size_t k = 0; k < n; ++k) free_node[k] = seen[k];
  }
  const std::vector<float> out2 = SquaredEdt(occupied, nx_, ny_);
  const std::vector<float> in2 = SquaredEdt(free_node, nx_, ny_);
  data_.assign(3 * n, 0.0f);
  for (std::size_t k = 0; k < n; ++k) {
    double d;
    if (!seen.empty() && !seen[k]) {
      // Inside (a solid, or free space never seen): as deep as the nearest
      // seen free node is far; in the band the exact depth when its nearest
      // outline is the seen one (the two agree within a cell; a node nearer
      // an unseen face reads more than a cell less exactly).
      const double to_seen =
          std::isfinite(in2[k]) ? (std::sqrt(static_cast<double>(in2[k])) - 0.5) * cell_ : kFar;
      const bool band = occupied[k] && !deep[k] && !std::isnan(exact[k]) &&
                        std::abs(static_cast<double>(exact[k]) - to_seen) <= cell_;
      d = -(band ? static_cast<double>(exact[k]) : to_seen);
    } else if (!deep[k] && !std::isnan(exact[k])) {
      d = -static_cast<double>(exact[k]);
    } else if (occupied[k]) {
      d = std::isfinite(in2[k]) ? -(std::sqrt(static_cast<double>(in2[k])) - 0.5) * cell_ : -kFar;
    } else {
      d = std::isfinite(out2[k]) ? (std::sqrt(static_cast<double>(out2[k])) - 0.5) * cell_ : kFar;
    }
    data_[3 * k] = static_cast<float>(std::clamp(d, -kFar, kFar));
  }
  // Gradient tables: central differences (one-sided on the border).
  for (std::size_t iy = 0; iy < sy; ++iy) {
    for (std::size_t ix = 0; ix < sx; ++ix) {
      const std::size_t k = iy * sx + ix;
      const std::size_t xl = ix > 0 ? k - 1 : k, xr = ix + 1 < sx ? k + 1 : k;
      const std::size_t yl = iy > 0 ? k - sx : k, yr = iy + 1 < sy ? k + sx : k;
      const double gx = (data_[3 * xr] - data_[3 * xl]) / (cell_ * static_cast<double>((xr - xl)));
      const double gy =
          (data_[3 * yr] - data_[3 * yl]) / (cell_ * static_cast<double>((yr - yl) / sx));
      data_[3 * k + 1] = static_cast<float>(gx);
      data_[3 * k + 2] = static_cast<float>(gy);
    }
  }
  // The solids' exact distances for ExactDistance: a grid of two cells per
  // axis (its SignedDistance does not depend on the grid).
  probe_ = std::make_unique<OccupancyGrid>(
      solids_, rect,
      OccupancyGrid::Options{
          0.5 * std::min(rect.max_x_m - rect.min_x_m, rect.max_y_m - rect.min_y_m), 1, 0.0, 1.0});
}

std::vector<char> DistanceMap::SeenFreeNodes(const std::vector<char>& free_node,
                                             const std::array<double, 2>& from,
                                             const std::optional<Region>& region) const {
  const auto sx = static_cast<std::size_t>(nx_);
  const std::size_t n = free_node.size();
  const auto inside = [&](std::size_t k) {
    if (!region) return true;
    const double x = origin_x_ + (static_cast<double>(k % sx) + 0.5) * cell_;
    const double y = origin_y_ + (static_cast<double>(k / sx) + 0.5) * cell_;
    return x >= region->min_x && x <= region->max_x && y >= region->min_y && y <= region->max_y;
  };
  // The seed: the free node nearest to `from` (within the region).
  std::size_t seed = n;
  double best = std::numeric_limits<double>::infinity();
  const int cx = static_cast<int>(std::floor((from[0] - origin_x_) * inv_cell_));
  const int cy = static_cast<int>(std::floor((from[1] - origin_y_) * inv_cell_));
  for (int r = 0; r < std::max(nx_, ny_) && seed == n; ++r) {
    for (int iy = std::max(0, cy - r); iy <= std::min(ny_ - 1, cy + r); ++iy) {
      for (int ix = std::max(0, cx - r); ix <= std::min(nx_ - 1, cx + r); ++ix) {
        const std::size_t k = static_cast<std::size_t>(iy) * sx + static_cast<std::size_t>(ix);
        if (!free_node[k] || !inside(k)) continue;
        const double d2 = std::pow(ix - cx, 2) + std::pow(iy - cy, 2);
        if (d2 < best) {
          best = d2;
          seed = k;
        }
      }
    }
  }
  std::vector<char> seen(n, 0);
  if (seed == n) return seen;
  std::vector<std::size_t> queue{seed};
  seen[seed] = 1;
  while (!queue.empty()) {
    const std::size_t k = queue.back();
    queue.pop_back();
    const std::size_t ix = k % sx, iy = k / sx;
    const std::size_t next[4] = {ix > 0 ? k - 1 : n, ix + 1 < sx ? k + 1 : n,
                                 iy > 0 ? k - sx : n, k + sx < n ? k + sx : n};
    for (std::size_t m : next) {
      if (m < n && !seen[m] && free_node[m] && inside(m)) {
        seen[m] = 1;
        queue.push_back(m);
      }
    }
  }
  return seen;
}

DistanceMap::~DistanceMap() = default;

double DistanceMap::ExactDistance(double x, double y) const {
  double sd = probe_->SignedDistance(x, y);  // inside +
  for (const Polygon& p : slices_) sd = std::max(sd, PolygonSignedDistance(p, x, y));
  return -sd;
}

}  // namespace linesim::estimation
