#pragma once
// The rules of the FMI 2.0 and 3.0 model description schemas (the XSDs'
// attribute types: fmi2ScalarVariable.xsd, fmi2Type.xsd, fmi3Variable.xsd,
// fmi3Type.xsd) and of the standards' text that the XSDs cannot express
// (FMI 2.0.4 section 2.2.7, FMI 3.0.2 section 2.4.7: min <= start <= max,
// units defined in UnitDefinitions, declared types in TypeDefinitions,
// start required or forbidden by causality, the causality / variability
// combinations, every output in ModelStructure), written out here because
// no validator of the XSDs is packaged for Debian. Used on the project's
// test FMUs and on every export (tests/fmu_export/).
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <pugixml.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace linesim::fmu::test {

// The value space of an XSD type an attribute takes.
enum class Xsd {
  kDouble,
  kFloat,
  kByte,
  kUByte,
  kShort,
  kUShort,
  kInt,
  kUInt,
  kLong,
  kULong,
  kBool
};

inline std::optional<double> ParseXsd(const std::string& text, Xsd type) {
  if (text.empty()) return std::nullopt;
  if (type == Xsd::kBool) {
    if (text == "true" || text == "1") return 1.0;
    if (text == "false" || text == "0") return 0.0;
    return std::nullopt;
  }
  if (type == Xsd::kDouble || type == Xsd::kFloat) {
    // xs:double's lexical space: a decimal or scientific number, or INF,
    // -INF, NaN (never "inf" or "nan", which C writes).
    if (text == "INF") return std::numeric_limits<double>::infinity();
    if (text == "-INF") return -std::numeric_limits<double>::infinity();
    if (text == "NaN") return std::numeric_limits<double>::quiet_NaN();
    if (text.find_first_not_of("0123456789+-.eE") != std::string::npos) return std::nullopt;
    char* end = nullptr;
    const double x = std::strtod(text.c_str(), &end);
    if (*end != '\0' || !std::isfinite(x)) return std::nullopt;
    if (type == Xsd::kFloat && std::fabs(x) > FLT_MAX) return std::nullopt;
    return x;
  }
  if (text.find_first_not_of("0123456789+-") != std::string::npos) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const bool is_unsigned =
      type == Xsd::kUByte || type == Xsd::kUShort || type == Xsd::kUInt || type == Xsd::kULong;
  if (is_unsigned) {
    if (text[0] == '-' && text.find_first_not_of("-0") != std::string::npos) return std::nullopt;
    const unsigned long long u = std::strtoull(text.c_str(), &end, 10);
    if (*end != '\0' || errno == ERANGE) return std::nullopt;
    const unsigned long long max = type == Xsd::kUByte    ? UINT8_MAX
                                   : type == Xsd::kUShort ? UINT16_MAX
                                   : type == Xsd::kUInt   ? UINT32_MAX
                                                          : UINT64_MAX;
    if (u > max) return std::nullopt;
    return static_cast<double>(u);
  }
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE) return std::nullopt;
  const long long lo = type == Xsd::kByte    ? INT8_MIN
                       : type == Xsd::kShort ? INT16_MIN
                       : type == Xsd::kInt   ? INT32_MIN
                                             : INT64_MIN;
  const long long hi = type == Xsd::kByte    ? INT8_MAX
                       : type == Xsd::kShort ? INT16_MAX
                       : type == Xsd::kInt   ? INT32_MAX
                                             : INT64_MAX;
  if (v < lo || v > hi) return std::nullopt;
  return static_cast<double>(v);
}

// What the checks below share while reading one model description.
struct SchemaCheck {
  bool v3 = false;
  std::set<std::string> units, types, names;
  std::map<std::string, int> value_references;
  std::vector<std::string> outputs;  // FMI 2.0: index; FMI 3.0: value reference
  std::vector<std::string> problems;
  void Problem(const std::string& where, const std::string& what) {
    problems.push_back(where + ": " + what);
  }
};

