#include "cosim/variable_table.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "cosim/time.h"

namespace linesim::cosim {

std::string_view ToString(VarType t) {
  switch (t) {
    case VarType::kReal:
      return "Real";
    case VarType::kInteger:
      return "Integer";
    case VarType::kBoolean:
      return "Boolean";
    case VarType::kString:
      return "String";
    case VarType::kRealArray:
      return "Real[]";
  }
  return "?";
}

std::string_view ToString(Causality c) {
  switch (c) {
    case Causality::kParameter:
      return "parameter";
    case Causality::kInput:
      return "input";
    case Causality::kOutput:
      return "output";
    case Causality::kLocal:
      return "local";
  }
  return "?";
}

std::string_view ToString(Variability v) {
  switch (v) {
    case Variability::kConstant:
      return "constant";
    case Variability::kFixed:
      return "fixed";
    case Variability::kTunable:
      return "tunable";
    case Variability::kDiscrete:
      return "discrete";
    case Variability::kContinuous:
      return "continuous";
  }
  return "?";
}

std::string FormatValue(double x) {
  char buf[32];
  auto res = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, res.ptr);
}

std::optional<double> ParseFiniteValue(std::string_view text) {
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double x = 0.0;
  const char* end = text.data() + text.size();
  const auto res = std::from_chars(text.data(), end, x);
  if (text.empty() || res.ec != std::errc() || res.ptr != end || !std::isfinite(x)) {
    return std::nullopt;
  }
  return x;
}

std::string FormatValue(const Value& v) {
  struct Visitor {
    std::string operator()(double x) const { return FormatValue(x); }
    std::string operator()(std::int64_t x) const { return std::to_string(x); }
    std::string operator()(bool x) const { return x ? "true" : "false"; }
    std::string operator()(const std::string& x) const { return "\"" + x + "\""; }
    std::string operator()(const std::vector<double>& x) const {
      std::string out = "[";
      for (std::size_t i = 0; i < x.size(); ++i) {
        if (i) out += ", ";
        out += FormatValue(x[i]);
      }
      return out + "]";
    }
  };
  return std::visit(Visitor{}, v);
}

namespace {

std::string JoinTexts(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& i : items) out += (out.empty() ? "" : ", ") + i;
  return out;
}

}  // namespace

Rule Rule::Finite() {
  Rule r;
  r.numeric_ = true;
  return r;
}
Rule Rule::Positive() { return AtLeast(0.0, false); }
Rule Rule::NonNegative() { return AtLeast(0.0, true); }

Rule Rule::AtLeast(double min, bool inclusive) {
  if (!std::isfinite(min)) throw std::logic_error("Rule::AtLeast: the bound must be finite");
  Rule r = Finite();
  r.min_ = Bound{min, inclusive};
  return r;
}

Rule Rule::AtMost(double max, bool inclusive) {
  if (!std::isfinite(max)) throw std::logic_error("Rule::AtMost: the bound must be finite");
  Rule r = Finite();
  r.max_ = Bound{max, inclusive};
  return r;
}

Rule Rule::Range(double min, bool min_inclusive, double max, bool max_inclusive) {
  if (!(min < max) && !(min == max && min_inclusive && max_inclusive)) {
    throw std::logic_error("Rule::Range: no value lies between " + FormatValue(min) + " and " +
                           FormatValue(max));
  }
  Rule r = AtLeast(min, min_inclusive);
  r.max_ = AtMost(max, max_inclusive).max_;
  return r;
}

Rule Rule::OneOf(std::vector<std::string> allowed) {
  if (allowed.empty()) throw std::logic_error("Rule::OneOf: no allowed value");
  Rule r;
  r.strings_ = std::move(allowed);
  return r;
}
Rule Rule::OneOf(std::initializer_list<const char*> allowed) {
  return OneOf(std::vector<std::string>(allowed.begin(), allowed.end()));
}
Rule Rule::OneOf(std::vector<std::int64_t> allowed) {
  if (allowed.empty()) throw std::logic_error("Rule::OneOf: no allowed value");
  Rule r;
  r.integers_ = std::move(allowed);
  return r;
}
Rule Rule::OneOf(std::initializer_list<int> allowed) {
  return OneOf(std::vector<std::int64_t>(allowed.begin(), allowed.end()));
}

