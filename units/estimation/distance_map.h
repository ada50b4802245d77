#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <vector>

#include "models/scene.h"

namespace linesim::estimation {

class OccupancyGrid;

/// The distance map Perfect Match looks its error up in (Lauer, Lange,
/// Riedmiller 2005, "Calculating the perfect match: an efficient and
/// accurate approach for robot self-localization", Sec. 3: a precomputed
/// distance transform of the map with gradient tables, on a lookup grid).
///
/// The map: the scene's static solids sliced by the horizontal plane z: a
/// point (x, y) is occupied when (x, y, z) lies inside an obstacle (a box
/// with yaw or a vertical cylinder, OccupancyGrid::CoversPlane) or inside a
/// terrain piece (a tilted box: its slice is a convex polygon). Carried
/// objects move with their belt and are left out. With a region, only the
/// solids whose footprint (obstacles: the bounding box of the outline;
/// terrain: of the slice) lies inside it.
///
/// The grid: nodes at the cell centres of a grid of cell h over the
/// region (or the floor's rectangle) plus `margin`; each node holds d, the
/// SIGNED distance to the nearest outline (positive in free space, negative
/// inside a solid), and its gradient (dd/dx, dd/dy). Outside the grid the
/// map reads `kFar` with a zero gradient (the error of such a point is
/// ~1 and does not pull).
///
/// How d is computed:
///  - occupancy of the nodes and, within `band_cells` cells of an outline,
///    the EXACT signed distance: for obstacles from OccupancyGrid's
///    rasterised profile M = clamp(1 + d / w, 0, 2) of one level at cell h
///    with w = band_cells h (d = (M - 1) w where 0 < M < 2; the same
///    rasteriser hector's map uses, not repeated here), for terrain from
///    the slice polygon;
///  - farther away, Felzenszwalb and Huttenlocher's exact Euclidean distance
///    transform ("Distance transforms of sampled functions", Theory of
///    Computing 8, 2012) of the occupied nodes (outside) and of the free
///    nodes (inside), minus h / 2 (the distance from a node to the nearest
///    other-side node's centre overstates the distance to the outline between
///    them by half a cell for a face on the cell boundary).
/// Why the exact band: the EDT of cell centres puts each face on a cell
/// boundary, up to h / 2 off (25 mm at Tribots' 50 mm cells), a bias as
/// large as the LMS151's statistical error; the scan points that decide
/// the match lie on the outlines, where the band is exact.
/// Why signed: the bilinear interpolant of |d| is flat (h / 2) between the
/// two nodes either side of a face, so the error has no minimum on the
/// face; a signed d is linear across a straight face and reproduced exactly
/// by the bilinear interpolant (the error d^2 / (c^2 + d^2) is even in d).
///
/// The basin's limit from thin solids: inside a solid d is minus the
/// distance to its NEAREST outline, so a point pushed deeper than half the
/// solid's thickness (a pose error) is pulled out through its far face.
/// Starts must stay within half the thinnest seen solid's thickness of the
/// truth at the walls (25 mm for a van's 5 cm sheet walls, 0.1 m for 0.2 m
/// hall walls), unless Options::seen_from keeps only the seen faces.
///
/// Interpolation error (what the tests bound): the bilinear interpolant of a
/// function with second derivatives |d_xx|, |d_yy| <= K on the cell is off
/// by at most K h^2 / 4 (K h^2 / 8 per axis), i.e. 0 on a straight face
/// (linear d), h^2 / (4 R) next to a cylinder of radius R, and about h / 2
/// within a cell of a corner or the medial axis. The gradient tables are
/// central differences of d at the nodes, interpolated bilinearly: exact
/// where d is linear over three nodes.
class DistanceMap {
 public:
  struct Region {
    double min_x = 0.0, max_x = 0.0, min_y = 0.0, max_y = 0.0;
  };
  struct Options {
    double cell = 0.02;       // m, the lookup grid's cell h
    double margin = 1.0;      // m beyond the region (or the floor)
    double band_cells = 4.0;  // the exact band, in cells (>= 2)
    /// A point (x, y) in the free space the robot drives in: the map then
    /// holds only the outlines seen from the free space connected to it
    /// (inside the region, when there is one), as a map built by SLAM
    /// does (paper 2: "only the inner contours of the van interior").
    /// Free space not connected to it (behind a wall, outside the region)
    /// counts as inside a solid, and inside a solid d is minus the distance
    /// to the nearest seen outline: a thin wall then has one face, and a
    /// point pushed through it is pulled back out the side it was seen
    /// from (without it, a 5 cm van wall gives two minima 5 cm apart).
    std::optional<std::array<double, 2>> seen_from;
  };
  /// What outside the grid reads (m).
  static constexpr double kFar = 100.0;