// min, max, nominal and start of a numeric or Boolean variable: each value
// in its type's range (an array's start is a list), min <= start <= max,
// nominal > 0 and only on floats.
inline void CheckNumbers(const pugi::xml_node& type_node, Xsd xsd, bool real,
                         const std::string& where, SchemaCheck& c) {
  std::optional<double> min, max, start;
  for (const std::string attribute : {"min", "max", "nominal", "start"}) {
    const pugi::xml_attribute a = type_node.attribute(attribute.c_str());
    if (!a) continue;
    if (xsd == Xsd::kBool && attribute != "start") {
      c.Problem(where, attribute + " on a Boolean");
      continue;
    }
    if (attribute == "nominal" && !real) {
      c.Problem(where, "nominal on a non-float type");
      continue;
    }
    std::istringstream items(a.value());
    std::string item;
    int count = 0;
    while (items >> item) {
      ++count;
      const auto x = ParseXsd(item, xsd);
      if (!x) {
        c.Problem(where, attribute + "=\"" + a.value() + "\" is outside or no value of " +
                             type_node.name() + "'s type");
        continue;
      }
      if (attribute == "min") min = x;
      if (attribute == "max") max = x;
      if (attribute == "start" && count == 1) start = x;
      if (attribute == "nominal" && !(*x > 0)) c.Problem(where, "nominal must be > 0, is " + item);
    }
    if (count == 0) c.Problem(where, attribute + " is empty");
  }
  if (min && max && *min > *max) c.Problem(where, "min > max");
  if (start && min && *start < *min) c.Problem(where, "start below min");
  if (start && max && *start > *max) c.Problem(where, "start above max");
}

// Causality and variability, each a known value and allowed together
// (FMI 2.0.4 section 2.2.7, FMI 3.0.2 section 2.4.7.4).
inline void CheckCausality(const std::string& causality, const std::string& variability, bool real,
                           const std::string& where, SchemaCheck& c) {
  static const std::set<std::string> kCausalities = {
      "parameter",   "calculatedParameter", "input", "output", "local",
      "independent", "structuralParameter"};
  static const std::set<std::string> kVariabilities = {"constant", "fixed", "tunable", "discrete",
                                                       "continuous"};
  if (!kCausalities.count(causality) || (!c.v3 && causality == "structuralParameter")) {
    c.Problem(where, "causality '" + causality + "'");
  }
  if (!kVariabilities.count(variability)) c.Problem(where, "variability '" + variability + "'");
  if (variability == "continuous" && !real) c.Problem(where, "continuous, but not a float type");
  if ((causality == "parameter" || causality == "structuralParameter") && variability != "fixed" &&
      variability != "tunable") {
    c.Problem(where, "a parameter must be fixed or tunable, is " + variability);
  }
  if (causality == "independent" && variability != "continuous") {
    c.Problem(where, "the independent variable must be continuous");
  }
  if (causality == "input" &&
      (variability == "constant" || variability == "fixed" || variability == "tunable")) {
    c.Problem(where, "an input must be discrete or continuous, is " + variability);
  }
}

// One variable (FMI 2.0: a ScalarVariable with its type child; FMI 3.0: the
// type element), the `index`-th of ModelVariables.
inline void CheckVariable(const pugi::xml_node& sv, int index, SchemaCheck& c) {
  // FMI 3.0's element name, FMI 2.0's type element -> XSD type of min,
  // max, nominal, start.
  static const std::map<std::string, Xsd> kTypes3 = {
      {"Float64", Xsd::kDouble}, {"Float32", Xsd::kFloat}, {"Int8", Xsd::kByte},
      {"UInt8", Xsd::kUByte},    {"Int16", Xsd::kShort},   {"UInt16", Xsd::kUShort},
      {"Int32", Xsd::kInt},      {"UInt32", Xsd::kUInt},   {"Int64", Xsd::kLong},
      {"UInt64", Xsd::kULong},   {"Boolean", Xsd::kBool},  {"Enumeration", Xsd::kLong}};
  static const std::map<std::string, Xsd> kTypes2 = {{"Real", Xsd::kDouble},
                                                     {"Integer", Xsd::kInt},
                                                     {"Enumeration", Xsd::kInt},
                                                     {"Boolean", Xsd::kBool}};
  const pugi::xml_node type_node = c.v3 ? sv : sv.first_child();
  const std::string tag = type_node.name();
  const std::string name = sv.attribute("name").value();
  const std::string where = "variable '" + name + "' (" + tag + ")";
  if (name.empty()) c.Problem(where, "no name (required)");
  if (!c.names.insert(name).second) c.Problem(where, "name used twice");
  if (!ParseXsd(sv.attribute("valueReference").value(), Xsd::kUInt)) {
    c.Problem(where, "valueReference is no xs:unsignedInt");
  }
  // FMI 2.0 allows aliases (one reference, several names); FMI 3.0 none.
  if (c.value_references[sv.attribute("valueReference").value()]++ && c.v3) {
    c.Problem(where, "valueReference used twice");
  }
  const bool real = tag == "Real" || tag == "Float64" || tag == "Float32";
  const std::string causality =
      sv.attribute("causality") ? sv.attribute("causality").value() : "local";
  const std::string variability = sv.attribute("variability") ? sv.attribute("variability").value()
                                  : real                      ? "continuous"
                                                              : "discrete";
  CheckCausality(causality, variability, real, where, c);
  if (causality == "output") {
    c.outputs.push_back(c.v3 ? std::string(sv.attribute("valueReference").value())
                             : std::to_string(index));
  }
  const bool needs_start = causality == "parameter" || causality == "input" ||
                           causality == "structuralParameter" || variability == "constant";
  if (tag == "Binary" || tag == "String" || tag == "Clock") {
    if (needs_start && !type_node.attribute("start") && !type_node.child("Start")) {
      c.Problem(where, "no start value, required of a " + causality);
    }
    return;
  }
  const auto& kinds = c.v3 ? kTypes3 : kTypes2;
  const auto kind = kinds.find(tag);
  if (kind == kinds.end()) {
    c.Problem(where, "unknown type element");
    return;
  }
  CheckNumbers(type_node, kind->second, real, where, c);
  const bool has_start = type_node.attribute("start");
  if (needs_start && !has_start) {
    c.Problem(where, "no start value, required of a " + causality + " / " + variability);
  }
  const std::string initial = sv.attribute("initial").value();
  if ((causality == "independent" || initial == "calculated") && has_start) {
    c.Problem(where, "a start value, forbidden for " +
                         (causality == "independent" ? std::string("the independent variable")
                                                     : std::string("initial=calculated")));
  }
  for (const std::string attribute : {"unit", "displayUnit"}) {
    const std::string unit = type_node.attribute(attribute.c_str()).value();
    if (!unit.empty() && !c.units.count(unit)) {
      c.Problem(where, attribute + " '" + unit + "' is not in UnitDefinitions");
    }
  }
  const std::string declared = type_node.attribute("declaredType").value();
  if (!declared.empty() && !c.types.count(declared)) {
    c.Problem(where, "declaredType '" + declared + "' is not in TypeDefinitions");
  }
}