Rule Rule::NoDefault() const {
  Rule r = *this;
  r.required_ = true;
  return r;
}

Rule Rule::Limited(double max_abs, double resolution, const char* why) const {
  Rule r = *this;
  r.numeric_ = true;
  if (!r.min_ || r.min_->value < -max_abs) r.min_ = Bound{-max_abs, true};
  if (!r.max_ || r.max_->value > max_abs) r.max_ = Bound{max_abs, true};
  if (r.min_->value > r.max_->value) {
    throw std::logic_error("Rule: no value lies between " + FormatValue(r.min_->value) + " and " +
                           FormatValue(r.max_->value) + " within the limit");
  }
  r.limit_ = Limit{max_abs, resolution, why};
  return r;
}

Rule Rule::Time() const {
  return Limited(kMaxTimeSeconds, kTimeResolutionSeconds,
                 "4.6e9 s is the longest time linesim represents: int64 nanoseconds, with room "
                 "for a time plus a duration");
}

Rule Rule::Count() const {
  return Limited(kMaxExactCount, 0.0, "2^53 is the largest count a Real carries exactly");
}

std::string Rule::LimitReason(double x) const {
  if (!limit_ || std::abs(x) <= limit_->max_abs) return "";
  return std::string(" (") + limit_->why + ")";
}

bool Rule::empty() const { return !numeric_ && !strings_ && !integers_ && !required_; }

std::string Rule::Bounds() const {
  if (min_ && max_) {
    return std::string(min_->inclusive ? "[" : "(") + FormatValue(min_->value) + ", " +
           FormatValue(max_->value) + (max_->inclusive ? "]" : ")");
  }
  if (min_) return (min_->inclusive ? ">= " : "> ") + FormatValue(min_->value);
  if (max_) return (max_->inclusive ? "<= " : "< ") + FormatValue(max_->value);
  return "";
}

std::string Rule::Text() const {
  std::vector<std::string> parts;
  if (required_) parts.push_back("required");
  if (!Bounds().empty()) {
    parts.push_back(Bounds());
  } else if (numeric_ && !required_) {
    parts.push_back("finite");
  }
  if (strings_) parts.push_back("one of: " + JoinTexts(*strings_));
  if (integers_) {
    std::vector<std::string> texts;
    for (auto n : *integers_) texts.push_back(std::to_string(n));
    parts.push_back("one of: " + JoinTexts(texts));
  }
  return JoinTexts(parts);
}

namespace {

constexpr const char* kNotSet = "must be set (robot-specific: no default)";

}  // namespace

std::optional<std::string> Rule::Violation(double x) const {
  if (required_ && std::isnan(x)) return kNotSet;
  if (!numeric_ && !required_) return std::nullopt;
  // "in [0, 1]" reads better than "[0, 1]" in a sentence; "> 0" as is.
  const std::string bounds = (min_ && max_ ? "in " : "") + Bounds();
  if (!std::isfinite(x)) {
    return "must be finite" + (bounds.empty() ? "" : " and " + bounds) + ", got " + FormatValue(x);
  }
  const bool low = min_ && (min_->inclusive ? x < min_->value : x <= min_->value);
  const bool high = max_ && (max_->inclusive ? x > max_->value : x >= max_->value);
  if (low || high) return "must be " + bounds + LimitReason(x) + ", got " + FormatValue(x);
  if (limit_ && x != 0.0 && std::abs(x) < limit_->resolution) {
    return "must be " + std::string(min_ && min_->value == 0.0 && !min_->inclusive ? "" : "0 or ") +
           "at least " + FormatValue(limit_->resolution) +
           " in magnitude (1 ns is the time resolution: it would round to 0), got " +
           FormatValue(x);
  }
  return std::nullopt;
}

std::optional<std::string> Rule::Violation(std::int64_t x) const {
  if (min_ || max_) {
    if (auto v = Violation(static_cast<double>(x))) {
      // The integer as written, not as the double that compared.
      return v->substr(0, v->rfind(", got ")) + ", got " + std::to_string(x);
    }
  }
  if (integers_ && std::find(integers_->begin(), integers_->end(), x) == integers_->end()) {
    return "must be " + Text() + ", got " + std::to_string(x);
  }
  return std::nullopt;
}

