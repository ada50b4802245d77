#include "units/belt/belt_unit.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <utility>

namespace linesim::belt {

BeltUnit::BeltUnit(std::string name, int belt_count, std::vector<std::vector<Switch>> schedules,
                   std::uint64_t seed)
    : cosim::Unit(kTypeName, std::move(name)),
      belt_count_(belt_count),
      schedules_(std::move(schedules)) {
  if (belt_count < 1) {
    throw cosim::UnitError(Where() + ": belt_count must be at least 1, got " +
                           std::to_string(belt_count));
  }
  const auto n = static_cast<std::size_t>(belt_count);
  if (schedules_.empty()) schedules_.resize(n);
  if (schedules_.size() != n) {
    throw cosim::UnitError(Where() + ": " + std::to_string(schedules_.size()) +
                           " schedules given for " + std::to_string(n) + " belts");
  }

  // Drawn once, here, so that the signal depends only on the seed and the
  // parameters, never on step sizes or on how often it is evaluated.
  // Base ratios 0.6, 1.0, 1.4 with +-10 % jitter keep the periods apart
  // (frequencies differ by at least 0.4 / variation_period), so no two terms
  // beat slowly and the signal keeps its spread over any few periods.
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(0.9, 1.1);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * std::numbers::pi);
  constexpr double kRatios[kVariationTerms] = {0.6, 1.0, 1.4};
  for (std::size_t b = 0; b < n; ++b) {
    for (double ratio : kRatios) {
      period_factors_.push_back(ratio * jitter(rng));
      phases_rad_.push_back(phase(rng));
    }
  }

  // Defaults: one 10 m x 1 m belt along x at the origin, running at the
  // representative 0.1 m/s of automotive lines (paper 1, Sec. V) with the
  // +-10 % of Sec. II. The 20 s variation period and the 0.5 m/s^2 ramp are
  // assumptions (no source gives them): a line drive ramps up within a
  // fraction of a second.
  direction_.assign(n, 0.0);
  direction_x_.assign(n, 1.0);
  direction_y_.assign(n, 0.0);
  nominal_speed_.assign(n, 0.1);
  initially_on_.assign(n, 1.0);
  speed_variation_.assign(n, 0.1);
  variation_period_.assign(n, 20.0);
  acceleration_.assign(n, 0.5);
  velocity_.assign(2 * n, 0.0);
  belt_speed_.assign(n, 0.0);
  on_.assign(n, 0.0);
  travel_.assign(n, 0.0);

  auto& v = variables();
  v.Parameter("direction", "rad", &direction_,
              "direction of motion in the map frame, counter-clockwise from x",
              cosim::Rule::Finite());
  v.Parameter("nominal_speed", "m/s", &nominal_speed_, "speed while on before the variation",
              cosim::Rule::Positive());
  v.Parameter("initially_on", "1", &initially_on_,
              "1 if on before the first switch of the schedule, else 0 (nothing in between)",
              cosim::Rule::Range(0, 1));
  v.Parameter("speed_variation", "1", &speed_variation_,
              "amplitude of the slow speed variation as a fraction of speed",
              cosim::Rule::Range(0, 0.5));
  v.Parameter("variation_period", "s", &variation_period_,
              "time scale of the speed variation: its three sinusoids have periods of about "
              "0.6, 1 and 1.4 times this",
              cosim::Rule::Positive());
  v.Parameter("acceleration", "m/s2", &acceleration_,
              "slew limit of the speed: a start or stop takes nominal_speed / acceleration",
              cosim::Rule::Positive());

  v.Output("velocity", "m/s", &velocity_,
           "surface velocity in the map frame: vx, vy of belt 0, then of belt 1, ...", {});
  v.Output("speed", "m/s", &belt_speed_, "surface speed along the direction of motion", {});
  v.Output("on", "1", &on_, "scheduled state: 1 on, 0 off (the speed ramps after a switch)", {});
  v.Output("travel", "m", &travel_,
           "distance the belt's surface has moved along its direction since the start (what "
           "carries the objects on it)",
           {});
}

namespace {

std::vector<std::vector<BeltUnit::Switch>> Schedules(const std::vector<models::Belt>& belts) {
  std::vector<std::vector<BeltUnit::Switch>> schedules;
  for (const models::Belt& b : belts) {
    schedules.emplace_back();
    for (const models::BeltSwitch& s : b.schedule) schedules.back().push_back({s.time_ns, s.on});
  }
  return schedules;
}

}  // namespace

BeltUnit::BeltUnit(std::string name, const std::vector<models::Belt>& belts, std::uint64_t seed)
    : BeltUnit(std::move(name), static_cast<int>(belts.size()), Schedules(belts), seed) {
  for (std::size_t b = 0; b < belts.size(); ++b) {
    direction_[b] = belts[b].area.direction_rad;
    nominal_speed_[b] = belts[b].nominal_speed_mps;
    initially_on_[b] = belts[b].initially_on ? 1.0 : 0.0;
    speed_variation_[b] = belts[b].speed_variation;
    variation_period_[b] = belts[b].variation_period_s;
    acceleration_[b] = belts[b].acceleration_mps2;
  }
}

