#include "units/fmu/model_description.h"

#include <pugixml.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <unordered_map>

namespace linesim::fmu {

namespace {

using Exponents = std::array<int, 8>;  // kg m s A K mol cd rad

// SI symbols (no prefixes) as base-unit exponents: the ones FMI's
// UnitDefinitions and Modelica unit strings use.
std::optional<Exponents> SymbolExponents(std::string_view s) {
  struct Entry {
    const char* symbol;
    Exponents e;
  };
  static const Entry kSymbols[] = {
      {"kg", {1, 0, 0, 0, 0, 0, 0, 0}},    {"m", {0, 1, 0, 0, 0, 0, 0, 0}},
      {"s", {0, 0, 1, 0, 0, 0, 0, 0}},     {"A", {0, 0, 0, 1, 0, 0, 0, 0}},
      {"K", {0, 0, 0, 0, 1, 0, 0, 0}},     {"mol", {0, 0, 0, 0, 0, 1, 0, 0}},
      {"cd", {0, 0, 0, 0, 0, 0, 1, 0}},    {"rad", {0, 0, 0, 0, 0, 0, 0, 1}},
      {"N", {1, 1, -2, 0, 0, 0, 0, 0}},    {"J", {1, 2, -2, 0, 0, 0, 0, 0}},
      {"W", {1, 2, -3, 0, 0, 0, 0, 0}},    {"V", {1, 2, -3, -1, 0, 0, 0, 0}},
      {"Ohm", {1, 2, -3, -2, 0, 0, 0, 0}}, {"H", {1, 2, -2, -2, 0, 0, 0, 0}},
      {"Hz", {0, 0, -1, 0, 0, 0, 0, 0}},   {"Pa", {1, -1, -2, 0, 0, 0, 0, 0}},
      {"C", {0, 0, 1, 1, 0, 0, 0, 0}},     {"F", {-1, -2, 4, 2, 0, 0, 0, 0}},
      {"T", {1, 0, -2, -1, 0, 0, 0, 0}},   {"Wb", {1, 2, -2, -1, 0, 0, 0, 0}},
      {"S", {-1, -2, 3, 2, 0, 0, 0, 0}},
  };
  for (const auto& entry : kSymbols) {
    if (s == entry.symbol) return entry.e;
  }
  return std::nullopt;
}

// "N.m", "kg.m2", "m.s-1": a product of symbols with integer exponents.
std::optional<Exponents> ProductExponents(std::string_view text) {
  Exponents total{};
  if (text == "1") return total;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t dot = std::min(text.find('.', pos), text.size());
    const std::string_view factor = text.substr(pos, dot - pos);
    std::size_t k = 0;
    while (k < factor.size() && std::isalpha(static_cast<unsigned char>(factor[k]))) ++k;
    const auto symbol = SymbolExponents(factor.substr(0, k));
    if (!symbol) return std::nullopt;
    int power = 1;
    if (k < factor.size()) {
      const char* first = factor.data() + k;
      const char* last = factor.data() + factor.size();
      const auto [end, ec] = std::from_chars(first, last, power);
      if (ec != std::errc() || end != last) return std::nullopt;
    }
    for (int i = 0; i < 8; ++i) total[static_cast<std::size_t>(i)] += power * (*symbol)[static_cast<std::size_t>(i)];
    if (dot == text.size()) break;
    pos = dot + 1;
  }
  return total;
}

// A Modelica / FMI unit expression "numerator[/denominator]".
std::optional<Exponents> ExpressionExponents(std::string_view text) {
  if (text.empty()) return std::nullopt;
  const std::size_t slash = text.find('/');
  if (slash == std::string_view::npos) return ProductExponents(text);
  auto num = ProductExponents(text.substr(0, slash));
  std::string_view den_text = text.substr(slash + 1);
  if (den_text.size() > 2 && den_text.front() == '(' && den_text.back() == ')')
    den_text = den_text.substr(1, den_text.size() - 2);
  const auto den = ProductExponents(den_text);
  if (!num || !den) return std::nullopt;
  for (std::size_t i = 0; i < 8; ++i) (*num)[i] -= (*den)[i];
  return num;
}

// linesim's unit spellings (the units' VariableTables), in order of
// preference for base units that several share.
const std::vector<std::string>& LinesimSpellings() {
  static const std::vector<std::string> kSpellings = {
      "1",     "m",      "m/s",    "m/s2",   "rad",       "rad/s",   "rad/s2", "s",
      "1/s",   "Hz",     "V",      "A",      "Ohm",       "H",       "N",      "N.m",
      "kg",    "kg.m2",  "N/m",    "N.s/m",  "N.m.s/rad", "V.s/rad", "V/rad",  "V.s2/rad",
      "N.m/A", "W",      "J",      "Pa",     "K"};
  return kSpellings;
}

// The byte offsets at which the lines of `text` start, to turn an offset
// into a line in O(log lines): counting the newlines before each variable
// made reading a model description quadratic (40k variables: 30 s).
class LineIndex {
 public:
  explicit LineIndex(const std::string& text) {
    starts_.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i) {
      if (text[i] == '\n') starts_.push_back(i + 1);
    }
  }
  int LineOf(std::ptrdiff_t offset) const {
    if (offset < 0) return 0;
    const auto after = std::upper_bound(starts_.begin(), starts_.end(),
                                        static_cast<std::size_t>(offset));
    return static_cast<int>(after - starts_.begin());
  }