std::optional<std::string> Rule::Violation(const std::string& x) const {
  if (required_ && x.empty()) return kNotSet;
  if (strings_ && std::find(strings_->begin(), strings_->end(), x) == strings_->end()) {
    return "must be one of: " + JoinTexts(*strings_) + ", got '" + x + "'";
  }
  return std::nullopt;
}

void Rule::CheckApplies(const std::string& variable, VarType type) const {
  const auto refuse = [&](const std::string& what) {
    throw std::logic_error("parameter '" + variable + "' is " + std::string(ToString(type)) + ": " +
                           what);
  };
  switch (type) {
    case VarType::kReal:
    case VarType::kRealArray:
      if (strings_ || integers_) refuse("a set of allowed values applies to String or Integer");
      break;
    case VarType::kInteger:
      if (strings_) refuse("a set of strings applies to a String");
      if (required_) refuse("an integer has no 'not set' value, so it cannot be required");
      break;
    case VarType::kBoolean:
      if (!empty()) refuse("a Boolean takes no rule");
      break;
    case VarType::kString:
      if (numeric_ || integers_) refuse("a number rule applies to a Real or an Integer");
      break;
  }
}

namespace {

template <typename T>
constexpr VarType kTypeOf = VarType::kReal;
template <>
constexpr VarType kTypeOf<std::vector<double>> = VarType::kRealArray;
template <>
constexpr VarType kTypeOf<std::int64_t> = VarType::kInteger;
template <>
constexpr VarType kTypeOf<bool> = VarType::kBoolean;
template <>
constexpr VarType kTypeOf<std::string> = VarType::kString;

template <typename T>
std::size_t ElementCount(const T&) {
  return 1;
}
std::size_t ElementCount(const std::vector<double>& v) { return v.size(); }

// Inputs and outputs exchanged as signals are continuous for reals and
// discrete for the other types.
Variability SignalVariability(VarType t) {
  return (t == VarType::kReal || t == VarType::kRealArray) ? Variability::kContinuous
                                                           : Variability::kDiscrete;
}

// A parameter in seconds: units convert it to integer nanoseconds, so its
// rule is a time's (Rule::Time) whatever else it says.
bool IsTime(const VariableInfo& i) {
  return i.causality == Causality::kParameter && i.unit == "s" &&
         (i.type == VarType::kReal || i.type == VarType::kRealArray);
}

// A required parameter's start value: NaN, every element NaN, or "".
bool IsUnset(double x) { return std::isnan(x); }
bool IsUnset(const std::vector<double>& x) {
  return std::all_of(x.begin(), x.end(), [](double e) { return std::isnan(e); });
}
bool IsUnset(const std::string& x) { return x.empty(); }
bool IsUnset(std::int64_t) { return false; }
bool IsUnset(bool) { return false; }

}  // namespace

template <typename T>
ValueRef VariableTable::Bind(std::string name, Causality causality, Variability variability,
                             std::string unit, T* storage, std::string description,
                             const std::vector<std::string>& depends_on) {
  VariableInfo info;
  info.name = std::move(name);
  info.type = kTypeOf<T>;
  info.size = ElementCount(*storage);
  info.causality = causality;
  info.variability = variability;
  info.unit = std::move(unit);
  info.description = std::move(description);
  info.start = *storage;
  info.depends_on = ResolveDependencies(info.name, depends_on);
  if (info.name.empty()) throw std::logic_error("variable with an empty name");
  if (by_name_.count(info.name)) {
    throw std::logic_error("variable '" + info.name + "' declared twice");
  }
  if (IsTime(info)) info.rule = Rule().Time();
  info.ref = static_cast<ValueRef>(infos_.size());
  by_name_.emplace(info.name, info.ref);
  if constexpr (std::is_same_v<T, double> || std::is_same_v<T, std::vector<double>>) {
    RealSlot slot;
    if constexpr (std::is_same_v<T, double>) {
      slot.scalar = storage;
    } else {
      slot.array = storage;
    }
    if (causality == Causality::kInput) {
      real_inputs_.push_back(info.ref);
      real_input_slots_.push_back(slot);
    }
    if (causality == Causality::kOutput) {
      real_outputs_.push_back(info.ref);
      real_output_slots_.push_back(slot);
    }
  }
  infos_.push_back(std::move(info));
  storage_.push_back(storage);
  read_only_.push_back(variability == Variability::kConstant ? 1 : 0);
  return infos_.back().ref;
}