std::vector<cosim::ParameterProblem> BeltUnit::CheckParameters() const {
  // The declared rules, then what a rule cannot say: initially_on is 0 or 1
  // (its rule [0, 1] reports the rest), and each schedule (structural, not a
  // parameter) switches at increasing times.
  auto problems = cosim::Unit::CheckParameters();
  for (std::size_t b = 0; b < initially_on_.size(); ++b) {
    const double x = initially_on_[b];
    if (x > 0.0 && x < 1.0) {
      problems.push_back(
          {"initially_on", b, "must be 0 (off) or 1 (on), got " + cosim::FormatValue(x)});
    }
  }
  for (std::size_t b = 0; b < schedules_.size(); ++b) {
    const auto& s = schedules_[b];
    for (std::size_t i = 1; i < s.size(); ++i) {
      if (s[i].time <= s[i - 1].time) {
        problems.push_back({"schedules." + std::to_string(b), i,
                            "switch times must increase, got " + cosim::FormatSeconds(s[i].time) +
                                " s after " + cosim::FormatSeconds(s[i - 1].time) + " s"});
      }
    }
  }
  return problems;
}

double BeltUnit::VariationSignal(int b, cosim::TimeNs t) const {
  const auto bb = static_cast<std::size_t>(b);
  // Seconds from the integer time each call: nothing is accumulated.
  const double t_s = cosim::NsToSeconds(t);
  double sum = 0.0;
  for (std::size_t k = 0; k < kVariationTerms; ++k) {
    const std::size_t j = bb * kVariationTerms + k;
    const double period_s = variation_period_[bb] * period_factors_[j];
    sum += std::sin(2.0 * std::numbers::pi * t_s / period_s + phases_rad_[j]);
  }
  return sum / kVariationTerms;
}

bool BeltUnit::ScheduledOn(int b, cosim::TimeNs t) const {
  const auto bb = static_cast<std::size_t>(b);
  bool on = initially_on_[bb] != 0.0;
  for (const Switch& s : schedules_[bb]) {
    if (s.time > t) break;
    on = s.on;
  }
  return on;
}

double BeltUnit::TargetSpeed(std::size_t b, bool on, cosim::TimeNs t) const {
  if (!on) return 0.0;
  return nominal_speed_[b] * (1.0 + speed_variation_[b] * VariationSignal(static_cast<int>(b), t));
}

void BeltUnit::ComputeOutputs(cosim::TimeNs t) {
  for (std::size_t b = 0; b < nominal_speed_.size(); ++b) {
    on_[b] = ScheduledOn(static_cast<int>(b), t) ? 1.0 : 0.0;
    velocity_[2 * b] = belt_speed_[b] * direction_x_[b];
    velocity_[2 * b + 1] = belt_speed_[b] * direction_y_[b];
  }
}

void BeltUnit::CacheDirections() {
  for (std::size_t b = 0; b < direction_.size(); ++b) {
    direction_x_[b] = std::cos(direction_[b]);
    direction_y_[b] = std::sin(direction_[b]);
  }
}

void BeltUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void BeltUnit::Initialize() {
  ThrowIfBadParameters();
  CacheDirections();
  for (std::size_t b = 0; b < nominal_speed_.size(); ++b) {
    belt_speed_[b] = TargetSpeed(b, ScheduledOn(static_cast<int>(b), start_), start_);
    travel_[b] = 0.0;
  }
  ComputeOutputs(start_);
}

cosim::StepResult BeltUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  const cosim::TimeNs t_end = t + dt;
  for (std::size_t b = 0; b < nominal_speed_.size(); ++b) {
    // Sub-steps end at each switch inside (t, t_end), so that a ramp starts
    // exactly at its switching time whatever the step size. Within a
    // sub-step the scheduled state is the one at its start and the target
    // is taken at its end.
    // The travel takes the speed as linear over each sub-step (the
    // trapezoid of its ends), as the slew limit makes it while ramping.
    double s = belt_speed_[b];
    double travel = travel_[b];
    const auto slew = [&](cosim::TimeNs from, cosim::TimeNs to) {
      const bool on = ScheduledOn(static_cast<int>(b), from);
      const double target = TargetSpeed(b, on, to);
      const double h_s = cosim::NsToSeconds(to - from);
      const double max_change = acceleration_[b] * h_s;
      const double before = s;
      s += std::clamp(target - s, -max_change, max_change);
      travel += 0.5 * (before + s) * h_s;
    };
    cosim::TimeNs from = t;
    for (const Switch& sw : schedules_[b]) {
      if (sw.time <= t) continue;
      if (sw.time >= t_end) break;
      slew(from, sw.time);
      from = sw.time;
    }
    slew(from, t_end);
    belt_speed_[b] = s;
    travel_[b] = travel;
  }
  ComputeOutputs(t_end);
  return cosim::StepResult::kOk;
}

// The speeds are outputs and come back with the variables; the drawn
// variation terms are saved too, so that a state also restores into a unit
// built with another seed.
void BeltUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals = period_factors_;
  state.reals.insert(state.reals.end(), phases_rad_.begin(), phases_rad_.end());
  state.integers = {start_};
}

void BeltUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t terms = period_factors_.size();
  if (state.reals.size() != 2 * terms || state.integers.size() != 1) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(2 * terms) + " and 1");
  }
  const auto middle = state.reals.begin() + static_cast<std::ptrdiff_t>(terms);
  period_factors_.assign(state.reals.begin(), middle);
  phases_rad_.assign(middle, state.reals.end());
  start_ = state.integers[0];
  // The parameters came back with the variables.
  CacheDirections();
}

}  // namespace linesim::belt
