#include "cosim/parameter_checks.h"

#include <cmath>

namespace linesim::cosim {

namespace {

constexpr const char* kPositive = "must be positive and finite";
constexpr const char* kNonNegative = "must be zero or positive and finite";
constexpr const char* kFinite = "must be finite";

bool IsPositive(double x) { return x > 0.0 && std::isfinite(x); }
bool IsNonNegative(double x) { return x >= 0.0 && std::isfinite(x); }
bool IsFinite(double x) { return std::isfinite(x); }

}  // namespace

void ParameterChecks::Add(const char* name, std::optional<std::size_t> index, const char* expected,
                          double value) {
  problems_.push_back({name, index, std::string(expected) + ", got " + FormatValue(value)});
}

void ParameterChecks::Positive(const char* name, double value) {
  Check(name, value, IsPositive, kPositive);
}
void ParameterChecks::Positive(const char* name, const std::vector<double>& values) {
  Check(name, values, IsPositive, kPositive);
}
void ParameterChecks::NonNegative(const char* name, double value) {
  Check(name, value, IsNonNegative, kNonNegative);
}
void ParameterChecks::NonNegative(const char* name, const std::vector<double>& values) {
  Check(name, values, IsNonNegative, kNonNegative);
}
void ParameterChecks::Finite(const char* name, double value) {
  Check(name, value, IsFinite, kFinite);
}
void ParameterChecks::Finite(const char* name, const std::vector<double>& values) {
  Check(name, values, IsFinite, kFinite);
}

}  // namespace linesim::cosim