ValueRef VariableTable::Parameter(std::string name, std::string unit, double* s, std::string d,
                                  Variability v) {
  return Bind(std::move(name), Causality::kParameter, v, std::move(unit), s, std::move(d));
}
ValueRef VariableTable::Parameter(std::string name, std::string unit, std::vector<double>* s,
                                  std::string d, Variability v) {
  return Bind(std::move(name), Causality::kParameter, v, std::move(unit), s, std::move(d));
}
ValueRef VariableTable::Parameter(std::string name, std::int64_t* s, std::string d, Variability v) {
  return Bind(std::move(name), Causality::kParameter, v, "1", s, std::move(d));
}
ValueRef VariableTable::Parameter(std::string name, bool* s, std::string d, Variability v) {
  return Bind(std::move(name), Causality::kParameter, v, "1", s, std::move(d));
}
ValueRef VariableTable::Parameter(std::string name, std::string* s, std::string d, Variability v) {
  return Bind(std::move(name), Causality::kParameter, v, "", s, std::move(d));
}

ValueRef VariableTable::Parameter(std::string name, std::string unit, double* s, std::string d,
                                  Rule rule, Variability v) {
  const ValueRef ref = Parameter(std::move(name), std::move(unit), s, std::move(d), v);
  SetRule(ref, std::move(rule));
  return ref;
}
ValueRef VariableTable::Parameter(std::string name, std::string unit, std::vector<double>* s,
                                  std::string d, Rule rule, Variability v) {
  const ValueRef ref = Parameter(std::move(name), std::move(unit), s, std::move(d), v);
  SetRule(ref, std::move(rule));
  return ref;
}
ValueRef VariableTable::Parameter(std::string name, std::int64_t* s, std::string d, Rule rule,
                                  Variability v) {
  const ValueRef ref = Parameter(std::move(name), s, std::move(d), v);
  SetRule(ref, std::move(rule));
  return ref;
}
ValueRef VariableTable::Parameter(std::string name, std::string* s, std::string d, Rule rule,
                                  Variability v) {
  const ValueRef ref = Parameter(std::move(name), s, std::move(d), v);
  SetRule(ref, std::move(rule));
  return ref;
}

void VariableTable::SetRule(ValueRef ref, Rule rule) {
  VariableInfo& i = infos_.at(ref);
  if (i.causality != Causality::kParameter) {
    throw std::logic_error("'" + i.name + "' is " + std::string(ToString(i.causality)) +
                           ": only parameters have rules");
  }
  rule.CheckApplies(i.name, i.type);
  if (rule.required()) {
    // No default means no default: a start value would hide a missing one.
    const auto& start = i.start;
    const bool unset = std::visit([](const auto& x) { return IsUnset(x); }, start);
    if (!unset) {
      throw std::logic_error("parameter '" + i.name + "' is required (no default) but starts at " +
                             FormatValue(start) + ": start it at NaN (or \"\")");
    }
  }
  i.rule = IsTime(i) ? rule.Time() : std::move(rule);
}

void VariableTable::Lock() {
  locked_ = true;
  for (const auto& i : infos_) {
    if (i.causality == Causality::kParameter && i.variability == Variability::kFixed) {
      read_only_[i.ref] = 1;
    }
  }
}

void VariableTable::ThrowReadOnly(ValueRef ref) const {
  const VariableInfo& i = infos_[ref];
  if (i.variability == Variability::kConstant) {
    throw std::logic_error(std::string(ToString(i.causality)) + " '" + i.name +
                           "' is a constant of the unit: it cannot be set");
  }
  throw std::logic_error("parameter '" + i.name +
                         "' is fixed: it is set before the run and cannot change once the unit "
                         "is initialized (a parameter that may change between steps is declared "
                         "tunable)");
}

