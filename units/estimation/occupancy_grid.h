#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "models/scene.h"

namespace linesim::estimation {

/// The multi-resolution map a laser scan is matched against (hector_mapping's
/// MapRepMultiMap: one grid per level, level i with cells of
/// resolution * 2^i, each rasterised at its own cell size), built from the
/// scene's static solids before time zero instead of by mapping.
///
/// What is in it: every scene obstacle (models::Solid box or cylinder) whose
/// vertical extent [bottom, bottom + height] contains one of the scan plane
/// heights given; not the carried objects (they move with their belt) and
/// not the belts (flush with the floor). The grid covers the floor rectangle
/// plus `margin` on each side; outside it the map reads 0.
///
/// Cell values and their profile. A node (the centre of a cell) holds
///   M = clamp(1 + d / w, 0, 2),  w = profile_cells * cell size,
/// with d the signed distance from the node to the nearest solid's outline in
/// the scan plane, positive inside the solid (the largest over the solids:
/// the union). So M is 1 ON the outline, falls to 0 at w in front of it, and
/// rises to 2 at w behind it. Why not a peak (1 on the outline, less on both
/// sides, like hector's log-odds cells): the bilinear interpolant of nodes
/// is piecewise linear, so its maximum always lies on a node (or a flat
/// segment between two), never between nodes: a peaked profile puts the
/// matcher's optimum on the node nearest the face, up to half a cell off
/// (12.5 mm at 0.025 m) and the same for every point of an axis-aligned
/// wall. A profile LINEAR across the face is reproduced exactly by the
/// bilinear interpolant wherever the four nodes around a point lie within
/// w of a plane face (w >= 2 cells guarantees it for a point within
/// w - 1 cell of the face, and the face is the nearest feature of all four),
/// so the residual 1 - M = -d / w is zero exactly on the face and the
/// matcher's cost is the point-to-line distance squared (over w^2): no bias
/// for straight faces. On a cylinder of radius R the profile bends
/// (|d''| = 1 / (rho w) across the radius): the bilinear error is at most
/// 2 (cell^2 / 8) / (R w), i.e. a face offset of at most cell^2 / (4 R)
/// (0.6 mm for the scene's 0.25 m pillars at 0.025 m cells). The residual is what peaks
/// (at zero) on the outline. Stored as float (the values are O(1) and
/// interpolated; float halves the memory the lookups touch).
///
/// Learned map (the other constructor, `map: mapping` of laser_localization):
/// the same levels over the same rectangle, every cell unknown, learned from
/// scans as hector_mapping does (tu-darmstadt hector_slam: MapRepMultiMap
/// updates every level with every scan; OccGridMapBase::updateByScan,
/// GridMapLogOdds.h). Per cell a log-odds L (0 = unknown); a scan adds
/// log_odds_occupied (log(0.9 / 0.1) = 2.197 for hector's launch file's
/// update_factor_occupied 0.9) to the cell holding each beam's end point
/// and log_odds_free (log(0.4 / 0.6) = -0.405, update_factor_free 0.4) to
/// every cell a Bresenham line from the laser's cell passes before it (the
/// end cell skipped). Each cell counts once per scan (hector's update
/// index: a per-cell stamp; a cell first marked free and then hit has its
/// free update undone, hector's updateUnsetFree). A beam whose start or end
/// cell leaves the grid, or that ends in its start cell, updates nothing
/// (hector). L is bounded: a hit only while L < 50 (hector's bound), a miss
/// only while L > -50 (ours, the mirror: hector's stablize uses +-50 as
/// "very occupied / very free"). The matcher reads `value` = the cell's
/// probability 1 / (1 + exp(-L)) (hector's getGridProbability; unknown 0.5),
/// kept in step with L at each update: the peaked profile this comment's
/// first part warns about (the hit cell's centre is where the map peaks),
/// which is hector's.
class OccupancyGrid {
 public:
  struct Options {
    double resolution = 0.025;   // finest cell (m): hector's map_resolution default
    int levels = 3;              // hector's map_multi_res_levels default
    double margin = 0.5;         // m beyond the floor rectangle
    double profile_cells = 2.0;  // w in cells of each level (see above)
  };
  struct Level {
    double cell = 0.0, inv_cell = 0.0;
    double origin_x = 0.0, origin_y = 0.0;  // corner of cell (0, 0)
    int nx = 0, ny = 0;
    double w = 0.0;            // profile width (m)
    std::vector<float> value;  // nx * ny, row-major in y
    // Learned maps only (empty otherwise): log-odds and update stamps per cell.
    std::vector<float> log_odds;
    std::vector<std::uint32_t> stamp;
  };
  /// hector_mapping's default launch file (mapping_default.launch):
  /// update_factor_occupied 0.9, update_factor_free 0.4.
  struct UpdateFactors {
    double occupied = 0.9;
    double free = 0.4;
  };
  static constexpr float kLogOddsBound = 50.0f;
  /// The most cells a level may have (a float each, several arrays: 1 GiB).
  static constexpr double kMaxCells = double(1 << 28);

