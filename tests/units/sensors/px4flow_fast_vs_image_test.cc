// The fast model of the px4flow unit against the image-level reference
// (rendered frames + the firmware's compute_flow) over a grid of texture
// contrast, light and speed: mean frame quality and flow noise (standard
// deviation of the frame flow over many frames).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "tests/spread.h"
#include "tests/units/test_helpers.h"
#include "units/sensors/px4flow_image.h"
#include "units/sensors/px4flow_unit.h"

namespace linesim::sensors {
namespace {

using cosim::TimeNs;
constexpr double kHeight = 0.1841;  // paper 1

struct Stats {
  double quality = 0.0;  // mean frame quality over all frames
  double mean = 0.0;     // mean frame flow x over frames of quality > 0
  double std = 0.0;      // its standard deviation
  int valid = 0;
  /// The standard error of `std` (a normal sample's: std / sqrt(2 (n - 1))).
  double StdError() const { return valid > 1 ? std / std::sqrt(2.0 * (valid - 1)) : 0.0; }
};

Stats Summarize(const std::vector<double>& q, const std::vector<double>& f) {
  Stats s;
  double sum = 0.0, sq = 0.0;
  for (std::size_t i = 0; i < q.size(); ++i) {
    s.quality += q[i];
    if (q[i] > 0) {
      sum += f[i];
      sq += f[i] * f[i];
      ++s.valid;
    }
  }
  s.quality /= static_cast<double>(q.size());
  if (s.valid > 1) {
    s.mean = sum / s.valid;
    s.std = std::sqrt(std::max(0.0, sq / s.valid - s.mean * s.mean));
  }
  return s;
}

Stats Image(double contrast, double lux, double v, int frames, std::uint64_t seed,
            double defocus_px = 0.0) {
  Px4FlowCamera cam;
  std::vector<double> q, f;
  // Several textures (seeds), as the fast model's blocks are independent
  // draws over many surface patches.
  for (int k = 0; k < 4; ++k) {
    Px4FlowImageModel m(cam, seed + static_cast<std::uint64_t>(k));
    for (int i = 0; i < frames / 4; ++i) {
      const FlowResult r = m.Step(v, 0.0, kHeight, contrast, lux, 1.0, defocus_px);
      q.push_back(r.quality);
      f.push_back(r.flow_x_px);
    }
  }
  return Summarize(q, f);
}

Stats Fast(double contrast, double lux, double v, int frames, std::uint64_t seed,
           double focus_distance = 0.0) {
  models::Scene s;
  s.surfaces.push_back({"floor", 0.8, contrast, lux});
  s.floor = {-50, 50, -50, 50, 0};
  Px4FlowUnit u("flow", s, seed);
  test_helpers::SetAll(u, "mount_x", 0.0);
  test_helpers::SetAll(u, "mount_y", 0.0);
  test_helpers::SetAll(u, "mount_height", kHeight);
  test_helpers::SetAll(u, "focus_distance", focus_distance);
  test_helpers::SetAll(u, "scale_error", 0.0);
  u.Setup(0, 1'000'000'000'000);
  u.Initialize();
  // The robot moving -x over the floor at rest: the surface moves +x.
  test_helpers::SetArray(u, "linear_velocity", {-v, 0.0});
  std::vector<double> q, f;
  const TimeNs frame = 2'500'000;  // one frame per step at 400 Hz
  for (int i = 0; i < frames; ++i) {
    EXPECT_EQ(u.DoStep(i * frame, frame), cosim::StepResult::kOk);
    q.push_back(test_helpers::Get(u, "frame_quality")[0]);
    f.push_back(test_helpers::Get(u, "frame_flow")[0]);
  }
  return Summarize(q, f);
}

// Grid: contrast 0.02..0.3, light 20..1000 lx, speed 0..0.5 m/s (flow up
// to 4.5 px/frame, inside the 2014 firmware's window). The figures of
// agreement are printed; the assertions hold what the calibration reaches
// (see the report in px4flow_unit.h): quality within one firmware step
// (255/25 = 10.2) in most cells, noise within what the reference's own
// sampling error allows. The reference's std over n valid frames (24) is
// itself a random draw with a standard error of std / sqrt(2 (n - 1)) (15 %
// at 24 frames; the fast model's, over 2000 frames, 1.6 %): a cell agrees
// when the two differ by at most 3 of those standard errors combined, plus
// 0.03 px (the half-pixel quantization of a single texture). A fixed 20 %
// (about 1.3 standard errors) made the count of agreeing cells a coin toss:
// one seed set in 8 fell short of 3/4.
// One set of seeds runs (a set takes 2.7 s). Over 8 sets (kSets = 8),
// measured once before the match's blur law: quality within one step in
// 0.889 / 0.986 / 1 of the cells (36 cells; 3/4 asked); noise within 3
// standard errors + 0.03 px in 0.966 / 1 / 1 of the cells (27 to 30 cells;
// 9/10 asked). With it, over 4 sets: quality 0.944 / 0.986 / 1, noise
// 0.897 / 0.965 / 1 (26 of 29 cells in the worst set, the floor of 9/10
// of 29: this set, set 0, has 29 of 29).
// The mean frame flow (what a velocity reading inherits): a cell agrees
// when the two differ by at most 3 standard errors of the reference's mean
// (std / sqrt(n)) plus 0.2 px (the half-pixel quantization bias a few
// textures leave: up to 0.25 px). 36 of 36 cells in each of the 4 sets
// with the blur law (px4flow_unit.cc, FastFrame); 31 of 36 before it, when
// the fast model read up to 1.14 px too fast at long exposures and 0.5 m/s
// (9/10 asked).
TEST(Px4FlowFastVsImage, QualityAndNoiseAgreeOverTheGrid) {
  const double contrasts[] = {0.02, 0.05, 0.1, 0.3};
  const double luxes[] = {20.0, 200.0, 1000.0};
  const double speeds[] = {0.0, 0.25, 0.5};
  constexpr int kImageFrames = 24, kFastFrames = 2000;
  // Sets of seeds: set j renders textures 100 + 4 j .. 103 + 4 j and runs
  // the fast model with seed 200 + j.
  constexpr int kSets = 1;
  std::vector<double> quality_share, noise_share, mean_share;
  for (int set = 0; set < kSets; ++set) {
    int cells = 0, quality_ok = 0, noise_ok = 0, noise_cells = 0, strict_ok = 0, mean_ok = 0;
    for (double c : contrasts) {
      for (double lux : luxes) {
        for (double v : speeds) {
          const Stats im =
              Image(c, lux, v, kImageFrames, 100 + 4 * static_cast<std::uint64_t>(set));
          const Stats fa = Fast(c, lux, v, kFastFrames, 200 + static_cast<std::uint64_t>(set));
          ++cells;
          const bool q_ok = std::abs(im.quality - fa.quality) <= 255.0 / 25.0;
          quality_ok += q_ok;
          // Noise compared where it is resolvable: below 0.05 px it is
          // dominated by the half-pixel quantization of a single texture.
          bool n_ok = true;
          if (im.std > 0.05 || fa.std > 0.05) {
            ++noise_cells;
            const double se = std::hypot(im.StdError(), fa.StdError());
            n_ok = std::abs(fa.std - im.std) <= 3.0 * se + 0.03;
            noise_ok += n_ok;
            strict_ok += std::abs(fa.std - im.std) <= 0.2 * im.std;
          }
          const bool m_ok =
              std::abs(fa.mean - im.mean) <= 3.0 * im.std / std::sqrt(std::max(im.valid, 1)) + 0.2;
          mean_ok += m_ok;
          std::printf(
              "c=%.2f lux=%6.0f v=%.2f | quality image %6.1f fast %6.1f %s | flow mean image "
              "%6.3f fast %6.3f %s | std image %.3f fast %.3f %s\n",
              c, lux, v, im.quality, fa.quality, q_ok ? "ok" : "--", im.mean, fa.mean,
              m_ok ? "ok" : "--", im.std, fa.std, n_ok ? "ok" : "--");
        }
      }
    }
    std::printf(
        "quality within one step: %d of %d cells; noise within 3 standard errors + 0.03 px: %d of "
        "%d cells, "
        "within 20 %%: %d; mean within 3 standard errors + 0.2 px: %d of %d cells\n",
        quality_ok, cells, noise_ok, noise_cells, strict_ok, mean_ok, cells);
    EXPECT_GE(quality_ok, cells * 3 / 4);
    EXPECT_GE(noise_ok, noise_cells * 9 / 10);
    EXPECT_GE(mean_ok, cells * 9 / 10);
    quality_share.push_back(static_cast<double>(quality_ok) / cells);
    noise_share.push_back(static_cast<double>(noise_ok) / noise_cells);
    mean_share.push_back(static_cast<double>(mean_ok) / cells);
  }
  test_spread::Print("share of cells with the quality within one step", quality_share);
  test_spread::Print("share of cells with the noise within 3 standard errors + 0.03 px",
                     noise_share);
  test_spread::Print("share of cells with the mean within 3 standard errors + 0.2 px", mean_share);
}

// Flicker through the whole unit (its exposure timing, the lamp's phase and
// the brightness step between frames), fast model against image mode: a
// belt of texture contrast `contrast` under 300 lx of lamps at 120 Hz and
// the robot's steady 500 lx (the treadmill lab: contrast 0.12), at 0.2 m/s.
// Mean and standard deviation of the frame flow over the frames of
// quality > 0.
Stats UnitFlicker(const std::string& mode, double contrast, double depth, int frames,
                  std::uint64_t seed) {
  models::Scene s;
  models::Surface surf{"belt", 0.8, contrast, 300.0};
  surf.flicker_hz = 120.0;
  surf.flicker_depth = depth;
  s.surfaces.push_back(surf);
  s.floor = {-50, 50, -50, 50, 0};
  Px4FlowUnit u("flow", s, seed);
  test_helpers::SetAll(u, "mount_x", 0.0);
  test_helpers::SetAll(u, "mount_y", 0.0);
  test_helpers::SetAll(u, "mount_height", kHeight);
  test_helpers::SetAll(u, "added_light", 500.0);
  u.variables().SetValue(*u.variables().Find("mode"), cosim::Value{mode});
  u.Setup(0, 1'000'000'000'000);
  u.Initialize();
  test_helpers::SetArray(u, "linear_velocity", {-0.2, 0.0});
  std::vector<double> q, f;
  const TimeNs frame = 2'500'000;
  for (int i = 0; i < frames; ++i) {
    EXPECT_EQ(u.DoStep(i * frame, frame), cosim::StepResult::kOk);
    q.push_back(test_helpers::Get(u, "frame_quality")[0]);
    f.push_back(test_helpers::Get(u, "frame_flow")[0]);
  }
  return Summarize(q, f);
}

// The fast model's flicker (each block's snr bounded by 0.82 (d_block /
// delta)^1.25) against the image-level reference over texture contrast 0.03..0.2
// and depth 0 (none), 0.1 (electronic ballasts; the treadmill lab's) and
// 0.3 (magnetic ballasts): the lost share of the blocks, which pulls the
// mean towards 0, depends on depth / contrast. Two seed sets (each: image
// 400 frames, fast 4000). Measured over the 24 cells: fast - image mean
// -0.09 / +0.01 / +0.15 px (min / median / max), fast / image std 0.61 /
// 0.93 / 1.52; at the treadmill lab's cell (contrast 0.12, depth 0.1)
// -0.02 px. Before the per-block law (the frame's snr scaled by the
// gap ratio to the power 0.65, fitted at contrast 0.12 only) the same
// grid gave fast - image mean up to +0.41 px (contrast 0.03, depth 0.1)
// and +0.29 px (0.05, 0.1), +0.02 px at the lab's: the fast model read a
// low-contrast belt under flicker up to 20 % faster than the firmware on
// rendered frames.
// Asserted: the mean within 0.2 px (11 % of the true 1.81 px), the
// standard deviation within a factor 2, and both models' standard
// deviation growing with the depth (the SAD is not brightness invariant)
// where most blocks still match.
TEST(Px4FlowFastVsImage, FlickerAgrees) {
  std::vector<double> mean_diff, std_ratio;
  for (const double contrast : {0.03, 0.05, 0.12, 0.2}) {
    for (std::uint64_t set = 0; set < 2; ++set) {
      double last_im = 0.0, last_fa = 0.0;
      for (const double depth : {0.0, 0.1, 0.3}) {
        const Stats im = UnitFlicker("image", contrast, depth, 400, 300 + 2 * set);
        const Stats fa = UnitFlicker("fast", contrast, depth, 4000, 301 + 2 * set);
        std::printf(
            "contrast %.2f set %d depth %.2f | quality image %6.1f fast %6.1f | mean image %.3f "
            "fast %.3f | std image %.3f fast %.3f\n",
            contrast, static_cast<int>(set), depth, im.quality, fa.quality, im.mean, fa.mean,
            im.std, fa.std);
        EXPECT_NEAR(im.mean, fa.mean, 0.2) << contrast << " " << depth;
        EXPECT_LT(fa.std, 2.0 * im.std) << contrast << " " << depth;
        EXPECT_GT(fa.std, 0.5 * im.std) << contrast << " " << depth;
        // (At contrast 0.03 and depth 0.3 four fifths of the blocks match
        // noise: the frame flow's spread is then that of a mean of noise
        // matches, which need not grow further.)
        if (contrast >= 0.05) {
          EXPECT_GE(im.std, last_im) << contrast << " " << depth;
          EXPECT_GE(fa.std, last_fa) << contrast << " " << depth;
        }
        last_im = im.std;
        last_fa = fa.std;
        mean_diff.push_back(fa.mean - im.mean);
        std_ratio.push_back(fa.std / im.std);
      }
    }
  }
  test_spread::Print("frame flow mean, fast - image (px)", mean_diff);
  test_spread::Print("frame flow std, fast / image", std_ratio);
}

// The focus distance that gives a blur circle of `c` px (thin lens, f =
// 16 mm at f/1.4, the sensor focused behind the floor at 0.1841 m):
// v_h - v_f = c pitch N v_h / f.
double FocusFor(double c_px) {
  const double f = 666.7 * 24e-6, pitch = 24e-6;
  const double v_h = f * kHeight / (kHeight - f);
  const double v_f = v_h * (1.0 - c_px * pitch * 1.4 / f);
  return f * v_f / (v_f - f);
}

// The fast model's defocus (the blur circle as the box of the same
// variance per axis, in the blur law) against frames rendered through the
// disk: blur circles of 2 and 8 px (a lens focused 9 mm and 37 mm behind
// the floor at f/1.4) at texture contrast 0.05, 0.12 and 0.3, 800 lx (the
// treadmill's light with the robot's lamp), 0.2 m/s. Asserted in every
// cell: the mean frame flow within 3 standard errors of the reference's
// mean + 0.2 px (the grid test's rule) and the quality within 3 firmware
// steps (30.6). Measured once over 1, 2, 4, 8 and 16 px (24 frames, 8 at
// 16 px): mean fast - image -0.09..+0.07 px up to 8 px, +0.27 px at 16 px
// and contrast 0.05; quality within 26; the fast model's std up to 2.1x
// the reference's at contrast 0.05 and 4 px (0.164 against 0.078 px).
// Beyond that the box law keeps too much texture: a disk smooths the
// differences faster (their variance falls as c^-3, a box's as c^-2): at
// 24 and 39 px (a lens focused at 3 m) the reference reads 0.96 and 0.76
// px of the true 1.81, the fast model 1.56 and 1.06 px (contrast 0.12).
TEST(Px4FlowFastVsImage, DefocusAgrees) {
  std::vector<double> mean_diff, quality_diff;
  for (const double c : {2.0, 8.0}) {
    for (const double contrast : {0.05, 0.12, 0.3}) {
      const Stats im = Image(contrast, 800.0, 0.2, 16, 400, c);
      const Stats fa = Fast(contrast, 800.0, 0.2, 2000, 401, FocusFor(c));
      std::printf(
          "defocus %.0f px contrast %.2f | quality image %6.1f fast %6.1f | mean image %.3f "
          "fast %.3f | std image %.3f fast %.3f\n",
          c, contrast, im.quality, fa.quality, im.mean, fa.mean, im.std, fa.std);
      EXPECT_NEAR(fa.mean, im.mean, 3.0 * im.std / std::sqrt(std::max(im.valid, 1)) + 0.2)
          << c << " " << contrast;
      EXPECT_NEAR(fa.quality, im.quality, 3.0 * 255.0 / 25.0) << c << " " << contrast;
      mean_diff.push_back(fa.mean - im.mean);
      quality_diff.push_back(fa.quality - im.quality);
    }
  }
  test_spread::Print("defocus: frame flow mean, fast - image (px)", mean_diff);
  test_spread::Print("defocus: quality, fast - image", quality_diff);
}

}  // namespace
}  // namespace linesim::sensors
