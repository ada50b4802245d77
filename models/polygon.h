#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace linesim::models {

/// Why a list of [x, y] corners is no simple polygon a point can lie in,
/// or nothing: fewer than 3 corners, a corner that repeats the one before
/// it (the last counts as before the first), all corners on one line
/// (within rounding: each corner's distance from the line through corner 0
/// and the corner farthest from it at most 1e-12 times that distance), or
/// edges that cross, touch or fold back onto each other (self-
/// intersecting, a bow tie among them). Such a field would hold
/// no point, or points the even-odd rule counts as outside: a protective
/// field that silently never stops the robot. Exact orientation tests on
/// the corners as given (no tolerance beyond the area's), O(n^2) in the
/// corners, which fields have a few of.
std::optional<std::string> PolygonProblem(const std::vector<std::array<double, 2>>& corners);

}  // namespace linesim::models