void VariableTable::RestoreValue(ValueRef ref, const Value& v) {
  const char was = read_only_.at(ref);
  read_only_[ref] = 0;
  try {
    SetValue(ref, v);
  } catch (...) {
    read_only_[ref] = was;
    throw;
  }
  read_only_[ref] = was;
}

ValueRef VariableTable::Input(std::string name, std::string unit, double* s, std::string d) {
  return Bind(std::move(name), Causality::kInput, SignalVariability(VarType::kReal),
              std::move(unit), s, std::move(d));
}
ValueRef VariableTable::Input(std::string name, std::string unit, std::vector<double>* s,
                              std::string d) {
  return Bind(std::move(name), Causality::kInput, SignalVariability(VarType::kRealArray),
              std::move(unit), s, std::move(d));
}
ValueRef VariableTable::Input(std::string name, std::int64_t* s, std::string d) {
  return Bind(std::move(name), Causality::kInput, Variability::kDiscrete, "1", s, std::move(d));
}
ValueRef VariableTable::Input(std::string name, bool* s, std::string d) {
  return Bind(std::move(name), Causality::kInput, Variability::kDiscrete, "1", s, std::move(d));
}
ValueRef VariableTable::Input(std::string name, std::string* s, std::string d) {
  return Bind(std::move(name), Causality::kInput, Variability::kDiscrete, "", s, std::move(d));
}

ValueRef VariableTable::Output(std::string name, std::string unit, double* s, std::string d,
                               const std::vector<std::string>& deps) {
  return Bind(std::move(name), Causality::kOutput, SignalVariability(VarType::kReal),
              std::move(unit), s, std::move(d), deps);
}
ValueRef VariableTable::Output(std::string name, std::string unit, std::vector<double>* s,
                               std::string d, const std::vector<std::string>& deps) {
  return Bind(std::move(name), Causality::kOutput, SignalVariability(VarType::kRealArray),
              std::move(unit), s, std::move(d), deps);
}
ValueRef VariableTable::Output(std::string name, std::int64_t* s, std::string d,
                               const std::vector<std::string>& deps) {
  return Bind(std::move(name), Causality::kOutput, Variability::kDiscrete, "1", s, std::move(d),
              deps);
}
ValueRef VariableTable::Output(std::string name, bool* s, std::string d,
                               const std::vector<std::string>& deps) {
  return Bind(std::move(name), Causality::kOutput, Variability::kDiscrete, "1", s, std::move(d),
              deps);
}
ValueRef VariableTable::Output(std::string name, std::string* s, std::string d,
                               const std::vector<std::string>& deps) {
  return Bind(std::move(name), Causality::kOutput, Variability::kDiscrete, "", s, std::move(d),
              deps);
}

ValueRef VariableTable::Local(std::string name, std::string unit, double* s, std::string d) {
  return Bind(std::move(name), Causality::kLocal, Variability::kContinuous, std::move(unit), s,
              std::move(d));
}
ValueRef VariableTable::Local(std::string name, std::string unit, std::vector<double>* s,
                              std::string d) {
  return Bind(std::move(name), Causality::kLocal, Variability::kContinuous, std::move(unit), s,
              std::move(d));
}

std::vector<ValueRef> VariableTable::ResolveDependencies(
    const std::string& output, const std::vector<std::string>& names) const {
  std::vector<ValueRef> refs;
  for (const auto& n : names) {
    auto it = by_name_.find(n);
    if (it == by_name_.end() || infos_[it->second].causality != Causality::kInput) {
      throw std::logic_error("output '" + output + "' depends on '" + n +
                             "', which is not an input declared before it");
    }
    refs.push_back(it->second);
  }
  return refs;
}

std::optional<ValueRef> VariableTable::Find(std::string_view name) const {
  auto it = by_name_.find(std::string(name));
  if (it == by_name_.end()) return std::nullopt;
  return it->second;
}

std::vector<std::string> VariableTable::Names() const {
  std::vector<std::string> names;
  names.reserve(infos_.size());
  for (const auto& i : infos_) names.push_back(i.name);
  return names;
}

