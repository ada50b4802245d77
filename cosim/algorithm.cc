#include "cosim/algorithm.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

namespace linesim::cosim {

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

struct JacobiAlgorithm::Arena {
  explicit Arena(int threads) : arena(threads) {}
  tbb::task_arena arena;
};

JacobiAlgorithm::JacobiAlgorithm(int threads) {
  if (threads > 1) arena_ = std::make_unique<Arena>(threads);
}

JacobiAlgorithm::~JacobiAlgorithm() = default;

StepStatus JacobiAlgorithm::Step(TimeNs, TimeNs, StepContext& c) {
  const auto due = c.due();
  // Every due unit reads the values of this communication point. Outputs
  // with direct feedthrough follow them first (FMI: outputs read after
  // inputs are set reflect them); dependency order puts a feedthrough unit
  // after the units feeding it, so one pass resolves chains, each update
  // passed on to the due units it feeds.
  for (std::size_t u : due) c.TransferInto(u);
  for (std::size_t u : due) {
    if (!c.has_feedthrough(u)) continue;
    if (!c.UpdateOutputs(u)) return StepStatus::kError;
    c.TransferFrom(u);
  }
  // Every unit steps (failures are kept per unit), then the guard: all
  // units see the same inputs, so none is to blame for another's output.
  results_.resize(due.size());
  if (arena_ && due.size() > 1) {
    arena_->arena.execute([&] {
      tbb::parallel_for(std::size_t{0}, due.size(),
                        [&](std::size_t i) { results_[i] = c.StepUnit(due[i]); });
    });
  } else {
    for (std::size_t i = 0; i < due.size(); ++i) results_[i] = c.StepUnit(due[i]);
  }
  bool discard = false;
  bool error = false;
  for (const StepResult r : results_) {
    discard |= r == StepResult::kDiscard;
    error |= r == StepResult::kError;
  }
  if (error) return StepStatus::kError;
  if (discard) return StepStatus::kDiscard;
  bool ok = true;
  for (std::size_t u : due) ok &= c.CheckOutputs(u);
  return ok ? StepStatus::kOk : StepStatus::kError;
}

StepStatus GaussSeidelAlgorithm::Step(TimeNs, TimeNs, StepContext& c) {
  const auto due = c.due();
  // Outputs with direct feedthrough follow the inputs of this point; the
  // other units get theirs right before they step.
  for (std::size_t u : due) {
    if (!c.has_feedthrough(u)) continue;
    c.TransferInto(u);
    if (!c.UpdateOutputs(u)) return StepStatus::kError;
  }
  // Each unit is checked before the next one consumes its outputs, so that
  // a NaN is blamed on the unit that made it.
  for (std::size_t u : due) {
    c.TransferInto(u);
    switch (c.StepUnit(u)) {
      case StepResult::kOk:
        break;
      case StepResult::kDiscard:
        return StepStatus::kDiscard;
      case StepResult::kError:
        return StepStatus::kError;
    }
    if (!c.CheckOutputs(u)) return StepStatus::kError;
  }
  return StepStatus::kOk;
}

std::unique_ptr<StepAlgorithm> MakeAlgorithm(Algorithm kind, int threads) {
  switch (kind) {
    case Algorithm::kJacobi:
      return std::make_unique<JacobiAlgorithm>(threads);
    case Algorithm::kGaussSeidel:
      return std::make_unique<GaussSeidelAlgorithm>();
  }
  return nullptr;
}

}  // namespace linesim::cosim
