// RayScene's ranges against the kernels Embree picks at run time (SSE2 ...
// AVX-512 by the CPU): a machine-dependent range would make every closed loop
// on lasers machine-dependent.
#include "units/sensors/ray_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "models/scene.h"

namespace linesim::sensors {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// A hall as models/scenes/factory_line.yaml (30 x 20 m floor, walls on its
// edges) with many boxes (some sharing faces, where single-precision kernels
// disagree on which is met first), pillars and a ramp.
models::Scene Hall() {
  models::Scene s = models::OpenFloor();
  s.floor = {-15.0, 15.0, -10.0, 10.0, 0};
  s.obstacles.push_back({"north", "wall", models::BoxSolid(0.0, 9.9, 0.0, 30.0, 0.2, 4.0)});
  s.obstacles.push_back({"south", "wall", models::BoxSolid(0.0, -9.9, 0.0, 30.0, 0.2, 4.0)});
  s.obstacles.push_back({"west", "wall", models::BoxSolid(-14.9, 0.0, 90 * kDeg, 19.6, 0.2, 4.0)});
  s.obstacles.push_back({"east", "wall", models::BoxSolid(14.9, 0.0, 90 * kDeg, 19.6, 0.2, 4.0)});
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const double x = -12 + 24 * u(rng), y = -8 + 16 * u(rng);
    s.obstacles.push_back({"b" + std::to_string(i), "box",
                           models::BoxSolid(x, y, (i % 3 == 0) ? 0.0 : u(rng) * 3.0,
                                            0.2 + 2 * u(rng), 0.2 + 2 * u(rng), 0.1 + 2 * u(rng))});
    // A twin sharing its face (same plane, touching): exact ties.
    if (i % 5 == 0) {
      const models::Solid& b = s.obstacles.back().solid;
      s.obstacles.push_back({"t" + std::to_string(i), "box",
                             models::BoxSolid(b.x_m + b.length_m, b.y_m, 0.0, b.length_m,
                                              b.width_m, b.height_m)});
    }
  }
  for (int i = 0; i < 10; ++i) {
    s.obstacles.push_back({"p" + std::to_string(i), "pillar",
                           models::CylinderSolid(-10 + 20 * u(rng), -10 + 20 * u(rng),
                                                 0.05 + 0.3 * u(rng), 3.0)});
  }
  models::TerrainPiece ramp;
  ramp.name = "ramp";
  ramp.center_x_m = 3.0;
  ramp.center_y_m = -4.0;
  ramp.length_m = 2.0;
  ramp.width_m = 1.5;
  ramp.thickness_m = 0.05;
  ramp.pitch_rad = 15.0 * kDeg;
  s.terrain.push_back(ramp);
  return s;
}

std::vector<Ray> Scans() {
  std::vector<Ray> rays;
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int scan = 0; scan < 40; ++scan) {
    const double x = -8 + 16 * u(rng), y = -8 + 16 * u(rng), z = 0.05 + 0.4 * u(rng);
    const double pitch = (scan % 4 == 0) ? (u(rng) - 0.5) * 30 * kDeg : 0.0;
    for (int i = 0; i < 541; ++i) {
      const double a = -135 * kDeg + i * 0.5 * kDeg + u(rng) * 1e-3;
      Ray r;
      r.origin = {x, y, z};
      // A level scanner's beams, rotated by the mount and the chassis'
      // attitude, have vertical components of rounding size and either sign
      // (as in a robot scenario): rays parallel to the floor and box tops.
      const double dz = pitch != 0.0 ? std::sin(pitch)
                        : scan % 4 == 1 ? -1e-18 * (0.5 + u(rng))
                        : scan % 4 == 2 ? 0.0
                                        : ((i * 7 + scan) % 3 - 1) * 1e-18 * u(rng);
      r.direction = {std::cos(a) * std::cos(pitch), std::sin(a) * std::cos(pitch), dz};
      r.max_range = 29.5;
      rays.push_back(r);
    }
  }
  return rays;
}

std::vector<RayHit> CastAll(const char* max_isa) {
  if (max_isa != nullptr) {
    setenv("LINESIM_EMBREE_MAX_ISA", max_isa, 1);
  } else {
    unsetenv("LINESIM_EMBREE_MAX_ISA");
  }
  RayScene scene(Hall());
  unsetenv("LINESIM_EMBREE_MAX_ISA");
  const std::vector<Ray> rays = Scans();
  std::vector<RayHit> hits(rays.size());
  // As a scanner's steps cast them: an S300 turning at 25 Hz casts 13 or 14
  // beams in a 1 ms step (packets of 8 and 6 lanes), a whole scan at once in
  // a 40 ms step (packets of 16).
  for (std::size_t first = 0; first < rays.size(); first += 541) {
    const std::size_t chunk = (first / 541) % 2 == 0 ? 14 : 541;
    for (std::size_t f = first; f < first + 541; f += chunk) {
      const std::size_t n = std::min(chunk, first + 541 - f);
      scene.Cast(std::span<const Ray>(rays).subspan(f, n), std::span<RayHit>(hits).subspan(f, n),
                 {}, {});
    }
  }
  return hits;
}