 private:
  std::vector<std::size_t> starts_;
};

class Parser {
 public:
  Parser(const std::string& text, std::string file)
      : text_(text), file_(std::move(file)), lines_(text) {}

  ModelDescription Parse() {
    const pugi::xml_parse_result result = doc_.load_buffer(text_.data(), text_.size());
    if (!result) {
      throw FmuError(file_ + ":" + std::to_string(lines_.LineOf(result.offset)) +
                     ": invalid XML: " + result.description());
    }
    const pugi::xml_node root = doc_.child("fmiModelDescription");
    if (!root) Fail(doc_.first_child(), "the root element is not <fmiModelDescription>");
    ModelDescription md;
    md.fmi_version = root.attribute("fmiVersion").as_string();
    // The schemas fix the attribute's value: fixed="2.0" (fmi2ModelDescription.xsd)
    // and fixed="3.0" (fmi3ModelDescription.xsd); anything else ("2.0abc",
    // "2.1", " 3.0") is not an FMU of a version linesim implements.
    if (md.fmi_version == "2.0") {
      md.fmi_major = 2;
    } else if (md.fmi_version == "3.0") {
      md.fmi_major = 3;
    } else {
      Fail(root, "unsupported FMI version '" + md.fmi_version +
                     "': fmiVersion must be exactly \"2.0\" or \"3.0\" (the values the FMI "
                     "2.0 and 3.0 schemas fix); linesim imports FMI 2.0 and FMI 3.0 "
                     "co-simulation FMUs");
    }
    md.model_name = root.attribute("modelName").as_string();
    md.token = root.attribute(md.fmi_major == 2 ? "guid" : "instantiationToken").as_string();
    md.description = root.attribute("description").as_string();
    md.generation_tool = root.attribute("generationTool").as_string();
    md.generation_date = root.attribute("generationDateAndTime").as_string();

    const pugi::xml_node cs = root.child("CoSimulation");
    md.has_co_simulation = bool(cs);
    md.has_model_exchange = bool(root.child("ModelExchange"));
    md.has_scheduled_execution = bool(root.child("ScheduledExecution"));
    if (!cs) {
      std::string what = md.has_model_exchange ? "model exchange only"
                         : md.has_scheduled_execution ? "scheduled execution only"
                                                      : "no interface";
      Fail(root, "the FMU is " + what +
                     " (no <CoSimulation> element): linesim imports co-simulation FMUs");
    }
    md.model_identifier = cs.attribute("modelIdentifier").as_string();
    if (md.model_identifier.empty()) Fail(cs, "<CoSimulation> has no modelIdentifier");
    md.can_get_and_set_state = cs.attribute("canGetAndSetFMUstate").as_bool() ||
                               cs.attribute("canGetAndSetFMUState").as_bool();
    md.can_serialize_state = cs.attribute("canSerializeFMUstate").as_bool() ||
                             cs.attribute("canSerializeFMUState").as_bool();
    md.can_handle_variable_step = cs.attribute("canHandleVariableCommunicationStepSize").as_bool();
    md.can_interpolate_inputs = cs.attribute("canInterpolateInputs").as_bool();
    md.can_return_early = cs.attribute("mightReturnEarlyFromDoStep").as_bool();
    md.needs_execution_tool = cs.attribute("needsExecutionTool").as_bool();
    md.only_once_per_process = cs.attribute("canBeInstantiatedOnlyOncePerProcess").as_bool();
    if (const auto a = cs.attribute("fixedInternalStepSize")) md.fixed_internal_step = Real(cs, a);
    // FMI 3.0 event mode (hasEventMode) is offered, not required: linesim
    // instantiates with eventModeUsed = false.

    if (const pugi::xml_node de = root.child("DefaultExperiment")) {
      if (const auto a = de.attribute("startTime")) md.default_start = Real(de, a);
      if (const auto a = de.attribute("stopTime")) md.default_stop = Real(de, a);
      if (const auto a = de.attribute("tolerance")) md.default_tolerance = Real(de, a);
      if (const auto a = de.attribute("stepSize")) md.default_step = Real(de, a);
    }
    ReadUnits(root, md);
    ReadTypes(root, md.fmi_major);
    if (md.fmi_major == 2) {
      ReadVariables2(root, md);
      ReadStructure2(root, md);
    } else {
      ReadVariables3(root, md);
      ReadStructure3(root, md);
    }
    for (auto& v : md.variables) {
      v.unit = v.type == FmiType::kFloat64 ? LinesimUnit(v.fmi_unit, md.units) : "";
    }
    return md;
  }