// Every output in ModelStructure, once (FMI 2.0: in the order of
// ModelVariables); the units of declared types defined.
inline void CheckStructureAndTypes(const pugi::xml_node& root, SchemaCheck& c) {
  std::vector<std::string> listed;
  const pugi::xml_node structure = root.child("ModelStructure");
  if (c.v3) {
    for (const auto& o : structure.children("Output")) {
      listed.push_back(o.attribute("valueReference").value());
    }
    const std::multiset<std::string> a(c.outputs.begin(), c.outputs.end());
    if (a != std::multiset<std::string>(listed.begin(), listed.end())) {
      c.Problem("ModelStructure", "the <Output> elements are not the outputs, once each");
    }
  } else {
    for (const auto& u : structure.child("Outputs").children("Unknown")) {
      listed.push_back(u.attribute("index").value());
    }
    if (listed != c.outputs) c.Problem("ModelStructure/Outputs", "not every output, in order");
  }
  for (const auto& t : root.child("TypeDefinitions").children()) {
    std::vector<pugi::xml_node> nodes{t};
    for (const auto& child : t.children()) nodes.push_back(child);  // FMI 2.0's type element
    for (const auto& n : nodes) {
      const std::string unit = n.attribute("unit").value();
      if (!unit.empty() && !c.units.count(unit)) {
        c.Problem(std::string("type '") + t.attribute("name").value() + "'",
                  "unit '" + unit + "' is not in UnitDefinitions");
      }
    }
  }
}

// Every way `xml` (a modelDescription.xml of FMI 2.0 or 3.0) breaks the
// rules, one line each naming the variable and attribute; empty when none.
inline std::vector<std::string> SchemaProblems(const std::string& xml) {
  pugi::xml_document doc;
  if (!doc.load_string(xml.c_str())) return {"not well-formed XML"};
  const pugi::xml_node root = doc.child("fmiModelDescription");
  const std::string version = root.attribute("fmiVersion").value();
  SchemaCheck c;
  c.v3 = version.rfind("3.", 0) == 0;
  if (version != "2.0" && !c.v3) return {"fmiVersion '" + version + "'"};
  for (const char* a : {"modelName", c.v3 ? "instantiationToken" : "guid"}) {
    if (!root.attribute(a))
      c.Problem("fmiModelDescription", std::string("no ") + a + " (required)");
  }
  if (!root.child("CoSimulation").attribute("modelIdentifier")) {
    c.Problem("CoSimulation", "no modelIdentifier (required)");
  }
  for (const auto& u : root.child("UnitDefinitions").children("Unit")) {
    c.units.insert(u.attribute("name").value());
  }
  for (const auto& t : root.child("TypeDefinitions").children()) {
    c.types.insert(t.attribute("name").value());
  }
  int index = 0;
  for (const auto& sv : root.child("ModelVariables").children()) {
    if (sv.type() == pugi::node_element) CheckVariable(sv, ++index, c);
  }
  CheckStructureAndTypes(root, c);
  return c.problems;
}

}  // namespace linesim::fmu::test
