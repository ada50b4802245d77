#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::cosim {

/// The co-simulation algorithms a scenario chooses with master.algorithm.
enum class Algorithm { kJacobi, kGaussSeidel };
/// "jacobi" or "gauss_seidel": the names scenarios, summaries and messages use.
std::string_view ToString(Algorithm a);
/// The inverse of ToString; false, leaving *out alone, for any other text.
bool ParseAlgorithm(std::string_view text, Algorithm* out);
std::vector<std::string> AlgorithmNames();

/// What a step algorithm may do at one communication point: the execution
/// side of the master (which units are due, links, unit calls with their
/// failures recorded, the NaN/Inf guard). The master implements it; an
/// algorithm only decides the order of these calls.
class StepContext {
 public:
  virtual ~StepContext() = default;
  /// The units that step at this communication point, in dependency order.
  std::span<const std::size_t> due() const { return due_; }
  /// Whether some output of unit u depends directly on its inputs.
  bool has_feedthrough(std::size_t u) const { return (*feedthrough_)[u]; }
  /// Sets u's inputs over the links whose source is at a communication point.
  virtual void TransferInto(std::size_t u) = 0;
  /// Passes u's outputs on to the due units it feeds.
  virtual void TransferFrom(std::size_t u) = 0;
  /// UpdateOutputs() of unit u, then the guard on its outputs; false (the
  /// failure recorded) when either fails.
  virtual bool UpdateOutputs(std::size_t u) = 0;
  /// Steps unit u from the communication point by its own step (the
  /// master's step, or its multiple for a slower unit). A failure or a
  /// discard is kept for the master to report or retry. Safe to call for
  /// different units at the same time.
  virtual StepResult StepUnit(std::size_t u) = 0;
  /// The guard on u's outputs after its step; false (recorded) on NaN/Inf.
  virtual bool CheckOutputs(std::size_t u) = 0;

 protected:
  // Plain data, read per unit in the algorithms' loops (no virtual call).
  std::span<const std::size_t> due_;
  const std::vector<bool>* feedthrough_ = nullptr;
};

/// How a communication step ended.
enum class StepStatus {
  kOk,
  kDiscard,  // some unit discarded its step and none failed: it may be retried
  kError,    // a unit failed: the run ends
};

/// A co-simulation algorithm: the order of transfers, output updates and
/// unit steps within one communication step, as libcosim separates its
/// `algorithm` from the `execution` that drives time and observers. The
/// master owns time, multirate, retries, errors and observers.
class StepAlgorithm {
 public:
  virtual ~StepAlgorithm() = default;
  virtual Algorithm kind() const = 0;
  /// Advances the due units of `context` from t over the communication
  /// step dt (a unit slower than the master steps its own multiple).
  virtual StepStatus Step(TimeNs t, TimeNs dt, StepContext& context) = 0;
};

/// Jacobi: every due unit steps from the values exchanged at t (outputs
/// with direct feedthrough updated first); optionally on several threads,
/// with identical results.
class JacobiAlgorithm final : public StepAlgorithm {
 public:
  explicit JacobiAlgorithm(int threads = 1);
  ~JacobiAlgorithm() override;
  Algorithm kind() const override { return Algorithm::kJacobi; }
  StepStatus Step(TimeNs t, TimeNs dt, StepContext& context) override;

 private:
  struct Arena;  // TBB arena of `threads` threads (kept out of this header)
  std::unique_ptr<Arena> arena_;
  std::vector<StepResult> results_;
};

/// Gauss-Seidel: units step one after the other in dependency order, each
/// from the outputs its predecessors computed for the end of the step.
class GaussSeidelAlgorithm final : public StepAlgorithm {
 public:
  Algorithm kind() const override { return Algorithm::kGaussSeidel; }
  StepStatus Step(TimeNs t, TimeNs dt, StepContext& context) override;
};

/// The algorithm of that name; `threads` applies to Jacobi.
std::unique_ptr<StepAlgorithm> MakeAlgorithm(Algorithm kind, int threads = 1);

}  // namespace linesim::cosim
