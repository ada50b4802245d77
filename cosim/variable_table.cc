#include "cosim/variable_table.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

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
  info.ref = static_cast<ValueRef>(infos_.size());
  by_name_.emplace(info.name, info.ref);
  if (info.type == VarType::kReal || info.type == VarType::kRealArray) {
    if (causality == Causality::kInput) real_inputs_.push_back(info.ref);
    if (causality == Causality::kOutput) real_outputs_.push_back(info.ref);
  }
  infos_.push_back(std::move(info));
  storage_.push_back(storage);
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
  auto* dst = Slot<std::vector<double>>(ref, VarType::kRealArray);
  if (v.size() != dst->size()) {
    throw std::invalid_argument("'" + infos_[ref].name + "' holds " + std::to_string(dst->size()) +
                                " elements, got " + std::to_string(v.size()));
  }
  std::copy(v.begin(), v.end(), dst->begin());
}

double VariableTable::GetRealElement(ValueRef ref, std::size_t index) const {
  return Slot<std::vector<double>>(ref, VarType::kRealArray)->at(index);
}

void VariableTable::SetRealElement(ValueRef ref, std::size_t index, double v) {
  Slot<std::vector<double>>(ref, VarType::kRealArray)->at(index) = v;
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

std::optional<std::string> FirstNonFinite(const VariableTable& table,
                                          std::span<const ValueRef> refs) {
  const auto describe = [&](const VariableInfo& info, std::string element, double v) {
    return std::string(ToString(info.causality)) + " '" + info.name + element + "' is " +
           FormatValue(v);
  };
  for (ValueRef ref : refs) {
    const VariableInfo& info = table.info(ref);
    if (info.type == VarType::kReal) {
      const double v = table.GetReal(ref);
      if (!std::isfinite(v)) return describe(info, "", v);
    } else {
      const auto values = table.GetRealArray(ref);
      for (std::size_t k = 0; k < values.size(); ++k) {
        if (!std::isfinite(values[k])) {
          return describe(info, "[" + std::to_string(k) + "]", values[k]);
        }
      }
    }
  }
  return std::nullopt;
}

}  // namespace linesim::cosim