 private:
  [[noreturn]] void Fail(const pugi::xml_node& at, const std::string& message) const {
    throw FmuError(file_ + ":" + std::to_string(lines_.LineOf(at ? at.offset_debug() : 0)) +
                   ": " + message);
  }
  double Real(const pugi::xml_node& at, const pugi::xml_attribute& a) const {
    const std::string s = a.as_string();
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size()) {
      Fail(at, std::string("attribute ") + a.name() + "=\"" + s + "\" is not a number");
    }
    return v;
  }
  std::uint32_t Unsigned(const pugi::xml_node& at, const char* name) const {
    const auto a = at.attribute(name);
    if (!a) Fail(at, std::string("missing attribute ") + name);
    const std::string s = a.as_string();
    std::uint32_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size()) {
      Fail(at, std::string("attribute ") + name + "=\"" + s + "\" is not an unsigned integer");
    }
    return v;
  }
  std::vector<std::uint32_t> UnsignedList(const pugi::xml_node& at, const char* name) const {
    std::vector<std::uint32_t> out;
    std::istringstream in(at.attribute(name).as_string());
    std::string word;
    while (in >> word) {
      std::uint32_t v = 0;
      const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
      if (ec != std::errc() || end != word.data() + word.size()) {
        Fail(at, std::string("attribute ") + name + " has '" + word + "', not an unsigned integer");
      }
      out.push_back(v);
    }
    return out;
  }

  void ReadUnits(const pugi::xml_node& root, ModelDescription& md) {
    for (const auto& u : root.child("UnitDefinitions").children("Unit")) {
      FmiUnit unit;
      unit.name = u.attribute("name").as_string();
      if (const auto b = u.child("BaseUnit")) {
        unit.has_base_unit = true;
        static const char* kNames[8] = {"kg", "m", "s", "A", "K", "mol", "cd", "rad"};
        for (int i = 0; i < 8; ++i) unit.exponents[i] = b.attribute(kNames[i]).as_int(0);
        if (const auto a = b.attribute("factor")) unit.factor = Real(b, a);
        if (const auto a = b.attribute("offset")) unit.offset = Real(b, a);
      }
      md.units[unit.name] = unit;
    }
  }

  // Declared types: name -> unit (and, FMI 3.0, the type element's name).
  void ReadTypes(const pugi::xml_node& root, int major) {
    for (const auto& t : root.child("TypeDefinitions").children()) {
      if (major == 2) {
        // <SimpleType name="..."><Real unit="..."/></SimpleType>
        const pugi::xml_node real = t.child("Real");
        type_units_[t.attribute("name").as_string()] = real ? real.attribute("unit").as_string() : "";
      } else {
        // <Float64Type name="..." unit="..."/>
        type_units_[t.attribute("name").as_string()] = t.attribute("unit").as_string();
      }
    }
  }

  std::string UnitOf(const pugi::xml_node& element) const {
    if (const auto a = element.attribute("unit")) return a.as_string();
    if (const auto d = element.attribute("declaredType")) {
      if (const auto it = type_units_.find(d.as_string()); it != type_units_.end()) return it->second;
      Fail(element, std::string("declaredType '") + d.as_string() +
                        "' is not in <TypeDefinitions>");
    }
    return "";
  }

  void ReadStart(FmiVariable& v, const pugi::xml_node& at, const char* text) {
    v.has_start = true;
    std::istringstream in(text);
    std::string word;
    std::vector<std::string> words;
    while (in >> word) words.push_back(word);
    const auto bad = [&](const std::string& w) {
      Fail(at, "variable '" + v.name + "': start value '" + w + "' is not a " + ToString(v.type));
    };
    switch (v.type) {
      case FmiType::kFloat64:
        for (const auto& w : words) {
          double x = 0;
          if (w == "INF" || w == "inf") {
            x = HUGE_VAL;
          } else if (w == "-INF" || w == "-inf") {
            x = -HUGE_VAL;
          } else if (w == "NaN" || w == "nan") {
            x = std::nan("");
          } else {
            const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), x);
            if (ec != std::errc() || end != w.data() + w.size()) bad(w);
          }
          v.start_reals.push_back(x);
        }
        if (v.start_reals.size() == 1 && v.size > 1) v.start_reals.assign(v.size, v.start_reals[0]);
        if (v.start_reals.size() != v.size) {
          Fail(at, "variable '" + v.name + "' has " + std::to_string(v.start_reals.size()) +
                       " start values for " + std::to_string(v.size) + " elements");
        }
        break;
      case FmiType::kInt32: {
        if (words.size() != 1) bad(text);
        std::int64_t x = 0;
        const auto [end, ec] = std::from_chars(words[0].data(), words[0].data() + words[0].size(), x);
        if (ec != std::errc() || end != words[0].data() + words[0].size() || x < INT32_MIN ||
            x > INT32_MAX)
          bad(words[0]);
        v.start_integer = x;
        break;
      }
      case FmiType::kBoolean:
        if (words.size() != 1) bad(text);
        if (words[0] == "true" || words[0] == "1") {
          v.start_boolean = true;
        } else if (words[0] == "false" || words[0] == "0") {
          v.start_boolean = false;
        } else {
          bad(words[0]);
        }
        break;
      case FmiType::kString:
        v.start_string = text;
        break;
    }
  }

  void CommonAttributes(FmiVariable& v, const pugi::xml_node& e) {
    v.name = e.attribute("name").as_string();
    if (v.name.empty()) Fail(e, "a variable has no name");
    v.value_reference = Unsigned(e, "valueReference");
    if (const auto a = e.attribute("causality")) v.causality = a.as_string();
    if (const auto a = e.attribute("variability")) v.variability = a.as_string();
    v.description = e.attribute("description").as_string();
    v.line = lines_.LineOf(e.offset_debug());
    static const std::set<std::string> kCausalities = {
        "parameter", "calculatedParameter", "structuralParameter", "input",
        "output",    "local",               "independent"};
    if (!kCausalities.count(v.causality)) {
      Fail(e, "variable '" + v.name + "' has an unknown causality '" + v.causality + "'");
    }
  }

  // At most kMaxVariables variables (every element of ModelVariables, also
  // those linesim leaves out), counted before any is read.
  void CheckVariableCount(const pugi::xml_node& root) const {
    const pugi::xml_node list = root.child("ModelVariables");
    std::size_t n = 0;
    for (pugi::xml_node e = list.first_child(); e; e = e.next_sibling()) {
      if (e.type() == pugi::node_element && ++n > kMaxVariables) {
        Fail(e, "more than " + std::to_string(kMaxVariables) +
                    " variables in <ModelVariables>: linesim reads at most " +
                    std::to_string(kMaxVariables) + " (kMaxVariables)");
      }
    }
  }

  void ReadVariables2(const pugi::xml_node& root, ModelDescription& md) {
    CheckVariableCount(root);
    for (const auto& sv : root.child("ModelVariables").children("ScalarVariable")) {
      FmiVariable v;
      v.variability = "continuous";
      CommonAttributes(v, sv);
      const pugi::xml_node t = sv.first_child();
      const std::string tag = t.name();
      if (tag == "Real") {
        v.type = FmiType::kFloat64;
        v.fmi_unit = UnitOf(t);
      } else if (tag == "Integer") {
        v.type = FmiType::kInt32;
      } else if (tag == "Boolean") {
        v.type = FmiType::kBoolean;
      } else if (tag == "String") {
        v.type = FmiType::kString;
      } else {
        Unsupported(v, sv, tag.empty() ? "no type" : "type " + tag);
        index2_.push_back(-1);
        continue;
      }
      if (const auto s = t.attribute("start")) ReadStart(v, t, s.as_string());
      index2_.push_back(static_cast<long>(md.variables.size()));
      md.variables.push_back(std::move(v));
    }
  }

  void ReadVariables3(const pugi::xml_node& root, ModelDescription& md) {
    CheckVariableCount(root);
    for (const auto& e : root.child("ModelVariables").children()) {
      if (e.type() != pugi::node_element) continue;
      const std::string tag = e.name();
      FmiVariable v;
      v.variability = tag == "Float64" || tag == "Float32" ? "continuous" : "discrete";
      CommonAttributes(v, e);
      if (tag == "Clock") {
        Fail(e, "variable '" + v.name + "' is a clock: FMI 3.0 clocks are not supported");
      }
      if (tag == "Float64") {
        v.type = FmiType::kFloat64;
        v.fmi_unit = UnitOf(e);
      } else if (tag == "Int32") {
        v.type = FmiType::kInt32;
      } else if (tag == "Boolean") {
        v.type = FmiType::kBoolean;
      } else if (tag == "String") {
        v.type = FmiType::kString;
      } else {
        Unsupported(v, e, "type " + tag);
        continue;
      }
      for (const auto& d : e.children("Dimension")) {
        if (v.type != FmiType::kFloat64) {
          Fail(d, "variable '" + v.name + "' is an array of " + tag +
                      ": linesim maps arrays of Float64 only");
        }
        if (d.attribute("valueReference")) {
          Fail(d, "variable '" + v.name +
                      "' has a dimension set by a structural parameter: linesim maps arrays of "
                      "fixed dimensions only");
        }
        v.dimensions.push_back(Unsigned(d, "start"));
      }
      v.size = 1;
      for (std::size_t n : v.dimensions) v.size *= n;
      if (!v.dimensions.empty() && v.size == 0) Fail(e, "variable '" + v.name + "' has no elements");
      if (v.type == FmiType::kString) {
        const auto s = e.child("Start");
        if (s) ReadStart(v, s, s.attribute("value").as_string());
      } else if (const auto s = e.attribute("start")) {
        ReadStart(v, e, s.as_string());
      }
      md.variables.push_back(std::move(v));
    }
  }

  // A variable of a type linesim does not map: refused where it would be
  // exchanged (parameters, inputs, outputs), left out where it stays
  // inside the FMU (locals, calculated parameters, the independent time).
  void Unsupported(const FmiVariable& v, const pugi::xml_node& e, const std::string& what) {
    if (v.causality == "input" || v.causality == "output" || v.causality == "parameter" ||
        v.causality == "structuralParameter") {
      Fail(e, "variable '" + v.name + "' (" + v.causality + ") has " + what +
                  ": linesim maps Real/Float64, Integer/Int32, Boolean and String (and arrays of "
                  "Float64)");
    }
  }

  void ReadStructure2(const pugi::xml_node& root, ModelDescription& md) {
    for (const auto& u : root.child("ModelStructure").child("Outputs").children("Unknown")) {
      const std::uint32_t index = Unsigned(u, "index");
      if (index == 0 || index > index2_.size() || index2_[index - 1] < 0) {
        Fail(u, "output index " + std::to_string(index) + " names no mapped variable");
      }
      FmiVariable& out = md.variables[static_cast<std::size_t>(index2_[index - 1])];
      if (!u.attribute("dependencies")) continue;  // unknown: every input
      std::vector<std::uint32_t> refs;
      for (std::uint32_t d : UnsignedList(u, "dependencies")) {
        if (d == 0 || d > index2_.size()) {
          Fail(u, "dependency index " + std::to_string(d) + " names no variable");
        }
        if (index2_[d - 1] < 0) continue;
        const auto dep = static_cast<std::size_t>(index2_[d - 1]);
        if (md.variables[dep].causality == "input") refs.push_back(static_cast<std::uint32_t>(dep));
      }
      out.dependencies = refs;
    }
  }

  void ReadStructure3(const pugi::xml_node& root, ModelDescription& md) {
    // Value reference -> the first mapped variable with it, built once (a
    // search per output and per dependency was quadratic).
    std::unordered_map<std::uint32_t, std::size_t> by_vr;
    by_vr.reserve(md.variables.size());
    for (std::size_t i = 0; i < md.variables.size(); ++i) {
      by_vr.emplace(md.variables[i].value_reference, i);
    }
    for (const auto& o : root.child("ModelStructure").children("Output")) {
      const std::uint32_t vr = Unsigned(o, "valueReference");
      const auto it = by_vr.find(vr);
      if (it == by_vr.end()) {
        Fail(o, "output valueReference " + std::to_string(vr) + " names no mapped variable");
      }
      if (!o.attribute("dependencies")) continue;
      std::vector<std::uint32_t> refs;
      for (std::uint32_t d : UnsignedList(o, "dependencies")) {
        const auto dep = by_vr.find(d);
        if (dep != by_vr.end() && md.variables[dep->second].causality == "input") {
          refs.push_back(static_cast<std::uint32_t>(dep->second));
        }
      }
      md.variables[it->second].dependencies = refs;
    }
  }

  const std::string& text_;
  std::string file_;
  LineIndex lines_;
  pugi::xml_document doc_;
  std::map<std::string, std::string> type_units_;
  std::vector<long> index2_;  // FMI 2.0: ScalarVariable index -> mapped variable, -1 if left out
};

}  // namespace

