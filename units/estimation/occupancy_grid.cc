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

OccupancyGrid::OccupancyGrid(const models::Floor& floor, Options options, UpdateFactors factors)
    : learned_(true) {
  if (!(factors.occupied > 0.0 && factors.occupied < 1.0 && factors.free > 0.0 &&
        factors.free < 1.0)) {
    throw std::invalid_argument("occupancy grid: update factors must be in (0, 1)");
  }
  // hector's probToLogOdds, in float as hector keeps them.
  log_odds_occupied_ = static_cast<float>(std::log(factors.occupied / (1.0 - factors.occupied)));
  log_odds_free_ = static_cast<float>(std::log(factors.free / (1.0 - factors.free)));
  Build(floor, options);
  for (Level& l : levels_) {
    l.log_odds.assign(l.value.size(), 0.0f);
    l.stamp.assign(l.value.size(), 0u);
  }
  Clear();
}

void OccupancyGrid::Clear() {
  if (!learned_) throw std::logic_error("occupancy grid: Clear on a map built from the scene");
  for (Level& l : levels_) {
    std::fill(l.log_odds.begin(), l.log_odds.end(), 0.0f);
    std::fill(l.value.begin(), l.value.end(), Probability(0.0f));
    std::fill(l.stamp.begin(), l.stamp.end(), 0u);
  }
  update_index_ = 0;
}

void OccupancyGrid::SetLogOdds(int i, std::span<const float> log_odds) {
  if (!learned_) throw std::logic_error("occupancy grid: SetLogOdds on a map built from the scene");
  Level& l = levels_.at(static_cast<std::size_t>(i));
  if (log_odds.size() != l.log_odds.size()) {
    throw std::invalid_argument("occupancy grid: level " + std::to_string(i) + " holds " +
                                std::to_string(l.log_odds.size()) + " cells, got " +
                                std::to_string(log_odds.size()));
  }
  for (std::size_t k = 0; k < log_odds.size(); ++k) {
    l.log_odds[k] = log_odds[k];
    l.value[k] = Probability(log_odds[k]);
  }
  std::fill(l.stamp.begin(), l.stamp.end(), 0u);
}

bool OccupancyGrid::CellOf(int i, double x, double y, int& ix, int& iy) const {
  const Level& l = level(i);
  const double fx = std::floor((x - l.origin_x) * l.inv_cell);
  const double fy = std::floor((y - l.origin_y) * l.inv_cell);
  // Compare before converting: NaN or far away never indexes.
  if (!(fx >= 0.0 && fy >= 0.0 && fx < l.nx && fy < l.ny)) return false;
  ix = static_cast<int>(fx);
  iy = static_cast<int>(fy);
  return true;
}

// Update marks of one scan (update_index_ + ...): 1 a miss skipped at the
// bound, 2 a miss applied, 3 a hit. A cell whose stamp is below 1 is
// untouched by this scan.
namespace {
constexpr std::uint32_t kMissSkipped = 1, kMissApplied = 2, kHit = 3, kMarks = 4;
}  // namespace

void OccupancyGrid::Free(Level& l, std::size_t k) const {
  std::uint32_t& st = l.stamp[k];
  if (st > update_index_) return;  // already missed or hit in this scan
  float& lo = l.log_odds[k];
  if (lo > -kLogOddsBound) {
    lo += log_odds_free_;
    l.value[k] = Probability(lo);
    st = update_index_ + kMissApplied;
  } else {
    st = update_index_ + kMissSkipped;
  }
}

void OccupancyGrid::Occupy(Level& l, std::size_t k) const {
  std::uint32_t& st = l.stamp[k];
  if (st >= update_index_ + kHit) return;  // already hit in this scan
  float& lo = l.log_odds[k];
  // A miss of this scan undone (hector's updateUnsetFree): the cell counts
  // once, as a hit.
  if (st == update_index_ + kMissApplied) lo -= log_odds_free_;
  if (lo < kLogOddsBound) lo += log_odds_occupied_;
  l.value[k] = Probability(lo);
  st = update_index_ + kHit;
}

void OccupancyGrid::UpdateLevel(Level& l, std::span<const double> px, std::span<const double> py,
                                double ox, double oy, double x, double y, double c, double s) {
  const auto cell = [&l](double wx, double wy, int& ix, int& iy) {
    const double fx = std::floor((wx - l.origin_x) * l.inv_cell);
    const double fy = std::floor((wy - l.origin_y) * l.inv_cell);
    if (!(fx >= 0.0 && fy >= 0.0 && fx < l.nx && fy < l.ny)) return false;
    ix = static_cast<int>(fx);
    iy = static_cast<int>(fy);
    return true;
  };
  int x0 = 0, y0 = 0;
  if (!cell(x + c * ox - s * oy, y + s * ox + c * oy, x0, y0)) return;  // laser off the map
  const std::ptrdiff_t nx = l.nx;
  const std::ptrdiff_t start = static_cast<std::ptrdiff_t>(y0) * nx + x0;
  const std::size_t n = std::min(px.size(), py.size());
  for (std::size_t i = 0; i < n; ++i) {
    int x1 = 0, y1 = 0;
    if (!cell(x + c * px[i] - s * py[i], y + s * px[i] + c * py[i], x1, y1)) continue;
    if (x1 == x0 && y1 == y0) continue;
    const int dx = x1 - x0, dy = y1 - y0;
    const int adx = std::abs(dx), ady = std::abs(dy);
    const std::ptrdiff_t sx = dx > 0 ? 1 : (dx < 0 ? -1 : 0);
    const std::ptrdiff_t sy = dy > 0 ? nx : (dy < 0 ? -nx : 0);
    // Bresenham along the dominant axis a: the start cell and the next
    // |da| - 1 cells are misses; the end cell (|da| steps on) is the hit.
    const int da = adx >= ady ? adx : ady, db = adx >= ady ? ady : adx;
    const std::ptrdiff_t step_a = adx >= ady ? sx : sy, step_b = adx >= ady ? sy : sx;
    int err = da / 2;
    std::ptrdiff_t k = start;
    Free(l, static_cast<std::size_t>(k));
    for (int j = 1; j < da; ++j) {
      k += step_a;
      err += db;
      if (err >= da) {
        k += step_b;
        err -= da;
      }
      Free(l, static_cast<std::size_t>(k));
    }
    Occupy(l, static_cast<std::size_t>(static_cast<std::ptrdiff_t>(y1) * nx + x1));
  }
}

void OccupancyGrid::UpdateByScan(std::span<const double> px, std::span<const double> py, double ox,
                                 double oy, double x, double y, double yaw) {
  if (!learned_)
    throw std::logic_error("occupancy grid: UpdateByScan on a map built from the scene");
  // Before the marks could wrap: every stamp back below the next scan's.
  if (update_index_ > std::numeric_limits<std::uint32_t>::max() - 2 * kMarks) {
    for (Level& l : levels_) std::fill(l.stamp.begin(), l.stamp.end(), 0u);
    update_index_ = 0;
  }
  const double c = std::cos(yaw), s = std::sin(yaw);
  for (Level& l : levels_) UpdateLevel(l, px, py, ox, oy, x, y, c, s);
  update_index_ += kMarks;
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
    if (!(nx * ny <= kMaxCells) || nx < 2 || ny < 2) {
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