void VariableTable::ThrowTypeMisuse(ValueRef ref, VarType expected) const {
  if (ref >= infos_.size()) {
    throw std::logic_error("value reference " + std::to_string(ref) + " out of range");
  }
  throw std::logic_error("variable '" + infos_[ref].name + "' is " +
                         std::string(ToString(infos_[ref].type)) + ", accessed as " +
                         std::string(ToString(expected)));
}

std::span<const double> VariableTable::GetRealArray(ValueRef ref) const {
  const auto* v = Slot<std::vector<double>>(ref, VarType::kRealArray);
  return {v->data(), v->size()};
}

void VariableTable::SetRealArray(ValueRef ref, std::span<const double> v) {
  auto* dst = Writable<std::vector<double>>(ref, VarType::kRealArray);
  if (v.size() != dst->size()) {
    throw std::invalid_argument("'" + infos_[ref].name + "' holds " + std::to_string(dst->size()) +
                                " elements, got " + std::to_string(v.size()));
  }
  std::copy(v.begin(), v.end(), dst->begin());
}

VariableTable::RealSlot VariableTable::ResolveReal(ValueRef ref) const {
  if (ref < infos_.size() && infos_[ref].type == VarType::kReal) {
    return {Slot<double>(ref, VarType::kReal), nullptr};
  }
  return {nullptr, Slot<std::vector<double>>(ref, VarType::kRealArray)};
}

VariableTable::WritableRealSlot VariableTable::ResolveWritableReal(ValueRef ref) {
  if (ref < infos_.size() && infos_[ref].type == VarType::kReal) {
    return {Writable<double>(ref, VarType::kReal), nullptr};
  }
  return {nullptr, Writable<std::vector<double>>(ref, VarType::kRealArray)};
}

double VariableTable::GetRealElement(ValueRef ref, std::size_t index) const {
  return Slot<std::vector<double>>(ref, VarType::kRealArray)->at(index);
}

void VariableTable::SetRealElement(ValueRef ref, std::size_t index, double v) {
  Writable<std::vector<double>>(ref, VarType::kRealArray)->at(index) = v;
}

Value VariableTable::GetValue(ValueRef ref) const {
  switch (info(ref).type) {
    case VarType::kReal:
      return GetReal(ref);
    case VarType::kInteger:
      return GetInteger(ref);
    case VarType::kBoolean:
      return GetBoolean(ref);
    case VarType::kString:
      return GetString(ref);
    case VarType::kRealArray: {
      auto s = GetRealArray(ref);
      return std::vector<double>(s.begin(), s.end());
    }
  }
  return {};
}

void VariableTable::SetValue(ValueRef ref, const Value& v) {
  const VariableInfo& i = info(ref);
  const auto expected = [&]() -> std::string {
    if (i.type == VarType::kRealArray) {
      return "a number or a list of " + std::to_string(i.size) + " numbers";
    }
    switch (i.type) {
      case VarType::kReal:
        return "a number";
      case VarType::kInteger:
        return "an integer";
      case VarType::kBoolean:
        return "true or false";
      default:
        return "a string";
    }
  };
  switch (i.type) {
    case VarType::kReal:
      if (auto* d = std::get_if<double>(&v)) return SetReal(ref, *d);
      if (auto* n = std::get_if<std::int64_t>(&v)) return SetReal(ref, static_cast<double>(*n));
      break;
    case VarType::kInteger:
      if (auto* n = std::get_if<std::int64_t>(&v)) return SetInteger(ref, *n);
      break;
    case VarType::kBoolean:
      if (auto* b = std::get_if<bool>(&v)) return SetBoolean(ref, *b);
      break;
    case VarType::kString:
      if (auto* s = std::get_if<std::string>(&v)) return SetString(ref, *s);
      break;
    case VarType::kRealArray: {
      double scalar = 0;
      if (auto* d = std::get_if<double>(&v)) {
        scalar = *d;
      } else if (auto* n = std::get_if<std::int64_t>(&v)) {
        scalar = static_cast<double>(*n);
      } else if (auto* a = std::get_if<std::vector<double>>(&v)) {
        if (a->size() == i.size) return SetRealArray(ref, *a);
        throw std::invalid_argument("expected " + expected() + ", got a list of " +
                                    std::to_string(a->size()));
      } else {
        break;
      }
      std::vector<double> filled(i.size, scalar);
      return SetRealArray(ref, filled);
    }
  }
  throw std::invalid_argument("expected " + expected() + ", got " + FormatValue(v));
}

