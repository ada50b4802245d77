#include "cosim/master.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <bit>
#include <chrono>
#include <cstring>

namespace linesim::cosim {

namespace {

using Clock = std::chrono::steady_clock;

// Adds the wall time of its scope to `total`, only when profiling, so that
// every exit of a function is counted and an unprofiled run reads no clock.
class ScopedTimer {
 public:
  ScopedTimer(bool on, double& total) : total_(on ? &total : nullptr) {
    if (total_) start_ = Clock::now();
  }
  ~ScopedTimer() {
    if (total_) *total_ += std::chrono::duration<double>(Clock::now() - start_).count();
  }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double* total_;
  Clock::time_point start_;
};

bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

}  // namespace

std::string_view ToString(Algorithm a) {
  switch (a) {
    case Algorithm::kJacobi:
      return "jacobi";
    case Algorithm::kGaussSeidel:
      return "gauss_seidel";
  }
  return "?";
}

bool ParseAlgorithm(std::string_view text, Algorithm* out) {
  for (const Algorithm a : {Algorithm::kJacobi, Algorithm::kGaussSeidel}) {
    if (text == ToString(a)) {
      *out = a;
      return true;
    }
  }
  return false;
}

std::vector<std::string> AlgorithmNames() {
  return {std::string(ToString(Algorithm::kJacobi)),
          std::string(ToString(Algorithm::kGaussSeidel))};
}

// Keeps TBB out of the public header; limits Jacobi to `threads` threads.
struct Master::Arena {
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;
};

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
  for (std::size_t l = 0; l < links.size(); ++l) {
    links_into_[links[l].to_unit].push_back(l);
    links_from_[links[l].from_unit].push_back(l);
  }
  has_feedthrough_.assign(n, false);
  for (std::size_t u = 0; u < n; ++u) {
    for (const auto& info : system_.unit(u).variables().infos()) {
      if (!info.depends_on.empty()) has_feedthrough_[u] = true;
    }
  }
  if (options_.threads > 1) arena_ = std::make_unique<Arena>(options_.threads);
  time_ = options_.start;
}

bool Master::Transfer(const Link& link) {
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

void Master::RecordError(std::size_t u, TimeNs t, const std::string& phase,
                         const std::string& cause) {
  // Units name themselves in their messages, so that a unit used on its own
  // reports clearly; here the master names it once, in front.
  const std::string who = system_.unit(u).Where();
  const std::string prefix = who + ": ";
  const std::string what = cause.starts_with(prefix) ? cause.substr(prefix.size()) : cause;
  errors_.push_back(who + " at t = " + FormatSeconds(t) +
                    " s: " + (phase.empty() ? "" : phase + ": ") + what);
  failed_ = true;
}

bool Master::InitializeUnit(std::size_t u) {
  try {
    const ScopedTimer timer(options_.profile, unit_wall_seconds_[u]);
    system_.unit(u).Initialize();
    return true;
  } catch (const std::exception& e) {
    RecordError(u, time_, "initialize failed", e.what());
    return false;
  }
}

bool Master::CheckOutputs(std::size_t u, TimeNs t) {
  const VariableTable& table = system_.unit(u).variables();
  const auto problem = FirstNonFinite(table, table.real_outputs());
  if (!problem) return true;
  RecordError(u, t, "", *problem);
  return false;
}

// Steps one unit; returns false with the cause in the unit's error slot.
// Safe to call for different units concurrently.
bool Master::StepUnit(std::size_t u, TimeNs t, TimeNs dt) {
  Unit& unit = system_.unit(u);
  StepResult result;
  std::string cause;
  try {
    const ScopedTimer timer(options_.profile, unit_wall_seconds_[u]);
    result = unit.DoStep(t, dt);
    if (result == StepResult::kDiscard) {
      cause = "discarded the step (" + unit.last_error() + "); a fixed-step master cannot retry it";
    } else if (result == StepResult::kError) {
      cause = unit.last_error().empty() ? "step failed" : unit.last_error();
    }
  } catch (const std::exception& e) {
    result = StepResult::kError;
    cause = e.what();
  }
  if (result != StepResult::kOk) {
    pending_errors_[u] = std::move(cause);
    return false;
  }
  return true;
}

bool Master::UpdateUnitOutputs(std::size_t u, TimeNs t) {
  try {
    const ScopedTimer timer(options_.profile, unit_wall_seconds_[u]);
    system_.unit(u).UpdateOutputs();
  } catch (const std::exception& e) {
    RecordError(u, t, "updating outputs from new inputs failed", e.what());
    return false;
  }
  return CheckOutputs(u, t);
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
    for (const Link& link : system_.links()) {
      if (Transfer(link)) changed[link.to_unit] = any = true;
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
  pending_errors_.assign(n, {});
  unit_wall_seconds_.assign(n, 0.0);
  total_wall_seconds_ = 0;
  const ScopedTimer timer(options_.profile, total_wall_seconds_);
  errors_.clear();
  failed_ = false;
  time_ = options_.start;
  step_index_ = 0;
  for (std::size_t u = 0; u < n; ++u) {
    try {
      const ScopedTimer unit_timer(options_.profile, unit_wall_seconds_[u]);
      system_.unit(u).Setup(options_.start, options_.stop);
    } catch (const std::exception& e) {
      RecordError(u, time_, "setup failed", e.what());
    }
  }
  if (!failed_) {
    try {
      for (std::size_t u = 0; u < n; ++u) InitializeUnit(u);
      if (!failed_) PropagateInitialValues();
    } catch (const std::exception& e) {
      errors_.push_back(std::string("initialization at t = ") + FormatSeconds(time_) +
                        " s: " + e.what());
      failed_ = true;
    }
  }
  for (std::size_t u = 0; u < n && !failed_; ++u) CheckOutputs(u, time_);
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
      errors_.push_back(std::string("observer at start: ") + e.what());
      failed_ = true;
    }
  }
  if (!failed_) Notify(time_);
}

