#include "units/fmu/model_description.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <pugixml.hpp>
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
    for (int i = 0; i < 8; ++i)
      total[static_cast<std::size_t>(i)] += power * (*symbol)[static_cast<std::size_t>(i)];
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
      "1",     "m",     "m/s", "m/s2",  "rad",       "rad/s",   "rad/s2", "s",
      "1/s",   "Hz",    "V",   "A",     "Ohm",       "H",       "N",      "N.m",
      "kg",    "kg.m2", "N/m", "N.s/m", "N.m.s/rad", "V.s/rad", "V/rad",  "V.s2/rad",
      "N.m/A", "W",     "J",   "Pa",    "K"};
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
    const auto after =
        std::upper_bound(starts_.begin(), starts_.end(), static_cast<std::size_t>(offset));
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
      std::string what = md.has_model_exchange        ? "model exchange only"
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
      CheckRules(root, md);
      ReadStructure2(root, md);
    } else {
      ReadVariables3(root, md);
      ResolveDimensions(md);
      CheckRules(root, md);
      ReadStructure3(root, md);
    }
    for (auto& v : md.variables) {
      v.unit = StorageOf(v.type) == 0 ? LinesimUnit(v.fmi_unit, md.units) : "";
    }
    return md;
  }

 private:
  [[noreturn]] void Fail(const pugi::xml_node& at, const std::string& message) const {
    throw FmuError(file_ + ":" + std::to_string(lines_.LineOf(at ? at.offset_debug() : 0)) + ": " +
                   message);
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

  // A declared type: its element ("Real", "Enumeration", "Float64Type",
  // "EnumerationType", ...), unit, bounds, nominal and items.
  struct DeclaredType {
    std::string element;
    std::string unit;
    std::optional<double> min, max, nominal;
    std::vector<std::pair<std::int64_t, std::string>> items;
  };

  std::optional<double> OptionalNumber(const pugi::xml_node& at, const char* name) const {
    if (const auto a = at.attribute(name)) return Real(at, a);
    return std::nullopt;
  }

  void ReadTypes(const pugi::xml_node& root, int major) {
    for (const auto& t : root.child("TypeDefinitions").children()) {
      if (t.type() != pugi::node_element) continue;
      DeclaredType d;
      // FMI 2.0: <SimpleType name="..."><Real unit="..."/></SimpleType>;
      // FMI 3.0: <Float64Type name="..." unit="..."/>.
      const pugi::xml_node body = major == 2 ? t.first_child() : t;
      d.element = body.name();
      d.unit = body.attribute("unit").as_string();
      d.min = OptionalNumber(body, "min");
      d.max = OptionalNumber(body, "max");
      d.nominal = OptionalNumber(body, "nominal");
      if (d.element == "Enumeration" || d.element == "EnumerationType") {
        std::set<std::int64_t> values;
        for (const auto& item : body.children("Item")) {
          const std::string text = item.attribute("value").as_string();
          std::int64_t value = 0;
          const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
          if (ec != std::errc() || end != text.data() + text.size()) {
            Fail(item, "enumeration '" + std::string(t.attribute("name").as_string()) +
                           "': item value '" + text + "' is not an integer");
          }
          if (!values.insert(value).second) {
            Fail(item, "enumeration '" + std::string(t.attribute("name").as_string()) +
                           "': two items have the value " + text + " (item values must be unique)");
          }
          d.items.emplace_back(value, item.attribute("name").as_string());
        }
        if (d.items.empty()) {
          Fail(body, "enumeration '" + std::string(t.attribute("name").as_string()) +
                         "' has no <Item> (an enumeration needs at least one)");
        }
        std::sort(d.items.begin(), d.items.end());
      }
      types_[t.attribute("name").as_string()] = std::move(d);
    }
  }

  // The declared type of `element`, checked to exist and to be of the
  // variable's kind (`kinds`: the type elements that fit, "" for none
  // declared); nullptr when none is declared.
  const DeclaredType* DeclaredTypeOf(const pugi::xml_node& element, const FmiVariable& v,
                                     std::initializer_list<const char*> kinds) const {
    const auto d = element.attribute("declaredType");
    if (!d) return nullptr;
    const auto it = types_.find(d.as_string());
    if (it == types_.end()) {
      Fail(element,
           std::string("declaredType '") + d.as_string() + "' is not in <TypeDefinitions>");
    }
    for (const char* k : kinds) {
      if (it->second.element == k) return &it->second;
    }
    Fail(element, "variable '" + v.name + "': declaredType '" + d.as_string() + "' is a " +
                      it->second.element + ", not a type for this variable (" + *kinds.begin() +
                      ")");
  }

  // Unit, bounds, nominal and items from the variable's element, else its
  // declared type.
  void Attributes(FmiVariable& v, const pugi::xml_node& element, const DeclaredType* d) {
    v.declared_type = element.attribute("declaredType").as_string();
    if (d) {
      v.fmi_unit = d->unit;
      v.min = d->min;
      v.max = d->max;
      v.nominal = d->nominal;
      v.items = d->items;
    }
    if (const auto a = element.attribute("unit")) v.fmi_unit = a.as_string();
    if (auto x = OptionalNumber(element, "min")) v.min = x;
    if (auto x = OptionalNumber(element, "max")) v.max = x;
    if (auto x = OptionalNumber(element, "nominal")) v.nominal = x;
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
      case FmiType::kFloat32:
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
          if (v.type == FmiType::kFloat32 && std::isfinite(x) && std::fabs(x) > FLT_MAX) {
            Fail(at,
                 "variable '" + v.name + "': start value '" + w + "' is outside the Float32 range");
          }
          v.start_reals.push_back(x);
        }
        if (v.start_reals.size() == 1 && v.size > 1) v.start_reals.assign(v.size, v.start_reals[0]);
        if (v.start_reals.size() != v.size && !v.size_from_structural) {
          Fail(at, "variable '" + v.name + "' has " + std::to_string(v.start_reals.size()) +
                       " start values for " + std::to_string(v.size) + " elements");
        }
        break;
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
      default: {  // the integer types
        if (words.size() != 1) bad(text);
        const std::string& w = words[0];
        const auto [lo, hi] = IntegerRange(v.type);
        std::int64_t x = 0;
        if (v.type == FmiType::kUInt64) {
          std::uint64_t u = 0;
          const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), u);
          if (ec != std::errc() || end != w.data() + w.size()) bad(w);
          if (u > static_cast<std::uint64_t>(hi)) {
            Fail(at, "variable '" + v.name + "': UInt64 start value " + w +
                         " is above linesim's Integer range (at most 2^63 - 1)");
          }
          x = static_cast<std::int64_t>(u);
        } else {
          const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), x);
          if (ec != std::errc() || end != w.data() + w.size() || x < lo || x > hi) bad(w);
        }
        v.start_integer = x;
        break;
      }
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
        "parameter", "calculatedParameter", "structuralParameter", "input", "output",
        "local",     "independent"};
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
        Attributes(v, t, DeclaredTypeOf(t, v, {"Real"}));
      } else if (tag == "Integer") {
        v.type = FmiType::kInt32;
        Attributes(v, t, DeclaredTypeOf(t, v, {"Integer"}));
      } else if (tag == "Enumeration") {
        // fmi2Get/SetInteger carry it; its values are the items'.
        v.type = FmiType::kInt32;
        const DeclaredType* d = DeclaredTypeOf(t, v, {"Enumeration"});
        if (!d) Fail(t, "Enumeration variable '" + v.name + "' has no declaredType (required)");
        Attributes(v, t, d);
        v.fmi_unit.clear();
      } else if (tag == "Boolean") {
        v.type = FmiType::kBoolean;
        DeclaredTypeOf(t, v, {"Boolean"});
      } else if (tag == "String") {
        v.type = FmiType::kString;
        DeclaredTypeOf(t, v, {"String"});
      } else {
        Fail(sv, "variable '" + v.name + "' has " + (tag.empty() ? "no type" : "type " + tag) +
                     ": FMI 2.0 knows Real, Integer, Enumeration, Boolean and String");
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
      static const std::map<std::string, FmiType> kTypes = {
          {"Float64", FmiType::kFloat64},  {"Float32", FmiType::kFloat32},
          {"Int8", FmiType::kInt8},        {"UInt8", FmiType::kUInt8},
          {"Int16", FmiType::kInt16},      {"UInt16", FmiType::kUInt16},
          {"Int32", FmiType::kInt32},      {"UInt32", FmiType::kUInt32},
          {"Int64", FmiType::kInt64},      {"UInt64", FmiType::kUInt64},
          {"Boolean", FmiType::kBoolean},  {"String", FmiType::kString},
          {"Enumeration", FmiType::kInt64}};
      if (tag == "Binary") {
        // Left out: the FMU keeps its start value; nothing to connect.
        md.left_out.push_back(v.name + " (Binary)");
        binary_vrs_.insert(v.value_reference);
        continue;
      }
      const auto known = kTypes.find(tag);
      if (known == kTypes.end()) {
        Fail(e, "variable '" + v.name + "' has type " + tag + ": not an FMI 3.0 variable type");
      }
      v.type = known->second;
      const std::string type_element = tag + "Type";
      const DeclaredType* d = DeclaredTypeOf(e, v, {type_element.c_str()});
      if (tag == "Enumeration" && !d) {
        Fail(e, "Enumeration variable '" + v.name + "' has no declaredType (required)");
      }
      Attributes(v, e, d);
      if (v.type != FmiType::kFloat64 && v.type != FmiType::kFloat32) v.fmi_unit.clear();
      for (const auto& dim : e.children("Dimension")) {
        if (v.type != FmiType::kFloat64) {
          Fail(dim, "variable '" + v.name + "' is an array of " + tag +
                        ": linesim maps arrays of Float64 only");
        }
        if (const auto a = dim.attribute("valueReference")) {
          // Sized by a structural parameter: its start value, resolved
          // once every variable is read.
          pending_dimensions_.push_back(
              {md.variables.size(), v.dimensions.size(), Unsigned(dim, "valueReference"), dim});
          v.size_from_structural = true;
          v.dimensions.push_back(0);
          continue;
        }
        v.dimensions.push_back(Unsigned(dim, "start"));
      }
      v.size = 1;
      for (std::size_t n : v.dimensions) v.size *= n;
      if (!v.dimensions.empty() && v.size == 0 && !v.size_from_structural) {
        Fail(e, "variable '" + v.name + "' has no elements");
      }
      if (v.type == FmiType::kString) {
        const auto s = e.child("Start");
        if (s) ReadStart(v, s, s.attribute("value").as_string());
      } else if (const auto s = e.attribute("start")) {
        ReadStart(v, e, s.as_string());
      }
      md.variables.push_back(std::move(v));
    }
  }

  // Dimensions given by a structural parameter (FMI 3.0 section 2.4.7.6):
  // the parameter's start value, which linesim never changes (structural
  // parameters are constants of the unit).
  struct PendingDimension {
    std::size_t variable, dimension;
    std::uint32_t vr;
    pugi::xml_node at;
  };
  void ResolveDimensions(ModelDescription& md) {
    if (pending_dimensions_.empty()) return;
    std::unordered_map<std::uint32_t, std::size_t> by_vr;
    for (std::size_t i = 0; i < md.variables.size(); ++i)
      by_vr.emplace(md.variables[i].value_reference, i);
    for (const PendingDimension& p : pending_dimensions_) {
      FmiVariable& v = md.variables[p.variable];
      const auto it = by_vr.find(p.vr);
      if (it == by_vr.end()) {
        Fail(p.at, "variable '" + v.name + "': the dimension's valueReference " +
                       std::to_string(p.vr) + " names no variable");
      }
      const FmiVariable& n = md.variables[it->second];
      if ((n.causality != "structuralParameter" && n.variability != "constant") ||
          StorageOf(n.type) != 1 || !n.has_start || n.start_integer < 1) {
        Fail(p.at, "variable '" + v.name + "': the dimension's valueReference " +
                       std::to_string(p.vr) + " names '" + n.name +
                       "', not a structural parameter or constant of an integer type with a "
                       "start value of at least 1 (FMI 3.0 section 2.4.7.6)");
      }
      v.dimensions[p.dimension] = static_cast<std::size_t>(n.start_integer);
    }
    for (const PendingDimension& p : pending_dimensions_) {
      FmiVariable& v = md.variables[p.variable];
      std::size_t size = 1;
      for (std::size_t d : v.dimensions) {
        if (d > kMaxVariables || size * d > kMaxVariables) {
          Fail(p.at, "variable '" + v.name + "' would have more than " +
                         std::to_string(kMaxVariables) + " elements");
        }
        size *= d;
      }
      v.size = size;
      if (v.has_start && v.start_reals.size() == 1 && size > 1)
        v.start_reals.assign(size, v.start_reals[0]);
      if (v.has_start && v.start_reals.size() != size) {
        Fail(p.at, "variable '" + v.name + "' has " + std::to_string(v.start_reals.size()) +
                       " start values for " + std::to_string(size) + " elements");
      }
    }
  }

  // Rules of the standards that the schemas cannot express; each refusal
  // names its rule.
  void CheckRules(const pugi::xml_node& root, const ModelDescription& md) {
    const auto at = [&](const FmiVariable& v) -> std::string {
      return file_ + ":" + std::to_string(v.line) + ": variable '" + v.name + "': ";
    };
    const auto settable = [](const FmiVariable& v) {
      return v.causality == "parameter" || v.causality == "input" ||
             v.causality == "structuralParameter";
    };
    if (md.fmi_major == 3) {
      // FMI 3.0 section 2.4.7: a valueReference is unique among the FMU's
      // variables (aliases are <Alias> elements of one variable).
      std::unordered_map<std::uint32_t, std::size_t> seen;
      for (std::size_t i = 0; i < md.variables.size(); ++i) {
        const FmiVariable& v = md.variables[i];
        const auto [it, fresh] = seen.emplace(v.value_reference, i);
        if (!fresh) {
          throw FmuError(at(v) + "valueReference " + std::to_string(v.value_reference) +
                         " is also variable '" + md.variables[it->second].name +
                         "''s (FMI 3.0: every variable has a valueReference of its own)");
        }
      }
    } else {
      // FMI 2.0.4 section 2.2.7: variables with one valueReference and one
      // base type are aliases of one value. A value set from outside can
      // come from one variable only (two parameters, two inputs, or a
      // parameter and an input on one reference), and an input cannot be
      // an alias of an output or another computed variable (its value
      // would be both set and computed).
      std::map<std::pair<int, std::uint32_t>, std::size_t> first_set, first_computed;
      for (std::size_t i = 0; i < md.variables.size(); ++i) {
        const FmiVariable& v = md.variables[i];
        const std::pair<int, std::uint32_t> key{StorageOf(v.type), v.value_reference};
        if (settable(v)) {
          const auto [it, fresh] = first_set.emplace(key, i);
          if (!fresh) {
            throw FmuError(at(v) + "valueReference " + std::to_string(v.value_reference) +
                           " is also " + md.variables[it->second].causality + " '" +
                           md.variables[it->second].name + "': two " +
                           "variables set from outside " +
                           "share a value (FMI 2.0 aliases: at most one parameter or input per "
                           "alias set)");
          }
        } else if (v.causality == "output" || v.causality == "local" ||
                   v.causality == "calculatedParameter") {
          first_computed.emplace(key, i);
        }
      }
      for (const auto& [key, i] : first_set) {
        const FmiVariable& v = md.variables[i];
        const auto c = first_computed.find(key);
        if (v.causality == "input" && c != first_computed.end()) {
          const FmiVariable& o = md.variables[c->second];
          throw FmuError(at(v) + "the input's valueReference " + std::to_string(v.value_reference) +
                         " is also " + o.causality + " '" + o.name +
                         "': an input cannot alias a computed variable (FMI 2.0 aliases)");
        }
      }
    }
    // A unit names a <Unit> of <UnitDefinitions> (FMI 2.0.4 section 2.2.2,
    // Definition of Units, and FMI 3.0's: the unit attribute references a
    // unit defined there). An FMU without UnitDefinitions is still read, its unit
    // names understood as SI expressions (see LinesimUnit).
    const bool has_unit_definitions = static_cast<bool>(root.child("UnitDefinitions"));
    for (const FmiVariable& v : md.variables) {
      if (has_unit_definitions && !v.fmi_unit.empty() && !md.units.contains(v.fmi_unit)) {
        throw FmuError(at(v) + "unit '" + v.fmi_unit +
                       "' is not in <UnitDefinitions> (FMI: a variable's unit names a unit "
                       "defined there)");
      }
      // A value linesim gives the FMU has a start value: a parameter's
      // initial is exact, and initial exact or approx or causality input
      // needs a start (FMI 2.0.4 section 2.2.7, FMI 3.0 section 2.4.7.5).
      // Without it, linesim would have no value of the FMU's to give.
      if (settable(v) && !v.has_start) {
        throw FmuError(at(v) + v.causality +
                       " without a start value (FMI: a parameter or input must have one)");
      }
    }
    for (const FmiVariable& v : md.variables) {
      // min <= max, and a start value within them (FMI 2.0.4 section
      // 2.2.7, FMI 3.0 section 2.4.7.4: min <= start <= max).
      if (v.min && v.max && !(*v.min <= *v.max)) {
        throw FmuError(at(v) + "min " + std::to_string(*v.min) + " is above max " +
                       std::to_string(*v.max) + " (FMI: min <= max)");
      }
      if (!v.has_start) continue;
      std::vector<double> starts = v.start_reals;
      if (StorageOf(v.type) == 1) starts = {static_cast<double>(v.start_integer)};
      for (double x : starts) {
        if (std::isnan(x) && settable(v)) {
          throw FmuError(at(v) + "start value NaN: a value linesim gives the FMU (" + v.causality +
                         ") must be a number");
        }
        if ((v.min && x < *v.min) || (v.max && x > *v.max)) {
          throw FmuError(at(v) + "start value " + FormatNumber(x) + " is outside [" +
                         (v.min ? FormatNumber(*v.min) : "-inf") + ", " +
                         (v.max ? FormatNumber(*v.max) : "inf") + "] (FMI: min <= start <= max)");
        }
      }
      if (!v.items.empty() &&
          !std::binary_search(v.items.begin(), v.items.end(),
                              std::pair<std::int64_t, std::string>{v.start_integer, ""},
                              [](const auto& a, const auto& b) { return a.first < b.first; })) {
        throw FmuError(at(v) + "start value " + std::to_string(v.start_integer) +
                       " is no item of enumeration '" + v.declared_type + "'");
      }
    }
  }

  static std::string FormatNumber(double x) {
    char buf[32];
    const auto res = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, res.ptr);
  }

  void ReadStructure2(const pugi::xml_node& root, ModelDescription& md) {
    // Every index of ModelStructure names a ScalarVariable (FMI 2.0.4
    // section 2.2.8: indices count from 1 in ModelVariables).
    for (const char* list : {"Derivatives", "InitialUnknowns"}) {
      for (const auto& u : root.child("ModelStructure").child(list).children("Unknown")) {
        const std::uint32_t index = Unsigned(u, "index");
        if (index == 0 || index > index2_.size()) {
          Fail(u, std::string("ModelStructure/") + list + ": index " + std::to_string(index) +
                      " names no variable (there are " + std::to_string(index2_.size()) + ")");
        }
        for (std::uint32_t d : UnsignedList(u, "dependencies")) {
          if (d == 0 || d > index2_.size()) {
            Fail(u, std::string("ModelStructure/") + list + ": dependency index " +
                        std::to_string(d) + " names no variable");
          }
        }
      }
    }
    for (const auto& u : root.child("ModelStructure").child("Outputs").children("Unknown")) {
      const std::uint32_t index = Unsigned(u, "index");
      if (index == 0 || index > index2_.size()) {
        Fail(u, "output index " + std::to_string(index) + " names no variable (there are " +
                    std::to_string(index2_.size()) + ")");
      }
      // An output linesim leaves out is the FMU's own: it refuses nothing
      // unless a scenario connects or records it (then it is no variable).
      if (index2_[index - 1] < 0) continue;
      FmiVariable& out = md.variables[static_cast<std::size_t>(index2_[index - 1])];
      if (out.causality != "output") {
        Fail(u, "ModelStructure/Outputs: index " + std::to_string(index) + " is '" + out.name +
                    "', a " + out.causality +
                    " (FMI 2.0.4 section 2.2.8: every output, and "
                    "only outputs, are listed)");
      }
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
    for (const auto& u : root.child("ModelStructure").children()) {
      if (u.type() != pugi::node_element || std::string(u.name()) == "Output") continue;
      const std::uint32_t vr = Unsigned(u, "valueReference");
      if (!by_vr.count(vr) && !binary_vrs_.count(vr)) {
        Fail(u, std::string("ModelStructure: <") + u.name() + " valueReference=\"" +
                    std::to_string(vr) + "\"> names no variable");
      }
    }
    for (const auto& o : root.child("ModelStructure").children("Output")) {
      const std::uint32_t vr = Unsigned(o, "valueReference");
      const auto it = by_vr.find(vr);
      // A Binary output (the Reference-FMUs' Feedthrough has one) is left
      // out: the FMU is refused only where a scenario connects or records
      // it, as no variable of the unit.
      if (it == by_vr.end() && binary_vrs_.count(vr)) continue;
      if (it == by_vr.end()) {
        Fail(o, "output valueReference " + std::to_string(vr) + " names no variable");
      }
      if (md.variables[it->second].causality != "output") {
        Fail(o, "ModelStructure: <Output valueReference=\"" + std::to_string(vr) + "\"> is '" +
                    md.variables[it->second].name + "', a " + md.variables[it->second].causality +
                    " (FMI 3.0 section 2.4.8: only outputs are listed as outputs)");
      }
      if (!o.attribute("dependencies")) continue;
      std::vector<std::uint32_t> refs;
      for (std::uint32_t d : UnsignedList(o, "dependencies")) {
        const auto dep = by_vr.find(d);
        if (dep == by_vr.end() && !binary_vrs_.count(d)) {
          Fail(o, "ModelStructure: output " + std::to_string(vr) + " depends on valueReference " +
                      std::to_string(d) + ", which names no variable");
        }
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
  std::vector<long> index2_;  // FMI 2.0: ScalarVariable index -> mapped variable, -1 if left out
  std::map<std::string, DeclaredType> types_;
  std::vector<PendingDimension> pending_dimensions_;
  std::set<std::uint32_t> binary_vrs_;  // FMI 3.0 Binary variables (left out)
};

}  // namespace

const char* ToString(FmiType type) {
  switch (type) {
    case FmiType::kFloat64:
      return "Float64";
    case FmiType::kInt32:
      return "Int32";
    case FmiType::kBoolean:
      return "Boolean";
    case FmiType::kString:
      return "String";
    case FmiType::kFloat32:
      return "Float32";
    case FmiType::kInt8:
      return "Int8";
    case FmiType::kUInt8:
      return "UInt8";
    case FmiType::kInt16:
      return "Int16";
    case FmiType::kUInt16:
      return "UInt16";
    case FmiType::kUInt32:
      return "UInt32";
    case FmiType::kInt64:
      return "Int64";
    case FmiType::kUInt64:
      return "UInt64";
  }
  return "?";
}

int StorageOf(FmiType type) {
  switch (type) {
    case FmiType::kFloat64:
    case FmiType::kFloat32:
      return 0;
    case FmiType::kBoolean:
      return 2;
    case FmiType::kString:
      return 3;
    default:
      return 1;
  }
}

std::pair<std::int64_t, std::int64_t> IntegerRange(FmiType type) {
  switch (type) {
    case FmiType::kInt8:
      return {INT8_MIN, INT8_MAX};
    case FmiType::kUInt8:
      return {0, UINT8_MAX};
    case FmiType::kInt16:
      return {INT16_MIN, INT16_MAX};
    case FmiType::kUInt16:
      return {0, UINT16_MAX};
    case FmiType::kInt32:
      return {INT32_MIN, INT32_MAX};
    case FmiType::kUInt32:
      return {0, UINT32_MAX};
    case FmiType::kUInt64:
      return {0, INT64_MAX};
    default:
      return {INT64_MIN, INT64_MAX};
  }
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
  std::error_code ec;
  if (const auto size = std::filesystem::file_size(file, ec);
      !ec && size > kMaxModelDescriptionBytes) {
    throw FmuError(file + ": the model description is " + std::to_string(size) +
                   " bytes, more than the " + std::to_string(kMaxModelDescriptionBytes >> 20) +
                   " MiB linesim reads (kMaxModelDescriptionBytes)");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw FmuError(file + ": cannot read the model description");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return ParseModelDescriptionText(buffer.str(), file);
}

}  // namespace linesim::fmu