namespace {
// A value is inf or NaN exactly when its exponent bits are all set, and then
// adding one to the exponent carries into the sign bit: OR-ing the carries
// of many values tests them all in one branch-free pass, which the compiler
// vectorizes with SSE2 (every unit's real inputs and outputs are checked
// every step, a laser's ranges among them).
std::uint64_t NonFiniteCarry(double x) {
  constexpr std::uint64_t kExponentBits = 0x7ff0000000000000ULL;
  constexpr std::uint64_t kExponentOne = std::uint64_t{1} << 52;
  return (std::bit_cast<std::uint64_t>(x) & kExponentBits) + kExponentOne;
}
}  // namespace

bool VariableTable::AllFinite(std::span<const RealSlot> slots) {
  std::uint64_t carries = 0;
  for (const RealSlot& slot : slots) {
    if (slot.scalar != nullptr) {
      carries |= NonFiniteCarry(*slot.scalar);
      continue;
    }
    for (const double x : *slot.array) carries |= NonFiniteCarry(x);
  }
  return (carries >> 63) == 0;
}

std::optional<NonFinite> FindNonFinite(const VariableTable& table,
                                       std::span<const ValueRef> refs) {
  // The common case, all finite, in one pass first.
  std::uint64_t carries = 0;
  for (ValueRef ref : refs) {
    for (const double x : table.RealValues(ref)) carries |= NonFiniteCarry(x);
  }
  if ((carries >> 63) == 0) return std::nullopt;
  for (ValueRef ref : refs) {
    const VariableInfo& info = table.info(ref);
    const auto values = table.RealValues(ref);
    for (std::size_t k = 0; k < values.size(); ++k) {
      if (std::isfinite(values[k])) continue;
      const std::string name =
          info.name + (info.type == VarType::kReal ? "" : "[" + std::to_string(k) + "]");
      return NonFinite{name, std::string(ToString(info.causality)) + " '" + name + "' is " +
                                 FormatValue(values[k])};
    }
  }
  return std::nullopt;
}

std::optional<std::string> FirstNonFinite(const VariableTable& table,
                                          std::span<const ValueRef> refs) {
  auto found = FindNonFinite(table, refs);
  if (!found) return std::nullopt;
  return std::move(found->text);
}

std::vector<ParameterProblem> CheckRule(const VariableInfo& info, const Value& v) {
  std::vector<ParameterProblem> problems;
  if (info.rule.empty()) return problems;
  const auto add = [&](std::optional<std::size_t> index, std::optional<std::string> message) {
    if (message) problems.push_back({info.name, index, std::move(*message)});
  };
  const bool real = info.type == VarType::kReal || info.type == VarType::kRealArray;
  if (const auto* d = std::get_if<double>(&v); d && real) {
    add(std::nullopt, info.rule.Violation(*d));
  } else if (const auto* n = std::get_if<std::int64_t>(&v)) {
    if (real) add(std::nullopt, info.rule.Violation(static_cast<double>(*n)));
    if (info.type == VarType::kInteger) add(std::nullopt, info.rule.Violation(*n));
  } else if (const auto* a = std::get_if<std::vector<double>>(&v);
             a && info.type == VarType::kRealArray) {
    for (std::size_t k = 0; k < a->size(); ++k) add(k, info.rule.Violation((*a)[k]));
  } else if (const auto* t = std::get_if<std::string>(&v); t && info.type == VarType::kString) {
    add(std::nullopt, info.rule.Violation(*t));
  }
  return problems;
}

std::vector<ParameterProblem> CheckRules(const VariableTable& table) {
  std::vector<ParameterProblem> problems;
  for (const auto& info : table.infos()) {
    if (info.causality != Causality::kParameter || info.rule.empty()) continue;
    for (auto& p : CheckRule(info, table.GetValue(info.ref))) problems.push_back(std::move(p));
  }
  return problems;
}

}  // namespace linesim::cosim
