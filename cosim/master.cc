#include "cosim/master.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <chrono>
#include <cstring>

namespace linesim::cosim {

namespace {

using Clock = std::chrono::steady_clock;

// Adds the wall time of its scope, times `scale`, to `total`, only when
// profiling, so that every exit of a function is counted and an unprofiled
// run reads no clock.
class ScopedTimer {
 public:
  ScopedTimer(bool on, double& total, double scale = 1.0)
      : total_(on ? &total : nullptr), scale_(scale) {
    if (total_) start_ = Clock::now();
  }
  ~ScopedTimer() {
    if (total_) *total_ += scale_ * std::chrono::duration<double>(Clock::now() - start_).count();
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double* total_;
  double scale_;
  Clock::time_point start_;
};

// The units' step and output times are sampled at one base step in this
// many (scaled by it): two clock reads per unit step cost 2-3 % of a robot
// run at 1 ms (van_entry: 14 units). A prime, so that a unit stepping every
// d base steps is sampled at one of its own steps in this many for any d
// that is not a multiple of it (no aliasing).
constexpr std::int64_t kProfileEvery = 31;

std::int64_t NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

}  // namespace

// Times one DoStep or UpdateOutputs of unit u on a timed base step: the same
// two clock reads give the unit's sampled time, its scaled estimate and the
// busy union, so that on one thread the units' times add up to the union.
class UnitCallTimer {
 public:
  UnitCallTimer(Master& m, std::size_t u) : m_(m.profile_step_ ? &m : nullptr), u_(u) {
    if (m_) started_ns_ = m_->UnitCallStarts();
  }
  ~UnitCallTimer() {
    if (m_) m_->UnitCallEnds(u_, started_ns_);
  }
  UnitCallTimer(const UnitCallTimer&) = delete;
  UnitCallTimer& operator=(const UnitCallTimer&) = delete;