  /// Builds every level (throws std::invalid_argument for a resolution <= 0,
  /// levels < 1, or a grid beyond 2^28 cells).
  OccupancyGrid(const models::Scene& scene, std::span<const double> plane_heights, Options options);
  OccupancyGrid(const std::vector<models::Solid>& solids, const models::Floor& floor,
                Options options);
  /// A learned map over the floor rectangle + margin, every cell unknown
  /// (log-odds 0, value 0.5). Throws std::invalid_argument for factors
  /// outside (0, 1).
  OccupancyGrid(const models::Floor& floor, Options options, UpdateFactors factors);

  bool learned() const { return learned_; }
  float log_odds_occupied() const { return log_odds_occupied_; }
  float log_odds_free() const { return log_odds_free_; }
  /// The probability a log-odds value stands for (what `value` holds).
  static float Probability(float log_odds) { return 1.0f / (1.0f + std::exp(-log_odds)); }
  /// Learned maps: every cell back to unknown.
  void Clear();
  /// Learned maps: the scan's beams (points px, py in the robot's frame, the
  /// laser at (ox, oy) in that frame) entered into every level with the
  /// robot at (x, y, yaw) in map. Allocation-free.
  void UpdateByScan(std::span<const double> px, std::span<const double> py, double ox, double oy,
                    double x, double y, double yaw);
  /// Learned maps: level i's log-odds replaced by `log_odds` (nx * ny
  /// values), the values recomputed, the stamps reset (a stamp only matters
  /// within one update). Throws std::invalid_argument on a size mismatch.
  void SetLogOdds(int i, std::span<const float> log_odds);
  /// The cell (ix, iy) of level i holding (x, y); false outside the grid.
  bool CellOf(int i, double x, double y, int& ix, int& iy) const;

  /// Whether a solid is in the map for these scan plane heights.
  static bool CoversPlane(const models::Solid& s, std::span<const double> plane_heights);

  int levels() const { return static_cast<int>(levels_.size()); }
  const Level& level(int i) const { return levels_[static_cast<std::size_t>(i)]; }
  double cell_size(int i) const { return level(i).cell; }
  std::size_t solid_count() const { return solids_.size(); }
  const std::vector<models::Solid>& solids() const { return solids_; }

  /// The value a node holds at a point (the profile of its signed distance
  /// to the map's solids) on level i: what the grid samples.
  double ProfileAt(int i, double x, double y) const;
  /// Signed distance (m, positive inside) from (x, y) to the nearest solid's
  /// outline (the largest over the solids); -inf without solids.
  double SignedDistance(double x, double y) const;

  /// Bilinear value at (x, y) (map, m) on level i; 0 outside the grid.
  double Value(int i, double x, double y) const {
    double gx, gy;
    return ValueAndGradient(i, x, y, gx, gy);
  }
  /// Bilinear value and its gradient (1/m) at (x, y) (hector's
  /// interpolateMapValueWithDerivatives, in SI and with the nodes at the cell
  /// centres); value and gradient 0 where the 2 x 2 nodes leave the grid.
  double ValueAndGradient(int i, double x, double y, double& gx, double& gy) const {
    const Level& l = levels_[static_cast<std::size_t>(i)];
    const double fx = (x - l.origin_x) * l.inv_cell - 0.5;
    const double fy = (y - l.origin_y) * l.inv_cell - 0.5;
    // Compare before converting: a NaN or a point far outside never indexes.
    if (!(fx >= 0.0 && fy >= 0.0 && fx < l.nx - 1 && fy < l.ny - 1)) {
      gx = gy = 0.0;
      return 0.0;
    }
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const double tx = fx - ix, ty = fy - iy;
    const float* p = l.value.data() +
                     static_cast<std::size_t>(iy) * static_cast<std::size_t>(l.nx) +
                     static_cast<std::size_t>(ix);
    const double v00 = p[0], v10 = p[1], v01 = p[l.nx], v11 = p[l.nx + 1];
    const double a = v00 + tx * (v10 - v00);  // along x at y = iy
    const double b = v01 + tx * (v11 - v01);  // along x at y = iy + 1
    gx = ((v10 - v00) * (1.0 - ty) + (v11 - v01) * ty) * l.inv_cell;
    gy = (b - a) * l.inv_cell;
    return a + ty * (b - a);
  }

 private:
  void Build(const models::Floor& floor, const Options& options);
  void Rasterise(Level& l, const models::Solid& s) const;
  void UpdateLevel(Level& l, std::span<const double> px, std::span<const double> py, double ox,
                   double oy, double x, double y, double c, double s);
  void Free(Level& l, std::size_t k) const;
  void Occupy(Level& l, std::size_t k) const;

  std::vector<models::Solid> solids_;
  std::vector<Level> levels_;
  bool learned_ = false;
  float log_odds_occupied_ = 0.0f, log_odds_free_ = 0.0f;
  // hector's update index: a scan's free mark is update_index_ + 1, its
  // occupied mark update_index_ + 2; + 3 per scan.
  std::uint32_t update_index_ = 0;
};

}  // namespace linesim::estimation
