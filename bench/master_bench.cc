// Master overhead: the cost of one base step for N trivial units in a chain
// (each copies its one Real input to its one Real output), so that nearly
// all of the time is the master's own work: due-unit selection, transfers,
// the NaN guard, observers (none here) and, with profiling on, two clock
// reads per unit step.
//
// Arguments: N units, algorithm (0 Jacobi, 1 Gauss-Seidel), profile (0/1),
// feedthrough (0/1: the units declare y depends on u), threads (Jacobi on a
// TBB arena of that many threads).
// Counters: unit_step = time per unit step (the benchmark's own time column
// is the time per master base step).
//
// BM_MasterStepRetry: the cost of master.retry when nothing discards, i.e.
// of saving every due unit's state before each step (Unit::SaveStateInto).
// Arguments: N units, algorithm, retry (0/1), the size of a Real array
// output each unit carries (0, or 360 like a laser's ranges), profiling off.

#include <benchmark/benchmark.h>

#include <memory>
#include <string>
#include <vector>

#include "cosim/master.h"

namespace {

using linesim::cosim::Algorithm;
using linesim::cosim::Master;
using linesim::cosim::MasterOptions;
using linesim::cosim::StepResult;
using linesim::cosim::System;
using linesim::cosim::TimeNs;
using linesim::cosim::Unit;

// y = u, declared with or without direct feedthrough (with it, the master
// also updates the output at each communication point: the worst case).
class CopyUnit : public Unit {
 public:
  CopyUnit(std::string name, bool feedthrough) : Unit("Copy", std::move(name)) {
    variables().Input("u", "1", &u_, "input");
    variables().Output("y", "1", &y_, "copy of u",
                       feedthrough ? std::vector<std::string>{"u"} : std::vector<std::string>{});
  }
  void Initialize() override { y_ = u_; }
  void UpdateOutputs() override { y_ = u_; }
  StepResult DoStep(TimeNs, TimeNs) override {
    y_ = u_;
    return StepResult::kOk;
  }

 private:
  double u_ = 1.0;
  double y_ = 0.0;
};

void BM_MasterStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  System system;
  for (int i = 0; i < n; ++i)
    system.Add(std::make_unique<CopyUnit>("u" + std::to_string(i), state.range(3) != 0));
  for (int i = 1; i < n; ++i) {
    system.Connect("u" + std::to_string(i - 1) + ".y", "u" + std::to_string(i) + ".u");
  }
  MasterOptions o;
  o.algorithm = state.range(1) == 0 ? Algorithm::kJacobi : Algorithm::kGaussSeidel;
  o.profile = state.range(2) != 0;
  o.threads = static_cast<int>(state.range(4));
  o.base_step = 1'000'000;
  o.stop = o.base_step * 1'000'000'000'000;  // far beyond any iteration count
  Master master(system, o);
  master.Start();

  for (auto _ : state) {
    if (!master.Step()) {
      state.SkipWithError("master stopped");
      break;
    }
  }
  state.counters["unit_step"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
  state.SetLabel(std::string(ToString(o.algorithm)) + (o.profile ? " profile" : " no_profile") +
                 (state.range(3) ? " feedthrough" : ""));
  master.Finish();
}

BENCHMARK(BM_MasterStep)
    ->ArgNames({"units", "gs", "profile", "feedthrough", "threads"})
    ->ArgsProduct({{1, 10, 100}, {0, 1}, {0, 1}, {0, 1}, {1}});

// y = u, plus a Real array output of a given size (its state to save).
class ArrayCopyUnit : public Unit {
 public:
  ArrayCopyUnit(std::string name, std::size_t size)
      : Unit("ArrayCopy", std::move(name)), array_(size, 1.0) {
    variables().Input("u", "1", &u_, "input");
    variables().Output("y", "1", &y_, "copy of u", {});
    if (size > 0) variables().Output("ranges", "m", &array_, "an array output", {});
  }
  StepResult DoStep(TimeNs, TimeNs) override {
    y_ = u_;
    return StepResult::kOk;
  }

 private:
  double u_ = 1.0;
  double y_ = 0.0;
  std::vector<double> array_;
};

void BM_MasterStepRetry(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  System system;
  for (int i = 0; i < n; ++i) {
    system.Add(std::make_unique<ArrayCopyUnit>("u" + std::to_string(i),
                                               static_cast<std::size_t>(state.range(3))));
  }
  for (int i = 1; i < n; ++i) {
    system.Connect("u" + std::to_string(i - 1) + ".y", "u" + std::to_string(i) + ".u");
  }
  MasterOptions o;
  o.algorithm = state.range(1) == 0 ? Algorithm::kJacobi : Algorithm::kGaussSeidel;
  o.profile = false;
  o.retry.enabled = state.range(2) != 0;
  o.base_step = 1'000'000;
  o.stop = o.base_step * 1'000'000'000'000;
  Master master(system, o);
  master.Start();
  for (auto _ : state) {
    if (!master.Step()) {
      state.SkipWithError("master stopped");
      break;
    }
  }
  state.counters["unit_step"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate |
                                                     benchmark::Counter::kInvert);
  state.SetLabel(std::string(ToString(o.algorithm)) + (o.retry.enabled ? " retry" : " no_retry"));
  master.Finish();
}

BENCHMARK(BM_MasterStepRetry)
    ->ArgNames({"units", "gs", "retry", "array"})
    ->ArgsProduct({{10, 100}, {0, 1}, {0, 1}, {0, 360}});
// The parallel Jacobi path: what a second thread costs or gains for units
// this cheap (the arena's hand-off dominates).
BENCHMARK(BM_MasterStep)
    ->ArgNames({"units", "gs", "profile", "feedthrough", "threads"})
    ->ArgsProduct({{10, 100}, {0}, {0}, {0}, {2}});

}  // namespace