const char* ToString(FmiType type) {
  switch (type) {
    case FmiType::kFloat64: return "Float64";
    case FmiType::kInt32: return "Int32";
    case FmiType::kBoolean: return "Boolean";
    case FmiType::kString: return "String";
  }
  return "?";
}

std::string LinesimUnit(const std::string& fmi_unit, const std::map<std::string, FmiUnit>& units) {
  if (fmi_unit.empty()) return "1";
  std::optional<Exponents> exps;
  if (const auto it = units.find(fmi_unit); it != units.end() && it->second.has_base_unit) {
    const FmiUnit& u = it->second;
    if (u.factor != 1.0 || u.offset != 0.0) return fmi_unit;  // not SI: no conversion
    exps.emplace();
    for (std::size_t i = 0; i < 8; ++i) (*exps)[i] = u.exponents[i];
  } else {
    exps = ExpressionExponents(fmi_unit);
  }
  if (!exps) return fmi_unit;
  const auto& spellings = LinesimSpellings();
  // The FMU's own spelling when it is one of linesim's and means the same.
  if (std::find(spellings.begin(), spellings.end(), fmi_unit) != spellings.end() &&
      ExpressionExponents(fmi_unit) == exps) {
    return fmi_unit;
  }
  for (const auto& s : spellings) {
    if (ExpressionExponents(s) == exps) return s;
  }
  return fmi_unit;
}

std::optional<std::array<int, 8>> SiExponents(const std::string& unit) {
  return ExpressionExponents(unit);
}

ModelDescription ParseModelDescriptionText(const std::string& text, const std::string& file) {
  return Parser(text, file).Parse();
}

ModelDescription ParseModelDescription(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw FmuError(file + ": cannot read the model description");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return ParseModelDescriptionText(buffer.str(), file);
}

}  // namespace linesim::fmu