  /// The map of the scene's static solids at slice height z (m above the
  /// floor). Throws std::invalid_argument for a bad option, an empty
  /// region or a grid beyond 2^28 nodes.
  DistanceMap(const models::Scene& scene, double z, std::optional<Region> region, Options options);
  ~DistanceMap();
  DistanceMap(const DistanceMap&) = delete;
  DistanceMap& operator=(const DistanceMap&) = delete;

  /// The slice of a terrain piece at height z: a convex polygon
  /// (counter-clockwise, x y pairs), empty when the plane misses it.
  static std::vector<std::array<double, 2>> TerrainSlice(const models::TerrainPiece& t, double z);

  /// The free nodes connected to the one nearest `from` (4-neighbours,
  /// within `region` when given).
  std::vector<char> SeenFreeNodes(const std::vector<char>& free_node,
                                  const std::array<double, 2>& from,
                                  const std::optional<Region>& region) const;
  /// Signed distance (positive outside) from (x, y) to the map's outlines,
  /// evaluated from the geometry (for tests and for the band).
  double ExactDistance(double x, double y) const;

  /// Bilinear d (m) and gradient at (x, y); kFar and 0 outside the grid.
  double Lookup(double x, double y, double& gx, double& gy) const {
    const double fx = (x - origin_x_) * inv_cell_ - 0.5;
    const double fy = (y - origin_y_) * inv_cell_ - 0.5;
    // Compare before converting: a NaN or a point far outside never indexes.
    if (!(fx >= 0.0 && fy >= 0.0 && fx < nx_ - 1 && fy < ny_ - 1)) {
      gx = gy = 0.0;
      return kFar;
    }
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const double tx = fx - ix, ty = fy - iy;
    const float* p =
        data_.data() + 3 * (static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) +
                            static_cast<std::size_t>(ix));
    const float* q = p + 3 * static_cast<std::size_t>(nx_);
    const double w00 = (1.0 - tx) * (1.0 - ty), w10 = tx * (1.0 - ty), w01 = (1.0 - tx) * ty,
                 w11 = tx * ty;
    gx = w00 * p[1] + w10 * p[4] + w01 * q[1] + w11 * q[4];
    gy = w00 * p[2] + w10 * p[5] + w01 * q[2] + w11 * q[5];
    return w00 * p[0] + w10 * p[3] + w01 * q[0] + w11 * q[3];
  }

  /// Bilinear d (m) and the interpolant's own gradient (its derivative,
  /// from the 4 nodes' d alone, no gradient tables). kFar and 0 outside
  /// the grid.
  double LookupInterpolant(double x, double y, double& gx, double& gy) const {
    const double fx = (x - origin_x_) * inv_cell_ - 0.5;
    const double fy = (y - origin_y_) * inv_cell_ - 0.5;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < nx_ - 1 && fy < ny_ - 1)) {
      gx = gy = 0.0;
      return kFar;
    }
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const double tx = fx - ix, ty = fy - iy;
    const float* p =
        data_.data() + 3 * (static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) +
                            static_cast<std::size_t>(ix));
    const float* q = p + 3 * static_cast<std::size_t>(nx_);
    const double v00 = p[0], v10 = p[3], v01 = q[0], v11 = q[3];
    const double a = v00 + tx * (v10 - v00);
    const double b = v01 + tx * (v11 - v01);
    gx = ((v10 - v00) * (1.0 - ty) + (v11 - v01) * ty) * inv_cell_;
    gy = (b - a) * inv_cell_;
    return a + ty * (b - a);
  }

  double cell() const { return cell_; }
  int nx() const { return nx_; }
  int ny() const { return ny_; }
  double origin_x() const { return origin_x_; }
  double origin_y() const { return origin_y_; }
  /// Node (ix, iy)'s d (m).
  double NodeDistance(int ix, int iy) const {
    return data_[3 * (static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) +
                      static_cast<std::size_t>(ix))];
  }
  std::size_t occupied_nodes() const { return occupied_; }
  const std::vector<models::Solid>& solids() const { return solids_; }
  std::size_t terrain_count() const { return slices_.size(); }
  std::size_t bytes() const { return data_.size() * sizeof(float); }

 private:
  std::vector<models::Solid> solids_;
  std::vector<std::vector<std::array<double, 2>>> slices_;  // terrain slice polygons
  double cell_ = 0.0, inv_cell_ = 0.0, origin_x_ = 0.0, origin_y_ = 0.0;
  int nx_ = 0, ny_ = 0;
  std::size_t occupied_ = 0;
  std::vector<float> data_;               // per node d, gx, gy; row-major in y
  std::unique_ptr<OccupancyGrid> probe_;  // the solids, for ExactDistance
};

}  // namespace linesim::estimation