bool Master::Step() {
  if (!started_ || failed_ || time_ >= options_.stop) return false;
  const ScopedTimer timer(options_.profile, total_wall_seconds_);
  const TimeNs t = time_;
  const TimeNs h = options_.base_step;
  const auto& links = system_.links();
  const auto at_point = [&](std::size_t u) { return step_index_ % decimation_[u] == 0; };
  // A link transfers when its destination steps now and its source is at a
  // communication point too, so a slow unit's future output never leaks
  // into a fast unit between the slow unit's points.
  const auto transfer_into = [&](std::size_t u) {
    for (std::size_t l : links_into_[u]) {
      if (at_point(links[l].from_unit)) Transfer(links[l]);
    }
  };

  due_.clear();
  for (std::size_t u : system_.dependency_order()) {
    if (at_point(u)) due_.push_back(u);
  }

  // Outputs with direct feedthrough follow the inputs of this communication
  // point (FMI: outputs read after inputs are set reflect them). Dependency
  // order puts a feedthrough unit after the units feeding it, so one pass
  // resolves chains; each update is passed on to the due units it feeds.
  // Gauss-Seidel transfers into every unit right before it steps anyway, so
  // here only the feedthrough units need their inputs.
  const bool jacobi = options_.algorithm == Algorithm::kJacobi;
  if (jacobi) {
    for (std::size_t u : due_) transfer_into(u);
  }
  for (std::size_t u : due_) {
    if (!has_feedthrough_[u]) continue;
    if (!jacobi) transfer_into(u);
    if (!UpdateUnitOutputs(u, t)) {
      return false;
    }
    // Gauss-Seidel transfers into each unit right before it updates or
    // steps; only Jacobi needs the new outputs passed on here.
    if (jacobi) {
      for (std::size_t l : links_from_[u]) {
        if (at_point(links[l].to_unit)) Transfer(links[l]);
      }
    }
  }

  bool ok = true;
  if (jacobi) {
    if (options_.threads > 1 && due_.size() > 1) {
      arena_->arena.execute([&] {
        tbb::parallel_for(std::size_t{0}, due_.size(), [&](std::size_t i) {
          const std::size_t u = due_[i];
          StepUnit(u, t, h * decimation_[u]);
        });
      });
      for (std::size_t u : due_) ok &= pending_errors_[u].empty();
    } else {
      for (std::size_t u : due_) ok &= StepUnit(u, t, h * decimation_[u]);
    }
  } else {
    // Check each unit before the next one consumes its outputs, so that a
    // NaN is blamed on the unit that made it.
    for (std::size_t u : due_) {
      transfer_into(u);
      if (!StepUnit(u, t, h * decimation_[u])) {
        ok = false;
        break;
      }
      if (!CheckOutputs(u, t + h * decimation_[u])) {
        return false;
      }
    }
  }

  if (!ok) {
    for (std::size_t u : due_) {
      if (!pending_errors_[u].empty()) {
        RecordError(u, t, "", pending_errors_[u]);
        pending_errors_[u].clear();
      }
    }
    return false;
  }
  if (jacobi) {
    for (std::size_t u : due_) ok &= CheckOutputs(u, t + h * decimation_[u]);
    if (!ok) {
      return false;
    }
  }
  ++step_index_;
  time_ = options_.start + step_index_ * h;
  Notify(time_);
  return time_ < options_.stop;
}

RunResult Master::Finish() {
  const ScopedTimer timer(options_.profile, total_wall_seconds_);
  for (std::size_t u = 0; u < system_.unit_count(); ++u) {
    try {
      system_.unit(u).Terminate();
    } catch (const std::exception& e) {
      RecordError(u, time_, "terminate failed", e.what());
    }
  }
  for (Observer* o : observers_) o->OnEnd(time_, !failed_);
  RunResult r;
  r.ok = !failed_;
  r.end_time = time_;
  r.base_steps = step_index_;
  r.errors = errors_;
  return r;
}

RunResult Master::Run() {
  Start();
  while (Step()) {
  }
  return Finish();
}

}  // namespace linesim::cosim
