#pragma once

#include <cstddef>
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
class OccupancyGrid {
 public:
  struct Options {
    double resolution = 0.025;  // finest cell (m): hector's map_resolution default
    int levels = 3;             // hector's map_multi_res_levels default
    double margin = 0.5;        // m beyond the floor rectangle
    double profile_cells = 2.0; // w in cells of each level (see above)
  };
  struct Level {
    double cell = 0.0, inv_cell = 0.0;
    double origin_x = 0.0, origin_y = 0.0;  // corner of cell (0, 0)
    int nx = 0, ny = 0;
    double w = 0.0;  // profile width (m)
    std::vector<float> value;  // nx * ny, row-major in y
  };

  /// Builds every level (throws std::invalid_argument for a resolution <= 0,
  /// levels < 1, or a grid beyond 2^28 cells).
  OccupancyGrid(const models::Scene& scene, std::span<const double> plane_heights,
                Options options);
  OccupancyGrid(const std::vector<models::Solid>& solids, const models::Floor& floor,
                Options options);

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
    const float* p = l.value.data() + static_cast<std::size_t>(iy) * static_cast<std::size_t>(l.nx) +
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

  std::vector<models::Solid> solids_;
  std::vector<Level> levels_;
};

}  // namespace linesim::estimation
