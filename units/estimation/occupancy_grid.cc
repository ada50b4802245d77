#include "units/estimation/occupancy_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace linesim::estimation {
namespace {

// Signed distance (positive inside) from (x, y) to the outline of a solid's
// footprint.
double SolidSignedDistance(const models::Solid& s, double x, double y) {
  const double dx = x - s.x_m, dy = y - s.y_m;
  if (s.kind == models::Solid::Kind::kCylinder) return s.radius_m - std::hypot(dx, dy);
  const double c = std::cos(s.yaw_rad), sn = std::sin(s.yaw_rad);
  const double u = std::abs(c * dx + sn * dy) - 0.5 * s.length_m;
  const double v = std::abs(-sn * dx + c * dy) - 0.5 * s.width_m;
  const double outside = std::hypot(std::max(u, 0.0), std::max(v, 0.0));
  const double inside = std::min(std::max(u, v), 0.0);
  return -(outside + inside);
}

double Profile(double d, double w) { return std::clamp(1.0 + d / w, 0.0, 2.0); }

}  // namespace

bool OccupancyGrid::CoversPlane(const models::Solid& s, std::span<const double> plane_heights) {
  for (const double z : plane_heights) {
    if (z >= s.bottom_m && z <= s.bottom_m + s.height_m) return true;
  }
  return false;
}

OccupancyGrid::OccupancyGrid(const models::Scene& scene, std::span<const double> plane_heights,
                             Options options) {
  for (const models::Obstacle& o : scene.obstacles) {
    if (CoversPlane(o.solid, plane_heights)) solids_.push_back(o.solid);
  }
  Build(scene.floor, options);
}

OccupancyGrid::OccupancyGrid(const std::vector<models::Solid>& solids, const models::Floor& floor,
                             Options options)
    : solids_(solids) {
  Build(floor, options);
}

double OccupancyGrid::SignedDistance(double x, double y) const {
  double d = -std::numeric_limits<double>::infinity();
  for (const models::Solid& s : solids_) d = std::max(d, SolidSignedDistance(s, x, y));
  return d;
}

double OccupancyGrid::ProfileAt(int i, double x, double y) const {
  return Profile(SignedDistance(x, y), level(i).w);
}

void OccupancyGrid::Build(const models::Floor& floor, const Options& o) {
  if (!(o.resolution > 0.0) || o.levels < 1 || o.levels > 8 || !(o.profile_cells >= 1.0) ||
      !(o.margin >= 0.0)) {
    throw std::invalid_argument(
        "occupancy grid: resolution must be > 0, levels 1..8, profile_cells >= 1, margin >= 0");
  }
  levels_.resize(static_cast<std::size_t>(o.levels));
  for (int i = 0; i < o.levels; ++i) {
    Level& l = levels_[static_cast<std::size_t>(i)];
    l.cell = o.resolution * std::ldexp(1.0, i);
    l.inv_cell = 1.0 / l.cell;
    l.w = o.profile_cells * l.cell;
    const double span_x = floor.max_x_m - floor.min_x_m + 2.0 * o.margin;
    const double span_y = floor.max_y_m - floor.min_y_m + 2.0 * o.margin;
    const double nx = std::ceil(span_x / l.cell), ny = std::ceil(span_y / l.cell);
    if (!(nx * ny <= double(1 << 28)) || nx < 2 || ny < 2) {
      throw std::invalid_argument("occupancy grid: the floor gives " + std::to_string(nx) + " x " +
                                  std::to_string(ny) + " cells at " + std::to_string(l.cell) +
                                  " m (at most 2^28, at least 2 x 2)");
    }
    l.nx = static_cast<int>(nx);
    l.ny = static_cast<int>(ny);
    // The grid centred on the floor rectangle.
    l.origin_x = 0.5 * (floor.min_x_m + floor.max_x_m) - 0.5 * nx * l.cell;
    l.origin_y = 0.5 * (floor.min_y_m + floor.max_y_m) - 0.5 * ny * l.cell;
    l.value.assign(static_cast<std::size_t>(l.nx) * static_cast<std::size_t>(l.ny), 0.0f);
    for (const models::Solid& s : solids_) Rasterise(l, s);
  }
}

void OccupancyGrid::Rasterise(Level& l, const models::Solid& s) const {
  // The footprint's bounding box, grown by the profile's width (beyond it
  // the profile is 0).
  double hx = s.radius_m, hy = s.radius_m;
  if (s.kind == models::Solid::Kind::kBox) {
    const double c = std::abs(std::cos(s.yaw_rad)), sn = std::abs(std::sin(s.yaw_rad));
    hx = 0.5 * (s.length_m * c + s.width_m * sn);
    hy = 0.5 * (s.length_m * sn + s.width_m * c);
  }
  hx += l.w + l.cell;
  hy += l.w + l.cell;
  const auto index = [&l](double p, double origin, int n) {
    return std::clamp(static_cast<int>(std::floor((p - origin) * l.inv_cell - 0.5)), 0, n - 1);
  };
  const int x0 = index(s.x_m - hx, l.origin_x, l.nx), x1 = index(s.x_m + hx, l.origin_x, l.nx) + 1;
  const int y0 = index(s.y_m - hy, l.origin_y, l.ny), y1 = index(s.y_m + hy, l.origin_y, l.ny) + 1;
  for (int iy = y0; iy <= std::min(y1, l.ny - 1); ++iy) {
    const double y = l.origin_y + (iy + 0.5) * l.cell;
    float* row = l.value.data() + static_cast<std::size_t>(iy) * static_cast<std::size_t>(l.nx);
    for (int ix = x0; ix <= std::min(x1, l.nx - 1); ++ix) {
      const double x = l.origin_x + (ix + 0.5) * l.cell;
      const auto m = static_cast<float>(Profile(SolidSignedDistance(s, x, y), l.w));
      row[ix] = std::max(row[ix], m);
    }
  }
}

}  // namespace linesim::estimation