 private:
  Master* m_;
  std::size_t u_;
  std::int64_t started_ns_ = 0;
};

std::int64_t Master::UnitCallStarts() {
  const std::lock_guard<std::mutex> lock(busy_mutex_);
  const std::int64_t now = NowNs();
  if (units_running_++ == 0) busy_since_ns_ = now;
  return now;
}

void Master::UnitCallEnds(std::size_t u, std::int64_t started_ns) {
  const std::lock_guard<std::mutex> lock(busy_mutex_);
  const std::int64_t now = NowNs();
  const double own_s = 1e-9 * static_cast<double>(now - started_ns);
  sampled_unit_seconds_[u] += own_s;
  unit_wall_seconds_[u] += static_cast<double>(kProfileEvery) * own_s;
  if (--units_running_ == 0) sampled_busy_seconds_ += 1e-9 * static_cast<double>(now - busy_since_ns_);
}

std::string RunResult::ErrorText() const {
  std::string text;
  for (const auto& e : errors) text += (text.empty() ? "" : "; ") + e.message;
  return text;
}

Master::~Master() = default;

Master::Master(System& system, MasterOptions options) : system_(system), options_(options) {
  if (!system_.built()) system_.Build();
  std::vector<Problem> problems;
  const TimeNs h = options_.base_step;
  if (h <= 0) problems.push_back({"master step must be positive", std::nullopt});
  if (options_.stop < options_.start) {
    problems.push_back({"stop time " + FormatSeconds(options_.stop) + " s is before start time " +
                            FormatSeconds(options_.start) + " s",
                        std::nullopt});
  }
  if (options_.threads < 1) problems.push_back({"threads must be at least 1", std::nullopt});
  const RetryOptions& retry = options_.retry;
  if (retry.enabled) {
    if (!(retry.shrink > 0.0 && retry.shrink < 1.0)) {
      problems.push_back({"master.retry.shrink must be in (0, 1)", std::nullopt});
    }
    if (!(retry.grow >= 1.0) || !std::isfinite(retry.grow)) {
      problems.push_back({"master.retry.grow must be at least 1", std::nullopt});
    }
    if (retry.min_step <= 0 || (h > 0 && retry.min_step > h)) {
      problems.push_back({"master.retry.min_step_s " + FormatSeconds(retry.min_step) +
                              " s must be positive and at most the master step " +
                              FormatSeconds(h) + " s",
                          std::nullopt});
    }
  }
  const TimeNs duration = options_.stop - options_.start;
  if (h > 0 && duration % h != 0) {
    problems.push_back({"duration " + FormatSeconds(duration) +
                            " s is not a whole number of master steps of " + FormatSeconds(h) +
                            " s",
                        std::nullopt});
  }
  const std::size_t n = system_.unit_count();
  decimation_.assign(n, 1);
  for (std::size_t u = 0; u < n && h > 0; ++u) {
    const TimeNs step = system_.unit_step(u) == 0 ? h : system_.unit_step(u);
    const std::string& name = system_.unit(u).name();
    if (step % h != 0) {
      problems.push_back({"unit '" + name + "' step " + FormatSeconds(step) +
                              " s is not an integer multiple of the master step " +
                              FormatSeconds(h) + " s",
                          std::nullopt, u});
    } else if (duration % step != 0) {
      problems.push_back({"unit '" + name + "' step " + FormatSeconds(step) +
                              " s does not divide the duration " + FormatSeconds(duration) + " s",
                          std::nullopt, u});
    }
    decimation_[u] = std::max<TimeNs>(1, step / h);
  }
  if (!problems.empty()) throw ConfigError(std::move(problems));

  links_into_.assign(n, {});
  links_from_.assign(n, {});
  const auto& links = system_.links();
  resolved_.clear();
  for (std::size_t l = 0; l < links.size(); ++l) {
    const Link& link = links[l];
    links_into_[link.to_unit].push_back(l);
    links_from_[link.from_unit].push_back(l);
    ResolvedLink r{link.from_unit, link.to_unit, link.type, {}, {}, link.from_index, link.to_index};
    if (link.type == VarType::kReal || link.type == VarType::kRealArray) {
      r.from = system_.unit(link.from_unit).variables().ResolveReal(link.from_ref);
      r.to = system_.unit(link.to_unit).variables().ResolveWritableReal(link.to_ref);
    }
    resolved_.push_back(r);
  }
  has_feedthrough_.assign(n, false);
  for (std::size_t u = 0; u < n; ++u) {
    for (const auto& info : system_.unit(u).variables().infos()) {
      if (!info.depends_on.empty()) has_feedthrough_[u] = true;
    }
  }
  for (std::size_t u : system_.dependency_order()) {
    if (decimation_[u] == 1) every_step_.push_back(u);
  }
  algorithm_ = MakeAlgorithm(options_.algorithm, options_.threads);
  feedthrough_ = &has_feedthrough_;
  if (retry.enabled) {
    // Every divisor of h, found by trial division up to sqrt(h): once.
    for (TimeNs d = 1; d * d <= h; ++d) {
      if (h % d != 0) continue;
      divisors_.push_back(d);
      if (d != h / d) divisors_.push_back(h / d);
    }
    std::sort(divisors_.begin(), divisors_.end());
    saved_.resize(n);
  }
  pending_.resize(n);
  time_ = options_.start;
}

bool Master::TransferChecked(const Link& link) {
  const VariableTable& from = system_.unit(link.from_unit).variables();
  VariableTable& to = system_.unit(link.to_unit).variables();
  switch (link.type) {
    case VarType::kReal: {
      const double v = link.from_index < 0 ? from.GetReal(link.from_ref)
                                           : from.GetRealElement(link.from_ref, link.from_index);
      const double old = link.to_index < 0 ? to.GetReal(link.to_ref)
                                           : to.GetRealElement(link.to_ref, link.to_index);
      if (link.to_index < 0) {
        to.SetReal(link.to_ref, v);
      } else {
        to.SetRealElement(link.to_ref, link.to_index, v);
      }
      return !SameBits(v, old);
    }
    case VarType::kRealArray: {
      const auto src = from.GetRealArray(link.from_ref);
      const auto dst = to.GetRealArray(link.to_ref);
      const bool changed = std::memcmp(src.data(), dst.data(), src.size_bytes()) != 0;
      if (changed) to.SetRealArray(link.to_ref, src);
      return changed;
    }
    case VarType::kInteger: {
      const auto v = from.GetInteger(link.from_ref);
      const bool changed = v != to.GetInteger(link.to_ref);
      to.SetInteger(link.to_ref, v);
      return changed;
    }
    case VarType::kBoolean: {
      const bool v = from.GetBoolean(link.from_ref);
      const bool changed = v != to.GetBoolean(link.to_ref);
      to.SetBoolean(link.to_ref, v);
      return changed;
    }
    case VarType::kString: {
      const std::string& v = from.GetString(link.from_ref);
      const bool changed = v != to.GetString(link.to_ref);
      if (changed) to.SetString(link.to_ref, v);
      return changed;
    }
  }
  return false;
}

void Master::RecordError(std::size_t u, TimeNs t, RunPhase phase, std::string_view phase_text,
                         std::string cause, std::string variable) {
  const Unit& unit = system_.unit(u);
  errors_.push_back(MakeUnitRunError(unit.name(), unit.type_name(), t, phase, phase_text,
                                     std::move(cause), std::move(variable)));
  failed_ = true;
}

bool Master::InitializeUnit(std::size_t u) {
  try {
    const ScopedTimer timer(options_.profile, unit_wall_seconds_[u]);
    system_.unit(u).Initialize();
    return true;
  } catch (const UnitError& e) {
    RecordError(u, time_, RunPhase::kInitialize, "initialize failed", e.what(), e.variable());
    return false;
  } catch (const std::exception& e) {
    RecordError(u, time_, RunPhase::kInitialize, "initialize failed", e.what());
    return false;
  }
}

bool Master::CheckUnitOutputs(std::size_t u, TimeNs t, RunPhase phase) {
  const VariableTable& table = system_.unit(u).variables();
  if (table.RealOutputsFinite()) return true;
  auto problem = FindNonFinite(table, table.real_outputs());
  if (!problem) return true;
  RecordError(u, t, phase, "", std::move(problem->text), std::move(problem->variable));
  return false;
}

bool Master::CheckOutputs(std::size_t u) {
  const TimeNs dt = decimation_[u] == 1 ? plan_dt_ : options_.base_step * decimation_[u];
  return CheckUnitOutputs(u, plan_t_ + dt, RunPhase::kStep);
}

bool Master::Transfer(std::size_t l) {
  const ResolvedLink& r = resolved_[l];
  if (r.type == VarType::kReal) {
    // A Real, or an element of a Real[] at either end; an index the array
    // no longer holds takes the checked path (which throws).
    const double* src = r.from.scalar;
    if (src == nullptr) {
      const auto i = static_cast<std::size_t>(r.from_index);
      if (i >= r.from.array->size()) return TransferChecked(system_.links()[l]);
      src = r.from.array->data() + i;
    }
    double* dst = r.to.scalar;
    if (dst == nullptr) {
      const auto i = static_cast<std::size_t>(r.to_index);
      if (i >= r.to.array->size()) return TransferChecked(system_.links()[l]);
      dst = r.to.array->data() + i;
    }
    const double v = *src;
    const bool changed = !SameBits(v, *dst);
    *dst = v;
    return changed;
  }
  if (r.type == VarType::kRealArray && r.from.array->size() == r.to.array->size()) {
    const std::vector<double>& src = *r.from.array;
    std::vector<double>& dst = *r.to.array;
    const bool changed = std::memcmp(src.data(), dst.data(), src.size() * sizeof(double)) != 0;
    if (changed) std::copy(src.begin(), src.end(), dst.begin());
    return changed;
  }
  return TransferChecked(system_.links()[l]);
}

void Master::TransferInto(std::size_t u) {
  // A link transfers when its destination steps now and its source is at a
  // communication point too, so a slow unit's future output never leaks
  // into a fast unit between the slow unit's points.
  for (std::size_t l : links_into_[u]) {
    if (AtPoint(resolved_[l].from_unit)) Transfer(l);
  }
}

void Master::TransferFrom(std::size_t u) {
  for (std::size_t l : links_from_[u]) {
    if (AtPoint(resolved_[l].to_unit)) Transfer(l);
  }
}

// Steps one unit; a failure or discard is kept in its pending slot. Safe to
// call for different units concurrently.
StepResult Master::StepUnit(std::size_t u) {
  Unit& unit = system_.unit(u);
  const TimeNs dt = decimation_[u] == 1 ? plan_dt_ : options_.base_step * decimation_[u];
  Pending& p = pending_[u];
  try {
    const UnitCallTimer timer(*this, u);
    p.result = unit.DoStep(plan_t_, dt);
    if (p.result == StepResult::kDiscard) {
      p.cause = "discarded the step (" + unit.last_error() + ")";
      p.variable = unit.last_error_variable();
    } else if (p.result == StepResult::kError) {
      p.cause = unit.last_error().empty() ? "step failed" : unit.last_error();
      p.variable = unit.last_error_variable();
    }
  } catch (const UnitError& e) {
    p.result = StepResult::kError;
    p.cause = e.what();
    p.variable = e.variable();
  } catch (const std::exception& e) {
    p.result = StepResult::kError;
    p.cause = e.what();
  }
  return p.result;
}

bool Master::UpdateOutputs(std::size_t u) {
  try {
    const UnitCallTimer timer(*this, u);
    system_.unit(u).UpdateOutputs();
  } catch (const UnitError& e) {
    RecordError(u, plan_t_, RunPhase::kUpdateOutputs, "updating outputs from new inputs failed",
                e.what(), e.variable());
    return false;
  } catch (const std::exception& e) {
    RecordError(u, plan_t_, RunPhase::kUpdateOutputs, "updating outputs from new inputs failed",
                e.what());
    return false;
  }
  return CheckUnitOutputs(u, plan_t_, RunPhase::kUpdateOutputs);
}

void Master::RecordPendingErrors() {
  for (std::size_t u : *plan_due_) {
    Pending& p = pending_[u];
    if (p.result == StepResult::kOk) continue;
    if (p.result == StepResult::kDiscard && !options_.retry.enabled) {
      p.cause += "; master.retry is off, so the step cannot be retried";
    }
    RecordError(u, plan_t_, RunPhase::kStep, "", std::move(p.cause), std::move(p.variable));
    p = Pending{};
  }
}

void Master::PropagateInitialValues() {
  // Outputs with direct feedthrough depend on inputs, which come from other
  // units' outputs: repeat transfer + Initialize of the units whose inputs
  // changed until nothing changes. Start() initialized every unit before the
  // first transfer; with no algebraic loop this settles within (longest
  // feedthrough chain + 1) passes.
  const std::size_t n = system_.unit_count();
  std::vector<bool> changed(n);
  for (std::size_t pass = 0; pass <= n + 1; ++pass) {
    std::fill(changed.begin(), changed.end(), false);
    bool any = false;
    for (std::size_t l = 0; l < resolved_.size(); ++l) {
      if (Transfer(l)) changed[resolved_[l].to_unit] = any = true;
    }
    if (!any) return;
    for (std::size_t u = 0; u < n; ++u) {
      if (changed[u] && !InitializeUnit(u)) return;
    }
  }
  throw UnitError("initial values did not settle after " + std::to_string(n + 2) + " passes");
}

void Master::Notify(TimeNs t) {
  for (Observer* o : observers_) o->OnSample(t, system_);
}

void Master::Start() {
  const std::size_t n = system_.unit_count();
  unit_wall_seconds_.assign(n, 0.0);
  sampled_unit_seconds_.assign(n, 0.0);
  sampled_step_seconds_ = 0;
  sampled_busy_seconds_ = 0;
  units_running_ = 0;
  total_wall_seconds_ = 0;
  const ScopedTimer timer(options_.profile, total_wall_seconds_);
  errors_.clear();
  failed_ = false;
  ended_by_.clear();
  time_ = options_.start;
  step_index_ = 0;
  current_step_ = options_.base_step;
  smallest_step_ = options_.base_step;
  rejected_steps_ = 0;
  for (Pending& p : pending_) p = Pending{};
  for (std::size_t u = 0; u < n; ++u) {
    try {
      const ScopedTimer unit_timer(options_.profile, unit_wall_seconds_[u]);
      system_.unit(u).Setup(options_.start, options_.stop);
    } catch (const std::exception& e) {
      const auto* unit_error = dynamic_cast<const UnitError*>(&e);
      RecordError(u, time_, RunPhase::kSetup, "setup failed", e.what(),
                  unit_error ? unit_error->variable() : std::string());
    }
  }
  if (!failed_) {
    try {
      for (std::size_t u = 0; u < n; ++u) InitializeUnit(u);
      if (!failed_) PropagateInitialValues();
    } catch (const std::exception& e) {
      errors_.push_back(MakeRunError(time_, RunPhase::kInitialize, "initialization", e.what()));
      failed_ = true;
    }
  }
  for (std::size_t u = 0; u < n && !failed_; ++u) CheckUnitOutputs(u, time_, RunPhase::kInitialize);
  // Initialization is over: fixed parameters keep their values from here on
  // (FMI: they may change only before exiting initialization mode).
  for (std::size_t u = 0; u < n; ++u) system_.unit(u).variables().Lock();
  started_ = true;
  // An observer that refuses the run (say, a recording interval off the
  // master's steps) fails it like a unit would: the units still terminate.
  for (Observer* o : observers_) {
    try {
      o->OnStart(*this);
    } catch (const std::exception& e) {
      RunError error = MakeRunError(std::nullopt, RunPhase::kObserver, "observer at start", e.what());
      error.time = time_;
      errors_.push_back(std::move(error));
      failed_ = true;
    }
  }
  if (!failed_) Notify(time_);
}

void Master::Plan(TimeNs tau, TimeNs dt, bool first) {
  plan_t_ = tau;
  plan_dt_ = dt;
  plan_first_ = first;
  if (first) {
    due_at_point_.clear();
    for (std::size_t u : system_.dependency_order()) {
      if (step_index_ % decimation_[u] == 0) due_at_point_.push_back(u);
    }
    plan_due_ = &due_at_point_;
  } else {
    // Between base points only the units at the master's own step step.
    plan_due_ = &every_step_;
  }
  due_ = *plan_due_;
}

bool Master::StopRequested() {
  for (std::size_t u : *plan_due_) {
    const Unit& unit = system_.unit(u);
    if (unit.stop_request().empty()) continue;
    ended_by_ = unit.Where() + ": " + unit.stop_request();
    return true;
  }
  return false;
}

bool Master::Step() {
  if (!started_ || failed_ || !ended_by_.empty() || time_ >= options_.stop) return false;
  const ScopedTimer timer(options_.profile, total_wall_seconds_);
  profile_step_ = options_.profile && step_index_ % kProfileEvery == 0;
  // The whole timed step, observers included: the units' calls lie inside.
  const ScopedTimer step_timer(profile_step_, sampled_step_seconds_);
  const TimeNs t = time_;
  if (options_.retry.enabled) {
    if (!StepWithRetry(t)) return false;
    if (!ended_by_.empty() && stopped_at_ != t + options_.base_step) {
      // A unit ended the run inside the base step: the observers see that
      // time last (a recorder keeps only its own grid's points).
      time_ = stopped_at_;
      Notify(time_);
      return false;
    }
  } else {
    Plan(t, options_.base_step, true);
    if (algorithm_->Step(t, options_.base_step, *this) != StepStatus::kOk) {
      RecordPendingErrors();
      failed_ = true;
      return false;
    }
    StopRequested();
  }
  ++step_index_;
  time_ = options_.start + step_index_ * options_.base_step;
  Notify(time_);
  return ended_by_.empty() && time_ < options_.stop;
}

TimeNs Master::DivisorAtMost(TimeNs limit) const {
  const auto it = std::upper_bound(divisors_.begin(), divisors_.end(), limit);
  return it == divisors_.begin() ? 0 : *(it - 1);
}

bool Master::StepWithRetry(TimeNs t) {
  const TimeNs h = options_.base_step;
  const TimeNs end = t + h;
  TimeNs tau = t;
  while (tau < end) {
    // Never past the next base point: observers and slower units meet the
    // master there.
    const TimeNs dt = std::min(current_step_, end - tau);
    Plan(tau, dt, tau == t);
    for (std::size_t u : *plan_due_) {
      try {
        system_.unit(u).SaveStateInto(saved_[u]);
      } catch (const std::exception& e) {
        RecordError(u, tau, RunPhase::kRetry, "saving its state for master.retry failed",
                    e.what());
        return false;
      }
    }
    const StepStatus status = algorithm_->Step(tau, dt, *this);
    if (status == StepStatus::kOk) {
      tau += dt;
      smallest_step_ = std::min(smallest_step_, dt);
      if (StopRequested()) {
        stopped_at_ = tau;
        return true;
      }
      if (current_step_ < h) {
        const double grown = std::floor(static_cast<double>(current_step_) * options_.retry.grow);
        current_step_ = std::max(current_step_, DivisorAtMost(static_cast<TimeNs>(
                                                     std::min(grown, static_cast<double>(h)))));
      }
      continue;
    }
    if (status == StepStatus::kError) {
      RecordPendingErrors();
      failed_ = true;
      return false;
    }
    // Discarded: back to tau, every unit that took part.
    ++rejected_steps_;
    for (std::size_t u : *plan_due_) {
      try {
        system_.unit(u).RestoreState(saved_[u]);
      } catch (const std::exception& e) {
        RecordError(u, tau, RunPhase::kRetry, "restoring its state for master.retry failed",
                    e.what());
        return false;
      }
    }
    const TimeNs smaller = DivisorAtMost(static_cast<TimeNs>(
        std::floor(static_cast<double>(dt) * options_.retry.shrink)));
    bool can_retry = smaller >= options_.retry.min_step && smaller < dt;
    std::string why;
    if (!can_retry) {
      why = smaller == 0 ? "; no smaller step divides the master step " + FormatSeconds(h) + " s"
                         : "; a step of " + FormatSeconds(smaller) +
                               " s would be below master.retry.min_step_s = " +
                               FormatSeconds(options_.retry.min_step) + " s";
    }
    for (std::size_t u : *plan_due_) {
      Pending& p = pending_[u];
      if (p.result == StepResult::kDiscard && decimation_[u] != 1) {
        // A slower unit keeps its own step whatever the master's.
        can_retry = false;
        p.cause += "; its step " + FormatSeconds(h * decimation_[u]) +
                   " s is a multiple of the master step, which master.retry does not shrink";
      }
    }
    if (!can_retry) {
      // "discarded the step (cause)" -> "discarded the step of dt s (cause); why"
      constexpr std::string_view kDiscarded = "discarded the step";
      for (std::size_t u : *plan_due_) {
        Pending& p = pending_[u];
        if (p.result != StepResult::kDiscard) continue;
        p.cause = std::string(kDiscarded) + " of " + FormatSeconds(dt) + " s" +
                  p.cause.substr(kDiscarded.size()) + (decimation_[u] == 1 ? why : "");
      }
      RecordPendingErrors();
      failed_ = true;
      return false;
    }
    for (std::size_t u : *plan_due_) pending_[u] = Pending{};
    current_step_ = smaller;
  }
  return true;
}

RunResult Master::Finish() {
  const ScopedTimer timer(options_.profile, total_wall_seconds_);
  for (std::size_t u = 0; u < system_.unit_count(); ++u) {
    try {
      system_.unit(u).Terminate();
    } catch (const std::exception& e) {
      RecordError(u, time_, RunPhase::kTerminate, "terminate failed", e.what());
    }
  }
  for (Observer* o : observers_) o->OnEnd(time_, !failed_);
  RunResult r;
  r.ok = !failed_;
  r.end_time = time_;
  r.base_steps = step_index_;
  r.errors = errors_;
  r.rejected_steps = rejected_steps_;
  r.smallest_step = smallest_step_;
  r.ended_by = ended_by_;
  return r;
}

RunResult Master::Run() {
  Start();
  while (Step()) {
  }
  return Finish();
}

}  // namespace linesim::cosim
