// models::PolygonProblem: what a protective or warning field must be.

#include "models/polygon.h"

#include <gtest/gtest.h>

#include <cmath>

namespace linesim::models {
namespace {

bool Says(const std::optional<std::string>& problem, const std::string& text) {
  return problem && problem->find(text) != std::string::npos;
}

// Guards against refusing real fields: the S300 fields of the shipped robot
// files are a rectangle, a trapezoid, a concave L and a triangle; orientation
// (clockwise or not) does not matter, nor a rotation into the scanner frame
// whose rounding leaves three corners almost (not exactly) on a line.
TEST(PolygonProblem, AcceptsSimplePolygons) {
  EXPECT_FALSE(PolygonProblem({{0.0, -0.4}, {0.6, -0.4}, {0.6, 0.4}, {0.0, 0.4}}));
  EXPECT_FALSE(PolygonProblem({{0.0, 0.4}, {0.6, 0.4}, {0.6, -0.4}, {0.0, -0.4}}));
  EXPECT_FALSE(PolygonProblem({{0.0, -0.3}, {1.2, -0.6}, {1.2, 0.6}, {0.0, 0.3}}));
  EXPECT_FALSE(PolygonProblem({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}));
  EXPECT_FALSE(PolygonProblem({{0, 0}, {1, 0}, {0, 1}}));
  // A rectangle with a corner in the middle of an edge (collinear with its
  // neighbours, but the polygon has area): accepted.
  EXPECT_FALSE(PolygonProblem({{0, 0}, {0.5, 0}, {1, 0}, {1, 1}, {0, 1}}));
  const double c = std::cos(0.3), s = std::sin(0.3);
  std::vector<std::array<double, 2>> rotated;
  for (const auto& [x, y] :
       std::vector<std::array<double, 2>>{{0, 0}, {0.1, 0}, {0.3, 0}, {0.3, 0.1}}) {
    rotated.push_back({c * x - s * y, s * x + c * y});
  }
  EXPECT_FALSE(PolygonProblem(rotated));
}

// Guards issue 37: a collinear or zero-area protective field was accepted
// and silently disabled the stop (no beam point is ever inside it).
TEST(PolygonProblem, RefusesZeroArea) {
  EXPECT_TRUE(Says(PolygonProblem({{0, 0}, {1, 0}, {2, 0}}), "zero area"));
  EXPECT_TRUE(Says(PolygonProblem({{0.1, 0.2}, {0.3, 0.6}, {0.5, 1.0}, {0.2, 0.4}}), "zero area"));
  EXPECT_TRUE(Says(PolygonProblem({{0, 0}, {1, 1}, {2, 2}}), "zero area"));
}

// Guards against fields the even-odd rule reads as something else than drawn:
// a bow tie (its crossing edges), a figure touching itself at a corner, an
// edge running back along the one before it, and too few or repeated corners.
TEST(PolygonProblem, RefusesSelfIntersectingAndDegenerate) {
  EXPECT_TRUE(Says(PolygonProblem({{0, 0}, {1, 1}, {1, 0}, {0, 1}}), "self-intersecting"));
  EXPECT_TRUE(
      Says(PolygonProblem({{0, 0}, {2, 0}, {1, 1}, {2, 2}, {0, 2}, {1, 1}}), "self-intersecting"));
  EXPECT_TRUE(Says(PolygonProblem({{0, 0}, {2, 0}, {1, 0}, {1, 1}}), "folds back"));
  EXPECT_TRUE(Says(PolygonProblem({{0, 0}, {1, 0}}), "at least 3 corners"));
  EXPECT_TRUE(Says(PolygonProblem({}), "at least 3 corners"));
  EXPECT_TRUE(Says(PolygonProblem({{0, 0}, {1, 0}, {1, 0}, {0, 1}}), "corner 2 repeats corner 1"));
  EXPECT_TRUE(Says(PolygonProblem({{0, 0}, {1, 0}, {0, 1}, {0, 0}}), "corner 0 repeats corner 3"));
}

}  // namespace
}  // namespace linesim::models