// The nearest exact hit over every solid, by brute force (ties to the lower
// object), as RayScene promises.
std::vector<RayHit> BruteForce(const models::Scene& s, const std::vector<Ray>& rays) {
  std::vector<RayHit> out;
  for (const Ray& r : rays) {
    RayHit best{std::numeric_limits<double>::infinity(), 0.0, -1};
    const double t_max = std::nextafter(r.max_range, 1e300);
    auto offer = [&](double t, const double* n, int object) {
      if (std::isinf(t)) return;
      if (t < best.range || (t == best.range && object < best.object)) {
        best = {t, std::abs(n[0] * r.direction[0] + n[1] * r.direction[1] + n[2] * r.direction[2]),
                object};
      }
    };
    const double* o = r.origin.data();
    const double* d = r.direction.data();
    if (d[2] != 0.0) {
      const double t = -o[2] / d[2];
      const double x = o[0] + t * d[0], y = o[1] + t * d[1];
      const double up[3] = {0.0, 0.0, 1.0};
      if (t > 1e-9 && t < t_max && x >= s.floor.min_x_m && x <= s.floor.max_x_m &&
          y >= s.floor.min_y_m && y <= s.floor.max_y_m) {
        offer(t, up, RayScene::kFloor);
      }
    }
    for (std::size_t i = 0; i < s.obstacles.size(); ++i) {
      const models::Solid& b = s.obstacles[i].solid;
      double n[3];
      double t;
      if (b.kind == models::Solid::Kind::kCylinder) {
        t = IntersectCylinder({b.x_m, b.y_m, b.radius_m, b.bottom_m, b.bottom_m + b.height_m, 0}, o,
                              d, t_max, n);
      } else {
        const double c = std::cos(b.yaw_rad), sn = std::sin(b.yaw_rad);
        t = IntersectOrientedBox({b.x_m, b.y_m, b.bottom_m + 0.5 * b.height_m},
                                 {0.5 * b.length_m, 0.5 * b.width_m, 0.5 * b.height_m},
                                 {{{c, sn, 0.0}, {-sn, c, 0.0}, {0.0, 0.0, 1.0}}}, o, d, t_max, n);
      }
      offer(t, n, 1 + static_cast<int>(i));
    }
    for (std::size_t i = 0; i < s.terrain.size(); ++i) {
      const models::TerrainPiece& p = s.terrain[i];
      double n[3];
      const double t = IntersectOrientedBox({p.center_x_m, p.center_y_m, p.center_z_m},
                                            {0.5 * p.length_m, 0.5 * p.width_m, 0.5 * p.thickness_m},
                                            models::TerrainAxes(p), o, d, t_max, n);
      offer(t, n, 1 + static_cast<int>(s.obstacles.size() + i));
    }
    out.push_back(best);
  }
  return out;
}

int CountDiffering(const std::vector<RayHit>& expected, const std::vector<RayHit>& got,
                   const std::string& what) {
  int differing = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const RayHit &a = expected[i], &b = got[i];
    if (std::memcmp(&a.range, &b.range, sizeof(double)) != 0 ||
        std::memcmp(&a.cos_incidence, &b.cos_incidence, sizeof(double)) != 0 ||
        a.object != b.object) {
      if (++differing <= 3) {
        ADD_FAILURE() << what << ": ray " << i << " range " << b.range << " object " << b.object
                      << ", expected " << a.range << " object " << a.object;
      }
    }
  }
  return differing;
}

// Guards: a hit Embree's traversal drops (its coherent packet traversal, with
// AVX-512 kernels, dropped beams whose vertical component was a rounding
// error: a whole machine class saw walls vanish), a candidate padded out.
TEST(RayScene, EveryRangeIsTheExactNearestHit) {
  const models::Scene hall = Hall();
  const std::vector<RayHit> expected = BruteForce(hall, Scans());
  EXPECT_EQ(CountDiffering(expected, CastAll(nullptr), "default kernels"), 0);
}

// Guards: Embree's kernels (its BVH layout, traversal order and float
// rounding) deciding a range. Every kernel family this CPU can run must give
// the default's ranges, incidences and objects to the bit.
TEST(RayScene, RangesDoNotDependOnTheKernelsEmbreePicks) {
  const std::vector<RayHit> reference = CastAll(nullptr);
  int hits = 0;
  for (const RayHit& h : reference) hits += h.object >= 0;
  ASSERT_GT(hits, 10000);  // the hall is hit, not missed
  __builtin_cpu_init();
  std::vector<const char*> isas = {"sse2", "sse4.2"};
  if (__builtin_cpu_supports("avx")) isas.push_back("avx");
  if (__builtin_cpu_supports("avx2")) isas.push_back("avx2");
  if (__builtin_cpu_supports("avx512f")) isas.push_back("avx512");
  for (const char* isa : isas) {
    EXPECT_EQ(CountDiffering(reference, CastAll(isa), isa), 0) << isa;
  }
}

}  // namespace
}  // namespace linesim::sensors
